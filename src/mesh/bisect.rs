//! Refinement of a triangle mesh by edge bisection until no edge is longer than a given length
//! (the longest edge of a face first, as in Rivara's longest-edge bisection: M.-C. Rivara,
//! "Algorithms for refining triangular grids suitable for adaptive and multigrid techniques",
//! IJNME 1984). The refined mesh is the same piecewise-linear surface with more vertices; every
//! split edge is split in all its faces, so the refinement is conforming, also at non-manifold
//! edges.

use glam::DVec3;
use rayon::prelude::*;
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

/// The faces on each edge, as cycles of face sides: side `3 f + k` is the edge from corner `k`
/// to corner `k + 1` of face `f`; `next` links the sides on one undirected edge in a cycle, in
/// the order the faces came onto the edge (a side alone on its edge links to itself), and the
/// first of them carries [`HEAD`]. The order is what makes the refinement deterministic.
struct Sides {
    next: Vec<u32>,
}

/// The flag of the first side of a cycle, in the high bit of `next`.
const HEAD: u32 = 1 << 31;

impl Sides {
    fn new(triangles: &[[u32; 3]], capacity: usize) -> Self {
        let mut next: Vec<u32> = Vec::with_capacity(3 * capacity);
        next.extend((0..3 * triangles.len() as u32).map(|s| s | HEAD));
        // Sides on one edge, in face order; a face that repeats a corner has zero area and is
        // never split, and its sides stay alone.
        let mut sides: Vec<((u32, u32), u32)> = triangles
            .iter()
            .enumerate()
            .filter(|(_, t)| t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
            .flat_map(|(f, t)| {
                (0..3).map(move |k| (key(t[k], t[(k + 1) % 3]), 3 * f as u32 + k as u32))
            })
            .collect();
        sides.sort_unstable();
        for run in sides.chunk_by(|x, y| x.0 == y.0) {
            let ring: Vec<u32> = run.iter().map(|&(_, s)| s).collect();
            link(&mut next, &ring);
        }
        Sides { next }
    }

    fn next(&self, s: u32) -> u32 {
        self.next[s as usize] & !HEAD
    }

    /// The sides on the edge of side `s`, the first to come onto it first.
    fn around(&self, s: u32, out: &mut Vec<u32>) {
        out.clear();
        let mut head = s;
        while self.next[head as usize] & HEAD == 0 {
            head = self.next(head);
        }
        let mut x = head;
        loop {
            out.push(x);
            x = self.next(x);
            if x == head {
                break;
            }
        }
    }

    /// Side `new` takes the place of side `old` in its cycle.
    fn replace(&mut self, old: u32, new: u32) {
        let after = self.next(old);
        let flag = self.next[old as usize] & HEAD;
        if after == old {
            self.set(new, new, flag);
            return;
        }
        let mut before = after;
        while self.next(before) != old {
            before = self.next(before);
        }
        let before_flag = self.next[before as usize] & HEAD;
        self.set(before, new, before_flag);
        self.set(new, after, flag);
    }

    fn set(&mut self, s: u32, next: u32, flag: u32) {
        let s = s as usize;
        if s >= self.next.len() {
            self.next.resize(s + 1, 0);
        }
        self.next[s] = next | flag;
    }

    fn push_face(&mut self) {
        let n = self.next.len() as u32;
        self.next.extend([n | HEAD, (n + 1) | HEAD, (n + 2) | HEAD]);
    }
}

/// Links `ring` (sides of one edge, in order) into a cycle, its first side the head.
fn link(next: &mut [u32], ring: &[u32]) {
    for (i, &s) in ring.iter().enumerate() {
        let flag = if i == 0 { HEAD } else { 0 };
        next[s as usize] = ring[(i + 1) % ring.len()] | flag;
    }
}

/// Splits edges of `mesh` at their midpoints, each face's longest first, until every edge is
/// at most `max_length` long (units of the mesh), or with a `scale` (a relative length in
/// (0, 1] over positions) at most `max_length` times the smallest scale at the corners of its
/// face. `None` when that takes more than `max_splits` splits (each adds one vertex; slivers,
/// whose bisection makes ever thinner slivers, can take far more than their area suggests).
/// Deterministic: the same input gives the same output.
pub fn bisect_to_length(
    mesh: &TriMesh,
    max_length: f64,
    scale: Option<&(dyn Fn(DVec3) -> f64 + Sync)>,
    max_splits: usize,
) -> Option<Refined> {
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
    let mut sides = Sides::new(&triangles, expected);
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
    // The scale at each vertex (squared), taken once per vertex.
    let mut scale2: Vec<f64> = match scale {
        Some(s) => positions.par_iter().map(|&p| s(p).powi(2)).collect(),
        None => Vec::new(),
    };
    let mut queue: VecDeque<u32> = (0..triangles.len() as u32).collect();
    let mut splits = 0;
    let (mut around, mut at_a, mut at_b) = (Vec::new(), Vec::new(), Vec::new());
    while let Some(f) = queue.pop_front() {
        let t = triangles[f as usize];
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
            continue;
        }
        let (k, d2) = longest(&positions, t);
        let limit2 = match scale {
            None => limit2,
            Some(_) => limit2 * t.iter().map(|&v| scale2[v as usize]).fold(1.0, f64::min),
        };
        if d2 <= limit2 || !d2.is_finite() {
            continue;
        }
        sides.around(3 * f + k as u32, &mut around);
        // (the cycles index sides by 31 bits: a refinement that big does not fit in memory)
        if splits >= max_splits || 3 * (triangles.len() + around.len()) >= HEAD as usize {
            return None;
        }
        let (a, b) = (t[k], t[(k + 1) % 3]);
        let m = positions.len() as u32;
        positions.push(0.5 * (positions[a as usize] + positions[b as usize]));
        if let Some(s) = scale {
            scale2.push(s(positions[m as usize]).powi(2));
        }
        splits += 1;
        at_a.clear();
        at_b.clear();
        for &s in &around {
            let (g, j) = (s / 3, (s % 3) as usize);
            let tg = triangles[g as usize];
            let (x, y, c) = (tg[j], tg[(j + 1) % 3], tg[(j + 2) % 3]);
            // g keeps x-m-c (its side j + 1 turns from y-c into m-c); h is m-y-c.
            let h = triangles.len() as u32;
            triangles[g as usize][(j + 1) % 3] = m;
            triangles.push([m, y, c]);
            parent.push(parent[g as usize]);
            sides.push_face();
            let yc = 3 * g + ((j + 1) % 3) as u32;
            sides.replace(yc, 3 * h + 1);
            link(&mut sides.next, &[yc, 3 * h + 2]);
            let (xm, my) = (3 * g + j as u32, 3 * h);
            if x == a {
                at_a.push(xm);
                at_b.push(my);
            } else {
                at_a.push(my);
                at_b.push(xm);
            }
            queue.push_back(g);
            queue.push_back(h);
        }
        link(&mut sides.next, &at_a);
        link(&mut sides.next, &at_b);
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

    /// With a scale, each edge is at most the length times the smallest scale at its face's
    /// corners: finer where the scale is small, as coarse as without it where it is 1.
    #[test]
    fn a_scale_refines_where_it_is_small() {
        let mesh = test_meshes::uv_sphere(10.0, 6, 8);
        let half = |p: DVec3| if p.x > 0.0 { 0.5 } else { 1.0 };
        let r = bisect_to_length(&mesh, 2.0, Some(&half), usize::MAX).unwrap();
        let plain = bisect_to_length(&mesh, 2.0, None, usize::MAX).unwrap();
        assert!(r.positions.len() > plain.positions.len());
        for t in &r.triangles {
            let smallest = t
                .iter()
                .map(|&v| half(r.positions[v as usize]))
                .fold(1.0, f64::min);
            for k in 0..3 {
                let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                assert!(r.positions[a].distance(r.positions[b]) <= 2.0 * smallest + 1e-12);
            }
        }
        // A scale of 1 everywhere is no scale.
        let one = |_: DVec3| 1.0;
        let same = bisect_to_length(&mesh, 2.0, Some(&one), usize::MAX).unwrap();
        assert_eq!(same.positions, plain.positions);
        assert_eq!(same.triangles, plain.triangles);
    }

    #[test]
    fn refines_below_the_length_and_keeps_the_surface() {
        let mesh = test_meshes::uv_sphere(10.0, 6, 8);
        let r = bisect_to_length(&mesh, 1.0, None, usize::MAX).unwrap();
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
        assert!(bisect_to_length(&mesh, 1.0, None, 100).is_none());
    }

    #[test]
    fn a_mesh_already_fine_is_unchanged() {
        let mesh = test_meshes::uv_sphere(1.0, 6, 8);
        let r = bisect_to_length(&mesh, 10.0, None, 0).unwrap();
        assert_eq!(r.positions, mesh.positions);
        assert_eq!(r.triangles, mesh.triangles);
    }
}
