//! The optimization's last pass: the faces whose smallest angle is still below a bound, and
//! the faces that cross another, are mended one by one with the best of a few local operations,
//! each guarded against leaving the input surface and against making a crossing.

use glam::DVec3;

use super::*;
use crate::geometry::crossing_curve::CrossingCurve;
use crate::geometry::face_intersection::share_a_vertex;
use crate::geometry::polygon_triangulation::max_min_triangulation;
use crate::geometry::self_intersection::pairs_within;
use crate::mesh::crossing_guard::CrossingGuard;
use crate::mesh::edit::EditError;
use crate::surface::feature_lines::FeatureLines;
use crate::triangulate::flip::max_min_candidate;

/// One local operation on the mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Op {
    /// Flip the edge `x`–`y`.
    Flip(u32, u32),
    /// Collapse `removed` into `kept`, which moves to the position.
    Collapse(u32, u32, DVec3),
    /// Move the vertex to the position.
    Move(u32, DVec3),
    /// Split the edge `a`–`b` at a new vertex at the position.
    Split(u32, u32, DVec3),
    /// Remove the vertex and triangulate its link anew ([`try_remove`]).
    Remove(u32),
}

/// Mends the faces of `m` whose smallest angle is below `params.final_theta_deg` (worst first;
/// with `near`, only those with a corner marked in it, vertices beyond it unmarked), then the
/// faces that cross another face (the pairs of [`pairs_within`] `params.near`: exact, or nearer
/// than that), in up to
/// `params.final_rounds` rounds. For each such face the candidates are: the max-min flip of each
/// of its edges, the collapse of each of its edges (an end that may move merges into the other,
/// at the other's position or, when both may move, at the surface point nearest the edge's
/// midpoint), and the move of each corner that may move (towards the centroid of its neighbours
/// or the apex of the equilateral triangle on a small-angled face's far edge, all, half or a
/// quarter of the way, projected onto the surface; and to the surface point of best angle score
/// for its faces that a compass search finds, [`best_angle_position`]). A vertex on the boundary
/// moves only along the input's boundary curves `boundary` (none without them: [`slide_targets`]);
/// a fixed vertex on a crease moves only to undo a crossing; other fixed vertices (covering
/// vertices, at the tips of the input) move like the rest, their old position kept within the
/// collapse offset of their faces. Where none of these mends a face that crosses another or
/// folds onto a neighbour, each corner that may move may be removed, its link triangulated
/// anew ([`try_remove`]). Where none of these
/// mends the face, each of its interior edges may be split at a new vertex placed by the same
/// compass search ([`try_split`]; Hu et al.'s edge split): a boundary vertex where the
/// boundary turns by more than 180° and only two faces share the angle gets a third.
///
/// Of the candidates that pass every guard, the one whose new faces have the largest smallest
/// angle is taken: for a face with a small angle, when that angle is larger than the smallest
/// angle of the faces it replaces; for a crossing face, when it is not below the smaller of that
/// and the bound. The guards:
/// - no new face turns by more than `max_normal_turn_deg` from the face it replaces (a flip:
///   from the two old faces' mean normal);
/// - the mesh stays on the surface, within the offset a collapse of the optimization may make
///   (`collapse_offset`): a flip leaves the two faces no farther from the surface than that or
///   than the two old faces were (measured at the surface points nearest the two diagonals'
///   midpoints), a collapse leaves both old positions within it of the new faces, and a move
///   leaves the old position within it of them;
/// - no new face shares a point with a face it has no vertex in common with, nor comes within
///   `params.near` of one (the crossing guard's test, against the faces near it), so the pass
///   makes no crossing, nor faces that touch once written, and a crossing face is replaced only
///   by faces that cross nothing.
///
/// Returns what was done ([`MendStats`]): the operations made and the attempts against the
/// pass's budget ([`MEND_BUDGET_PER_FACE`] per face, at most [`MEND_TRIES_PER_FACE`] failed
/// attempts a face); and the pairs of faces (slots, the smaller first, sorted) that intersect
/// or come within `params.near` of it at the end, as [`pairs_within`] over the live faces gives
/// them. `known`: those pairs as the pass starts, when the caller has them (else searched for
/// over the whole mesh). Deterministic.
#[allow(clippy::too_many_arguments)] // where to work, and the pairs when known
pub(super) fn mend_faces<S: SurfaceQuery + ?Sized>(
    m: &mut Mesh,
    surface: &S,
    boundary: Option<&FeatureLines>,
    input_crossings: Option<&CrossingCurve>,
    fixed: &[bool],
    params: &Limits,
    near: Option<&[bool]>,
    known: Option<Vec<[u32; 2]>>,
) -> (MendStats, Vec<[u32; 2]>) {
    let marked = |t: [u32; 3]| {
        near.is_none_or(|n| {
            t.iter()
                .any(|&v| n.get(v as usize).copied().unwrap_or(false))
        })
    };
    // A crossing inside a region where the input's own faces cross is the input's: it is left
    // as it is (and costs no attempt). A fold (two faces that share a vertex) never is.
    let own = |m: &Mesh, t: [u32; 3]| input_crossings.is_some_and(|r| r.near(m.corners(t)));
    let bound = params.final_theta_deg;
    // The faces to mend: those with a small angle, smallest first, then those that cross
    // another face (of `pairs`, the intersecting pairs of live slots).
    let targets = |m: &Mesh, pairs: &[[u32; 2]]| -> Vec<u32> {
        let (live, slots) = m.live_faces();
        let mut small: Vec<(f64, u32)> = live
            .iter()
            .zip(&slots)
            .filter(|&(&t, _)| marked(t))
            .map(|(&t, &f)| (angle_score(m, t, params), f))
            .filter(|&(a, _)| a < bound)
            .collect();
        small.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut out: Vec<u32> = small.into_iter().map(|x| x.1).collect();
        let mut crossing: Vec<u32> = pairs
            .iter()
            .filter(|&&[f, g]| {
                let (t, u) = (face(m, f), face(m, g));
                share_a_vertex(t, u) || !own(m, t) || !own(m, u)
            })
            .flatten()
            .copied()
            .collect();
        crossing.sort_unstable();
        crossing.dedup();
        out.extend(crossing);
        out
    };
    // The intersecting pairs (slots, the smaller first, sorted): `known`, or searched over the
    // whole mesh once, then after each round only around the faces the round made or moved
    // (the pairs of faces it left alone stand), through the guard.
    let mut pairs: Vec<[u32; 2]> = if let Some(mut known) = known {
        for p in known.iter_mut() {
            *p = [p[0].min(p[1]), p[0].max(p[1])];
        }
        known.sort_unstable();
        known.dedup();
        known
    } else {
        let (live, slots) = m.live_faces();
        let mut pairs: Vec<[u32; 2]> = pairs_within(m.positions(), &live, params.near)
            .into_iter()
            .map(|[f, g]| {
                let (a, b) = (slots[f as usize], slots[g as usize]);
                [a.min(b), a.max(b)]
            })
            .collect();
        pairs.sort_unstable();
        pairs
    };
    let mut faces = targets(m, &pairs);
    let mut stats = MendStats {
        budget: MEND_BUDGET_PER_FACE * m.live_faces().0.len() + MEND_BUDGET_BASE,
        ..MendStats::default()
    };
    if faces.is_empty() {
        stats.left = faces_left(m, params, |t| own(m, t));
        return (stats, pairs);
    }
    let mut guard = CrossingGuard::within(m, params.near);
    let is_fixed = |v: u32| fixed.get(v as usize).copied().unwrap_or(false);
    // The failed attempts at each face slot, and the vertices the previous round's operations
    // touched (`None` in the first round, when every target is tried): a later round tries a
    // face again only where an operation changed its neighbourhood, so it costs what the
    // round before it touched.
    let mut tries: Vec<u8> = vec![0; m.slots()];
    let mut touched_before: Option<Vec<bool>> = None;
    // The slots the round's operations made or moved, and the update of the pairs around them.
    let mut changed: Vec<u32> = Vec::new();
    let update =
        |m: &Mesh, guard: &CrossingGuard, pairs: &mut Vec<[u32; 2]>, changed: &mut Vec<u32>| {
            changed.sort_unstable();
            changed.dedup();
            pairs.retain(|p| {
                p.iter()
                    .all(|&f| m.face(f).is_some() && changed.binary_search(&f).is_err())
            });
            pairs.extend(guard.pairs_with(m, changed));
            pairs.sort_unstable();
            pairs.dedup();
            changed.clear();
        };
    'rounds: for _ in 0..params.final_rounds {
        let mut made = 0;
        let mut touched = vec![false; m.vertex_count()];
        // The faces in a pair as the round starts (sorted slots): no operation makes a pair
        // (the crossing guard refuses it), so no other face crosses one during the round.
        let mut paired: Vec<u32> = pairs.iter().flatten().copied().collect();
        paired.sort_unstable();
        paired.dedup();
        for &f in &faces {
            let Some(t) = m.face(f) else {
                continue;
            };
            let slot_tries = tries.get(f as usize).copied().unwrap_or(0);
            if slot_tries as usize >= MEND_TRIES_PER_FACE {
                continue;
            }
            // A face that crosses another is mended by any operation that replaces or moves it
            // without a crossing or a new angle below the bound; there, a covering vertex may
            // go too. A face with a small angle is mended by one that raises that angle.
            let crossing = paired.binary_search(&f).is_ok()
                && guard.visit_crossed(m, t, m.corners(t), &[f], |g| {
                    !own(m, t) || m.face(g).is_some_and(|u| share_a_vertex(t, u))
                });
            if !crossing && angle_score(m, t, params) >= bound {
                continue;
            }
            // After the first round, a face with a small angle is tried again only where an
            // operation changed its neighbourhood (a crossing face also when its partner moved,
            // which its own corners do not show).
            if let Some(before) = &touched_before {
                if !crossing
                    && !t
                        .iter()
                        .any(|&v| before.get(v as usize).copied().unwrap_or(true))
                {
                    continue;
                }
            }
            if stats.attempts >= stats.budget {
                stats.exhausted = true;
                break 'rounds;
            }
            stats.attempts += 1;
            let stays = |m: &Mesh, v: u32| {
                (is_fixed(v) && !crossing && m.ring(v).iter().any(|&u| m.is_protected(v, u)))
                    || m.is_boundary_vertex(v)
            };
            let mut best: Option<(f64, Op)> = None;
            // Whether an operation taking the smallest angle score from `old` to `new` would be
            // taken over `best`: only then are its new faces tested for crossings (the costly
            // guard), which gives the same choices.
            let better = |best: &Option<(f64, Op)>, old: f64, new: f64| {
                let good = if crossing {
                    new >= old.min(bound)
                } else {
                    new > old + IMPROVEMENT_TOLERANCE
                };
                good && best.is_none_or(|b| new > b.0)
            };
            let offer = |best: &mut Option<(f64, Op)>, value: Option<(f64, f64)>, op: Op| {
                let Some((old, new)) = value else {
                    return;
                };
                if better(best, old, new) {
                    *best = Some((new, op));
                }
            };
            for k in 0..3 {
                let (x, y) = (t[k], t[(k + 1) % 3]);
                let worth = |old, new| better(&best, old, new);
                let value = try_flip(m, surface, &guard, x, y, params, &worth);
                offer(&mut best, value, Op::Flip(x, y));
                for (removed, kept) in [(x, y), (y, x)] {
                    if stays(m, removed) {
                        continue;
                    }
                    let (pk, pr) = (m.position(kept), m.position(removed));
                    let mut aims = vec![pk];
                    if !stays(m, kept) {
                        if let Some(sp) = surface.closest_point_to_midpoint(pk, pr) {
                            aims.push(sp.position);
                        }
                    }
                    for q in aims {
                        let worth = |old, new| better(&best, old, new);
                        let value = try_collapse(m, &guard, removed, kept, q, params, &worth);
                        offer(&mut best, value, Op::Collapse(removed, kept, q));
                    }
                }
            }
            for &v in &t {
                if let (Some(lines), true) = (boundary, m.is_boundary_vertex(v)) {
                    // A boundary vertex moves along the input's boundary only.
                    if let Some(q) = slide_targets(m, lines, v, params) {
                        let worth = |old, new| better(&best, old, new);
                        let value = try_move(m, &guard, v, q, params, &worth);
                        offer(&mut best, value, Op::Move(v, q));
                    }
                    continue;
                }
                if stays(m, v) {
                    continue;
                }
                for q in move_targets(m, surface, v, params) {
                    let worth = |old, new| better(&best, old, new);
                    let value = try_move(m, &guard, v, q, params, &worth);
                    offer(&mut best, value, Op::Move(v, q));
                }
            }
            // Only where nothing else mends it, a face that crosses another (or folds onto a
            // neighbour) may lose a corner: the corner's link triangulated anew on the side of
            // the fan's mean normal, which unfolds a fan that the other operations, each
            // comparing with the folded faces' turned-over normals, cannot.
            if crossing && best.is_none() {
                for &v in &t {
                    if !stays(m, v) {
                        if let Some((value, _)) = try_remove(m, &guard, v, params) {
                            offer(&mut best, Some(value), Op::Remove(v));
                        }
                    }
                }
            }
            // Only where nothing else mends the face, one of its edges is split at the surface
            // point nearest its middle (a vertex with too few faces for the angle around it,
            // such as a boundary vertex where the boundary turns, gets one more).
            if best.is_none() {
                if let Some((x, y)) = opposite_largest_angle(m, t, params) {
                    if let Some((value, q)) = try_split(m, surface, &guard, x, y, params) {
                        offer(&mut best, Some(value), Op::Split(x, y, q));
                    }
                }
            }
            let Some((_, op)) = best else {
                if f as usize >= tries.len() {
                    tries.resize(f as usize + 1, 0);
                }
                tries[f as usize] = slot_tries + 1;
                continue;
            };
            let applied = match op {
                Op::Flip(x, y) => m.flip_edge(x, y, None).map(|s| s.to_vec()),
                Op::Collapse(removed, kept, q) => m
                    .collapse_edge(removed, kept, q, None)
                    .map(|_| m.faces_around(kept).to_vec()),
                Op::Move(v, q) => m.relocate_vertex(v, q).map(|_| m.faces_around(v).to_vec()),
                Op::Split(x, y, q) => {
                    let v = m.add_vertex(q);
                    let split = m.split_edge(x, y, v, None).map(|s| s.to_vec());
                    if split.is_err() {
                        m.pop_vertex();
                    }
                    split
                }
                Op::Remove(v) => match try_remove(m, &guard, v, params) {
                    Some((_, new)) => remove_vertex(m, v, &new),
                    None => Err(EditError::NoSuchVertex { vertex: v }),
                },
            };
            if let Ok(slots) = applied {
                guard.changed(m, &slots);
                changed.extend_from_slice(&slots);
                made += 1;
                touched.resize(m.vertex_count(), false);
                // The changed faces' corners and their rings: every face whose candidate
                // operations (a flip or collapse of its edges, a move of its corners) now see
                // a changed face.
                for &g in &slots {
                    if let Some(u) = m.face(g) {
                        for v in u {
                            touched[v as usize] = true;
                            for w in m.ring(v) {
                                touched[w as usize] = true;
                            }
                        }
                    }
                }
            }
        }
        stats.ops += made;
        if made == 0 {
            break;
        }
        touched_before = Some(touched);
        update(m, &guard, &mut pairs, &mut changed);
        faces = targets(m, &pairs);
        if faces.is_empty() {
            break;
        }
    }
    // A round the budget cut short: its changes too.
    if !changed.is_empty() {
        update(m, &guard, &mut pairs, &mut changed);
    }
    stats.left = faces_left(m, params, |t| own(m, t));
    (stats, pairs)
}

