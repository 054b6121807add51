//! Benchmarks of the remesh pipeline on the horse (`../shared/data/horse.obj`, 48,485
//! vertices) at 8600 output points, on `criterion`:
//! - `horse/remesh 8600` — the whole job as `remesh` runs it: read, remesh, write (no distance
//!   measurement); about a second per run, so 10 samples; one run's split per stage is
//!   printed first;
//! - `horse/linear scan` — the randomized linear scan (Sec. 6.1) of 86,000 surface candidates
//!   at the sigma_p that leaves about 8600 samples;
//! - `horse/triangulate` — the triangulation of those samples (tangent-plane Delaunay
//!   umbrellas merged by votes, then the manifold clean-up).
//!
//! `cargo bench --bench horse` (a filter picks some: `cargo bench --bench horse -- scan`).
//! Wall-clock time on a shared machine is noisy: compare runs on the same machine.

use std::path::PathBuf;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use spectral_remesh::internal::{
    linear_scan, surface_candidates, triangulate, validate_input, Kernel, LinearScanParams,
    SampleSet, TriangulateParams, Uniform, SAMPLES_PER_SIGMA2,
};
use spectral_remesh::{read_mesh, run_remesh, Density, RemeshJob, RemeshParams};

/// Output vertices, as the harness remeshes the horse.
const POINTS: usize = 8600;

fn horse() -> PathBuf {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data/horse.obj");
    assert!(
        path.exists(),
        "{} is missing: the benchmarks need the shared test models",
        path.display()
    );
    path
}

fn remesh_job(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let job = RemeshJob {
        input: horse(),
        output: dir.path().join("out.obj"),
        format: None,
        params: RemeshParams {
            density: Density::Points(POINTS),
            ..Default::default()
        },
        strict: false,
        measure_distance: false,
        max_memory: None,
        as_points: false,
        viewpoint: None,
        report: None,
    };
    // The split per stage of one run, which criterion's total does not show.
    let report = run_remesh(&job, &|_| {}).expect("remesh");
    println!("horse/remesh 8600, one run by stage:");
    for s in &report.stages {
        println!("  {:<18} {:>7.3} s", s.stage, s.seconds);
    }
    c.bench_function("horse/remesh 8600", |b| {
        b.iter(|| run_remesh(&job, &|_| {}).expect("remesh"))
    });
}

fn stages(c: &mut Criterion) {
    let (mesh, _) = read_mesh(&horse()).expect("read the horse");
    let normalized = validate_input(&mesh)
        .expect("a valid input")
        .apply_mesh(&mesh);
    let candidates = surface_candidates(&normalized, 10 * POINTS, 1);
    let sigma_p = (SAMPLES_PER_SIGMA2 * normalized.area() / POINTS as f64).sqrt();
    let kernel = Kernel::new(sigma_p, f64::INFINITY).expect("a valid kernel");
    let params = LinearScanParams::default();
    c.bench_function("horse/linear scan", |b| {
        b.iter(|| linear_scan(&kernel, &candidates, None, &[], &Uniform, &params))
    });

    let samples = linear_scan(&kernel, &candidates, None, &[], &Uniform, &params).samples;
    let positions: Vec<_> = samples.iter().map(|s| s.position).collect();
    let normals: Vec<_> = samples.iter().map(|s| s.normal).collect();
    let set = SampleSet {
        positions: &positions,
        normals: &normals,
        boundary_edges: &[],
    };
    let params = TriangulateParams::default();
    c.bench_function("horse/triangulate", |b| {
        b.iter(|| triangulate(&set, &params))
    });
}

fn config() -> Criterion {
    Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(12))
}

criterion_group! {
    name = benches;
    config = config();
    targets = remesh_job, stages
}
criterion_main!(benches);
