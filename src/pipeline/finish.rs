//! The finishing stage, shared by meshes and point sets: the triangulated samples optimized
//! against the surface they came from (cover, collapse, flip, relax), fitted to it, faces that
//! cross moved apart (and, where that collapsed edges, the faces around them mended by the
//! optimization's last pass again), faces of no area mended, stray shells left out, closed parts
//! turned outward.

use glam::DVec3;

use crate::finish::degenerate::{mend_degenerate_faces, DegenerateStats};
use crate::finish::fit::{fit_to_surface, FitStats};
use crate::finish::optimize::{mend_near, optimize, MendStats, OptimizeParams, OptimizeStats};
use crate::finish::refine::{refine_faces, RefineCrossingsParams, RefineCrossingsStats};
use crate::finish::stray_shells::{remove_stray_shells, StrayShells};
use crate::finish::untangle::{
    untangle_known, untangle_near, UntangleParams, UntangleStats, Untangled,
};
use crate::geometry::crossing_curve::{output_spacing, CrossingCurve};
use crate::geometry::face_intersection::faces_intersect;
use crate::geometry::self_intersection::intersecting_pairs;
use crate::geometry::triangle::AngleBounds;
use crate::mesh::{orient_consistently, OrientStats, TriMesh};
use crate::surface::feature_lines::FeatureLines;
use crate::surface::SurfaceQuery;
use crate::timing::StageTimer;
use crate::triangulate::FaceSource;

/// The most vertices of a shell [`remove_stray_shells`] removes: a few samples closing on
/// themselves at a tip (4 make a tetrahedron), not a part of the surface.
pub(crate) const STRAY_SHELL_VERTICES: usize = 8;

/// The sources of the faces of an edited mesh: a face that is still face `f` of the mesh before
/// (`origin`, as `EditMesh::into_parts` gives it) keeps `sources[f]`; a new or changed one is
/// `Refined`.
pub(crate) fn carried_sources(origin: &[Option<u32>], sources: &[FaceSource]) -> Vec<FaceSource> {
    origin
        .iter()
        .map(|o| o.map_or(FaceSource::Refined, |f| sources[f as usize]))
        .collect()
}

/// Which shells are stray: keep the largest `keep` parts, and of the others (at most
/// [`STRAY_SHELL_VERTICES`] vertices) remove those the test says are stray.
pub(crate) struct StrayRule<'a> {
    pub keep: usize,
    pub stray: &'a dyn Fn(&[DVec3]) -> bool,
}

/// What the finishing stage reads besides the mesh (bbox-100 units).
pub(crate) struct Finishing<'a, S: SurfaceQuery + ?Sized> {
    /// The surface the samples came from.
    pub surface: &'a S,
    /// Points of that surface the optimization keeps within its cover distance of the output.
    pub cover_points: &'a [DVec3],
    /// The first `fixed` vertices stay where they are (boundary and crease samples).
    pub fixed: usize,
    /// Whether the separation of crossing faces may move the `fixed` vertices too (a point
    /// set's boundary samples are estimates of where its data ends; an input mesh's are on its
    /// boundary).
    pub untangle_moves_fixed: bool,
    /// Edges the optimization keeps (the sampled creases).
    pub protected: &'a [[u32; 2]],
    /// The input's boundary curves, which boundary vertices slide along.
    pub boundary: Option<&'a FeatureLines>,
    /// Where the input crosses itself: the output's crossings there are left alone.
    pub input_crossings: Option<&'a CrossingCurve>,
    /// The report's rule of whose a crossing is, which the refinement mends by (`None`: every
    /// crossing is the output's own).
    pub crossing_rule: Option<CrossingRule<'a>>,
    /// The kernel width the samples were placed at.
    pub sigma_p: f64,
    /// The local optimization (`None`: skipped).
    pub optimize: Option<&'a OptimizeParams>,
    /// Iterations of the least-squares fit (0: none).
    pub fit_iterations: usize,
    /// The separation of crossing faces.
    pub untangle: UntangleParams,
    /// The refinement where the output still crosses itself after that (`max_rounds` 0: none).
    pub refine: RefineCrossingsParams,
    /// Stray shells to leave out (`None`: all kept).
    pub stray: Option<StrayRule<'a>>,
}

/// The mesh as a round of refinement found it, and the vertices removed until then.
struct Kept {
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    sources: Vec<FaceSource>,
    later_dropped: usize,
}

