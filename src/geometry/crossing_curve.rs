//! Where an input's own faces cross, or its closed parts meet, as a curve: the output's crossing
//! pairs near that curve are the input's, not the output's (issue 76's rule, the decision issue
//! 55's note asked for).
//!
//! A crossing pair of the input (two faces that pass through each other) meets along a segment:
//! the points where an edge of one pierces the other, the two farthest apart. Two coplanar faces
//! that overlap meet in an area, kept as the smaller of the two triangles. Sheets that meet at a
//! non-manifold edge (one of more than two faces) meet along that edge. An output
//! face lies at the curve when it comes within `reach` (one output spacing) of one of those
//! pieces; a crossing pair of the output is the input's when both its faces do, whatever
//! vertex they share (a fold at the curve is where the input's sheets meet, not a fold of the
//! output's own).

use std::collections::HashMap;
use std::sync::Mutex;

use glam::DVec3;
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::partitioning::Bvh;

use super::bvh::bvh_of;
use super::face_intersection::share_a_vertex;
use super::self_intersection::triangle_aabb;
use super::triangle_intersection::{
    point_triangle_distance, segment_triangle_distance, triangles_within,
};

/// A piece of the curve.
#[derive(Debug, Clone, Copy)]
enum Piece {
    /// A segment (a point when its ends coincide).
    Segment(DVec3, DVec3),
    /// An area where two coplanar faces overlap (the smaller face).
    Area([DVec3; 3]),
}

impl Piece {
    fn aabb(&self) -> Aabb {
        match *self {
            Piece::Segment(a, b) => Aabb::new(a.min(b), a.max(b)),
            Piece::Area(t) => triangle_aabb(t),
        }
    }

    /// Whether the closed triangle `t` comes within `reach` of the piece.
    fn within(&self, t: [DVec3; 3], reach: f64) -> bool {
        match *self {
            Piece::Segment(a, b) if a == b => point_triangle_distance(a, t) <= reach,
            Piece::Segment(a, b) => segment_triangle_distance(a, b, t) <= reach,
            Piece::Area(s) => triangles_within(s, t, reach),
        }
    }
}

/// The curve where an input's faces cross or its closed parts meet (see the module), with the
/// reach within which an output face lies at it.
pub struct CrossingCurve {
    pieces: Vec<Piece>,
    bvh: Bvh,
    reach: f64,
    /// The answers of [`Self::near`] so far, by the triangle's corners (their bits, in the
    /// order [`corner_key`] gives): the finishing stage asks again for the faces it did not
    /// move, round after round (cycloidal.ply at 3000: 18% of the run went to the distances).
    answers: Mutex<HashMap<[u64; 9], bool>>,
}

/// The most answers [`CrossingCurve::near`] keeps (about 100 bytes each); past it they are
/// dropped and gathered anew.
const MAX_ANSWERS: usize = 1 << 20;

/// The corners' bits, in an order that does not depend on the order of the corners.
fn corner_key(t: [DVec3; 3]) -> [u64; 9] {
    let mut c = t.map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]);
    c.sort_unstable();
    let mut key = [0; 9];
    for (k, x) in c.iter().flatten().enumerate() {
        key[k] = *x;
    }
    key
}

impl CrossingCurve {
    /// The curve of the crossing `pairs` (as
    /// [`intersecting_pairs`](super::intersecting_pairs) gives them) of the faces `triangles`
    /// over `positions`, and of the non-manifold `edges` (vertex pairs: where sheets meet); an
    /// output face lies at it within `reach` (one output spacing, [`output_spacing`]; the units of `positions`).
    pub fn new(
        positions: &[DVec3],
        triangles: &[[u32; 3]],
        pairs: &[[u32; 2]],
        edges: &[[u32; 2]],
        reach: f64,
    ) -> Self {
        let corners = |f: u32| triangles[f as usize].map(|v| positions[v as usize]);
        let mut pieces: Vec<Piece> = pairs
            .iter()
            .map(|&[f, g]| meeting(corners(f), corners(g)))
            .collect();
        pieces.extend(
            edges
                .iter()
                .map(|&[a, b]| Piece::Segment(positions[a as usize], positions[b as usize])),
        );
        let loosen = DVec3::splat(reach.max(0.0));
        let bvh = bvh_of(pieces.iter().enumerate().map(|(i, p)| {
            let b = p.aabb();
            (i, Aabb::new(b.mins - loosen, b.maxs + loosen))
        }));
        CrossingCurve {
            pieces,
            bvh,
            reach,
            answers: Mutex::new(HashMap::new()),
        }
    }

