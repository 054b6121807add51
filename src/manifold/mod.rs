//! Point sets near a manifold of any dimension, in R^d: the linear scan (Algorithm 1) and the
//! gradient ascent (eq. 11) on the paper's kernel, for curves, surfaces, volumes and
//! higher-dimensional manifolds alike (the paper's abstract and Sec. 3: "the analysis and
//! algorithms are general and can be applied for simplifying and resampling point clouds lying near
//! a manifold of arbitrary dimension").
//!
//! A point p of R^d with a unit normal n (optional) is mapped to x = [p/sigma_p, n/sigma_n] in R^K,
//! K = 2d (K = d with positions only, sigma_n = infinity), and two points meet with the Gaussian
//! k(x, y) = exp(-|x - y|²) ([`GaussianKernel`](crate::internal::GaussianKernel)). The spectral
//! measure is the crate's one implementation
//! ([`spectral_measure`](crate::internal::spectral_measure), generic over the kernel); the kd-trees
//! are kiddo's in K dimensions ([`StaticKdTree`],
//! [`DynamicKdTree`](crate::internal::DynamicKdTree)). Every routine is written once over the const
//! dimension K and instantiated for K = 1 to [`MAX_KERNEL_DIMENSION`]: d up to 16 with positions
//! only, up to 8 with normals.
//!
//! - `linear_scan.rs`: Algorithm 1 over the points in a seeded random order, and the search for the
//!   sigma_p that gives a count.
//! - `gradient_ascent.rs`: eq. 11 on the samples, each move projected onto the manifold by a
//!   [`ManifoldProjection`].
//! - `projection.rs`: the projection onto the point set itself (local principal components).
//! - `dimension.rs`: the manifold's dimension estimated from the points (Levina and Bickel 2004).
//!
//! Units: positions and sigma_p in the point set's own units (no rescaling: a point set in R^d has
//! no bounding-box convention of its own); sigma_n dimensionless.

mod dimension;
mod gradient_ascent;
mod linear_scan;
mod projection;

use crate::error::{Error, Result};
use crate::kernel::SUPPORT_RADIUS;
use crate::measure::DEFAULT_EPSILON;
use crate::sampling::gradient_ascent::{GradientAscentParams, GradientAscentResult};
use crate::spatial::StaticKdTree;

pub use dimension::{estimate_dimension, DIMENSION_NEIGHBOURS};
pub use projection::{DataProjection, ManifoldProjection, PROJECTION_ITERATIONS};

/// The step of eq. 11 in kernel units for point sets in R^d (the surface sampler's is 0.55,
/// [`GradientAscentParams::step`], measured on meshes). A curve is stiffer than a surface: the
/// step is the one measured on a circle, the Clifford torus, a Swiss roll and the 3-sphere
/// (`tests/manifold_sampling.rs`); the figures are in `docs/decisions/manifold-ascent-step.md`.
pub const MANIFOLD_ASCENT_STEP: f64 = 0.45;

/// The largest kernel-space dimension K = d (positions only) or 2d (with normals) the sampler
/// is built for.
pub const MAX_KERNEL_DIMENSION: usize = 16;

/// A point set in R^d: `len()` points with `dim()` coordinates each, and optionally a unit
/// normal per point (any direction field the kernel should tell apart: the normal of a
/// hypersurface, a tangent, a feature vector of the same length).
#[derive(Debug, Clone, PartialEq)]
pub struct PointSet {
    dim: usize,
    positions: Vec<f64>,
    normals: Option<Vec<f64>>,
}

