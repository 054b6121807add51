//! Inputs the fuzz targets (fuzz/) found failing, kept as tests named after the bug. The reader
//! findings live beside the other reader tests (tests/io.rs, `fuzz_regression_*`).

use glam::DVec3;
use spectral_remesh::quality::topology;
use spectral_remesh::triangulate::{triangulate, SampleSet, TriangulateParams};
use spectral_remesh::TriMesh;

/// The point sets of the `triangulate` fuzz target (fuzz/fuzz_targets/triangulate.rs), from its
/// input bytes: a sphere or a torus, a count, position and normal noise, the placements.
fn fuzz_points(data: &[u8]) -> (Vec<DVec3>, Vec<DVec3>) {
    let mut at = 0;
    let mut unit = || {
        let mut v = 0u32;
        for _ in 0..2 {
            let b = data.get(at).copied().unwrap_or(0x5a);
            at += 1;
            v = v << 8 | b as u32;
        }
        v as f64 / 65536.0
    };
    let torus = unit() < 0.5;
    let n = 20 + (unit() * 1500.0) as usize;
    let noise = unit().powi(2) * 3.0;
    let normal_noise = unit().powi(2);
    let (big, small) = (30.0, 5.0 + 20.0 * unit());
    let mut positions = Vec::with_capacity(n);
    let mut normals = Vec::with_capacity(n);
    for _ in 0..n {
        let (u, v) = (unit() * std::f64::consts::TAU, unit());
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
        let jitter = DVec3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5);
        positions.push(p + jitter * noise);
        normals.push((nrm + jitter * normal_noise).normalize_or(DVec3::Z));
    }
    (positions, normals)
}

/// The triangulation's guarantees, as the fuzz target asserts them.
fn assert_triangulation_is_clean(positions: Vec<DVec3>, normals: &[DVec3]) {
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
}

/// Found by the triangulate fuzz target: hundreds of samples at the same few positions (the
/// input bytes ran out, so every later point repeated one placement) gave a face with zero area.
#[test]
fn fuzz_regression_coincident_samples_gave_a_degenerate_face() {
    let data = include_bytes!("fuzz/triangulate-coincident-samples.bin");
    let (p, n) = fuzz_points(data);
    assert_triangulation_is_clean(p, &n);
}

/// Found by the triangulate fuzz target: samples on a line (the bytes placed several points at the
/// same (u, v) with noise along one axis) left a hole of three collinear samples, which the
/// clean-up closed with a flat triangle.
#[test]
fn fuzz_regression_collinear_hole_was_closed_by_a_flat_triangle() {
    let data = include_bytes!("fuzz/triangulate-collinear-hole.bin");
    let (p, n) = fuzz_points(data);
    assert_triangulation_is_clean(p, &n);
}