/// The input's crossings as the report counts them (`app::quality`): a crossing pair of the
/// output is the input's when both faces lie within one output spacing of the curve of the
/// input's crossing `pairs` and non-manifold `edges` (of `mesh`, bbox-100 units).
#[derive(Clone, Copy)]
pub(crate) struct CrossingRule<'a> {
    pub mesh: &'a TriMesh,
    pub pairs: &'a [[u32; 2]],
    pub edges: &'a [[u32; 2]],
}

/// What the finishing stage did.
pub(crate) struct Finished {
    pub optimize: OptimizeStats,
    /// Of the protected edges, those still edges after the optimization.
    pub protected_kept: usize,
    /// Vertices no face used after the optimization (samples dropped).
    pub dropped_samples: usize,
    /// Vertices removed after that (by untangle's collapses and the mending).
    pub later_dropped: usize,
    pub fit: Option<FitStats>,
    pub untangle: UntangleStats,
    /// The optimization's last pass again around the faces untangle's collapses changed (none
    /// without collapses or without the optimization).
    pub mend_after_untangle: MendStats,
    /// The rounds of refinement and untangling where the output's own crossings were left.
    pub refine: RefineCrossingsStats,
    pub degenerate: DegenerateStats,
    pub stray_shells: StrayShells,
    /// What orienting the output did (closed parts turned outward).
    pub orientation: OrientStats,
}

