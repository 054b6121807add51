//! The closest point of a triangle mesh to a point that moved a little from a previous answer,
//! found by walking over the faces around that answer's face, with a certificate that no face
//! farther away is closer; where the certificate fails, the tree is asked
//! ([`ClosestPointTree::closest`]).
//!
//! Each face `f` carries its ring (the other faces that share a vertex with it) and its
//! clearance `c(f)`: a lower bound on the distance from `f` to every face outside the ring,
//! `|m - x| - r` with `x` the closest point to `f`'s centroid `m` among those faces and `r` the
//! radius of the ball around `m` that holds `f` (every point of `f` is within `r` of `m`);
//! where that bound is small against `|m - x|` (a long thin face, another sheet near), the
//! exact distance from `f` to the faces within `|m - x| + r` of `m`. A
//! walk from face `s` takes the closest of `s` and its ring, moves to that face while it is
//! another one, and stops at a face `s` that is the closest of its own ring, at distance `d`
//! from the point `p` (its closest point `q` on `s`). Every face `g` outside that ring then lies
//! at least `dist(q, g) - |p - q| >= c(s) - d` from `p`: when `2 d < c(s)`, none is closer than
//! `s`, and `s`'s closest point is the mesh's. A surface point that moves by less than half
//! the spacing of the input's vertices from its last answer needs no tree query, which is the
//! common case of a gradient-ascent step, a relaxation move or a fit's quadrature point
//! (issue 77: the tree's walk from the root was 15% of a remesh's processor time).
//!
//! The answer is the tree's, also among faces at exactly the same distance (the point's closest
//! point a vertex or an edge they share: all of them lie in the ring), where both keep the
//! smallest identifier ([`ClosestPointTree::nearer`]). Faces that share no vertex index but
//! touch (an input with unwelded seams) have no clearance, and their points are left to the
//! tree.

use glam::DVec3;
use rayon::prelude::*;

use super::closest_point_tree::{closest_on_triangle, Closest, ClosestPointTree};
use super::tolerance::SEARCH_BOUND_SLACK;
use super::triangle_intersection::triangles_distance;

/// Faces a walk moves to at most before the tree is asked instead.
const MAX_STEPS: usize = 4;

/// The ball around a face's centroid bounds its clearance (`|m - x| - r`) where that keeps at
/// least this share of `|m - x|`; elsewhere (a long thin face, a face near another sheet) the
/// faces that can come closer are measured exactly, triangle to triangle.
const BALL_BOUND_KEPT: f64 = 0.05;

/// Faces per job of the parallel build.
const CHUNK: usize = 4096;

/// The rings and clearances of the faces of a [`ClosestPointTree`] (see the module).
#[derive(Debug, Clone, Default)]
pub struct FaceRings {
    /// Slot `k`'s ring is `ring[offsets[k]..offsets[k + 1]]` (tree slots, ascending).
    offsets: Vec<u32>,
    ring: Vec<u32>,
    /// Half of slot `k`'s clearance less the rounding margin: a walk that ends at `k` at a
    /// distance below it is certified.
    half_clearance: Vec<f64>,
    /// Slot `k`'s centroid and the radius of the ball around it that holds the face (a rounding
    /// margin wider): a face whose ball lies farther from a point than the best distance so far
    /// is not tried.
    balls: Vec<(DVec3, f64)>,
}

/// Where a walk ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Walked {
    /// The closest point of the mesh below the bound (`None`: no face that close).
    Certified(Option<Closest>),
    /// Not certified: the identifier of the closest face the walk found, for the tree's start.
    Unsure(u32),
}

