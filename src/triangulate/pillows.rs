//! Faces of a scan's mesh that fold over the data. Where the data is one sheet a sample or two
//! wide (a strip of a range map seen at a grazing angle), the umbrellas cover it from one side
//! and the assembly's hole filling closes its outline from the other, so the strip comes out as
//! a closed part of no thickness ("pillow"), both sides on the same data; or, partly closed, as
//! a part folded over itself; near the boundary of the surface itself, as a flap folded back
//! over it. Such a face faces against the data (the RIMLS gradient at its centroid) and no data
//! lies on its side: no data point near it has a normal on its side ([`FaceSide::Fold`]). A thin
//! part of a closed model can face against the gradient too (two sheets closer than the RIMLS
//! support, where the surface has one side), but data of its other sheet lies near those faces
//! with normals on their side ([`FaceSide::Backed`]).

use glam::DVec3;
use serde::Serialize;

use crate::mesh::parts::parts;
use crate::mesh::TriMesh;
use crate::triangulate::unsupported::remove_faces_keeping_manifold;
use crate::triangulate::FaceSource;

/// Where a face lies against the data, as the caller's `side(centroid, unit normal)` of
/// [`open_pillows`] says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaceSide {
    /// It faces along the data (or nothing says otherwise).
    Front,
    /// It faces against the data, but data with normals on its side lies near it (a thin
    /// part's other sheet).
    Backed,
    /// It faces against the data and no data lies on its side: a fold over one sheet.
    Fold,
}

/// What [`open_pillows`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Pillows {
    /// Parts opened (closed ones) or trimmed (open ones, the largest included).
    pub opened: usize,
    /// Their faces removed (the folds).
    pub faces: usize,
    /// Faces of the smaller fans at vertices the removal pinched.
    pub pinched_faces: usize,
}