/// The faces still outside the angle bounds, each counted once under the first reason that
/// holds: a corner on a kept crease (where creases meet at a smaller angle than the bound, or
/// a crease turns, no face there can be in bounds), on the boundary, inside a region where the
/// input's own faces cross (`own`), or none of these.
fn faces_left(m: &Mesh, params: &Limits, own: impl Fn([u32; 3]) -> bool) -> FacesLeft {
    let mut left = FacesLeft::default();
    let (live, _) = m.live_faces();
    for t in live {
        if angle_score(m, t, params) >= params.final_theta_deg {
            continue;
        }
        left.total += 1;
        if t.iter()
            .any(|&v| m.ring(v).iter().any(|&u| m.is_protected(v, u)))
        {
            left.at_creases += 1;
        } else if t.iter().any(|&v| m.is_boundary_vertex(v)) {
            left.on_boundary += 1;
        } else if own(t) {
            left.at_input_crossings += 1;
        }
    }
    left
}

/// The faces the last pass leaves outside the angle bounds, by where they are (see
/// [`MendStats::left`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct FacesLeft {
    /// All of them.
    pub total: usize,
    /// With a corner on a kept crease.
    pub at_creases: usize,
    /// Of the rest, with a corner on the boundary.
    pub on_boundary: usize,
    /// Of the rest, where the input's own faces cross.
    pub at_input_crossings: usize,
}

