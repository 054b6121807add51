//! The sample spacing a kernel width gives: how many samples the linear scan and gradient
//! ascent leave on a surface at sigma_p, and the spacing of the fixed samples on its boundary and
//! crease curves, in units of sigma_p (bbox-100 units throughout).

/// Output samples per unit of sigma_p^-2 area: a linear scan with epsilon = 0.5 followed by
/// gradient ascent leaves about `SAMPLES_PER_SIGMA2 · A / sigma_p^2` samples on a surface of area
/// A. Measured on the shared models (horse, spot, fandisk); used for the first guess of the
/// sigma_p search and to size the candidate pool when sigma_p is given.
pub const SAMPLES_PER_SIGMA2: f64 = 1.0;

/// Spacing of the boundary samples in units of sigma_p: the mean edge length the interior
/// sampling reaches (measured), so boundary triangles match interior ones.
pub const BOUNDARY_SPACING_PER_SIGMA: f64 = 1.0;

/// Spacing of the crease samples in units of sigma_p: the median edge length of the output
/// away from the creases, so the triangles along a crease are as large as the others (at the
/// boundary's 1.0 they stood too tall on their crease edge; the figures:
/// `docs/decisions/feature-spacing.md`).
pub const FEATURE_SPACING_PER_SIGMA: f64 = 1.15;

/// The mean edge of a point set's output in units of sigma_p: its samples lie sparser than a
/// mesh's at the same sigma_p (the RIMLS surface's projection). Measured at sigma_p 2 and 6.25:
/// 1.18 (20,000 points on a sphere), 1.19 (../shared/scans/bun000.xyz), 1.22
/// (../shared/scans/milk.pcd). `--edge-length L` on a point set takes sigma_p = L / this (bbox-100).
pub const POINT_SET_EDGE_PER_SIGMA: f64 = 1.2;

/// The samples a surface of area `area` with boundary curves `boundary_length` long (bbox-100
/// units) is expected to get at `sigma_p`: `SAMPLES_PER_SIGMA2 · A / sigma_p²` inside and one
/// per `BOUNDARY_SPACING_PER_SIGMA · sigma_p` along the boundary.
pub fn expected_samples(area: f64, boundary_length: f64, sigma_p: f64) -> f64 {
    SAMPLES_PER_SIGMA2 * area / (sigma_p * sigma_p)
        + boundary_length / (BOUNDARY_SPACING_PER_SIGMA * sigma_p)
}

/// The first guess of the sigma_p search for `count` samples (bbox-100 units): the larger of
/// the sigma_p at which the area alone (`sqrt(SAMPLES_PER_SIGMA2 · A / count)`) and the boundary
/// curves alone (`L / (BOUNDARY_SPACING_PER_SIGMA · count)`) give `count`. Each term of
/// [`expected_samples`] alone is at most `count` there, so the expected count at the guess is
/// between `count` and `2 · count`, however long the boundary is for the area (a sliver, a
/// needle): from the area alone the guess would be far too small there, and the boundary
/// samples alone many times the target. On a surface whose area term dominates (every closed
/// one) it is the area-only guess.
pub fn sigma_p_for_count(area: f64, boundary_length: f64, count: f64) -> f64 {
    let from_area = (SAMPLES_PER_SIGMA2 * area / count).sqrt();
    let from_boundary = boundary_length / (BOUNDARY_SPACING_PER_SIGMA * count);
    from_area.max(from_boundary)
}
