//! The paper's samplers on the periodic unit square (Sec. 7.1, Fig. 11): gradient ascent on the
//! spectral measure (Sec. 6.2, eq. 11) and the randomized linear scan (Sec. 6.1, Algorithm 1),
//! with toroidal distances in the kernel and in the neighbour search.
//!
//! A point (x, y) enters the crate's kernel as the position (x, y, 0) with the constant normal
//! (0, 0, 1) and sigma_n = infinity, so k(p, q) = exp(-|p - q|² / sigma²). For a point p the
//! neighbours are the periodic images nearest to p of the points within the support radius
//! 2.5 sigma; with 2.5 sigma <= 1/4 (checked) the distances among those images are the toroidal
//! ones, so the local kernel matrix is the one of the torus.
//!
//! What is the library's and what is not: the kernel, the measure and its gradient
//! (`measure::measure_and_gradient`, `measure::spectral_measure`), the sigma search
//! (`sampling::target_count`) and the linear scan itself ([`torus_linear_scan`] drives
//! `sampling::linear_scan::LinearScanner` with the kept points' periodic images). The gradient
//! ascent is this module's own ([`torus_gradient_ascent`]): the library's
//! (`sampling::gradient_ascent`) finds each sample's neighbours once per call in a kd-tree of
//! absolute positions and moves samples through a surface projection, while on the torus a
//! moving point wraps across the edges (its neighbours' nearest images change with it) and the
//! random start needs its neighbourhoods found afresh at every move; giving the library's
//! ascent a neighbour query per move would change the product's sampler for the sake of this
//! experiment.
//!
//! Two paths, both named in Sec. 7.1:
//! - [`spectral_from_random`] (the paper's): n uniform random points, then 10 sweeps of gradient
//!   ascent with sigma = 2.5 r, r = rho / sqrt(2 sqrt(3) n), rho = 0.75 ([`paper_sigma`]).
//! - [`spectral_from_dense`]: a dense uniform random set subsampled by the linear scan at the
//!   sigma that gives about n points (searched as `sampling::target_count` does), then resampled
//!   by gradient ascent.

use glam::{DVec2, DVec3};
use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::torus::{delta, periodic_images, wrap, TorusGrid};
use spectral_remesh::internal::{
    find_sigma_p, measure_and_gradient, spectral_measure, Kernel, KernelPoint, LinearScanParams,
    LinearScanner, MeasureWorkspace, TargetCountParams, DEFAULT_EPSILON, SUPPORT_RADIUS,
};
use spectral_remesh::{Error, Result};

/// The largest support radius (2.5 sigma, in units of the square's side) the torus samplers
/// accept: up to 1/4, two neighbours of a point are at most 1/2 apart, so the distance between
/// their images nearest to the point is their toroidal distance.
pub const MAX_SUPPORT: f64 = 0.25;

/// The normalized Poisson-disk radius the paper's kernel width is built from (Sec. 7.1: "rho =
/// 0.75 the optimal Poisson disk radius", after Lagae and Dutré 2008).
pub const PAPER_RHO: f64 = 0.75;

/// The kernel width of Sec. 7.1 for `n` points on the unit square: sigma = 2.5 r with
/// r = rho / sqrt(2 sqrt(3) n), the Poisson-disk radius (half the minimum distance) at
/// normalized radius `rho` (Lagae and Dutré 2008: r_max = 1 / sqrt(2 sqrt(3) n) is the radius of
/// n disks in the densest, hexagonal packing). In units of the square's side; for n = 4096,
/// rho = 0.75: 0.01574.
pub fn paper_sigma(n: usize, rho: f64) -> f64 {
    2.5 * rho / (2.0 * 3f64.sqrt() * n as f64).sqrt()
}

