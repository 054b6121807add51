//! The randomized linear scan (Sec. 6.1, Algorithm 1) on a point set in R^d, and the search for
//! the sigma_p that gives a count of samples.
//!
//! The output set O is kept in a dynamic kd-tree over the kernel-space points x = [p/sigma_p,
//! n/sigma_n] themselves, so a query within the support radius r = 2.5 finds exactly the
//! neighbours of Sec. 6.3, nearest first. A point is rejected at once when its nearest sample y
//! alone gives s(x) <= 1 - k(x, y)² <= epsilon (adding neighbours only lowers s); otherwise its
//! measure is evaluated over the whole neighbourhood with the iterative inversion of eq. 10,
//! stopping as soon as s <= epsilon.

use rand::seq::SliceRandom;
use rand::SeedableRng;

use super::dimension::estimate_in;
use super::{
    check_widths, random_probes, tree_frame, ManifoldSampleParams, ManifoldSampling, PointSet,
};
use crate::error::{Error, Result};
use crate::kernel::{GaussianKernel, UnitKernel};
use crate::measure::{spectral_measure, MeasureWorkspace};
use crate::sampling::target_count::{find_sigma_p, TargetCountParams};
use crate::spatial::{DynamicKdTree, StaticKdTree};

/// The parameters checked against the point set (see [`super::sample_manifold`]'s errors).
pub(super) fn check_params(points: &PointSet, params: &ManifoldSampleParams) -> Result<()> {
    let bad = |name, message: String| Err(Error::InvalidParameter { name, message });
    match (params.sigma_p, params.count) {
        (None, None) => return bad("count", "give sigma_p or count".into()),
        (Some(_), Some(_)) => return bad("count", "give sigma_p or count, not both".into()),
        (None, Some(c)) if c == 0 || c > points.len() => {
            return bad(
                "count",
                format!("must be from 1 to the {} points, got {c}", points.len()),
            )
        }
        _ => {}
    }
    check_widths(points, params.sigma_p.unwrap_or(1.0), params.sigma_n)?;
    if !(params.epsilon > 0.0 && params.epsilon < 1.0) {
        return bad(
            "epsilon",
            format!("must be in (0, 1), got {}", params.epsilon),
        );
    }
    if !(params.support_radius.is_finite() && params.support_radius > 0.0) {
        return bad(
            "support_radius",
            format!("must be a positive number, got {}", params.support_radius),
        );
    }
    if !(params.count_tolerance >= 0.0 && params.count_tolerance.is_finite()) {
        return bad(
            "count_tolerance",
            format!("must be a number >= 0, got {}", params.count_tolerance),
        );
    }
    if let Some(m) = params.dimension {
        if m == 0 || m > points.dim() {
            return bad(
                "dim",
                format!(
                    "the manifold's dimension must be from 1 to the space's {}, got {m}",
                    points.dim()
                ),
            );
        }
    }
    Ok(())
}

/// One linear scan's outcome: the accepted indices in the order of acceptance and its counts.
struct Scan {
    accepted: Vec<usize>,
    rejected_by_nearest: usize,
    measured: usize,
}

/// Algorithm 1 over the kernel-space points `x`, visited in `order`.
fn scan<const K: usize>(x: &[[f64; K]], order: &[usize], epsilon: f64, support: f64) -> Scan {
    let k = GaussianKernel::<K>;
    let mut tree = DynamicKdTree::<K>::new();
    let mut kept: Vec<[f64; K]> = Vec::new();
    let mut out = Scan {
        accepted: Vec::new(),
        rejected_by_nearest: 0,
        measured: 0,
    };
    let (mut found, mut near, mut ws) = (Vec::new(), Vec::new(), MeasureWorkspace::new());
    let r2 = support * support;
    for &i in order {
        let xi = x[i];
        let q = tree_frame(&xi);
        let accept = match tree.nearest(&q) {
            None => true,
            Some((j, _)) => {
                let k1 = k.eval(&xi, &kept[j as usize]);
                if k1 * k1 >= 1.0 - epsilon {
                    out.rejected_by_nearest += 1;
                    false
                } else {
                    tree.within(&q, r2, &mut found);
                    near.clear();
                    near.extend(found.iter().map(|&(j, _)| kept[j as usize]));
                    out.measured += 1;
                    near.is_empty()
                        || spectral_measure(&k, &xi, near.iter().copied(), epsilon, &mut ws).s
                            > epsilon
                }
            }
        };
        if accept {
            tree.add(&q, kept.len() as u32);
            kept.push(xi);
            out.accepted.push(i);
        }
    }
    out
}