/// Failed mend attempts per face slot over the whole pass at most: a face that no operation
/// mends is tried again only where an operation changed its neighbourhood (or while it crosses
/// another), and at most this often; attempts that mend count against the pass's budget only.
const MEND_TRIES_PER_FACE: usize = 3;

/// The pass's budget of mend attempts: this many per face of the mesh it starts from, plus
/// [`MEND_BUDGET_BASE`]. Each attempt evaluates a bounded number of candidate operations (3
/// flips, up to 12 collapses, up to 3 · (1 + 3 · 8) moves and one split, each compass search at
/// most 64 · 8 surface projections), so the pass costs O(faces · log) with that constant.
const MEND_BUDGET_PER_FACE: usize = 2;

/// The budget's floor, for tiny meshes.
const MEND_BUDGET_BASE: usize = 64;

/// What the optimization's last pass (the mending of faces outside the angle bounds or
/// crossing another) did and what it was allowed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct MendStats {
    /// Operations applied (flips, collapses, moves, splits).
    pub ops: usize,
    /// Faces tried (each a bounded number of candidate operations).
    pub attempts: usize,
    /// The most attempts allowed: 2 per face of the mesh the pass starts from, plus 64.
    pub budget: usize,
    /// Whether the pass stopped because the budget ran out.
    pub exhausted: bool,
    /// The faces it left outside the angle bounds, by where they are.
    pub left: FacesLeft,
}