impl PointSet {
    /// A point set from row-major `positions` (`n × dim` values, the point set's own units) and
    /// optional row-major `normals` of the same shape, each normalized to unit length.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when `dim` is 0 or exceeds [`MAX_KERNEL_DIMENSION`], when a
    /// length is not a multiple of `dim` or
    /// the normals' differs from the positions', when there is no point, or when a coordinate
    /// is not finite or a normal has no direction (both named by row).
    pub fn new(dim: usize, positions: Vec<f64>, normals: Option<Vec<f64>>) -> Result<Self> {
        let bad = |name, message: String| Err(Error::InvalidParameter { name, message });
        if dim == 0 {
            return bad("X", "points need at least one coordinate".into());
        }
        if dim > MAX_KERNEL_DIMENSION {
            return bad(
                "X",
                format!("{dim} coordinates are more than the {MAX_KERNEL_DIMENSION} supported"),
            );
        }
        if !positions.len().is_multiple_of(dim) {
            return bad(
                "X",
                format!("{} values are not rows of {dim}", positions.len()),
            );
        }
        if positions.is_empty() {
            return bad("X", "no points".into());
        }
        if let Some(row) = positions
            .chunks_exact(dim)
            .position(|p| p.iter().any(|c| !c.is_finite()))
        {
            return bad(
                "X",
                format!("point {row} has a coordinate that is not finite"),
            );
        }
        let normals = match normals {
            None => None,
            Some(mut n) => {
                if n.len() != positions.len() {
                    return bad(
                        "normals",
                        format!(
                            "{} rows for {} points",
                            n.len() / dim,
                            positions.len() / dim
                        ),
                    );
                }
                for (row, v) in n.chunks_exact_mut(dim).enumerate() {
                    let len = v.iter().map(|c| c * c).sum::<f64>().sqrt();
                    if !(len.is_finite() && len > 0.0) {
                        return bad(
                            "normals",
                            format!("normal {row} has no direction (zero, or not finite)"),
                        );
                    }
                    v.iter_mut().for_each(|c| *c /= len);
                }
                Some(n)
            }
        };
        Ok(PointSet {
            dim,
            positions,
            normals,
        })
    }

    /// The dimension d of the space.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        self.positions.len() / self.dim
    }

    /// Whether there is no point (never, for a set made by [`PointSet::new`]).
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Point `i`'s coordinates.
    pub fn position(&self, i: usize) -> &[f64] {
        &self.positions[i * self.dim..(i + 1) * self.dim]
    }

    /// The positions, row-major (`len() × dim()`).
    pub fn positions(&self) -> &[f64] {
        &self.positions
    }

    /// The unit normals, row-major, when the set has them.
    pub fn normals(&self) -> Option<&[f64]> {
        self.normals.as_deref()
    }

    /// The points `indices`, in that order, as a point set of their own.
    ///
    /// # Panics
    /// When an index is out of range.
    pub fn subset(&self, indices: &[usize]) -> PointSet {
        let pick = |v: &[f64]| -> Vec<f64> {
            indices
                .iter()
                .flat_map(|&i| v[i * self.dim..(i + 1) * self.dim].iter().copied())
                .collect()
        };
        PointSet {
            dim: self.dim,
            positions: pick(&self.positions),
            normals: self.normals.as_deref().map(pick),
        }
    }

    /// The kernel-space dimension for the normal width `sigma_n`: 2d with normals and a finite
    /// sigma_n, d otherwise.
    fn kernel_dim(&self, sigma_n: f64) -> usize {
        if self.normals.is_some() && sigma_n.is_finite() {
            2 * self.dim
        } else {
            self.dim
        }
    }

    /// The positions in R^K (zeros past d) in the kd-trees' frame ([`tree_frame`]), and a
    /// static kd-tree over them: index i of a query's result is point i.
    fn position_tree<const K: usize>(&self) -> (Vec<[f64; K]>, StaticKdTree<K>) {
        let rows: Vec<[f64; K]> = self
            .embed::<K>(1.0, f64::INFINITY)
            .iter()
            .map(tree_frame)
            .collect();
        let tree = StaticKdTree::new(&rows);
        (rows, tree)
    }

    /// Every point mapped to kernel space, x = [p/sigma_p, n/sigma_n] (zeros beyond the
    /// position part when the set has no normals or sigma_n is infinite; K >= kernel_dim).
    fn embed<const K: usize>(&self, sigma_p: f64, sigma_n: f64) -> Vec<[f64; K]> {
        (0..self.len())
            .map(|i| {
                let mut x = [0.0; K];
                let d = self.dim;
                for (c, p) in x.iter_mut().zip(self.position(i)) {
                    *c = p / sigma_p;
                }
                if let (Some(n), false) = (&self.normals, sigma_n.is_infinite()) {
                    for (c, v) in x[d..2 * d].iter_mut().zip(&n[i * d..(i + 1) * d]) {
                        *c = v / sigma_n;
                    }
                }
                x
            })
            .collect()
    }
}

