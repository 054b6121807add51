//! A bounding-volume hierarchy of triangles built for one question: the closest point of a
//! triangle set to a query point, optionally warm-started from a triangle near the answer.
//!
//! Issue 38 measured parry's general BVH (`TriMesh::project_local_point_and_get_location`)
//! at a quarter of a remesh's processor time: a best-first search over a binary heap, generic
//! over shapes. Here the tree is a flat array of boxes with the triangles' corners stored in
//! leaf order beside them, built once by median splits; a query is a depth-first walk, nearer
//! child first, pruned by the squared distance to the best triangle found so far. A query that
//! starts from a triangle (the face of the previous answer at a point that moved a little)
//! begins with that triangle's distance as the bound, so the walk visits only the boxes that
//! could hold something closer: the root-to-leaf paths near the point. The answer is the
//! exact closest point either way (Ericson, *Real-Time Collision Detection*, 2005, Sec. 5.1.5,
//! for the point-triangle test); among triangles at exactly equal distances (a point whose
//! closest point is a vertex or an edge they share) every query keeps the one of the smallest
//! identifier, so the answer is one with or without a start and in any order of visits
//! ([`ClosestPointTree::closest_each`], and the walk over a face's ring that is asked first,
//! `geometry::closest_point_walk`).

use glam::DVec3;

/// Triangles per leaf at most.
const LEAF_SIZE: usize = 4;

/// Points of one [`ClosestPointTree::closest_each`] walk at most.
pub const GROUP: usize = 8;

/// Entries of a query's stack: twice the depth of a tree of 2^32 triangles, with room to spare.
const STACK: usize = 72;

/// One box of the tree: a leaf holds `count > 0` triangles from `first` (leaf order); an inner
/// node's two children are the nodes `first` and `first + 1`.
#[derive(Debug, Clone, Copy)]
struct Node {
    lo: DVec3,
    hi: DVec3,
    first: u32,
    count: u32,
}

/// The closest point of the tree's triangles to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Closest {
    /// The caller's identifier of the triangle the point lies on.
    pub id: u32,
    /// The closest point (units of the triangles).
    pub point: DVec3,
    /// Its barycentric coordinates in that triangle's corners as given (sum 1).
    pub barycentric: [f64; 3],
    /// The squared distance from the query point to `point`.
    pub distance_squared: f64,
}

/// A bounding-volume hierarchy of triangles for closest-point queries (see the module
/// documentation). Built once; queries are `&self` and run from any number of threads.
#[derive(Debug, Clone, Default)]
pub struct ClosestPointTree {
    nodes: Vec<Node>,
    /// The triangles' corners in leaf order.
    corners: Vec<[DVec3; 3]>,
    /// Leaf order -> the caller's identifier.
    ids: Vec<u32>,
    /// The caller's identifier -> leaf order (`u32::MAX` for an identifier not given).
    slot: Vec<u32>,
}

impl ClosestPointTree {
    /// The tree of `triangles`, `(identifier, corners)`; identifiers are distinct and index
    /// a table, so keep them small (face numbers). Triangles of zero area are accepted (their
    /// closest point is still exact) but make no better answer than their neighbours.
    pub fn new(triangles: impl IntoIterator<Item = (u32, [DVec3; 3])>) -> Self {
        let mut items: Vec<(u32, [DVec3; 3], DVec3)> = triangles
            .into_iter()
            .map(|(id, t)| (id, t, (t[0] + t[1] + t[2]) / 3.0))
            .collect();
        let mut nodes = Vec::with_capacity(2 * items.len() / LEAF_SIZE + 1);
        if !items.is_empty() {
            nodes.push(Node {
                lo: DVec3::ZERO,
                hi: DVec3::ZERO,
                first: 0,
                count: 0,
            });
            build(&mut nodes, 0, &mut items, 0);
        }
        let slot_len = items
            .iter()
            .map(|&(id, ..)| id as usize + 1)
            .max()
            .unwrap_or(0);
        let mut slot = vec![u32::MAX; slot_len];
        for (k, &(id, ..)) in items.iter().enumerate() {
            slot[id as usize] = k as u32;
        }
        ClosestPointTree {
            nodes,
            corners: items.iter().map(|&(_, t, _)| t).collect(),
            ids: items.iter().map(|&(id, ..)| id).collect(),
            slot,
        }
    }