/// Finishes `mesh` (its faces' sources carried along) as `f` says, in the stages "optimize" and
/// "untangle".
pub(crate) fn finish<S: SurfaceQuery + ?Sized>(
    mesh: &mut TriMesh,
    face_sources: &mut Vec<FaceSource>,
    f: &Finishing<S>,
    on_stage: &(dyn Fn(&str) + Sync),
    timer: &mut StageTimer,
) -> Finished {
    on_stage("optimize");
    // The intersecting pairs of the mesh as the optimization left it (`None`: not known).
    let mut intersecting: Option<Vec<[u32; 2]>> = None;
    let fixed_prefix = |n: usize| -> Vec<bool> { (0..n).map(|i| i < f.fixed).collect() };
    let optimize_stats = match f.optimize {
        Some(op) => {
            let (st, edited) = optimize(
                mesh,
                f.surface,
                f.cover_points,
                &fixed_prefix(mesh.positions.len()),
                f.protected,
                f.boundary,
                f.input_crossings,
                f.sigma_p,
                op,
            );
            *face_sources = carried_sources(&edited.origin, face_sources);
            intersecting = Some(edited.intersecting);
            st
        }
        None => OptimizeStats::default(),
    };
    // Connectivity is final here but for the collapses of untangle's folds (where the output
    // crosses itself where the input does not).
    let protected_kept = edges_present(mesh, f.protected);
    let renumbered = mesh.compact_vertices();
    let dropped_samples = renumbered.iter().filter(|&&i| i == u32::MAX).count();
    // The protected edges by the new numbers, for the mending after untangle.
    let protected = renumber_edges(f.protected, &renumbered);
    timer.lap("optimize");
    on_stage("untangle");
    let fixed = fixed_prefix(mesh.positions.len());
    // The least-squares fit to the surface, before the separation of crossing faces (which then
    // sees the final positions). It keeps the angles the last pass of optimize reached.
    let fit = (f.fit_iterations > 0).then(|| {
        fit_to_surface(
            mesh,
            f.surface,
            &fixed,
            f.fit_iterations,
            f.optimize.map(OptimizeParams::angle_bounds),
            intersecting.as_deref(),
        )
    });
    // Faces that still cross (where the surface's sheets lie closer than the output's chords
    // bend away from them) are moved apart.
    let mut later_dropped = 0;
    let none_fixed;
    let untangle_fixed: &[bool] = if f.untangle_moves_fixed {
        none_fixed = vec![false; mesh.positions.len()];
        &none_fixed
    } else {
        &fixed
    };
    // Two stages: first the collapses that keep the mesh within the optimization's bound on a
    // collapse (then the last pass mends around them, with the surface at hand: a fold it can
    // undo keeps its vertices), then, where folds are left, any collapse that removes them.
    let mut untangle_stats = UntangleStats::default();
    let mut mend_after_untangle = MendStats::default();
    // The intersecting pairs of the mesh as the mending after untangle left it (no search).
    intersecting = None;
    // The pairs within untangle's `near` the first stage left when it collapsed nothing: the
    // second starts from them (no search).
    let mut known: Option<Vec<[u32; 2]>> = None;
    // The output's own crossing pairs the last stage left.
    let mut own_left: Option<Vec<[u32; 2]>> = None;
    for (stage, offset) in [f.untangle.collapse_offset_sigma_p, f64::INFINITY]
        .into_iter()
        .enumerate()
    {
        let params = UntangleParams {
            collapse_offset_sigma_p: offset,
            ..f.untangle
        };
        let before_untangle = mesh.positions.clone();
        let Untangled {
            stats,
            origin,
            left,
            moved,
        } = untangle_known(
            mesh,
            untangle_fixed,
            f.sigma_p,
            &params,
            f.input_crossings,
            known.take(),
        );
        untangle_stats = if stage == 0 {
            stats
        } else {
            untangle_stats.then(&stats)
        };
        if stats.collapses > 0 {
            *face_sources = carried_sources(&origin, face_sources);
        }
        let edited = stats.collapses > 0 || stats.vertices_moved > 0;
        if let (Some(op), true) = (f.optimize, edited) {
            // The collapses leave the faces around them as they fall (a hub where a fold was
            // collapsed away), and a press moves vertices by up to the round's step: the last
            // pass of the optimization mends those faces, and the faces around them, under its
            // guards (no new crossing, near the surface).
            let pressed = pressed_out_of_bounds(mesh, &before_untangle, &moved, op.angle_bounds());
            let near = around_changed_faces(mesh, &origin, &pressed);
            // The pairs untangle left are those the mending starts from where both take one
            // `near` (no search of the whole mesh).
            let same_near = untangle_near(&params, f.sigma_p) == op.near.max(0.0);
            let known = left.filter(|_| same_near);
            let (stats, pairs) =
                mend_changed(mesh, face_sources, f, op, &fixed, &protected, &near, known);
            mend_after_untangle = mend_after_untangle.then(&stats);
            intersecting = Some(pairs);
            later_dropped += mesh.remove_unreferenced_vertices();
        } else if stats.collapses > 0 {
            later_dropped += mesh.remove_unreferenced_vertices();
        } else if let Some(left) = left {
            // Of the pairs left within `near`, those that intersect.
            intersecting = Some(intersecting_of(mesh, left.clone()));
            known = Some(left);
        }
        // The second stage only where the first left the output's own folds or crossings.
        // Untangle's pairs at the end are those within its `near` (0 or more) of the mesh as it
        // is when it collapsed nothing: none of them, no face crossing either (no search).
        let none_left = stats.collapses == 0 && stats.pairs_after == 0;
        let own = if none_left {
            Vec::new()
        } else {
            own_crossings(mesh, intersecting.take(), f.input_crossings)
        };
        let done = own.is_empty();
        own_left = Some(own);
        if done {
            break;
        }
    }
    // Where the output's own crossings are left (its chords cut across a sheet of the input
    // that lies closer than the spacing, or long faces fan out of fixed crease samples), the
    // crossing faces' edges are split at the surface and untangle runs again, in rounds.
    let refine = if f.refine.max_rounds > 0 {
        refine_rounds(
            mesh,
            face_sources,
            f,
            protected,
            own_left,
            &mut Totals {
                untangle: &mut untangle_stats,
                mend: &mut mend_after_untangle,
                later_dropped: &mut later_dropped,
            },
        )
    } else {
        RefineCrossingsStats::default()
    };
    // No face of no area is written.
    let (degenerate, origin) = mend_degenerate_faces(mesh, &fixed);
    if let Some(origin) = origin {
        *face_sources = carried_sources(&origin, face_sources);
        later_dropped += mesh.remove_unreferenced_vertices();
    }
    // Tiny shells split off at tips too thin for the count (four samples closing into a
    // tetrahedron) go when the output has more parts than it should.
    let stray_shells = match &f.stray {
        Some(rule) => remove_stray_shells(
            mesh,
            face_sources,
            rule.keep,
            STRAY_SHELL_VERTICES,
            rule.stray,
        ),
        None => StrayShells::default(),
    };
    if stray_shells.shells > 0 {
        mesh.remove_unreferenced_vertices();
    }
    // The output follows the surface's orientation: its closed parts are turned outward.
    let orientation = orient_consistently(mesh, true);
    timer.lap("untangle");
    Finished {
        optimize: optimize_stats,
        protected_kept,
        dropped_samples,
        later_dropped,
        fit,
        untangle: untangle_stats,
        mend_after_untangle,
        refine,
        degenerate,
        stray_shells,
        orientation,
    }
}