/// Parameters of the gradient ascent on the torus (Sec. 6.2 and 6.3; the defaults are the
/// crate's surface sampler's, `sampling::gradient_ascent::GradientAscentParams`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorusAscentParams {
    /// Sweeps over all points (default 10, Sec. 6.3 and 7.1).
    pub iterations: usize,
    /// Step of eq. 11, p ← p + step ∇s(p), in kernel units (default 0.55; eq. 11 prints 0.5).
    /// Path A at n = 4096, 10 sets, seed 1, mean rho after 10 sweeps: 0.60 at 0.55 (clusters of
    /// the random start not yet apart in 5 of the 10 sets), 0.69 at 0.7, 0.62 at 0.85, 0.28 at
    /// 0.4; at 0.55 it reaches 0.79 after 15 sweeps and 0.83 after 30.
    pub step: f64,
    /// Largest move of one point in one sweep, in units of sigma (default 0.25).
    pub max_move: f64,
    /// Neighbourhood radius in kernel units (default 2.5, Sec. 6.3).
    pub support_radius: f64,
    /// Seed of the visit order.
    pub seed: u64,
    /// Not in the paper (default `None`): with `Some(s_ref)`, a point whose measure s is below
    /// s_ref takes a step s_ref / s times longer (at most 1000 times), still bounded by
    /// `max_move`. The gradient of s vanishes with s inside tight clusters of a uniform random
    /// start (about 5 points within 0.5 sigma: s and |∇s| below 1e-3), which then take most of
    /// the 10 sweeps to come apart; the longer step is the step along ∇ log s there.
    /// Path A at n = 4096, 10 sets, step 0.55, max_move 0.5, s_ref 0.3: mean rho 0.790, 0.790,
    /// 0.775 for seeds 1, 2, 3 (s_ref 0.5 gives 0.59–0.71: boosting points near the optimum
    /// s ≈ 0.55 makes them oscillate).
    pub small_s_boost: Option<f64>,
    /// Halvings of a step that would lower s (neighbours held where they are) before it is
    /// taken anyway (default 0: every step is taken, as in eq. 11). Path A, seed 1: step 1.0,
    /// max_move 0.5 and 2 or 3 halvings give mean rho 0.773; no gain at step 0.55.
    pub backtracking: usize,
}

impl Default for TorusAscentParams {
    fn default() -> Self {
        TorusAscentParams {
            iterations: 10,
            step: 0.55,
            max_move: 0.25,
            support_radius: SUPPORT_RADIUS,
            seed: 1,
            small_s_boost: None,
            backtracking: 0,
        }
    }
}

/// What the gradient ascent did, per sweep.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
pub struct TorusAscentResult {
    /// Mean distance a point moved (units of the square's side).
    pub mean_move: Vec<f64>,
    /// Mean s over the points, each taken just before its move.
    pub mean_s: Vec<f64>,
    /// Minimum of those s.
    pub min_s: Vec<f64>,
}

fn check_width(sigma: f64, support_radius: f64) -> Result<()> {
    if !(sigma.is_finite() && sigma > 0.0) {
        return Err(Error::InvalidParameter {
            name: "sigma",
            message: format!("must be a positive number, got {sigma}"),
        });
    }
    if !(support_radius.is_finite() && support_radius > 0.0) {
        return Err(Error::InvalidParameter {
            name: "support_radius",
            message: format!("must be a positive number, got {support_radius}"),
        });
    }
    let r = support_radius * sigma;
    if r > MAX_SUPPORT {
        return Err(Error::InvalidParameter {
            name: "sigma",
            message: format!(
                "the support radius {support_radius} sigma = {r:.4} exceeds 1/4 of the square \
                 (too few points: the neighbourhoods would wrap onto themselves)"
            ),
        });
    }
    Ok(())
}

/// The neighbours of `p` among `points` (grid `grid`), except `skip`, within the support radius
/// `r`: their offsets to `p` (nearest periodic image), embedded in kernel space with `p` at the
/// origin, nearest first.
#[allow(clippy::too_many_arguments)]
fn gather(
    kernel: &Kernel,
    grid: &TorusGrid,
    points: &[DVec2],
    p: DVec2,
    skip: u32,
    r: f64,
    near: &mut Vec<(f64, KernelPoint)>,
    out: &mut Vec<KernelPoint>,
) {
    near.clear();
    grid.for_each_near(p, |j| {
        if j == skip {
            return;
        }
        let d = delta(p, points[j as usize]);
        let d2 = d.length_squared();
        if d2 <= r * r {
            near.push((d2, kernel.embed(DVec3::new(d.x, d.y, 0.0), DVec3::Z)));
        }
    });
    near.sort_by(|a, b| a.0.total_cmp(&b.0));
    out.clear();
    out.extend(near.iter().map(|n| n.1));
}

