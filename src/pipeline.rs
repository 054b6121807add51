//! The remeshing pipeline: normalize (bbox 100) and orient consistently → candidates → linear scan (with the sigma_p
//! search for a target count) → gradient ascent + projection → triangulate → clean up → back to
//! model units.

use std::borrow::Cow;

use glam::DVec3;
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::geometry::self_intersection::{intersecting_pairs, CrossingRegions};
use crate::geometry::tolerance::{DEGENERATE_AREA_TOLERANCE, ON_SURFACE_RELATIVE};
use crate::kernel::Kernel;
use crate::mesh::edit::{EditMesh, SlotPolicy};
use crate::mesh::sheets::Sheets;
use crate::mesh::{orient_consistently, Normalization, OrientStats, TriMesh};
use crate::sampling::boundary::{
    boundary_curves, boundary_sample_count, curve_length, sample_curves_and_features,
};
use crate::sampling::candidates::surface_candidates;
use crate::sampling::crease_band::CreaseBand;
use crate::sampling::features::{corner_width, feature_pieces, graded_corners, GradedCorner};
use crate::sampling::gradient_ascent::{
    gradient_ascent_graded, GradientAscentParams, GradientAscentResult,
};
use crate::sampling::grading::{Grading, GradingParams, GradingStats};
use crate::sampling::linear_scan::{
    linear_scan, linear_scan_graded, LinearScanParams, LinearScanResult,
};
use crate::sampling::target_count::{find_sigma_p, TargetCountParams};
use crate::sampling::WidthField;
use crate::surface::curvature::{Curvature, CurvatureParams, CurvatureWidths};
use crate::surface::feature_lines::FeatureLines;
use crate::surface::features::{
    detect_features, long_curve_share, FeatureDetection, FeatureParams, Features,
    AUTO_FEATURE_MIN_SHARE,
};
use crate::surface::winding::BuriedTest;
use crate::surface::MeshSurface;
use crate::surface::SurfaceSample;
pub use crate::timing::Stage;
use crate::timing::StageTimer;
use crate::triangulate::degenerate::mend_degenerate_faces;
use crate::triangulate::optimize::{optimize, OptimizeParams, OptimizeStats};
use crate::triangulate::recover::{close_slits, flip_crease_slivers, recover_edges, RecoverStats};
use crate::triangulate::stray_shells::{remove_stray_shells, StrayShells};
use crate::triangulate::untangle::{untangle, UntangleParams, UntangleStats};
use crate::triangulate::{
    triangulate, triangulate_restricted, AssemblyStats, FaceSource, SampleSet, TriangulateParams,
    TriangulationMethod,
};

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
}

/// A linear scan's result with the edges between its fixed curve samples: boundary edges, then
/// feature edges.
type ScanWithBoundary = (
    LinearScanResult,
    Vec<[u32; 2]>,
    Vec<[u32; 2]>,
    Vec<GradedCorner>,
);

/// [`Density`] resolved for one input: a vertex count or sigma_p.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Target {
    Points(usize),
    SigmaP(f64),
}

/// Output samples per unit of sigma_p^-2 area: a linear scan with epsilon = 0.5 followed by
/// gradient ascent leaves about `SAMPLES_PER_SIGMA2 · A / sigma_p^2` samples on a surface of area
/// A. Measured on the shared models (horse, spot, fandisk); used for the first guess of the
/// sigma_p search and to size the candidate pool when sigma_p is given.
pub const SAMPLES_PER_SIGMA2: f64 = 1.0;

/// Spacing of the boundary samples in units of sigma_p: the mean edge length the interior
/// sampling reaches (measured), so boundary triangles match interior ones.
pub const BOUNDARY_SPACING_PER_SIGMA: f64 = 1.0;

/// Spacing of the crease samples in units of sigma_p: the median edge length of the output
/// away from the creases (measured: fandisk 6000, 2.04 for sigma_p 1.77, so 1.15), so the
/// triangles along a crease are as large as the others. At 1.0 (the boundary's), the faces on a
/// crease edge stood 1.04 of its length tall (0.87 is equilateral) and their mean Q was 0.84
/// against 0.90 elsewhere; at 1.15, 0.88 tall and Q 0.88 (fandisk Qave 0.884 → 0.894, seeds
/// 1–2).
pub const FEATURE_SPACING_PER_SIGMA: f64 = 1.15;

/// The samples a surface of area `area` with boundary curves `boundary_length` long (bbox-100
/// units) is expected to get at `sigma_p`: `SAMPLES_PER_SIGMA2 · A / sigma_p²` inside and one
/// per `BOUNDARY_SPACING_PER_SIGMA · sigma_p` along the boundary.
pub fn expected_samples(area: f64, boundary_length: f64, sigma_p: f64) -> f64 {
    SAMPLES_PER_SIGMA2 * area / (sigma_p * sigma_p)
        + boundary_length / (BOUNDARY_SPACING_PER_SIGMA * sigma_p)
}

/// The first guess of the sigma_p search for `count` samples (bbox-100 units): the larger of
/// the sigma_p at which the area alone (`sqrt(SAMPLES_PER_SIGMA2 · A / count)`) and the boundary
/// curves alone (`L / (BOUNDARY_SPACING_PER_SIGMA · count)`) give `count`. Each term of
/// [`expected_samples`] alone is at most `count` there, so the expected count at the guess is
/// between `count` and `2 · count`, however long the boundary is for the area (a sliver, a
/// needle): from the area alone the guess would be far too small there, and the boundary
/// samples alone many times the target. On a surface whose area term dominates (every closed
/// one) it is the area-only guess.
pub fn sigma_p_for_count(area: f64, boundary_length: f64, count: f64) -> f64 {
    let from_area = (SAMPLES_PER_SIGMA2 * area / count).sqrt();
    let from_boundary = boundary_length / (BOUNDARY_SPACING_PER_SIGMA * count);
    from_area.max(from_boundary)
}