    /// Whether some triangle lies at a squared distance below `max_distance_squared` from `p`
    /// (false for `p` not finite): the walk of [`ClosestPointTree::closest`], ended at the first
    /// such triangle, which is usually in the first leaf it reaches.
    pub fn any_within(&self, p: DVec3, max_distance_squared: f64) -> bool {
        self.walk(p, max_distance_squared, None, true).is_some()
    }

    /// [`ClosestPointTree::any_within`], trying the triangle `start` names first (the one a
    /// previous point near `p` found): the identifier of a triangle that close, `None` when
    /// there is none.
    pub fn any_within_from(
        &self,
        p: DVec3,
        max_distance_squared: f64,
        start: Option<u32>,
    ) -> Option<u32> {
        self.walk(p, max_distance_squared, start, true)
            .map(|c| c.id)
    }

    /// Whether the tree has no triangle.
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// The closest point of the triangles to `p` at a squared distance below
    /// `max_distance_squared`, or `None` (no triangle that close, or `p` not finite). `start`,
    /// when it names a triangle of the tree, is tried first and bounds the search: give the
    /// triangle of a previous answer near `p`. The answer is the same with or without it (among
    /// triangles at exactly equal distances, the smallest identifier).
    pub fn closest(
        &self,
        p: DVec3,
        max_distance_squared: f64,
        start: Option<u32>,
    ) -> Option<Closest> {
        self.walk(p, max_distance_squared, start, false)
    }

    /// [`ClosestPointTree::closest`] for up to [`GROUP`] points near each other at once (the
    /// quadrature points of one face): point k's answer goes to `out[k]`, searched below
    /// `max_distance_squared[k]` and started from `start[k]`. One walk serves them all: a box is
    /// entered when it meets the box around every point's ball of its best distance so far
    /// (one test per box instead of one per point), and a leaf's triangles are tried for the
    /// points its box is closer to than their best. Each answer is [`ClosestPointTree::closest`]'s
    /// for that point. The four slices have one length (more than [`GROUP`] points are answered
    /// in groups).
    pub fn closest_each(
        &self,
        points: &[DVec3],
        max_distance_squared: &[f64],
        start: &[Option<u32>],
        out: &mut [Option<Closest>],
    ) {
        let n = points.len();
        assert!(max_distance_squared.len() == n && start.len() == n && out.len() == n);
        if n > GROUP {
            for k in (0..n).step_by(GROUP) {
                let e = (k + GROUP).min(n);
                self.closest_each(
                    &points[k..e],
                    &max_distance_squared[k..e],
                    &start[k..e],
                    &mut out[k..e],
                );
            }
            return;
        }
        out.fill(None);
        if self.nodes.is_empty() {
            return;
        }
        // A point not finite is never closer than its bound of -1.
        let mut best = [-1.0f64; GROUP];
        let mut found: [Option<(usize, DVec3, [f64; 3])>; GROUP] = [None; GROUP];
        for k in 0..n {
            if !points[k].is_finite() {
                continue;
            }
            best[k] = max_distance_squared[k];
            found[k] = self.start_answer(points[k], start[k], &mut best[k]);
        }
        // The box around every point's ball of its best distance so far (a hair wider, for
        // the rounding of the root): a box that misses it holds nothing closer for any point.
        let reach = |best: &[f64; GROUP]| -> (DVec3, DVec3) {
            let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
            for k in 0..n {
                if best[k] >= 0.0 {
                    let r = best[k].sqrt() * (1.0 + 1e-9) + f64::MIN_POSITIVE;
                    lo = lo.min(points[k] - r);
                    hi = hi.max(points[k] + r);
                }
            }
            (lo, hi)
        };
        let (mut lo, mut hi) = reach(&best);
        let centre = 0.5 * (lo + hi);
        let meets =
            |node: &Node, lo: DVec3, hi: DVec3| node.lo.cmple(hi).all() && node.hi.cmpge(lo).all();
        let mut stack = [0u32; STACK];
        let mut len = 0;
        if meets(&self.nodes[0], lo, hi) {
            len = 1;
        }
        while len > 0 {
            len -= 1;
            let node = self.nodes[stack[len] as usize];
            if !meets(&node, lo, hi) {
                continue;
            }
            if node.count > 0 {
                let first = node.first as usize;
                let mut to_box = [0.0f64; GROUP];
                for k in 0..n {
                    to_box[k] = box_distance_squared(points[k], &node);
                }
                let mut closer = false;
                for t in first..first + node.count as usize {
                    for k in 0..n {
                        if to_box[k] > best[k] {
                            continue;
                        }
                        let (q, bary) = closest_on_triangle(points[k], &self.corners[t]);
                        let d = q.distance_squared(points[k]);
                        if self.nearer(d, t, best[k], found[k].map(|f| f.0)) {
                            best[k] = d;
                            found[k] = Some((t, q, bary));
                            closer = true;
                        }
                    }
                }
                if closer {
                    (lo, hi) = reach(&best);
                }
            } else {
                let (l, r) = (node.first, node.first + 1);
                let (nl, nr) = (&self.nodes[l as usize], &self.nodes[r as usize]);
                let (ml, mr) = (meets(nl, lo, hi), meets(nr, lo, hi));
                let (near, far) = match (ml, mr) {
                    (true, true)
                        if box_distance_squared(centre, nr) < box_distance_squared(centre, nl) =>
                    {
                        (Some(r), Some(l))
                    }
                    (true, true) => (Some(l), Some(r)),
                    (true, false) => (Some(l), None),
                    (false, true) => (Some(r), None),
                    (false, false) => (None, None),
                };
                for c in [far, near].into_iter().flatten() {
                    stack[len] = c;
                    len += 1;
                }
            }
        }
        for k in 0..n {
            out[k] = found[k].map(|(t, point, barycentric)| Closest {
                id: self.ids[t],
                point,
                barycentric,
                distance_squared: best[k],
            });
        }
    }

