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
    use glam::DVec3;

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    #[test]
    fn a_sphere_has_none_and_a_pushed_vertex_makes_some() {
        // A closed UV sphere: no self-intersection.
        let (nu, nv) = (24, 12);
        let mut positions = vec![v(0., 0., 1.), v(0., 0., -1.)];
        for j in 1..nv {
            let th = std::f64::consts::PI * j as f64 / nv as f64;
            for i in 0..nu {
                let ph = std::f64::consts::TAU * i as f64 / nu as f64;
                positions.push(v(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()));
            }
        }
        let idx = |j: usize, i: usize| (2 + (j - 1) * nu + i % nu) as u32;
        let mut triangles = Vec::new();
        for i in 0..nu {
            triangles.push([0, idx(1, i), idx(1, i + 1)]);
            triangles.push([1, idx(nv - 1, i + 1), idx(nv - 1, i)]);
        }
        for j in 1..nv - 1 {
            for i in 0..nu {
                triangles.push([idx(j, i), idx(j + 1, i), idx(j + 1, i + 1)]);
                triangles.push([idx(j, i), idx(j + 1, i + 1), idx(j, i + 1)]);
            }
        }
        let mut m = TriMesh::new(positions, triangles);
        let r = self_intersections(&m);
        assert_eq!((r.pairs, r.first), (0, None), "{r:?}");
        assert!(r.candidates > 0);
        // Push one vertex through the opposite side: its fan crosses faces there.
        let k = idx(6, 0) as usize;
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
