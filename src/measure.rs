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
/// or [`GaussianKernel`](crate::internal::GaussianKernel) on points of R^K.
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
///
/// For a graded kernel (see [`Kernel`](crate::internal::Kernel)), x's width w follows a sizing
/// field whose gradient at x, in kernel units (d w / d(p / sigma_p)), is `width_gradient`; the
/// gradient returned is that of s(x) with x's width moving with it. The neighbours keep their
/// widths.
///
/// With log k_i = 3/2 (log w + log w_i - log s_i²) - |p - p_i|² / s_i² - |Δn|², s_i² = (w² + w_i²)
/// / 2 (positions in kernel units):
///
/// ∇k_i = k_i [-2 (p - p_i) / s_i² + (3/2 (1/w - w/s_i²) + |p - p_i|² w / s_i⁴) ∇w], ∇s = -2 Σ_i
/// α_i ∇k_i;
///
/// with every width 1 and ∇w = 0 this is the formula above (and the same arithmetic, so the same
/// bits).
pub fn measure_and_gradient(
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
mod tests;