    /// Whether there is no curve.
    pub fn is_empty(&self) -> bool {
        self.pieces.is_empty()
    }

    /// Whether the triangle with corners `t` lies at the curve: it comes within the reach of a
    /// piece.
    pub fn near(&self, t: [DVec3; 3]) -> bool {
        if self.pieces.is_empty() {
            return false;
        }
        let key = corner_key(t);
        // An answer is a pure function of the corners: a poisoned lock's map is still right.
        let lock = || self.answers.lock().unwrap_or_else(|e| e.into_inner());
        let known = lock().get(&key).copied();
        if let Some(answer) = known {
            return answer;
        }
        let answer = self
            .bvh
            .intersect_aabb(&triangle_aabb(t))
            .any(|i| self.pieces[i as usize].within(t, self.reach));
        let mut map = lock();
        if map.len() >= MAX_ANSWERS {
            map.clear();
        }
        map.insert(key, answer);
        answer
    }

    /// Whether a crossing pair of triangles with corners `f` and `g` is the input's: both lie at
    /// the curve, whatever vertex they share.
    pub fn holds(&self, f: [DVec3; 3], g: [DVec3; 3]) -> bool {
        self.near(f) && self.near(g)
    }

    /// Whether the crossing pair of faces `a` and `b` (vertex indices of one mesh) with corners
    /// `pa` and `pb` is where the input's sheets pass through each other, which the finishing
    /// stage leaves alone: both lie at the curve ([`Self::holds`]) and they share no vertex. A
    /// fold (faces that share a vertex) is mended wherever it lies, though the report counts it
    /// as the input's at the curve.
    pub fn holds_faces(&self, a: [u32; 3], pa: [DVec3; 3], b: [u32; 3], pb: [DVec3; 3]) -> bool {
        !share_a_vertex(a, b) && self.holds(pa, pb)
    }

    /// How many of the crossing `pairs` of the faces `triangles` over `positions` (another mesh
    /// in the same frame, the output) are the input's ([`Self::holds`]).
    pub fn count_inside(
        &self,
        positions: &[DVec3],
        triangles: &[[u32; 3]],
        pairs: &[[u32; 2]],
    ) -> usize {
        let corners = |f: u32| triangles[f as usize].map(|v| positions[v as usize]);
        pairs
            .iter()
            .filter(|&&[f, g]| self.holds(corners(f), corners(g)))
            .count()
    }
}

/// One output spacing, the reach of a [`CrossingCurve`]: the mean length of the edges of the
/// faces `triangles` over `positions` (each edge once per face that has it), in their units; 0
/// without faces.
pub fn output_spacing(positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    let total: f64 = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| [t[k], t[(k + 1) % 3]]))
        .map(|[a, b]| positions[a as usize].distance(positions[b as usize]))
        .sum();
    if triangles.is_empty() {
        0.0
    } else {
        total / (3 * triangles.len()) as f64
    }
}

