//! Closest-point queries on the horse split once at its edge midpoints (193,934 vertices,
//! 387,864 faces; issue 38: they were a quarter of a remesh's processor time through parry's
//! BVH), on `criterion`, 100,000 queries per sample:
//! - `closest point/parry` — parry's `TriMesh::project_local_point_and_get_location`, the
//!   structure `MeshSurface` used before;
//! - `closest point/tree` — `MeshSurface::closest_point`, the BVH built for this query;
//! - `closest point/tree, warm` — `MeshSurface::closest_point_from`, started from the face of
//!   the answer to the query before it moved (as the gradient ascent, the relaxation and the
//!   fit ask).
//!
//! The queries are the pipeline's kind: a point of the surface moved by a tenth of the mean
//! edge length in a random direction. `cargo bench --bench closest_point`.

use std::path::PathBuf;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use glam::DVec3;
use parry3d_f64::query::PointQueryWithLocation;
use rand::{RngExt, SeedableRng};
use spectral_remesh::internal::MeshSurface;
use spectral_remesh::{read_mesh, TriMesh};

/// The horse split once at its edge midpoints: each triangle into four.
fn subdivided_horse() -> TriMesh {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data/horse.obj");
    assert!(
        path.exists(),
        "{} is missing: the benchmark needs the shared test models",
        path.display()
    );
    let (mesh, _) = read_mesh(&path).expect("the horse reads");
    let mut positions = mesh.positions.clone();
    let mut midpoint = std::collections::HashMap::new();
    let mut mid = |a: u32, b: u32, positions: &mut Vec<DVec3>| {
        *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
            positions.push(0.5 * (positions[a as usize] + positions[b as usize]));
            positions.len() as u32 - 1
        })
    };
    let mut triangles = Vec::with_capacity(4 * mesh.triangles.len());
    for &[a, b, c] in &mesh.triangles {
        let (ab, bc, ca) = (
            mid(a, b, &mut positions),
            mid(b, c, &mut positions),
            mid(c, a, &mut positions),
        );
        triangles.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    TriMesh::new(positions, triangles)
}

fn closest_point(c: &mut Criterion) {
    let mesh = subdivided_horse();
    let surface = MeshSurface::new(&mesh).expect("the horse has area");
    let parry = parry3d_f64::shape::TriMesh::new(mesh.positions.clone(), mesh.triangles.clone())
        .expect("the horse has area");
    let step = 0.1 * mean_edge(&mesh);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    // (query, the face of the point it moved from)
    let queries: Vec<(DVec3, u32)> = (0..100_000)
        .map(|_| {
            let f = rng.random_range(0..mesh.triangles.len());
            let [a, b, c] = mesh.corners(f);
            let (u, v) = (rng.random_range(0.0..0.5), rng.random_range(0.0..0.5));
            let on = a + u * (b - a) + v * (c - a);
            let dir = DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            (on + step * dir.normalize_or_zero(), f as u32)
        })
        .collect();
    let mut g = c.benchmark_group("closest point");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    g.bench_function("parry", |b| {
        b.iter(|| {
            queries
                .iter()
                .map(|&(p, _)| {
                    parry
                        .project_local_point_and_get_location(p, false)
                        .0
                        .point
                        .x
                })
                .sum::<f64>()
        })
    });
    g.bench_function("tree", |b| {
        b.iter(|| {
            queries
                .iter()
                .map(|&(p, _)| surface.closest_point(p).map_or(0.0, |s| s.distance))
                .sum::<f64>()
        })
    });
    g.bench_function("tree, warm", |b| {
        b.iter(|| {
            queries
                .iter()
                .map(|&(p, f)| {
                    surface
                        .closest_point_from(p, f, f64::MAX)
                        .map_or(0.0, |s| s.distance)
                })
                .sum::<f64>()
        })
    });
    g.finish();
}

fn mean_edge(mesh: &TriMesh) -> f64 {
    let sum: f64 = (0..mesh.triangles.len())
        .map(|f| {
            let [a, b, c] = mesh.corners(f);
            a.distance(b) + b.distance(c) + c.distance(a)
        })
        .sum();
    sum / (3 * mesh.triangles.len()) as f64
}

criterion_group!(benches, closest_point);
criterion_main!(benches);
