//! Self-intersections of a triangle mesh, as the invariant check and the report count them.

use serde::Serialize;

use crate::geometry::self_intersection::classified_pairs;
use crate::geometry::PairKind;
use crate::mesh::TriMesh;

/// The outcome of [`self_intersections`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct SelfIntersections {
    /// Pairs of faces that intersect by the standard definition
    /// ([`faces_intersect`](crate::geometry::faces_intersect)): they share no vertex and their
    /// closed triangles share a point, share one vertex and meet elsewhere too, or share an edge
    /// and overlap. The sum of the three counts below.
    pub pairs: usize,
    /// Of those, pairs of faces with no vertex in common (they cross or touch).
    pub apart: usize,
    /// Pairs of faces with one vertex in common that meet elsewhere too (a fan folded over
    /// itself).
    pub at_vertex: usize,
    /// Pairs of faces with an edge in common that overlap (a face folded flat onto its
    /// neighbour).
    pub along_edge: usize,
    /// The first such pair `[f, g]`, f < g, in lexicographic order.
    pub first: Option<[u32; 2]>,
    /// The kind of the first pair.
    pub first_kind: Option<PairKind>,
    /// Pairs of faces whose bounding boxes overlap: the exact tests made.
    pub candidates: usize,
    /// Faces that entered the search: those with every index in range, finite corners and
    /// non-zero area, and of the faces on the same three vertices (duplicates, in any order or
    /// winding) only the first, so that a duplicate's pairs are counted once.
    pub faces: usize,
}

impl SelfIntersections {
    /// The pairs of `kind`.
    pub fn of_kind(&self, kind: PairKind) -> usize {
        match kind {
            PairKind::Apart => self.apart,
            PairKind::AtVertex => self.at_vertex,
            PairKind::AlongEdge => self.along_edge,
        }
    }
}

/// Finds the pairs of faces of `mesh` that intersect (see [`SelfIntersections`]; the search is
/// [`classified_pairs`]: a BVH and exact predicates, parallel and deterministic). Faces with an
/// index out of range, a non-finite corner or zero area are left out, and faces on the same
/// three vertices as an earlier face are searched once, as the first of them (the invariant
/// check and the topology count both kinds on their own).
pub fn self_intersections(mesh: &TriMesh) -> SelfIntersections {
    let (pairs, search) = classified_pairs(&mesh.positions, &mesh.triangles);
    let count = |k: PairKind| pairs.iter().filter(|p| p.1 == k).count();
    SelfIntersections {
        pairs: pairs.len(),
        apart: count(PairKind::Apart),
        at_vertex: count(PairKind::AtVertex),
        along_edge: count(PairKind::AlongEdge),
        first: pairs.first().map(|p| p.0),
        first_kind: pairs.first().map(|p| p.1),
        candidates: search.candidates,
        faces: search.faces,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::triangle_intersection::triangles_intersect;

    #[test]
    fn pairs_are_counted_by_kind() {
        use glam::DVec3;
        // Two faces on the edge 0-1, the second folded flat onto the first; a third face around
        // vertex 0 lying over the first's corner region; a fourth apart, through the first.
        let p = vec![
            DVec3::new(0., 0., 0.),
            DVec3::new(4., 0., 0.),
            DVec3::new(0., 4., 0.),
            DVec3::new(1., 2., 0.),
            DVec3::new(1., 1., 0.),
            DVec3::new(0.5, 0.2, 0.),
            DVec3::new(1., 1., -1.),
            DVec3::new(1., 1., 1.),
            DVec3::new(2., 1., 1.),
        ];
        let m = TriMesh::new(p, vec![[0, 1, 2], [1, 0, 3], [0, 4, 5], [6, 7, 8]]);
        let r = self_intersections(&m);
        // [0,1,2] with [1,0,3] along the edge; [0,1,2] and [1,0,3] with [0,4,5] at vertex 0;
        // [6,7,8] apart from all three, through the point (1, 1, 0) that each of them holds.
        assert_eq!(r.along_edge, 1, "{r:?}");
        assert_eq!(r.at_vertex, 2, "{r:?}");
        assert_eq!(r.apart, 3, "{r:?}");
        assert_eq!(r.pairs, 6);
        assert_eq!(
            (r.first, r.first_kind),
            (Some([0, 1]), Some(PairKind::AlongEdge))
        );
        let text = crate::check::check_invariants(&m)
            .iter()
            .map(|v| v.to_string())
            .collect::<Vec<_>>()
            .join("; ");
        assert!(
            text.contains(
                "6 pairs of faces intersect (3 apart, 2 at a shared vertex, 1 along a shared edge)"
            ),
            "{text}"
        );
    }

    #[test]
    fn a_sphere_has_none_and_a_pushed_vertex_makes_some() {
        // A closed UV sphere: no self-intersection.
        let mut m = crate::mesh::test_meshes::uv_sphere(1.0, 12, 24);
        let r = self_intersections(&m);
        assert_eq!((r.pairs, r.first), (0, None), "{r:?}");
        assert!(r.candidates > 0);
        // Push one vertex through the opposite side: its fan crosses faces there.
        // Ring 6 (the equator), longitude 0: vertex 2 + 5 · 24.
        let k = 2 + 5 * 24;
        m.positions[k] = -1.5 * m.positions[k];
        let r = self_intersections(&m);
        assert!(r.pairs > 0, "{r:?}");
        let [f, g] = r.first.unwrap();
        assert!(triangles_intersect(
            m.corners(f as usize),
            m.corners(g as usize)
        ));
        assert_eq!(r, self_intersections(&m));
    }
}
