//! The two ways to the restricted Delaunay triangulation through the whole job: cells grown over
//! the input refined (the default) and cells clipped exactly from its facets
//! (`--triangulation restricted-clipped`). On surfaces without thin parts both give a closed
//! output of the input's topology with no crossing or fold.

mod common;

use common::{grid_box, icosphere};

use glam::DVec3;
use spectral_remesh::internal::{
    self_intersections, FeatureDetection, RestrictedDelaunayParams, TriangulationMethod,
};
use spectral_remesh::{remesh, topology, Density, RemeshOutput, RemeshParams, TriMesh};

fn run(mesh: &TriMesh, clipped: bool, features: FeatureDetection, seed: u64) -> RemeshOutput {
    let params = RemeshParams {
        density: Density::Points(2000),
        seed,
        features,
        triangulation: TriangulationMethod::RestrictedDelaunay(RestrictedDelaunayParams {
            clipped,
            ..Default::default()
        }),
        ..RemeshParams::default()
    };
    remesh(mesh, &params, &|_| {}).expect("remesh")
}

/// A sphere (no creases) and a box (its edges kept as creases), seeds 1 to 3, both ways: one
/// closed piece of genus 0, manifold, no crossing or fold, every sample kept within 2% of the
/// count; and the triangles came from the cells asked for (not the umbrellas' fallback).
#[test]
fn refined_and_clipped_cells_close_a_sphere_and_a_box() {
    let sphere = {
        let mut m = icosphere(4);
        for p in &mut m.positions {
            *p *= 50.0;
        }
        m
    };
    let cube = grid_box(DVec3::ZERO, DVec3::splat(100.0), 6);
    for (name, mesh, features) in [
        ("sphere", &sphere, FeatureDetection::Off),
        ("box", &cube, FeatureDetection::Auto),
    ] {
        for clipped in [false, true] {
            for seed in 1..=3 {
                let at = format!("{name}, clipped {clipped}, seed {seed}");
                let run = run(mesh, clipped, features, seed);
                let rd = run.restricted_delaunay.as_ref().expect("restricted cells");
                assert_eq!(
                    (rd.refined_vertices > 0, rd.clipped_facets > 0),
                    (!clipped, clipped),
                    "{at}"
                );
                let out = run.mesh;
                let t = topology(&out);
                assert_eq!(
                    (
                        t.components,
                        t.euler_characteristic,
                        t.boundary_edges,
                        t.non_manifold_edges + t.non_manifold_vertices
                    ),
                    (1, 2, 0, 0),
                    "{at}"
                );
                assert_eq!(self_intersections(&out).pairs, 0, "{at}");
                let v = out.vertex_count() as f64;
                assert!((v - 2000.0).abs() <= 40.0, "{at}: {v} vertices");
            }
        }
    }
}
