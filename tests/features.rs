//! Issue 16: sharp features. With `--feature-angle`, the creases of a part are sampled evenly
//! and come out as output edges, so the part's edges are kept instead of chamfered.

mod common;

use common::grid_box_counts;
use glam::DVec3;
use spectral_remesh::{remesh, Density, RemeshParams, TriMesh, CAD_FEATURE_ANGLE_DEG};

/// The largest distance from points along the box's 12 edges (20 per edge) to the nearest
/// edge of `mesh`.
fn box_edges_to_mesh_edges(lo: DVec3, hi: DVec3, mesh: &TriMesh) -> f64 {
    let corner = |k: usize| {
        DVec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        )
    };
    let mut segments = Vec::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a < b {
                segments.push((mesh.positions[a as usize], mesh.positions[b as usize]));
            }
        }
    }
    let mut worst: f64 = 0.0;
    for a in 0..8usize {
        for axis in [1usize, 2, 4] {
            if a & axis != 0 {
                continue;
            }
            let (p, q) = (corner(a), corner(a | axis));
            for i in 0..=20 {
                let x = p.lerp(q, i as f64 / 20.0);
                let d = segments
                    .iter()
                    .map(|&(s, e)| {
                        let se = e - s;
                        let t = ((x - s).dot(se) / se.length_squared()).clamp(0.0, 1.0);
                        x.distance(s + se * t)
                    })
                    .fold(f64::INFINITY, f64::min);
                worst = worst.max(d);
            }
        }
    }
    worst
}

#[test]
fn a_boxs_edges_are_output_edges_at_every_seed_with_the_feature_angle() {
    let (lo, hi) = (DVec3::ZERO, DVec3::new(100.0, 60.0, 40.0));
    let input = grid_box_counts(lo, hi, [20, 12, 8]);
    for seed in 1..=5 {
        let params = RemeshParams {
            density: Density::Points(2000),
            feature_angle_deg: CAD_FEATURE_ANGLE_DEG,
            seed,
            ..Default::default()
        };
        let out = remesh(&input, &params, &|_| {}).expect("remesh");
        let f = &out.features;
        assert_eq!((f.curves, f.corners), (12, 8), "seed {seed}: {f:?}");
        assert!(
            f.sampled_edges > 0 && f.kept_edges == f.sampled_edges,
            "seed {seed}: {f:?}"
        );
        let v = out.mesh.positions.len() as f64;
        assert!((v - 2000.0).abs() <= 20.0, "seed {seed}: {v} vertices");
        let d = box_edges_to_mesh_edges(lo, hi, &out.mesh);
        assert!(
            d < 1e-9,
            "seed {seed}: a box edge is {d} from the output's edges"
        );
    }
    // Without the features the edges are cut across (the check above means something).
    let out = remesh(
        &input,
        &RemeshParams {
            density: Density::Points(2000),
            ..Default::default()
        },
        &|_| {},
    )
    .expect("remesh");
    assert_eq!(out.features.curves, 0);
    assert!(box_edges_to_mesh_edges(lo, hi, &out.mesh) > 0.1);
}
