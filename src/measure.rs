//! The spectral measure s(x) = 1 - k^T K^-1 k / k(x, x) (Sec. 4.3, eq. 9), computed from the
//! neighbours of x only, and its gradient (Sec. 6.2).
//!
//! s(x) is the squared norm of the part of the feature vector φ(x) orthogonal to the span of the
//! φ(x_i), relative to |φ(x)|^2 (Appendix B): 1 for a point far from every other, 0 for a point
//! that duplicates one. Adding neighbours can only lower it, so the linear scan stops adding them
//! as soon as s <= epsilon (Sec. 6.1).

use crate::kernel::{Kernel, KernelPoint, UnitKernel};

/// The acceptance threshold of the linear scan (Sec. 6.3: epsilon = 0.5 for all the paper's
/// results).
pub const DEFAULT_EPSILON: f64 = 0.5;

pub use crate::geometry::tolerance::SINGULAR_TOLERANCE;

/// The outcome of one evaluation of the measure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measure {
    /// s(x) over the neighbours taken (in [0, 1]); an upper bound of s over all of them when
    /// `stopped_early` is set.
    pub s: f64,
    /// Neighbours taken into K.
    pub used: usize,
    /// Neighbours skipped as (numerically) in the span of the others.
    pub skipped: usize,
    /// The evaluation stopped once s fell to the stop value, before the last neighbour.
    pub stopped_early: bool,
}

/// The inverse of the kernel matrix of a growing set of points, updated one point at a time with
/// the block inversion formula of eq. 10 (Sec. 6.1; Moghaddam et al. 2008):
///
/// K_{n+1}^-1 = [[K_n^-1 + g a a^T, -g a], [-g a^T, g]],
/// a = K_n^-1 k_n(x_{n+1}), g = (k(x_{n+1}, x_{n+1}) - k_n(x_{n+1})^T a)^-1.
///
/// Costs O(n^2) per point. Reuse one value across evaluations to avoid allocation. `P` is the
/// kernel's point type ([`UnitKernel::Point`]): [`KernelPoint`] for surfaces in R^3, `[f64; K]`
/// for point sets in R^d.
#[derive(Debug, Clone)]
pub struct IncrementalInverse<P = KernelPoint> {
    points: Vec<P>,
    /// K^-1, row-major, n × n.
    inv: Vec<f64>,
    scratch: Vec<f64>,
    b: Vec<f64>,
    a: Vec<f64>,
}

/// What [`IncrementalInverse::push`] did with a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Push {
    /// The point was added; `g` as in eq. 10.
    Added {
        /// g = 1 / (k(y, y) - k^T K^-1 k).
        g: f64,
    },
    /// The point was skipped: g^-1 below [`SINGULAR_TOLERANCE`].
    Skipped,
}

impl<P> Default for IncrementalInverse<P> {
    fn default() -> Self {
        IncrementalInverse {
            points: Vec::new(),
            inv: Vec::new(),
            scratch: Vec::new(),
            b: Vec::new(),
            a: Vec::new(),
        }
    }
}

impl<P: Copy> IncrementalInverse<P> {
    /// An empty set (K is 0 × 0).
    pub fn new() -> Self {
        Self::default()
    }

    /// Empties the set, keeping the allocations.
    pub fn clear(&mut self) {
        self.points.clear();
        self.inv.clear();
    }

    /// Number of points in K.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether K is empty.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The points of K, in the order they were added.
    pub fn points(&self) -> &[P] {
        &self.points
    }

    /// K^-1 as a row-major `n × n` slice.
    pub fn inverse(&self) -> &[f64] {
        &self.inv
    }

    /// The vector a = K^-1 k(y) of the last successful or skipped [`IncrementalInverse::push`].
    pub fn last_a(&self) -> &[f64] {
        &self.a
    }

    /// Adds y to the set with eq. 10, or skips it when it is numerically in the span.
    pub fn push<K: UnitKernel<Point = P>>(&mut self, kernel: &K, y: P) -> Push {
        let n = self.points.len();
        self.b.clear();
        self.b
            .extend(self.points.iter().map(|p| kernel.eval(p, &y)));
        self.a.clear();
        self.a.resize(n, 0.0);
        for i in 0..n {
            let row = &self.inv[i * n..(i + 1) * n];
            self.a[i] = row.iter().zip(&self.b).map(|(m, b)| m * b).sum();
        }
        let g_inv = 1.0 - self.b.iter().zip(&self.a).map(|(b, a)| b * a).sum::<f64>();
        if !(g_inv > SINGULAR_TOLERANCE) {
            return Push::Skipped;
        }
        let g = 1.0 / g_inv;
        let m = n + 1;
        self.scratch.clear();
        self.scratch.resize(m * m, 0.0);
        for i in 0..n {
            let gai = g * self.a[i];
            for j in 0..n {
                self.scratch[i * m + j] = self.inv[i * n + j] + gai * self.a[j];
            }
            self.scratch[i * m + n] = -gai;
            self.scratch[n * m + i] = -gai;
        }
        self.scratch[n * m + n] = g;
        std::mem::swap(&mut self.inv, &mut self.scratch);
        self.points.push(y);
        Push::Added { g }
    }
}