/// Removes the folds of `mesh` ([`FaceSide::Fold`] by `side(centroid, unit normal)`): in every
/// open part (in the largest, only when `flaps`, and only those with a corner on its boundary or
/// one edge from it: a flap folded back over the surface at the data's edge), and in every closed part but the
/// largest (by faces; the first of equals) whose
/// faces against the data are all folds (a pillow; one with a [`FaceSide::Backed`] face is a
/// volume, if a thin one, and stays closed). A part whose faces are all folds, or none, stays
/// as it is. The smaller fans at vertices the removal pinches go too, so the output stays
/// manifold. Vertices stay (unreferenced ones are left for the caller); `sources` (one per
/// face, or empty) is filtered along. Deterministic; does not fail.
pub fn open_pillows(
    mesh: &mut TriMesh,
    sources: &mut Vec<FaceSource>,
    flaps: bool,
    side: impl Fn(DVec3, DVec3) -> FaceSide,
) -> Pillows {
    let parts = parts(mesh);
    let Some(largest) = (0..parts.len()).max_by_key(|&k| (parts[k].faces.len(), usize::MAX - k))
    else {
        return Pillows::default();
    };
    // The vertices on the boundary or one edge from it: the largest part's folds are flaps
    // there (elsewhere, a face against data without data on its side is a thin part whose
    // data's normals are wrong, and removing it would open the surface). Read only with flaps.
    let mut near_boundary = vec![false; mesh.positions.len()];
    let uses = if flaps {
        mesh.edge_uses()
    } else {
        Default::default()
    };
    for (&(a, b), &(_, n)) in &uses {
        if n == 1 {
            near_boundary[a as usize] = true;
            near_boundary[b as usize] = true;
        }
    }
    let on_boundary = near_boundary.clone();
    for &(a, b) in uses.keys() {
        if on_boundary[a as usize] || on_boundary[b as usize] {
            near_boundary[a as usize] = true;
            near_boundary[b as usize] = true;
        }
    }
    let mut record = Pillows::default();
    let mut drop = vec![false; mesh.triangles.len()];
    for (k, part) in parts.iter().enumerate() {
        if k == largest && (part.closed || !flaps) {
            continue;
        }
        let sides: Vec<FaceSide> = part
            .faces
            .iter()
            .map(|&f| {
                if k == largest && !mesh.triangles[f].iter().any(|&v| near_boundary[v as usize]) {
                    return FaceSide::Front;
                }
                let [a, b, c] = mesh.corners(f);
                side((a + b + c) / 3.0, mesh.face_normal(f))
            })
            .collect();
        let folds = sides.iter().filter(|&&s| s == FaceSide::Fold).count();
        if folds == 0 || folds == part.faces.len() {
            continue;
        }
        if part.closed && sides.contains(&FaceSide::Backed) {
            continue;
        }
        record.opened += 1;
        record.faces += folds;
        for (&f, &s) in part.faces.iter().zip(&sides) {
            drop[f] = s == FaceSide::Fold;
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

    /// Faces up are along the data, faces down folds over it.
    fn by_z(_: DVec3, n: DVec3) -> FaceSide {
        if n.z > 0.0 {
            FaceSide::Front
        } else {
            FaceSide::Fold
        }
    }

    #[test]
    fn a_flat_closed_part_is_opened_to_its_front_side() {
        let mut m = grid_and_pillow(0.01);
        let t = topology(&m);
        assert_eq!((t.boundary_loops, t.components), (1, 2), "the test case");
        let mut sources = vec![FaceSource::ThreeVotes; m.triangles.len()];
        let r = open_pillows(&mut m, &mut sources, true, by_z);
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
    fn an_open_part_loses_its_folds() {
        // The pillow with two faces of its bottom gone: open, folded over itself.
        let mut m = grid_and_pillow(0.5);
        m.triangles.remove(32);
        m.triangles.remove(32);
        assert_eq!(topology(&m).boundary_loops, 1 + 1, "the test case");
        let mut sources = vec![FaceSource::ThreeVotes; m.triangles.len()];
        let r = open_pillows(&mut m, &mut sources, true, by_z);
        assert_eq!((r.opened, r.faces), (1, 6));
        assert_eq!(m.triangles.len(), 32 + 16);
        assert!((32..m.triangles.len()).all(|f| m.face_normal(f).z > 0.0));
        assert!(topology(&m).is_manifold());
    }

    /// An 8 × 8 grid of squares in the plane z = 0, facing up, with its vertex (`i`, `j`) moved
    /// 1.5 along x, past its neighbour: faces around it turn over (a fold).
    fn grid_folded_at(i: u32, j: u32) -> TriMesh {
        let g = |i: u32, j: u32| j * 9 + i;
        let mut positions = Vec::new();
        for j in 0..9 {
            for i in 0..9 {
                positions.push(DVec3::new(i as f64, j as f64, 0.0));
            }
        }
        positions[g(i, j) as usize] += DVec3::new(1.5, 0.2, 0.0);
        let mut triangles = Vec::new();
        for j in 0..8 {
            for i in 0..8 {
                triangles.push([g(i, j), g(i + 1, j), g(i + 1, j + 1)]);
                triangles.push([g(i, j), g(i + 1, j + 1), g(i, j + 1)]);
            }
        }
        TriMesh::new(positions, triangles)
    }

    #[test]
    fn the_largest_part_loses_its_folds_at_the_boundary_only() {
        let mut sources = Vec::new();
        let folds = |m: &TriMesh| {
            (0..m.triangles.len())
                .filter(|&f| m.face_normal(f).z < 0.0)
                .count()
        };
        // One edge from the boundary: a flap folded back over the surface at the data's edge.
        let mut m = grid_folded_at(1, 4);
        let n = folds(&m);
        assert!(n > 0, "the test case");
        // Not where the data has no edges.
        assert_eq!(open_pillows(&mut m, &mut sources, false, by_z).opened, 0);
        let r = open_pillows(&mut m, &mut sources, true, by_z);
        assert_eq!((r.opened, r.faces), (1, n));
        assert_eq!(folds(&m), 0);
        assert!(topology(&m).is_manifold());
        // In the middle, a fold is taken for a thin part whose data's normals are wrong.
        let mut m = grid_folded_at(4, 4);
        assert!(folds(&m) > 0, "the test case");
        assert_eq!(open_pillows(&mut m, &mut sources, true, by_z).opened, 0);
    }

    #[test]
    fn backed_closed_parts_the_largest_closed_part_and_one_sided_parts_stay() {
        let mut sources = Vec::new();
        // One face against the data has data on its side: a thin part, not a pillow.
        let mut m = grid_and_pillow(0.01);
        let backed = |c: DVec3, n: DVec3| match by_z(c, n) {
            FaceSide::Fold if c.x < 21.0 => FaceSide::Backed,
            side => side,
        };
        assert_eq!(open_pillows(&mut m, &mut sources, true, backed).opened, 0);
        // The same pillow alone is the largest part.
        let mut alone = grid_and_pillow(0.01);
        alone.triangles.drain(..32);
        assert_eq!(open_pillows(&mut alone, &mut sources, true, by_z).opened, 0);
        // No face is a fold, or every face is: nothing to open.
        let mut m = grid_and_pillow(0.01);
        assert_eq!(
            open_pillows(&mut m, &mut sources, true, |_, _| FaceSide::Front).opened,
            0
        );
        assert_eq!(
            open_pillows(&mut m, &mut sources, true, |_, _| FaceSide::Fold).opened,
            0
        );
        assert_eq!(m.triangles.len(), 32 + 24);
    }
}
