//! The point sets of the `triangulate` target, shared with the regression tests
//! (tests/fuzz_regressions.rs) so that a finding replays exactly: a sphere or a torus, a count,
//! position and normal noise and the placements, all read from the input bytes, and the
//! triangulation's guarantees.

use glam::DVec3;
use spectral_remesh::mesh::edit::{EditMesh, SlotPolicy};
use spectral_remesh::quality::topology;
use spectral_remesh::triangulate::{triangulate, SampleSet, TriangulateParams};
use spectral_remesh::TriMesh;

/// Numbers in [0, 1) from the bytes, two bytes each (0x5a once they run out).
struct Bytes<'a>(&'a [u8], usize);

impl Bytes<'_> {
    fn unit(&mut self) -> f64 {
        let mut v = 0u32;
        for _ in 0..2 {
            let b = self.0.get(self.1).copied().unwrap_or(0x5a);
            self.1 += 1;
            v = v << 8 | b as u32;
        }
        v as f64 / 65536.0
    }
}

/// Positions and unit normals of 20 to 1520 noisy points on a sphere of radius 30 or a torus
/// (radii 30 and 5 to 25), shaped by `data`.
pub fn noisy_points(data: &[u8]) -> (Vec<DVec3>, Vec<DVec3>) {
    let mut b = Bytes(data, 0);
    let torus = b.unit() < 0.5;
    let n = 20 + (b.unit() * 1500.0) as usize;
    let noise = b.unit().powi(2) * 3.0;
    let normal_noise = b.unit().powi(2);
    let (big, small) = (30.0, 5.0 + 20.0 * b.unit());
    let mut positions = Vec::with_capacity(n);
    let mut normals = Vec::with_capacity(n);
    for _ in 0..n {
        let (u, v) = (b.unit() * std::f64::consts::TAU, b.unit());
        let (p, nrm) = if torus {
            let w = v * std::f64::consts::TAU;
            let nrm = DVec3::new(w.cos() * u.cos(), w.cos() * u.sin(), w.sin());
            let c = DVec3::new(u.cos(), u.sin(), 0.0) * big;
            (c + nrm * small, nrm)
        } else {
            let z = 2.0 * v - 1.0;
            let s = (1.0 - z * z).max(0.0).sqrt();
            let nrm = DVec3::new(s * u.cos(), s * u.sin(), z);
            (nrm * big, nrm)
        };
        let jitter = DVec3::new(b.unit() - 0.5, b.unit() - 0.5, b.unit() - 0.5);
        positions.push(p + jitter * noise);
        normals.push((nrm + jitter * normal_noise).normalize_or(DVec3::Z));
    }
    (positions, normals)
}

/// Triangulates the points and asserts the assembly's guarantees: indices in range, every edge
/// in at most two faces, every vertex one fan, consistent orientation, no degenerate or
/// duplicate face.
pub fn assert_triangulation_is_clean(positions: Vec<DVec3>, normals: &[DVec3]) {
    let set = SampleSet {
        positions: &positions,
        normals,
        boundary_edges: &[],
    };
    let (faces, _, _) = triangulate(&set, &TriangulateParams::default());
    let mesh = TriMesh::new(positions.clone(), faces);
    assert!(mesh.check_indices().is_none());
    let t = topology(&mesh);
    assert_eq!(t.non_manifold_edges, 0, "{t:?}");
    assert_eq!(t.non_manifold_vertices, 0, "{t:?}");
    assert_eq!(t.inconsistent_orientation_edges, 0, "{t:?}");
    assert_eq!(t.degenerate_faces, 0, "{t:?}");
    assert_eq!(t.duplicate_faces, 0, "{t:?}");
    // The edit mesh's invariants (the same, plus its own tables).
    let edit: EditMesh = EditMesh::from_trimesh(&mesh, |_| (), SlotPolicy::Reuse);
    assert_eq!(edit.sanity_check(), Ok(()));
}