/// Parameters of [`sample_manifold`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ManifoldSampleParams {
    /// The kernel width in the point set's units; `None`: searched for `count`.
    pub sigma_p: Option<f64>,
    /// About this many samples (within `count_tolerance`), sigma_p searched for; used when
    /// `sigma_p` is `None`.
    pub count: Option<usize>,
    /// The normal width (> 0; default infinity: positions only). Finite values need normals.
    pub sigma_n: f64,
    /// Acceptance threshold of Algorithm 1 (default 0.5, Sec. 6.3).
    pub epsilon: f64,
    /// Neighbourhood radius in kernel units (default 2.5, Sec. 6.3).
    pub support_radius: f64,
    /// The dimension m of the manifold the points lie near (for the count search's first step);
    /// `None`: estimated from the points ([`estimate_dimension`]).
    pub dimension: Option<usize>,
    /// Relative tolerance of the count (default 0.005).
    pub count_tolerance: f64,
    /// Seed of the visit order.
    pub seed: u64,
}

impl Default for ManifoldSampleParams {
    fn default() -> Self {
        ManifoldSampleParams {
            sigma_p: None,
            count: None,
            sigma_n: f64::INFINITY,
            epsilon: DEFAULT_EPSILON,
            support_radius: SUPPORT_RADIUS,
            dimension: None,
            count_tolerance: 0.005,
            seed: 1,
        }
    }
}

/// What [`sample_manifold`] chose.
#[derive(Debug, Clone, PartialEq)]
pub struct ManifoldSampling {
    /// Indices of the samples into the point set, increasing.
    pub indices: Vec<usize>,
    /// The kernel width used, in the point set's units.
    pub sigma_p: f64,
    /// The normal width used.
    pub sigma_n: f64,
    /// The manifold's dimension m given or estimated (`None` when sigma_p was given and none was
    /// needed).
    pub dimension: Option<usize>,
    /// Whether the count is within its tolerance (true when sigma_p was given).
    pub reached: bool,
    /// Every linear scan of the sigma_p search as (sigma_p, count), in order.
    pub search: Vec<(f64, usize)>,
    /// Points of the chosen scan rejected by their nearest sample alone.
    pub rejected_by_nearest: usize,
    /// Points of the chosen scan whose measure was evaluated over their whole neighbourhood.
    pub measured: usize,
}

/// Parameters of [`resample_manifold`]: the kernel of the samples and the sweeps of eq. 11.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ManifoldResampleParams {
    /// The kernel width in the point set's units (the one the samples were taken with).
    pub sigma_p: f64,
    /// The normal width (default infinity). Finite values need normals.
    pub sigma_n: f64,
    /// Sweeps over all samples (default 10, Sec. 6.3).
    pub iterations: usize,
    /// Step of eq. 11 in kernel units (default [`MANIFOLD_ASCENT_STEP`], 0.45).
    pub step: f64,
    /// Largest move of one sample in one sweep, in units of sigma_p (default 0.25).
    pub max_move_sigma_p: f64,
    /// Neighbourhood radius in kernel units (default 2.5, Sec. 6.3).
    pub support_radius: f64,
    /// Seed of the visit order.
    pub seed: u64,
}

impl ManifoldResampleParams {
    /// The defaults at `sigma_p`, positions only: the surface sampler's sweeps, largest move and
    /// support ([`GradientAscentParams::default`]), the step [`MANIFOLD_ASCENT_STEP`].
    pub fn new(sigma_p: f64) -> Self {
        let g = GradientAscentParams::default();
        ManifoldResampleParams {
            sigma_p,
            sigma_n: f64::INFINITY,
            iterations: g.iterations,
            step: MANIFOLD_ASCENT_STEP,
            max_move_sigma_p: g.max_move_sigma_p,
            support_radius: g.support_radius,
            seed: 1,
        }
    }
}

/// Runs `$body` with the const `$k` bound to the runtime kernel-space dimension `$dim`
/// (1 to [`MAX_KERNEL_DIMENSION`]); `$none` otherwise.
macro_rules! with_kernel_dim {
    ($dim:expr, $k:ident => $body:expr, $none:expr) => {
        match $dim {
            1 => {
                const $k: usize = 1;
                $body
            }
            2 => {
                const $k: usize = 2;
                $body
            }
            3 => {
                const $k: usize = 3;
                $body
            }
            4 => {
                const $k: usize = 4;
                $body
            }
            5 => {
                const $k: usize = 5;
                $body
            }
            6 => {
                const $k: usize = 6;
                $body
            }
            7 => {
                const $k: usize = 7;
                $body
            }
            8 => {
                const $k: usize = 8;
                $body
            }
            9 => {
                const $k: usize = 9;
                $body
            }
            10 => {
                const $k: usize = 10;
                $body
            }
            11 => {
                const $k: usize = 11;
                $body
            }
            12 => {
                const $k: usize = 12;
                $body
            }
            13 => {
                const $k: usize = 13;
                $body
            }
            14 => {
                const $k: usize = 14;
                $body
            }
            15 => {
                const $k: usize = 15;
                $body
            }
            16 => {
                const $k: usize = 16;
                $body
            }
            _ => $none,
        }
    };
}
pub(crate) use with_kernel_dim;