impl MendStats {
    /// These stats followed by those of a `later` pass on the result: the operations,
    /// attempts and budgets of both, whether either ran out, and the faces the later one left.
    pub fn then(&self, later: &MendStats) -> MendStats {
        MendStats {
            ops: self.ops + later.ops,
            attempts: self.attempts + later.attempts,
            budget: self.budget + later.budget,
            exhausted: self.exhausted || later.exhausted,
            left: later.left,
        }
    }
}

/// The smallest angle of the faces `t`, degrees (infinity for none).
fn worst_angle(m: &Mesh, faces: impl IntoIterator<Item = [u32; 3]>, params: &Limits) -> f64 {
    faces
        .into_iter()
        .map(|t| angle_score(m, t, params))
        .fold(f64::INFINITY, f64::min)
}

/// Whether an operation that takes the smallest angle score from the first value to the second
/// is worth the crossing guard: the operations below test crossings, the costliest guard, last
/// and only when it says yes.
type Worth<'a> = &'a dyn Fn(f64, f64) -> bool;

/// The smallest angle of the two faces the max-min flip of `x`–`y` makes, when it passes the
/// guards of [`mend_faces`].
fn try_flip<S: SurfaceQuery + ?Sized>(
    m: &Mesh,
    surface: &S,
    guard: &CrossingGuard,
    x: u32,
    y: u32,
    params: &Limits,
    worth: Worth<'_>,
) -> Option<(f64, f64)> {
    let flip = max_min_candidate(m, x, y)?;
    let [t1, t2] = flip.old;
    let [new1, new2] = flip.new;
    let (c, d) = (t1[2], t2[2]);
    let mean_old = normal(m, t1) + normal(m, t2);
    let (m1, m2) = (normal(m, new1), normal(m, new2));
    let cos_turn = params.max_normal_turn_deg.to_radians().cos();
    let mean = mean_old.normalize_or_zero();
    if m1.dot(mean) < cos_turn || m2.dot(mean) < cos_turn || m1.dot(m2) < 0.0 {
        return None;
    }
    // How far each pair of faces is from the surface: at the surface points nearest the two
    // diagonals' midpoints.
    let (px, py, pc, pd) = (m.position(x), m.position(y), m.position(c), m.position(d));
    let old_mid = surface.closest_point_to_midpoint(px, py)?;
    let new_mid = surface.closest_point_to_midpoint(pc, pd)?;
    let old_off = old_mid
        .distance
        .max(distance_to(m, flip.old, new_mid.position));
    let new_off = new_mid
        .distance
        .max(distance_to(m, flip.new, old_mid.position));
    let old = worst_angle(m, flip.old, params);
    let new = worst_angle(m, flip.new, params);
    if new_off > params.collapse_offset.max(old_off) || !worth(old, new) {
        return None;
    }
    if guard.crosses(m, &flip.new, &flip.slots) {
        return None;
    }
    Some((old, new))
}