/// Gradient ascent on the spectral measure (eq. 11) on the torus: `params.iterations` sweeps,
/// each visiting the points one at a time in a seeded random order (Sec. 6.2), each move seeing
/// the moves before it. A point p moves by sigma · step · ∇s (∇s in kernel units, see
/// `measure::measure_and_gradient`), at most `max_move` sigma, and is wrapped back into [0, 1)².
///
/// Unlike the surface sampler (Sec. 6.3), the neighbourhoods are found afresh for every move
/// (a uniform grid on the torus, updated as points move): the paper's start here is a uniform
/// random set, far from the near-optimal positions that make fixed neighbourhoods safe.
///
/// `points`: positions in [0, 1)² (wrapped on entry), units of the square's side; `sigma` the
/// kernel width in the same units.
///
/// # Errors
/// [`Error::InvalidParameter`] when sigma or the support radius is not positive, when
/// 2.5 sigma > 1/4 (see [`MAX_SUPPORT`]), or when step or max_move is not a finite number >= 0.
pub fn torus_gradient_ascent(
    points: &mut [DVec2],
    sigma: f64,
    params: &TorusAscentParams,
) -> Result<TorusAscentResult> {
    check_width(sigma, params.support_radius)?;
    for (name, v) in [("step", params.step), ("max_move", params.max_move)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(Error::InvalidParameter {
                name,
                message: format!("must be a finite number >= 0, got {v}"),
            });
        }
    }
    let kernel = Kernel::new(sigma, f64::INFINITY)?;
    let r = params.support_radius * sigma;
    for p in points.iter_mut() {
        *p = wrap(*p);
    }
    let mut grid = TorusGrid::with_points(points, r);
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    let (mut ws, mut near, mut nb) = (MeasureWorkspace::new(), Vec::new(), Vec::new());
    let origin = kernel.embed(DVec3::ZERO, DVec3::Z);
    let max_move = params.max_move * sigma;
    let mut result = TorusAscentResult::default();
    for _ in 0..params.iterations {
        order.shuffle(&mut rng);
        let (mut total_move, mut total_s, mut min_s) = (0.0, 0.0, f64::INFINITY);
        for &i in &order {
            let p = points[i as usize];
            gather(&kernel, &grid, points, p, i, r, &mut near, &mut nb);
            let (s, g) = measure_and_gradient(&kernel, &origin, [0.0; 3], &nb, &mut ws);
            let boost = params
                .small_s_boost
                .map_or(1.0, |s_ref| (s_ref / s.max(1e-12)).clamp(1.0, 1000.0));
            let mut step = DVec2::new(g[0], g[1]) * (params.step * sigma * boost);
            let len = step.length();
            if len > max_move {
                step *= max_move / len;
            }
            for _ in 0..params.backtracking {
                let y = kernel.embed(DVec3::new(step.x, step.y, 0.0), DVec3::Z);
                if spectral_measure(&kernel, &y, nb.iter().copied(), -1.0, &mut ws).s >= s {
                    break;
                }
                step *= 0.5;
            }
            let q = wrap(p + step);
            points[i as usize] = q;
            grid.relocate(i, q);
            total_move += step.length();
            total_s += s;
            min_s = min_s.min(s);
        }
        let m = order.len().max(1) as f64;
        result.mean_move.push(total_move / m);
        result.mean_s.push(total_s / m);
        result
            .min_s
            .push(if order.is_empty() { 1.0 } else { min_s });
    }
    Ok(result)
}

/// Parameters of the linear scan on the torus.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorusScanParams {
    /// Acceptance threshold: a candidate joins the output when s > epsilon (default 0.5,
    /// Sec. 6.3).
    pub epsilon: f64,
    /// Neighbourhood radius in kernel units (default 2.5, Sec. 6.3).
    pub support_radius: f64,
}

impl Default for TorusScanParams {
    fn default() -> Self {
        TorusScanParams {
            epsilon: DEFAULT_EPSILON,
            support_radius: SUPPORT_RADIUS,
        }
    }
}

