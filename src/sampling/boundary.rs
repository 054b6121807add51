//! The boundary curves of an open input and their sampling.
//!
//! A surface with boundary is sampled in two steps: its boundary curves (the 1-manifold where it
//! ends) first, evenly by arc length at the spacing the surface sampling will have, then the
//! surface by the linear scan with those samples already in the output set. The boundary samples
//! stay fixed during gradient ascent, and consecutive ones become the output mesh's boundary
//! edges, so every hole of the input stays a hole of the output and no other hole appears.

use rustc_hash::FxHashMap;

use crate::mesh::TriMesh;
use crate::sampling::curves::sample_curves;
pub use crate::sampling::curves::{BoundaryCurve, BoundarySamples};
use crate::sampling::sizing::Uniform;

/// The boundary curves of `mesh`: chains of edges that belong to exactly one triangle.
/// Deterministic (ordered by the lowest vertex index each curve starts from).
pub fn boundary_curves(mesh: &TriMesh) -> Vec<BoundaryCurve> {
    // Count undirected edges; remember the direction and face of the single use.
    let mut uses: FxHashMap<(u32, u32), (u32, u32, u32, u32)> = FxHashMap::default();
    for (f, t) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let key = (a.min(b), a.max(b));
            let e = uses.entry(key).or_insert((0, a, b, f as u32));
            e.0 += 1;
        }
    }
    let mut directed: Vec<(u32, u32, u32)> = uses
        .values()
        .filter(|e| e.0 == 1)
        .map(|e| (e.1, e.2, e.3))
        .collect();
    directed.sort_unstable();
    let mut out_deg: FxHashMap<u32, u32> = FxHashMap::default();
    let mut in_deg: FxHashMap<u32, u32> = FxHashMap::default();
    for &(a, b, _) in &directed {
        *out_deg.entry(a).or_default() += 1;
        *in_deg.entry(b).or_default() += 1;
    }
    let regular = |v: u32| out_deg.get(&v) == Some(&1) && in_deg.get(&v) == Some(&1);
    // Outgoing edges per vertex, in sorted order.
    let mut next: FxHashMap<u32, Vec<usize>> = FxHashMap::default();
    for (i, &(a, _, _)) in directed.iter().enumerate() {
        next.entry(a).or_default().push(i);
    }
    let mut used = vec![false; directed.len()];
    let mut curves = Vec::new();
    let walk = |start_edge: usize, used: &mut Vec<bool>| -> BoundaryCurve {
        let mut vertices = vec![directed[start_edge].0];
        let mut faces = Vec::new();
        let mut e = start_edge;
        loop {
            used[e] = true;
            let (_, b, f) = directed[e];
            faces.push(f);
            if b == vertices[0] {
                return BoundaryCurve {
                    vertices,
                    faces,
                    closed: true,
                };
            }
            vertices.push(b);
            if !regular(b) {
                return BoundaryCurve {
                    vertices,
                    faces,
                    closed: false,
                };
            }
            match next
                .get(&b)
                .and_then(|v| v.iter().copied().find(|&i| !used[i]))
            {
                Some(n) => e = n,
                None => {
                    return BoundaryCurve {
                        vertices,
                        faces,
                        closed: false,
                    }
                }
            }
        }
    };
    // Open chains start at irregular vertices; what is left are closed loops.
    for i in 0..directed.len() {
        if !used[i] && !regular(directed[i].0) {
            curves.push(walk(i, &mut used));
        }
    }
    for i in 0..directed.len() {
        if !used[i] {
            curves.push(walk(i, &mut used));
        }
    }
    curves
}

/// Places samples along every boundary curve of `mesh` at equal arc-length steps as close to
/// `spacing` (bbox-100 units) as a whole number of steps allows: a closed loop gets at least 3,
/// and the ends of open chains are shared between the chains that meet there.
pub fn sample_boundary(mesh: &TriMesh, curves: &[BoundaryCurve], spacing: f64) -> BoundarySamples {
    sample_curves(mesh, curves, &[], spacing, spacing, 1.0, &Uniform)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// A square grid of `n × n` quads in the plane z = 0, side 1, with the quad `hole` removed.
    fn grid(n: usize, hole: Option<(usize, usize)>) -> TriMesh {
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                positions.push(DVec3::new(i as f64 / n as f64, j as f64 / n as f64, 0.0));
            }
        }
        let mut triangles = Vec::new();
        for j in 0..n {
            for i in 0..n {
                if hole == Some((i, j)) {
                    continue;
                }
                let v = (j * (n + 1) + i) as u32;
                let w = v + n as u32 + 1;
                triangles.push([v, v + 1, w + 1]);
                triangles.push([v, w + 1, w]);
            }
        }
        TriMesh::new(positions, triangles)
    }

    #[test]
    fn finds_outer_boundary_and_hole_with_surface_on_the_left() {
        let mesh = grid(4, Some((1, 2)));
        let curves = boundary_curves(&mesh);
        assert_eq!(curves.len(), 2);
        assert!(curves.iter().all(|c| c.closed));
        let mut sizes: Vec<usize> = curves.iter().map(|c| c.vertices.len()).collect();
        sizes.sort();
        assert_eq!(sizes, vec![4, 16]);
        for c in &curves {
            // Signed area in the plane: outer loop counter-clockwise (positive), hole clockwise.
            let area: f64 = (0..c.vertices.len())
                .map(|k| {
                    let a = mesh.positions[c.vertices[k] as usize];
                    let b = mesh.positions[c.vertices[(k + 1) % c.vertices.len()] as usize];
                    a.x * b.y - b.x * a.y
                })
                .sum::<f64>()
                * 0.5;
            if c.vertices.len() == 16 {
                assert!((area - 1.0).abs() < 1e-12);
            } else {
                assert!((area + 1.0 / 16.0).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn boundary_samples_are_evenly_spaced_loops() {
        let mesh = grid(4, None);
        let curves = boundary_curves(&mesh);
        let b = sample_boundary(&mesh, &curves, 0.1);
        assert_eq!(b.samples.len(), 40);
        assert_eq!(b.edges.len(), 40);
        for e in &b.edges {
            let d = b.samples[e[0] as usize]
                .position
                .distance(b.samples[e[1] as usize].position);
            assert!(
                (d - 0.1).abs() < 1e-9 || (d - 0.1f64.hypot(0.0)).abs() < 1e-9,
                "{d}"
            );
        }
        // A closed mesh has none.
        assert!(boundary_curves(&TriMesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        ))
        .is_empty());
    }
}
