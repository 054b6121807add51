//! Robust implicit moving least squares (RIMLS): a smooth, feature-preserving surface defined by an
//! oriented point set, and the projection of points onto it.
//!
//! The surface is the zero set of
//!
//! ```text
//! f(x) = Σ_i w_i(x) n_iᵀ(x - p_i) / Σ_i w_i(x)
//! ```
//!
//! (implicit MLS with a constant fit of the normals' offsets), where the weight of point i is the
//! spatial kernel times two robust terms that are refitted iteratively:
//!
//! ```text
//! w_i = φ(|x - p_i|) · exp(-(r_i / (σ_r σ_p))²) · exp(-|∇f - n_i|² / σ_n²),
//! r_i = f(x) - n_iᵀ(x - p_i)
//! ```
//!
//! with f and ∇f of the previous fit (the first fit uses φ alone). The gradient is the paper's: the
//! robust terms are held constant in it,
//!
//! ```text
//! ∇f = (Σ ∇w_i n_iᵀ(x - p_i) - f Σ ∇w_i + Σ w_i n_i) / Σ w_i.
//! ```
//!
//! The kernel is the one of the spectral sampling paper (Öztireli, Alexa, Gross 2010, Sec. 3,
//! [`Kernel`](crate::internal::Kernel)): k(x, y) = exp(-|x - y|²) with x = [p/σ_p, n/σ_n], so the
//! spatial weight is φ = exp(-|x - p_i|²/σ_p²) and the normal term exp(-|∇f - n_i|²/σ_n²) uses the
//! same σ_n (σ_n = ∞ turns it off: positions only). φ is cut off at `support_radius_sigma_p · σ_p`
//! and shifted down by its value there, so that f stays continuous when a point enters or leaves
//! the support.
//!
//! A point may carry a mass m_i ≥ 0 ([`Rimls::with_masses`]; 1 by default) that multiplies its
//! weight: the point then counts as m_i coincident points. A subsampled point set carries the
//! weights of the points it dropped this way (Sec. 5 of the spectral sampling paper: a dropped
//! point's weight moves to the points that span it; see `representation_weights` in the
//! `spectral-experiments` crate).
//!
//! # References
//! - A. C. Öztireli, G. Guennebaud, M. Gross. *Feature Preserving Point Set Surfaces based on
//!   Non-Linear Kernel Regression.* Computer Graphics Forum 28(2) (Eurographics 2009),
//!   doi:10.1111/j.1467-8659.2009.01388.x: robust fitting by iteratively reweighted least squares
//!   with the residual and normal terms, and the pseudo-code (Algorithm 1) of the evaluation of f
//!   and ∇f followed here. That paper's text is not in this repository; the defaults of σ_r and of
//!   the refitting count come from its public reference implementations (see [`RimlsParams`])
//!   rather than from the paper itself.
//! - A. C. Öztireli, M. Alexa, M. Gross. *Spectral Sampling of Manifolds.* ACM TOG 29(6) (SIGGRAPH
//!   Asia 2010), Sec. 3 and 5: the kernel and its σ_p, σ_n.
//!
//! # Accuracy
//! A planar (constant-offset) fit is biased on curved surfaces: with exact normals the zero set
//! lies about σ_p² (κ_1 + κ_2) / 4 off the true surface (κ_i the principal curvatures), outward on
//! convex parts. On a sphere of radius R that is σ_p² / (2R). The tests measure it.
//!
//! # Runtime
//! One evaluation of f costs one fixed-radius kd-tree query and `1 + max_refit` passes over the
//! neighbours; a projection a few evaluations.

use crate::surface::SurfacePoint;
use glam::DVec3;
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::spatial::StaticTree;