    /// The start of a query at `p`: `start`'s closest point when `start` names a triangle of
    /// the tree and it lies below `best` (which it then lowers to its squared distance).
    fn start_answer(
        &self,
        p: DVec3,
        start: Option<u32>,
        best: &mut f64,
    ) -> Option<(usize, DVec3, [f64; 3])> {
        let k = *start.and_then(|id| self.slot.get(id as usize))?;
        if k == u32::MAX {
            return None;
        }
        let (q, bary) = closest_on_triangle(p, &self.corners[k as usize]);
        let d = q.distance_squared(p);
        (d < *best).then(|| {
            *best = d;
            (k as usize, q, bary)
        })
    }

    /// The number of triangles (slots `0..len`, in leaf order).
    pub(crate) fn len(&self) -> usize {
        self.ids.len()
    }

    /// The caller's identifier of the triangle at `slot`.
    pub(crate) fn id(&self, slot: usize) -> u32 {
        self.ids[slot]
    }

    /// The slot of the triangle the caller calls `id`, if the tree holds it.
    pub(crate) fn slot_of(&self, id: u32) -> Option<usize> {
        let k = *self.slot.get(id as usize)?;
        (k != u32::MAX).then_some(k as usize)
    }

    /// The corners of the triangle at `slot`, as given.
    pub(crate) fn corners_at(&self, slot: usize) -> &[DVec3; 3] {
        &self.corners[slot]
    }

    /// The box around every triangle (`None` without triangles).
    pub(crate) fn bounds(&self) -> Option<(DVec3, DVec3)> {
        self.nodes.first().map(|n| (n.lo, n.hi))
    }

    /// [`ClosestPointTree::closest`] (no start) among the triangles whose slot `skip` is false
    /// for.
    pub(crate) fn closest_skipping(
        &self,
        p: DVec3,
        max_distance_squared: f64,
        skip: impl Fn(usize) -> bool,
    ) -> Option<Closest> {
        self.walk_by(p, max_distance_squared, None, false, skip)
    }

