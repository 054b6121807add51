//! Parts of an open scan apart from its surface that face against the data. Where the data is
//! one sheet a sample or two wide (a strip of a range map seen at a grazing angle), the
//! umbrellas cover it from one side and the assembly's hole filling closes its outline from
//! the other, so the strip comes out as a closed part of no thickness ("pillow"), both sides on
//! the same data; or, partly closed, as an open part folded over itself. One sheet of data
//! encloses no volume, and two sheets closer than sigma_p are one RIMLS surface: a closed part
//! whose thickness 3·volume/area (the radius of a ball, 1.5 times that of a long tube) is far
//! below sigma_p is a pillow, and in an open part, a face facing against the data's normals is
//! a fold. Both lose the faces facing against the data; the side facing along it stays, so the
//! strip is kept as an open part with the data under it. Closed parts thicker than that stay
//! (a thin part of a closed model that split off is a volume, if a wrong one), and so does the
//! largest part (the surface itself).

use glam::DVec3;
use serde::Serialize;

use crate::mesh::parts::parts;
use crate::mesh::TriMesh;
use crate::triangulate::unsupported::remove_faces_keeping_manifold;
use crate::triangulate::FaceSource;

/// What [`open_pillows`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Pillows {
    /// Parts opened (closed ones) or trimmed (open ones).
    pub opened: usize,
    /// Their faces removed (those facing against the data).
    pub faces: usize,
    /// Faces of the smaller fans at vertices the removal pinched.
    pub pinched_faces: usize,
}