/// Parameters of the RIMLS surface. Lengths are in the units of the point positions (bbox-100
/// units in this crate's pipeline).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RimlsParams {
    /// Spatial kernel width σ_p (> 0, finite; position units): φ = exp(-|x - p_i|²/σ_p²), the
    /// spatial part of the spectral sampling kernel (Sec. 3). Default 1.
    pub sigma_p: f64,
    /// Normal kernel width σ_n (> 0; `f64::INFINITY` for positions only): the refitting weight
    /// exp(-|∇f - n_i|²/σ_n²), the normal part of the sampling kernel (Sec. 3), with ∇f (not
    /// normalized, about unit length near the surface) in place of the query's normal, as in the
    /// RIMLS paper. Smaller values give sharper features. Default 0.75, the value the spectral
    /// sampling paper reconstructs with (Fig. 15).
    pub sigma_n: f64,
    /// Residual scale σ_r, in units of σ_p (> 0; `f64::INFINITY` turns the residual term off):
    /// the refitting weight exp(-(r_i/(σ_r σ_p))²) on the residual r_i = f - n_iᵀ(x - p_i). The
    /// residuals are relative to the spatial scale of the fit (MeshLab's RIMLS, by the paper's
    /// second author, divides them by the local point radius); here by σ_p. Default 0.5, the
    /// default of the Ponca library's RIMLS.
    pub sigma_r: f64,
    /// Radius of the neighbourhood, in units of σ_p (> 0): points farther than
    /// `support_radius_sigma_p · σ_p` are ignored. Default 3: the Gaussian is exp(-9) ≈ 1.2e-4
    /// there, and φ is the Gaussian minus that value.
    pub support_radius_sigma_p: f64,
    /// Robust refitting iterations after the first (unweighted) fit (RIMLS paper, Algorithm 1).
    /// 0 gives plain implicit MLS. Default 3, as in MeshLab's RIMLS (measured against 1 and 10
    /// near fandisk's sharp edges: see `docs/decisions/rimls-projection.md`).
    pub max_refit: usize,
    /// Newton steps of [`Rimls::project`] at most (≥ 1). Default 20.
    pub max_projection_steps: usize,
    /// Convergence tolerance (> 0, dimensionless): projection stops when
    /// |f| < `tolerance · σ_p`; refitting stops when |∇f - ∇f_previous| < `tolerance`.
    /// Default 1e-5.
    pub tolerance: f64,
}

impl Default for RimlsParams {
    fn default() -> Self {
        RimlsParams {
            sigma_p: 1.0,
            sigma_n: 0.75,
            sigma_r: 0.5,
            support_radius_sigma_p: 3.0,
            max_refit: 3,
            max_projection_steps: 20,
            tolerance: 1e-5,
        }
    }
}

impl RimlsParams {
    /// The default parameters with these kernel widths: `sigma_p` in position units, `sigma_n`
    /// dimensionless (`f64::INFINITY` for positions only). Checked by [`Rimls::new`].
    pub fn new(sigma_p: f64, sigma_n: f64) -> Self {
        RimlsParams {
            sigma_p,
            sigma_n,
            ..Self::default()
        }
    }

    /// Checks every field's range.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first field out of range.
    pub fn validate(&self) -> Result<()> {
        let bad =
            |name: &'static str, message: String| Err(Error::InvalidParameter { name, message });
        if !(self.sigma_p.is_finite() && self.sigma_p > 0.0) {
            return bad(
                "sigma_p",
                format!("must be a positive finite number, got {}", self.sigma_p),
            );
        }
        if self.sigma_n.is_nan() || self.sigma_n <= 0.0 {
            return bad(
                "sigma_n",
                format!("must be positive (or infinite), got {}", self.sigma_n),
            );
        }
        if self.sigma_r.is_nan() || self.sigma_r <= 0.0 {
            return bad(
                "sigma_r",
                format!("must be positive (or infinite), got {}", self.sigma_r),
            );
        }
        if !(self.support_radius_sigma_p.is_finite() && self.support_radius_sigma_p > 0.0) {
            return bad(
                "support_radius_sigma_p",
                format!(
                    "must be a positive finite number, got {}",
                    self.support_radius_sigma_p
                ),
            );
        }
        if self.max_projection_steps == 0 {
            return bad("max_projection_steps", "must be at least 1".into());
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return bad(
                "tolerance",
                format!("must be a positive finite number, got {}", self.tolerance),
            );
        }
        Ok(())
    }
}