/// The smallest angle of the faces the collapse of `removed` into `kept` at `q` makes, when it
/// passes the guards of [`mend_faces`].
fn try_collapse(
    m: &mut Mesh,
    guard: &CrossingGuard,
    removed: u32,
    kept: u32,
    q: DVec3,
    params: &Limits,
    worth: Worth<'_>,
) -> Option<(f64, f64)> {
    let (f1, f2, c, d) = m.edge_faces(removed, kept).ok()?;
    if !collapse_keeps_links(m, removed, kept, c, d) {
        return None;
    }
    let involved = faces_around_edge(m, removed, kept, f1, f2);
    let old_faces: Vec<[u32; 3]> = involved
        .iter()
        .chain([&f1, &f2])
        .map(|&g| face(m, g))
        .collect();
    let old = worst_angle(m, old_faces.iter().copied(), params);
    let old_normals: Vec<DVec3> = involved.iter().map(|&g| normal(m, face(m, g))).collect();
    let (pa, pb) = (m.position(removed), m.position(kept));
    let new_faces: Vec<[u32; 3]> = involved
        .iter()
        .map(|&g| face(m, g).map(|u| if u == removed { kept } else { u }))
        .collect();
    m.relocate_vertex(kept, q).ok()?;
    let cos_turn = params.max_normal_turn_deg.to_radians().cos();
    let turned = turned(m, &new_faces, &old_normals, cos_turn);
    let near = distance_to(m, new_faces.iter().copied(), pa) <= params.collapse_offset
        && distance_to(m, new_faces.iter().copied(), pb) <= params.collapse_offset;
    let new = worst_angle(m, new_faces.iter().copied(), params);
    let mut replaced = involved.clone();
    replaced.extend([f1, f2]);
    let ok = !turned && near && worth(old, new) && !guard.crosses(m, &new_faces, &replaced);
    // The old position was finite: restoring it cannot fail.
    let _ = m.relocate_vertex(kept, pb);
    ok.then_some((old, new))
}

/// Where a move of `v` is tried: towards the centroid of its neighbours and towards the apex of
/// the equilateral triangle on the far edge of each of its faces with an angle below `bound`
/// (all the way, half and a quarter of the way), projected onto the surface.
fn move_targets<S: SurfaceQuery + ?Sized>(
    m: &Mesh,
    surface: &S,
    v: u32,
    params: &Limits,
) -> Vec<DVec3> {
    let old = m.position(v);
    let ring = m.ring(v);
    if ring.is_empty() {
        return Vec::new();
    }
    let centroid = ring
        .iter()
        .map(|&u| m.position(u))
        .fold(DVec3::ZERO, |a, b| a + b)
        / ring.len() as f64;
    let mut aims = vec![centroid];
    for &f in m.faces_around(v) {
        let t = starting_at(face(m, f), v);
        if angle_score(m, t, params) >= params.final_theta_deg {
            continue;
        }
        aims.extend(equilateral_apex(old, m.position(t[1]), m.position(t[2])));
    }
    let mut targets: Vec<DVec3> = aims
        .iter()
        .flat_map(|&a| [1.0, 0.5, 0.25].map(|s| old.lerp(a, s)))
        // The vertex lies on the surface (or near it): its distance bounds the search.
        .filter_map(|p| {
            surface
                .closest_point_hinted(p, p.distance(old), f64::MAX)
                .map(|sp| sp.position)
        })
        .collect();
    targets.extend(best_angle_position(m, surface, v, params));
    targets
}

