//! Self-intersections of a triangle mesh, as the invariant check and the report count them.

use serde::Serialize;

use crate::geometry::self_intersection::intersecting_pairs_counted;
use crate::mesh::TriMesh;

/// The outcome of [`self_intersections`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct SelfIntersections {
    /// Pairs of non-adjacent faces (no vertex index in common) whose closed triangles share at
    /// least one point: they cross, or touch at a point, along an edge or in a common area.
    pub pairs: usize,
    /// The first such pair `[f, g]`, f < g, in lexicographic order.
    pub first: Option<[u32; 2]>,
    /// Pairs of non-adjacent faces whose bounding boxes overlap: the exact tests made.
    pub candidates: usize,
}

/// Finds the pairs of non-adjacent faces of `mesh` that intersect (see [`SelfIntersections`];
/// the search is [`intersecting_pairs_counted`]: a BVH and exact predicates, parallel and
/// deterministic). Faces with an index out of range, a non-finite corner or zero area are left
/// out (the invariant check reports them on their own).
pub fn self_intersections(mesh: &TriMesh) -> SelfIntersections {
    let (pairs, candidates) = intersecting_pairs_counted(&mesh.positions, &mesh.triangles);
    SelfIntersections {
        pairs: pairs.len(),
        first: pairs.first().copied(),
        candidates,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::triangle_intersection::triangles_intersect;

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