/// The last pass of the optimization again around the vertices flagged in `near` (`V` flags),
/// the faces' sources carried along: what it did, and the pairs of faces that intersect after
/// it (or come within its `near`). `known`: the pairs within that `near` before it, when known.
#[allow(clippy::too_many_arguments)] // mend_near's arguments from the finishing stage's
fn mend_changed<S: SurfaceQuery + ?Sized>(
    mesh: &mut TriMesh,
    face_sources: &mut Vec<FaceSource>,
    f: &Finishing<S>,
    op: &OptimizeParams,
    fixed: &[bool],
    protected: &[[u32; 2]],
    near: &[bool],
    known: Option<Vec<[u32; 2]>>,
) -> (MendStats, Vec<[u32; 2]>) {
    let (stats, mended) = mend_near(
        mesh,
        f.surface,
        fixed,
        protected,
        f.boundary,
        f.input_crossings,
        f.sigma_p,
        op,
        near,
        known,
    );
    *face_sources = carried_sources(&mended.origin, face_sources);
    (stats, mended.intersecting)
}

/// What the rounds of refinement add to (the finishing stage's totals).
struct Totals<'t> {
    untangle: &'t mut UntangleStats,
    mend: &'t mut MendStats,
    later_dropped: &'t mut usize,
}

/// The refinement of the faces that cross outside the input's crossings (by the report's rule,
/// [`CrossingRule`]; `own_left`: the pairs the finishing stage's narrower curve leaves, when
/// known): in rounds, their edges split at the surface ([`refine_faces`]), untangle with any
/// collapse, and the last pass around the changed faces; the round with the fewest such pairs
/// is kept, the later ones taken back.
fn refine_rounds<S: SurfaceQuery + ?Sized>(
    mesh: &mut TriMesh,
    face_sources: &mut Vec<FaceSource>,
    f: &Finishing<S>,
    mut protected: Vec<[u32; 2]>,
    own_left: Option<Vec<[u32; 2]>>,
    totals: &mut Totals,
) -> RefineCrossingsStats {
    let mut refine = RefineCrossingsStats::default();
    let fixed_prefix = |n: usize| -> Vec<bool> { (0..n).map(|i| i < f.fixed).collect() };
    // By the report's rule, at the output's spacing now (the splits change it little).
    let rule = f
        .crossing_rule
        .filter(|r| !r.pairs.is_empty() || !r.edges.is_empty())
        .map(|r| {
            let reach = output_spacing(&mesh.positions, &mesh.triangles);
            CrossingCurve::new(
                &r.mesh.positions,
                &r.mesh.triangles,
                r.pairs,
                r.edges,
                reach,
            )
        });
    let by_rule = |mesh: &TriMesh, pairs: Vec<[u32; 2]>| -> Vec<[u32; 2]> {
        let corners = |t: [u32; 3]| t.map(|v| mesh.positions[v as usize]);
        let mut pairs = pairs;
        pairs.retain(|&[f, g]| {
            let (a, b) = (mesh.triangles[f as usize], mesh.triangles[g as usize]);
            rule.as_ref()
                .is_none_or(|r| !r.holds(corners(a), corners(b)))
        });
        pairs
    };
    let mut own = by_rule(
        mesh,
        own_left.unwrap_or_else(|| own_crossings(mesh, None, f.input_crossings)),
    );
    refine.pairs_before = own.len();
    // The fewest own pairs yet, and the mesh that had them once a later round changed it.
    let mut best: (usize, Option<Kept>) = (own.len(), None);
    let budget = (f.refine.max_splits_per_vertex * mesh.positions.len() as f64).ceil() as usize;
    while refine.rounds < f.refine.max_rounds && !own.is_empty() && refine.splits < budget {
        refine.rounds += 1;
        if best.1.is_none() {
            best.1 = Some(Kept {
                positions: mesh.positions.clone(),
                triangles: mesh.triangles.clone(),
                sources: face_sources.clone(),
                later_dropped: *totals.later_dropped,
            });
        }
        let mut faces: Vec<u32> = own.iter().flatten().copied().collect();
        faces.sort_unstable();
        faces.dedup();
        let (splits, refused, origin) = refine_faces(
            mesh,
            f.surface,
            &faces,
            &protected,
            f.refine.min_edge_sigma_p * f.sigma_p,
            budget - refine.splits,
        );
        refine.splits += splits;
        refine.refused += refused;
        if splits == 0 {
            best.1 = None;
            break;
        }
        *face_sources = carried_sources(&origin, face_sources);
        // The vertices of the faces the splits made, for the mending after untangle.
        let split_faces = around_changed_faces(mesh, &origin, &[]);
        let fixed = fixed_prefix(mesh.positions.len());
        let none_fixed = vec![false; mesh.positions.len()];
        let untangle_fixed = if f.untangle_moves_fixed {
            &none_fixed
        } else {
            &fixed
        };
        let params = UntangleParams {
            collapse_offset_sigma_p: f64::INFINITY,
            ..f.untangle
        };
        let Untangled {
            stats,
            origin,
            left,
            ..
        } = untangle_known(
            mesh,
            untangle_fixed,
            f.sigma_p,
            &params,
            f.input_crossings,
            None,
        );
        *totals.untangle = totals.untangle.then(&stats);
        if stats.collapses > 0 {
            *face_sources = carried_sources(&origin, face_sources);
        }
        let mut pairs = None;
        if let Some(op) = f.optimize {
            // The faces the splits made and those untangle changed, and their neighbours:
            // the last pass mends their angles under its guards.
            let near = around_changed_faces(mesh, &origin, &split_faces);
            let (stats, mended) =
                mend_changed(mesh, face_sources, f, op, &fixed, &protected, &near, None);
            *totals.mend = totals.mend.then(&stats);
            pairs = Some(mended);
        } else if stats.collapses == 0 {
            pairs = left.map(|left| intersecting_of(mesh, left));
        }
        let renumbered = mesh.compact_vertices();
        *totals.later_dropped += renumbered.iter().filter(|&&i| i == u32::MAX).count();
        protected = renumber_edges(&protected, &renumbered);
        own = by_rule(mesh, own_crossings(mesh, pairs, f.input_crossings));
        if own.len() < best.0 {
            best = (own.len(), None);
        }
    }
    // The rounds after the one with the fewest own pairs are taken back.
    if let (_, Some(kept)) = best {
        mesh.positions = kept.positions;
        mesh.triangles = kept.triangles;
        *face_sources = kept.sources;
        *totals.later_dropped = kept.later_dropped;
        own = by_rule(mesh, own_crossings(mesh, None, f.input_crossings));
    }
    refine.pairs_after = own.len();
    refine
}