/// Algorithm 1 on the torus: visits `candidates` in the order given (pass them in random order;
/// uniform random points already are) and keeps a candidate when its measure s (eq. 9) against
/// the kept points within the support radius exceeds epsilon, or when it has none. Returns the
/// kept points in the order kept.
///
/// The scan is the library's ([`LinearScanner::offer`]: quick rejections by the nearest and the
/// few nearest kept points, then eq. 10 over the neighbours nearest first, stopping once
/// s <= epsilon) on the points (x, y, 0): every kept point enters it with its periodic images
/// that lie within the support radius of the square ([`periodic_images`]). With 2.5 sigma <= 1/4
/// (checked) a candidate in the square sees each kept point at most once, as the image nearest
/// to it: its neighbourhood is the toroidal one.
///
/// Units: positions in [0, 1)² (wrapped), sigma in units of the square's side.
///
/// # Errors
/// As [`torus_gradient_ascent`] for sigma and the support radius; epsilon must be in [0, 1).
pub fn torus_linear_scan(
    candidates: &[DVec2],
    sigma: f64,
    params: &TorusScanParams,
) -> Result<Vec<DVec2>> {
    check_width(sigma, params.support_radius)?;
    if !(0.0..1.0).contains(&params.epsilon) {
        return Err(Error::InvalidParameter {
            name: "epsilon",
            message: format!("must be in [0, 1), got {}", params.epsilon),
        });
    }
    let kernel = Kernel::new(sigma, f64::INFINITY)?;
    let r = params.support_radius * sigma;
    let mut scanner = LinearScanner::new(
        &kernel,
        &LinearScanParams {
            epsilon: params.epsilon,
            support_radius: params.support_radius,
        },
    );
    let plane = |p: DVec2| DVec3::new(p.x, p.y, 0.0);
    let mut kept: Vec<DVec2> = Vec::new();
    for &c in candidates {
        let p = wrap(c);
        if scanner.offer(plane(p), DVec3::Z) {
            kept.push(p);
            for q in periodic_images(p, r) {
                scanner.insert(plane(q), DVec3::Z);
            }
        }
    }
    Ok(kept)
}

/// `count` independent uniform random points on [0, 1)².
pub fn uniform_random(count: usize, rng: &mut ChaCha8Rng) -> Vec<DVec2> {
    (0..count)
        .map(|_| DVec2::new(rng.random::<f64>(), rng.random::<f64>()))
        .collect()
}

/// A point set made by one of the two spectral paths.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectralPlaneResult {
    /// The points, in [0, 1)².
    pub points: Vec<DVec2>,
    /// The kernel width of the gradient ascent (units of the square's side).
    pub sigma: f64,
    /// The gradient ascent's per-sweep record.
    pub ascent: TorusAscentResult,
    /// Path B only: the linear scan's kernel width, its count, whether the count is within the
    /// search's tolerance of n, and every (sigma, count) the search tried.
    pub scan: Option<ScanRecord>,
}

/// The linear scan of path B.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ScanRecord {
    /// The kernel width of the scan (units of the square's side).
    pub sigma: f64,
    /// Points the scan kept.
    pub count: usize,
    /// Whether `count` is within the tolerance (0.5%) of the target.
    pub reached: bool,
    /// Every (sigma, count) evaluated by the search.
    pub history: Vec<(f64, usize)>,
    /// Candidates scanned.
    pub candidates: usize,
}

/// Path A (Sec. 7.1): `n` uniform random points, then gradient ascent with sigma =
/// [`paper_sigma`]`(n, rho)` (rho = [`PAPER_RHO`] in the paper).
///
/// # Errors
/// [`Error::InvalidParameter`] for n < 2, rho not positive, or n too small for the support radius
/// to fit ([`MAX_SUPPORT`]: n >= 102 at rho = 0.75).
pub fn spectral_from_random(
    n: usize,
    rho: f64,
    ascent: &TorusAscentParams,
    rng: &mut ChaCha8Rng,
) -> Result<SpectralPlaneResult> {
    check_count(n)?;
    if !(rho.is_finite() && rho > 0.0) {
        return Err(Error::InvalidParameter {
            name: "rho",
            message: format!("must be a positive number, got {rho}"),
        });
    }
    let sigma = paper_sigma(n, rho);
    check_width(sigma, ascent.support_radius)?;
    let mut points = uniform_random(n, rng);
    let record = torus_gradient_ascent(&mut points, sigma, ascent)?;
    Ok(SpectralPlaneResult {
        points,
        sigma,
        ascent: record,
        scan: None,
    })
}

