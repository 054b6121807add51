//! The weights a subset carries for the points it dropped (Sec. 5 of the spectral sampling
//! paper).

use glam::DVec3;
use rayon::prelude::*;

use spectral_remesh::internal::{
    projection_coefficients, Kernel, KernelPoint, MeasureWorkspace, StaticTree, SUPPORT_RADIUS,
};
use spectral_remesh::{Error, Result};

/// Parameters of [`representation_weights`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RepresentationParams {
    /// The kept points a dropped point is projected onto are those within this kernel-space
    /// distance of it (dimensionless, > 0). Default [`SUPPORT_RADIUS`] = 2.5, the neighbourhood of
    /// the linear scan (Sec. 6.3).
    pub support_radius: f64,
    /// At most this many of them, the nearest in kernel space (≥ 1). Default 32: on a surface
    /// the linear scan's samples (ε = 0.5) are about 0.8 σ_p apart, so about 30 lie within the
    /// support; the projection costs O(m³) in their number m.
    pub max_neighbours: usize,
}

impl Default for RepresentationParams {
    fn default() -> Self {
        RepresentationParams {
            support_radius: SUPPORT_RADIUS,
            max_neighbours: 32,
        }
    }
}

/// The output of [`representation_weights`].
#[derive(Debug, Clone, PartialEq)]
pub struct RepresentationWeights {
    /// One weight per kept point (in the order of `kept`), ≥ 0, in units of input points: about
    /// how many input points it stands for. They sum to the input's count, less what was
    /// clamped.
    pub weights: Vec<f64>,
    /// Kept points whose summed coefficient came out negative and was set to 0.
    pub clamped: usize,
    /// Input points with no kept point within the support (possible for subsets other than the
    /// linear scan's: the scan keeps every point with no sample in its support); each gave its
    /// weight to the kept point nearest in position.
    pub unsupported: usize,
}

/// Input points per sequential run of the accumulation (fixed, so the sums do not depend on the
/// number of threads).
const CHUNK: usize = 1 << 14;

