//! Whether two faces of an indexed triangle mesh intersect, by the standard definition (CGAL's
//! `Polygon_mesh_processing::self_intersections` / `does_self_intersect`, MeshLab's
//! self-intersection selection): decided by the vertex indices the two faces share and exact
//! orientation predicates.
//!
//! - **No vertex in common**: they intersect when their closed triangles share a point
//!   ([`triangles_intersect`](super::triangles_intersect)): they cross, touch at a point, along an edge or in an area.
//! - **One vertex in common**: they intersect when they meet anywhere but at that vertex: a fan
//!   that wraps twice around its vertex, a face folded over another of its vertex's faces. The
//!   two triangles' intersection is a convex set holding the shared vertex; it holds another
//!   point exactly when the edge of one opposite the shared vertex meets the other triangle.
//! - **An edge in common**: they intersect when they overlap: coplanar, their third corners on
//!   the same side of the edge (a face folded flat onto its neighbour).
//! - Three vertices in common (a duplicate face) or a face repeating an index: not decided here;
//!   the invariant check reports those faces on their own, as it does faces of zero area.
//!
//! Source: the case analysis of CGAL's `self_intersections` (S. Loriot, J. Tournois,
//! I. O. Yaz, *Polygon Mesh Processing*, CGAL User and Reference Manual), with J. R. Shewchuk's
//! exact predicates (*Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric
//! Predicates*, Discrete Comput. Geom. 18, 1997).

use glam::DVec3;
use serde::Serialize;

use super::triangle_intersection::{
    apart_segment_within, orient, point_triangle_distance, same_side_in_plane,
    segment_meets_triangle, triangles_within,
};

/// How the two faces of an intersecting pair are joined in the mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PairKind {
    /// No vertex in common: the faces cross or touch.
    Apart,
    /// One vertex in common: they meet elsewhere too (a fan folded over itself).
    AtVertex,
    /// An edge in common: they overlap (a face folded flat onto its neighbour).
    AlongEdge,
}

impl PairKind {
    /// The three kinds, in order.
    pub const ALL: [PairKind; 3] = [PairKind::Apart, PairKind::AtVertex, PairKind::AlongEdge];

    /// A few words for the report: "apart", "at a shared vertex", "along a shared edge".
    pub fn describe(self) -> &'static str {
        match self {
            PairKind::Apart => "apart",
            PairKind::AtVertex => "at a shared vertex",
            PairKind::AlongEdge => "along a shared edge",
        }
    }
}

/// The vertex indices two faces share, as positions in each face.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Shared {
    /// None in common.
    None,
    /// One: at corner `.0` of the first face and `.1` of the second.
    Vertex(usize, usize),
    /// Two: the first face's corners other than `.0`, and the second's other than `.1` (the
    /// third corners, off the shared edge).
    Edge(usize, usize),
    /// Three, or a face that repeats an index: not a pair this module decides.
    Undecided,
}

/// Which vertex indices faces `a` and `b` share ([`Shared`]).
pub(crate) fn shared(a: [u32; 3], b: [u32; 3]) -> Shared {
    let repeats = |t: [u32; 3]| t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
    if repeats(a) || repeats(b) {
        return Shared::Undecided;
    }
    let mut common = 0;
    let (mut ia, mut ib) = (0, 0);
    let (mut off_a, mut off_b) = (0, 0);
    for (i, v) in a.iter().enumerate() {
        match b.iter().position(|u| u == v) {
            Some(j) => {
                common += 1;
                ia = i;
                ib = j;
            }
            None => off_a = i,
        }
    }
    for (j, u) in b.iter().enumerate() {
        if !a.contains(u) {
            off_b = j;
        }
    }
    match common {
        0 => Shared::None,
        1 => Shared::Vertex(ia, ib),
        2 => Shared::Edge(off_a, off_b),
        _ => Shared::Undecided,
    }
}

/// Whether faces `a` and `b` have a vertex index in common (or one repeats an index): a pair that
/// intersects is then a fold of the mesh's own faces, never two sheets passing through each
/// other.
pub(crate) fn share_a_vertex(a: [u32; 3], b: [u32; 3]) -> bool {
    shared(a, b) != Shared::None
}

/// Whether faces `a` and `b` (vertex indices) with corners `pa` and `pb` (their vertices'
/// positions, any length unit) intersect by the standard definition (see the module), and how
/// they are joined; `None` when they do not, or when the pair is not one this test decides (a
/// duplicate face, a face that repeats an index). Exact: no tolerance, touching counts. Both
/// triangles must be non-degenerate (the callers leave out faces of zero area).
pub fn faces_intersect(
    a: [u32; 3],
    pa: [DVec3; 3],
    b: [u32; 3],
    pb: [DVec3; 3],
) -> Option<PairKind> {
    faces_within(a, pa, b, pb, 0.0)
}