/// The result of [`Rimls::project_detailed`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RimlsProjection {
    /// The projected position (position units).
    pub position: DVec3,
    /// The unit normal there: ∇f / |∇f|.
    pub normal: DVec3,
    /// f at `position` (position units).
    pub value: f64,
    /// Newton steps taken.
    pub steps: usize,
    /// Whether |f| < `tolerance · σ_p` was reached (false: the steps ran out).
    pub converged: bool,
}

/// The RIMLS surface of an oriented point set, ready for evaluation and projection.
pub struct Rimls {
    positions: Vec<DVec3>,
    normals: Vec<DVec3>,
    /// Per-point masses; empty when every mass is 1.
    masses: Vec<f64>,
    params: RimlsParams,
    tree: StaticTree,
    /// Squared support radius (position units²).
    support_2: f64,
    /// 1/σ_p².
    inv_sigma_p2: f64,
    /// 1/σ_n² (0 for σ_n = ∞).
    inv_sigma_n2: f64,
    /// 1/(σ_r σ_p)² (0 for σ_r = ∞).
    inv_sigma_r2: f64,
    /// exp(-support_radius_sigma_p²): the Gaussian's value at the cut-off, subtracted from φ.
    tail: f64,
}

impl std::fmt::Debug for Rimls {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Rimls")
            .field("points", &self.positions.len())
            .field("params", &self.params)
            .finish()
    }
}