/// How far along each of its boundary edges a boundary vertex is tried, as fractions of the edge
/// (less than half: the vertex stays between its neighbours on the boundary).
const SLIDE_FRACTIONS: [f64; 4] = [0.1, 0.2, 0.3, 0.4];

/// Where a move of the boundary vertex `v` is tried: of the points along each of its two
/// boundary edges by [`SLIDE_FRACTIONS`] of the edge, projected onto the input's boundary curves
/// `lines`, the one of best angle score for its faces ([`ring_score`]), when that is better than
/// where `v` is (a projection that lands farther from the edge's point than a quarter of the way
/// there, onto another stretch of boundary, is left out). None for a vertex on more or fewer
/// than two boundary edges or on a crease (a corner of the boundary, or the end of a crease on
/// it).
fn slide_targets(m: &Mesh, lines: &FeatureLines, v: u32, params: &Limits) -> Option<DVec3> {
    let ring = m.ring(v);
    if ring.iter().any(|&u| m.is_protected(v, u)) {
        return None;
    }
    let along: Vec<u32> = ring
        .into_iter()
        .filter(|&u| m.face_on(v, u).is_none() || m.face_on(u, v).is_none())
        .collect();
    let [a, b] = along[..] else {
        return None;
    };
    let faces = ring_of(m, v);
    let bounds = params.angle_bounds();
    let p = m.position(v);
    let (best, _) = [a, b]
        .into_iter()
        .flat_map(|u| SLIDE_FRACTIONS.map(|s| (u, s)))
        .filter_map(|(u, s)| {
            let aim = p.lerp(m.position(u), s);
            let q = lines.closest_point(aim);
            (q.distance(aim) <= 0.25 * aim.distance(p)).then_some(q)
        })
        .map(|q| (q, ring_score(&faces, q, &bounds)))
        .fold((p, ring_score(&faces, p, &bounds)), |best, c| {
            if c.1 > best.1 + IMPROVEMENT_TOLERANCE {
                c
            } else {
                best
            }
        });
    (best != p).then_some(best)
}

/// The faces around `v` as their two other corners, in order (the ring [`ring_score`] scores).
fn ring_of(m: &Mesh, v: u32) -> Vec<[DVec3; 2]> {
    m.faces_around(v)
        .iter()
        .map(|&f| {
            let t = starting_at(face(m, f), v);
            [m.position(t[1]), m.position(t[2])]
        })
        .collect()
}

/// The position of `v` on the surface that raises the smallest angle score of its faces most,
/// by a compass search in its tangent plane (8 directions, the step halved when none helps,
/// from a quarter of its mean edge down to 1/64 of it; each point projected onto the surface):
/// the vertex relocation of Hu et al. ("Error-bounded and feature preserving surface remeshing
/// with minimal angle improvement", TVCG 2017, Sec. 5), which raises the worst angle of a ring
/// that neither the centroid nor an equilateral apex does. `None` when no step helps.
fn best_angle_position<S: SurfaceQuery + ?Sized>(
    m: &Mesh,
    surface: &S,
    v: u32,
    params: &Limits,
) -> Option<DVec3> {
    let ring = ring_of(m, v);
    let old = m.position(v);
    let best = compass_search(surface, &ring, old, params);
    (best != old).then_some(best)
}

