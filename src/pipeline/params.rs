//! The parameters of [`remesh`](super::remesh) and the density they ask for.

use crate::error::{Error, Result};
use crate::finish::optimize::OptimizeParams;
use crate::finish::refine::RefineCrossingsParams;
use crate::finish::untangle::UntangleParams;
use crate::kernel::Kernel;
use crate::mesh::TriMesh;
use crate::sampling::gradient_ascent::GradientAscentParams;
use crate::sampling::grading::GradingParams;
use crate::sampling::linear_scan::LinearScanParams;
use crate::surface::curvature::CurvatureParams;
use crate::surface::features::FeatureDetection;
use crate::triangulate::{TriangulateParams, TriangulationMethod};

/// How dense the output is: a vertex count, or sigma_p directly.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Density {
    /// About this many output vertices (sigma_p is searched for; Sec. 6.3 and the `--points`
    /// option).
    Points(usize),
    /// This sigma_p, bbox-100 units.
    SigmaP(f64),
    /// As many output vertices as the input has vertices (the command line's default).
    InputVertices,
    /// Output edges about this long, model units: the count of equilateral triangles of this
    /// edge on the input's area, 2 A / (√3 L²), then as for `Points`; for a point set (whose
    /// area is known only once its surface is) sigma_p = L / 1.2 in bbox-100 units
    /// (`sampling::spacing::POINT_SET_EDGE_PER_SIGMA`).
    EdgeLength(f64),
}

/// The vertex count of a mesh of equilateral triangles of edge `length` on area `area` (both
/// in the same units): 2 A / (√3 L²), a vertex per two triangles; at least 4.
pub fn points_for_edge_length(area: f64, length: f64) -> usize {
    (2.0 * area / (3f64.sqrt() * length * length))
        .round()
        .clamp(4.0, 1e15) as usize
}

/// The iterations of the least-squares fit, by default: the RMS distance is within 2% of its
/// limit after 3 (`docs/decisions/fit-iterations.md`).
pub const FIT_ITERATIONS: usize = 3;

/// The most output points [`remesh`](super::remesh) takes: 20 million (with 10 candidates per
/// sample the pool holds 2e8 points, about 11 GB).
pub const MAX_POINTS: usize = 20_000_000;

/// Parameters of [`remesh`](super::remesh). `Default`: 10,000 output vertices and the command
/// line's other defaults (the command line's own density, without `--points`, is the input's
/// vertex count, [`Density::InputVertices`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RemeshParams {
    /// Output density.
    pub density: Density,
    /// sigma_n (bbox-100 units of the normal part; infinity = isotropic sampling).
    pub sigma_n: f64,
    /// Candidates per expected output sample in the linear scan's pool (default 10).
    pub candidates_per_sample: f64,
    /// The linear scan.
    pub linear_scan: LinearScanParams,
    /// The gradient ascent.
    pub gradient_ascent: GradientAscentParams,
    /// The triangulation: where its candidate triangles come from.
    pub triangulation: TriangulationMethod,
    /// The triangulation's local step (umbrellas only) and assembly.
    pub triangulate: TriangulateParams,
    /// The local optimization against the input surface after triangulation (`None`: skipped).
    pub optimize: Option<OptimizeParams>,
    /// The separation of crossing faces, last.
    pub untangle: UntangleParams,
    /// Where the output's own crossings are left after that: the refinement of the crossing
    /// faces, untangle again after each round (`max_rounds` 0: none). Meshes only: on a point
    /// set the faces that still cross are removed instead.
    pub refine: RefineCrossingsParams,
    /// The sizing field from the local feature size (`sampling::grading`, meshes only; the
    /// command line's `--lfs-factor`). `None`, the default: one sigma_p everywhere, as in the
    /// paper. Not yet the default: on the shared models it grades nothing at the eval counts,
    /// and where it grades, the wedges at kept creases and the points where sheets touch (a local
    /// feature size of 0) cost crease edges and parts (`docs/decisions/sizing-field.md`).
    pub grading: Option<GradingParams>,
    /// Sample density graded by curvature (`None`, the default: one sigma_p everywhere).
    pub curvature: Option<CurvatureParams>,
    /// Iterations of the least-squares fit of the output's vertices to the input along their
    /// normals ([`fit_to_surface`](crate::internal::fit_to_surface); default [`FIT_ITERATIONS`]; 0:
    /// the vertices stay on the input, as in the paper, and the command line's `--no-fit`).
    pub fit_iterations: usize,
    /// The sharp-feature detection ([`detect_features`](crate::internal::detect_features), at the
    /// sample spacing of the first sigma_p): the creases found are sampled evenly along with the
    /// boundary (`sampling::features::feature_pieces`), kept fixed, and their consecutive samples
    /// reported as output edges. Default [`FeatureDetection::Auto`]: at
    /// [`CAD_FEATURE_ANGLE_DEG`](crate::internal::CAD_FEATURE_ANGLE_DEG), kept when the creases are
    /// a part's (long curves), left out on a scan.
    pub features: FeatureDetection,
    /// Times at most the sampling runs again with a finer spacing around the samples the
    /// triangulation inserted for the topological ball property, when they take the count out
    /// of its tolerance on an input without non-manifold edges or crossing faces
    /// (default 1: on ADIS16480 at 3000 points 0 left the property failing at 6 pairs of
    /// cells after 24 rounds, 1 kept the genus, 2 took 40 s instead of 30; 0: the inserted
    /// samples are kept as they are).
    pub topology_refinements: usize,
    /// Relative tolerance of the count search (default 0.005).
    pub count_tolerance: f64,
    /// Seed of every random choice.
    pub seed: u64,
}