/// Reusable buffers for [`spectral_measure`] and [`measure_and_gradient`]; one per thread. `P` is
/// the kernel's point type, as for [`IncrementalInverse`].
#[derive(Debug, Clone)]
pub struct MeasureWorkspace<P = KernelPoint> {
    inverse: IncrementalInverse<P>,
    k: Vec<f64>,
    chol: Vec<f64>,
    z: Vec<f64>,
    kept: Vec<usize>,
}

impl<P> Default for MeasureWorkspace<P> {
    fn default() -> Self {
        MeasureWorkspace {
            inverse: IncrementalInverse::default(),
            k: Vec::new(),
            chol: Vec::new(),
            z: Vec::new(),
            kept: Vec::new(),
        }
    }
}

impl<P> MeasureWorkspace<P> {
    /// Empty buffers.
    pub fn new() -> Self {
        Self::default()
    }

    /// After [`solve_alpha`]: the neighbours kept (indices into its `neighbors`), with their
    /// α_i = (K^-1 k)_i and k_i = k(x, y_i), row by row.
    pub(crate) fn alpha_rows(&self) -> impl Iterator<Item = (usize, f64, f64)> + '_ {
        self.kept
            .iter()
            .zip(&self.z)
            .zip(&self.k)
            .map(|((&j, &a), &k)| (j, a, k))
    }
}

/// s(x) (eq. 9) from the neighbours `neighbors` of x, taken in the order given (nearest first, as
/// Sec. 6.1 prescribes), each added to K with the block inversion of eq. 10; stops as soon as
/// s <= `stop_at` (pass a negative value to take every neighbour). Neighbours whose g^-1 falls
/// below [`SINGULAR_TOLERANCE`] are skipped.
///
/// With no neighbour s = 1. k(x, x) = 1 for this kernel, so s = 1 - k^T K^-1 k. The update of
/// q = k^T K^-1 k per added neighbour y is q += g (k(x, y) - a^T k)^2 (the Schur complement of
/// eq. 10), O(n^2) per neighbour.
///
/// Generic over the kernel ([`UnitKernel`]): the surface kernel [`Kernel`] on [`KernelPoint`]s,
/// or [`GaussianKernel`](crate::GaussianKernel) on points of R^K.
pub fn spectral_measure<K: UnitKernel>(
    kernel: &K,
    x: &K::Point,
    neighbors: impl IntoIterator<Item = K::Point>,
    stop_at: f64,
    ws: &mut MeasureWorkspace<K::Point>,
) -> Measure {
    ws.inverse.clear();
    ws.k.clear();
    let mut q = 0.0;
    let mut skipped = 0;
    let mut iter = neighbors.into_iter().peekable();
    while let Some(y) = iter.next() {
        match ws.inverse.push(kernel, y) {
            Push::Skipped => skipped += 1,
            Push::Added { g } => {
                let c = kernel.eval(x, &y);
                let t = c - ws
                    .inverse
                    .last_a()
                    .iter()
                    .zip(&ws.k)
                    .map(|(a, k)| a * k)
                    .sum::<f64>();
                q += g * t * t;
                ws.k.push(c);
                let s = (1.0 - q).clamp(0.0, 1.0);
                if s <= stop_at && iter.peek().is_some() {
                    return Measure {
                        s,
                        used: ws.inverse.len(),
                        skipped,
                        stopped_early: true,
                    };
                }
            }
        }
    }
    Measure {
        s: (1.0 - q).clamp(0.0, 1.0),
        used: ws.inverse.len(),
        skipped,
        stopped_early: false,
    }
}

