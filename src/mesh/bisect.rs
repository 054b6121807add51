//! Refinement of a triangle mesh by edge bisection until no edge is longer than a given length
//! (the longest edge of a face first, as in Rivara's longest-edge bisection: M.-C. Rivara,
//! "Algorithms for refining triangular grids suitable for adaptive and multigrid techniques",
//! IJNME 1984). The refined mesh is the same piecewise-linear surface with more vertices; every
//! split edge is split in all its faces, so the refinement is conforming, also at non-manifold
//! edges.

use glam::DVec3;
use rustc_hash::FxHashMap;
use std::collections::VecDeque;

use super::TriMesh;

/// A refined mesh: positions, faces, and for each face the face of the source mesh it lies in.
#[derive(Debug, Clone, PartialEq)]
pub struct Refined {
    /// Vertex positions: the source mesh's vertices first (same indices), then the edge
    /// midpoints (units of the source mesh).
    pub positions: Vec<DVec3>,
    /// Faces, oriented like the source face they lie in.
    pub triangles: Vec<[u32; 3]>,
    /// `parent[f]`: index of the source face that face `f` lies in.
    pub parent: Vec<u32>,
}

/// The most splits [`bisect_to_length`] makes: a guard against a length far below the mesh's
/// size (each split adds one vertex).
pub const MAX_SPLITS: usize = 20_000_000;

fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Splits edges of `mesh` at their midpoints, each face's longest first, until every edge is
/// at most `max_length` long (units of the mesh) or [`MAX_SPLITS`] splits were made.
/// Deterministic: the same input gives the same output.
pub fn bisect_to_length(mesh: &TriMesh, max_length: f64) -> Refined {
    let mut positions = mesh.positions.clone();
    let mut triangles = mesh.triangles.clone();
    let mut parent: Vec<u32> = (0..triangles.len() as u32).collect();
    let mut edge_faces: FxHashMap<(u32, u32), Vec<u32>> = FxHashMap::default();
    for (f, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            edge_faces
                .entry(key(t[k], t[(k + 1) % 3]))
                .or_default()
                .push(f as u32);
        }
    }
    let limit2 = max_length * max_length;
    let longest = |positions: &[DVec3], t: [u32; 3]| -> (usize, f64) {
        (0..3)
            .map(|k| {
                let d =
                    positions[t[k] as usize].distance_squared(positions[t[(k + 1) % 3] as usize]);
                (k, d)
            })
            .fold((0, -1.0), |best, x| if x.1 > best.1 { x } else { best })
    };
    let mut queue: VecDeque<u32> = (0..triangles.len() as u32).collect();
    let mut splits = 0;
    while let Some(f) = queue.pop_front() {
        let t = triangles[f as usize];
        let (k, d2) = longest(&positions, t);
        if d2 <= limit2 || !d2.is_finite() || splits >= MAX_SPLITS {
            continue;
        }
        let (a, b) = (t[k], t[(k + 1) % 3]);
        let m = positions.len() as u32;
        positions.push(0.5 * (positions[a as usize] + positions[b as usize]));
        splits += 1;
        let faces = edge_faces.remove(&key(a, b)).unwrap_or_default();
        for g in faces {
            let tg = triangles[g as usize];
            let Some(j) = (0..3).find(|&j| key(tg[j], tg[(j + 1) % 3]) == key(a, b)) else {
                continue;
            };
            let (x, y, c) = (tg[j], tg[(j + 1) % 3], tg[(j + 2) % 3]);
            let h = triangles.len() as u32;
            triangles[g as usize] = [x, m, c];
            triangles.push([m, y, c]);
            parent.push(parent[g as usize]);
            edge_faces.entry(key(x, m)).or_default().push(g);
            edge_faces.entry(key(m, y)).or_default().push(h);
            let mc = edge_faces.entry(key(m, c)).or_default();
            mc.push(g);
            mc.push(h);
            if let Some(yc) = edge_faces.get_mut(&key(y, c)) {
                if let Some(s) = yc.iter_mut().find(|s| **s == g) {
                    *s = h;
                }
            }
            queue.push_back(g);
            queue.push_back(h);
        }
    }
    Refined {
        positions,
        triangles,
        parent,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes;

    fn max_edge(r: &Refined) -> f64 {
        r.triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
            .map(|(a, b)| r.positions[a as usize].distance(r.positions[b as usize]))
            .fold(0.0, f64::max)
    }

    #[test]
    fn refines_below_the_length_and_keeps_the_surface() {
        let mesh = test_meshes::uv_sphere(10.0, 6, 8);
        let r = bisect_to_length(&mesh, 1.0);
        assert!(max_edge(&r) <= 1.0 + 1e-12);
        let before = TriMesh::new(mesh.positions.clone(), mesh.triangles.clone());
        let after = TriMesh::new(r.positions.clone(), r.triangles.clone());
        assert!((before.area() - after.area()).abs() < 1e-9 * before.area());
        // Conforming: closed stays closed, with the same Euler characteristic.
        let t = crate::check::topology(&after);
        assert_eq!(t.boundary_edges, 0);
        assert_eq!(t.non_manifold_edges, 0);
        assert_eq!(
            t.euler_characteristic,
            crate::check::topology(&before).euler_characteristic
        );
        // Every face lies in its parent.
        for f in 0..r.triangles.len() {
            let n = after.face_normal(f);
            let np = before.face_normal(r.parent[f] as usize);
            assert!(n.dot(np) > 1.0 - 1e-9, "face {f} turned against its parent");
        }
    }

    #[test]
    fn a_mesh_already_fine_is_unchanged() {
        let mesh = test_meshes::uv_sphere(1.0, 6, 8);
        let r = bisect_to_length(&mesh, 10.0);
        assert_eq!(r.positions, mesh.positions);
        assert_eq!(r.triangles, mesh.triangles);
    }
}