fn check_count(n: usize) -> Result<()> {
    if n < 2 {
        return Err(Error::InvalidParameter {
            name: "--n",
            message: format!("needs at least 2 points, got {n}"),
        });
    }
    Ok(())
}

/// Path B (Sec. 7.1, last sentence): `oversampling · n` uniform random points, subsampled by
/// [`torus_linear_scan`] at the sigma whose count is within 0.5% of n (searched with
/// `sampling::target_count::find_sigma_p`, starting at [`paper_sigma`]`(n, 0.75)`), then resampled
/// by gradient ascent at the scan's sigma (the same kernel for both algorithms, as in the paper).
///
/// # Errors
/// As [`spectral_from_random`]; `oversampling` must be at least 2. When the search ends outside
/// the tolerance the closest count found is used (see [`ScanRecord::reached`]).
pub fn spectral_from_dense(
    n: usize,
    oversampling: usize,
    scan: &TorusScanParams,
    ascent: &TorusAscentParams,
    rng: &mut ChaCha8Rng,
) -> Result<SpectralPlaneResult> {
    check_count(n)?;
    if oversampling < 2 {
        return Err(Error::InvalidParameter {
            name: "--oversampling",
            message: format!("must be at least 2, got {oversampling}"),
        });
    }
    let candidates = uniform_random(n.saturating_mul(oversampling), rng);
    let start = paper_sigma(n, PAPER_RHO);
    check_width(start, scan.support_radius)?;
    let mut failure: Option<Error> = None;
    let search = find_sigma_p(&TargetCountParams::new(n), start, |sigma| {
        // A width too large for the torus counts as "too few points" (the search moves down).
        match torus_linear_scan(&candidates, sigma, scan) {
            Ok(kept) => (kept.len(), kept),
            Err(e) => {
                failure.get_or_insert(e);
                (0, Vec::new())
            }
        }
    });
    if search.count == 0 {
        return Err(failure.unwrap_or(Error::Internal {
            stage: "linear scan",
            message: "kept no point".into(),
        }));
    }
    let mut points = search.value;
    let record = torus_gradient_ascent(&mut points, search.sigma_p, ascent)?;
    Ok(SpectralPlaneResult {
        points,
        sigma: search.sigma_p,
        ascent: record,
        scan: Some(ScanRecord {
            sigma: search.sigma_p,
            count: search.count,
            reached: search.reached,
            history: search.history,
            candidates: candidates.len(),
        }),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plane::analysis::normalized_poisson_disk_radius;

    #[test]
    fn paper_sigma_matches_sec_7_1() {
        // n = 4096, rho = 0.75: r = 0.75 / sqrt(2 sqrt(3) 4096) = 0.0062963, sigma = 2.5 r.
        let s = paper_sigma(4096, 0.75);
        assert!((s - 0.015_740_77).abs() < 1e-7, "{s}");
    }

    #[test]
    fn too_few_points_for_the_support_radius_is_an_error() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        assert!(matches!(
            spectral_from_random(50, PAPER_RHO, &TorusAscentParams::default(), &mut rng),
            Err(Error::InvalidParameter { .. })
        ));
        assert!(
            spectral_from_random(1, PAPER_RHO, &TorusAscentParams::default(), &mut rng).is_err()
        );
        let mut pts = uniform_random(10, &mut rng);
        let bad = TorusAscentParams {
            step: f64::NAN,
            ..Default::default()
        };
        assert!(torus_gradient_ascent(&mut pts, 0.01, &bad).is_err());
        assert!(torus_gradient_ascent(&mut pts, -1.0, &TorusAscentParams::default()).is_err());
        assert!(torus_linear_scan(&pts, 0.2, &TorusScanParams::default()).is_err());
    }

    /// The torus has no seam: shifting every point by the same vector (wrapped) shifts the
    /// result of the gradient ascent by that vector.
    #[test]
    fn gradient_ascent_commutes_with_a_periodic_shift() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let n = 400;
        let sigma = paper_sigma(n, PAPER_RHO);
        let start = uniform_random(n, &mut rng);
        let shift = DVec2::new(0.437, 0.791);
        let params = TorusAscentParams {
            iterations: 2,
            ..Default::default()
        };
        let mut a = start.clone();
        torus_gradient_ascent(&mut a, sigma, &params).unwrap();
        let mut b: Vec<DVec2> = start.iter().map(|&p| wrap(p + shift)).collect();
        torus_gradient_ascent(&mut b, sigma, &params).unwrap();
        let mut worst: f64 = 0.0;
        for (p, q) in a.iter().zip(&b) {
            worst = worst.max(delta(wrap(*p + shift), *q).length());
        }
        assert!(worst < 1e-9, "largest difference {worst}");
        assert!(a
            .iter()
            .zip(&start)
            .any(|(p, q)| delta(*p, *q).length() > 1e-4));
    }

    #[test]
    fn linear_scan_keeps_a_poisson_disk_set_and_ascent_raises_its_measure() {
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        let n = 1000;
        let sigma = paper_sigma(n, PAPER_RHO);
        let kept = torus_linear_scan(
            &uniform_random(20 * n, &mut rng),
            sigma,
            &TorusScanParams::default(),
        )
        .unwrap();
        // A kept pair has s <= 1 - k² when the second arrives, so k² < 1/2:
        // |p - q| > sigma sqrt(ln 2 / 2).
        let d_min = crate::plane::analysis::min_toroidal_distance(&kept);
        assert!(
            d_min > sigma * (std::f64::consts::LN_2 / 2.0).sqrt(),
            "{d_min}"
        );
        assert!(kept.len() > 600 && kept.len() < 1400, "{} kept", kept.len());
        let rho0 = normalized_poisson_disk_radius(&kept);
        let mut pts = kept.clone();
        let r = torus_gradient_ascent(&mut pts, sigma, &TorusAscentParams::default()).unwrap();
        assert!(r.mean_s.last() > r.mean_s.first(), "{:?}", r.mean_s);
        assert!(normalized_poisson_disk_radius(&pts) > rho0);
        assert!(r.mean_move.last() < r.mean_move.first());
    }

    /// Algorithm 1 on the torus written out directly: every kept point, toroidal differences,
    /// the measure over all neighbours within the support radius, nearest first.
    fn brute_force_scan(candidates: &[DVec2], sigma: f64) -> Vec<DVec2> {
        let kernel = Kernel::new(sigma, f64::INFINITY).unwrap();
        let r = SUPPORT_RADIUS * sigma;
        let origin = kernel.embed(DVec3::ZERO, DVec3::Z);
        let mut ws = MeasureWorkspace::new();
        let mut kept: Vec<DVec2> = Vec::new();
        for &c in candidates {
            let p = wrap(c);
            let mut near: Vec<(f64, KernelPoint)> = kept
                .iter()
                .map(|&q| delta(p, q))
                .filter(|d| d.length_squared() <= r * r)
                .map(|d| {
                    let x = kernel.embed(DVec3::new(d.x, d.y, 0.0), DVec3::Z);
                    (d.length_squared(), x)
                })
                .collect();
            near.sort_by(|a, b| a.0.total_cmp(&b.0));
            let s = spectral_measure(&kernel, &origin, near.iter().map(|n| n.1), -1.0, &mut ws).s;
            if near.is_empty() || s > DEFAULT_EPSILON {
                kept.push(p);
            }
        }
        kept
    }

    #[test]
    fn linear_scan_makes_the_decisions_of_the_brute_force_scan() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let n = 300;
        let sigma = paper_sigma(n, PAPER_RHO);
        let candidates = uniform_random(20 * n, &mut rng);
        let fast = torus_linear_scan(&candidates, sigma, &TorusScanParams::default()).unwrap();
        let slow = brute_force_scan(&candidates, sigma);
        assert_eq!(fast, slow);
        // Kept points near the edges have neighbours across them.
        assert!(fast.iter().any(|p| p.x < 0.01) && fast.iter().any(|p| p.x > 0.99));
    }
}
