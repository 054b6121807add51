//! Poisson-disk subsampling by dart throwing on the input points.

use glam::DVec3;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rustc_hash::FxHashMap;

use spectral_remesh::internal::{find_sigma_p, TargetCountParams, TargetCountResult};

/// Visits `positions` (any units; `radius` in the same) in a random order (seeded) and keeps a
/// point when no kept point lies closer than `radius` (Euclidean distance): a maximal Poisson-
/// disk subset of the input (every dropped point is within `radius` of a kept one). Returns the
/// kept indices in increasing order. Non-finite points are ignored; a `radius` that is not
/// positive and finite keeps every finite point.
///
/// Uses a hash grid of cells of side `radius`: a point's conflicts lie in its cell and the 26
/// around it.
///
/// Source: dart throwing (R. L. Cook, *Stochastic Sampling in Computer Graphics*, ACM TOG 5(1),
/// 1986, doi:10.1145/7529.8927), here restricted to the input points as candidates, as in
/// sample elimination for point sets.
pub fn poisson_disk_subsample(positions: &[DVec3], radius: f64, seed: u64) -> Vec<usize> {
    let mut order: Vec<usize> = (0..positions.len())
        .filter(|&i| positions[i].is_finite())
        .collect();
    if !(radius.is_finite() && radius > 0.0) {
        return order;
    }
    order.shuffle(&mut ChaCha8Rng::seed_from_u64(seed));
    let cell_of = |p: DVec3| {
        let q = (p / radius).floor();
        [q.x as i64, q.y as i64, q.z as i64]
    };
    let r2 = radius * radius;
    let mut grid: FxHashMap<[i64; 3], Vec<u32>> = FxHashMap::default();
    let mut kept: Vec<usize> = Vec::new();
    for i in order {
        let p = positions[i];
        let c = cell_of(p);
        let mut free = true;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                        if list
                            .iter()
                            .any(|&j| positions[j as usize].distance_squared(p) < r2)
                        {
                            free = false;
                            break 'search;
                        }
                    }
                }
            }
        }
        if free {
            grid.entry(c).or_default().push(i as u32);
            kept.push(i);
        }
    }
    kept.sort_unstable();
    kept
}

/// [`poisson_disk_subsample`] with the radius searched (log-log secant, starting from `start`)
/// for `target.target` points within `target.tolerance`; the result's `sigma_p` is the radius.
pub fn poisson_disk_subsample_to_count(
    positions: &[DVec3],
    target: &TargetCountParams,
    start: f64,
    seed: u64,
) -> TargetCountResult<Vec<usize>> {
    find_sigma_p(target, start, |radius| {
        let kept = poisson_disk_subsample(positions, radius, seed);
        (kept.len(), kept)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;

    #[test]
    fn kept_points_are_apart_and_dropped_ones_are_covered() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let positions: Vec<DVec3> = (0..5000)
            .map(|_| DVec3::new(rng.random(), rng.random(), 0.0) * 10.0)
            .collect();
        let radius = 0.3;
        let kept = poisson_disk_subsample(&positions, radius, 2);
        // Brute-force oracle.
        for (a, &i) in kept.iter().enumerate() {
            for &j in &kept[a + 1..] {
                assert!(positions[i].distance(positions[j]) >= radius);
            }
        }
        for (i, p) in positions.iter().enumerate() {
            if kept.binary_search(&i).is_err() {
                assert!(kept.iter().any(|&j| positions[j].distance(*p) < radius));
            }
        }
        assert_eq!(kept, poisson_disk_subsample(&positions, radius, 2));
        let r = poisson_disk_subsample_to_count(&positions, &TargetCountParams::new(300), 1.0, 2);
        assert!(r.reached, "{:?}", r.history);
    }
}
