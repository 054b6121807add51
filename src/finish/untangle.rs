//! Separating the faces of a triangulation that cross each other.
//!
//! The triangulation follows the input surface. Where that surface passes through itself (cow:
//! the tail's root inside the rump; horse: a fin on the tail; beetle: its legs), or where two of
//! its sheets lie closer than the chords of the output bend away from them, faces of the output
//! cross. This stage moves the vertices of each crossing pair just out of the other face's plane
//! until no pair is left (vertex relocations of an [`EditMesh`]; the connectivity stays).

use glam::DVec3;
use serde::Serialize;

use crate::geometry::crossing_curve::CrossingCurve;
use crate::geometry::face_intersection::{faces_intersect, share_a_vertex};
use crate::geometry::self_intersection::pairs_within;
use crate::geometry::triangle::{
    is_degenerate_face, is_degenerate_triangle, triangle_min_angle_deg,
};
use crate::geometry::triangle_intersection::{point_triangle_distance, triangles_within};
use crate::mesh::crossing_guard::{new_faces_intersect, CrossingGuard};
use crate::mesh::edit::{EditMesh, SlotPolicy};
use crate::mesh::TriMesh;

/// The edit mesh of [`untangle`]: each face labelled with its index in the mesh given, `None`
/// once a collapse changed it.
type Mesh = EditMesh<Option<u32>>;

/// Parameters of [`untangle`]. Lengths are in units of σ_p.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct UntangleParams {
    /// Rounds at most (each: find every crossing pair, then move). Default 30.
    pub max_rounds: usize,
    /// How far past the other face's plane a moved vertex goes (> 0; σ_p units). Default 0.01.
    pub margin_sigma_p: f64,
    /// The longest move of a vertex in one round (σ_p units). Default 0.25.
    pub max_step_sigma_p: f64,
    /// Edge collapses at most when moves leave crossing pairs (default 100). Only for pairs that
    /// are the triangulation's own folds, which collapsing their edges removes: where the input
    /// mesh passes through itself or its parts meet (the [`CrossingCurve`] given to
    /// [`untangle`]) a crossing is the input's, and collapses would eat the part.
    pub max_collapses: usize,
    /// How far a collapse may leave the two old positions of its edge from the faces it makes
    /// (σ_p units; the optimization's `collapse_offset_sigma_p`). Default 0.25.
    pub collapse_offset_sigma_p: f64,
    /// Faces nearer than this count as crossing (bbox-100 units, not σ_p; at most a tenth of the
    /// margin is used): faces that would share a point once the mesh is written, whose coordinates
    /// are rounded
    /// ([`Normalization::written_rounding`](crate::internal::Normalization::written_rounding)).
    /// Default 0: the exact test alone.
    pub near: f64,
}

impl Default for UntangleParams {
    fn default() -> Self {
        UntangleParams {
            max_rounds: 30,
            margin_sigma_p: 0.01,
            max_step_sigma_p: 0.25,
            max_collapses: 100,
            collapse_offset_sigma_p: 0.25,
            near: 0.0,
        }
    }
}

/// What [`untangle`] did.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct UntangleStats {
    /// Intersecting pairs of faces before (all kinds).
    pub pairs_before: usize,
    /// Crossing pairs left after (0 unless the rounds ran out).
    pub pairs_after: usize,
    /// Rounds run.
    pub rounds: usize,
    /// Distinct vertices moved (in each run of [`untangle`], summed over runs by [`UntangleStats::then`]).
    pub vertices_moved: usize,
    /// The largest total displacement of a vertex (σ_p units).
    pub max_displacement: f64,
    /// Edges collapsed after the moves (see [`UntangleParams::max_collapses`]).
    pub collapses: usize,
}

impl UntangleStats {
    /// These stats followed by those of a `later` run on the result: the pairs before this
    /// one and after the later one, the rounds, vertices moved (counted once per run) and
    /// collapses of both, the larger displacement.
    pub fn then(&self, later: &UntangleStats) -> UntangleStats {
        UntangleStats {
            pairs_before: self.pairs_before,
            pairs_after: later.pairs_after,
            rounds: self.rounds + later.rounds,
            vertices_moved: self.vertices_moved + later.vertices_moved,
            max_displacement: self.max_displacement.max(later.max_displacement),
            collapses: self.collapses + later.collapses,
        }
    }
}