/// The position on the surface, from `start`, of the largest smallest angle score of the faces
/// `[p, ring[i][0], ring[i][1]]` around a vertex at p: a compass search in the plane of their
/// mean normal, 8 directions, the step halved when none helps, from a quarter of the mean edge
/// down to 1/64 of it; the compass points are scored in the plane and only a round's best is
/// projected onto the surface (and taken when it helps there too: one projection a round, not
/// eight, as the projections were a large share of the time; see
/// `docs/decisions/last-pass-compass.md`). `start` when no step helps.
fn compass_search<S: SurfaceQuery + ?Sized>(
    surface: &S,
    ring: &[[DVec3; 2]],
    start: DVec3,
    params: &Limits,
) -> DVec3 {
    let old = start;
    let n = ring
        .iter()
        .map(|&[b, c]| (b - old).cross(c - old).normalize_or_zero())
        .fold(DVec3::ZERO, |a, b| a + b)
        .normalize_or_zero();
    if ring.is_empty() || n == DVec3::ZERO {
        return start;
    }
    let bounds = params.angle_bounds();
    let score = |p: DVec3| ring_score(ring, p, &bounds);
    let mean_edge = ring.iter().map(|&[b, _]| old.distance(b)).sum::<f64>() / ring.len() as f64;
    let (u, w) = n.any_orthonormal_pair();
    let (mut best_p, mut best) = (old, score(old));
    let mut step = 0.25 * mean_edge;
    // Each round raises the score or halves the step; a round cap bounds the work.
    for _ in 0..64 {
        if step < mean_edge / 64.0 {
            break;
        }
        // The eight compass points in the tangent plane are scored as they are; only the best
        // of them is projected onto the surface (best_p lies on it, `step` from the point: the
        // search stays that near), and taken when it still raises the score there.
        let (mut aim, mut aim_score) = (best_p, best);
        for k in 0..8 {
            let a = k as f64 * std::f64::consts::FRAC_PI_4;
            let q = best_p + step * (a.cos() * u + a.sin() * w);
            let s = score(q);
            if s > aim_score {
                (aim, aim_score) = (q, s);
            }
        }
        let mut improved = false;
        if aim_score > best + IMPROVEMENT_TOLERANCE {
            if let Some(sp) = surface.closest_point_hinted(aim, step, f64::MAX) {
                let s = score(sp.position);
                if s > best + IMPROVEMENT_TOLERANCE {
                    (best_p, best) = (sp.position, s);
                    improved = true;
                }
            }
        }
        if !improved {
            step *= 0.5;
        }
    }
    best_p
}

/// The smallest angle score (`bounds`) of the faces `[p, ring[i][0], ring[i][1]]` around a vertex
/// at `p` (each face's other corners in order, as [`starting_at`] gives them).
fn ring_score(ring: &[[DVec3; 2]], p: DVec3, bounds: &AngleBounds) -> f64 {
    ring.iter()
        .map(|&[b, c]| bounds.score([p, b, c]))
        .fold(f64::INFINITY, f64::min)
}

/// The smallest angle of the faces around `v` once it is at `q`, when the move passes the
/// guards of [`mend_faces`].
fn try_move(
    m: &mut Mesh,
    guard: &CrossingGuard,
    v: u32,
    q: DVec3,
    params: &Limits,
    worth: Worth<'_>,
) -> Option<(f64, f64)> {
    let slots = m.faces_around(v).to_vec();
    let faces: Vec<[u32; 3]> = slots.iter().map(|&f| face(m, f)).collect();
    let old = worst_angle(m, faces.iter().copied(), params);
    let old_normals: Vec<DVec3> = faces.iter().map(|&t| normal(m, t)).collect();
    let p = m.position(v);
    m.relocate_vertex(v, q).ok()?;
    let cos_turn = params.max_normal_turn_deg.to_radians().cos();
    let turned = turned(m, &faces, &old_normals, cos_turn);
    let new = worst_angle(m, faces.iter().copied(), params);
    let ok = !turned
        && distance_to(m, faces.iter().copied(), p) <= params.collapse_offset
        && worth(old, new)
        && !guard.crosses(m, &faces, &slots);
    let _ = m.relocate_vertex(v, p);
    ok.then_some((old, new))
}

/// A vertex removal's smallest angle scores before and after, and the faces it makes.
type Removal = ((f64, f64), Vec<[u32; 3]>);

/// The link of the interior vertex `v`: its neighbours in the order of its faces (each face
/// `[v, a, b]` gives the link edge a → b), or `None` when its faces do not make one closed fan
/// with distinct neighbours (a boundary vertex, a pinched fan).
fn link_of(m: &Mesh, v: u32) -> Option<Vec<u32>> {
    let faces = m.faces_around(v);
    let edges: Vec<[u32; 2]> = faces
        .iter()
        .map(|&f| {
            let t = starting_at(face(m, f), v);
            [t[1], t[2]]
        })
        .collect();
    let mut link = vec![edges.first()?[0]];
    for _ in 0..edges.len() {
        let last = *link.last()?;
        let next = edges.iter().find(|e| e[0] == last)?[1];
        link.push(next);
    }
    // Closed after as many steps as faces, through distinct neighbours.
    if link.pop() != Some(link[0]) {
        return None;
    }
    let mut sorted = link.clone();
    sorted.sort_unstable();
    sorted.dedup();
    (sorted.len() == edges.len() && edges.len() >= 3).then_some(link)
}