/// The pairs of faces of `mesh` that intersect ([`intersecting_pairs`]; `known`: those pairs,
/// when the caller has them) other than where the input's own faces cross (a pair that shares a
/// vertex, a fold, always counts: as [`CrossingCurve::holds_faces`] says).
fn own_crossings(
    mesh: &TriMesh,
    known: Option<Vec<[u32; 2]>>,
    regions: Option<&CrossingCurve>,
) -> Vec<[u32; 2]> {
    let corners = |t: [u32; 3]| t.map(|v| mesh.positions[v as usize]);
    let mut pairs = known.unwrap_or_else(|| intersecting_pairs(&mesh.positions, &mesh.triangles));
    pairs.retain(|&[f, g]| {
        let (a, b) = (mesh.triangles[f as usize], mesh.triangles[g as usize]);
        regions.is_none_or(|r| !r.holds_faces(a, corners(a), b, corners(b)))
    });
    pairs
}

/// Of the pairs of faces `left` within untangle's `near` of each other, those that intersect.
fn intersecting_of(mesh: &TriMesh, left: Vec<[u32; 2]>) -> Vec<[u32; 2]> {
    let corners = |t: [u32; 3]| t.map(|v| mesh.positions[v as usize]);
    left.into_iter()
        .filter(|&[f, g]| {
            let (a, b) = (mesh.triangles[f as usize], mesh.triangles[g as usize]);
            faces_intersect(a, corners(a), b, corners(b)).is_some()
        })
        .collect()
}