/// Moves vertices of `mesh` (bbox-100 units) until no two faces intersect
/// ([`intersecting_pairs`](crate::geometry::intersecting_pairs): the standard definition), nor
/// come within `params.near` of intersecting (faces that would touch once written), or
/// `params.max_rounds` rounds have run. In a round the crossing pairs of faces that share no
/// vertex are taken in order (a fold, two faces that share a vertex, is left to the collapses);
/// for a pair that still crosses, the shortest of four moves separates it (for either face: its corners behind the other's plane
/// move along that plane's normal to `margin_sigma_p · σ_p` in front of it, or the other face
/// moves back along its normal until they are; at most `max_step_sigma_p · σ_p` per round). A
/// move of a vertex marked in `fixed` (a boundary sample) counts as four times as long, so
/// those move only when nothing else separates the pair. The moves of a round that made a
/// pair outside the input's own crossings (`input_crossings`) go back, vertex by vertex: a
/// press never trades a crossing where the input crosses for one where it does not. A round
/// that then does not lower the number of crossing pairs, or raises the number outside the
/// input's crossings, or the number that intersect (not merely come within `near`), is undone
/// and tried again with moves half as long (never worse than before). Faces that cross nothing do not move. Then, for pairs still crossing that are not
/// the input's own (both faces reaching into `input_crossings`, where the input's faces cross
/// or its parts meet), edges are collapsed (at most `params.max_collapses`; the only change of
/// connectivity).
///
/// The moves are local and small where the output merely grazes itself, and they press the
/// crossing sheet onto the other where the input itself passes through itself (the output then
/// lies against itself there instead of through it).
pub fn untangle(
    mesh: &mut TriMesh,
    fixed: &[bool],
    sigma_p: f64,
    params: &UntangleParams,
    input_crossings: Option<&CrossingCurve>,
) -> (UntangleStats, Vec<Option<u32>>) {
    let u = untangle_known(mesh, fixed, sigma_p, params, input_crossings, None);
    (u.stats, u.origin)
}

/// What [`untangle_known`] did and left.
pub(crate) struct Untangled {
    pub stats: UntangleStats,
    /// Each face's index before, or `None` for a face a collapse changed.
    pub origin: Vec<Option<u32>>,
    /// When no collapse was made: the pairs of faces (indices into the mesh's triangles,
    /// sorted) left within the parameters' `near` of intersecting, so that a later run on the
    /// same mesh, or a test of its crossings, needs no search.
    pub left: Option<Vec<[u32; 2]>>,
    /// The vertices the rounds moved (`V` flags, the mesh's numbering).
    pub moved: Vec<bool>,
}