/// The kernel's widths checked against `points`: sigma_p positive and finite, sigma_n positive
/// (infinity: positions only), finite only with normals, and the kernel space (2d with a finite
/// sigma_n) within [`MAX_KERNEL_DIMENSION`].
fn check_widths(points: &PointSet, sigma_p: f64, sigma_n: f64) -> Result<()> {
    // The kernel's own checks, the parameters named as this module's callers name them.
    crate::kernel::Kernel::new(sigma_p, sigma_n).map_err(|e| match e {
        Error::InvalidParameter { name, message } => Error::InvalidParameter {
            name: if name == "sigma_p" {
                "sigma_p"
            } else {
                "sigma_n"
            },
            message,
        },
        other => other,
    })?;
    if sigma_n.is_finite() && points.normals.is_none() {
        return Err(Error::InvalidParameter {
            name: "sigma_n",
            message: "a finite normal width needs normals".into(),
        });
    }
    if points.kernel_dim(sigma_n) > MAX_KERNEL_DIMENSION {
        return Err(Error::InvalidParameter {
            name: "sigma_n",
            message: format!(
                "a finite normal width in {} dimensions makes a kernel space of {}, more than \
                 the {MAX_KERNEL_DIMENSION} supported (normals are used up to {} dimensions)",
                points.dim,
                2 * points.dim,
                MAX_KERNEL_DIMENSION / 2
            ),
        });
    }
    Ok(())
}

/// Subsamples `points` by the randomized linear scan (Algorithm 1, Sec. 6.1) on the kernel
/// k(x, y) = exp(-|x - y|²), x = [p/sigma_p, n/sigma_n]: the points are visited in a random
/// order (seeded) and kept when s(x) > epsilon against the points kept so far (eq. 9, by the
/// iterative inversion of eq. 10), nearest neighbours first. With `count`, sigma_p is searched
/// for (`find_sigma_p`, log count against log sigma_p, first step along the manifold's
/// dimension).
///
/// Costs O(n log n) per scan plus the inversions of the points not rejected by their nearest
/// sample; a count search takes a few scans (at most 16).
///
/// # Errors
/// [`Error::InvalidParameter`] for neither or both of sigma_p and count, a count of 0 or more
/// than the points, sigma_p not positive and finite, sigma_n not positive, a finite sigma_n
/// without normals, epsilon outside (0, 1), a support radius not positive, or a dimension
/// outside 1..=d.
pub fn sample_manifold(
    points: &PointSet,
    params: &ManifoldSampleParams,
) -> Result<ManifoldSampling> {
    linear_scan::check_params(points, params)?;
    let k = points.kernel_dim(params.sigma_n);
    with_kernel_dim!(k, K => linear_scan::sample::<K>(points, params), unreachable_dimension(k))
}

/// Resamples `samples` by gradient ascent on the spectral measure (eq. 11, Sec. 6.2): for
/// `iterations` sweeps, each sample in a seeded random order moves along the gradient of its
/// measure over its neighbours (found once, Sec. 6.3) and is projected onto the manifold by
/// `projection`, which also gives its new normal. Runs of consecutive samples of which no two are
/// neighbours are moved together and projected in one call: the result is that of one sample at
/// a time.
///
/// Returns the moved samples (positions and, with normals, normals) and per sweep the mean move
/// (the point set's units), the mean and the least s before the sweep's moves.
///
/// # Errors
/// [`Error::InvalidParameter`] for the widths as [`sample_manifold`] checks them, a step or
/// largest move not finite and >= 0, a support radius not positive, a projection whose dimension
/// differs from the samples', and whatever the projection returns.
pub fn resample_manifold(
    samples: &PointSet,
    projection: &dyn ManifoldProjection,
    params: &ManifoldResampleParams,
) -> Result<(PointSet, GradientAscentResult)> {
    gradient_ascent::check_params(samples, projection, params)?;
    let k = samples.kernel_dim(params.sigma_n);
    with_kernel_dim!(
        k,
        K => gradient_ascent::resample::<K>(samples, projection, params),
        unreachable_dimension(k)
    )
}

