//! The last guard before a mesh is written: faces of no area (three corners on a line, as where
//! a triangle soup's boundary samples and a sample pressed between them close a cap) are mended
//! by one local operator each. A cap (a corner on the longest edge) has that edge flipped; a
//! face the flip cannot mend (the longest edge on the boundary, or the flip would make a face
//! of no area) has one of its two shorter edges collapsed onto the end that is not fixed, or
//! else its corner off the longest edge moved to the middle of its ring. Each face gets one
//! attempt of each, so the work is O(degenerate faces · degree).

use serde::Serialize;

use crate::geometry::triangle::is_degenerate_face;
use crate::mesh::edit::{EditMesh, SlotPolicy};
use crate::mesh::TriMesh;

/// What [`mend_degenerate_faces`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct DegenerateStats {
    /// Faces of no area found.
    pub found: usize,
    /// Edges flipped.
    pub flips: usize,
    /// Edges collapsed.
    pub collapses: usize,
    /// Vertices moved to the middle of their ring.
    pub moves: usize,
    /// Faces of no area left (neither operator applied).
    pub left: usize,
}

/// Mends the faces of `mesh` that have no area ([`is_degenerate_face`]): per face, the flip of
/// its longest edge when that edge has two faces and both new faces have an area, else the
/// collapse of one of its two shorter edges onto an end (never removing a vertex in `fixed`, a
/// boundary sample, that is on the mesh's boundary), when [`EditMesh::collapse_edge`] allows
/// it, else the move of the corner off the longest edge to the mean of its ring's vertices.
/// Returns what was done and each face's index in `mesh` before (`None` for a face an operator
/// made or changed), as `EditMesh::into_parts` gives it. A mesh without such faces is left as
/// it is.
pub fn mend_degenerate_faces(
    mesh: &mut TriMesh,
    fixed: &[bool],
) -> (DegenerateStats, Option<Vec<Option<u32>>>) {
    let mut stats = DegenerateStats::default();
    let found: Vec<u32> = (0..mesh.triangles.len() as u32)
        .filter(|&f| is_degenerate_face(&mesh.positions, mesh.triangles[f as usize]))
        .collect();
    if found.is_empty() {
        return (stats, None);
    }
    stats.found = found.len();
    let is_fixed = |v: u32| fixed.get(v as usize).copied().unwrap_or(false);
    let mut m: EditMesh<Option<u32>> = EditMesh::from_trimesh(mesh, Some, SlotPolicy::Reuse);
    for f in found {
        // The face may have gone or changed with an earlier operation.
        let Some(t) = m.face(f) else { continue };
        if m.label(f) != Some(f) || !is_degenerate_face(m.positions(), t) {
            continue;
        }
        let p = m.corners(t);
        // Edges by length: edge k runs from corner k to corner k + 1.
        let mut edges: Vec<(f64, usize)> = (0..3)
            .map(|k| (p[k].distance_squared(p[(k + 1) % 3]), k))
            .collect();
        edges.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let edge = |k: usize| (t[k], t[(k + 1) % 3]);
        let (a, b) = edge(edges[2].1);
        if flips_to_area(&m, a, b) && m.flip_edge(a, b, None).is_ok() {
            stats.flips += 1;
            continue;
        }
        // A fixed sample that the triangulation left inside the mesh (no boundary edge at it)
        // may go: its face has no area to keep.
        let pinned = |m: &EditMesh<Option<u32>>, v: u32| is_fixed(v) && m.is_boundary_vertex(v);
        let collapsed = edges[..2].iter().any(|&(_, k)| {
            let (a, b) = edge(k);
            let (removed, kept) = if pinned(&m, a) { (b, a) } else { (a, b) };
            !pinned(&m, removed)
                && m.collapse_edge(removed, kept, m.position(kept), None)
                    .is_ok()
        });
        if collapsed {
            stats.collapses += 1;
            continue;
        }
        // Else the corner off the longest edge moves to the middle of its ring (a relocation
        // the mesh refuses when a face around it would lose its area).
        let apex = t[(edges[2].1 + 2) % 3];
        let ring = m.ring(apex);
        if !pinned(&m, apex) && !ring.is_empty() {
            let centre =
                ring.iter().map(|&u| m.position(u)).sum::<glam::DVec3>() / ring.len() as f64;
            let from = m.position(apex);
            if m.relocate_vertex(apex, centre).is_ok()
                && m.faces_around(apex)
                    .iter()
                    .filter_map(|&g| m.face(g))
                    .all(|u| !is_degenerate_face(m.positions(), u))
            {
                stats.moves += 1;
                continue;
            }
            let _ = m.relocate_vertex(apex, from);
        }
        stats.left += 1;
    }
    let (positions, triangles, origin) = m.into_parts();
    mesh.positions = positions;
    mesh.triangles = triangles;
    (stats, Some(origin))
}

/// Whether flipping the edge `a`–`b` (of two faces) gives two faces with an area.
fn flips_to_area(m: &EditMesh<Option<u32>>, a: u32, b: u32) -> bool {
    let Ok((_, _, c, d)) = m.edge_faces(a, b) else {
        return false;
    };
    [[c, d, b], [d, c, a]]
        .iter()
        .all(|&t| !is_degenerate_face(m.positions(), t))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn a_cap_is_flipped_and_a_cap_on_the_boundary_has_its_apex_moved() {
        // A cap: vertex 4 exactly on the edge 0-2, in face [0, 4, 2]; the other side of 0-2 is
        // face [0, 2, 3] (vertex 1 and 4 make the rest of a fan).
        let positions = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, -1.0, 0.0),
            DVec3::new(2.0, 2.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
        ];
        let mut m = TriMesh::new(positions, vec![[0, 1, 4], [1, 2, 4], [0, 4, 2], [0, 2, 3]]);
        assert!(is_degenerate_face(&m.positions, m.triangles[2]));
        let (s, origin) = mend_degenerate_faces(&mut m, &[false; 5]);
        assert_eq!(
            (s.found, s.flips, s.collapses, s.left),
            (1, 1, 0, 0),
            "{s:?}"
        );
        assert!(m
            .triangles
            .iter()
            .all(|&t| !is_degenerate_face(&m.positions, t)));
        let origin = origin.unwrap();
        assert_eq!(origin.len(), m.triangles.len());
        assert_eq!(origin.iter().filter(|o| o.is_none()).count(), 2);
        // The same cap with its long edge on the boundary (no face beyond 0-2: no flip) and no
        // collapse the link condition allows: the apex 4, inside the mesh, moves to the middle
        // of its ring (even as a fixed sample: it is on no boundary edge).
        let mut open = TriMesh::new(m.positions.clone(), vec![[0, 1, 4], [1, 2, 4], [0, 4, 2]]);
        let (s, _) = mend_degenerate_faces(&mut open, &[true, true, true, false, true]);
        assert_eq!((s.found, s.moves, s.left), (1, 1, 0), "{s:?}");
        assert_eq!(
            open.positions[4],
            (DVec3::ZERO + DVec3::new(2.0, -1.0, 0.0) + DVec3::new(2.0, 2.0, 0.0)) / 3.0
        );
        assert!(open
            .triangles
            .iter()
            .all(|&t| !is_degenerate_face(&open.positions, t)));
        let before = open.clone();
        // A mesh with no such face is not touched.
        let mut clean = TriMesh::new(
            before.positions.clone(),
            vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]],
        );
        let (s, origin) = mend_degenerate_faces(&mut clean, &[false; 5]);
        assert_eq!(s, DegenerateStats::default());
        assert!(origin.is_none());
    }
}
