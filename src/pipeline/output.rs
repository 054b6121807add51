//! What [`remesh`](super::remesh) returns: the mesh and the record of every stage.

use super::input::{Candidates, NormalizedInput};
use super::params::Target;
use super::sizing::Sizing;
use super::Run;
use crate::finish::optimize::{MendStats, OptimizeStats};
use crate::finish::stray_shells::StrayShells;
use crate::finish::untangle::UntangleStats;
use crate::mesh::{Normalization, OrientStats, TriMesh};
use crate::sampling::gradient_ascent::GradientAscentResult;
use crate::sampling::grading::GradingStats;
use crate::surface::features::Features;
use crate::timing::{Stage, StageTimer};
use crate::triangulate::AssemblyStats;

/// The sharp features [`remesh`](super::remesh) found on its input
/// ([`detect_features`](crate::internal::detect_features)). Lengths in bbox-100 units.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FeatureStats {
    /// The feature angle, degrees.
    pub angle_deg: f64,
    /// With automatic detection
    /// ([`FeatureDetection::Auto`](crate::internal::FeatureDetection::Auto)): whether the creases
    /// found were kept (`false`: a scan's folds, left out; the counts below are what was found).
    pub automatic_kept: Option<bool>,
    /// The share of the creases' length in curves at least
    /// [`LONG_CURVE_SPACINGS`](crate::internal::LONG_CURVE_SPACINGS) spacings long
    /// ([`long_curve_share`](crate::internal::long_curve_share)).
    pub long_curve_share: f64,
    /// With automatic detection, when the long curves fell short: the share of the creases'
    /// length in curves that are long, closed or run from junction to junction
    /// ([`junction_curve_share`](crate::internal::junction_curve_share)).
    pub junction_curve_share: Option<f64>,
    /// When that share was enough: the creases' length times the spacing over the surface's
    /// area ([`MAX_CREASE_DENSITY`](crate::internal::MAX_CREASE_DENSITY) at most keeps them).
    pub crease_density: Option<f64>,
    /// When the density was low enough: the length of the creases found at
    /// [`GAP_ANGLE_DEG`](crate::internal::GAP_ANGLE_DEG) over that found at the feature angle
    /// (at most [`MAX_GAP_RATIO`](crate::internal::MAX_GAP_RATIO) keeps them).
    pub gap_ratio: Option<f64>,
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

/// The output of [`remesh`](super::remesh).
#[derive(Debug, Clone)]
pub struct RemeshOutput {
    /// The remeshed surface in model units.
    pub mesh: TriMesh,
    /// The same in bbox-100 units.
    pub mesh_normalized: TriMesh,
    /// The input in bbox-100 units, oriented consistently (see `orientation`).
    pub input_normalized: TriMesh,
    /// What orienting the input consistently did
    /// ([`orient_consistently`](crate::internal::orient_consistently) without turning closed parts
    /// outward: faces flipped, non-orientable components).
    pub orientation: OrientStats,
    /// What orienting the output did ([`orient_consistently`](crate::internal::orient_consistently)
    /// turning closed parts outward: the output follows the input's orientation, so this turns the
    /// output of an inward-facing closed input outward).
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
    /// The optimization's last pass again around the faces untangle's collapses changed.
    pub mend_after_untangle: MendStats,
    /// The refinement where the output's own crossings were left after untangle.
    pub refine: crate::finish::refine::RefineCrossingsStats,
    /// What the mending of faces of no area did.
    pub degenerate: crate::finish::degenerate::DegenerateStats,
    /// The pairs of `input_normalized`'s faces that cross (looked for only when the input
    /// passes through itself), as `geometry::self_intersection::intersecting_pairs` gives them.
    pub input_crossing_pairs: Vec<[u32; 2]>,
    /// The non-manifold edges of `input_normalized` (of more than two faces: where sheets
    /// meet), as vertex pairs, ascending. With `input_crossing_pairs`, what the
    /// [`CrossingCurve`](crate::internal::CrossingCurve) is built from: where the output's
    /// crossings are the input's own.
    pub junction: Vec<[u32; 2]>,
    /// What the least-squares fit to the input did (`None` when it was off).
    pub fit: Option<crate::finish::fit::FitStats>,
    /// How each face of `mesh` came in.
    pub face_sources: Vec<crate::triangulate::FaceSource>,
    /// What the restricted Delaunay triangulation did; `None` when the umbrellas made the
    /// triangles (asked for, the input's refinement would have been too large, or it gave no
    /// triangle).
    pub restricted_delaunay: Option<crate::triangulate::RestrictedDelaunayStats>,
    /// Samples that ended in no triangle and were dropped.
    pub dropped_samples: usize,
    /// Candidates left out as buried inside the input's own solid (a self-intersecting input;
    /// [`BuriedTest`](crate::internal::BuriedTest)).
    pub buried_candidates: usize,
    /// Samples the gradient ascent moved onto the buried part of a face, put back where the
    /// scan put them.
    pub buried_samples: usize,
    /// What the grading by the local feature size did (`None` when it was off).
    pub grading: Option<GradingStats>,
    /// The sharp features detected on the input (see
    /// [`RemeshParams::features`](super::RemeshParams::features)).
    pub features: FeatureStats,
    /// Tiny closed shells at unresolved tips removed (bbox-100 units).
    pub stray_shells: StrayShells,
    /// Timed stages in order.
    pub stages: Vec<Stage>,
}