/// In every part of `mesh` but the largest (by faces; the first of equals) that is open, or
/// closed with a thickness 3·|volume|/area below `max_thickness` (model units of `mesh`), the
/// faces that `front(centroid, unit normal)` says face against the data go. A part with all
/// its faces on one side (no back, or no front) stays as it is. The smaller fans at vertices
/// the removal pinches go too, so the output stays manifold. Vertices stay (unreferenced ones
/// are left for the caller); `sources` (one per face, or empty) is filtered along.
/// Deterministic; does not fail.
pub fn open_pillows(
    mesh: &mut TriMesh,
    sources: &mut Vec<FaceSource>,
    max_thickness: f64,
    front: impl Fn(DVec3, DVec3) -> bool,
) -> Pillows {
    let parts = parts(mesh);
    let Some(largest) = (0..parts.len()).max_by_key(|&k| (parts[k].faces.len(), usize::MAX - k))
    else {
        return Pillows::default();
    };
    let mut record = Pillows::default();
    let mut drop = vec![false; mesh.triangles.len()];
    for (k, part) in parts.iter().enumerate() {
        if k == largest {
            continue;
        }
        let area: f64 = part.faces.iter().map(|&f| mesh.face_area(f)).sum();
        let volume = mesh.signed_volume_of(part.faces.iter().copied()).abs();
        if part.closed && (area <= 0.0 || 3.0 * volume / area >= max_thickness) {
            continue;
        }
        let back: Vec<usize> = part
            .faces
            .iter()
            .copied()
            .filter(|&f| {
                let [a, b, c] = mesh.corners(f);
                !front((a + b + c) / 3.0, mesh.face_normal(f))
            })
            .collect();
        if back.is_empty() || back.len() == part.faces.len() {
            continue;
        }
        record.opened += 1;
        record.faces += back.len();
        for f in back {
            drop[f] = true;
        }
    }
    if record.opened > 0 {
        record.pinched_faces = remove_faces_keeping_manifold(mesh, sources, &drop);
    }
    record
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::topology;

    /// The largest part, a 4 × 4 grid of squares at z = -5 (32 faces, facing up), and beside
    /// it a closed part about `h`/2 thick: the two sides of a 4 × 1 strip in the plane z = 0
    /// joined along its outline (10 vertices), the bottom (8 faces, facing down) through the
    /// outline's own vertices, the top (16 faces, facing up) through 4 vertices lifted by `h`
    /// on its middle line (a range map's strip: the umbrellas on one side, the hole filling of
    /// its outline on the other).
    fn grid_and_pillow(h: f64) -> TriMesh {
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for j in 0..5 {
            for i in 0..5 {
                positions.push(DVec3::new(i as f64, j as f64, -5.0));
            }
        }
        let g = |i: u32, j: u32| j * 5 + i;
        for j in 0..4 {
            for i in 0..4 {
                triangles.push([g(i, j), g(i + 1, j), g(i + 1, j + 1)]);
                triangles.push([g(i, j), g(i + 1, j + 1), g(i, j + 1)]);
            }
        }
        let o = positions.len() as u32;
        let (b, t, c) = (|i: u32| o + i, |i: u32| o + 5 + i, |i: u32| o + 10 + i);
        for y in [0.0, 1.0] {
            for i in 0..5 {
                positions.push(DVec3::new(20.0 + i as f64, y, 0.0));
            }
        }
        for i in 0..4 {
            positions.push(DVec3::new(20.5 + i as f64, 0.5, h));
        }
        for j in 0..4 {
            triangles.push([b(j), t(j + 1), b(j + 1)]);
            triangles.push([b(j), t(j), t(j + 1)]);
        }
        triangles.push([b(0), c(0), t(0)]);
        for j in 0..4 {
            triangles.push([b(j), b(j + 1), c(j)]);
            triangles.push([t(j + 1), t(j), c(j)]);
        }
        for j in 0..3 {
            triangles.push([b(j + 1), c(j + 1), c(j)]);
            triangles.push([t(j + 1), c(j), c(j + 1)]);
        }
        triangles.push([b(4), t(4), c(3)]);
        TriMesh::new(positions, triangles)
    }

    fn faces_up(_: DVec3, n: DVec3) -> bool {
        n.z > 0.0
    }

    #[test]
    fn a_flat_closed_part_is_opened_to_its_front_side() {
        let mut m = grid_and_pillow(0.01);
        let t = topology(&m);
        assert_eq!((t.boundary_loops, t.components), (1, 2), "the test case");
        let mut sources = vec![FaceSource::ThreeVotes; m.triangles.len()];
        let r = open_pillows(&mut m, &mut sources, 0.05, faces_up);
        assert_eq!((r.opened, r.faces, r.pinched_faces), (1, 8, 0));
        assert_eq!(m.triangles.len(), 32 + 16);
        assert_eq!(sources.len(), m.triangles.len());
        let t = topology(&m);
        assert_eq!((t.boundary_loops, t.components), (2, 2));
        assert!(t.is_manifold());
        // What is left of the strip faces up: its top side.
        assert!((32..m.triangles.len()).all(|f| m.face_normal(f).z > 0.0));
    }

    #[test]
    fn an_open_part_loses_its_faces_facing_against_the_data() {
        // The pillow with two faces of its bottom gone: open, folded over itself.
        let mut m = grid_and_pillow(0.5);
        m.triangles.remove(32);
        m.triangles.remove(32);
        assert_eq!(topology(&m).boundary_loops, 1 + 1, "the test case");
        let mut sources = vec![FaceSource::ThreeVotes; m.triangles.len()];
        let r = open_pillows(&mut m, &mut sources, 0.05, faces_up);
        assert_eq!((r.opened, r.faces), (1, 6));
        assert_eq!(m.triangles.len(), 32 + 16);
        assert!((32..m.triangles.len()).all(|f| m.face_normal(f).z > 0.0));
        assert!(topology(&m).is_manifold());
    }

    #[test]
    fn thick_parts_the_largest_part_and_one_sided_parts_stay() {
        let mut sources = Vec::new();
        // Closed and thicker than the bound.
        let mut m = grid_and_pillow(0.5);
        assert_eq!(open_pillows(&mut m, &mut sources, 0.05, faces_up).opened, 0);
        // The same pillow alone is the largest part.
        let mut alone = grid_and_pillow(0.01);
        alone.triangles.drain(..32);
        assert_eq!(
            open_pillows(&mut alone, &mut sources, 0.05, faces_up).opened,
            0
        );
        // No face is on the back: nothing to open.
        let mut m = grid_and_pillow(0.01);
        assert_eq!(
            open_pillows(&mut m, &mut sources, 0.05, |_, _| true).opened,
            0
        );
        assert_eq!(m.triangles.len(), 32 + 24);
    }
}
