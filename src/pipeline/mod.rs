//! The remeshing pipeline, one stage per file: the input normalized to bbox 100, oriented and
//! indexed, candidates drawn on it ([`input`]) → sharp features ([`features`]) → the sizing
//! field ([`sizing`]) → the linear scan with the sigma_p search for a count ([`scan`]) → the
//! gradient ascent ([`ascent`]) → the triangulation ([`triangulation`]) → the finishing stage
//! shared with point sets ([`finish`]) → back to model units ([`output`]).
//!
//! The pipeline for a point set (a scan), on the RIMLS surface of its points, is [`points`]
//! (parts far apart each on its own: `points/parts.rs`).

mod ascent;
mod features;
pub(crate) mod finish;
mod input;
mod output;
mod params;
pub(crate) mod points;
mod scan;
mod sizing;
mod triangulation;

use crate::error::{Error, Result};
use crate::finish::optimize::OptimizeParams;
use crate::finish::untangle::UntangleParams;
use crate::geometry::crossing_curve::CrossingCurve;
use crate::mesh::{Normalization, TriMesh};
use crate::sampling::sizing::SizingField;
use crate::sampling::spacing::sigma_p_for_count;
use crate::surface::features::Features;
use crate::timing::StageTimer;
use crate::triangulate::TriangulationMethod;
use ascent::{ascend, Ascended};
use finish::{finish, CrossingRule, Finished, Finishing, StrayRule};
use input::{Candidates, InputIndex, NormalizedInput};
use params::Target;
use scan::{Scanned, Search};
use sizing::{crease_terms, Sizing};
use triangulation::{triangulate_samples, Triangulated};

pub use crate::sampling::spacing::{
    expected_samples, BOUNDARY_SPACING_PER_SIGMA, SAMPLES_PER_SIGMA2,
};
pub use output::{FeatureStats, RemeshOutput};
pub use params::{points_for_edge_length, Density, RemeshParams, FIT_ITERATIONS, MAX_POINTS};

/// Runs of the pipeline at most for one count: when the output's vertex count misses the target
/// by more than the search tolerance (the triangulation may set a few samples aside, at parts
/// thinner than the sampling), the search runs again once, for a target raised by the
/// shortfall: the retry's miss is how closely the count can be aimed on this input, and a
/// second retry aims no closer, at the cost of a third run.
const MAX_ATTEMPTS: usize = 2;

/// The refinement budget of the restricted Delaunay triangulation (vertices added per sample)
/// when the sampling runs again finer around inserted samples: with the default 200,
/// ADIS16480's second run fell back to the umbrellas (4 components, 2 boundary loops).
const REFINED_MAX_ADDED_PER_SAMPLE: usize = 1000;

