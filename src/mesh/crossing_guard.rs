//! The faces a new or moved face of an edit mesh would cross: a BVH over the faces' slots whose
//! leaves are updated as faces are made or moved ([`CrossingGuard::changed`]), so each query
//! costs O(log F) plus the faces whose boxes overlap, however many operations came before. (A
//! slot whose face was removed keeps its leaf; its face is skipped when a query meets it.) The
//! guard of the finishing stage's operators and of untangle's fold collapses.

use glam::DVec3;
use parry3d_f64::bounding_volume::BoundingVolume;
use parry3d_f64::partitioning::Bvh;

use super::edit::EditMesh;
use crate::geometry::self_intersection::triangle_aabb;
use crate::geometry::triangle_intersection::triangles_within;

/// A BVH over the live faces of an edit mesh, by slot (see the module).
pub(crate) struct CrossingGuard {
    bvh: Bvh,
    /// Faces nearer than this count as sharing a point (`triangles_within`); 0: the exact test.
    near: f64,
}

impl CrossingGuard {
    /// The guard of `m`'s live faces at their current positions.
    pub(crate) fn new<L: Copy>(m: &EditMesh<L>) -> Self {
        Self::within(m, 0.0)
    }

    /// The guard of `m`'s live faces at their current positions, for which two faces nearer
    /// than `near` (the mesh's units) share a point: faces that touch once rounded by `near / 2`.
    pub(crate) fn within<L: Copy>(m: &EditMesh<L>, near: f64) -> Self {
        let (live, slots) = m.live_faces();
        let boxes = live
            .iter()
            .zip(&slots)
            .map(|(&t, &f)| (f as usize, triangle_aabb(m.corners(t))));
        CrossingGuard {
            bvh: crate::geometry::bvh::bvh_of(boxes),
            near: near.max(0.0),
        }
    }

    /// Records that the faces in `slots` were made or moved: their leaves take their new boxes.
    pub(crate) fn changed<L: Copy>(&mut self, m: &EditMesh<L>, slots: &[u32]) {
        for &f in slots {
            if let Some(t) = m.face(f) {
                self.bvh.insert(triangle_aabb(m.corners(t)), f);
            }
        }
    }

    /// Calls `visit` with each live face (slot) of `m` that the face `t` with corners `p` (its
    /// vertices' positions, or where an operation would put them) shares a point with, leaving
    /// out the slots in `replaced` and the faces with a vertex of `t` (exact test, or nearer
    /// than the guard's `near`), until `visit` returns true; whether it did.
    pub(crate) fn visit_crossed<L: Copy>(
        &self,
        m: &EditMesh<L>,
        t: [u32; 3],
        p: [DVec3; 3],
        replaced: &[u32],
        mut visit: impl FnMut(u32) -> bool,
    ) -> bool {
        let query = triangle_aabb(p).loosened(self.near);
        let found = self.bvh.intersect_aabb(&query).any(|g| {
            if replaced.contains(&g) {
                return false;
            }
            let Some(u) = m.face(g) else {
                return false;
            };
            !t.iter().any(|v| u.contains(v))
                && triangles_within(p, m.corners(u), self.near)
                && visit(g)
        });
        found
    }

    /// How many live faces the face `t` with corners `p` crosses (as [`Self::visit_crossed`]).
    pub(crate) fn count_crossed<L: Copy>(
        &self,
        m: &EditMesh<L>,
        t: [u32; 3],
        p: [DVec3; 3],
        replaced: &[u32],
    ) -> usize {
        let mut n = 0;
        self.visit_crossed(m, t, p, replaced, |_| {
            n += 1;
            false
        });
        n
    }

    /// Whether one of `faces` (at the mesh's current positions) shares a point with a live face
    /// of `m` that is not in `replaced` and has no vertex in common with it.
    pub(crate) fn crosses<L: Copy>(
        &self,
        m: &EditMesh<L>,
        faces: &[[u32; 3]],
        replaced: &[u32],
    ) -> bool {
        faces
            .iter()
            .any(|&t| self.visit_crossed(m, t, m.corners(t), replaced, |_| true))
    }
}