    /// The slots of the triangles at a squared distance below `max_distance_squared` from `p`
    /// whose slot `skip` is false for, with those squared distances, into `out` (cleared first;
    /// in no particular order).
    pub(crate) fn within_skipping(
        &self,
        p: DVec3,
        max_distance_squared: f64,
        skip: impl Fn(usize) -> bool,
        out: &mut Vec<(usize, f64)>,
    ) {
        out.clear();
        if !p.is_finite() || self.nodes.is_empty() {
            return;
        }
        let mut stack = [0u32; STACK];
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let node = self.nodes[stack[len] as usize];
            if box_distance_squared(p, &node) >= max_distance_squared {
                continue;
            }
            if node.count > 0 {
                let first = node.first as usize;
                for k in first..first + node.count as usize {
                    if skip(k) {
                        continue;
                    }
                    let d = closest_on_triangle(p, &self.corners[k])
                        .0
                        .distance_squared(p);
                    if d < max_distance_squared {
                        out.push((k, d));
                    }
                }
            } else {
                stack[len] = node.first;
                stack[len + 1] = node.first + 1;
                len += 2;
            }
        }
    }

    /// Whether the triangle at `slot`, at squared distance `d`, is a better answer than the one
    /// at slot `found` at `best` (`None`: nothing below the bound `best` yet): nearer, or as near
    /// with a smaller identifier. Every search keeps the least in this order, so its answer
    /// does not depend on the order it visits the triangles in or where it starts.
    #[inline]
    pub(crate) fn nearer(&self, d: f64, slot: usize, best: f64, found: Option<usize>) -> bool {
        d < best || (d == best && found.is_some_and(|f| self.ids[slot] < self.ids[f]))
    }

    /// The depth-first walk of both queries: nearer child first, pruned by the best squared
    /// distance so far (first `start`'s, when it names a triangle); with `first_hit`, it ends at
    /// the first triangle below the bound.
    fn walk(
        &self,
        p: DVec3,
        max_distance_squared: f64,
        start: Option<u32>,
        first_hit: bool,
    ) -> Option<Closest> {
        self.walk_by(p, max_distance_squared, start, first_hit, |_| false)
    }

    /// [`ClosestPointTree::walk`] over the triangles whose slot `skip` is false for.
    #[inline(always)]
    fn walk_by(
        &self,
        p: DVec3,
        max_distance_squared: f64,
        start: Option<u32>,
        first_hit: bool,
        skip: impl Fn(usize) -> bool,
    ) -> Option<Closest> {
        if !p.is_finite() || self.nodes.is_empty() {
            return None;
        }
        let mut best = max_distance_squared;
        let mut found = self.start_answer(p, start, &mut best);
        if first_hit && found.is_some() {
            return found.map(|(k, point, barycentric)| Closest {
                id: self.ids[k],
                point,
                barycentric,
                distance_squared: best,
            });
        }
        // The stack grows by at most one entry per level, and median splits keep the depth
        // below 32 for any u32 count of triangles.
        let mut stack = [(0u32, 0.0f64); STACK];
        let mut len = 0;
        let root = box_distance_squared(p, &self.nodes[0]);
        if root <= best {
            stack[0] = (0, root);
            len = 1;
        }
        'walk: while len > 0 {
            len -= 1;
            let (n, d) = stack[len];
            if d > best {
                continue;
            }
            let node = self.nodes[n as usize];
            if node.count > 0 {
                let first = node.first as usize;
                for k in first..first + node.count as usize {
                    if skip(k) {
                        continue;
                    }
                    let (q, bary) = closest_on_triangle(p, &self.corners[k]);
                    let d = q.distance_squared(p);
                    if self.nearer(d, k, best, found.map(|f| f.0)) {
                        best = d;
                        found = Some((k, q, bary));
                        if first_hit {
                            break 'walk;
                        }
                    }
                }
            } else {
                let (l, r) = (node.first, node.first + 1);
                let dl = box_distance_squared(p, &self.nodes[l as usize]);
                let dr = box_distance_squared(p, &self.nodes[r as usize]);
                let ((near, dn), (far, df)) = if dl <= dr {
                    ((l, dl), (r, dr))
                } else {
                    ((r, dr), (l, dl))
                };
                for entry in [(far, df), (near, dn)] {
                    if entry.1 <= best {
                        stack[len] = entry;
                        len += 1;
                    }
                }
            }
        }
        found.map(|(k, point, barycentric)| Closest {
            id: self.ids[k],
            point,
            barycentric,
            distance_squared: best,
        })
    }
}

/// Fills node `at` with the tree of `items` (which sit at leaf positions `offset..`), splitting
/// at the median centroid along the longest side of the centroids' box.
fn build(nodes: &mut Vec<Node>, at: usize, items: &mut [(u32, [DVec3; 3], DVec3)], offset: usize) {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    let (mut clo, mut chi) = (lo, hi);
    for (_, t, c) in items.iter() {
        for v in t {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        clo = clo.min(*c);
        chi = chi.max(*c);
    }
    if items.len() <= LEAF_SIZE {
        nodes[at] = Node {
            lo,
            hi,
            first: offset as u32,
            count: items.len() as u32,
        };
        return;
    }
    let extent = chi - clo;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |a, b| {
        a.2[axis].total_cmp(&b.2[axis]).then(a.0.cmp(&b.0))
    });
    let first = nodes.len();
    nodes[at] = Node {
        lo,
        hi,
        first: first as u32,
        count: 0,
    };
    let blank = nodes[at];
    nodes.push(blank);
    nodes.push(blank);
    let (left, right) = items.split_at_mut(mid);
    build(nodes, first, left, offset);
    build(nodes, first + 1, right, offset + mid);
}