/// The width around the samples a triangulation inserted for the topological ball property,
/// relative to the width there, for the next attempt (see `RemeshParams::topology_refinements`).
const REFINEMENT_FACTOR: f64 = 0.5;

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
/// [`Error::InvalidParameter`] for a density or sigma out of range, or a density that gives no
/// triangle.
pub fn remesh(
    input: &TriMesh,
    params: &RemeshParams,
    on_stage: &(dyn Fn(&str) + Sync),
) -> Result<RemeshOutput> {
    let mut timer = StageTimer::new();
    let normalization = validate_input(input)?;
    let target = Target::of(params, input)?;
    on_stage("normalize");
    let (input, as_read) = NormalizedInput::new(input, normalization)?;
    let pool_size = input.pool_size(target, params)?;
    let index = InputIndex::new(
        &input.mesh,
        2 * pool_size + input.mesh.positions.len(),
        (pool_size as f64 / params.candidates_per_sample.max(1.0)) as usize,
    )?;
    timer.lap("normalize");

    on_stage("candidates");
    let mut candidates = Candidates::draw(as_read, &input, &index, pool_size, params.seed);
    timer.lap("candidates");

    // The search's first sigma_p (the given one for a sigma_p).
    let first_sigma_p = match target {
        Target::Points(n) => sigma_p_for_count(input.area, input.boundary_length, n as f64),
        Target::SigmaP(s) => s,
    };
    on_stage("features");
    let (features, feature_stats) =
        features::sharp_features(&input, &index.surface, first_sigma_p, params.features);
    timer.lap("features");
    let sizing = Sizing::new(
        &input,
        &index.surface,
        first_sigma_p,
        params,
        on_stage,
        &mut timer,
    )?;

    let mut search = Search {
        goal: target.count().unwrap_or(0),
        start: first_sigma_p,
        sigma_ref: first_sigma_p,
        // sigma_p is bounded only where the sizing field holds part of the count.
        max_sigma: params
            .grading
            .map(|g| g.max_coarsening * first_sigma_p)
            .filter(|&cap| sizing.grading.as_ref().is_some_and(|g| g.grades_below(cap)))
            .unwrap_or(f64::INFINITY),
        history: Vec::new(),
    };
    let mut attempt = 1;
    let mut refinements = 0;
    let mut sizing = sizing;
    let mut graded_for = None;
    let (run, reached) = loop {
        // The pool follows the sizing field (for the sigma_p the search starts from), drawn
        // again when the field changed.
        if graded_for != Some(refinements) {
            graded_for = Some(refinements);
            let widths = sizing.widths_at(&candidates.pool, search.sigma_ref);
            let field = widths.field();
            let round = refinements as u64;
            let seed = params.seed;
            candidates.grade(&input, &index, &field, search.sigma_ref, seed, round);
        }
        let stages = (&input, &index, &candidates, &features, &sizing);
        let refine_topology = refinements < params.topology_refinements;
        let run = match run_once(
            target,
            &mut search,
            stages,
            params,
            refine_topology,
            on_stage,
            &mut timer,
        )? {
            Attempt::Run(run) => *run,
            Attempt::Refine {
                inserted,
                widths,
                sigma_ref,
            } => {
                sizing.refine_at(&inserted, &widths, REFINEMENT_FACTOR, sigma_ref);
                refinements += 1;
                continue;
            }
        };
        match next_goal(target, attempt, &run, search.goal) {
            Next::Done { reached } => break (run, reached),
            Next::Again { goal } => {
                search.start = run.scanned.sigma_p * (search.goal as f64 / goal as f64).sqrt();
                search.goal = goal;
                attempt += 1;
            }
        }
    };
    let InputIndex {
        crossing_pairs,
        junction,
        ..
    } = index;
    let found = (&features, feature_stats, &sizing, search.sigma_ref);
    let record = (crossing_pairs, junction, &candidates, found);
    let output = output::assemble(input, record, run, target, reached, search.history, timer);
    if output.mesh.triangles.is_empty() {
        // Too few samples for any triangle to form (a handful of points on a closed surface, or
        // sigma_p as large as the model): nothing to write.
        let (name, what) = target.named(target.count().unwrap_or(0));
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

/// One run of the stages that depend on sigma_p.
struct Run<'s> {
    scanned: Scanned<'s>,
    ascended: Ascended,
    triangulated: Triangulated,
    finished: Finished,
}

/// What the stages before the sigma_p search made: the input, its index, the candidates, the
/// features and the sizing field.
type Prepared<'a, 's> = (
    &'a NormalizedInput,
    &'a InputIndex<'a>,
    &'a Candidates,
    &'a Features,
    &'s Sizing,
);

/// The linear scan for `search`'s goal, the gradient ascent, the triangulation and the
/// finishing stage.
fn run_once<'s>(
    target: Target,
    search: &mut Search,
    (input, index, candidates, features, sizing): Prepared<'_, 's>,
    params: &RemeshParams,
    refine_topology: bool,
    on_stage: &(dyn Fn(&str) + Sync),
    timer: &mut StageTimer,
) -> Result<Attempt<'s>> {
    on_stage("linear scan");
    let mut scanned = scan::scan(target, search, input, features, candidates, sizing, params)?;
    timer.lap("linear scan");

    on_stage("gradient ascent");
    let ascended = ascend(&mut scanned, index, params)?;
    timer.lap("gradient ascent");

    on_stage("triangulate");
    let (sigma_p, curves) = (scanned.sigma_p, &scanned.scan);
    let (boundary_edges, feature_edges) = (&curves.boundary_edges, &curves.feature_edges);
    let corners = scanned.corner_term();
    let creases = crease_terms(&corners, &scanned.scan.separation, &scanned.scan.curvature);
    let field = scanned.widths.field().with(&creases);
    let edges = (boundary_edges.as_slice(), feature_edges.as_slice());
    let samples = &ascended.samples;
    // A sampling run again finer around the samples an earlier triangulation inserted asks
    // for a finer refinement of the input there than the budget against slivers allows.
    let mut tri_params = *params;
    // So does a field graded by thickness.
    let graded = sizing
        .grading
        .as_ref()
        .is_some_and(|g| g.grades_below(scanned.widths.sigma_ref));
    if let (true, TriangulationMethod::RestrictedDelaunay(rd)) = (
        sizing.refinement.is_some() || graded,
        &mut tri_params.triangulation,
    ) {
        rd.max_added_per_sample = rd.max_added_per_sample.max(REFINED_MAX_ADDED_PER_SAMPLE);
    }
    let mut triangulated = triangulate_samples(samples, sigma_p, &field, edges, index, &tri_params);
    timer.lap("triangulate");
    search.history.extend(scanned.history.iter().copied());
    // Where the triangulation had to insert samples for the topological ball property, the
    // sampling was too coarse for the surface there: the width is lowered around them and the
    // sampling run again (before this run is finished), so that the samples there are placed
    // by the sampler itself. Only where the inserted samples take the count out of its
    // tolerance: a few inserted samples are kept as they are. (Nothing is inserted where the
    // triangulation does not check: see `triangulation::triangulate_samples`.)
    let inserted = triangulated.inserted.len() as f64;
    let aimed = samples.len().max(1) as f64;
    if refine_topology && inserted > params.count_tolerance * aimed {
        let widths = triangulated
            .inserted
            .iter()
            .map(|&p| field.width(p))
            .collect();
        return Ok(Attempt::Refine {
            inserted: std::mem::take(&mut triangulated.inserted),
            widths,
            sigma_ref: scanned.widths.sigma_ref,
        });
    }

    // Where the input's faces cross or its closed parts meet: the finishing stage leaves the
    // output's crossings within sigma_p of there alone. The input's crossings count only where
    // the buried test made the output follow the outer surface: without the test (an open input
    // too large for it) both sheets are sampled and pressed apart; and open sheets that meet at
    // a non-manifold edge are one surface, pressed apart too. The report's rule is wider (every
    // crossing and non-manifold edge, one output spacing: `app::quality`): the stage mends more
    // than the rule asks (corpus at 3000 seed 1: the rule's curve here left counter.unitsmm.STL
    // 33 pairs where this one leaves none, chair_model.obj 7 of its own where this one leaves 0).
    let pairs: &[[u32; 2]] = match index.buried_test {
        Some(_) => &index.crossing_pairs,
        None => &[],
    };
    let edges = &index.part_junction;
    let input_crossings = (!pairs.is_empty() || !edges.is_empty()).then(|| {
        let m = &input.mesh;
        CrossingCurve::new(&m.positions, &m.triangles, pairs, edges, sigma_p)
    });
    // With grading, tiny closed shells at tips too thin for the count go when the output has
    // more parts than the input.
    let sigma_ref = scanned.widths.sigma_ref;
    let stray = |shell: &[glam::DVec3]| {
        let (lo, hi) = shell.iter().fold(
            (
                glam::DVec3::splat(f64::INFINITY),
                glam::DVec3::splat(f64::NEG_INFINITY),
            ),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        lo.distance(hi) <= 4.0 * sigma_p
            || sizing
                .grading
                .as_ref()
                .is_some_and(|g| shell.iter().all(|&p| g.width(p, sigma_ref) < 1.0))
    };
    // Faces that would touch once written in model units are separated too, and the
    // optimization's guards keep them that far apart.
    let near = params
        .untangle
        .near
        .max(input.normalization.written_rounding());
    let optimize = params.optimize.map(|op| OptimizeParams {
        near: op.near.max(near),
        ..op
    });
    let cover_points = candidates.cover_points();
    let finishing = Finishing {
        surface: &index.surface,
        cover_points: &cover_points,
        fixed: ascended.boundary_count,
        untangle_moves_fixed: false,
        protected: feature_edges,
        boundary: input.boundary_lines.as_ref(),
        input_crossings: input_crossings.as_ref(),
        sigma_p,
        optimize: optimize.as_ref(),
        fit_iterations: params.fit_iterations,
        untangle: UntangleParams {
            near,
            ..params.untangle
        },
        refine: params.refine,
        crossing_rule: Some(CrossingRule {
            mesh: &input.mesh,
            pairs: &index.crossing_pairs,
            edges: &index.junction,
        }),
        stray: sizing.grading.as_ref().map(|_| StrayRule {
            keep: sizing.input_components,
            stray: &stray,
        }),
    };
    let (mesh, sources) = (&mut triangulated.mesh, &mut triangulated.face_sources);
    let finished = finish(mesh, sources, &finishing, on_stage, timer);
    Ok(Attempt::Run(Box::new(Run {
        scanned,
        ascended,
        triangulated,
        finished,
    })))
}