/// The most points the local feature size is estimated at for the grading (their spacing is
/// about the expected samples' otherwise).
const MAX_GRADING_POINTS: f64 = 200_000.0;

/// The most vertices of a shell [`remove_stray_shells`] removes: a few samples closing on
/// themselves at a tip (4 make a tetrahedron), not a part of the surface.
pub(crate) const STRAY_SHELL_VERTICES: usize = 8;

/// The iterations of the least-squares fit, by default: the RMS distance is within 2% of its
/// limit after 3 (flange at 6000 with --feature-angle 20: 0.0158 unfitted, 0.0090 after 1, 0.0089
/// after 3 and 5).
pub const FIT_ITERATIONS: usize = 3;

/// The most output points [`remesh`] takes: 20 million (with 10 candidates per sample the
/// pool holds 2e8 points, about 11 GB).
pub const MAX_POINTS: usize = 20_000_000;

/// Parameters of [`remesh`]. `Default` is the command line's default.
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
    /// Sample density graded by the local feature size (issue 15; `None`, the default: one
    /// sigma_p everywhere, as in the paper). Not yet the default: on horse at 8600 it raises the
    /// Hausdorff distance (median of seeds 1-5 from 0.449 to 0.508, at the ears) although it
    /// keeps the topology of thin parts at low counts.
    pub grading: Option<GradingParams>,
    /// Sample density graded by curvature (`None`, the default: one sigma_p everywhere).
    pub curvature: Option<CurvatureParams>,
    /// Iterations of the least-squares fit of the output's vertices to the input along their
    /// normals ([`fit_to_surface`](crate::fit_to_surface); default [`FIT_ITERATIONS`]; 0: the
    /// vertices stay on the input, as in the paper, and the command line's `--no-fit`).
    pub fit_iterations: usize,
    /// The sharp-feature detection ([`detect_features`], at the sample spacing of the first
    /// sigma_p): the creases found are sampled evenly along with the boundary
    /// (`sampling::features::feature_pieces`), kept fixed, and their consecutive samples
    /// reported as output edges. Default [`FeatureDetection::Auto`]: at
    /// [`CAD_FEATURE_ANGLE_DEG`](crate::CAD_FEATURE_ANGLE_DEG), kept when the creases are a
    /// part's (long curves), left out on a scan.
    pub features: FeatureDetection,
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
            grading: None,
            curvature: None,
            fit_iterations: FIT_ITERATIONS,
            features: FeatureDetection::Auto,
            count_tolerance: 0.005,
            seed: 1,
        }
    }
}

/// The sources of the faces of an edited mesh: a face that is still face `f` of the mesh before
/// (`origin`, as `EditMesh::into_parts` gives it) keeps `sources[f]`; a new or changed one is
/// `Refined`.
fn carried_sources(origin: &[Option<u32>], sources: &[FaceSource]) -> Vec<FaceSource> {
    origin
        .iter()
        .map(|o| o.map_or(FaceSource::Refined, |f| sources[f as usize]))
        .collect()
}

/// How many of `edges` (vertex pairs, either direction) are edges of a face of `mesh`.
fn edges_present(mesh: &TriMesh, edges: &[[u32; 2]]) -> usize {
    let mut have: rustc_hash::FxHashSet<(u32, u32)> = rustc_hash::FxHashSet::default();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            have.insert((a.min(b), a.max(b)));
        }
    }
    edges
        .iter()
        .filter(|e| have.contains(&(e[0].min(e[1]), e[0].max(e[1]))))
        .count()
}

/// The sharp features [`remesh`] found on its input ([`detect_features`]). Lengths in bbox-100
/// units.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FeatureStats {
    /// The feature angle, degrees.
    pub angle_deg: f64,
    /// With automatic detection ([`FeatureDetection::Auto`]): whether the creases found were
    /// kept (`false`: a scan's folds, left out; the counts below are what was found).
    pub automatic: Option<bool>,
    /// The share of the creases' length in curves at least
    /// [`LONG_CURVE_SPACINGS`](crate::LONG_CURVE_SPACINGS) spacings long
    /// ([`long_curve_share`]).
    pub long_curve_share: f64,
    /// The scale the creases were tested at (the sample spacing of the first sigma_p).
    pub scale: f64,
    /// Feature edges of the input.
    pub edges: usize,
    /// Curves they chain into.
    pub curves: usize,
    /// Of those, closed ones (without a corner).
    pub closed_curves: usize,
    /// Corners (ends of the open curves).
    pub corners: usize,
    /// Total length of the feature edges.
    pub length: f64,
    /// Edges between consecutive samples along the sampled feature curves.
    pub sampled_edges: usize,
    /// Of those, edges of the triangulation.
    pub triangulated_edges: usize,
    /// Of the sampled edges the triangulation left out, those put in afterwards
    /// (`triangulate::recover::recover_edges`).
    pub recovered_edges: usize,
    /// Of the sampled edges, edges of the output (after the optimization).
    pub kept_edges: usize,
    /// How far the detected creases (all of them, sampled or not) are from the output's edges
    /// ([`crease_distance`](crate::check::crease_distance), points every sigma_p / 4; bbox-100
    /// units); `None` without creases.
    pub crease_distance: Option<crate::check::CreaseDistance>,
}

