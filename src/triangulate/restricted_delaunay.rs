//! The restricted Delaunay triangulation of surface samples, as the dual of their Voronoi cells
//! restricted to the input mesh: each sample's cell is the part of the surface nearer to it than
//! to any other sample, grown over the mesh from the sample (so a cell never jumps across a thin
//! part to the sheet on its other side, as a cell of the plain restricted Voronoi diagram does
//! where the closed-ball property fails: H. Edelsbrunner, N. Shah, "Triangulating topological
//! spaces", IJCGA 1997). Three cells meeting at a point of the surface give a triangle.
//!
//! The cells are computed on the input refined by edge bisection to a fraction of the sample
//! spacing ([`bisect_to_length`]): every refined vertex takes the sample nearest to it among those
//! whose cell reaches it through the mesh (a multi-source Dijkstra search with the Euclidean
//! distance to the sample as key, as the discrete restricted Voronoi diagrams of clustering
//! remeshers: S. Valette, J.-M. Chassery, R. Prost, "Generic remeshing of 3D triangular meshes
//! with metric-dependent discrete Voronoi diagrams", TVCG 2008). A refined face whose three
//! corners lie in three cells is a vertex of the diagram; its dual triangle is oriented like the
//! input.

use glam::DVec3;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::tangent_delaunay::VotedTriangle;
use crate::mesh::bisect::bisect_to_length;
use crate::spatial::StaticTree;
use crate::surface::MeshSurface;

/// Parameters of [`restricted_delaunay`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestrictedDelaunayParams {
    /// Longest edge of the refined input, as a fraction of the mean sample spacing
    /// sqrt(area / samples) (default 0.3: about 25 refined vertices per cell).
    pub resolution: f64,
}

impl Default for RestrictedDelaunayParams {
    fn default() -> Self {
        RestrictedDelaunayParams { resolution: 0.3 }
    }
}

/// What [`restricted_delaunay`] did.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct RestrictedDelaunayStats {
    /// Vertices of the refined input.
    pub refined_vertices: usize,
    /// Distinct dual triangles.
    pub triangles: usize,
    /// Samples whose cell holds no vertex of the refined input (in no triangle).
    pub empty_cells: usize,
}