/// What a run of [`run_once`] ends in.
enum Attempt<'s> {
    /// A finished run.
    Run(Box<Run<'s>>),
    /// The triangulation inserted too many samples for the topological ball property: the
    /// positions inserted (bbox-100 units) and the width there, relative to `sigma_ref`, for
    /// the sizing field's refinement.
    Refine {
        inserted: Vec<glam::DVec3>,
        widths: Vec<f64>,
        sigma_ref: f64,
    },
}

/// What follows a run.
#[derive(Debug, PartialEq)]
enum Next {
    /// The output: `reached` whether the count came within 1% of the target (for a sigma_p,
    /// whether the scan reached it).
    Done { reached: bool },
    /// Another attempt for `goal` samples.
    Again { goal: usize },
}

/// How far from `--points` the output's vertex count may land (relative): the README's promise.
const COUNT_PROMISE: f64 = 0.01;

/// After attempt number `attempt` (aimed at `goal` samples) of a run for `target`: done, or
/// another attempt for the goal raised by the miss (see [`MAX_ATTEMPTS`]). A count within
/// [`COUNT_PROMISE`] of the target is done: another run (the whole pipeline again) could only
/// aim closer than the promise, and did not always (boolean.glb at 3000, seed 1: 2978, then
/// 2959); the search's own tolerance is finer, for the samples it places.
fn next_goal(target: Target, attempt: usize, run: &Run, goal: usize) -> Next {
    let count = run.triangulated.mesh.vertex_count();
    goal_after(target, attempt, count, run.scanned.target_reached, goal)
}