impl Default for RemeshParams {
    fn default() -> Self {
        RemeshParams {
            density: Density::Points(10_000),
            sigma_n: f64::INFINITY,
            candidates_per_sample: 10.0,
            linear_scan: LinearScanParams::default(),
            gradient_ascent: GradientAscentParams::default(),
            triangulation: TriangulationMethod::default(),
            triangulate: TriangulateParams::default(),
            optimize: Some(OptimizeParams::default()),
            untangle: UntangleParams::default(),
            refine: RefineCrossingsParams::default(),
            grading: None,
            curvature: None,
            fit_iterations: FIT_ITERATIONS,
            features: FeatureDetection::Auto,
            topology_refinements: 1,
            count_tolerance: 0.005,
            seed: 1,
        }
    }
}

/// [`Density`] resolved for one input: a vertex count or sigma_p.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Target {
    Points(usize),
    SigmaP(f64),
}

/// Checks an asked count of output points: 4 to [`MAX_POINTS`], for a mesh or a point set.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `points`.
pub(crate) fn check_count(n: usize) -> Result<()> {
    if n < 4 {
        return Err(Error::InvalidParameter {
            name: "points",
            message: format!("at least 4 points are needed for a closed surface, got {n}"),
        });
    }
    if n > MAX_POINTS {
        return Err(Error::InvalidParameter {
            name: "points",
            message: format!(
                "{n} is more than the {MAX_POINTS} points this remesher holds in memory; \
                 for larger point sets use `remesh simplify`"
            ),
        });
    }
    Ok(())
}

impl Target {
    /// The density `params` ask of `input`, checked: a count of 4 to [`MAX_POINTS`], a positive
    /// finite sigma_p, and a valid sigma_n.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the parameter.
    pub(super) fn of(params: &RemeshParams, input: &TriMesh) -> Result<Target> {
        let target = match params.density {
            Density::Points(n) => Target::Points(n),
            Density::SigmaP(s) => Target::SigmaP(s),
            Density::InputVertices => Target::Points(input.vertex_count()),
            Density::EdgeLength(l) if !(l.is_finite() && l > 0.0) => {
                return Err(Error::InvalidParameter {
                    name: "edge_length",
                    message: format!("must be a positive number, got {}", crate::error::shown(l)),
                })
            }
            Density::EdgeLength(l) => Target::Points(points_for_edge_length(input.area(), l)),
        };
        match target {
            Target::Points(n) => check_count(n)?,
            Target::SigmaP(s) if !(s.is_finite() && s > 0.0) => {
                return Err(Error::InvalidParameter {
                    name: "sigma_p",
                    message: format!("must be a positive number, got {}", crate::error::shown(s)),
                })
            }
            _ => {}
        }
        // Validate sigma_n early.
        Kernel::new(1.0, params.sigma_n)?;
        Ok(target)
    }

    /// The asked count, if one was asked for.
    pub(super) fn count(self) -> Option<usize> {
        match self {
            Target::Points(n) => Some(n),
            Target::SigmaP(_) => None,
        }
    }

    /// The parameter and the value asked, for an error message: with a count, `goal` points.
    pub(super) fn named(self, goal: usize) -> (&'static str, String) {
        match self {
            Target::Points(_) => ("points", format!("{goal} points")),
            Target::SigmaP(s) => ("sigma_p", format!("sigma_p {s}")),
        }
    }
}