/// s(x) and its gradient with respect to the position part of x, in kernel units (multiply by
/// 1/sigma_p for the gradient in bbox-100 units), from all of `neighbors`.
///
/// With α = K^-1 k, s = 1 - k·α and, since ∂k_i/∂x = -2 (x - x_i) k_i,
///
/// ∇s = 4 Σ_i α_i k_i (x - x_i) = 2 Σ_ij K^-1_ij k_i k_j (2x - x_i - x_j).
///
/// Sec. 6.2 prints this with the factor -2/σ^2, in position units: the sign there is reversed
/// (the expression as printed is -∇s; the step of eq. 11 must go along +∇s to raise s), which a
/// finite-difference test of this function checks. α is found by a Cholesky factorization built
/// row by row in the same nearest-first order as eq. 10: the squared pivot of row n+1 is exactly
/// g_n^-1, so skipping rows whose squared pivot is below [`SINGULAR_TOLERANCE`] skips the same
/// neighbours as eq. 10 does.
pub fn measure_and_gradient(
    kernel: &Kernel,
    x: &KernelPoint,
    neighbors: &[KernelPoint],
    ws: &mut MeasureWorkspace,
) -> (f64, [f64; 3]) {
    measure_and_gradient_graded(kernel, x, [0.0; 3], neighbors, ws)
}

/// [`measure_and_gradient`] for a graded kernel (see [`Kernel`](crate::Kernel)): x's width w follows a
/// width field whose gradient at x, in kernel units (d w / d(p / sigma_p)), is
/// `width_gradient`; the gradient returned is that of s(x) with x's width moving with it. The
/// neighbours keep their widths.
///
/// With log k_i = 3/2 (log w + log w_i - log s_i²) - |p - p_i|² / s_i² - |Δn|²,
/// s_i² = (w² + w_i²) / 2 (positions in kernel units):
///
/// ∇k_i = k_i [-2 (p - p_i) / s_i² + (3/2 (1/w - w/s_i²) + |p - p_i|² w / s_i⁴) ∇w],
/// ∇s = -2 Σ_i α_i ∇k_i;
///
/// with every width 1 and ∇w = 0 this is the formula of [`measure_and_gradient`] (and the same
/// arithmetic, so the same bits).
pub fn measure_and_gradient_graded(
    kernel: &Kernel,
    x: &KernelPoint,
    width_gradient: [f64; 3],
    neighbors: &[KernelPoint],
    ws: &mut MeasureWorkspace,
) -> (f64, [f64; 3]) {
    let q = solve_alpha(kernel, x, neighbors, ws);
    let mut grad = [0.0; 3];
    let w = x.width;
    for (r, &j) in ws.kept.iter().enumerate() {
        let y = &neighbors[j];
        let alpha_k = ws.z[r] * ws.k[r];
        if w == 1.0 && y.width == 1.0 && width_gradient == [0.0; 3] {
            let c = 4.0 * alpha_k;
            for (g, (xc, yc)) in grad.iter_mut().zip(x.coords.iter().zip(&y.coords)) {
                *g += c * (xc - yc);
            }
            continue;
        }
        let s2 = 0.5 * (w * w + y.width * y.width);
        let mut dp2 = 0.0;
        for k in 0..3 {
            let t = x.coords[k] - y.coords[k];
            dp2 += t * t;
        }
        let c_p = 4.0 * alpha_k / s2;
        let c_w = -2.0 * alpha_k * (1.5 * (1.0 / w - w / s2) + dp2 * w / (s2 * s2));
        for k in 0..3 {
            grad[k] += c_p * (x.coords[k] - y.coords[k]) + c_w * width_gradient[k];
        }
    }
    ((1.0 - q).clamp(0.0, 1.0), grad)
}

/// The coefficients α = K^-1 k of the projection of φ(x) onto the span of the φ(y) of
/// `neighbors` (Sec. 5 and Appendix B: φ(x) ≈ Σ α_i φ(y_i), so that k(z, x) ≈ Σ α_i k(z, y_i)
/// for every z), written to `alpha` as `(neighbour index, α_i)` pairs; returns s(x) (eq. 9) over
/// the same neighbours.
///
/// Sec. 5 uses them to drop a point x_j from a kernel sum Σ w_i k(·, x_i): the weight w_j moves
/// to the others as w_i + w_j α_i (the error left is w_j times the orthogonal part, whose squared
/// norm relative to |φ(x_j)|² is s(x_j)). `representation_weights`
/// (in the `spectral-experiments` crate) does that for every point a subsampler dropped.
///
/// The neighbours are taken in the order given (nearest first) with the same Cholesky
/// factorization as [`measure_and_gradient`]; those numerically in the span of the ones before
/// them (squared pivot below [`SINGULAR_TOLERANCE`], exactly the neighbours eq. 10 skips) get no
/// pair. With no neighbours `alpha` is empty and s = 1; a neighbour equal to x gets α = 1 and
/// the others 0 (up to rounding).
pub fn projection_coefficients<K: UnitKernel>(
    kernel: &K,
    x: &K::Point,
    neighbors: &[K::Point],
    ws: &mut MeasureWorkspace<K::Point>,
    alpha: &mut Vec<(usize, f64)>,
) -> f64 {
    let q = solve_alpha(kernel, x, neighbors, ws);
    alpha.clear();
    alpha.extend(ws.kept.iter().copied().zip(ws.z.iter().copied()));
    (1.0 - q).clamp(0.0, 1.0)
}