/// The error for a kernel dimension [`PointSet::new`] lets through but no instance serves (none:
/// both stop at [`MAX_KERNEL_DIMENSION`]).
fn unreachable_dimension<T>(k: usize) -> Result<T> {
    Err(Error::Internal {
        stage: "manifold sampling",
        message: format!("no sampler built for kernel dimension {k}"),
    })
}

/// The vector v of [`tree_frame`]'s reflection: v_k = 0.5 + frac(0.618034 (k + 1)) (golden-ratio
/// steps: no two alike, none zero), for every kernel dimension.
const FRAME: [f64; MAX_KERNEL_DIMENSION] = {
    let mut v = [0.0; MAX_KERNEL_DIMENSION];
    let mut k = 0;
    while k < MAX_KERNEL_DIMENSION {
        let x = 0.618_033_988_749_895 * (k + 1) as f64;
        // x - trunc(x), as f64::fract computes it (x is positive and below 2^53).
        v[k] = 0.5 + (x - (x as u64) as f64);
        k += 1;
    }
    v
};

/// |v|² of [`FRAME`]'s first K components.
struct FrameNorm<const K: usize>;

impl<const K: usize> FrameNorm<K> {
    const VV: f64 = {
        let mut vv = 0.0;
        let mut k = 0;
        while k < K {
            vv += FRAME[k] * FRAME[k];
            k += 1;
        }
        vv
    };
}

/// A fixed reflection of R^K (Householder, I - 2 v v^T / |v|² with v = [`FRAME`]): the kd-trees
/// hold points in this frame so that points sharing a coordinate exactly (a grid, an
/// axis-aligned plane, zero normal parts) leave no bucket the tree cannot split. Distances are
/// kept (to rounding).
#[inline]
fn tree_frame<const K: usize>(x: &[f64; K]) -> [f64; K] {
    let mut vx = 0.0;
    for (v, xk) in FRAME.iter().zip(x) {
        vx += v * xk;
    }
    let c = 2.0 * vx / FrameNorm::<K>::VV;
    let mut out = *x;
    for (o, v) in out.iter_mut().zip(&FRAME) {
        *o -= c * v;
    }
    out
}

/// At most `most` indices below `n`, in a random order drawn with `seed`.
fn random_probes(n: usize, most: usize, seed: u64) -> Vec<usize> {
    use rand::seq::SliceRandom;
    use rand::SeedableRng;
    let mut probe: Vec<usize> = (0..n).collect();
    probe.shuffle(&mut rand_chacha::ChaCha8Rng::seed_from_u64(seed));
    probe.truncate(most);
    probe
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::GaussianKernel;

    #[test]
    fn point_sets_are_checked_and_normals_made_unit() {
        assert!(PointSet::new(2, vec![0.0, 1.0, 2.0], None).is_err());
        assert!(PointSet::new(0, vec![], None).is_err());
        assert!(PointSet::new(2, vec![], None).is_err());
        assert!(PointSet::new(17, vec![0.0; 17], None).is_err());
        assert!(PointSet::new(16, vec![0.0; 16], None).is_ok());
        let e = PointSet::new(2, vec![0.0, 1.0, f64::NAN, 0.0], None).unwrap_err();
        assert!(e.to_string().contains("point 1"), "{e}");
        let e = PointSet::new(2, vec![0.0; 4], Some(vec![1.0, 0.0, 0.0, 0.0])).unwrap_err();
        assert!(e.to_string().contains("normal 1"), "{e}");
        let p = PointSet::new(2, vec![0.0; 4], Some(vec![3.0, 4.0, 0.0, -2.0])).unwrap();
        assert_eq!(p.normals().unwrap(), &[0.6, 0.8, 0.0, -1.0]);
        assert_eq!(p.len(), 2);
        assert_eq!(p.subset(&[1]).normals().unwrap(), &[0.0, -1.0]);
    }

    #[test]
    fn the_tree_frame_keeps_distances_and_breaks_axis_ties() {
        let a = [1.0, 2.0, 0.0, 0.0];
        let b = [1.0, -1.0, 0.0, 0.0];
        let (fa, fb) = (tree_frame(&a), tree_frame(&b));
        let d = |x: &[f64; 4], y: &[f64; 4]| GaussianKernel::<4>::dist2(x, y);
        assert!((d(&fa, &fb) - d(&a, &b)).abs() < 1e-12);
        // The shared coordinates 0, 2 and 3 differ after the reflection.
        assert!((0..4).all(|k| fa[k] != fb[k]));
        // A reflection is its own inverse.
        let back = tree_frame(&fa);
        assert!((0..4).all(|k| (back[k] - a[k]).abs() < 1e-12));
    }
}
