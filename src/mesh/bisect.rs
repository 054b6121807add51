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
use crate::geometry::tolerance::LENGTH_TIE;

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

fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Undirected edge -> the faces on it: two inline (`NONE` when empty), more (a non-manifold
/// edge) in `more`.
#[derive(Default)]
struct EdgeFaces {
    two: FxHashMap<(u32, u32), [u32; 2]>,
    more: FxHashMap<(u32, u32), Vec<u32>>,
}

const NONE: u32 = u32::MAX;

impl EdgeFaces {
    fn with_capacity(n: usize) -> Self {
        EdgeFaces {
            two: FxHashMap::with_capacity_and_hasher(n, Default::default()),
            more: FxHashMap::default(),
        }
    }

    fn push(&mut self, e: (u32, u32), f: u32) {
        let slot = self.two.entry(e).or_insert([NONE; 2]);
        if slot[0] == NONE {
            slot[0] = f;
        } else if slot[1] == NONE {
            slot[1] = f;
        } else {
            self.more.entry(e).or_default().push(f);
        }
    }

    /// Removes the edge; returns its faces.
    fn take(&mut self, e: (u32, u32), out: &mut Vec<u32>) {
        out.clear();
        if let Some(slot) = self.two.remove(&e) {
            out.extend(slot.into_iter().filter(|&f| f != NONE));
            if let Some(m) = self.more.remove(&e) {
                out.extend(m);
            }
        }
    }

    /// Face `g` on edge `e` becomes face `h`.
    fn replace(&mut self, e: (u32, u32), g: u32, h: u32) {
        if let Some(slot) = self.two.get_mut(&e) {
            if let Some(s) = slot.iter_mut().find(|s| **s == g) {
                *s = h;
                return;
            }
        }
        if let Some(m) = self.more.get_mut(&e) {
            if let Some(s) = m.iter_mut().find(|s| **s == g) {
                *s = h;
            }
        }
    }
}

/// Splits edges of `mesh` at their midpoints, each face's longest first, until every edge is
/// at most `max_length` long (units of the mesh). `None` when that takes more than `max_splits`
/// splits (each adds one vertex; slivers, whose bisection makes ever thinner slivers, can take
/// far more than their area suggests). Deterministic: the same input gives the same output.
pub fn bisect_to_length(mesh: &TriMesh, max_length: f64, max_splits: usize) -> Option<Refined> {
    let mut positions = mesh.positions.clone();
    let mut triangles = mesh.triangles.clone();
    let mut parent: Vec<u32> = (0..triangles.len() as u32).collect();
    let limit2 = max_length * max_length;
    // About how many faces the refinement makes (a face of the refined mesh has about half the
    // area of a right triangle with legs max_length / 2 or more).
    let expected = triangles.len() + (mesh.area() / (0.2 * limit2)).min(max_splits as f64) as usize;
    positions.reserve(expected / 2);
    triangles.reserve(expected);
    parent.reserve(expected);
    let mut edge_faces = EdgeFaces::with_capacity(3 * expected / 2);
    for (f, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            edge_faces.push(key(t[k], t[(k + 1) % 3]), f as u32);
        }
    }
    // The longest edge; edges equal in length up to LENGTH_TIE (the same mesh read from float32
    // and from text) are told apart by their vertex indices, so both refine alike.
    let longest = |positions: &[DVec3], t: [u32; 3]| -> (usize, f64) {
        let d = |k: usize| {
            positions[t[k] as usize].distance_squared(positions[t[(k + 1) % 3] as usize])
        };
        let (mut best, mut best_d) = (0, d(0));
        for k in 1..3 {
            let dk = d(k);
            let tie = (dk - best_d).abs() <= LENGTH_TIE * dk.max(best_d);
            if (!tie && dk > best_d)
                || (tie && key(t[k], t[(k + 1) % 3]) < key(t[best], t[(best + 1) % 3]))
            {
                (best, best_d) = (k, dk);
            }
        }
        (best, best_d)
    };
    let mut queue: VecDeque<u32> = (0..triangles.len() as u32).collect();
    let mut splits = 0;
    let mut faces = Vec::new();
    while let Some(f) = queue.pop_front() {
        let t = triangles[f as usize];
        let (k, d2) = longest(&positions, t);
        if d2 <= limit2 || !d2.is_finite() {
            continue;
        }
        if splits >= max_splits {
            return None;
        }
        let (a, b) = (t[k], t[(k + 1) % 3]);
        let m = positions.len() as u32;
        positions.push(0.5 * (positions[a as usize] + positions[b as usize]));
        splits += 1;
        edge_faces.take(key(a, b), &mut faces);
        for &g in &faces {
            let tg = triangles[g as usize];
            let Some(j) = (0..3).find(|&j| key(tg[j], tg[(j + 1) % 3]) == key(a, b)) else {
                continue;
            };
            let (x, y, c) = (tg[j], tg[(j + 1) % 3], tg[(j + 2) % 3]);
            let h = triangles.len() as u32;
            triangles[g as usize] = [x, m, c];
            triangles.push([m, y, c]);
            parent.push(parent[g as usize]);
            edge_faces.push(key(x, m), g);
            edge_faces.push(key(m, y), h);
            edge_faces.push(key(m, c), g);
            edge_faces.push(key(m, c), h);
            edge_faces.replace(key(y, c), g, h);
            queue.push_back(g);
            queue.push_back(h);
        }
    }
    Some(Refined {
        positions,
        triangles,
        parent,
    })
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
        let r = bisect_to_length(&mesh, 1.0, usize::MAX).unwrap();
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
    fn the_split_budget_is_kept() {
        let mesh = test_meshes::uv_sphere(10.0, 6, 8);
        assert!(bisect_to_length(&mesh, 1.0, 100).is_none());
    }

    #[test]
    fn a_mesh_already_fine_is_unchanged() {
        let mesh = test_meshes::uv_sphere(1.0, 6, 8);
        let r = bisect_to_length(&mesh, 10.0, 0).unwrap();
        assert_eq!(r.positions, mesh.positions);
        assert_eq!(r.triangles, mesh.triangles);
    }
}