/// The smallest angle scores of the faces around `v` and of the faces that replace them when
/// `v` is removed and its link ([`link_of`]) is triangulated anew, with those faces, when the
/// removal passes the guards of [`mend_faces`]. The new faces are the triangulation of the link
/// of largest smallest angle score ([`max_min_triangulation`]) among those with no diagonal
/// that is already an edge and every face facing the side of the link's own normal (Newell's:
/// the fan's mean orientation, which folded faces do not turn over as they turn their own
/// normals; the other operations' turn guard compares with those); the old position of `v`
/// stays within `collapse_offset` of them and none crosses another face or another new face.
/// The vertex removal of Schroeder et al. ("Decimation of triangle meshes", SIGGRAPH 1992),
/// here a mend: it replaces a fan folded over itself or onto a neighbour.
fn try_remove(m: &Mesh, guard: &CrossingGuard, v: u32, params: &Limits) -> Option<Removal> {
    let link = link_of(m, v)?;
    let pts: Vec<DVec3> = link.iter().map(|&u| m.position(u)).collect();
    let center = pts.iter().sum::<DVec3>() / pts.len() as f64;
    let n_ref = (0..pts.len())
        .map(|i| (pts[i] - center).cross(pts[(i + 1) % pts.len()] - center))
        .sum::<DVec3>()
        .try_normalize()?;
    let new = max_min_triangulation(
        &link,
        |a, b| !m.has_edge(a, b),
        |t| {
            if normal(m, t).dot(n_ref) <= 0.0 {
                -1.0
            } else {
                angle_score(m, t, params)
            }
        },
    )?;
    let slots = m.faces_around(v).to_vec();
    let old = worst_angle(m, slots.iter().map(|&f| face(m, f)), params);
    if distance_to(m, new.iter().copied(), m.position(v)) > params.collapse_offset
        || guard.crosses(m, &new, &slots)
    {
        return None;
    }
    let value = worst_angle(m, new.iter().copied(), params);
    Some(((old, value), new))
}

/// Removes the faces around `v` and fills the hole with `new` (its link's triangulation, as
/// [`try_remove`] gives it): the new faces' slots. `v` is left unreferenced.
/// On an error the old faces are put back (in new slots) and the error returned.
fn remove_vertex(m: &mut Mesh, v: u32, new: &[[u32; 3]]) -> Result<Vec<u32>, EditError> {
    let old: Vec<(u32, [u32; 3])> = m.faces_around(v).iter().map(|&f| (f, face(m, f))).collect();
    for &(f, _) in &old {
        m.remove_face(f)?;
    }
    m.fill_hole(new, None).inspect_err(|_| {
        let faces: Vec<[u32; 3]> = old.iter().map(|&(_, t)| t).collect();
        // The faces were there a moment ago: their edges are free again.
        let _ = m.fill_hole(&faces, None);
    })
}

/// The edge of `t` opposite its largest angle, when that angle is above the bound
/// (`final_theta_max_deg`): the edge a split mends it by (the new edge to the split point cuts
/// the angle in two).
fn opposite_largest_angle(m: &Mesh, t: [u32; 3], params: &Limits) -> Option<(u32, u32)> {
    let p = m.corners(t);
    let angle = |k: usize| {
        let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
        (b - a).angle_between(c - a).to_degrees()
    };
    let k = (0..3).max_by(|&i, &j| angle(i).total_cmp(&angle(j)))?;
    (angle(k) > params.final_theta_max_deg).then_some((t[(k + 1) % 3], t[(k + 2) % 3]))
}

/// The smallest angle scores before and after splitting the interior edge `a`–`b` at the surface
/// point nearest its middle, and that point, when the split passes the guards of
/// [`mend_faces`]: no new face turns by more than `max_normal_turn_deg` from the face it is cut
/// from, the new vertex is within `collapse_offset` of the edge's middle (not on a sheet across
/// a thin part), and no new face crosses another. `None` for a boundary or protected edge.
fn try_split<S: SurfaceQuery + ?Sized>(
    m: &mut Mesh,
    surface: &S,
    guard: &CrossingGuard,
    a: u32,
    b: u32,
    params: &Limits,
) -> Option<((f64, f64), DVec3)> {
    if m.is_protected(a, b) {
        return None;
    }
    let (f1, f2, c, d) = m.edge_faces(a, b).ok()?;
    let (pa, pb) = (m.position(a), m.position(b));
    let mid = surface.closest_point_to_midpoint(pa, pb)?.position;
    // The new vertex's ring, and its best position from the edge's middle.
    let [qa, qb, qc, qd] = [a, b, c, d].map(|v| m.position(v));
    let q = compass_search(
        surface,
        &[[qc, qa], [qb, qc], [qd, qb], [qa, qd]],
        mid,
        params,
    );
    if q.distance(0.5 * (pa + pb)) > params.collapse_offset {
        return None;
    }
    let old_faces = [face(m, f1), face(m, f2)];
    let old = worst_angle(m, old_faces, params);
    let old_normals = old_faces.map(|t| normal(m, t));
    let v = m.add_vertex(q);
    let new = [[a, v, c], [v, b, c], [b, v, d], [v, a, d]];
    let cos_turn = params.max_normal_turn_deg.to_radians().cos();
    let ok = new
        .iter()
        .enumerate()
        .all(|(k, &t)| normal(m, t).dot(old_normals[k / 2]) >= cos_turn)
        && !guard.crosses(m, &new, &[f1, f2]);
    let value = worst_angle(m, new, params);
    m.pop_vertex();
    ok.then_some(((old, value), q))
}

#[cfg(test)]
mod tests;