/// The output of [`remesh`].
#[derive(Debug, Clone)]
pub struct RemeshOutput {
    /// The remeshed surface in model units.
    pub mesh: TriMesh,
    /// The same in bbox-100 units.
    pub mesh_normalized: TriMesh,
    /// The input in bbox-100 units, oriented consistently (see `orientation`).
    pub input_normalized: TriMesh,
    /// What orienting the input consistently did ([`orient_consistently`] without turning
    /// closed parts outward: faces flipped, non-orientable components).
    pub orientation: OrientStats,
    /// What orienting the output did ([`orient_consistently`] turning closed parts outward:
    /// the output follows the input's orientation, so this turns the output of an inward-facing
    /// closed input outward).
    pub output_orientation: OrientStats,
    /// Model units ↔ bbox-100 units.
    pub normalization: Normalization,
    /// The sigma_p used (bbox-100 units).
    pub sigma_p: f64,
    /// The target count, when one was asked for.
    pub target: Option<usize>,
    /// Whether the sample count of the search came within its tolerance of the target.
    pub target_reached: bool,
    /// The search's evaluations as (sigma_p, samples).
    pub search_history: Vec<(f64, usize)>,
    /// Samples produced by the sampler (before triangulation).
    pub samples: usize,
    /// Of those, samples on the input's boundary curves.
    pub boundary_samples: usize,
    /// Size of the candidate pool.
    pub candidates: usize,
    /// The final linear scan's statistics.
    pub rejected_by_nearest: usize,
    /// Candidates whose measure was evaluated.
    pub measured: usize,
    /// The gradient ascent's convergence record.
    pub gradient_ascent: GradientAscentResult,
    /// The triangulation's statistics.
    pub assembly: AssemblyStats,
    /// What the local optimization did.
    pub optimize: OptimizeStats,
    /// What the separation of crossing faces did.
    pub untangle: UntangleStats,
    /// What the mending of faces of no area did.
    pub degenerate: crate::triangulate::degenerate::DegenerateStats,
    /// The pairs of `input_normalized`'s faces that cross (looked for only when the input
    /// passes through itself), as [`intersecting_pairs`] gives them.
    pub input_crossing_pairs: Vec<[u32; 2]>,
    /// The faces of `input_normalized` where closed parts meet at a non-manifold edge (the
    /// junction of `mesh::sheets::Sheets`). With `input_crossing_pairs`, what
    /// [`CrossingRegions`] are built from: where the output's crossings are the input's own.
    pub junction_faces: Vec<u32>,
    /// What the least-squares fit to the input did (`None` when it was off).
    pub fit: Option<crate::triangulate::fit::FitStats>,
    /// How each face of `mesh` came in.
    pub face_sources: Vec<crate::triangulate::FaceSource>,
    /// What the restricted Delaunay triangulation did; `None` when the umbrellas made the
    /// triangles (asked for, the input's refinement would have been too large, or it gave no
    /// triangle).
    pub restricted_delaunay: Option<crate::triangulate::RestrictedDelaunayStats>,
    /// Samples that ended in no triangle and were dropped.
    pub dropped_samples: usize,
    /// Candidates left out as buried inside the input's own solid (a self-intersecting input;
    /// [`BuriedTest`]).
    pub buried_candidates: usize,
    /// Samples the gradient ascent moved onto the buried part of a face, put back where the
    /// scan put them.
    pub buried_samples: usize,
    /// What the grading by the local feature size did (`None` when it was off).
    pub grading: Option<GradingStats>,
    /// The sharp features detected on the input (see [`RemeshParams::features`]).
    pub features: FeatureStats,
    /// Tiny closed shells at unresolved tips removed (bbox-100 units).
    pub stray_shells: StrayShells,
    /// Timed stages in order.
    pub stages: Vec<Stage>,
}

/// Checks `mesh` and returns its normalization to bbox 100.
///
/// # Errors
/// [`Error::InvalidMesh`] for no faces, an index out of range, a non-finite coordinate, or a
/// bounding box of zero size or one too small or too large to scale to bbox 100 (the message
/// gives its size).
pub fn validate_input(mesh: &TriMesh) -> Result<Normalization> {
    if mesh.triangles.is_empty() {
        return Err(Error::invalid_mesh("", "the mesh has no faces"));
    }
    mesh.check_geometry()?;
    let bbox = mesh
        .bbox()
        .ok_or_else(|| Error::invalid_mesh("", "the mesh has no vertices"))?;
    Normalization::for_bbox(&bbox)
        .ok_or_else(|| Error::invalid_mesh("", Normalization::refusal(&bbox)))
}

