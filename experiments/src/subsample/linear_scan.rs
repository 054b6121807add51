//! The paper's subsampler over an in-memory point set: the randomized linear scan.

use glam::DVec3;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use spectral_remesh::internal::{Kernel, LinearScanParams, LinearScanner};

/// Algorithm 1 (Sec. 6.1) over `positions` (bbox-100 units) with unit `normals` (same length):
/// the points are visited in a random order (seeded) and kept when s(x) > epsilon against the
/// points kept so far, with `kernel` (the same sigma_p, sigma_n the surface is reconstructed
/// with, Sec. 3). Returns the kept indices in increasing order.
///
/// # Panics
/// When `normals` is shorter than `positions`.
pub fn linear_scan_subsample(
    positions: &[DVec3],
    normals: &[DVec3],
    kernel: &Kernel,
    params: &LinearScanParams,
    seed: u64,
) -> Vec<usize> {
    let mut order: Vec<usize> = (0..positions.len()).collect();
    order.shuffle(&mut ChaCha8Rng::seed_from_u64(seed));
    let batch: Vec<(DVec3, DVec3)> = order.iter().map(|&i| (positions[i], normals[i])).collect();
    let mut scanner = LinearScanner::new(kernel, params);
    let mut accepted = Vec::new();
    scanner.offer_batch(&batch, &mut accepted);
    let mut out: Vec<usize> = accepted.into_iter().map(|k| order[k]).collect();
    out.sort_unstable();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_fewer_points_for_a_wider_kernel_and_repeats() {
        // A 40 x 40 plane, points on a 0.1 grid, normals up.
        let positions: Vec<DVec3> = (0..400 * 400)
            .map(|k| DVec3::new((k % 400) as f64 * 0.1, (k / 400) as f64 * 0.1, 0.0))
            .collect();
        let normals = vec![DVec3::Z; positions.len()];
        let params = LinearScanParams::default();
        let count = |s: f64| {
            let k = Kernel::new(s, 0.75).unwrap();
            linear_scan_subsample(&positions, &normals, &k, &params, 1).len()
        };
        let (a, b) = (count(1.0), count(2.0));
        // On a surface the count goes like sigma_p^-2.
        let ratio = a as f64 / b as f64;
        assert!((3.0..5.0).contains(&ratio), "{a} vs {b}");
        let k = Kernel::new(1.0, 0.75).unwrap();
        let x = linear_scan_subsample(&positions, &normals, &k, &params, 1);
        assert_eq!(
            x,
            linear_scan_subsample(&positions, &normals, &k, &params, 1)
        );
        assert!(x.windows(2).all(|w| w[0] < w[1]));
    }
}