impl Rimls {
    /// The RIMLS surface of `positions` (`N`, any units; σ_p in the same units) with `normals`
    /// (`N`, normalized here; they must point outward: f is positive on their side).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when the parameters are out of range
    /// ([`RimlsParams::validate`]), the two lists are empty or of different lengths, a position is
    /// not finite, or a normal is not finite or zero (the message names the point's index).
    pub fn new(positions: Vec<DVec3>, normals: Vec<DVec3>, params: RimlsParams) -> Result<Self> {
        params.validate()?;
        if positions.is_empty() {
            return Err(Error::InvalidParameter {
                name: "positions",
                message: "no points".into(),
            });
        }
        if positions.len() != normals.len() {
            return Err(Error::InvalidParameter {
                name: "normals",
                message: format!(
                    "{} normals for {} positions",
                    normals.len(),
                    positions.len()
                ),
            });
        }
        if u32::try_from(positions.len()).is_err() {
            return Err(Error::InvalidParameter {
                name: "positions",
                message: format!("{} points, more than 2^32 - 1", positions.len()),
            });
        }
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "positions",
                message: format!("point {i} has a non-finite coordinate {}", positions[i]),
            });
        }
        let mut unit = Vec::with_capacity(normals.len());
        for (i, n) in normals.iter().enumerate() {
            match n.try_normalize() {
                Some(u) if n.is_finite() => unit.push(u),
                _ => {
                    return Err(Error::InvalidParameter {
                        name: "normals",
                        message: format!("normal {i} is zero or not finite: {n}"),
                    })
                }
            }
        }
        let tree = StaticTree::new(&positions);
        let support = params.support_radius_sigma_p * params.sigma_p;
        Ok(Rimls {
            positions,
            normals: unit,
            masses: Vec::new(),
            tree,
            support_2: support * support,
            inv_sigma_p2: 1.0 / (params.sigma_p * params.sigma_p),
            inv_sigma_n2: 1.0 / (params.sigma_n * params.sigma_n),
            inv_sigma_r2: 1.0 / (params.sigma_r * params.sigma_r * params.sigma_p * params.sigma_p),
            tail: (-params.support_radius_sigma_p * params.support_radius_sigma_p).exp(),
            params,
        })
    }

    /// [`Rimls::new`] with a mass per point (`N`, finite, ≥ 0, dimensionless): point i's weight
    /// is multiplied by `masses[i]`, as if it stood `masses[i]` times at the same place (a
    /// point of mass 0 takes no part). Scaling every mass by the same factor changes nothing.
    ///
    /// # Errors
    /// Those of [`Rimls::new`], and [`Error::InvalidParameter`] when `masses` has another
    /// length than `positions`, a mass is negative or not finite (the message names its
    /// index), or every mass is 0.
    pub fn with_masses(
        positions: Vec<DVec3>,
        normals: Vec<DVec3>,
        masses: Vec<f64>,
        params: RimlsParams,
    ) -> Result<Self> {
        let mut rimls = Self::new(positions, normals, params)?;
        if masses.len() != rimls.positions.len() {
            return Err(Error::InvalidParameter {
                name: "masses",
                message: format!(
                    "{} masses for {} positions",
                    masses.len(),
                    rimls.positions.len()
                ),
            });
        }
        if let Some(i) = masses.iter().position(|m| !(m.is_finite() && *m >= 0.0)) {
            return Err(Error::InvalidParameter {
                name: "masses",
                message: format!("mass {i} is {}, not a finite number >= 0", masses[i]),
            });
        }
        if !masses.iter().any(|&m| m > 0.0) {
            return Err(Error::InvalidParameter {
                name: "masses",
                message: "every mass is 0".into(),
            });
        }
        rimls.masses = masses;
        Ok(rimls)
    }

    /// The parameters.
    pub fn params(&self) -> &RimlsParams {
        &self.params
    }

    /// The points (`N`, position units), in the order given.
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// The point nearest to `p`: its index and squared distance (the surface's own kd-tree).
    pub fn nearest(&self, p: DVec3) -> Option<(u32, f64)> {
        self.tree.nearest(p)
    }

    /// The unit normals (`N`, outward), in the order given.
    pub fn normals(&self) -> &[DVec3] {
        &self.normals
    }

    /// Calls `visit(index, squared distance)` for the points within squared distance
    /// `radius_2` of `p` (position units²), in no particular order.
    pub fn visit_within(&self, p: DVec3, radius_2: f64, visit: impl FnMut(u32, f64)) {
        self.tree.visit_within(p, radius_2, visit);
    }

    /// The `k` points nearest `p`, nearest first, as `(index, squared distance)`.
    pub fn nearest_n(&self, p: DVec3, k: usize, out: &mut Vec<(u32, f64)>) {
        self.tree.nearest_n(p, k, out);
    }

    /// Always false ([`Rimls::new`] refuses an empty set).
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// The implicit function f(x) (position units; about the signed distance to the surface,
    /// positive on the normals' side) and its gradient ∇f (dimensionless, about unit length near
    /// the surface), after the robust refitting of the RIMLS paper's Algorithm 1: at most
    /// `max_refit` reweightings, stopping early when ∇f changes by less than `tolerance`.
    ///
    /// `None` when `x` is not finite or no point lies within `support_radius_sigma_p · σ_p` of
    /// it.
    pub fn value_and_gradient(&self, x: DVec3) -> Option<(f64, DVec3)> {
        let mut neighbours = Vec::new();
        self.evaluate(x, &mut neighbours)
    }

    /// f and ∇f at `x` with `neighbours` as scratch space.
    fn evaluate(&self, x: DVec3, neighbours: &mut Vec<(u32, f64)>) -> Option<(f64, DVec3)> {
        if !x.is_finite() {
            return None;
        }
        self.tree.within_unsorted(x, self.support_2, neighbours);
        // The spatial weights do not change between refits: replace each squared distance by
        // the Gaussian exp(-d²/σ_p²), dropping the points on or beyond the cut-off (φ <= 0).
        neighbours.retain_mut(|(_, d2)| {
            *d2 = (-*d2 * self.inv_sigma_p2).exp();
            *d2 > self.tail
        });
        if neighbours.is_empty() {
            return None;
        }
        let mut f = 0.0;
        let mut grad = DVec3::ZERO;
        for iteration in 0..=self.params.max_refit {
            let mut sum_w = 0.0;
            let mut sum_wf = 0.0;
            let mut sum_gw = DVec3::ZERO;
            let mut sum_gwf = DVec3::ZERO;
            let mut sum_wn = DVec3::ZERO;
            for &(i, gauss) in neighbours.iter() {
                let (p, n) = (self.positions[i as usize], self.normals[i as usize]);
                let phi = gauss - self.tail;
                let diff = x - p;
                let offset = diff.dot(n);
                let alpha = if iteration == 0 {
                    1.0
                } else {
                    let r = offset - f;
                    (-(r * r) * self.inv_sigma_r2 - (n - grad).length_squared() * self.inv_sigma_n2)
                        .exp()
                };
                let alpha = match self.masses.get(i as usize) {
                    Some(&mass) => alpha * mass,
                    None => alpha,
                };
                let w = alpha * phi;
                // ∇φ = -2 (x - p) / σ_p² · exp(-|x - p|²/σ_p²); the shift is a constant.
                let gw = diff * (-2.0 * self.inv_sigma_p2 * gauss * alpha);
                sum_w += w;
                sum_wf += w * offset;
                sum_gw += gw;
                sum_gwf += gw * offset;
                sum_wn += w * n;
            }
            if !(sum_w > 0.0 && sum_w.is_finite()) {
                // Every neighbour on the cut-off (first fit), or every one rejected by the
                // robust terms: keep the previous fit if there is one.
                return (iteration > 0).then_some((f, grad));
            }
            let new_f = sum_wf / sum_w;
            let new_grad = (sum_gwf - new_f * sum_gw + sum_wn) / sum_w;
            let change = (new_grad - grad).length();
            f = new_f;
            grad = new_grad;
            if iteration > 0 && change < self.params.tolerance {
                break;
            }
        }
        (f.is_finite() && grad.is_finite()).then_some((f, grad))
    }

    /// Projects `x` onto the surface by Newton steps x ← x - f(x) ∇f / |∇f|² until
    /// |f| < `tolerance · σ_p` or `max_projection_steps` steps are taken; returns the position
    /// and the unit normal ∇f/|∇f| there (the last iterate when the steps run out).
    ///
    /// ∇f is the RIMLS gradient, which holds the robust weights constant; near sharp features it
    /// can underestimate the slope of f and the Newton step overshoots. After a step across the
    /// surface (f changes sign) the step length is f divided by the secant slope measured along
    /// that step instead of by |∇f| (the direction stays ∇f), so that the projections near sharp
    /// edges converge (see `docs/decisions/rimls-projection.md`).
    ///
    /// `None` when an iterate leaves the support (no point within `support_radius_sigma_p · σ_p`),
    /// or ∇f vanishes.
    pub fn project(&self, x: DVec3) -> Option<(DVec3, DVec3)> {
        self.project_detailed(x).map(|p| (p.position, p.normal))
    }

    /// [`Rimls::project`], also saying how many steps it took and whether it converged.
    pub fn project_detailed(&self, x: DVec3) -> Option<RimlsProjection> {
        self.project_with(x, &mut Vec::new())
    }

    /// f of [`Rimls::value_and_gradient`] at every point of `xs` (`None` outside the support),
    /// in order, in parallel, reusing each thread's neighbour buffer.
    pub fn value_all(&self, xs: &[DVec3]) -> Vec<Option<f64>> {
        xs.par_iter()
            .map_init(Vec::new, |neighbours, &x| {
                self.evaluate(x, neighbours).map(|(f, _)| f)
            })
            .collect()
    }

    /// [`Rimls::project`] for every point of `xs`, in parallel (rayon); result `i` is the
    /// projection of `xs[i]`, the same whatever the number of threads.
    pub fn project_all(&self, xs: &[DVec3]) -> Vec<Option<(DVec3, DVec3)>> {
        xs.par_iter()
            .map_init(Vec::new, |neighbours, &x| {
                self.project_with(x, neighbours)
                    .map(|p| (p.position, p.normal))
            })
            .collect()
    }

    /// [`Rimls::project_detailed`] with caller-provided scratch space.
    fn project_with(&self, x: DVec3, neighbours: &mut Vec<(u32, f64)>) -> Option<RimlsProjection> {
        let threshold = self.params.tolerance * self.params.sigma_p;
        let mut position = x;
        let (mut f, mut grad) = self.evaluate(position, neighbours)?;
        // The previous f and the signed length of the step taken from it.
        let mut previous: Option<(f64, f64)> = None;
        let mut steps = 0;
        while f.abs() >= threshold && steps < self.params.max_projection_steps {
            // evaluate() returns finite values only.
            let slope = grad.length();
            if slope <= f64::MIN_POSITIVE.sqrt() {
                return None;
            }
            // ∇f holds the robust weights constant, so near features it can underestimate how
            // fast f changes and the Newton step overshoots (f changes sign, and may oscillate
            // with growing amplitude). After an overshoot the slope along the last step,
            // (f_previous - f) / step, measured by the secant, sets the step length instead.
            let slope = match previous {
                Some((f_previous, step)) if f_previous.signum() != f.signum() => {
                    let secant = (f_previous - f) / step;
                    if secant.is_finite() && secant > 0.0 {
                        secant
                    } else {
                        slope
                    }
                }
                _ => slope,
            };
            let step = f / slope;
            position -= grad * (step / grad.length());
            previous = Some((f, step));
            (f, grad) = self.evaluate(position, neighbours)?;
            steps += 1;
        }
        let normal = grad.try_normalize()?;
        Some(RimlsProjection {
            position,
            normal,
            value: f,
            steps,
            converged: f.abs() < threshold,
        })
    }
}

