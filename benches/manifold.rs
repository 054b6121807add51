//! Benchmarks of the sampler on point sets in R^d (`src/manifold/`), on `criterion`:
//! - `manifold/scan R^3, kernel space` and `manifold/scan R^3, surface scanner` — the linear
//!   scan (Sec. 6.1) of the same 100,000 points of a sphere of radius 20 at sigma_p 1 (about
//!   3600 samples), once by `sample_manifold` (one kd-tree over the kernel-space points, one
//!   candidate at a time) and once by the surface sampler's `LinearScanner` (a kd-tree over
//!   positions, chunks of candidates tested in parallel): what the R^d path costs against
//!   the 3D one on the 3D one's own ground (they make the same decisions, a unit test checks);
//! - `manifold/circle 100k -> 200` — the count search on 100,000 points of a circle in R^2;
//! - `manifold/resample Clifford torus 1000` — 10 sweeps of gradient ascent on 1000 samples of
//!   100,000 points of the Clifford torus in R^4, projected onto the points.
//!
//! `cargo bench --bench manifold`. Wall-clock time on a shared machine is noisy: compare runs
//! on the same machine. Measured on the project's 2-core machine (2026-11-24, release build,
//! criterion's estimates, with another build running beside it): scan in kernel space 67 ms,
//! surface scanner 60 ms (on 2 threads; the kernel-space scan is one thread); circle
//! 100k -> 200 78 ms (three scans); resample of the torus 257 ms.

use std::f64::consts::TAU;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use glam::DVec3;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use spectral_remesh::internal::{Kernel, LinearScanParams, LinearScanner};
use spectral_remesh::{
    resample_manifold, sample_manifold, DataProjection, ManifoldResampleParams,
    ManifoldSampleParams, PointSet,
};

fn sphere(n: usize) -> Vec<DVec3> {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    (0..n)
        .map(|_| {
            let v = DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            20.0 * v.normalize_or(DVec3::Z)
        })
        .collect()
}

fn scan_in_r3(c: &mut Criterion) {
    let pts = sphere(100_000);
    let flat: Vec<f64> = pts.iter().flat_map(|p| p.to_array()).collect();
    let set = PointSet::new(3, flat, None).expect("points");
    let params = ManifoldSampleParams {
        sigma_p: Some(1.0),
        ..Default::default()
    };
    let mut group = c.benchmark_group("manifold");
    group.sample_size(20);
    group.bench_function("scan R^3, kernel space", |b| {
        b.iter(|| sample_manifold(&set, &params).expect("scan"))
    });
    let kernel = Kernel::new(1.0, f64::INFINITY).expect("kernel");
    let batch: Vec<(DVec3, DVec3)> = pts.iter().map(|&p| (p, p / 20.0)).collect();
    group.bench_function("scan R^3, surface scanner", |b| {
        b.iter(|| {
            let mut scanner = LinearScanner::new(&kernel, &LinearScanParams::default());
            let mut accepted = Vec::new();
            scanner.offer_batch(&batch, &mut accepted);
            accepted
        })
    });
    group.finish();
}

fn circle_and_torus(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let xy: Vec<f64> = (0..100_000)
        .flat_map(|_| {
            let t: f64 = rng.random_range(0.0..TAU);
            [t.cos(), t.sin()]
        })
        .collect();
    let circle = PointSet::new(2, xy, None).expect("points");
    let mut group = c.benchmark_group("manifold");
    group.sample_size(20);
    let count = ManifoldSampleParams {
        count: Some(200),
        ..Default::default()
    };
    group.bench_function("circle 100k -> 200", |b| {
        b.iter(|| sample_manifold(&circle, &count).expect("sample"))
    });
    let r = 0.5f64.sqrt();
    let x: Vec<f64> = (0..100_000)
        .flat_map(|_| {
            let (a, b): (f64, f64) = (rng.random_range(0.0..TAU), rng.random_range(0.0..TAU));
            [r * a.cos(), r * a.sin(), r * b.cos(), r * b.sin()]
        })
        .collect();
    let torus = PointSet::new(4, x, None).expect("points");
    let picked = sample_manifold(
        &torus,
        &ManifoldSampleParams {
            count: Some(1000),
            ..Default::default()
        },
    )
    .expect("sample");
    let start = torus.subset(&picked.indices);
    let projection = DataProjection::new(&torus, picked.dimension, 1).expect("projection");
    let params = ManifoldResampleParams::new(picked.sigma_p);
    group.measurement_time(Duration::from_secs(8));
    group.bench_function("resample Clifford torus 1000", |b| {
        b.iter(|| resample_manifold(&start, &projection, &params).expect("resample"))
    });
    group.finish();
}

criterion_group!(benches, scan_in_r3, circle_and_torus);
criterion_main!(benches);