/// [`untangle`] starting from `known`, the pairs of faces of `mesh` within `near` of
/// intersecting (with the `near` of `params` as [`untangle`] takes it; `None`: searched for
/// here), also giving the pairs it left.
pub(crate) fn untangle_known(
    mesh: &mut TriMesh,
    fixed: &[bool],
    sigma_p: f64,
    params: &UntangleParams,
    input_crossings: Option<&CrossingCurve>,
    known: Option<Vec<[u32; 2]>>,
) -> Untangled {
    let start = mesh.positions.clone();
    let mut m: Mesh = EditMesh::from_trimesh(mesh, Some, SlotPolicy::Reuse);
    let (triangles, slots) = m.live_faces();
    let mut stats = UntangleStats::default();
    let mut moved = vec![false; m.vertex_count()];
    let margin = params.margin_sigma_p * sigma_p;
    let near = untangle_near(params, sigma_p);
    let mut pairs = match known {
        Some(mut known) => {
            known.sort_unstable();
            known.dedup();
            known
        }
        None => pairs_within(&mesh.positions, &mesh.triangles, near),
    };
    stats.pairs_before = pairs.len();
    // A face's slot is its index in `triangles` when every face is live, as here.
    let in_order = slots.iter().enumerate().all(|(k, &f)| f as usize == k);
    // The rounds move a few vertices each: the pairs are updated around them through a guard
    // whose leaves follow the moves, not searched for again over the whole mesh.
    let mut guard = (!pairs.is_empty() && in_order).then(|| CrossingGuard::within(&m, near));
    drop(slots);
    // The pairs at the current positions from `pairs` (those at the positions before the
    // vertices in `changed` moved).
    let update =
        |m: &Mesh, guard: &mut Option<CrossingGuard>, pairs: &[[u32; 2]], changed: &[u32]| {
            match guard {
                Some(guard) => guard.moved(m, pairs, changed),
                None => pairs_within(m.positions(), &triangles, near),
            }
        };
    // The pairs that lie outside the input's own crossings: a round may trade a pair where the
    // input crosses for nothing, never for one where it does not.
    // A fold (faces that share a vertex) counts as outside wherever it lies: it is mended.
    let outside = |positions: &[DVec3], pairs: &[[u32; 2]]| match input_crossings {
        Some(r) => pairs
            .iter()
            .filter(|&&[f, g]| {
                let (a, b) = (triangles[f as usize], triangles[g as usize]);
                let c = |t: [u32; 3]| t.map(|v| positions[v as usize]);
                !r.holds_faces(a, c(a), b, c(b))
            })
            .count(),
        None => pairs.len(),
    };
    let mut pairs_outside = outside(&mesh.positions, &pairs);
    // Of the pairs, those that intersect (not merely within `near`): a round never trades
    // pairs that only come near each other for pairs that intersect.
    let intersecting = |positions: &[DVec3], pairs: &[[u32; 2]]| {
        pairs
            .iter()
            .filter(|&&[f, g]| {
                let (a, b) = (triangles[f as usize], triangles[g as usize]);
                let c = |t: [u32; 3]| t.map(|v| positions[v as usize]);
                faces_intersect(a, c(a), b, c(b)).is_some()
            })
            .count()
    };
    let mut pairs_intersecting = intersecting(&mesh.positions, &pairs);
    let mut scale = 1.0;
    while !pairs.is_empty() && stats.rounds < params.max_rounds {
        stats.rounds += 1;
        let moves = round_moves(
            &m,
            &triangles,
            &pairs,
            fixed,
            margin,
            scale * params.max_step_sigma_p * sigma_p,
            near,
        );
        if moves.is_empty() {
            break;
        }
        let saved: Vec<(u32, DVec3)> = moves.iter().map(|&(v, _)| (v, m.position(v))).collect();
        let mut relocated = true;
        for &(v, d) in &moves {
            relocated &= m.relocate_vertex(v, m.position(v) + d).is_ok();
        }
        // Moves change positions only: the faces are still `triangles`.
        let vertices: Vec<u32> = moves.iter().map(|&(v, _)| v).collect();
        let mut after = update(&m, &mut guard, &pairs, &vertices);
        // Moves that made a pair outside the input's crossings go back (their vertices only),
        // a few times over, as undoing one move can uncover another pair.
        for _ in 0..UNDO_PASSES {
            let mut made: Vec<u32> = match input_crossings {
                Some(r) => after
                    .iter()
                    .filter(|p| pairs.binary_search(p).is_err())
                    .filter(|&&[f, g]| {
                        let (a, b) = (triangles[f as usize], triangles[g as usize]);
                        let c = |t: [u32; 3]| t.map(|v| m.position(v));
                        !r.holds_faces(a, c(a), b, c(b))
                    })
                    .flat_map(|&[f, g]| {
                        triangles[f as usize]
                            .into_iter()
                            .chain(triangles[g as usize])
                    })
                    .collect(),
                None => Vec::new(),
            };
            made.sort_unstable();
            made.dedup();
            let back: Vec<(u32, DVec3)> = saved
                .iter()
                .copied()
                .filter(|(v, p)| made.binary_search(v).is_ok() && m.position(*v) != *p)
                .collect();
            if back.is_empty() {
                break;
            }
            for &(v, p) in &back {
                let _ = m.relocate_vertex(v, p);
            }
            let vertices: Vec<u32> = back.iter().map(|&(v, _)| v).collect();
            after = update(&m, &mut guard, &after, &vertices);
        }
        let after_outside = outside(m.positions(), &after);
        let after_intersecting = intersecting(m.positions(), &after);
        if relocated
            && after.len() < pairs.len()
            && after_outside <= pairs_outside
            && after_intersecting <= pairs_intersecting
        {
            for &(v, p) in &saved {
                moved[v as usize] |= m.position(v) != p;
            }
            pairs = after;
            pairs_outside = after_outside;
            pairs_intersecting = after_intersecting;
            scale = 1.0;
        } else {
            // Never worse: undo, and try shorter moves next round (three halvings at most).
            for &(v, p) in &saved {
                let _ = m.relocate_vertex(v, p);
            }
            if let Some(guard) = &mut guard {
                // The pairs are those before the round again; the guard follows the positions.
                let vertices: Vec<u32> = saved.iter().map(|&(v, _)| v).collect();
                guard.vertices_moved(&m, &vertices);
            }
            scale *= 0.5;
            if scale < 0.1 {
                break;
            }
        }
    }
    // A pair is the output's own fold unless its faces share no vertex and both lie where the
    // input's faces cross or its parts meet (there a collapse would eat the part).
    let own = |m: &Mesh, [f, g]: [u32; 2]| {
        input_crossings.is_none_or(|r| match (m.face(f), m.face(g)) {
            (Some(t), Some(u)) => !r.holds_faces(t, m.corners(t), u, m.corners(u)),
            _ => true,
        })
    };
    let mut pairs_after = pairs.len();
    let left = pairs.clone();
    if !pairs.is_empty() && params.max_collapses > 0 {
        let offset = params.collapse_offset_sigma_p * sigma_p;
        // The rounds' guard and pairs are those of the mesh as it is now (when every face is
        // live, as here, a face's slot is its index): no search again.
        let found = guard.map(|g| (g, pairs.clone()));
        let (collapses, left) = collapse_folds(
            &mut m,
            fixed,
            params.max_collapses,
            near,
            offset,
            &own,
            found,
        );
        stats.collapses = collapses;
        pairs_after = left;
    }
    // Each face's index before, or None for a face a collapse changed.
    let (positions, triangles, origin) = m.into_parts();
    mesh.positions = positions;
    mesh.triangles = triangles;
    stats.pairs_after = pairs_after;
    stats.vertices_moved = moved.iter().filter(|&&m| m).count();
    stats.max_displacement = mesh
        .positions
        .iter()
        .zip(&start)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max)
        / sigma_p;
    let left = (stats.collapses == 0 && in_order).then_some(left);
    Untangled {
        stats,
        origin,
        left,
        moved,
    }
}

