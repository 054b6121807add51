//! Dense random point sets drawn from a mesh's surface, streamed to a PLY file: the large inputs
//! of the point-cloud tests and benchmarks (millions of points) are made, not committed.

use std::path::Path;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::stream::{PlyPointWriter, Point};
use crate::error::{Error, Result};
use crate::mesh::TriMesh;
use crate::surface::area_sampler::{AreaSample, AreaSampler};

/// Points drawn per chunk (bounds the memory of [`write_surface_points`]).
const CHUNK: usize = 1 << 20;

/// Draws `count` points uniformly by area on `mesh` (model units) and writes them with normals
/// (the angle-weighted vertex normals interpolated at the point) to `path` as binary PLY, in
/// chunks: memory stays O(mesh + 1M points) whatever `count` is. Deterministic for a `seed`.
///
/// # Errors
/// [`Error::InvalidMesh`] when the mesh has no area; [`Error::Write`] when the file cannot be
/// written (nothing is left at `path` then).
pub fn write_surface_points(mesh: &TriMesh, count: u64, seed: u64, path: &Path) -> Result<()> {
    let mut sampler = SurfaceSampler::new(mesh, seed)?;
    let mut writer = PlyPointWriter::create(path, count)?;
    let mut chunk: Vec<Point> = Vec::with_capacity(CHUNK.min(count as usize));
    let mut left = count;
    while left > 0 {
        let n = (left as usize).min(CHUNK);
        chunk.clear();
        chunk.extend((0..n).map(|_| sampler.draw()));
        writer.write(&chunk)?;
        left -= n as u64;
    }
    writer.finish()
}

/// `count` points drawn uniformly by area on `mesh` (its units), in memory, each with the
/// angle-weighted vertex normals interpolated at the point (a smooth normal field, like a
/// scanner's), in the order drawn. The same points as [`write_surface_points`] with the same
/// seed. Deterministic for a `seed`.
///
/// # Errors
/// [`Error::InvalidMesh`] when the mesh has no area.
pub fn surface_points(mesh: &TriMesh, count: usize, seed: u64) -> Result<Vec<Point>> {
    surface_points_with(mesh, count, seed, NormalField::Smooth)
}

/// The normals given to points drawn on a mesh.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum NormalField {
    /// The vertex normals ([`TriMesh::vertex_normals`]) interpolated across each face: smooth
    /// everywhere, also across the model's sharp edges (where they average the two sides).
    Smooth,
    /// The corner normals with a crease angle ([`TriMesh::corner_normals`]) interpolated
    /// across each face: smooth across edges flatter than the angle, the two sides' own
    /// normals across sharper ones (the creases of CAD models such as fandisk).
    Crease {
        /// The crease angle in degrees (dihedral angle between face normals).
        angle_deg: f64,
    },
}

/// [`surface_points`] with the normals of `normals`: the same positions for the same seed,
/// whatever the normal field.
///
/// # Errors
/// [`Error::InvalidMesh`] when the mesh has no area.
pub fn surface_points_with(
    mesh: &TriMesh,
    count: usize,
    seed: u64,
    normals: NormalField,
) -> Result<Vec<Point>> {
    let mut sampler = SurfaceSampler::new(mesh, seed)?;
    if let NormalField::Crease { angle_deg } = normals {
        sampler.corner_normals = Some(mesh.corner_normals(angle_deg));
    }
    Ok((0..count).map(|_| sampler.draw()).collect())
}

/// Area-uniform random points on a mesh ([`AreaSampler`]) with interpolated vertex normals.
struct SurfaceSampler<'a> {
    mesh: &'a TriMesh,
    faces: AreaSampler,
    normals: Vec<glam::DVec3>,
    /// Per face corner, replacing `normals` when set.
    corner_normals: Option<Vec<[glam::DVec3; 3]>>,
    rng: ChaCha8Rng,
}

impl<'a> SurfaceSampler<'a> {
    fn new(mesh: &'a TriMesh, seed: u64) -> Result<Self> {
        let faces = AreaSampler::new(mesh)
            .ok_or_else(|| Error::invalid_mesh("", "the mesh has no area to draw points from"))?;
        Ok(SurfaceSampler {
            mesh,
            faces,
            normals: mesh.vertex_normals(),
            corner_normals: None,
            rng: ChaCha8Rng::seed_from_u64(seed),
        })
    }

    fn draw(&mut self) -> Point {
        let mesh = self.mesh;
        let AreaSample {
            face: f,
            u,
            v,
            position,
        } = self.faces.draw(mesh, &mut self.rng);
        let w = 1.0 - u - v;
        let [na, nb, nc] = match &self.corner_normals {
            Some(c) => c[f],
            None => mesh.triangles[f].map(|i| self.normals[i as usize]),
        };
        let n = w * na + u * nb + v * nc;
        let normal = n.try_normalize().unwrap_or_else(|| mesh.face_normal(f));
        Point { position, normal }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::points::stream::PointReader;
    use glam::DVec3;

    #[test]
    fn points_lie_on_the_surface_with_its_normals_and_the_seed_repeats() {
        // The unit cube's six faces.
        let cube = crate::mesh::test_meshes::cuboid(DVec3::ZERO, DVec3::ONE);
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.ply"), dir.path().join("b.ply"));
        write_surface_points(&cube, 5000, 3, &a).unwrap();
        write_surface_points(&cube, 5000, 3, &b).unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
        let mut r = PointReader::open(&a).unwrap();
        let mut pts = Vec::new();
        assert_eq!(r.read_chunk(&mut pts, 10_000).unwrap(), 5000);
        let mut per_face = [0usize; 6];
        for q in &pts {
            let x = q.position;
            let d = [x.z, 1.0 - x.z, x.y, 1.0 - x.x, 1.0 - x.y, x.x];
            let (face, dist) = d
                .iter()
                .enumerate()
                .min_by(|a, b| a.1.total_cmp(b.1))
                .map(|(k, &v)| (k, v))
                .unwrap();
            assert!(dist.abs() < 1e-6, "{x:?} is off the cube");
            assert!(q.normal.length() > 0.99);
            per_face[face] += 1;
        }
        // Uniform by area: about 5000/6 per face.
        assert!(
            per_face.iter().all(|&c| (700..=970).contains(&c)),
            "{per_face:?}"
        );
        // With a crease angle below the cube's 90° the normals are the faces' own; smooth ones
        // lean towards the neighbouring faces near the edges.
        let outward = |x: DVec3| {
            let c = x - DVec3::splat(0.5);
            let k = (0..3)
                .max_by(|&a, &b| c[a].abs().total_cmp(&c[b].abs()))
                .unwrap();
            let mut n = DVec3::ZERO;
            n[k] = c[k].signum();
            n
        };
        let creased =
            surface_points_with(&cube, 2000, 3, NormalField::Crease { angle_deg: 60.0 }).unwrap();
        let smooth = surface_points(&cube, 2000, 3).unwrap();
        let mut leaning = 0;
        for (c, s) in creased.iter().zip(&smooth) {
            assert_eq!(c.position, s.position);
            assert!((c.normal - outward(c.position)).length() < 1e-12, "{c:?}");
            if s.normal.dot(outward(s.position)) < 0.99 {
                leaning += 1;
            }
        }
        assert!(leaning > 500, "{leaning}");
    }
}
