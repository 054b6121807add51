//! Every tolerance of the crate, in one place.
//!
//! The pipeline works in bbox-100 units (the input scaled so that its bounding box's longest
//! side is 100, Sec. 7 of the paper), so a length tolerance given here in those units scales
//! with the model. Tolerances on measures that are themselves scale-free (areas relative to the
//! squared edge length, the spectral measure, triangle quality Q) are dimensionless.

/// Relative tolerance of the zero-area test: a triangle is degenerate when
/// `|(b-a)×(c-a)| <= DEGENERATE_AREA_TOLERANCE · h²`, with `h` its longest edge. The test is
/// scale-free (both sides scale with length²); `|(b-a)×(c-a)| / h²` is about the sine of the
/// triangle's smallest angle, so the threshold flags triangles whose smallest angle is below
/// about 1e-12 rad (≈ 6e-11°).
pub const DEGENERATE_AREA_TOLERANCE: f64 = 1e-12;

/// A neighbour x_{n+1} whose g_n^-1 = k(x_{n+1}, x_{n+1}) - k_n^T K_n^-1 k_n falls below this is
/// skipped: φ(x_{n+1}) is then (numerically) in the span of the neighbours already taken and adds
/// nothing to the projection (Sec. 6.1 of the paper). Dimensionless (k(x, x) = 1).
pub const SINGULAR_TOLERANCE: f64 = 1e-9;

/// How far in front of the surface a point is tested for being buried inside the input's own
/// solid ([`BuriedTest`](crate::BuriedTest)), bbox-100 units: far below any sampling spacing,
/// far above rounding.
pub const BURIED_OFFSET: f64 = 1e-3;

/// The relative slack on a distance bound used only to prune a closest-point search (the bound
/// is made strictly larger than the answer it must not exclude). Dimensionless.
pub const SEARCH_BOUND_SLACK: f64 = 1e-9;
