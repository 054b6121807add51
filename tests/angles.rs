//! Issue 15: θmin ≥ 25° and no crossing faces at every seed. Before the optimization's last pass
//! (and the fix of `EditMesh::is_boundary_vertex`), stanford-bunny at its harness count 9635
//! kept a 23.2° sliver at seeds 1 and 4 on its smallest hole: two boundary samples 0.4 spacings
//! apart and the interior vertex across them a whole spacing away, never moved because a vertex
//! whose faces touch the boundary counted as on it.

mod common;

use spectral_remesh::internal::intersecting_pairs;
use spectral_remesh::internal::triangle_quality;
use spectral_remesh::{read_mesh, remesh, Density, RemeshParams};

#[test]
#[ignore = "needs ../shared: .ci/run runs it"]
fn shared_bunny_at_its_harness_count_has_no_angle_below_25_and_no_crossing_at_seeds_1_to_5() {
    let (input, _) = read_mesh(&common::model("stanford-bunny.obj")).unwrap();
    for seed in 1..=5 {
        let params = RemeshParams {
            density: Density::Points(9635),
            seed,
            ..RemeshParams::default()
        };
        let out = remesh(&input, &params, &|_| {}).unwrap();
        let mesh = &out.mesh_normalized;
        let q = triangle_quality(mesh);
        assert!(
            q.theta_min >= 25.0 && q.pct_theta_below_30 <= 0.1,
            "seed {seed}: θmin {:.1}, %θ<30 {:.3}",
            q.theta_min,
            q.pct_theta_below_30
        );
        let pairs = intersecting_pairs(&mesh.positions, &mesh.triangles);
        assert!(pairs.is_empty(), "seed {seed}: crossing pairs {pairs:?}");
    }
}