/// α = K^-1 k over `neighbors` (in the order given, near-singular ones skipped) by a Cholesky
/// factorization built row by row: afterwards `ws.kept[r]` is the neighbour of row r, `ws.z[r]`
/// its α and `ws.k[r]` its k(x, y). Returns q = k^T K^-1 k.
pub(crate) fn solve_alpha<K: UnitKernel>(
    kernel: &K,
    x: &K::Point,
    neighbors: &[K::Point],
    ws: &mut MeasureWorkspace<K::Point>,
) -> f64 {
    let n = neighbors.len();
    // Lower-triangular L with stride n over the kept rows; kept[r] = neighbour index of row r.
    ws.chol.clear();
    ws.chol.resize(n * n, 0.0);
    ws.kept.clear();
    ws.z.clear();
    ws.k.clear();
    let mut q = 0.0;
    for (j, y) in neighbors.iter().enumerate() {
        let r = ws.kept.len();
        // Row r: solve L[0..r, 0..r] l = b with b_i = k(x_kept[i], y).
        let mut dot = 0.0;
        for i in 0..r {
            let b = kernel.eval(&neighbors[ws.kept[i]], y);
            let row = &ws.chol[i * n..i * n + i];
            let s: f64 = row
                .iter()
                .zip(&ws.chol[r * n..r * n + i])
                .map(|(a, b)| a * b)
                .sum();
            let l = (b - s) / ws.chol[i * n + i];
            ws.chol[r * n + i] = l;
            dot += l * l;
        }
        let pivot2 = 1.0 - dot;
        if !(pivot2 > SINGULAR_TOLERANCE) {
            // The partial row is overwritten by the next kept neighbour.
            continue;
        }
        let d = pivot2.sqrt();
        ws.chol[r * n + r] = d;
        let kj = kernel.eval(x, y);
        let s: f64 = ws.chol[r * n..r * n + r]
            .iter()
            .zip(&ws.z)
            .map(|(a, b)| a * b)
            .sum();
        let zr = (kj - s) / d;
        q += zr * zr;
        ws.z.push(zr);
        ws.k.push(kj);
        ws.kept.push(j);
    }
    // α = L^-T z (back substitution, in place in z).
    let m = ws.kept.len();
    for r in (0..m).rev() {
        let mut s = ws.z[r];
        for i in r + 1..m {
            s -= ws.chol[i * n + r] * ws.z[i];
        }
        ws.z[r] = s / ws.chol[r * n + r];
    }
    q
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;
    use nalgebra::{DMatrix, DVector};
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn iso(sigma: f64) -> Kernel {
        Kernel::new(sigma, f64::INFINITY).unwrap()
    }

    /// A jittered hexagonal grid in the plane z = 0 with spacing `h`, `n × n` points.
    fn jittered_plane(n: usize, h: f64, jitter: f64, seed: u64) -> Vec<DVec3> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut pts = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let x =
                    (i as f64 + 0.5 * (j % 2) as f64) * h + jitter * rng.random_range(-1.0..1.0);
                let y = j as f64 * h * 3f64.sqrt() / 2.0 + jitter * rng.random_range(-1.0..1.0);
                pts.push(DVec3::new(x, y, 0.0));
            }
        }
        pts
    }

    /// s(x) with the global K over all `pts` by a direct inverse (nalgebra LU).
    fn global_measure(kernel: &Kernel, x: &KernelPoint, pts: &[KernelPoint]) -> f64 {
        let n = pts.len();
        let kmat = DMatrix::from_fn(n, n, |i, j| kernel.eval(&pts[i], &pts[j]));
        let kvec = DVector::from_fn(n, |i, _| kernel.eval(x, &pts[i]));
        let alpha = kmat.lu().solve(&kvec).unwrap();
        1.0 - kvec.dot(&alpha)
    }

    fn sorted_neighbors(
        kernel: &Kernel,
        x: &KernelPoint,
        pts: &[KernelPoint],
        r: f64,
    ) -> Vec<KernelPoint> {
        let mut v: Vec<_> = pts
            .iter()
            .copied()
            .filter(|p| p.dist2(x) <= r * r)
            .collect();
        v.sort_by(|a, b| a.dist2(x).total_cmp(&b.dist2(x)));
        let _ = kernel;
        v
    }

    /// The largest |local - global| of s over query points inside a jittered hexagonal patch of
    /// spacing `h` (kernel units), with neighbours within `r`.
    fn max_truncation_error(h: f64, r: f64) -> f64 {
        let k = iso(1.0);
        let pts: Vec<_> = jittered_plane(18, h, 0.15 * h, 1)
            .into_iter()
            .map(|p| k.embed(p, DVec3::Z))
            .collect();
        let mut ws = MeasureWorkspace::new();
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let mut worst: f64 = 0.0;
        for _ in 0..40 {
            // Query points well inside the patch, so the local neighbourhood is complete.
            let x = k.embed(
                DVec3::new(
                    rng.random_range(6.0..11.0) * h,
                    rng.random_range(5.0..9.0) * h,
                    0.0,
                ),
                DVec3::Z,
            );
            let local = spectral_measure(&k, &x, sorted_neighbors(&k, &x, &pts, r), -1.0, &mut ws);
            assert!((0.0..=1.0).contains(&local.s));
            worst = worst.max((local.s - global_measure(&k, &x, &pts)).abs());
        }
        worst
    }

    #[test]
    fn local_measure_converges_to_the_global_kernel_matrix() {
        // Spacings around the sampler's (mean edge about 1.2 sigma_p).
        for h in [0.8, 1.0, 1.2] {
            let e25 = max_truncation_error(h, 2.5);
            let e35 = max_truncation_error(h, 3.5);
            assert!(e35 < 1e-3, "h {h}: r 3.5 error {e35}");
            assert!(e25 < 1e-2, "h {h}: r 2.5 error {e25}");
        }
    }

    /// Issue 2 asks the local measure at the paper's r = 2.5 to agree with the global K within
    /// 1e-3; measured here: 2.1e-3 to 6.3e-3 on these patches at h = 0.8 to 1.2 (1.5e-3 at
    /// h = 1.5), within 1e-3 at r = 3.5. The gap is the Gaussian's tail beyond r:
    /// exp(-2.5^2) = 1.9e-3 per neighbour left out.
    #[test]
    #[ignore = "issue 2: at r = 2.5 the local measure is within 6.3e-3 of the global, not 1e-3 (met at r = 3.5)"]
    fn local_measure_at_r_2_5_agrees_with_the_global_within_1e_3() {
        for h in [0.8, 1.0, 1.2] {
            let e = max_truncation_error(h, 2.5);
            assert!(e < 1e-3, "h {h}: error {e}");
        }
    }

    #[test]
    fn measure_is_one_alone_zero_on_a_duplicate_and_in_unit_range() {
        let k = iso(1.0);
        let mut ws = MeasureWorkspace::new();
        let x = k.embed(DVec3::new(0.3, 0.2, 0.0), DVec3::Z);
        assert_eq!(spectral_measure(&k, &x, [], -1.0, &mut ws).s, 1.0);
        let pts: Vec<_> = jittered_plane(6, 0.7, 0.2, 3)
            .into_iter()
            .map(|p| k.embed(p, DVec3::Z))
            .collect();
        for p in &pts {
            let m = spectral_measure(&k, p, sorted_neighbors(&k, p, &pts, 2.5), -1.0, &mut ws);
            assert!(m.s.abs() < 1e-6, "duplicate point has s = {}", m.s);
        }
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        for _ in 0..100 {
            let x = k.embed(
                DVec3::new(
                    rng.random_range(-1.0..5.0),
                    rng.random_range(-1.0..5.0),
                    rng.random_range(-1.0..1.0),
                ),
                DVec3::Z,
            );
            let m = spectral_measure(&k, &x, sorted_neighbors(&k, &x, &pts, 2.5), -1.0, &mut ws);
            assert!((0.0..=1.0).contains(&m.s));
        }
    }

    #[test]
    fn block_inversion_matches_a_direct_inverse() {
        let k = Kernel::new(1.0, 0.75).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let pts: Vec<_> = (0..30)
            .map(|_| {
                let p = DVec3::new(
                    rng.random_range(0.0..4.0),
                    rng.random_range(0.0..4.0),
                    rng.random_range(-0.3..0.3),
                );
                let n = DVec3::new(
                    rng.random_range(-0.3..0.3),
                    rng.random_range(-0.3..0.3),
                    1.0,
                )
                .normalize();
                k.embed(p, n)
            })
            .collect();
        let mut inc = IncrementalInverse::new();
        for p in &pts {
            assert!(matches!(inc.push(&k, *p), Push::Added { .. }));
        }
        let n = pts.len();
        let direct = DMatrix::from_fn(n, n, |i, j| k.eval(&pts[i], &pts[j]))
            .try_inverse()
            .unwrap();
        let mut max_err: f64 = 0.0;
        for i in 0..n {
            for j in 0..n {
                max_err = max_err.max((inc.inverse()[i * n + j] - direct[(i, j)]).abs());
            }
        }
        let scale = direct.abs().max();
        assert!(
            max_err <= 1e-9 * scale.max(1.0),
            "max error {max_err} (scale {scale})"
        );
    }

    #[test]
    fn near_singular_neighbours_are_skipped() {
        let k = iso(1.0);
        let a = k.embed(DVec3::ZERO, DVec3::Z);
        let b = k.embed(DVec3::new(1e-7, 0.0, 0.0), DVec3::Z);
        let c = k.embed(DVec3::new(0.8, 0.0, 0.0), DVec3::Z);
        let mut ws = MeasureWorkspace::new();
        let x = k.embed(DVec3::new(0.5, 0.5, 0.0), DVec3::Z);
        let m = spectral_measure(&k, &x, [a, b, c], -1.0, &mut ws);
        assert_eq!(m.skipped, 1);
        assert_eq!(m.used, 2);
        let reference = spectral_measure(&k, &x, [a, c], -1.0, &mut ws);
        assert!((m.s - reference.s).abs() < 1e-9);
    }

    #[test]
    fn early_stop_gives_an_upper_bound_at_or_below_the_threshold() {
        let k = iso(1.0);
        let pts: Vec<_> = jittered_plane(8, 0.8, 0.1, 6)
            .into_iter()
            .map(|p| k.embed(p, DVec3::Z))
            .collect();
        let x = k.embed(DVec3::new(2.9, 2.1, 0.0), DVec3::Z);
        let mut ws = MeasureWorkspace::new();
        let nb = sorted_neighbors(&k, &x, &pts, 2.5);
        let full = spectral_measure(&k, &x, nb.clone(), -1.0, &mut ws);
        let early = spectral_measure(&k, &x, nb.clone(), 0.5, &mut ws);
        assert!(early.stopped_early);
        assert!(early.s <= 0.5);
        assert!(early.s >= full.s - 1e-12);
        assert!(early.used < full.used);
    }

    /// `n` points in the slab |x|, |y| <= 3, |z| <= 0.5 with normals within about 35° of +z,
    /// embedded with `k`.
    fn slab_points(k: &Kernel, n: usize, rng: &mut ChaCha8Rng) -> Vec<KernelPoint> {
        (0..n)
            .map(|_| {
                let p = DVec3::new(
                    rng.random_range(-3.0..3.0),
                    rng.random_range(-3.0..3.0),
                    rng.random_range(-0.5..0.5),
                );
                let n = DVec3::new(
                    rng.random_range(-0.5..0.5),
                    rng.random_range(-0.5..0.5),
                    1.0,
                )
                .normalize();
                k.embed(p, n)
            })
            .collect()
    }

    #[test]
    fn cholesky_measure_matches_block_inversion() {
        let k = Kernel::new(1.2, 0.6).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        let mut ws = MeasureWorkspace::new();
        for _ in 0..20 {
            let pts = slab_points(&k, 25, &mut rng);
            let x = k.embed(DVec3::new(0.1, -0.2, 0.05), DVec3::Z);
            let s_eq10 = spectral_measure(&k, &x, pts.clone(), -1.0, &mut ws).s;
            let (s_chol, _) = measure_and_gradient(&k, &x, &pts, &mut ws);
            assert!((s_eq10 - s_chol).abs() < 1e-9, "{s_eq10} vs {s_chol}");
        }
    }

    #[test]
    fn projection_coefficients_match_a_direct_solve_and_reproduce_a_neighbour() {
        let k = Kernel::new(1.2, 0.6).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(10);
        let mut ws = MeasureWorkspace::new();
        let mut alpha = Vec::new();
        for _ in 0..20 {
            let pts = slab_points(&k, 20, &mut rng);
            let x = k.embed(DVec3::new(0.3, 0.1, -0.05), DVec3::Z);
            let s = projection_coefficients(&k, &x, &pts, &mut ws, &mut alpha);
            // Oracle: α = K^-1 k by LU over the neighbours kept (none is near-singular here).
            assert_eq!(alpha.len(), pts.len());
            let n = pts.len();
            let kmat = DMatrix::from_fn(n, n, |i, j| k.eval(&pts[i], &pts[j]));
            let kvec = DVector::from_fn(n, |i, _| k.eval(&x, &pts[i]));
            let direct = kmat.lu().solve(&kvec).unwrap();
            for &(i, a) in &alpha {
                assert!(
                    (a - direct[i]).abs() < 1e-6 * (1.0 + direct[i].abs()),
                    "{a} vs {}",
                    direct[i]
                );
            }
            assert!((s - (1.0 - kvec.dot(&direct))).abs() < 1e-9);
            // x equal to neighbour 3: φ(x) is φ(y_3), α = e_3 and s = 0.
            let s = projection_coefficients(&k, &pts[3], &pts, &mut ws, &mut alpha);
            assert!(s < 1e-9, "{s}");
            for &(i, a) in &alpha {
                let want = if i == 3 { 1.0 } else { 0.0 };
                assert!((a - want).abs() < 1e-6, "neighbour {i}: {a}");
            }
        }
        // No neighbours: nothing to project on.
        let x = k.embed(DVec3::ZERO, DVec3::Z);
        assert_eq!(
            projection_coefficients(&k, &x, &[], &mut ws, &mut alpha),
            1.0
        );
        assert!(alpha.is_empty());
    }

    #[test]
    fn gradient_matches_finite_differences_of_the_measure() {
        let k = Kernel::new(1.5, 0.8).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let mut ws = MeasureWorkspace::new();
        for trial in 0..25 {
            let pts = slab_points(&k, 18, &mut rng);
            let p0 = DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                0.0,
            );
            let x = k.embed(p0, DVec3::Z);
            let (_, g) = measure_and_gradient(&k, &x, &pts, &mut ws);
            let h = 1e-6;
            for (c, &gc) in g.iter().enumerate() {
                let mut xp = x;
                let mut xm = x;
                xp.coords[c] += h;
                xm.coords[c] -= h;
                let fd = (spectral_measure(&k, &xp, pts.clone(), -1.0, &mut ws).s
                    - spectral_measure(&k, &xm, pts.clone(), -1.0, &mut ws).s)
                    / (2.0 * h);
                assert!(
                    (fd - gc).abs() < 1e-5 * (1.0 + fd.abs()),
                    "trial {trial} axis {c}: analytic {gc} finite difference {fd}"
                );
            }
        }
    }

    /// A smooth width field in (0, 1] over kernel-unit positions, and its gradient.
    fn width_field(p: DVec3) -> (f64, [f64; 3]) {
        let w = 0.55 + 0.3 * (0.9 * p.x).sin() * (0.7 * p.y).cos() + 0.1 * p.z;
        let g = [
            0.27 * (0.9 * p.x).cos() * (0.7 * p.y).cos(),
            -0.21 * (0.9 * p.x).sin() * (0.7 * p.y).sin(),
            0.1,
        ];
        (w, g)
    }

    /// Points of `slab_points` with the widths of `width_field`.
    fn graded_slab(k: &Kernel, n: usize, rng: &mut ChaCha8Rng) -> Vec<KernelPoint> {
        slab_points(k, n, rng)
            .into_iter()
            .map(|mut p| {
                p.width = width_field(p.position()).0;
                p
            })
            .collect()
    }

    #[test]
    fn graded_kernel_matrix_is_positive_definite_and_the_measure_in_unit_range() {
        let k = Kernel::new(1.0, 0.7).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut ws = MeasureWorkspace::new();
        for _ in 0..10 {
            // Widths from 0.05 to 1, points close together: the matrix a plain Gaussian with
            // a per-pair width could make indefinite.
            let pts: Vec<KernelPoint> = slab_points(&k, 40, &mut rng)
                .into_iter()
                .map(|mut p| {
                    p.width = rng.random_range(0.05..1.0);
                    p
                })
                .collect();
            let n = pts.len();
            let kmat = DMatrix::from_fn(n, n, |i, j| k.eval(&pts[i], &pts[j]));
            assert!((kmat.clone() - kmat.transpose()).abs().max() == 0.0);
            let eig = kmat.symmetric_eigenvalues();
            assert!(eig.min() > -1e-12, "smallest eigenvalue {}", eig.min());
            for i in 0..n {
                assert_eq!(kmat[(i, i)], 1.0);
            }
            for _ in 0..20 {
                let mut x = k.embed(
                    DVec3::new(
                        rng.random_range(-3.0..3.0),
                        rng.random_range(-3.0..3.0),
                        0.0,
                    ),
                    DVec3::Z,
                );
                x.width = rng.random_range(0.05..1.0);
                let m = spectral_measure(&k, &x, pts.clone(), -1.0, &mut ws);
                assert!((0.0..=1.0).contains(&m.s), "s = {}", m.s);
            }
        }
    }

    #[test]
    fn graded_local_measure_converges_to_the_global_kernel_matrix() {
        // Sample-like spacing: a jittered grid whose spacing follows the width field, so each
        // point has a few neighbours within its own width.
        let k = iso(1.0);
        let mut rng = ChaCha8Rng::seed_from_u64(12);
        let mut pts = Vec::new();
        for p in jittered_plane(40, 0.25, 0.05, 13) {
            let (w, _) = width_field(p);
            // Thin the grid to a density of about 1 / (spacing w)^2.
            let spacing = 1.0;
            if rng.random_range(0.0..1.0) < (0.25 / (spacing * w)).powi(2) {
                pts.push(k.embed_graded(p, DVec3::Z, w));
            }
        }
        let mut ws = MeasureWorkspace::new();
        let mut worst: f64 = 0.0;
        for _ in 0..40 {
            let p = DVec3::new(rng.random_range(3.0..6.0), rng.random_range(3.0..5.5), 0.0);
            let x = k.embed_graded(p, DVec3::Z, width_field(p).0);
            // Measured: the largest error is 2.2e-3 at r = 3.5 and 0.011-0.029 at the scan's 2.5
            // (spacing 0.9-1.2 w), against 6.3e-3 at 2.5 for the global kernel: a point among
            // wider ones sees them over their width. Within 1e-3 from r = 4.5.
            let r2 = 5.0 * 5.0;
            let mut near: Vec<KernelPoint> = pts
                .iter()
                .copied()
                .filter(|y| x.pair_dist2(y) <= r2)
                .collect();
            near.sort_by(|a, b| x.pair_dist2(a).total_cmp(&x.pair_dist2(b)));
            let local = spectral_measure(&k, &x, near, -1.0, &mut ws);
            let global = global_measure(&k, &x, &pts);
            assert!((0.0..=1.0).contains(&local.s));
            worst = worst.max((local.s - global).abs());
        }
        assert!(worst < 1e-3, "largest |local - global| {worst}");
    }

    #[test]
    fn graded_gradient_matches_finite_differences_along_the_width_field() {
        let k = Kernel::new(1.0, 0.8).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(14);
        let mut ws = MeasureWorkspace::new();
        for trial in 0..25 {
            let pts = graded_slab(&k, 18, &mut rng);
            let p0 = DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                0.0,
            );
            let at = |p: DVec3| {
                let mut x = k.embed(p, DVec3::Z);
                x.width = width_field(p).0;
                x
            };
            let x = at(p0);
            let (_, g) = measure_and_gradient_graded(&k, &x, width_field(p0).1, &pts, &mut ws);
            let h = 1e-6;
            for (c, &gc) in g.iter().enumerate() {
                let mut d = DVec3::ZERO;
                d[c] = h;
                let fd = (spectral_measure(&k, &at(p0 + d), pts.clone(), -1.0, &mut ws).s
                    - spectral_measure(&k, &at(p0 - d), pts.clone(), -1.0, &mut ws).s)
                    / (2.0 * h);
                assert!(
                    (fd - gc).abs() < 1e-5 * (1.0 + fd.abs()),
                    "trial {trial} axis {c}: analytic {gc} finite difference {fd}"
                );
            }
        }
    }

    #[test]
    fn unit_widths_give_the_paper_kernel_bit_for_bit() {
        let k = Kernel::new(1.3, 0.8).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(15);
        let mut ws = MeasureWorkspace::new();
        let pts = slab_points(&k, 20, &mut rng);
        let x = k.embed_graded(DVec3::new(0.2, 0.1, 0.0), DVec3::Z, 1.0);
        let plain = measure_and_gradient(&k, &x, &pts, &mut ws);
        let graded = measure_and_gradient_graded(&k, &x, [0.0; 3], &pts, &mut ws);
        assert_eq!(plain, graded);
        // And a width below 1 changes it: the grading is not ignored.
        let mut y = x;
        y.width = 0.5;
        assert_ne!(measure_and_gradient(&k, &y, &pts, &mut ws), plain);
    }
}
