//! A sliver triangle (base 1, height 1e-7) remeshed at 100,000 points: every sample is a
//! boundary sample. Before issue 36 every sample's umbrella walked the whole boundary chain
//! (80 s; 7 s after). Timed here, not in a test (tests/degenerate_input.rs runs it for its
//! result only, whatever the machine's load). `cargo bench --bench degenerate`.

use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use glam::DVec3;
use spectral_remesh::{remesh, Density, RemeshParams, TriMesh};

fn sliver_at_100k(c: &mut Criterion) {
    let sliver = TriMesh::new(
        vec![DVec3::ZERO, DVec3::X, DVec3::new(0.5, 1e-7, 0.0)],
        vec![[0, 1, 2]],
    );
    let params = RemeshParams {
        density: Density::Points(100_000),
        ..RemeshParams::default()
    };
    let mut group = c.benchmark_group("degenerate");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(60));
    group.bench_function("sliver, 100k points", |b| {
        b.iter(|| remesh(&sliver, &params, &|_| {}).expect("the sliver remeshes"))
    });
    group.finish();
}

criterion_group!(benches, sliver_at_100k);
criterion_main!(benches);
