//! The faces a new or moved face of an edit mesh would cross: a BVH over the faces' slots whose
//! leaves are updated as faces are made or moved ([`CrossingGuard::changed`]), so each query
//! costs O(log F) plus the faces whose boxes overlap, however many operations came before. (A
//! slot whose face was removed keeps its leaf; its face is skipped when a query meets it.) The
//! guard of the finishing stage's operators and of untangle's fold collapses.

use glam::DVec3;
use parry3d_f64::bounding_volume::BoundingVolume;
use parry3d_f64::partitioning::Bvh;

use super::edit::EditMesh;
use crate::geometry::face_intersection::faces_within;
use crate::geometry::self_intersection::triangle_aabb;
use crate::geometry::triangle::is_degenerate_face;

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
    /// vertices' positions, or where an operation would put them) intersects by the standard
    /// definition ([`faces_within`]: sharing no vertex and meeting, sharing one and meeting
    /// elsewhere too, sharing an edge and overlapping; exact, or nearer than the guard's `near`),
    /// leaving out the slots in `replaced`, until `visit` returns true; whether it did. The
    /// faces sharing a vertex with `t` that are not replaced must have their corners where `p`
    /// has them (an operation replaces every face around a vertex it moves).
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
            faces_within(t, p, u, m.corners(u), self.near).is_some() && visit(g)
        });
        found
    }

    /// The pairs `[f, g]` (slots, f < g) of live faces that intersect or come within the
    /// guard's `near` of intersecting ([`faces_within`]) with at least one of them in `faces`:
    /// the pairs of [`pairs_within`](crate::geometry::self_intersection::pairs_within) over the
    /// live faces that touch `faces`, decided by the same test with the smaller slot first
    /// (degenerate faces and faces with a corner not finite left out). Sorted, each once. The
    /// guard must know every face's current box ([`Self::changed`]).
    pub(crate) fn pairs_with<L: Copy>(&self, m: &EditMesh<L>, faces: &[u32]) -> Vec<[u32; 2]> {
        let p = m.positions();
        let usable =
            |t: [u32; 3]| t.iter().all(|&v| p[v as usize].is_finite()) && !is_degenerate_face(p, t);
        let mut listed = faces.to_vec();
        listed.sort_unstable();
        listed.dedup();
        let mut pairs = Vec::new();
        for &f in &listed {
            let Some(t) = m.face(f).filter(|&t| usable(t)) else {
                continue;
            };
            let query = triangle_aabb(m.corners(t)).loosened(self.near);
            for g in self.bvh.intersect_aabb(&query) {
                // A pair of two listed faces is tested once, from its smaller slot (the boxes'
                // overlap within `near` is symmetric).
                if g < f && listed.binary_search(&g).is_ok() {
                    continue;
                }
                let Some(u) = m.face(g).filter(|&u| g != f && usable(u)) else {
                    continue;
                };
                let (a, b) = if f < g { (t, u) } else { (u, t) };
                if faces_within(a, m.corners(a), b, m.corners(b), self.near).is_some() {
                    pairs.push([f.min(g), f.max(g)]);
                }
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        pairs
    }

    /// The pairs of [`Self::pairs_with`] over all live faces after the vertices in `moved`
    /// moved, from `pairs` (those before): the faces around the moved vertices take their new
    /// boxes, their pairs are dropped and searched again; the others' pairs stand. Sorted.
    pub(crate) fn moved<L: Copy>(
        &mut self,
        m: &EditMesh<L>,
        pairs: &[[u32; 2]],
        moved: &[u32],
    ) -> Vec<[u32; 2]> {
        let faces = self.vertices_moved(m, moved);
        let mut after: Vec<[u32; 2]> = pairs
            .iter()
            .copied()
            .filter(|p| p.iter().all(|f| faces.binary_search(f).is_err()))
            .collect();
        after.extend(self.pairs_with(m, &faces));
        after.sort_unstable();
        after.dedup();
        after
    }

    /// Records that the vertices in `moved` moved: the faces around them (returned, sorted) take
    /// their new boxes (as [`Self::moved`] does, without searching their pairs).
    pub(crate) fn vertices_moved<L: Copy>(&mut self, m: &EditMesh<L>, moved: &[u32]) -> Vec<u32> {
        let mut faces: Vec<u32> = moved
            .iter()
            .flat_map(|&v| m.faces_around(v).iter().copied())
            .collect();
        faces.sort_unstable();
        faces.dedup();
        self.changed(m, &faces);
        faces
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

    /// Whether one of `faces` (at the mesh's current positions: the faces an operation makes in
    /// place of the slots `replaced`) intersects a live face of `m` that is not in `replaced`
    /// ([`Self::visit_crossed`]), or another of `faces` ([`new_faces_intersect`]).
    pub(crate) fn crosses<L: Copy>(
        &self,
        m: &EditMesh<L>,
        faces: &[[u32; 3]],
        replaced: &[u32],
    ) -> bool {
        new_faces_intersect(faces, |t| m.corners(t), self.near)
            || faces
                .iter()
                .any(|&t| self.visit_crossed(m, t, m.corners(t), replaced, |_| true))
    }
}

/// Whether two of `faces` (vertex indices; `corners` gives each one's corners) intersect or come
/// within `near` of intersecting ([`faces_within`]): the faces an operation makes, among
/// themselves (a fan moved around its vertex may fold over itself). Degenerate faces are left
/// out, as everywhere.
pub(crate) fn new_faces_intersect(
    faces: &[[u32; 3]],
    corners: impl Fn([u32; 3]) -> [DVec3; 3],
    near: f64,
) -> bool {
    // A face that repeats an index is never decided (`faces_within`); one of no area is left
    // out here.
    let usable = |t: [u32; 3]| {
        let p = corners(t);
        p.iter().all(|x| x.is_finite()) && !crate::geometry::triangle::is_degenerate_triangle(p)
    };
    faces.iter().enumerate().any(|(i, &a)| {
        usable(a)
            && faces[i + 1..]
                .iter()
                .any(|&b| usable(b) && faces_within(a, corners(a), b, corners(b), near).is_some())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::self_intersection::pairs_within;
    use crate::mesh::edit::SlotPolicy;
    use crate::mesh::test_meshes::grid;
    use crate::mesh::TriMesh;
    use rand::{RngExt, SeedableRng};

    /// Pairs kept up to date through the guard, moves after moves, are the pairs a search of
    /// the whole mesh finds: two wavy sheets 0.05 apart whose vertices are pushed about by up
    /// to 0.1 (so pairs come and go), with `near` 0 and 0.02.
    #[test]
    fn the_pairs_kept_through_the_guard_are_the_pairs_of_a_whole_search() {
        let sheet = |z: f64| {
            grid(12, move |i, j| {
                DVec3::new(i as f64, j as f64, z + 0.03 * ((i + 2 * j) as f64).sin())
            })
        };
        let (a, b) = (sheet(0.0), sheet(0.05));
        let offset = a.positions.len() as u32;
        let mesh = TriMesh::new(
            [a.positions, b.positions].concat(),
            a.triangles
                .into_iter()
                .chain(b.triangles.into_iter().map(|t| t.map(|v| v + offset)))
                .collect(),
        );
        for near in [0.0, 0.02] {
            let mut m: EditMesh<()> = EditMesh::from_trimesh(&mesh, |_| (), SlotPolicy::Reuse);
            let triangles = m.live_faces().0;
            let mut guard = CrossingGuard::within(&m, near);
            let mut pairs = pairs_within(m.positions(), &triangles, near);
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
            let mut seen = 0;
            for _ in 0..40 {
                let moved: Vec<u32> = (0..5)
                    .map(|_| rng.random_range(0..m.vertex_count() as u32))
                    .collect();
                for &v in &moved {
                    let d = DVec3::new(0.0, 0.0, rng.random_range(-0.1..0.1));
                    m.relocate_vertex(v, m.position(v) + d).unwrap();
                }
                pairs = guard.moved(&m, &pairs, &moved);
                assert_eq!(pairs, pairs_within(m.positions(), &triangles, near));
                seen = seen.max(pairs.len());
            }
            assert!(seen > 0, "the moves made no pair: the test tests nothing");
        }
    }
}