/// The `near` [`untangle`] takes from `params`: at most a tenth of the margin it moves faces
/// apart by (model units as `sigma_p`).
pub(crate) fn untangle_near(params: &UntangleParams, sigma_p: f64) -> f64 {
    params
        .near
        .min(0.1 * params.margin_sigma_p * sigma_p)
        .max(0.0)
}

/// Passes of a round that put back the moves that made a crossing pair outside the input's own
/// crossings.
const UNDO_PASSES: usize = 3;

/// Edges tried per collapse: the shortest edges of the faces still crossing.
const COLLAPSE_CANDIDATES: usize = 16;

/// Collapses edges of crossing faces, one at a time: of the `COLLAPSE_CANDIDATES` shortest edges
/// of the faces of pairs that `own` keeps (neither end `fixed`), each collapsed to its midpoint
/// or to either end, with both old positions of the edge within `offset` of the faces it makes
/// (the optimization's bound on a collapse: a fold at a thin tip is not cut off with the tip),
/// the legal collapse ([`EditMesh::collapse_edge`]) that leaves fewer
/// crossings among the faces it makes than there were among the faces around the edge, and of
/// those the best smallest angle among the faces it makes; until no pair is left to `own`, none
/// helps, or `max` collapses are made. The faces are in a [`CrossingGuard`] (a BVH whose leaves
/// follow the collapses), and the crossing pairs are updated around each collapse: a collapse
/// costs O(log F) per face it tries, not O(F). `found`: such a guard of `m` (built with the same
/// `near`) and the pairs of slots it gives, when the caller has them (else both are made here,
/// with one search of the whole mesh). Returns the collapses made and the crossing pairs left.
/// Deterministic.
#[allow(clippy::too_many_arguments)] // the mesh, its bounds, and what the caller found
fn collapse_folds(
    m: &mut Mesh,
    fixed: &[bool],
    max: usize,
    near: f64,
    offset: f64,
    own: &dyn Fn(&Mesh, [u32; 2]) -> bool,
    found: Option<(CrossingGuard, Vec<[u32; 2]>)>,
) -> (usize, usize) {
    let is_fixed = |v: u32| fixed.get(v as usize).copied().unwrap_or(false);
    // Crossing pairs of slots, each as [f, g] with f < g.
    let (mut guard, mut pairs) = match found {
        Some((guard, pairs)) => {
            let pairs = pairs
                .into_iter()
                .map(|[f, g]| [f.min(g), f.max(g)])
                .collect();
            (guard, pairs)
        }
        None => {
            let (live, slots) = m.live_faces();
            let pairs: Vec<[u32; 2]> = pairs_within(m.positions(), &live, near)
                .into_iter()
                .map(|[f, g]| {
                    let (a, b) = (slots[f as usize], slots[g as usize]);
                    [a.min(b), a.max(b)]
                })
                .collect();
            (CrossingGuard::within(m, near), pairs)
        }
    };
    let mut made = 0;
    while made < max {
        let folds: Vec<[u32; 2]> = pairs.iter().copied().filter(|&p| own(m, p)).collect();
        if folds.is_empty() {
            break;
        }
        let mut edges: Vec<(f64, u32, u32)> = Vec::new();
        for &f in folds.iter().flatten() {
            let Some(t) = m.face(f) else { continue };
            for k in 0..3 {
                let (a, b) = (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]));
                if !is_fixed(a) && !is_fixed(b) {
                    edges.push((m.position(a).distance(m.position(b)), a, b));
                }
            }
        }
        edges.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
        edges.dedup_by(|x, y| (x.1, x.2) == (y.1, y.2));
        // The collapses that lower the crossings around their edge, best smallest angle first.
        let mut better: Vec<(f64, u32, u32, DVec3)> = Vec::new();
        for &(_, a, b) in edges.iter().take(COLLAPSE_CANDIDATES) {
            let around = faces_around_both(m, a, b);
            let before = crossings_around(m, &guard, &around);
            let (pa, pb) = (m.position(a), m.position(b));
            for (removed, kept, at) in [(a, b, 0.5 * (pa + pb)), (a, b, pb), (b, a, pa)] {
                let fan: Vec<[u32; 3]> = around
                    .iter()
                    .filter_map(|&g| m.face(g))
                    .filter(|t| !(t.contains(&removed) && t.contains(&kept)))
                    .map(|t| t.map(|u| if u == removed { kept } else { u }))
                    .collect();
                let corners = |t: [u32; 3]| t.map(|u| if u == kept { at } else { m.position(u) });
                if fan.iter().any(|&t| is_degenerate_triangle(corners(t)))
                    || new_faces_intersect(&fan, corners, near)
                    || [pa, pb].into_iter().any(|p| {
                        fan.iter()
                            .map(|&t| point_triangle_distance(p, corners(t)))
                            .fold(f64::INFINITY, f64::min)
                            > offset
                    })
                {
                    continue;
                }
                let after: usize = fan
                    .iter()
                    .map(|&t| guard.count_crossed(m, t, corners(t), &around))
                    .sum();
                if after >= before {
                    continue;
                }
                let angle = fan
                    .iter()
                    .map(|&t| triangle_min_angle_deg(corners(t)))
                    .fold(f64::INFINITY, f64::min);
                better.push((angle, removed, kept, at));
            }
        }
        better.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
        // The best one the mesh allows (the link condition, protected edges).
        let Some((around, kept)) = better.iter().find_map(|&(_, removed, kept, at)| {
            let around = faces_around_both(m, removed, kept);
            m.collapse_edge(removed, kept, at, None)
                .ok()
                .map(|_| (around, kept))
        }) else {
            break;
        };
        made += 1;
        // The faces around the edge went or changed: their pairs go, the new fan's come in.
        pairs.retain(|p| !p.iter().any(|f| around.contains(f)));
        let fan: Vec<u32> = m.faces_around(kept).to_vec();
        guard.changed(m, &fan);
        for &f in &fan {
            let Some(t) = m.face(f) else { continue };
            guard.visit_crossed(m, t, m.corners(t), &[], |g| {
                // A pair inside the fan once, from its larger slot.
                if !(fan.contains(&g) && g < f) {
                    pairs.push([f.min(g), f.max(g)]);
                }
                false
            });
        }
        pairs.sort_unstable();
        pairs.dedup();
    }
    (made, pairs.len())
}