/// What the stages before the search left for the record: the input's crossing pairs and
/// junction faces, the candidates, and the features found with the sizing field and its
/// sigma_ref.
pub(super) type Record<'a> = (
    Vec<[u32; 2]>,
    Vec<[u32; 2]>,
    &'a Candidates,
    (&'a Features, FeatureStats, &'a Sizing, f64),
);

/// The output of the last run: the mesh back in model units, and the record of every stage.
pub(super) fn assemble(
    input: NormalizedInput,
    (input_crossing_pairs, junction, candidates, found): Record,
    run: Run,
    target: Target,
    target_reached: bool,
    search_history: Vec<(f64, usize)>,
    mut timer: StageTimer,
) -> RemeshOutput {
    let (features, feature_stats, sizing, sigma_ref) = found;
    let Run {
        scanned,
        ascended,
        triangulated,
        finished,
    } = run;
    let (sigma_p, mesh_normalized) = (scanned.sigma_p, triangulated.mesh);
    let normalization = input.normalization;
    let crease_distance = crate::check::crease_distance(
        &input.mesh.positions,
        &features.edges,
        &mesh_normalized,
        sigma_p / 4.0,
    );
    let grading = sizing.grading.as_ref().map(|g| {
        g.stats(
            &mesh_normalized.positions,
            sigma_ref,
            &normalization,
            input.area,
        )
    });
    RemeshOutput {
        mesh: normalization.invert_mesh(&mesh_normalized),
        mesh_normalized,
        input_normalized: input.mesh,
        orientation: input.orientation,
        output_orientation: finished.orientation,
        normalization,
        sigma_p,
        target: target.count(),
        target_reached,
        search_history,
        samples: ascended.samples.len(),
        boundary_samples: ascended.boundary_count,
        candidates: candidates.pool.len(),
        rejected_by_nearest: ascended.rejected_by_nearest,
        measured: ascended.measured,
        gradient_ascent: ascended.record,
        assembly: triangulated.assembly,
        restricted_delaunay: triangulated.restricted_delaunay,
        optimize: finished.optimize,
        untangle: finished.untangle,
        mend_after_untangle: finished.mend_after_untangle,
        refine: finished.refine,
        degenerate: finished.degenerate,
        input_crossing_pairs,
        junction,
        fit: finished.fit,
        face_sources: triangulated.face_sources,
        dropped_samples: finished.dropped_samples,
        buried_candidates: candidates.buried,
        buried_samples: ascended.buried_samples,
        grading,
        features: FeatureStats {
            sampled_edges: scanned.scan.feature_edges.len(),
            triangulated_edges: triangulated.feature_edges_triangulated,
            recovered_edges: triangulated.recovery.recovered,
            kept_edges: finished.protected_kept,
            crease_distance,
            ..feature_stats
        },
        stray_shells: finished.stray_shells,
        stages: timer.take_stages(),
    }
}
