//! Meshes the unit tests build (integration tests have their own in `tests/common`).

use glam::DVec3;

use crate::mesh::TriMesh;

/// An open cylinder of radius `r` round the z axis from z = 0: `sides` facets round, `rings`
/// bands of height `band`, each quad split along a diagonal; outward. Vertex `k · sides + i` is
/// ring k's i-th.
pub(crate) fn open_cylinder(r: f64, sides: usize, rings: usize, band: f64) -> TriMesh {
    let mut positions = Vec::new();
    for k in 0..=rings {
        for i in 0..sides {
            let a = std::f64::consts::TAU * i as f64 / sides as f64;
            positions.push(DVec3::new(r * a.cos(), r * a.sin(), band * k as f64));
        }
    }
    let at = |k: usize, i: usize| (k * sides + i % sides) as u32;
    let mut triangles = Vec::new();
    for k in 0..rings {
        for i in 0..sides {
            triangles.push([at(k, i), at(k, i + 1), at(k + 1, i + 1)]);
            triangles.push([at(k, i), at(k + 1, i + 1), at(k + 1, i)]);
        }
    }
    TriMesh::new(positions, triangles)
}