/// [`next_goal`] for an output of `count` vertices, `scan_reached` whether the scan reached its
/// goal.
fn goal_after(
    target: Target,
    attempt: usize,
    count: usize,
    scan_reached: bool,
    goal: usize,
) -> Next {
    let Target::Points(n) = target else {
        return Next::Done {
            reached: scan_reached,
        };
    };
    let miss = n as f64 - count as f64;
    let within = miss.abs() <= COUNT_PROMISE * n as f64;
    // A raised target helps only where the sampler reached its own: a count the search could
    // not reach is not reached by asking for more.
    if attempt >= MAX_ATTEMPTS || within || !scan_reached {
        return Next::Done { reached: within };
    }
    Next::Again {
        goal: ((goal as f64 + miss).round() as usize).max(4),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_count_within_the_promise_is_kept_and_one_past_it_is_run_again_once() {
        let n = Target::Points(3000);
        // 0.73% off (boolean.glb seed 1's first run): kept, though past the search's 0.5%.
        assert_eq!(
            goal_after(n, 1, 2978, true, 3000),
            Next::Done { reached: true }
        );
        assert_eq!(
            goal_after(n, 1, 3030, true, 3000),
            Next::Done { reached: true }
        );
        // Past 1%: run again for the goal moved by the miss, once.
        assert_eq!(
            goal_after(n, 1, 3249, true, 3000),
            Next::Again { goal: 2751 }
        );
        assert_eq!(
            goal_after(n, 1, 2969, true, 3000),
            Next::Again { goal: 3031 }
        );
        assert_eq!(
            goal_after(n, 2, 3086, true, 2224),
            Next::Done { reached: false }
        );
        // A scan that did not reach its goal is not asked for more.
        assert_eq!(
            goal_after(n, 1, 2000, false, 3000),
            Next::Done { reached: false }
        );
        // A sigma_p is reached when the scan reached it.
        let s = Target::SigmaP(2.0);
        assert_eq!(goal_after(s, 1, 10, true, 0), Next::Done { reached: true });
    }
}
