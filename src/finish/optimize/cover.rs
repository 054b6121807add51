//! Covering: input-surface points farther than the cover distance from the mesh become
//! vertices (tips and rims the sampling could not resolve).

use glam::DVec3;
use rayon::prelude::*;

use crate::geometry::morton::morton_order;
use crate::geometry::segment::distance_to_segment;

use super::*;

/// One round of covering: the points of `points` farther than `cover_distance` from the mesh,
/// farthest first and at most one per face, each split into the face nearest to it. `watch`
/// carries, from the first round to the next, the points worth looking at again. Returns how
/// many were inserted.
pub(super) fn cover(
    m: &mut Mesh,
    points: &[DVec3],
    watch: &mut Option<Vec<u32>>,
    params: &Limits,
) -> usize {
    let (live, slot) = m.live_faces();
    let current = TriMesh::new(m.positions().to_vec(), live);
    let Ok(output) = MeshSurface::new(&current) else {
        return 0;
    };
    // The points to look at: all of them the first time; then those that could come farther
    // than the cover distance: a collapse moves the mesh by up to `collapse_offset` from a
    // surface point, relaxation by less.
    if watch.is_none() {
        // Asked in Morton order (the points are drawn in random order), which keeps the
        // output's tree in cache; the answers are the same in any order.
        let reach = (params.cover_distance - params.collapse_offset).max(0.0);
        // Each point tries first the face the point before it found (a neighbour in Morton
        // order, usually as close to the same face).
        let mut far: Vec<u32> = morton_order(points)
            .into_par_iter()
            .map_init(
                || None,
                |last: &mut Option<u32>, i| {
                    let hit = output.within_from(points[i as usize], reach, *last);
                    *last = hit.or(*last);
                    (i, hit.is_none())
                },
            )
            .filter_map(|(i, far)| far.then_some(i))
            .collect();
        far.sort_unstable();
        *watch = Some(far);
    }
    let watched = watch.as_deref().unwrap_or_default();
    let mut far: Vec<(f64, usize, u32)> = watched
        .par_iter()
        .filter_map(|&i| {
            let i = i as usize;
            let sp = output.closest_point(points[i])?;
            (sp.distance > params.cover_distance).then_some((
                sp.distance,
                i,
                slot[sp.face as usize],
            ))
        })
        .collect();
    far.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let mut touched = vec![false; m.slots()];
    let mut added = 0;
    for (_, i, f) in far {
        let t = face(m, f);
        // One insertion per face and its neighbours per round: the next round sees the result.
        if touched[f as usize] {
            continue;
        }
        let p = points[i];
        let [pa, pb, pc] = m.corners(t);
        let n = (pb - pa).cross(pc - pa);
        let corner = [pa, pb, pc];
        let v = m.vertex_count() as u32;
        // Which side of each edge k (corner k → k+1) p is on, in the face's plane.
        let outside: Vec<usize> = (0..3)
            .filter(|&k| {
                let (x, y) = (corner[k], corner[(k + 1) % 3]);
                (y - x).cross(p - x).dot(n) <= 0.0
            })
            .collect();
        // (new face, the old face it comes from), and the edge to split (`None`: the face).
        let (plan, split): (SplitPlan, Option<(u32, u32)>) = if outside.is_empty() {
            // Inside the face: split it in three.
            let [a, b, c] = t;
            (vec![([a, b, v], t), ([b, c, v], t), ([c, a, v], t)], None)
        } else {
            // Beyond an edge (or a corner: the nearer of its two edges): split that edge and
            // the face across it.
            let k = *outside
                .iter()
                .min_by(|&&k1, &&k2| {
                    let d = |k: usize| distance_to_segment(p, corner[k], corner[(k + 1) % 3]);
                    d(k1).total_cmp(&d(k2))
                })
                .unwrap_or(&outside[0]);
            let (x, y, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            // A boundary edge stays as the boundary samples made it.
            let Some(g) = m.face_on(y, x) else {
                continue;
            };
            if touched[g as usize] {
                continue;
            }
            let u = face(m, g);
            let d = starting_at(u, y)[2];
            (
                vec![
                    ([x, v, c], t),
                    ([v, y, c], t),
                    ([y, v, d], u),
                    ([v, x, d], u),
                ],
                Some((x, y)),
            )
        };
        // Every new face must face the way the face it comes from did.
        let at = |u: u32| if u == v { p } else { m.position(u) };
        let unit = |t: [u32; 3]| {
            let [a, b, c] = t.map(at);
            (b - a).cross(c - a).normalize_or_zero()
        };
        let fits = plan
            .iter()
            .all(|&(new, old)| unit(new).dot(normal(m, old)) > 0.0);
        if !fits {
            continue;
        }
        m.add_vertex(p);
        let done = match split {
            None => m.split_face(f, v, None).map(|_| ()),
            Some((x, y)) => m.split_edge(x, y, v, None).map(|_| ()),
        };
        if done.is_err() {
            m.pop_vertex();
            continue;
        }
        touched.resize(m.slots(), true);
        for &u in plan.iter().flat_map(|x| x.0.iter()) {
            for &g in m.faces_around(u) {
                touched[g as usize] = true;
            }
        }
        added += 1;
    }
    added
}

/// The faces a split makes: (new face, the old face it comes from).
type SplitPlan = Vec<([u32; 3], [u32; 3])>;