impl crate::surface::Projection for Rimls {
    /// [`Rimls::project`]; `face` is 0.
    fn project(&self, p: DVec3) -> Option<crate::surface::SurfaceSample> {
        Rimls::project(self, p).map(|(position, normal)| crate::surface::SurfaceSample {
            position,
            normal,
            face: 0,
        })
    }
}

/// The RIMLS surface answering the closest-point queries of the stages after the triangulation
/// (so they can fit a mesh to a point set's surface). The "closest point" is the Newton foot
/// point of [`Rimls::project`]: on the surface, along the gradient from `p`, which is the
/// closest point up to the surface's curvature over the distance (not a global search: a point
/// nearer another sheet than σ_p may go to that sheet). `face` is 0 and `barycentric` a third
/// each; `None` where the projection fails (no input point within 3 σ_p, a vanishing
/// gradient).
impl crate::surface::SurfaceQuery for Rimls {
    fn closest_point_within(&self, p: DVec3, max_dist: f64) -> Option<SurfacePoint> {
        if !p.is_finite() {
            return None;
        }
        let (position, _) = Rimls::project(self, p)?;
        let distance = position.distance(p);
        (distance <= max_dist).then_some(SurfacePoint {
            position,
            face: 0,
            barycentric: [1.0 / 3.0; 3],
            distance,
        })
    }

    /// ∇f / |∇f| at the point (zero where the gradient vanishes or the point is outside the
    /// support).
    fn smooth_normal(&self, sp: &SurfacePoint) -> DVec3 {
        self.value_and_gradient(sp.position)
            .map_or(DVec3::ZERO, |(_, g)| g.normalize_or_zero())
    }
}

#[cfg(test)]
mod tests;