/// `edges` by the vertices' new indices (`renumbered`, as [`TriMesh::compact_vertices`] gives
/// them), those with a removed end left out.
fn renumber_edges(edges: &[[u32; 2]], renumbered: &[u32]) -> Vec<[u32; 2]> {
    edges
        .iter()
        .filter_map(|e| {
            let [a, b] = e.map(|v| renumbered.get(v as usize).copied().unwrap_or(u32::MAX));
            (a != u32::MAX && b != u32::MAX).then_some([a, b])
        })
        .collect()
}

/// The vertices of the faces of `mesh` that the presses of untangle put out of the angle
/// `bounds` (a corner in `moved`, and a score now below the bound and below the one at the
/// positions `before`): `V` flags. A face out of bounds before the presses (at a kept crease,
/// say) is not the presses' doing, and the mending after them leaves it.
fn pressed_out_of_bounds(
    mesh: &TriMesh,
    before: &[DVec3],
    moved: &[bool],
    bounds: AngleBounds,
) -> Vec<bool> {
    let mut flags = vec![false; mesh.positions.len()];
    for t in &mesh.triangles {
        if !t
            .iter()
            .any(|&v| moved.get(v as usize).copied().unwrap_or(false))
        {
            continue;
        }
        let now = bounds.score(t.map(|v| mesh.positions[v as usize]));
        let was = bounds.score(t.map(|v| before[v as usize]));
        if now < bounds.min_deg && now < was {
            for &v in t {
                flags[v as usize] = true;
            }
        }
    }
    flags
}

/// The vertices of the faces of `mesh` that an edit changed (`origin[f]` is `None`: as
/// `EditMesh::into_parts` gives it) and of the faces that share a vertex with them: `V` flags.
fn around_changed_faces(mesh: &TriMesh, origin: &[Option<u32>], moved: &[bool]) -> Vec<bool> {
    let mut changed = vec![false; mesh.positions.len()];
    for (c, &m) in changed.iter_mut().zip(moved) {
        *c |= m;
    }
    for (t, o) in mesh.triangles.iter().zip(origin) {
        if o.is_none() {
            for &v in t {
                changed[v as usize] = true;
            }
        }
    }
    with_their_faces(mesh, changed)
}

/// `flags` (`V` flags of `mesh`'s vertices) with the vertices of every face that has a flagged
/// vertex set too.
pub(crate) fn with_their_faces(mesh: &TriMesh, flags: Vec<bool>) -> Vec<bool> {
    let mut near = flags.clone();
    for t in &mesh.triangles {
        if t.iter().any(|&v| flags[v as usize]) {
            for &v in t {
                near[v as usize] = true;
            }
        }
    }
    near
}

/// How many of `edges` (vertex pairs, either direction) are edges of a face of `mesh`.
pub(crate) fn edges_present(mesh: &TriMesh, edges: &[[u32; 2]]) -> usize {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Of three faces around a pressed vertex: the one the press folded below the bound is
    /// marked, the one already below it and no worse is not, and a face with no moved corner
    /// is not either.
    #[test]
    fn only_the_faces_a_press_made_worse_are_mended() {
        let bounds = AngleBounds {
            min_deg: 35.0,
            max_deg: 100.0,
        };
        // 0-1-2: equilateral, its corner 2 then pressed nearly onto edge 0-1 (out of bounds).
        // 3-4-5: a sliver before and after (corner 5 moves along it, no worse). 6-7-8: untouched.
        let h = 3f64.sqrt() / 2.0;
        let before = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.5, h, 0.0),
            DVec3::new(10.0, 0.0, 0.0),
            DVec3::new(11.0, 0.0, 0.0),
            DVec3::new(10.5, 0.05, 0.0),
            DVec3::new(20.0, 0.0, 0.0),
            DVec3::new(21.0, 0.0, 0.0),
            DVec3::new(20.5, 0.1, 0.0),
        ];
        let mut after = before.clone();
        after[2] = DVec3::new(0.5, 0.1, 0.0);
        after[5] = DVec3::new(10.5, 0.06, 0.0);
        let mesh = TriMesh::new(after, vec![[0, 1, 2], [3, 4, 5], [6, 7, 8]]);
        let moved = [false, false, true, false, false, true, false, false, false];
        let flags = pressed_out_of_bounds(&mesh, &before, &moved, bounds);
        assert_eq!(
            flags,
            [true, true, true, false, false, false, false, false, false]
        );
        // Unmoved, the first face is left too.
        let none = [false; 9];
        assert!(!pressed_out_of_bounds(&mesh, &before, &none, bounds)
            .iter()
            .any(|&f| f));
    }
}
