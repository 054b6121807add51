//! Benchmarks of the quality report on an 81,920-face icosphere (level 6), on `criterion`:
//! the triangle measures with the topology and the invariant check (self-intersections
//! included); the two BVH builds of a distance measurement; and the two-sided surface
//! distance (100,000 random samples plus the vertices per side) against a rotated, scaled copy.
//!
//! `cargo bench --bench quality`. (This was the ignored "timing" test of `tests/quality.rs`.)

use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use glam::{DQuat, DVec3};
use spectral_remesh::internal::{surface_distance_with, triangle_quality, MeshSurface};
use spectral_remesh::{check_invariants, topology, TriMesh};

#[path = "../tests/common/mod.rs"]
mod common;

fn quality(c: &mut Criterion) {
    let a = common::icosphere(6);
    let rot = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.3);
    let b = TriMesh::new(
        a.positions.iter().map(|p| 1.01 * (rot * *p)).collect(),
        a.triangles.clone(),
    );
    c.bench_function(
        "icosphere 6/triangle measures, topology, invariants",
        |bench| {
            bench.iter(|| {
                let q = triangle_quality(&a);
                let t = topology(&a);
                let inv = check_invariants(&a);
                assert!(inv.is_empty() && t.genus == Some(0) && q.q_min > 0.5);
            })
        },
    );
    c.bench_function("icosphere 6/two BVH builds", |bench| {
        bench.iter(|| {
            (
                MeshSurface::new(&a).expect("a surface"),
                MeshSurface::new(&b).expect("a surface"),
            )
        })
    });
    let (sa, sb) = (
        MeshSurface::new(&a).expect("a surface"),
        MeshSurface::new(&b).expect("a surface"),
    );
    c.bench_function(
        "icosphere 6/surface distance, 100k samples per side",
        |bench| bench.iter(|| surface_distance_with(&a, &sa, &b, &sb, 100_000, 1)),
    );
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(5));
    targets = quality
}
criterion_main!(benches);