/// Squared distance from `p` to the box of `node` (0 inside).
#[inline]
fn box_distance_squared(p: DVec3, node: &Node) -> f64 {
    let d = (node.lo - p).max(p - node.hi).max(DVec3::ZERO);
    d.length_squared()
}

/// The closest point of triangle `t` to `p` and its barycentric coordinates in `t`'s corners
/// (Ericson 2005, Sec. 5.1.5: the Voronoi region of `p` among the corners, edges and face).
#[inline]
pub(crate) fn closest_on_triangle(p: DVec3, t: &[DVec3; 3]) -> (DVec3, [f64; 3]) {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + v * ab, [1.0 - v, v, 0.0]);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + w * ac, [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + w * (c - b), [0.0, 1.0 - w, w]);
    }
    let denom = va + vb + vc;
    if !(denom > 0.0) {
        // A triangle of zero area whose regions all missed (rounding): its nearest corner.
        let k = (0..3)
            .min_by(|&i, &j| {
                t[i].distance_squared(p)
                    .total_cmp(&t[j].distance_squared(p))
            })
            .unwrap_or(0);
        let mut bary = [0.0; 3];
        bary[k] = 1.0;
        return (t[k], bary);
    }
    let (v, w) = (vb / denom, vc / denom);
    (a + v * ab + w * ac, [1.0 - v - w, v, w])
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    fn random_triangles(n: usize, seed: u64) -> Vec<(u32, [DVec3; 3])> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut v = || {
            DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
        };
        (0..n)
            .map(|i| {
                let c = v();
                let t = [c + 0.1 * v(), c + 0.1 * v(), c + 0.1 * v()];
                // Identifiers with gaps, as a mesh's faces with zero-area ones left out.
                (3 * i as u32 + 1, t)
            })
            .collect()
    }

    /// The brute-force answer: the least distance over all triangles.
    fn brute(tris: &[(u32, [DVec3; 3])], p: DVec3) -> f64 {
        tris.iter()
            .map(|(_, t)| closest_on_triangle(p, t).0.distance_squared(p))
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn agrees_with_brute_force_with_and_without_a_start() {
        let tris = random_triangles(300, 3);
        let tree = ClosestPointTree::new(tris.iter().copied());
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        for i in 0..500 {
            let p = DVec3::new(
                rng.random_range(-1.5..1.5),
                rng.random_range(-1.5..1.5),
                rng.random_range(-1.5..1.5),
            );
            let want = brute(&tris, p);
            let start = Some(tris[i % tris.len()].0);
            for s in [None, start, Some(2)] {
                let c = tree.closest(p, f64::INFINITY, s).unwrap();
                assert!(
                    (c.distance_squared - want).abs() <= 1e-12 * (1.0 + want),
                    "{p:?}: {} vs {want}",
                    c.distance_squared
                );
                // The answer lies on the triangle it names, at its barycentric coordinates.
                let t = tris.iter().find(|(id, _)| *id == c.id).unwrap().1;
                let rebuilt =
                    c.barycentric[0] * t[0] + c.barycentric[1] * t[1] + c.barycentric[2] * t[2];
                assert!(rebuilt.distance(c.point) < 1e-12);
                assert!((c.barycentric.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn one_walk_for_a_group_gives_each_point_its_own_answer() {
        let tris = random_triangles(300, 6);
        let tree = ClosestPointTree::new(tris.iter().copied());
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        for round in 0..200 {
            // 11 points around one centre (more than a group), some with a bound that leaves
            // their answer out, some started from a triangle, one not finite.
            let centre = DVec3::new(
                rng.random_range(-1.5..1.5),
                rng.random_range(-1.5..1.5),
                rng.random_range(-1.5..1.5),
            );
            let mut points: Vec<DVec3> = (0..11)
                .map(|_| {
                    centre
                        + 0.1
                            * DVec3::new(
                                rng.random_range(-1.0..1.0),
                                rng.random_range(-1.0..1.0),
                                rng.random_range(-1.0..1.0),
                            )
                })
                .collect();
            points[round % 11] = DVec3::NAN;
            let bounds: Vec<f64> = (0..11)
                .map(|k| if k % 4 == 1 { 0.01 } else { f64::INFINITY })
                .collect();
            let starts: Vec<Option<u32>> = (0..11)
                .map(|k| (k % 3 == 0).then(|| tris[(round + k) % tris.len()].0))
                .collect();
            let mut out = vec![None; 11];
            tree.closest_each(&points, &bounds, &starts, &mut out);
            for k in 0..11 {
                let alone = tree.closest(points[k], bounds[k], starts[k]);
                match (out[k], alone) {
                    (None, None) => {}
                    (Some(a), Some(b)) => {
                        assert_eq!(a.distance_squared, b.distance_squared, "point {k}");
                        let want = brute(&tris, points[k]);
                        assert!((a.distance_squared - want).abs() <= 1e-12 * (1.0 + want));
                    }
                    other => panic!("point {k} of round {round}: {other:?}"),
                }
            }
            assert!(out[round % 11].is_none());
        }
    }

    #[test]
    fn any_within_agrees_with_the_closest_distance() {
        let tris = random_triangles(200, 4);
        let tree = ClosestPointTree::new(tris.iter().copied());
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let (mut inside, mut outside) = (0, 0);
        for _ in 0..2000 {
            let p = DVec3::new(
                rng.random_range(-1.5..1.5),
                rng.random_range(-1.5..1.5),
                rng.random_range(-1.5..1.5),
            );
            let r2: f64 = rng.random_range(0.0..0.05);
            let want = brute(&tris, p) < r2;
            assert_eq!(tree.any_within(p, r2), want, "{p:?} {r2}");
            // From any start (near or not, within or not): the same decision, and a triangle
            // found is that close.
            let start = rng.random_range(0..3 * tris.len() as u32 + 5);
            let hit = tree.any_within_from(p, r2, Some(start));
            assert_eq!(hit.is_some(), want, "{p:?} {r2} from {start}");
            if let Some(id) = hit {
                let t: Vec<_> = tris.iter().filter(|t| t.0 == id).copied().collect();
                assert!(t.len() == 1 && brute(&t, p) < r2);
            }
            if want {
                inside += 1;
            } else {
                outside += 1;
            }
        }
        assert!(inside > 100 && outside > 100, "{inside} {outside}");
        assert!(!tree.any_within(DVec3::new(f64::NAN, 0.0, 0.0), 1.0));
    }

    #[test]
    fn a_bound_leaves_out_what_is_farther() {
        let tris = random_triangles(50, 5);
        let tree = ClosestPointTree::new(tris.iter().copied());
        let p = DVec3::new(4.0, 0.0, 0.0);
        let want = brute(&tris, p);
        assert!(tree.closest(p, 0.99 * want, None).is_none());
        assert!(tree.closest(p, 0.99 * want, Some(tris[0].0)).is_none());
        assert!(tree.closest(p, 1.01 * want, None).is_some());
        assert!(tree
            .closest(DVec3::new(f64::NAN, 0.0, 0.0), f64::INFINITY, None)
            .is_none());
        assert!(ClosestPointTree::new([])
            .closest(p, f64::INFINITY, None)
            .is_none());
    }

    #[test]
    fn regions_of_one_triangle() {
        let t = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let cases = [
            (DVec3::new(0.2, 0.3, 1.0), DVec3::new(0.2, 0.3, 0.0)),
            (DVec3::new(-1.0, -1.0, 0.0), DVec3::ZERO),
            (DVec3::new(2.0, -0.5, 0.0), DVec3::X),
            (DVec3::new(0.5, -2.0, 0.3), DVec3::new(0.5, 0.0, 0.0)),
            (DVec3::new(1.0, 1.0, 0.0), DVec3::new(0.5, 0.5, 0.0)),
            (DVec3::new(-0.5, 0.5, 0.0), DVec3::new(0.0, 0.5, 0.0)),
            (DVec3::new(-0.1, 3.0, 0.0), DVec3::Y),
        ];
        for (p, want) in cases {
            let (q, b) = closest_on_triangle(p, &t);
            assert!(q.distance(want) < 1e-15, "{p:?}: {q:?}");
            assert!((b[0] * t[0] + b[1] * t[1] + b[2] * t[2]).distance(q) < 1e-15);
        }
        // A degenerate triangle (three points on a line) still gives its nearest point.
        let line = [DVec3::ZERO, DVec3::X, 2.0 * DVec3::X];
        let (q, _) = closest_on_triangle(DVec3::new(1.5, 1.0, 0.0), &line);
        assert!(q.distance(DVec3::new(1.5, 0.0, 0.0)) < 1e-12);
    }
}
