//! Area-uniform random points on a triangle mesh: a face chosen with probability proportional to
//! its area (inverse transform of the running sums of the face areas), then a point uniform in
//! it (barycentric `(u, v)` uniform on the unit square, reflected into the triangle when
//! `u + v > 1`).
//!
//! Every area-uniform draw of the crate goes through here: the dense point sets of
//! `points::generate` (`remesh points`, the reconstruction experiment's inputs) draw faces with
//! [`AreaSampler`]; the linear scan's candidate pool (`surface::candidates`) is stratified per
//! face instead and draws only the point in the face with [`random_barycentric`].
//!
//! # References
//! - G. Turk. *Generating Random Points in Triangles.* Graphics Gems (1990), 24–28: the
//!   reflection of the unit square onto the triangle.

use glam::DVec3;
use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use crate::mesh::TriMesh;

/// Barycentric coordinates `(u, v)` of a point uniform in a triangle: two `f64` draws from `rng`,
/// `u` first, reflected to `(1 - u, 1 - v)` when `u + v > 1`. The point is
/// [`point_in_triangle`]`(corners, u, v)`.
pub fn random_barycentric(rng: &mut ChaCha8Rng) -> (f64, f64) {
    let (mut u, mut v): (f64, f64) = (rng.random(), rng.random());
    if u + v > 1.0 {
        u = 1.0 - u;
        v = 1.0 - v;
    }
    (u, v)
}

/// `a + u (b - a) + v (c - a)` for corners `[a, b, c]` (any units).
pub fn point_in_triangle([a, b, c]: [DVec3; 3], u: f64, v: f64) -> DVec3 {
    a + u * (b - a) + v * (c - a)
}

/// A face drawn with probability proportional to its area, and a point uniform in it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AreaSample {
    /// The face drawn (index into the mesh's triangles; it has positive area).
    pub face: usize,
    /// Barycentric coordinate of the second corner.
    pub u: f64,
    /// Barycentric coordinate of the third corner (the first one's is `1 - u - v`).
    pub v: f64,
    /// The point, in the mesh's units: [`point_in_triangle`] of the face's corners.
    pub position: DVec3,
}

/// The running sums of a mesh's face areas, to draw faces by area.
///
/// Faces with an out-of-range vertex index or a non-finite area have no weight. Each draw takes
/// three `f64` from the caller's `rng` (face, then `u`, `v`): deterministic across platforms
/// for a seeded `ChaCha8Rng`.
#[derive(Debug, Clone)]
pub struct AreaSampler {
    /// Running sums of the face areas, one per face.
    cumulative: Vec<f64>,
    /// The last sum: the total area.
    total: f64,
    /// The last face with positive area (where a draw at the top of the range lands).
    last_with_area: usize,
}

impl AreaSampler {
    /// The sampler of `mesh`'s faces; `None` when no face has positive, finite area (or the
    /// total overflows).
    pub fn new(mesh: &TriMesh) -> Option<Self> {
        let n = mesh.positions.len();
        let mut cumulative = Vec::with_capacity(mesh.triangles.len());
        let mut total = 0.0;
        let mut last_with_area = None;
        for (f, t) in mesh.triangles.iter().enumerate() {
            let area = if t.iter().all(|&i| (i as usize) < n) {
                mesh.face_area(f)
            } else {
                0.0
            };
            let area = if area.is_finite() { area } else { 0.0 };
            if area > 0.0 {
                last_with_area = Some(f);
            }
            total += area;
            cumulative.push(total);
        }
        let last_with_area = last_with_area?;
        (total.is_finite() && total > 0.0).then_some(AreaSampler {
            cumulative,
            total,
            last_with_area,
        })
    }

    /// The total weighted area (the mesh's units squared).
    #[cfg(test)]
    pub fn total_area(&self) -> f64 {
        self.total
    }

    /// One area-uniform draw on `mesh` (the mesh this sampler was made from).
    ///
    /// # Panics
    /// When `mesh` has fewer faces than the one the sampler was made from.
    pub fn draw(&self, mesh: &TriMesh, rng: &mut ChaCha8Rng) -> AreaSample {
        let r = rng.random::<f64>() * self.total;
        // The first face whose running sum exceeds r: it has positive area.
        let face = self
            .cumulative
            .partition_point(|&c| c <= r)
            .min(self.last_with_area);
        let (u, v) = random_barycentric(rng);
        AreaSample {
            face,
            u,
            v,
            position: point_in_triangle(mesh.corners(face), u, v),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn draws_are_uniform_by_area_and_in_their_face() {
        // Two triangles, areas 1 and 3, a zero-area one between them and one with a bad index.
        let mesh = TriMesh::new(
            vec![
                DVec3::ZERO,
                DVec3::new(2.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(0.0, 0.0, 5.0),
                DVec3::new(2.0, 0.0, 5.0),
                DVec3::new(0.0, 3.0, 5.0),
            ],
            vec![[0, 1, 2], [0, 0, 1], [3, 4, 5], [3, 4, 9]],
        );
        let sampler = AreaSampler::new(&mesh).unwrap();
        assert_eq!(sampler.total_area(), 4.0);
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let n = 40_000;
        let mut on_second = 0;
        for _ in 0..n {
            let s = sampler.draw(&mesh, &mut rng);
            assert!(s.face == 0 || s.face == 2, "{s:?}");
            assert!(s.u >= 0.0 && s.v >= 0.0 && s.u + s.v <= 1.0);
            let z = if s.face == 0 { 0.0 } else { 5.0 };
            assert_eq!(s.position.z, z);
            on_second += usize::from(s.face == 2);
        }
        let share = on_second as f64 / n as f64;
        assert!((share - 0.75).abs() < 0.01, "{share}");
    }

    #[test]
    fn a_mesh_without_area_has_no_sampler() {
        let flat = TriMesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::new(2.0, 0.0, 0.0)],
            vec![[0, 1, 2]],
        );
        assert!(AreaSampler::new(&flat).is_none());
        assert!(AreaSampler::new(&TriMesh::new(vec![], vec![])).is_none());
    }
}
