//! A first guess of a point set's surface area from a uniformly random subset of its points:
//! the occupied cells of a grid at about twice their spacing. The sigma_p search starts from it
//! (`out_of_core.rs`), and the parts far apart share the count by it (`far_groups.rs`).

use glam::DVec3;

use super::stream::Point;

/// A first guess of the surface area (bbox-100 units²) of a uniformly random point subset, for
/// the start of the sigma_p search: the number of occupied cells of a grid of cell size h, times
/// h² / 1.5 (a plane of area A with unit normal n crosses about A (|n_x| + |n_y| + |n_z|) / h²
/// cells, 1.5 A / h² on average over orientations). h is 2, or twice the points' spacing where
/// that is wider: cells finer than the spacing see points, not the surface (200 points of a
/// sphere would read as 200 cells, a twentieth of its area, and the search would start where
/// every point is a sample and the count does not answer).
pub fn surface_area_guess(points: &[Point]) -> f64 {
    let h = (2.0 * median_spacing(points)).max(2.0);
    let mut cells: Vec<[i32; 3]> = points
        .iter()
        .map(|p| (p.position / h).floor().as_ivec3().to_array())
        .collect();
    cells.sort_unstable();
    cells.dedup();
    (cells.len() as f64 * h * h / 1.5).max(1.0)
}

/// The median distance from a point of `points` (a uniformly random subset) to its nearest
/// other, estimated on the first points (at most 20,000, scaled to the whole as the spacing goes
/// with the inverse square root of the count on a surface) at up to 1,000 of them; 0 for fewer
/// than two points.
fn median_spacing(points: &[Point]) -> f64 {
    let m = points.len().min(20_000);
    if m < 2 {
        return 0.0;
    }
    let positions: Vec<DVec3> = points[..m].iter().map(|p| p.position).collect();
    let tree = crate::spatial::StaticTree::new(&positions);
    let mut found = Vec::new();
    let mut d: Vec<f64> = positions
        .iter()
        .step_by(m.div_ceil(1000))
        .map(|&p| {
            tree.nearest_n(p, 2, &mut found);
            found.get(1).map_or(0.0, |&(_, d2)| d2.sqrt())
        })
        .collect();
    d.sort_by(f64::total_cmp);
    d[d.len() / 2] * (m as f64 / points.len() as f64).sqrt()
}