/// Where the crossing triangles `a` and `b` meet: the segment between the two farthest of the
/// points where an edge of one passes through the other's plane inside the other, or, when the
/// two are coplanar (or no such point is found in floating point), the smaller triangle.
fn meeting(a: [DVec3; 3], b: [DVec3; 3]) -> Piece {
    let area = |t: [DVec3; 3]| (t[1] - t[0]).cross(t[2] - t[0]).length();
    let smaller = if area(a) <= area(b) { a } else { b };
    let scale = a
        .iter()
        .chain(&b)
        .fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    let tolerance = 1e-9 * scale.max(f64::MIN_POSITIVE);
    let mut points: Vec<DVec3> = Vec::with_capacity(6);
    for (s, t) in [(a, b), (b, a)] {
        let Some(n) = (t[1] - t[0]).cross(t[2] - t[0]).try_normalize() else {
            return Piece::Area(smaller);
        };
        let d = s.map(|p| n.dot(p - t[0]));
        if d.iter().all(|x| x.abs() <= tolerance) {
            return Piece::Area(smaller);
        }
        for k in 0..3 {
            let (p, q, dp, dq) = (s[k], s[(k + 1) % 3], d[k], d[(k + 1) % 3]);
            let x = if dp.abs() <= tolerance {
                p
            } else if dp * dq < 0.0 {
                p + (q - p) * (dp / (dp - dq))
            } else {
                continue;
            };
            if point_triangle_distance(x, t) <= tolerance {
                points.push(x);
            }
        }
    }
    let mut best: Option<(f64, DVec3, DVec3)> = None;
    for (i, &p) in points.iter().enumerate() {
        for &q in &points[i..] {
            let d = p.distance_squared(q);
            if best.is_none_or(|(b, _, _)| d > b) {
                best = Some((d, p, q));
            }
        }
    }
    match best {
        Some((_, p, q)) => Piece::Segment(p, q),
        None => Piece::Area(smaller),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two unit triangles crossing along the segment x in [0, 0.75], y = 0.25, z = 0.
    fn crossing() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let p = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(-0.5, 0.25, -1.0),
            DVec3::new(-0.5, 0.25, 1.0),
            DVec3::new(2.0, 0.25, 0.0),
        ];
        (p, vec![[0, 1, 2], [3, 4, 5]])
    }

    #[test]
    fn the_meeting_of_two_crossing_faces_is_their_intersection_segment() {
        let (p, t) = crossing();
        let c = |f: usize| t[f].map(|v| p[v as usize]);
        let Piece::Segment(a, b) = meeting(c(0), c(1)) else {
            panic!("not a segment");
        };
        let (lo, hi) = if a.x < b.x { (a, b) } else { (b, a) };
        assert!(lo.distance(DVec3::new(0.0, 0.25, 0.0)) < 1e-12, "{lo}");
        assert!(hi.distance(DVec3::new(0.75, 0.25, 0.0)) < 1e-12, "{hi}");
    }

    /// A small face (0.1 across) at `c`, in the plane z = c.z.
    fn small_at(c: DVec3) -> [DVec3; 3] {
        [
            c,
            c + DVec3::new(0.1, 0.0, 0.0),
            c + DVec3::new(0.0, 0.1, 0.0),
        ]
    }

    #[test]
    fn a_face_lies_at_the_curve_within_the_reach_and_not_beyond_whatever_the_box_says() {
        let (p, t) = crossing();
        let curve = CrossingCurve::new(&p, &t, &[[0, 1]], &[], 0.2);
        assert!(curve.near(small_at(DVec3::new(0.3, 0.3, 0.05))));
        // Inside the two faces' overlapping box loosened by the reach, but past the segment's
        // end (0.75, 0.25, 0) by 0.226.
        assert!(!curve.near(small_at(DVec3::new(0.97, 0.3, 0.0))));
        assert!(!curve.near(small_at(DVec3::new(0.1, 0.75, 0.0))));
        // A pair sharing a vertex counts like any other: both faces near.
        let f = small_at(DVec3::new(0.3, 0.2, 0.0));
        let g = [
            f[0],
            f[0] + DVec3::new(0.0, 0.0, 0.1),
            f[0] + DVec3::new(0.1, 0.1, 0.0),
        ];
        assert!(curve.holds(f, g));
        assert!(!curve.holds(f, small_at(DVec3::new(0.1, 0.75, 0.0))));
    }

    #[test]
    fn non_manifold_edges_are_the_curve() {
        let p = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(5.0, 0.0, 0.0)];
        let t = vec![[0, 1, 2]];
        let curve = CrossingCurve::new(&p, &t, &[], &[[0, 1]], 0.1);
        assert!(curve.near(small_at(DVec3::new(0.5, 0.05, 0.05))));
        assert!(!curve.near(small_at(DVec3::new(0.0, 0.5, 0.5))));
        assert!(!CrossingCurve::new(&p, &t, &[], &[], 0.1).near(small_at(DVec3::ZERO)));
    }
}
