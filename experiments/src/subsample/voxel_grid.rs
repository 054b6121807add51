//! Voxel-grid clustering: one representative point per occupied voxel.

use glam::DVec3;
use rayon::prelude::*;

use spectral_remesh::internal::{find_sigma_p, TargetCountParams, TargetCountResult};

/// Clusters `positions` (any units; `voxel` in the same) by the cubic voxel of side `voxel` they
/// fall in (the grid anchored at the points' bounding-box minimum minus `offset · voxel`, each
/// component of `offset` in [0, 1): a shift of the grid) and keeps, per occupied voxel,
/// the point nearest the centroid of the voxel's points (ties: the lower index). Returns the kept
/// indices in increasing order; deterministic. Non-finite points are ignored; a `voxel` that is
/// not positive and finite keeps every finite point.
///
/// Source: the uniform clustering of M. Pauly, M. Gross, L. Kobbelt, *Efficient Simplification
/// of Point-Sampled Surfaces*, IEEE Visualization 2002, doi:10.1109/VISUAL.2002.1183771
/// (Sec. 3.1, clustering, with a voxel grid as the partition).
pub fn voxel_grid_subsample(positions: &[DVec3], voxel: f64, offset: DVec3) -> Vec<usize> {
    let finite: Vec<usize> = (0..positions.len())
        .filter(|&i| positions[i].is_finite())
        .collect();
    if !(voxel.is_finite() && voxel > 0.0) {
        return finite;
    }
    let lo = finite
        .iter()
        .fold(DVec3::splat(f64::INFINITY), |a, &i| a.min(positions[i]))
        - offset.clamp(DVec3::ZERO, DVec3::ONE) * voxel;
    let mut keyed: Vec<([i64; 3], usize)> = finite
        .par_iter()
        .map(|&i| {
            let q = ((positions[i] - lo) / voxel).floor();
            ([q.x as i64, q.y as i64, q.z as i64], i)
        })
        .collect();
    keyed.par_sort_unstable();
    let mut groups: Vec<&[([i64; 3], usize)]> = Vec::new();
    let mut start = 0;
    for k in 1..=keyed.len() {
        if k == keyed.len() || keyed[k].0 != keyed[start].0 {
            groups.push(&keyed[start..k]);
            start = k;
        }
    }
    let mut out: Vec<usize> = groups
        .par_iter()
        .map(|g| {
            let centroid = g.iter().map(|&(_, i)| positions[i]).sum::<DVec3>() / g.len() as f64;
            g.iter()
                .map(|&(_, i)| (positions[i].distance_squared(centroid), i))
                .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
                .map(|(_, i)| i)
                .unwrap_or(g[0].1)
        })
        .collect();
    out.sort_unstable();
    out
}

/// [`voxel_grid_subsample`] with the voxel size searched (log-log secant, starting from `start`
/// in the points' units) for `target.target` points within `target.tolerance`. The result's
/// `sigma_p` is the voxel size; `reached` says whether the count is within the tolerance (the
/// count is a step function of the size, so it may not be). `offset` shifts the grid as in
/// [`voxel_grid_subsample`].
pub fn voxel_grid_subsample_to_count(
    positions: &[DVec3],
    target: &TargetCountParams,
    start: f64,
    offset: DVec3,
) -> TargetCountResult<Vec<usize>> {
    find_sigma_p(target, start, |voxel| {
        let kept = voxel_grid_subsample(positions, voxel, offset);
        (kept.len(), kept)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_point_per_voxel_nearest_the_centroid() {
        // Two voxels of side 1: points at x = 0.1, 0.5, 0.8 and x = 1.2.
        let p = |x: f64| DVec3::new(x, 0.0, 0.0);
        let positions = vec![p(0.1), p(1.2), p(0.5), p(0.8), p(f64::NAN)];
        // The first voxel's centroid is 0.4667: 0.5 is nearest.
        assert_eq!(
            voxel_grid_subsample(&positions, 1.0, DVec3::ZERO),
            vec![1, 2]
        );
        assert_eq!(
            voxel_grid_subsample(&positions, 0.0, DVec3::ZERO),
            vec![0, 1, 2, 3]
        );
        // A shifted grid: points 0, 0.1, 0.4, 0.6, 0.95, 1.
        let positions: Vec<DVec3> = [0.0, 0.1, 0.4, 0.6, 0.95, 1.0].map(p).to_vec();
        // Voxels [0, 1) (centroid 0.41: 0.4) and [1, 2).
        assert_eq!(
            voxel_grid_subsample(&positions, 1.0, DVec3::ZERO),
            vec![2, 5]
        );
        // Shifted by half a voxel: [-0.5, 0.5) (centroid 0.167: 0.1) and [0.5, 1.5)
        // (centroid 0.85: 0.95).
        let half = DVec3::splat(0.5);
        assert_eq!(voxel_grid_subsample(&positions, 1.0, half), vec![1, 4]);
    }

    #[test]
    fn the_search_hits_the_count_on_a_dense_sphere() {
        // 100,000 points on a sphere of radius 10 (a Fibonacci spiral). (On an axis-aligned
        // plane the count is a coarse step function of the size and may miss the tolerance.)
        let n = 100_000;
        let positions: Vec<DVec3> = crate::test_points::fibonacci_sphere(n)
            .into_iter()
            .map(|u| 10.0 * u)
            .collect();
        let r = voxel_grid_subsample_to_count(
            &positions,
            &TargetCountParams::new(2000),
            1.0,
            DVec3::splat(0.3),
        );
        assert!(r.reached, "{:?}", r.history);
        assert!((r.count as f64 - 2000.0).abs() <= 10.0);
        assert_eq!(r.value.len(), r.count);
        assert!(r.history.len() <= 10, "{:?}", r.history);
    }
}
