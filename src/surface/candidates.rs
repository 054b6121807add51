//! The candidate pool of the linear scan: a dense, uniform random sampling of the input surface.
//!
//! A mesh's own vertices are a poor pool: too sparse where the mesh is coarse (the scan can only
//! choose among them) and uneven where it is not. The pool is instead drawn uniformly by area,
//! stratified per triangle (each triangle gets ⌊A_f ρ⌋ points plus one more with probability
//! equal to the fraction), at a density set relative to the expected output count; the visit
//! order is a seeded random permutation (Algorithm 1 takes points in random order).

use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::area_sampler::{point_in_triangle, random_barycentric};
use crate::mesh::TriMesh;
use crate::surface::SurfaceSample;

/// Draws about `count` points uniformly by area on `mesh` (bbox-100 units), each with its face's
/// unit normal, in a random visit order; deterministic for a given `seed`. Degenerate (zero-area)
/// triangles get none.
pub fn surface_candidates(mesh: &TriMesh, count: usize, seed: u64) -> Vec<SurfaceSample> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let area = mesh.area();
    let mut out = Vec::with_capacity(count + count / 16 + 16);
    if !(area > 0.0) || count == 0 {
        return out;
    }
    let density = count as f64 / area;
    draw_per_face(mesh, &mut rng, |_| density, &mut out);
    out.shuffle(&mut rng);
    out
}

/// Stratified area-uniform points on each face `f` of `mesh` at `per_area(f)` points per unit
/// area (none where it is not positive): ⌊A_f ρ⌋ points plus one more with probability equal to
/// the fraction, each with its face's unit normal, appended to `out` in face order.
fn draw_per_face(
    mesh: &TriMesh,
    rng: &mut ChaCha8Rng,
    per_area: impl Fn(usize) -> f64,
    out: &mut Vec<SurfaceSample>,
) {
    for f in 0..mesh.face_count() {
        let rho = per_area(f);
        if !(rho > 0.0) {
            continue;
        }
        let cross = mesh.face_cross(f);
        let a = 0.5 * cross.length();
        if !(a > 0.0) {
            continue;
        }
        let normal = cross / (2.0 * a);
        let expected = a * rho;
        let mut m = expected.floor() as usize;
        if rng.random::<f64>() < expected - m as f64 {
            m += 1;
        }
        let corners = mesh.corners(f);
        for _ in 0..m {
            let (u, v) = random_barycentric(rng);
            out.push(SurfaceSample {
                position: point_in_triangle(corners, u, v),
                normal,
                face: f as u32,
            });
        }
    }
}

/// The candidates a graded sizing field needs besides an area-uniform pool of `density` points
/// per unit area (bbox-100 units): on each face `f` of `mesh`, area-uniform points at
/// `density · (1 / w_f² − 1)` per unit area, `w_f = width(f)` in (0, 1] the face's smallest
/// relative width (a spacing w times finer takes 1 / w² times the samples, so the pool and the
/// supplement keep as many candidates per expected sample everywhere). Faces of width 1 get
/// none; in face order (the caller shuffles); deterministic for a given `seed`.
pub fn graded_candidates(
    mesh: &TriMesh,
    density: f64,
    width: impl Fn(usize) -> f64,
    seed: u64,
) -> Vec<SurfaceSample> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::new();
    if !(density > 0.0) {
        return out;
    }
    let per_area = |f: usize| {
        let w = width(f);
        if w < 1.0 && w > 0.0 {
            density * (1.0 / (w * w) - 1.0)
        } else {
            0.0
        }
    };
    draw_per_face(mesh, &mut rng, per_area, &mut out);
    out
}

/// Shuffles `pool` with `seed` (the linear scan visits candidates in this order).
pub fn shuffle_candidates(pool: &mut [SurfaceSample], seed: u64) {
    pool.shuffle(&mut ChaCha8Rng::seed_from_u64(seed));
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn candidates_are_on_the_surface_uniform_by_area_and_seeded() {
        // Two triangles, areas 1 and 3.
        let mesh = TriMesh::new(
            vec![
                DVec3::ZERO,
                DVec3::new(2.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(0.0, 0.0, 5.0),
                DVec3::new(2.0, 0.0, 5.0),
                DVec3::new(0.0, 3.0, 5.0),
            ],
            vec![[0, 1, 2], [3, 4, 5]],
        );
        let c = surface_candidates(&mesh, 40_000, 1);
        assert!((c.len() as f64 - 40_000.0).abs() < 200.0, "{}", c.len());
        let on_second = c.iter().filter(|s| s.face == 1).count() as f64 / c.len() as f64;
        assert!((on_second - 0.75).abs() < 0.01, "{on_second}");
        for s in &c {
            let z = if s.face == 0 { 0.0 } else { 5.0 };
            assert!((s.position.z - z).abs() < 1e-12);
            assert!(s.position.x >= -1e-12 && s.position.y >= -1e-12);
            assert_eq!(s.normal, DVec3::Z);
        }
        assert_eq!(c, surface_candidates(&mesh, 40_000, 1));
        assert_ne!(c, surface_candidates(&mesh, 40_000, 2));
    }
}
