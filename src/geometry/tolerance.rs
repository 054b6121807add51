//! Every tolerance of the crate, in one place.
//!
//! The pipeline works in bbox-100 units (the input scaled so that its bounding box's longest
//! side is 100, Sec. 7 of the paper), so a length tolerance given here in those units scales
//! with the model. Tolerances on measures that are themselves scale-free (areas relative to the
//! squared edge length, the spectral measure, triangle quality Q) are dimensionless.

/// Input vertices closer than this fraction of the input's bounding-box diagonal are one vertex
/// ([`TriMesh::weld_close_positions`](crate::TriMesh::weld_close_positions), on reading):
/// CAD exports repeat a seam's corners with positions a rounding apart (2.7e-16 of the diagonal
/// on featuretype.STL), which read exactly leave cracks along the seams. Far above rounding of
/// coordinates, far below any feature a remesher can keep: on the real-world corpus 1e-10 closes
/// every such crack (six files) and merges nothing else, while 1e-7 already joins distinct
/// sheets of a glTF scene into non-manifold edges. Dimensionless.
pub const WELD_RELATIVE: f64 = 1e-10;

/// Two input vertices are welded only when also within this fraction of the shortest edge at
/// either (`TriMesh::weld_close_positions`): in a mesh spanning many scales (a unit part and a
/// stray triangle 1e12 away, or a tetrahedron 2.5e10 long with a 0.4 edge) a fraction of the
/// bounding box's diagonal is larger than whole faces. A seam's corners a rounding apart are
/// 1e-15 of their edges and closer. Dimensionless.
pub const WELD_EDGE_RELATIVE: f64 = 1e-7;

/// Curve samples closer than this (bbox-100 units) are one sample
/// (`sampling::curves::sample_curves`): two boundary or crease curves along input edges that
/// coincide (a seam whose corners are a rounding apart but not welded, the edges at them being
/// slivers) otherwise put a sample of each at the same place, which the output would write as
/// two vertices a reader welds into duplicate faces. Far above rounding at bbox 100.
pub const CURVE_SAMPLE_COINCIDENT: f64 = 1e-9;

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

/// How far in front of the surface a point is tested for being buried inside the input's own solid
/// ([`BuriedTest`](crate::internal::BuriedTest)), bbox-100 units: far below any sampling spacing,
/// far above rounding.
pub const BURIED_OFFSET: f64 = 1e-3;

/// The relative slack on a distance bound used only to prune a closest-point search (the bound
/// is made strictly larger than the answer it must not exclude). Dimensionless.
pub const SEARCH_BOUND_SLACK: f64 = 1e-9;

/// Slack on an angle in radians when a wedge of a tangent-plane umbrella is tested for
/// containing an edge direction (`triangulate::tangent_delaunay`): an edge exactly on the
/// wedge's side counts as inside. Dimensionless (radians), far above rounding of `atan2`.
pub const ANGLE_SLACK: f64 = 1e-9;

/// The least gain in the smaller minimum angle of two triangles, in degrees, for a max-min edge
/// flip to be taken (`triangulate::flip`): smaller gains are rounding and would let two flips
/// undo each other forever.
pub const FLIP_MIN_ANGLE_GAIN_DEG: f64 = 1e-6;

/// The least gain in a quality (a triangle's Q, or a smallest angle in degrees) for a local
/// move of the optimization to count as an improvement, and the least Q of a triangle the hole
/// filling accepts. Dimensionless.
pub const IMPROVEMENT_TOLERANCE: f64 = 1e-9;

/// Below this width of the bracket on log sigma_p, and this difference of log counts between its
/// ends, the sigma_p search (`sampling::target_count`) stops narrowing it: the bracket is then a
/// relative width of 1e-9 on sigma_p. Dimensionless (natural logarithms).
pub const LOG_BRACKET_TOLERANCE: f64 = 1e-9;

/// Two log counts closer than this make no secant (`sampling::target_count`). Dimensionless.
pub const LOG_COUNT_TOLERANCE: f64 = 1e-12;

/// A point within this fraction of the sample spacing of an input face lies in it: the vertices
/// the restricted Delaunay triangulation adds to the input (edge midpoints) lie on their faces up
/// to rounding, far closer than a sheet across a thin part.
pub const ON_SURFACE_RELATIVE: f64 = 1e-9;

/// Two squared lengths within this relative difference count as equal where a choice between
/// them must not depend on rounding (the longest edge of a face in `mesh::bisect`: a mesh read
/// from float32 coordinates and the same mesh from text refine alike). Dimensionless.
pub const LENGTH_TIE: f64 = 1e-6;

/// The smallest angle (degrees) a triangle made by the recovery of a crease edge may have
/// (`triangulate::recover`): a vertex a hair off the segment would otherwise give a sliver of
/// nearly 180°, worse than leaving the edge out (found with `--sigma-n 3` on fandisk: 0.05°).
pub const RECOVERY_MIN_ANGLE_DEG: f64 = 2.0;