/// [`super::sample_manifold`] in kernel dimension K (checked parameters).
pub(super) fn sample<const K: usize>(
    points: &PointSet,
    params: &ManifoldSampleParams,
) -> Result<ManifoldSampling> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.shuffle(&mut rand_chacha::ChaCha8Rng::seed_from_u64(params.seed));
    let run = |sigma_p: f64| {
        let x = points.embed::<K>(sigma_p, params.sigma_n);
        scan(&x, &order, params.epsilon, params.support_radius)
    };
    let finish = |sigma_p: f64, s: Scan, dimension, reached, search| {
        let mut indices = s.accepted;
        indices.sort_unstable();
        ManifoldSampling {
            indices,
            sigma_p,
            sigma_n: params.sigma_n,
            dimension,
            reached,
            search,
            rejected_by_nearest: s.rejected_by_nearest,
            measured: s.measured,
        }
    };
    if let Some(sigma_p) = params.sigma_p {
        let s = run(sigma_p);
        let search = vec![(sigma_p, s.accepted.len())];
        return Ok(finish(sigma_p, s, params.dimension, true, search));
    }
    let target = params.count.unwrap_or(1);
    // One position tree for the dimension estimate and the first guess of sigma_p.
    let (rows, tree) = points.position_tree::<K>();
    let m = match params.dimension {
        Some(m) => m,
        None => estimate_in(&rows, &tree, params.seed).round_dimension(points.dim()),
    };
    let search = TargetCountParams {
        tolerance: params.count_tolerance,
        dimension: m as f64,
        ..TargetCountParams::new(target)
    };
    let start = first_sigma_p(&rows, &tree, target, m, params.seed);
    let r = find_sigma_p(&search, start, |sigma_p| {
        let s = run(sigma_p);
        (s.accepted.len(), s)
    });
    if !(r.sigma_p.is_finite() && r.sigma_p > 0.0) {
        // Coordinates so large (or so small) that the search left the floating-point range.
        return Err(Error::InvalidParameter {
            name: "X",
            message: format!(
                "the search for the sigma_p of {target} samples left the floating-point range \
                 (sigma_p {}): rescale the points",
                r.sigma_p
            ),
        });
    }
    Ok(finish(r.sigma_p, r.value, Some(m), r.reached, r.history))
}