impl FaceRings {
    /// The rings of the triangles of `tree`, whose identifiers index `triangles` (vertex
    /// indices of the mesh the tree was built from), and their clearances (one query of the
    /// tree each, in parallel).
    pub fn new(tree: &ClosestPointTree, triangles: &[[u32; 3]]) -> FaceRings {
        let n = tree.len();
        let corners_of = |k: usize| triangles[tree.id(k) as usize];
        // Vertex -> the slots of its faces.
        let vertices = (0..n)
            .flat_map(&corners_of)
            .max()
            .map_or(0, |v| v as usize + 1);
        let mut start = vec![0u32; vertices + 1];
        for k in 0..n {
            for v in corners_of(k) {
                start[v as usize + 1] += 1;
            }
        }
        for v in 0..vertices {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut around = vec![0u32; start[vertices] as usize];
        for k in 0..n {
            for v in corners_of(k) {
                around[fill[v as usize] as usize] = k as u32;
                fill[v as usize] += 1;
            }
        }
        let faces_at = |v: u32| &around[start[v as usize] as usize..start[v as usize + 1] as usize];
        let margin = tree.bounds().map_or(0.0, |(lo, hi)| {
            SEARCH_BOUND_SLACK * (hi - lo).length().max(lo.abs().max(hi.abs()).max_element())
        });
        // Per chunk of slots: each ring's length, the rings, the half clearances.
        #[allow(clippy::type_complexity)] // one chunk's share of the four arrays
        let chunks: Vec<(Vec<u32>, Vec<u32>, Vec<f64>, Vec<(DVec3, f64)>)> = (0..n)
            .step_by(CHUNK)
            .collect::<Vec<_>>()
            .into_par_iter()
            .map(|from| {
                let to = (from + CHUNK).min(n);
                let (mut lens, mut rings, mut halves) = (Vec::new(), Vec::new(), Vec::new());
                let mut balls = Vec::new();
                let mut ring: Vec<u32> = Vec::new();
                let mut near: Vec<(usize, f64)> = Vec::new();
                for k in from..to {
                    ring.clear();
                    for v in corners_of(k) {
                        ring.extend(faces_at(v).iter().filter(|&&j| j as usize != k));
                    }
                    ring.sort_unstable();
                    ring.dedup();
                    let t = tree.corners_at(k);
                    let m = (t[0] + t[1] + t[2]) / 3.0;
                    let r = t.iter().map(|c| c.distance(m)).fold(0.0, f64::max);
                    let skip = |j: usize| j == k || ring.binary_search(&(j as u32)).is_ok();
                    let clearance = match tree.closest_skipping(m, f64::MAX, skip) {
                        None => f64::INFINITY,
                        Some(c) => {
                            let to_centroid = c.distance_squared.sqrt();
                            if to_centroid - r >= BALL_BOUND_KEPT * to_centroid {
                                to_centroid - r
                            } else {
                                // The faces that can come closer to `k` than the nearest to
                                // its centroid, each at its exact distance.
                                let reach = (to_centroid + r) * (1.0 + SEARCH_BOUND_SLACK);
                                // Nearest to the centroid first: a face at `e` from it is at
                                // least `e - r` from `k`, so the search ends there.
                                tree.within_skipping(m, reach * reach, skip, &mut near);
                                near.sort_unstable_by(|a, b| a.1.total_cmp(&b.1));
                                let mut least = to_centroid;
                                for &(j, e) in &near {
                                    if e.sqrt() - r >= least {
                                        break;
                                    }
                                    least = least.min(triangles_distance(*t, *tree.corners_at(j)));
                                }
                                least
                            }
                        }
                    };
                    lens.push(ring.len() as u32);
                    rings.extend_from_slice(&ring);
                    halves.push(0.5 * (clearance - margin));
                    balls.push((m, r + margin));
                }
                (lens, rings, halves, balls)
            })
            .collect();
        let mut offsets = Vec::with_capacity(n + 1);
        offsets.push(0u32);
        let mut ring = Vec::with_capacity(chunks.iter().map(|c| c.1.len()).sum());
        let mut half_clearance = Vec::with_capacity(n);
        let mut all_balls = Vec::with_capacity(n);
        for (lens, rings, halves, balls) in chunks {
            for l in lens {
                let last = *offsets.last().unwrap_or(&0);
                offsets.push(last + l);
            }
            ring.extend(rings);
            half_clearance.extend(halves);
            all_balls.extend(balls);
        }
        FaceRings {
            offsets,
            ring,
            half_clearance,
            balls: all_balls,
        }
    }

    /// Whether these are the rings of a tree of `len` triangles.
    pub fn fits(&self, len: usize) -> bool {
        self.half_clearance.len() == len
    }

    /// The closest point of `tree`'s triangles (those these rings were built for) to `p`, at a
    /// squared distance below `max_distance_squared`, by a walk from the triangle `start` names
    /// (see the module): [`Walked::Certified`] with the tree's answer
    /// ([`ClosestPointTree::closest`]), or [`Walked::Unsure`] with the face to start the tree's
    /// search from. `start` not in the tree, or `p` not finite: `Unsure(start)`.
    pub fn closest_from(
        &self,
        tree: &ClosestPointTree,
        p: DVec3,
        max_distance_squared: f64,
        start: u32,
    ) -> Walked {
        let Some(mut at) = tree.slot_of(start).filter(|_| p.is_finite()) else {
            return Walked::Unsure(start);
        };
        let (q, bary) = closest_on_triangle(p, tree.corners_at(at));
        let mut best = (at, q, bary, q.distance_squared(p));
        // The best distance a hair longer: a face whose ball is farther is farther.
        let reach = |d2: f64| d2.sqrt() * (1.0 + SEARCH_BOUND_SLACK);
        let mut best_reach = reach(best.3);
        for _ in 0..MAX_STEPS {
            let ring = &self.ring[self.offsets[at] as usize..self.offsets[at + 1] as usize];
            for &j in ring {
                let (centre, radius) = self.balls[j as usize];
                let beyond = best_reach + radius;
                if p.distance_squared(centre) > beyond * beyond {
                    continue;
                }
                let (q, bary) = closest_on_triangle(p, tree.corners_at(j as usize));
                let d = q.distance_squared(p);
                if tree.nearer(d, j as usize, best.3, Some(best.0)) {
                    best = (j as usize, q, bary, d);
                    best_reach = reach(d);
                }
            }
            if best.0 != at {
                at = best.0;
                continue;
            }
            let half = self.half_clearance[at];
            if best.3 < half * half && half > 0.0 {
                let (k, point, barycentric, distance_squared) = best;
                return Walked::Certified((distance_squared < max_distance_squared).then(|| {
                    Closest {
                        id: tree.id(k),
                        point,
                        barycentric,
                        distance_squared,
                    }
                }));
            }
            break;
        }
        Walked::Unsure(tree.id(best.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// A bumpy grid of `n` x `n` squares (two triangles each) at height `z`, with `fold` the
    /// same grid turned back over it `gap` above (a thin part: two sheets a gap apart).
    fn sheets(n: usize, gap: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for sheet in 0..2 {
            let base = positions.len() as u32;
            for j in 0..=n {
                for i in 0..=n {
                    let (x, y) = (i as f64, j as f64);
                    let z = 0.2 * (0.7 * x).sin() * (0.5 * y).cos() + sheet as f64 * gap;
                    positions.push(DVec3::new(x, y, z));
                }
            }
            let at = |i: usize, j: usize| base + (j * (n + 1) + i) as u32;
            for j in 0..n {
                for i in 0..n {
                    let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                    triangles.push([a, b, c]);
                    triangles.push([a, c, d]);
                }
            }
        }
        (positions, triangles)
    }

    fn tree_of(positions: &[DVec3], triangles: &[[u32; 3]]) -> ClosestPointTree {
        ClosestPointTree::new(
            triangles
                .iter()
                .enumerate()
                .map(|(f, t)| (f as u32, t.map(|v| positions[v as usize]))),
        )
    }

    /// Points moved from answers on two sheets, near and far apart (some moves cross to the
    /// other sheet, some go far, some bounds are short): every certified answer is the tree's.
    #[test]
    fn a_certified_walk_gives_the_trees_distance() {
        for gap in [0.3, 2.0] {
            let (positions, triangles) = sheets(12, gap);
            let tree = tree_of(&positions, &triangles);
            let rings = FaceRings::new(&tree, &triangles);
            assert!(rings.fits(tree.len()));
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
            let mut certified = 0;
            for trial in 0..4000 {
                let p0 = DVec3::new(
                    rng.random_range(0.5..11.5),
                    rng.random_range(0.5..11.5),
                    rng.random_range(-1.0..1.0 + gap),
                );
                let Some(from) = tree.closest(p0, f64::MAX, None) else {
                    panic!("no closest point");
                };
                let reach = if trial % 2 == 0 { 0.1 } else { 1.5 };
                let step = DVec3::new(
                    rng.random_range(-reach..reach),
                    rng.random_range(-reach..reach),
                    rng.random_range(-reach..reach),
                );
                let p = from.point + step;
                let bound = if trial % 3 == 0 { 0.05 } else { f64::MAX };
                let want = tree.closest(p, bound, None);
                match rings.closest_from(&tree, p, bound, from.id) {
                    Walked::Certified(got) => {
                        certified += 1;
                        assert_eq!(got.is_some(), want.is_some(), "gap {gap} trial {trial}");
                        if let (Some(g), Some(w)) = (got, want) {
                            assert_eq!(g.distance_squared, w.distance_squared);
                            assert!(g.point.distance(w.point) < 1e-12);
                        }
                    }
                    Walked::Unsure(id) => {
                        assert!((id as usize) < triangles.len());
                    }
                }
            }
            // Both kinds of answer came up.
            assert!(certified > 0 && certified < 4000, "gap {gap}: {certified}");
            if gap > 1.0 {
                // A welded sheet far from the other: every face has a clearance, and a point
                // on the surface is certified from its own face.
                assert!(rings.half_clearance.iter().all(|&h| h > 0.0));
                for (f, t) in triangles.iter().enumerate() {
                    let c = t.map(|v| positions[v as usize]);
                    let on = (c[0] + 2.0 * c[1] + 3.0 * c[2]) / 6.0;
                    assert!(matches!(
                        rings.closest_from(&tree, on, f64::MAX, f as u32),
                        Walked::Certified(Some(_))
                    ));
                }
            }
        }
    }

    /// Two sheets closer than the faces are wide: a point between them is never certified
    /// from the wrong sheet (the clearance sees the other sheet), and a point beyond an
    /// unwelded seam is left to the tree.
    #[test]
    fn another_sheet_or_an_unwelded_seam_is_not_walked_past() {
        let (positions, triangles) = sheets(6, 0.05);
        let tree = tree_of(&positions, &triangles);
        let rings = FaceRings::new(&tree, &triangles);
        // A face of the lower sheet: its clearance is at most the gap.
        let lower = 0u32;
        let k = tree.slot_of(lower).unwrap_or(0);
        assert!(rings.half_clearance[k] <= 0.5 * 0.05 + 1e-9);
        // Just above the upper sheet over that face, started from the lower one.
        let t = triangles[0].map(|v| positions[v as usize]);
        let over = (t[0] + t[1] + t[2]) / 3.0 + DVec3::new(0.0, 0.0, 0.2);
        match rings.closest_from(&tree, over, f64::MAX, lower) {
            Walked::Certified(got) => {
                let want = tree
                    .closest(over, f64::MAX, None)
                    .map(|c| c.distance_squared);
                assert_eq!(got.map(|c| c.distance_squared), want);
            }
            Walked::Unsure(_) => {}
        }
        // The same grid with its faces' vertices unwelded: no face has a ring, no clearance.
        let soup: Vec<DVec3> = triangles
            .iter()
            .flat_map(|t| t.map(|v| positions[v as usize]))
            .collect();
        let soup_triangles: Vec<[u32; 3]> = (0..triangles.len() as u32)
            .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
            .collect();
        let tree = tree_of(&soup, &soup_triangles);
        let rings = FaceRings::new(&tree, &soup_triangles);
        let p = (soup[0] + soup[1] + soup[2]) / 3.0 + DVec3::new(0.0, 0.0, 0.01);
        assert_eq!(rings.closest_from(&tree, p, f64::MAX, 0), Walked::Unsure(0));
    }
}