/// The weights of a subset `kept` (indices into `positions`, distinct) of an oriented point set
/// (`positions` in bbox-100 units, unit `normals`, both `N` long) after Sec. 5 of the paper:
/// every input point x_j starts with weight 1; a dropped point's φ(x_j) is projected onto the
/// span of the φ(x_i) of the kept points near it, φ(x_j) ≈ Σ_i a_i^j φ(x_i) with
/// a^j = K^-1 k(x_j) ([`projection_coefficients`]; K over those kept points, nearest first, in
/// `kernel`'s space), and its weight moves to them: w_i += a_i^j. So a kernel sum over all
/// points, Σ_j k(·, x_j), is approximated by Σ_i w_i k(·, x_i) over the kept ones, with an error
/// set by the measure s(x_j) of each dropped point (Sec. 5: "the weighted average can be
/// computed by modifying the weights and storing only the vectors φ(x_i), i ≠ j"). A kept point
/// projects onto itself (a = 1 for it, 0 for the rest).
///
/// Coefficients can be negative; a kept point whose total is negative gets weight 0
/// ([`RepresentationWeights::clamped`]). An input point with no kept point within the support
/// gives its weight to the nearest kept point ([`RepresentationWeights::unsupported`]).
///
/// Reconstructing with these weights as masses ([`spectral_remesh::internal::Rimls::with_masses`])
/// makes the subset's RIMLS surface follow the all-points one where the subset's density
/// differs from the input's (the linear scan's adaptive sampling with a finite σ_n keeps more
/// points where the normals turn; uniform weights over-count them there).
///
/// Deterministic; runs in parallel (rayon) over fixed chunks of the input.
///
/// # Errors
/// [`Error::InvalidParameter`] when `normals` has another length than `positions`, `kept` is
/// empty or holds an index out of range, or the parameters are out of range.
pub fn representation_weights(
    positions: &[DVec3],
    normals: &[DVec3],
    kept: &[usize],
    kernel: &Kernel,
    params: &RepresentationParams,
) -> Result<RepresentationWeights> {
    let bad = |name: &'static str, message: String| Err(Error::InvalidParameter { name, message });
    if normals.len() != positions.len() {
        return bad(
            "normals",
            format!(
                "{} normals for {} positions",
                normals.len(),
                positions.len()
            ),
        );
    }
    if kept.is_empty() {
        return bad("kept", "no kept point".into());
    }
    if let Some(&i) = kept.iter().find(|&&i| i >= positions.len()) {
        return bad(
            "kept",
            format!("index {i} out of range for {} points", positions.len()),
        );
    }
    if !(params.support_radius.is_finite() && params.support_radius > 0.0) {
        return bad(
            "support_radius",
            format!(
                "must be a positive finite number, got {}",
                params.support_radius
            ),
        );
    }
    if params.max_neighbours == 0 {
        return bad("max_neighbours", "must be at least 1".into());
    }
    let kept_positions: Vec<DVec3> = kept.iter().map(|&i| positions[i]).collect();
    let embedded: Vec<KernelPoint> = kept
        .iter()
        .map(|&i| kernel.embed(positions[i], normals[i]))
        .collect();
    let tree = StaticTree::new(&kept_positions);
    // Kernel distance r bounds the position distance by r σ_p.
    let radius = params.support_radius * kernel.sigma_p();
    let support_2 = params.support_radius * params.support_radius;

    struct Scratch {
        found: Vec<(u32, f64)>,
        near: Vec<(f64, u32)>,
        points: Vec<KernelPoint>,
        alpha: Vec<(usize, f64)>,
        ws: MeasureWorkspace,
    }
    let new_scratch = || Scratch {
        found: Vec::new(),
        near: Vec::new(),
        points: Vec::new(),
        alpha: Vec::new(),
        ws: MeasureWorkspace::new(),
    };
    let m = kept.len();
    let chunks: Vec<(Vec<f64>, usize)> = (0..positions.len())
        .collect::<Vec<usize>>()
        .par_chunks(CHUNK)
        .map_init(new_scratch, |s, chunk| {
            let mut acc = vec![0.0; m];
            let mut unsupported = 0;
            for &j in chunk {
                let x = kernel.embed(positions[j], normals[j]);
                tree.within_unsorted(positions[j], radius * radius, &mut s.found);
                s.near.clear();
                s.near.extend(s.found.iter().filter_map(|&(i, _)| {
                    let d2 = x.dist2(&embedded[i as usize]);
                    (d2 <= support_2).then_some((d2, i))
                }));
                if s.near.is_empty() {
                    unsupported += 1;
                    tree.nearest_n(positions[j], 1, &mut s.found);
                    if let Some(&(i, _)) = s.found.first() {
                        acc[i as usize] += 1.0;
                    }
                    continue;
                }
                s.near
                    .sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                s.near.truncate(params.max_neighbours);
                s.points.clear();
                s.points
                    .extend(s.near.iter().map(|&(_, i)| embedded[i as usize]));
                projection_coefficients(kernel, &x, &s.points, &mut s.ws, &mut s.alpha);
                for &(r, a) in &s.alpha {
                    acc[s.near[r].1 as usize] += a;
                }
            }
            (acc, unsupported)
        })
        .collect();
    let mut weights = vec![0.0; m];
    let mut unsupported = 0;
    for (acc, u) in chunks {
        for (w, a) in weights.iter_mut().zip(acc) {
            *w += a;
        }
        unsupported += u;
    }
    let mut clamped = 0;
    for w in &mut weights {
        if *w < 0.0 {
            *w = 0.0;
            clamped += 1;
        }
    }
    Ok(RepresentationWeights {
        weights,
        clamped,
        unsupported,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::subsample::linear_scan_subsample;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use spectral_remesh::internal::LinearScanParams;

    /// A `side × side` square grid of spacing `h` in the plane z = 0, normals up.
    fn plane(side: usize, h: f64) -> (Vec<DVec3>, Vec<DVec3>) {
        let p: Vec<DVec3> = (0..side * side)
            .map(|k| DVec3::new((k % side) as f64 * h, (k / side) as f64 * h, 0.0))
            .collect();
        let n = vec![DVec3::Z; p.len()];
        (p, n)
    }

    #[test]
    fn weights_count_the_points_each_kept_point_stands_for() {
        // 200 x 200 points 0.1 apart; the linear scan at sigma_p 1 keeps about 1 in 60.
        let (p, n) = plane(200, 0.1);
        let kernel = Kernel::new(1.0, 0.75).unwrap();
        let kept = linear_scan_subsample(&p, &n, &kernel, &LinearScanParams::default(), 3);
        let r = representation_weights(&p, &n, &kept, &kernel, &RepresentationParams::default())
            .unwrap();
        assert_eq!(r.unsupported, 0);
        let total: f64 = r.weights.iter().sum();
        // A kernel sum over all points is reproduced by the weighted kept points, so the weights
        // add up to about the count: less the part of each dropped point orthogonal to the
        // kept ones (its measure, at most epsilon = 0.5), most of it at the plane's border.
        let ratio = total / p.len() as f64;
        assert!((0.9..1.01).contains(&ratio), "{total} for {}", p.len());
        // Inside, the weighted kernel sum over the kept points follows the kernel sum over all
        // points up to a constant factor (the projections' shortfall, the same everywhere for a
        // scan of a plane); with unit weights it follows the scan's local density instead.
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let (mut weighted, mut unit) = (Vec::new(), Vec::new());
        for _ in 0..300 {
            let z = kernel.embed(
                DVec3::new(
                    rng.random_range(5.0..15.0),
                    rng.random_range(5.0..15.0),
                    0.0,
                ),
                DVec3::Z,
            );
            let sum_all: f64 = p
                .iter()
                .map(|&q| kernel.eval(&z, &kernel.embed(q, DVec3::Z)))
                .sum();
            let k_kept = |i: usize| kernel.eval(&z, &kernel.embed(p[i], DVec3::Z));
            let sum_w: f64 = kept
                .iter()
                .zip(&r.weights)
                .map(|(&i, &w)| w * k_kept(i))
                .sum();
            let sum_1: f64 = kept.iter().map(|&i| k_kept(i)).sum();
            weighted.push(sum_w / sum_all);
            unit.push(sum_1 / sum_all);
        }
        let cv = |v: &[f64]| {
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / v.len() as f64;
            (mean, var.sqrt() / mean)
        };
        let ((mean_w, cv_w), (_, cv_1)) = (cv(&weighted), cv(&unit));
        // Measured: mean 0.96, cv 0.04 against 0.15 with unit weights.
        assert!((0.85..1.0).contains(&mean_w), "{mean_w}");
        assert!(cv_w < 0.5 * cv_1, "weighted cv {cv_w}, unit weights {cv_1}");
        // Same input, same weights.
        let again =
            representation_weights(&p, &n, &kept, &kernel, &RepresentationParams::default())
                .unwrap();
        assert_eq!(r, again);
    }

    #[test]
    fn a_kept_cluster_shares_the_weight_of_its_region() {
        // The plane kept on a regular 1.0 grid, but with 4 extra points kept close together
        // around (10, 10): together they stand for about what one grid point would.
        let (p, n) = plane(200, 0.1);
        let kernel = Kernel::new(1.0, f64::INFINITY).unwrap();
        let mut kept: Vec<usize> = (0..p.len())
            .filter(|&k| (k % 200) % 10 == 0 && (k / 200) % 10 == 0 && k != 100 * 200 + 100)
            .collect();
        let cluster = [
            99 * 200 + 99,
            99 * 200 + 101,
            101 * 200 + 99,
            101 * 200 + 101,
        ];
        kept.extend(cluster);
        kept.sort_unstable();
        let r = representation_weights(&p, &n, &kept, &kernel, &RepresentationParams::default())
            .unwrap();
        let weight_of = |i: usize| r.weights[kept.binary_search(&i).unwrap()];
        let grid_point = weight_of(80 * 200 + 80);
        assert!((80.0..120.0).contains(&grid_point), "{grid_point}");
        let cluster_total: f64 = cluster.iter().map(|&i| weight_of(i)).sum();
        assert!(
            (cluster_total / grid_point - 1.0).abs() < 0.25,
            "cluster {cluster_total} vs grid point {grid_point}"
        );
        // Unit weights would count the cluster 4 times.
        for &i in &cluster {
            assert!(weight_of(i) < 0.5 * grid_point, "{}", weight_of(i));
        }
    }

    #[test]
    fn a_far_point_goes_to_its_nearest_kept_point_and_bad_input_is_an_error() {
        let p = vec![
            DVec3::ZERO,
            DVec3::new(0.5, 0.0, 0.0),
            DVec3::new(50.0, 0.0, 0.0),
        ];
        let n = vec![DVec3::Z; 3];
        let kernel = Kernel::new(1.0, 0.75).unwrap();
        let params = RepresentationParams::default();
        let r = representation_weights(&p, &n, &[0], &kernel, &params).unwrap();
        assert_eq!(r.unsupported, 1);
        // Point 1 projects onto point 0 with a = k(x_1, x_0) = exp(-0.25); point 2 adds 1.
        assert!((r.weights[0] - (1.0 + (-0.25f64).exp() + 1.0)).abs() < 1e-12);
        assert!(representation_weights(&p, &n[..2], &[0], &kernel, &params).is_err());
        assert!(representation_weights(&p, &n, &[], &kernel, &params).is_err());
        assert!(representation_weights(&p, &n, &[3], &kernel, &params).is_err());
        let bad = RepresentationParams {
            max_neighbours: 0,
            ..params
        };
        assert!(representation_weights(&p, &n, &[0], &kernel, &bad).is_err());
    }
}