/// A first guess of the sigma_p that gives `target` samples of `points`, near a manifold of
/// dimension `m`: with h the median distance from a point to its nearest other (over at most
/// 1000 points), each point stands for a volume of about h^m, and a sample of the linear scan
/// for one of about sigma_p^m, so sigma_p ≈ h (n / target)^(1/m).
///
/// `rows` and `tree`: the points' positions and their kd-tree ([`PointSet::position_tree`]).
fn first_sigma_p<const K: usize>(
    rows: &[[f64; K]],
    tree: &StaticKdTree<K>,
    target: usize,
    m: usize,
    seed: u64,
) -> f64 {
    let probe = random_probes(rows.len(), 1000, seed ^ 0x5eed);
    let mut found = Vec::new();
    let mut h: Vec<f64> = probe
        .iter()
        .filter_map(|&i| {
            tree.nearest_n(&rows[i], 2, &mut found);
            found.get(1).map(|f| f.1.sqrt()).filter(|&h| h > 0.0)
        })
        .collect();
    h.sort_by(f64::total_cmp);
    let h = h.get(h.len() / 2).copied().unwrap_or(1.0);
    let ratio = rows.len() as f64 / target.max(1) as f64;
    h * ratio.max(1.0).powf(1.0 / m.max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::super::{sample_manifold, PointSet};
    use super::*;
    use crate::kernel::Kernel;
    use crate::sampling::linear_scan::tests::sphere_points;
    use crate::sampling::linear_scan::{LinearScanParams, LinearScanner};
    use rand::RngExt;

    /// Oracle: in R^3 the scan in kernel space makes the surface sampler's decisions
    /// (`LinearScanner`: a position kd-tree, quick tests, chunks in parallel), point for point,
    /// with and without normals.
    #[test]
    fn in_r3_the_scan_makes_the_surface_scanners_decisions() {
        for (sigma_n, seed) in [(f64::INFINITY, 1), (0.75, 2)] {
            let pts = sphere_points(30_000, seed);
            let kernel = Kernel::new(1.0, sigma_n).unwrap();
            let mut scanner = LinearScanner::new(&kernel, &LinearScanParams::default());
            let mut expected = Vec::new();
            scanner.offer_batch(&pts, &mut expected);
            let x: Vec<[f64; 6]> = pts
                .iter()
                .map(|&(p, n)| kernel.embed(p, n).coords)
                .collect();
            let order: Vec<usize> = (0..pts.len()).collect();
            let got = scan(&x, &order, 0.5, 2.5);
            assert!(expected.len() > 1000, "{}", expected.len());
            assert_eq!(got.accepted, expected, "sigma_n {sigma_n}");
        }
    }

    /// Points on the unit circle at uniform random angles.
    fn circle(n: usize, seed: u64) -> PointSet {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let xy: Vec<f64> = (0..n)
            .flat_map(|_| {
                let t: f64 = rng.random_range(0.0..std::f64::consts::TAU);
                [t.cos(), t.sin()]
            })
            .collect();
        PointSet::new(2, xy, None).unwrap()
    }

    #[test]
    fn a_count_is_found_and_the_same_seed_gives_the_same_samples() {
        let pts = circle(20_000, 3);
        let params = ManifoldSampleParams {
            count: Some(200),
            ..Default::default()
        };
        let a = sample_manifold(&pts, &params).unwrap();
        assert!(a.reached, "{:?}", a.search);
        assert!(
            (a.indices.len() as i64 - 200).abs() <= 1,
            "{}",
            a.indices.len()
        );
        assert_eq!(a.dimension, Some(1));
        assert!(a.indices.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(a, sample_manifold(&pts, &params).unwrap());
        let b = sample_manifold(&pts, &ManifoldSampleParams { seed: 2, ..params }).unwrap();
        assert_ne!(a.indices, b.indices);
        // sigma_p given: one scan at that width, a wider one keeps fewer (about 1/sigma_p).
        let at = |s: f64| {
            sample_manifold(
                &pts,
                &ManifoldSampleParams {
                    sigma_p: Some(s),
                    ..Default::default()
                },
            )
            .unwrap()
            .indices
            .len()
        };
        let ratio = at(0.02) as f64 / at(0.04) as f64;
        assert!((1.7..2.3).contains(&ratio), "{ratio}");
    }

    #[test]
    fn no_two_samples_are_closer_than_the_measure_allows() {
        // Two samples x, y with k(x, y)² >= 1 - epsilon cannot both be kept: the later one's s
        // is at most 1 - k² <= epsilon. With epsilon 0.5: |x - y|² > ln 2 / 2 in kernel units.
        let pts = circle(20_000, 4);
        let sigma_p = 0.03;
        let r = sample_manifold(
            &pts,
            &ManifoldSampleParams {
                sigma_p: Some(sigma_p),
                ..Default::default()
            },
        )
        .unwrap();
        let min_d = (std::f64::consts::LN_2 / 2.0).sqrt() * sigma_p;
        let p = |i: usize| pts.position(i).to_vec();
        for (a, &i) in r.indices.iter().enumerate() {
            for &j in &r.indices[a + 1..] {
                let d = p(i)
                    .iter()
                    .zip(p(j))
                    .map(|(u, v)| (u - v).powi(2))
                    .sum::<f64>()
                    .sqrt();
                assert!(d > min_d, "samples {i} and {j} at {d} < {min_d}");
            }
        }
    }

    #[test]
    fn bad_parameters_are_errors() {
        let pts = circle(100, 1);
        let with = |p: ManifoldSampleParams| sample_manifold(&pts, &p).unwrap_err().to_string();
        let d = ManifoldSampleParams::default();
        assert!(with(d).contains("sigma_p or count"));
        let both = ManifoldSampleParams {
            sigma_p: Some(1.0),
            count: Some(3),
            ..d
        };
        assert!(with(both).contains("not both"));
        assert!(with(ManifoldSampleParams {
            count: Some(101),
            ..d
        })
        .contains("count"));
        assert!(with(ManifoldSampleParams {
            sigma_p: Some(-1.0),
            ..d
        })
        .contains("invalid parameter sigma_p"));
        assert!(with(ManifoldSampleParams {
            sigma_p: Some(1.0),
            sigma_n: 0.5,
            ..d
        })
        .contains("needs normals"));
        assert!(with(ManifoldSampleParams {
            count: Some(10),
            dimension: Some(3),
            ..d
        })
        .contains("dimension"));
        // Coordinates near the top of the floating-point range: an error, not an infinite
        // sigma_p reported as reached.
        let huge = PointSet::new(2, vec![1e300, 0.0, -1e300, 0.0, 0.0, 1e300], None).unwrap();
        let r = sample_manifold(
            &huge,
            &ManifoldSampleParams {
                count: Some(1),
                ..d
            },
        );
        assert!(r.as_ref().map_or(true, |s| s.sigma_p.is_finite()), "{r:?}");
    }
}