/// The faces (slots) around `a` or `b`, each once.
fn faces_around_both(m: &Mesh, a: u32, b: u32) -> Vec<u32> {
    let mut faces: Vec<u32> = m.faces_around(a).to_vec();
    faces.extend_from_slice(m.faces_around(b));
    faces.sort_unstable();
    faces.dedup();
    faces
}

/// The crossing pairs of live faces with at least one face in `faces` (slots), as
/// untangle counts them (degenerate faces left out; faces within the
/// guard's `near` count), found through `guard`.
fn crossings_around(m: &Mesh, guard: &CrossingGuard, faces: &[u32]) -> usize {
    let p = m.positions();
    let mut count = 0;
    for &f in faces {
        let Some(t) = m.face(f) else { continue };
        if is_degenerate_face(p, t) {
            continue;
        }
        guard.visit_crossed(m, t, m.corners(t), &[], |g| {
            // A pair inside `faces` is counted once, from its smaller slot.
            let twice = g < f && faces.contains(&g);
            if !twice && m.face(g).is_some_and(|u| !is_degenerate_face(p, u)) {
                count += 1;
            }
            false
        });
    }
    count
}

/// One round's moves for the crossing `pairs`: `(vertex, displacement)`. The pairs are taken in
/// order against the positions as moved so far (a pair an earlier move already separated is
/// skipped), so one move of a vertex poking through a sheet resolves all its pairs.
fn round_moves(
    m: &Mesh,
    triangles: &[[u32; 3]],
    pairs: &[[u32; 2]],
    fixed: &[bool],
    margin: f64,
    max_step: f64,
    near: f64,
) -> Vec<(u32, DVec3)> {
    let is_fixed = |v: u32| fixed.get(v as usize).copied().unwrap_or(false);
    let mut positions = m.positions().to_vec();
    let mut total = vec![DVec3::ZERO; positions.len()];
    let corners = |p: &[DVec3], f: u32| triangles[f as usize].map(|v| p[v as usize]);
    for &[f, g] in pairs {
        // A pair that shares a vertex (a fold) is not separated by pushing one face off the
        // other's plane (the shared corners lie on both): the collapses and the mending after
        // them take it.
        let (a, b) = (triangles[f as usize], triangles[g as usize]);
        if share_a_vertex(a, b)
            || !triangles_within(corners(&positions, f), corners(&positions, g), near)
        {
            continue;
        }
        // Two ways to separate face a from face b: a's corners behind b's plane move forward
        // along b's normal to `margin` in front of it, or (`back`) b's corners move back along
        // its normal until a's deepest corner is `margin` in front of it. Each with the length
        // of its longest move as its cost.
        let option = |a: u32, b: u32, back: bool| -> Option<(f64, Vec<(u32, DVec3)>)> {
            let [p, q, r] = corners(&positions, b);
            let n = (q - p).cross(r - p).try_normalize()?;
            let needs: Vec<(u32, f64)> = triangles[a as usize]
                .iter()
                .map(|&v| (v, margin - n.dot(positions[v as usize] - p)))
                .filter(|&(_, need)| need > 0.0)
                .collect();
            let deepest = needs.iter().map(|x| x.1).fold(0.0f64, f64::max);
            if deepest <= 0.0 {
                return None;
            }
            let moves: Vec<(u32, DVec3)> = if back {
                triangles[b as usize]
                    .iter()
                    .map(|&v| (v, -n * deepest.min(max_step)))
                    .collect()
            } else {
                needs
                    .iter()
                    .map(|&(v, need)| (v, n * need.min(max_step)))
                    .collect()
            };
            // A move of a fixed vertex (a boundary sample, on the input's boundary curve) is
            // the last resort: it counts as four times as long.
            let cost = if moves.iter().any(|&(v, _)| is_fixed(v)) {
                4.0 * deepest
            } else {
                deepest
            };
            Some((cost, moves))
        };
        let best = [
            option(f, g, false),
            option(g, f, false),
            option(f, g, true),
            option(g, f, true),
        ]
        .into_iter()
        .flatten()
        .min_by(|x, y| x.0.total_cmp(&y.0));
        if let Some((_, moves)) = best {
            for (v, d) in moves {
                positions[v as usize] += d;
                total[v as usize] += d;
            }
        }
    }
    total
        .iter()
        .enumerate()
        .filter(|(_, d)| **d != DVec3::ZERO)
        .map(|(v, &d)| (v as u32, d))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::check_invariants;
    use crate::geometry::self_intersection::intersecting_pairs;
    use crate::mesh::test_meshes::grid;

    #[test]
    fn a_dent_through_a_nearby_sheet_is_pulled_back_and_a_clean_mesh_is_left_alone() {
        // Two parallel 6 x 6 grids 0.2 apart; one vertex of the upper one pokes through the
        // lower one.
        let (mut m, off) = crate::mesh::test_meshes::stacked_grids(6);
        let poke = off as usize + 3 * 7 + 3;
        m.positions[poke].z = -0.3;
        assert!(!intersecting_pairs(&m.positions, &m.triangles).is_empty());
        let fixed = vec![false; m.positions.len()];
        let (s, _) = untangle(&mut m, &fixed, 1.0, &UntangleParams::default(), None);
        assert!(s.pairs_before > 0 && s.pairs_after == 0, "{s:?}");
        assert!(
            check_invariants(&m).is_empty(),
            "{:?}",
            check_invariants(&m)
        );
        assert!(s.max_displacement < 0.6, "{s:?}");
        let edited: EditMesh = EditMesh::from_trimesh(&m, |_| (), SlotPolicy::Reuse);
        assert_eq!(edited.sanity_check(), Ok(()));
        // A fixed vertex stays when its partner can give way.
        let mut m2 = m.clone();
        m2.positions[poke].z = -0.3;
        let mut fixed = vec![false; m2.positions.len()];
        fixed[poke] = true;
        let (s, _) = untangle(&mut m2, &fixed, 1.0, &UntangleParams::default(), None);
        assert_eq!(s.pairs_after, 0, "{s:?}");
        assert_eq!(m2.positions[poke].z, -0.3);
        // A mesh without crossings is unchanged.
        let a = grid(6, |i, j| DVec3::new(i as f64, j as f64, 0.0));
        let mut clean = a.clone();
        let none = vec![false; clean.positions.len()];
        let (s, _) = untangle(&mut clean, &none, 1.0, &UntangleParams::default(), None);
        assert_eq!((s.pairs_before, s.rounds, s.vertices_moved), (0, 0, 0));
        assert_eq!(clean.positions, a.positions);
    }

    #[test]
    fn faces_nearer_than_near_are_separated_and_left_when_near_is_zero() {
        // A vertex of the upper of two grids 0.2 apart lowered to 1e-7 above the lower one: no
        // face crosses, but the faces around it would touch once rounded.
        let (mut m, off) = crate::mesh::test_meshes::stacked_grids(6);
        let poke = off as usize + 3 * 7 + 3;
        let below = m.positions[3 * 7 + 3].z;
        m.positions[poke].z = below + 1e-7;
        assert!(intersecting_pairs(&m.positions, &m.triangles).is_empty());
        let fixed = vec![false; m.positions.len()];
        let exact = m.clone();
        let mut left = m.clone();
        let (s, _) = untangle(&mut left, &fixed, 1.0, &UntangleParams::default(), None);
        assert_eq!((s.pairs_before, s.vertices_moved), (0, 0), "{s:?}");
        assert_eq!(left.positions, exact.positions);
        let params = UntangleParams {
            near: 1e-5,
            ..UntangleParams::default()
        };
        let (s, _) = untangle(&mut m, &fixed, 1.0, &params, None);
        assert!(s.pairs_before > 0 && s.pairs_after == 0, "{s:?}");
        assert!(pairs_within(&m.positions, &m.triangles, 1e-5).is_empty());
        // Apart by at least the margin now, by a short move.
        assert!(
            m.positions[poke].z - below >= 0.01 - 1e-12,
            "{}",
            m.positions[poke].z
        );
        assert!(s.max_displacement < 0.05, "{s:?}");
    }

    #[test]
    fn a_press_where_the_input_crosses_makes_no_crossing_where_it_does_not() {
        // The dent of the first test, where the input itself crosses (a region round the
        // dent), and a small sheet D inside the dent's cup, 0.05 over the lower grid: lifting
        // the dent's tip out of the lower grid brings its faces through D.
        let (mut m, off) = crate::mesh::test_meshes::stacked_grids(6);
        let poke = off as usize + 3 * 7 + 3;
        m.positions[poke].z = -0.3;
        let input = m.clone();
        let pairs = intersecting_pairs(&input.positions, &input.triangles);
        let regions = CrossingCurve::new(&input.positions, &input.triangles, &pairs, &[], 0.01);
        let d0 = m.positions.len() as u32;
        let p = m.positions[poke];
        m.positions.extend([
            DVec3::new(p.x - 0.4, p.y - 0.3, 0.05),
            DVec3::new(p.x + 0.4, p.y - 0.3, 0.05),
            DVec3::new(p.x, p.y + 0.4, 0.05),
        ]);
        m.triangles.push([d0, d0 + 1, d0 + 2]);
        assert_eq!(
            intersecting_pairs(&m.positions, &m.triangles).len(),
            pairs.len()
        );
        let fixed = vec![false; m.positions.len()];
        let params = UntangleParams {
            max_collapses: 0,
            ..UntangleParams::default()
        };
        // Without the input's regions every pair is the output's own: the dent is lifted
        // through D and D then moved aside, and nothing is left.
        let mut free = m.clone();
        let (s, _) = untangle(&mut free, &fixed, 1.0, &params, None);
        assert!(s.vertices_moved > 0 && s.pairs_after == 0, "{s:?}");
        // With them, lifting the dent would trade pairs where the input crosses for pairs with
        // D, where it does not: no move is kept, and what is left lies in the region.
        let before = m.positions.clone();
        let (s, _) = untangle(&mut m, &fixed, 1.0, &params, Some(&regions));
        assert_eq!((s.vertices_moved, s.pairs_after), (0, pairs.len()), "{s:?}");
        assert_eq!(m.positions, before);
        let left = intersecting_pairs(&m.positions, &m.triangles);
        assert_eq!(
            regions.count_inside(&m.positions, &m.triangles, &left),
            left.len()
        );
    }

    #[test]
    fn crossing_sheets_that_cannot_be_separated_are_not_made_worse() {
        // A flat grid and a tilted one through it: no small move separates them.
        let a = grid(6, |i, j| DVec3::new(i as f64, j as f64, 0.0));
        let b = grid(6, |i, j| {
            DVec3::new(i as f64 + 0.25, j as f64 + 0.3, 0.1 * i as f64 - 0.26)
        });
        let mut m = a.clone();
        let off = m.positions.len() as u32;
        m.positions.extend(b.positions.iter().copied());
        m.triangles
            .extend(b.triangles.iter().map(|t| t.map(|v| v + off)));
        let fixed = vec![false; m.positions.len()];
        let (s, _) = untangle(&mut m, &fixed, 1.0, &UntangleParams::default(), None);
        assert!(s.pairs_after <= s.pairs_before, "{s:?}");
        assert_eq!(
            s.pairs_after,
            intersecting_pairs(&m.positions, &m.triangles).len()
        );
    }

    #[test]
    fn a_fold_is_collapsed_away_when_asked_and_left_when_not() {
        // A flat 8 x 8 grid with one interior vertex dragged across its neighbours: its fan
        // folds over faces two columns away (coplanar overlaps share an area).
        let mut m = grid(8, |i, j| DVec3::new(i as f64, j as f64, 0.0));
        let v = 4 * 9 + 4;
        m.positions[v] = DVec3::new(6.5, 4.4, 0.0);
        let before = intersecting_pairs(&m.positions, &m.triangles).len();
        assert!(before > 0);
        let fixed = vec![false; m.positions.len()];
        // Collapses only (no move rounds), so the collapses are what is tested, and as far from
        // the old positions as they need.
        let only_collapses = UntangleParams {
            max_rounds: 0,
            max_collapses: 10,
            collapse_offset_sigma_p: f64::INFINITY,
            ..Default::default()
        };
        // A vertex of the upper of two sheets 0.2 apart poked to 0.3 below the lower one: the
        // collapse of the poked vertex leaves its position 0.5 from the faces it makes, more
        // than the optimization's bound (0.25 sigma_p): within the bound the vertex stays (other
        // collapses may lower the crossings); without it, the crossing goes.
        let (mut poked, off) = crate::mesh::test_meshes::stacked_grids(6);
        poked.positions[off as usize + 3 * 7 + 3].z = -0.3;
        let crossing = intersecting_pairs(&poked.positions, &poked.triangles).len();
        assert!(crossing > 0);
        // The lower sheet fixed: only the upper one's edges may go.
        let lower_fixed: Vec<bool> = (0..poked.positions.len())
            .map(|v| v < off as usize)
            .collect();
        let mut bounded = poked.clone();
        let (s, _) = untangle(
            &mut bounded,
            &lower_fixed,
            1.0,
            &UntangleParams {
                collapse_offset_sigma_p: 0.25,
                ..only_collapses
            },
            None,
        );
        assert!(s.pairs_after > 0 && s.pairs_after <= crossing, "{s:?}");
        let tip = off + 3 * 7 + 3;
        assert!(
            bounded.triangles.iter().any(|t| t.contains(&tip)),
            "the poked vertex is collapsed away"
        );
        assert_eq!(bounded.positions[tip as usize].z, -0.3);
        let (s, _) = untangle(&mut poked, &lower_fixed, 1.0, &only_collapses, None);
        assert!(s.collapses >= 1 && s.pairs_after == 0, "{s:?}");
        // A vertex dragged just past its neighbour: collapsing it into that neighbour leaves
        // its old position on the faces made (the grid is flat), within any bound.
        let mut near_fold = grid(8, |i, j| DVec3::new(i as f64, j as f64, 0.0));
        near_fold.positions[v] = DVec3::new(5.4, 4.3, 0.0);
        assert!(!intersecting_pairs(&near_fold.positions, &near_fold.triangles).is_empty());
        let (s, _) = untangle(
            &mut near_fold,
            &fixed,
            1.0,
            &UntangleParams {
                collapse_offset_sigma_p: 1e-9,
                ..only_collapses
            },
            None,
        );
        assert!(s.collapses >= 1, "{s:?}");
        assert!(intersecting_pairs(&near_fold.positions, &near_fold.triangles).is_empty());
        let mut without = m.clone();
        let (s, _) = untangle(
            &mut without,
            &fixed,
            1.0,
            &UntangleParams {
                max_collapses: 0,
                ..only_collapses
            },
            None,
        );
        assert_eq!((s.pairs_after, s.collapses), (before, 0), "{s:?}");
        // Where the input's own faces cross (here: a region over the whole grid), a crossing of
        // faces that share no vertex is the input's, and no collapse eats it: a second flat grid
        // passing upright through the first.
        let everywhere = |m: &TriMesh| {
            CrossingCurve::new(
                &m.positions,
                &m.triangles,
                &[],
                &m.triangles
                    .iter()
                    .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
                    .collect::<Vec<_>>(),
                0.1,
            )
        };
        let mut sheets = grid(8, |i, j| DVec3::new(i as f64, j as f64, 0.0));
        let upright = grid(8, |i, j| DVec3::new(i as f64 + 0.25, 3.5, j as f64 - 3.75));
        let offset = sheets.positions.len() as u32;
        sheets.positions.extend(upright.positions);
        sheets
            .triangles
            .extend(upright.triangles.iter().map(|t| t.map(|v| v + offset)));
        let crossing = intersecting_pairs(&sheets.positions, &sheets.triangles).len();
        assert!(crossing > 0);
        let regions = everywhere(&sheets);
        let fixed_sheets = vec![false; sheets.positions.len()];
        let (s, _) = untangle(
            &mut sheets,
            &fixed_sheets,
            1.0,
            &only_collapses,
            Some(&regions),
        );
        assert_eq!((s.pairs_after, s.collapses), (crossing, 0), "{s:?}");
        // A fold (faces sharing a vertex) is the output's own even there: it is collapsed.
        let mut folded = m.clone();
        let regions = everywhere(&m);
        let (s, _) = untangle(&mut folded, &fixed, 1.0, &only_collapses, Some(&regions));
        assert!(s.collapses >= 1 && s.pairs_after < before, "{s:?}");
        let (s, _) = untangle(&mut m, &fixed, 1.0, &only_collapses, None);
        assert!(s.collapses >= 1 && s.pairs_after == 0, "{s:?}");
        assert!(intersecting_pairs(&m.positions, &m.triangles).is_empty());
        m.remove_unreferenced_vertices();
        assert!(
            check_invariants(&m).is_empty(),
            "{:?}",
            check_invariants(&m)
        );
        let edited: EditMesh = EditMesh::from_trimesh(&m, |_| (), SlotPolicy::Reuse);
        assert_eq!(edited.sanity_check(), Ok(()));
    }
}