/// Remeshes `input` (model units): samples its surface with the spectral sampler and
/// triangulates the samples. `on_stage` is called with each stage's name as it starts (for
/// progress display).
///
/// # Errors
/// [`Error::InvalidMesh`] for an unusable input (see [`validate_input`]);
/// [`Error::InvalidParameter`] for a density or sigma out of range.
pub fn remesh(
    input: &TriMesh,
    params: &RemeshParams,
    on_stage: &(dyn Fn(&str) + Sync),
) -> Result<RemeshOutput> {
    let mut timer = StageTimer::new();
    let normalization = validate_input(input)?;
    let density = match params.density {
        Density::Points(n) => Target::Points(n),
        Density::SigmaP(s) => Target::SigmaP(s),
        Density::InputVertices => Target::Points(input.vertex_count()),
    };
    match density {
        Target::Points(n) if n < 4 => {
            return Err(Error::InvalidParameter {
                name: "--points",
                message: format!("at least 4 points are needed for a closed surface, got {n}"),
            })
        }
        Target::Points(n) if n > MAX_POINTS => {
            return Err(Error::InvalidParameter {
                name: "--points",
                message: format!("{n} is more than the {MAX_POINTS} points this remesher holds in memory; for larger point sets use `remesh simplify`"),
            })
        }
        Target::SigmaP(s) if !(s.is_finite() && s > 0.0) => {
            return Err(Error::InvalidParameter {
                name: "--sigma-p",
                message: format!("must be a positive number, got {}", crate::error::shown(s)),
            })
        }
        _ => {}
    }
    // Validate sigma_n early.
    Kernel::new(1.0, params.sigma_n)?;
    on_stage("normalize");
    let as_read = normalization.apply_mesh(input);
    let mut normalized = as_read.clone();
    // Every later stage takes the faces' orientation at face value (normals, tangent planes,
    // the triangulation's orientation): the input is oriented consistently first. Its closed
    // parts are turned outward on the output instead (below): the sampling does not depend on
    // which way a consistent input faces, but the projections' rounding does, so an inward
    // input that is otherwise fine (horse) keeps its output and only the orientation changes.
    let orientation = orient_consistently(&mut normalized, false);
    let area = normalized.area();
    let curves = boundary_curves(&normalized);
    let curve_lengths: Vec<f64> = curves
        .iter()
        .map(|c| curve_length(&normalized, c))
        .collect();
    let boundary_length: f64 = curve_lengths.iter().sum();
    // The boundary curves as segments, which the last pass of the optimization slides boundary
    // vertices along.
    let boundary_lines = FeatureLines::new(
        &normalized.positions,
        curves.iter().flat_map(|c| {
            let n = c.vertices.len();
            let edges = if c.closed { n } else { n.saturating_sub(1) };
            (0..edges).map(move |k| [c.vertices[k], c.vertices[(k + 1) % n]])
        }),
    );
    // A surface thinner everywhere than the zero-area test's tolerance of its own length (a
    // strip of colinear faces, a needle): every triangle on it would be degenerate, and sampling
    // its boundary curves at a spacing its area suggests would take without bound.
    if area <= DEGENERATE_AREA_TOLERANCE * boundary_length * boundary_length {
        return Err(Error::invalid_mesh(
            "",
            format!(
                "the surface has almost no area ({area:.1e}) but boundary curves \
                 {boundary_length:.3} long (bbox-100 units): its faces are (nearly) colinear, so \
                 every triangle on it would be degenerate"
            ),
        ));
    }
    // Candidates are drawn for the samples expected inside the surface.
    let expected = match density {
        Target::Points(n) => n as f64,
        Target::SigmaP(s) => SAMPLES_PER_SIGMA2 * area / (s * s),
    };
    if let Target::SigmaP(s) = density {
        // The same bound as --points: the candidate pool and the samples, those on the boundary
        // curves included, must fit in memory.
        let expected = expected_samples(area, boundary_length, s);
        if !(expected <= MAX_POINTS as f64) {
            // The positive root of expected_samples(s) = MAX_POINTS.
            let (n, a) = (MAX_POINTS as f64, SAMPLES_PER_SIGMA2 * area);
            let b = boundary_length / BOUNDARY_SPACING_PER_SIGMA;
            let smallest = (b + (b * b + 4.0 * n * a).sqrt()) / (2.0 * n);
            return Err(Error::InvalidParameter {
                name: "--sigma-p",
                message: format!(
                    "sigma_p {} would give {} samples on this surface, more than the \
                     {MAX_POINTS} this remesher holds in memory; the smallest sigma_p it takes \
                     here is {smallest:.4} (bbox-100 units)",
                    crate::error::shown(s),
                    if expected.is_finite() {
                        format!("about {expected:.2e}")
                    } else {
                        "too many".to_string()
                    }
                ),
            });
        }
    }
    let pool_size = (params.candidates_per_sample * expected)
        .ceil()
        .clamp(16.0, 2e8) as usize;
    // The search structure of the surface, and beside it (for an input that passes through
    // itself) the test for the points buried inside the input's own solid: each builds a BVH of
    // the input's faces on one thread.
    let (surface, buried_test) = rayon::join(
        || MeshSurface::new(&normalized),
        || BuriedTest::new(&normalized, 2 * pool_size + normalized.positions.len()),
    );
    let surface = surface?;
    // Where the input's own faces cross (only looked for when it passes through itself): the
    // finishing stage leaves the output's crossings there alone.
    let input_crossing_pairs = match &buried_test {
        Some(_) => intersecting_pairs(&normalized.positions, &normalized.triangles),
        None => Vec::new(),
    };
    // Where parts of the input meet at non-manifold edges (the triangulation keeps them apart).
    let sheets = Sheets::new(&normalized);
    let junction_faces = sheets.junction_faces(&normalized);
    timer.lap("normalize");

    on_stage("candidates");
    // The candidates are drawn on the faces as read, and a reversed face's candidates take its
    // reversed normal: orienting the input changes the sign of normals, not where points land
    // (the draw depends on a face's corner order), so it changes the output's orientation and
    // nothing else of the sampling.
    let mut pool = surface_candidates(&as_read, pool_size, params.seed);
    if orientation.faces_flipped > 0 {
        for c in &mut pool {
            if normalized.triangles[c.face as usize] != as_read.triangles[c.face as usize] {
                c.normal = -c.normal;
            }
        }
    }
    drop(as_read);
    // Where the input passes through itself, the candidates inside its own solid are left out
    // (and samples the gradient ascent moves there are put back): the output follows the outer
    // surface and does not cross itself there.
    let mut buried_candidates = 0;
    let mut input_points: Vec<DVec3> = normalized.positions.clone();
    if let Some(test) = &buried_test {
        buried_candidates = test.remove_buried(&mut pool, |c| (c.position, c.normal, Some(c.face)));
        let mut vertices = BuriedTest::vertex_points(&normalized);
        test.remove_buried(&mut vertices, |&v| v);
        input_points = vertices.into_iter().map(|(p, _, _)| p).collect();
    }
    // Input-surface points the optimization keeps within its cover distance of the output.
    let cover_points: Vec<DVec3> = input_points
        .iter()
        .copied()
        .chain(pool.iter().map(|c| c.position))
        .collect();
    timer.lap("candidates");

    // The local feature size, for the grading of the kernel width: estimated up to a few times
    // the largest width the search is expected to try (a part thicker than that is not graded).
    // The search's first sigma_p (the given one for --sigma-p).
    let first_sigma_p = match density {
        Target::Points(n) => sigma_p_for_count(area, boundary_length, n as f64),
        Target::SigmaP(s) => s,
    };
    // Sharp features: creases that stay sharp at the sample spacing.
    on_stage("features");
    let feature_scale = first_sigma_p / SAMPLES_PER_SIGMA2.sqrt();
    let mut features = detect_features(
        &surface,
        &FeatureParams {
            angle_deg: params.features.angle_deg(),
            scale: feature_scale,
        },
    );
    let long_share = long_curve_share(&features, &normalized.positions, feature_scale);
    // Automatic detection keeps a part's creases and leaves a scan's folds out.
    let auto_kept =
        (params.features == FeatureDetection::Auto).then_some(long_share >= AUTO_FEATURE_MIN_SHARE);
    let found = (
        features.edges.len(),
        features.curves.len(),
        features.corners.len(),
    );
    let found_closed = features.curves.iter().filter(|c| c.closed).count();
    let found_length = features.length(&normalized.positions);
    if auto_kept == Some(false) {
        features = Features::default();
    }
    let feature_stats = FeatureStats {
        angle_deg: params.features.angle_deg(),
        automatic: auto_kept,
        long_curve_share: long_share,
        scale: feature_scale,
        edges: found.0,
        curves: found.1,
        closed_curves: found_closed,
        corners: found.2,
        length: found_length,
        sampled_edges: 0,
        triangulated_edges: 0,
        recovered_edges: 0,
        kept_edges: 0,
        crease_distance: None,
    };
    timer.lap("features");
    let curvature = params.curvature.map(|p| (Curvature::new(&surface, &[]), p));
    let grading = match params.grading {
        Some(g) => {
            on_stage("local feature size");
            let cap = 1.5 * first_sigma_p / g.lfs_factor;
            // Estimate points every first_sigma_p (about one per expected sample), at most
            // MAX_GRADING_POINTS of them.
            let spacing = first_sigma_p.max((area / MAX_GRADING_POINTS).sqrt());
            let grading = Grading::new(&normalized, &curves, g, cap, spacing)?;
            timer.lap("local feature size");
            Some(grading)
        }
        None => None,
    };
    // The input's component count, which the stray-shell pass (grading only) brings the output
    // back to.
    let input_components = grading
        .as_ref()
        .map_or(0, |_| crate::check::topology(&normalized).components);

    // The sampler's count is searched for; the triangulation may set a few samples aside (at
    // parts thinner than the sampling), so when the output's vertex count misses the target by
    // more than the search tolerance, the search runs again for a target raised by the
    // shortfall, once: the retry's miss is how closely the count can be aimed on this input, and
    // a second retry aims no closer, at the cost of a third run.
    let mut goal = match density {
        Target::Points(n) => n,
        Target::SigmaP(_) => 0,
    };
    let mut start = first_sigma_p;
    let mut full_history = Vec::new();
    let mut attempt = 0;
    // The sigma_p the grading's widths are taken for (see the search).
    let mut sigma_ref = start;
    let output = loop {
        on_stage("linear scan");
        // The boundary samples of one evaluation are bounded: a sigma_p whose boundary curves
        // alone take more than four times the target (or more than the memory bound) is far
        // from the answer, and its count is reported without sampling (None: skipped). The
        // count is a lower bound of the scan's, so the search still moves the right way.
        let boundary_limit = match density {
            Target::Points(_) => (4.0 * goal as f64).clamp(64.0, MAX_POINTS as f64),
            Target::SigmaP(_) => MAX_POINTS as f64,
        };
        // With grading, the widths are those for sigma_ref (held fixed through a search, so the
        // count falls like sigma_p^-2 as without grading; see the search below).
        // The candidates' widths for one sigma_ref, taken once for a round's evaluations.
        let pool_widths =
            |w: &Widths| -> Vec<f64> { pool.par_iter().map(|c| w.width(c.position)).collect() };
        let widths_at = |sigma_ref: f64| Widths {
            grading: grading.as_ref(),
            curvature: curvature.as_ref().map(|(c, p)| {
                CurvatureWidths::new(c, &pool, sigma_ref, p.chord_error, p.min_width)
            }),
            sigma_ref,
        };
        // The creases' total length (the curves the scan samples besides the boundary).
        let crease_length: f64 = features
            .curves
            .iter()
            .map(|c| c.length(&normalized.positions))
            .sum();
        let scan = |sigma_p: f64,
                    widths: &Widths,
                    pool_widths: Option<&[f64]>|
         -> Result<(usize, Option<ScanWithBoundary>)> {
            let kernel = Kernel::new(sigma_p, params.sigma_n)?;
            let spacing = BOUNDARY_SPACING_PER_SIGMA * sigma_p;
            let feature_spacing = FEATURE_SPACING_PER_SIGMA * sigma_p;
            // The curves' samples from their lengths, before any is placed: a sigma_p whose
            // curves would take four times the limit is answered without placing them (a crease
            // of 10^8 spacings, a sliver's edge at a tiny sigma_p, filled the memory before the
            // count below was reached). Four times: creases crowded out by others take no
            // samples, so the count below can be lower than this one, not that much lower.
            let least = boundary_length / spacing + crease_length / feature_spacing;
            if !(least <= 4.0 * boundary_limit) {
                return Ok((least.min(usize::MAX as f64) as usize, None));
            }
            // The boundary curves, cut where creases end on them, and the creases long enough
            // to take samples at their spacing.
            let width = widths.active().then_some(|p: DVec3| widths.width(p));
            let (boundary_pieces, feature_curves) = feature_pieces(
                &normalized,
                &curves,
                &features,
                feature_spacing,
                width.as_ref().map(|f| f as WidthField),
            );
            let boundary_count = boundary_sample_count(&normalized, &boundary_pieces, spacing)
                + boundary_sample_count(
                    &normalized,
                    feature_curves.iter().map(|f| &f.curve),
                    feature_spacing,
                );
            if !(boundary_count <= boundary_limit) {
                return Ok((boundary_count.min(usize::MAX as f64) as usize, None));
            }
            // Around a corner that creases are graded towards, the other curves and the surface
            // samples are graded too (corner_width).
            let corners = graded_corners(&normalized, &feature_curves, feature_spacing);
            let graded = widths.active() || !corners.is_empty();
            let w = |p: DVec3| widths.at(p, &corners, feature_spacing);
            let field: Option<WidthField> = graded.then_some(&w);
            let b = sample_curves_and_features(
                &normalized,
                &boundary_pieces,
                &feature_curves,
                spacing,
                feature_spacing,
                field,
            );
            let r = if graded {
                // The candidates' widths: the round's, lowered around the graded corners.
                let pool_w: Option<Cow<[f64]>> = if corners.is_empty() {
                    pool_widths.map(Cow::Borrowed)
                } else {
                    Some(Cow::Owned(
                        pool.par_iter()
                            .enumerate()
                            .map(|(i, c)| {
                                pool_widths.map_or(1.0, |pw| pw[i]).min(corner_width(
                                    &corners,
                                    c.position,
                                    feature_spacing,
                                ))
                            })
                            .collect(),
                    ))
                };
                linear_scan_graded(
                    &kernel,
                    &pool,
                    pool_w.as_deref(),
                    &b.samples,
                    field,
                    &params.linear_scan,
                )
            } else {
                linear_scan(&kernel, &pool, &b.samples, &params.linear_scan)
            };
            Ok((
                r.samples.len(),
                Some((r, b.edges, b.feature_edges, corners)),
            ))
        };
        // The search's answer, with the widths of its last round (those of sigma_ref, which the
        // gradient ascent takes too).
        let (sigma_p, target_reached, search_history, value, widths) = match density {
            Target::SigmaP(s) => {
                let w = widths_at(s);
                let pool_w = w.active().then(|| pool_widths(&w));
                let (count, value) = scan(s, &w, pool_w.as_deref())?;
                (s, true, vec![(s, count)], value, w)
            }
            Target::Points(_) => {
                // The widths depend on sigma_p; a search over sigma_p with them moving could
                // find the count flat (a part graded at every sigma_p tried). So each search
                // holds the widths of sigma_ref, and when it ends far from sigma_ref, the
                // widths are taken again at its answer and the search repeats from there (at
                // most 3 rounds; only when the grading changes some width).
                let search = TargetCountParams {
                    tolerance: params.count_tolerance,
                    ..TargetCountParams::new(goal)
                };
                let mut history = Vec::new();
                let mut round_start = start;
                let mut round = 0;
                loop {
                    let w = widths_at(sigma_ref);
                    let pool_w = w.active().then(|| pool_widths(&w));
                    let mut failure = None;
                    let r = find_sigma_p(&search, round_start, |s| {
                        match scan(s, &w, pool_w.as_deref()) {
                            Ok(v) => v,
                            Err(e) => {
                                failure = Some(e);
                                (0, None)
                            }
                        }
                    });
                    if let Some(e) = failure {
                        return Err(e);
                    }
                    history.extend(r.history.iter().copied());
                    round += 1;
                    let moved = (r.sigma_p / sigma_ref).ln().abs() > 0.1;
                    let widths_change = grading
                        .as_ref()
                        .is_some_and(|g| g.grades_below(sigma_ref.max(r.sigma_p)))
                        || w.curvature.as_ref().is_some_and(CurvatureWidths::grades);
                    if round >= 3 || !moved || !widths_change {
                        break (r.sigma_p, r.reached, history, r.value, w);
                    }
                    sigma_ref = r.sigma_p;
                    round_start = r.sigma_p;
                }
            }
        };
        let Some((scan_result, boundary_edges, feature_edges, corners)) = value else {
            // Even the best sigma_p tried puts more samples on the boundary curves than the
            // bound (loops need 3 samples each, however short).
            let (name, what) = match density {
                Target::Points(_) => ("--points", format!("{goal} points")),
                Target::SigmaP(s) => ("--sigma-p", format!("sigma_p {s}")),
            };
            return Err(Error::InvalidParameter {
                name,
                message: format!(
                    "{what} cannot be reached on this surface: its {} boundary curves \
                     ({boundary_length:.3} long, bbox-100 units) alone take more than \
                     {boundary_limit} samples at every sigma_p tried",
                    curves.len()
                ),
            });
        };
        timer.lap("linear scan");

        on_stage("gradient ascent");
        let kernel = Kernel::new(sigma_p, params.sigma_n)?;
        let LinearScanResult {
            mut samples,
            initial: boundary_count,
            rejected_by_nearest,
            measured,
        } = scan_result;
        let before_ascent = buried_test.as_ref().map(|_| samples.clone());
        let feature_spacing = FEATURE_SPACING_PER_SIGMA * sigma_p;
        let width_field = (widths.active() || !corners.is_empty())
            .then_some(|p: DVec3| widths.at(p, &corners, feature_spacing));
        // Surface samples keep out of a band along the sampled creases.
        let band = {
            let positions: Vec<DVec3> = samples[..boundary_count]
                .iter()
                .map(|s| s.position)
                .collect();
            CreaseBand::new(
                &positions,
                &feature_edges,
                feature_spacing,
                0.05 * feature_spacing,
            )
        };
        let ga = gradient_ascent_graded(
            &kernel,
            &surface,
            &mut samples,
            boundary_count,
            width_field.as_ref().map(|f| f as WidthField),
            band.as_ref(),
            &params.gradient_ascent,
            params.seed,
        );
        // A face buried only in part can still take a sample onto its buried part (the closest
        // point of the input can lie there): such a sample goes back to where the scan put it.
        let mut buried_samples = 0;
        if let (Some(test), Some(before)) = (&buried_test, &before_ascent) {
            let buried = test.buried(
                &samples
                    .iter()
                    .map(|s| (s.position, s.normal, Some(s.face)))
                    .collect::<Vec<_>>(),
            );
            for (i, b) in buried.iter().enumerate() {
                if *b && i >= boundary_count {
                    samples[i] = before[i];
                    buried_samples += 1;
                }
            }
        }
        timer.lap("gradient ascent");

        on_stage("triangulate");
        let positions: Vec<DVec3> = samples.iter().map(|s| s.position).collect();
        let normals: Vec<DVec3> = samples
            .par_iter()
            .map(
                // A sample lies on the surface (up to rounding).
                |s: &SurfaceSample| match surface.closest_point_hinted(
                    s.position,
                    ON_SURFACE_RELATIVE * sigma_p,
                    f64::MAX,
                ) {
                    Some(sp) => surface.smooth_normal(&sp),
                    None => s.normal,
                },
            )
            .collect();
        let set = SampleSet {
            positions: &positions,
            normals: &normals,
            boundary_edges: &boundary_edges,
        };
        // The restricted Delaunay triangulation, or the umbrellas where it is not asked for or
        // its refinement of the input would be too large.
        let restricted = match params.triangulation {
            TriangulationMethod::Umbrellas => None,
            TriangulationMethod::RestrictedDelaunay(rd) => {
                // The sample spacing is about sigma_p (SAMPLES_PER_SIGMA2 samples per
                // sigma_p^2 of area; on boundary curves one per sigma_p or closer).
                let spacing = sigma_p / SAMPLES_PER_SIGMA2.sqrt();
                triangulate_restricted(&set, &surface, &sheets, spacing, &params.triangulate, &rd)
            }
        };
        let (faces, face_sources, mut assembly, restricted_delaunay) = match restricted {
            Some((f, s, a, rd)) => (f, s, a, Some(rd)),
            None => {
                let (f, s, a) = triangulate(&set, &params.triangulate);
                (f, s, a, None)
            }
        };
        let mut mesh_normalized = TriMesh::new(positions, faces);
        let feature_edges_triangulated = edges_present(&mesh_normalized, &feature_edges);
        let mut face_sources = face_sources;
        // Crease edges the triangulation left out (where a crease leaves a corner at a small
        // angle to another) are put in, and slits along graded creases (one sheet's faces
        // skipping a sample) closed.
        let recovery = if !feature_edges.is_empty() {
            let mut m: EditMesh<Option<u32>> =
                EditMesh::from_trimesh(&mesh_normalized, Some, SlotPolicy::Reuse);
            let slits = close_slits(&mut m, None);
            assembly.holes_left = assembly.holes_left.saturating_sub(slits);
            let stats = recover_edges(&mut m, &feature_edges, None);
            flip_crease_slivers(&mut m, None);
            let (positions, faces, origin) = m.into_parts();
            mesh_normalized = TriMesh::new(positions, faces);
            face_sources = carried_sources(&origin, &face_sources);
            stats
        } else {
            RecoverStats::default()
        };
        timer.lap("triangulate");
        // Where the input's faces cross or its parts meet: an output face within a spacing of
        // there is there.
        let input_crossings = (!input_crossing_pairs.is_empty() || !junction_faces.is_empty())
            .then(|| {
                CrossingRegions::new(
                    &normalized.positions,
                    &normalized.triangles,
                    &input_crossing_pairs,
                    &junction_faces,
                    sigma_p,
                )
            });
        on_stage("optimize");
        let optimize_stats = match &params.optimize {
            Some(op) => {
                let fixed: Vec<bool> = (0..samples.len()).map(|i| i < boundary_count).collect();
                let (st, origin) = optimize(
                    &mut mesh_normalized,
                    &surface,
                    &cover_points,
                    &fixed,
                    &feature_edges,
                    boundary_lines.as_ref(),
                    input_crossings.as_ref(),
                    sigma_p,
                    op,
                );
                face_sources = carried_sources(&origin, &face_sources);
                st
            }
            None => OptimizeStats::default(),
        };
        // Connectivity is final here but for the collapses of untangle's folds (where the output
        // crosses itself where the input does not).
        let feature_edges_kept = edges_present(&mesh_normalized, &feature_edges);
        let dropped_samples = mesh_normalized.remove_unreferenced_vertices();
        timer.lap("optimize");
        // Faces that still cross (where the input's sheets lie closer than the output's chords
        // bend away from them) are moved apart.
        let fixed: Vec<bool> = (0..mesh_normalized.positions.len())
            .map(|i| i < boundary_count)
            .collect();
        // The least-squares fit to the input, before the separation of crossing faces (which
        // then sees the final positions).
        let fit_stats = (params.fit_iterations > 0).then(|| {
            crate::triangulate::fit::fit_to_surface(
                &mut mesh_normalized,
                &surface,
                &fixed,
                params.fit_iterations,
                // The fit keeps the angles the last pass of optimize reached.
                params.optimize.as_ref().map(OptimizeParams::angle_bounds),
            )
        });
        // Faces that would touch once written in model units are separated too.
        let untangle_params = UntangleParams {
            near: params.untangle.near.max(normalization.written_rounding()),
            ..params.untangle
        };
        let (untangle_stats, origin) = untangle(
            &mut mesh_normalized,
            &fixed,
            sigma_p,
            &untangle_params,
            input_crossings.as_ref(),
        );
        if untangle_stats.collapses > 0 {
            face_sources = carried_sources(&origin, &face_sources);
            mesh_normalized.remove_unreferenced_vertices();
        }
        // No face of no area is written.
        let (degenerate_stats, origin) = mend_degenerate_faces(&mut mesh_normalized, &fixed);
        if let Some(origin) = origin {
            face_sources = carried_sources(&origin, &face_sources);
            mesh_normalized.remove_unreferenced_vertices();
        }
        // Tiny shells split off at tips too thin for the count (four samples closing into a
        // tetrahedron) go when the output has more parts than the input.
        let stray = match &grading {
            Some(g) => remove_stray_shells(
                &mut mesh_normalized,
                &mut face_sources,
                input_components,
                STRAY_SHELL_VERTICES,
                |shell| {
                    let (lo, hi) = shell.iter().fold(
                        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
                        |(lo, hi), &p| (lo.min(p), hi.max(p)),
                    );
                    lo.distance(hi) <= 4.0 * sigma_p
                        || shell.iter().all(|&p| g.width(p, sigma_ref) < 1.0)
                },
            ),
            None => StrayShells::default(),
        };
        if stray.shells > 0 {
            mesh_normalized.remove_unreferenced_vertices();
        }
        // The output follows the input's orientation: its closed parts are turned outward.
        let output_orientation = orient_consistently(&mut mesh_normalized, true);
        timer.lap("untangle");
        attempt += 1;
        let v = mesh_normalized.vertex_count() as f64;
        let (done, reached, miss) = match density {
            Target::SigmaP(_) => (true, target_reached, 0.0),
            Target::Points(n) => {
                let miss = n as f64 - v;
                // A raised target helps only where the sampler reached its own: a count the
                // search could not reach is not reached by asking for more.
                let done = attempt >= 2
                    || miss.abs() <= params.count_tolerance * n as f64
                    || (dropped_samples == 0 && miss.abs() <= 0.01 * n as f64)
                    || !target_reached;
                (done, miss.abs() <= 0.01 * n as f64, miss)
            }
        };
        if done {
            full_history.extend(search_history.iter().copied());
            let crease_distance = crate::check::crease_distance(
                &normalized.positions,
                &features.edges,
                &mesh_normalized,
                sigma_p / 4.0,
            );
            let grading_record = grading
                .as_ref()
                .map(|g| g.stats(&mesh_normalized.positions, sigma_ref, &normalization, area));
            break RemeshOutput {
                mesh: normalization.invert_mesh(&mesh_normalized),
                mesh_normalized,
                input_normalized: normalized,
                orientation,
                output_orientation,
                normalization,
                sigma_p,
                target: match density {
                    Target::Points(n) => Some(n),
                    Target::SigmaP(_) => None,
                },
                target_reached: reached,
                search_history: full_history,
                samples: samples.len(),
                boundary_samples: boundary_count,
                candidates: pool.len(),
                rejected_by_nearest,
                measured,
                gradient_ascent: ga,
                assembly,
                restricted_delaunay,
                optimize: optimize_stats,
                untangle: untangle_stats,
                degenerate: degenerate_stats,
                input_crossing_pairs: input_crossing_pairs.clone(),
                junction_faces: junction_faces.clone(),
                fit: fit_stats,
                face_sources,
                dropped_samples,
                buried_candidates,
                buried_samples,
                grading: grading_record,
                features: FeatureStats {
                    sampled_edges: feature_edges.len(),
                    triangulated_edges: feature_edges_triangulated,
                    recovered_edges: recovery.recovered,
                    kept_edges: feature_edges_kept,
                    crease_distance,
                    ..feature_stats.clone()
                },
                stray_shells: stray,
                stages: timer.take_stages(),
            };
        }
        full_history.extend(search_history.iter().copied());
        let new_goal = ((goal as f64 + miss).round() as usize).max(4);
        start = sigma_p * (goal as f64 / new_goal as f64).sqrt();
        goal = new_goal;
    };
    if output.mesh.triangles.is_empty() {
        // Too few samples for any triangle to form (a handful of points on a closed surface, or
        // sigma_p as large as the model): nothing to write.
        let (name, what) = match density {
            Target::Points(n) => ("--points", format!("{n} points")),
            Target::SigmaP(s) => ("--sigma-p", format!("sigma_p {s}")),
        };
        return Err(Error::InvalidParameter {
            name,
            message: format!(
                "{what} gave {} samples and no triangle on this surface; ask for more points \
                 (a smaller sigma_p)",
                output.samples
            ),
        });
    }
    Ok(output)
}

/// The kernel width field of one remesh round: the grading by thickness and the grading by
/// curvature, for the global `sigma_ref`, the smaller of the two.
struct Widths<'a> {
    grading: Option<&'a Grading>,
    curvature: Option<CurvatureWidths>,
    sigma_ref: f64,
}

impl Widths<'_> {
    /// Whether any grading is on.
    fn active(&self) -> bool {
        self.grading.is_some() || self.curvature.is_some()
    }

    /// The relative width at `p` (1 with no grading).
    fn width(&self, p: DVec3) -> f64 {
        let mut w: f64 = 1.0;
        if let Some(g) = self.grading {
            w = w.min(g.width(p, self.sigma_ref));
        }
        if let Some(c) = &self.curvature {
            w = w.min(c.width(p));
        }
        w
    }

    /// [`Widths::width`] lowered around graded `corners` ([`corner_width`] at the creases'
    /// `spacing`).
    fn at(&self, p: DVec3, corners: &[GradedCorner], spacing: f64) -> f64 {
        self.width(p).min(corner_width(corners, p, spacing))
    }
}