/// The dual triangles of the samples' restricted Voronoi cells on `surface`'s mesh, as
/// candidates for [`assemble`](super::assemble): each with 3 votes, oriented like the input,
/// the ones met at more refined faces first. `positions`: the samples (units of the mesh, on or
/// near the surface); `spacing`: the mean sample spacing (same units).
pub fn restricted_delaunay(
    surface: &MeshSurface,
    positions: &[DVec3],
    spacing: f64,
    params: &RestrictedDelaunayParams,
) -> (Vec<VotedTriangle>, RestrictedDelaunayStats) {
    let refined = bisect_to_length(surface.mesh(), params.resolution * spacing);
    let n = refined.positions.len();
    // Vertex -> the input faces it lies in, and vertex -> its neighbours (both CSR).
    let mut in_face: Vec<(u32, u32)> = refined
        .triangles
        .iter()
        .zip(&refined.parent)
        .flat_map(|(t, &p)| t.map(|v| (v, p)))
        .collect();
    in_face.sort_unstable();
    in_face.dedup();
    let in_face_start = csr_starts(n, in_face.iter().map(|x| x.0));
    let mut edges: Vec<(u32, u32)> = refined
        .triangles
        .iter()
        .flat_map(|t| (0..3).flat_map(move |k| [(t[k], t[(k + 1) % 3]), (t[(k + 1) % 3], t[k])]))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let edge_start = csr_starts(n, edges.iter().map(|x| x.0));

    // Seeds: the refined vertices around each sample's closest point, on its input face.
    let tree = StaticTree::new(&refined.positions);
    let radius = params.resolution * spacing * 1.01;
    let mut dist = vec![f64::INFINITY; n];
    let mut label = vec![u32::MAX; n];
    let mut heap: BinaryHeap<Reverse<(u64, u32, u32)>> = BinaryHeap::new();
    let mut near = Vec::new();
    let offer =
        |v: u32, s: u32, d: f64, dist: &mut [f64], label: &mut [u32], heap: &mut BinaryHeap<_>| {
            let i = v as usize;
            if d < dist[i] || (d == dist[i] && s < label[i]) {
                dist[i] = d;
                label[i] = s;
                heap.push(Reverse((d.to_bits(), s, v)));
            }
        };
    for (s, &x) in positions.iter().enumerate() {
        let Some(sp) = surface.closest_point(x) else {
            continue;
        };
        tree.within_unsorted(sp.position, radius * radius, &mut near);
        if near.is_empty() {
            tree.nearest_n(sp.position, 1, &mut near);
        }
        let on_face: Vec<u32> = near
            .iter()
            .map(|q| q.0)
            .filter(|&v| {
                let r = in_face_start[v as usize]..in_face_start[v as usize + 1];
                in_face[r].iter().any(|&(_, f)| f == sp.face)
            })
            .collect();
        let seeds = if on_face.is_empty() {
            near.iter().map(|q| q.0).take(1).collect()
        } else {
            on_face
        };
        for v in seeds {
            let d = refined.positions[v as usize].distance(x);
            offer(v, s as u32, d, &mut dist, &mut label, &mut heap);
        }
    }
    // Grow the cells over the mesh: a vertex takes the nearest sample among its neighbours'.
    while let Some(Reverse((d, s, v))) = heap.pop() {
        let i = v as usize;
        if d != dist[i].to_bits() || s != label[i] {
            continue;
        }
        let x = positions[s as usize];
        for &(_, u) in &edges[edge_start[i]..edge_start[i + 1]] {
            let du = refined.positions[u as usize].distance(x);
            offer(u, s, du, &mut dist, &mut label, &mut heap);
        }
    }

    // Dual triangles: refined faces with three labels, counted per triple and orientation.
    let mut seen: Vec<([u32; 3], bool)> = refined
        .triangles
        .iter()
        .map(|t| t.map(|v| label[v as usize]))
        .filter(|l| l[0] != l[1] && l[1] != l[2] && l[0] != l[2] && !l.contains(&u32::MAX))
        .map(|l| {
            // Rotate the smallest label first; the orientation is whether the rest ascend.
            let k = (0..3).min_by_key(|&k| l[k]).unwrap_or(0);
            let r = [l[k], l[(k + 1) % 3], l[(k + 2) % 3]];
            if r[1] < r[2] {
                (r, true)
            } else {
                ([r[0], r[2], r[1]], false)
            }
        })
        .collect();
    seen.sort_unstable();
    let mut tally: Vec<(usize, [u32; 3])> = Vec::new();
    let mut i = 0;
    while i < seen.len() {
        let t = seen[i].0;
        let (mut forward, mut backward) = (0usize, 0usize);
        while i < seen.len() && seen[i].0 == t {
            if seen[i].1 {
                forward += 1;
            } else {
                backward += 1;
            }
            i += 1;
        }
        let corners = if forward >= backward {
            t
        } else {
            [t[0], t[2], t[1]]
        };
        tally.push((forward.max(backward), corners));
    }
    tally.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    let mut owned = vec![false; positions.len()];
    for &l in &label {
        if l != u32::MAX {
            owned[l as usize] = true;
        }
    }
    let stats = RestrictedDelaunayStats {
        refined_vertices: n,
        triangles: tally.len(),
        empty_cells: owned.iter().filter(|o| !**o).count(),
    };
    let voted = tally
        .into_iter()
        .map(|(_, corners)| VotedTriangle {
            corners,
            votes: 3,
            orientation_conflict: false,
        })
        .collect();
    (voted, stats)
}

/// Start offsets of a CSR array whose rows (`rows`, ascending, each `< n`) are given per entry.
fn csr_starts(n: usize, rows: impl Iterator<Item = u32>) -> Vec<usize> {
    let mut start = vec![0usize; n + 1];
    for r in rows {
        start[r as usize + 1] += 1;
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    start
}