/// [`faces_intersect`], or the two faces come within `near` (the corners' unit; ≤ 0: the exact
/// test alone) of intersecting, so they may intersect once their corners are rounded by up to
/// `near / 2` (a mesh mapped into another frame, or written as `f32`):
/// - apart: the triangles come within `near` ([`triangles_within`]);
/// - one vertex in common: the edge of one opposite the shared vertex comes within `near` of the
///   other triangle;
/// - an edge in common: the third corners lie on the same side of the edge (in the first face's
///   plane) and one of them comes within `near` of the other face.
pub(crate) fn faces_within(
    a: [u32; 3],
    pa: [DVec3; 3],
    b: [u32; 3],
    pb: [DVec3; 3],
    near: f64,
) -> Option<PairKind> {
    let near = if near > 0.0 { near } else { 0.0 };
    match shared(a, b) {
        Shared::None => triangles_within(pa, pb, near).then_some(PairKind::Apart),
        Shared::Vertex(i, j) => {
            let (a1, a2) = (pa[(i + 1) % 3], pa[(i + 2) % 3]);
            let (b1, b2) = (pb[(j + 1) % 3], pb[(j + 2) % 3]);
            // Neither segment meets the other face past the first two tests: the distances
            // are those of segments apart.
            let meet = segment_meets_triangle(a1, a2, pb)
                || segment_meets_triangle(b1, b2, pa)
                || (near > 0.0
                    && (apart_segment_within(a1, a2, pb, near)
                        || apart_segment_within(b1, b2, pa, near)));
            meet.then_some(PairKind::AtVertex)
        }
        Shared::Edge(k, l) => {
            // The shared edge p q, and the third corners r (of a) and s (of b).
            let (p, q, r) = (pa[(k + 1) % 3], pa[(k + 2) % 3], pa[k]);
            let s = pb[l];
            let overlap = if orient(p, q, r, s) == 0 {
                same_side_in_plane(p, q, r, s)
            } else {
                near > 0.0
                    && (r - p).reject_from(q - p).dot((s - p).reject_from(q - p)) > 0.0
                    && (point_triangle_distance(s, pa) <= near
                        || point_triangle_distance(r, pb) <= near)
            };
            overlap.then_some(PairKind::AlongEdge)
        }
        Shared::Undecided => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    #[test]
    fn shared_indices() {
        assert_eq!(shared([0, 1, 2], [3, 4, 5]), Shared::None);
        assert_eq!(shared([0, 1, 2], [5, 1, 4]), Shared::Vertex(1, 1));
        assert_eq!(shared([0, 1, 2], [2, 1, 7]), Shared::Edge(0, 2));
        assert_eq!(shared([0, 1, 2], [2, 0, 1]), Shared::Undecided);
        assert_eq!(shared([0, 0, 2], [3, 4, 5]), Shared::Undecided);
    }

    #[test]
    fn a_flat_fan_is_clean_and_folded_faces_are_not() {
        // Four faces around vertex 0 at the origin, in the plane z = 0.
        let p = [
            v(0., 0., 0.),
            v(1., 0., 0.),
            v(0., 1., 0.),
            v(-1., 0., 0.),
            v(0., -1., 0.),
        ];
        let f = |t: [u32; 3]| (t, t.map(|i| p[i as usize]));
        let faces = [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]].map(f);
        for (i, &(a, pa)) in faces.iter().enumerate() {
            for &(b, pb) in &faces[i + 1..] {
                assert_eq!(faces_intersect(a, pa, b, pb), None, "{a:?} {b:?}");
            }
        }
        // A fifth face around the vertex, over the first one's sector: a fan wrapped twice.
        let (a, pa) = faces[0];
        let over = [0, 5, 6];
        let po = [p[0], v(2., 0.5, 0.), v(0.5, 2., 0.)];
        assert_eq!(faces_intersect(a, pa, over, po), Some(PairKind::AtVertex));
        // The same lifted off the plane but for the shared vertex: the faces meet only there.
        let lifted = [p[0], v(2., 0.5, 1.), v(0.5, 2., 1.)];
        assert_eq!(faces_intersect(a, pa, over, lifted), None);
        // Through the first face, from below to above.
        let through = [p[0], v(0.3, 0.3, 1.), v(0.3, 0.2, -1.)];
        assert_eq!(
            faces_intersect(a, pa, over, through),
            Some(PairKind::AtVertex)
        );
        // Folded flat onto its neighbour across the edge 0-2: the third corner on the same side.
        let (b, _) = faces[1];
        let folded = [p[0], p[2], v(0.5, 0.2, 0.)];
        assert_eq!(faces_intersect(a, pa, b, folded), Some(PairKind::AlongEdge));
        // Folded by less than all the way: the faces meet along the edge only.
        let creased = [p[0], p[2], v(0.5, 0.2, 1e-9)];
        assert_eq!(faces_intersect(a, pa, b, creased), None);
        // ... but within a `near` longer than the gap they count.
        assert_eq!(
            faces_within(a, pa, b, creased, 1e-6),
            Some(PairKind::AlongEdge)
        );
        // Flat the other way round (a sharp crease at 1e-9 on the far side): not within near.
        let flat = [p[0], p[2], v(-0.5, 0.2, 1e-9)];
        assert_eq!(faces_within(a, pa, b, flat, 1e-6), None);
    }
}
