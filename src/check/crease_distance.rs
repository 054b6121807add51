//! How far an input's creases are from the output's edges: the one-sided Hausdorff distance
//! from the feature curves to the output's edge paths (issue 16's measure of whether creases
//! are kept, not chamfered).

use glam::DVec3;
use rayon::prelude::*;

use crate::geometry::segment::{distance_to_segment, points_along};
use crate::mesh::TriMesh;
use crate::spatial::StaticTree;

/// The distance from points along the input's feature edges to the nearest edge of `output`.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct CreaseDistance {
    /// The largest distance (units of the meshes).
    pub max: f64,
    /// The mean over the points.
    pub mean: f64,
    /// Points measured.
    pub points: usize,
}

/// Output vertices whose incident edges are searched for each point.
const NEAREST_VERTICES: usize = 8;

/// Measures, for points every `step` or closer along each edge `[a, b]` of `edges` (indices into
/// `positions`, the input's vertices), the distance to the nearest edge of `output` (same
/// units). The nearest edge is looked for among the edges of the output vertices nearest the
/// point, which finds it wherever the output's vertices are about as dense as its edges are
/// long (a remeshed surface). `None` when there is no edge or the output has no face.
/// Deterministic.
pub fn crease_distance(
    positions: &[DVec3],
    edges: &[[u32; 2]],
    output: &TriMesh,
    step: f64,
) -> Option<CreaseDistance> {
    if edges.is_empty() || output.triangles.is_empty() || !(step > 0.0) {
        return None;
    }
    let mut incident: Vec<Vec<u32>> = vec![Vec::new(); output.positions.len()];
    for t in &output.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            incident[a as usize].push(b);
            incident[b as usize].push(a);
        }
    }
    let tree = StaticTree::new(&output.positions);
    let points: Vec<DVec3> = edges
        .iter()
        .flat_map(|e| points_along(positions[e[0] as usize], positions[e[1] as usize], step))
        .collect();
    let distances: Vec<f64> = points
        .par_iter()
        .map_init(Vec::new, |near, &x| {
            tree.nearest_n(x, NEAREST_VERTICES, near);
            let mut best = f64::INFINITY;
            for &(v, _) in near.iter() {
                let s = output.positions[v as usize];
                for &w in &incident[v as usize] {
                    best = best.min(distance_to_segment(x, s, output.positions[w as usize]));
                }
            }
            best
        })
        .collect();
    let max = distances.iter().copied().fold(0.0, f64::max);
    let mean = distances.iter().sum::<f64>() / distances.len() as f64;
    Some(CreaseDistance {
        max,
        mean,
        points: distances.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_edge_on_the_output_is_at_zero_and_one_across_a_face_is_not() {
        // Output: the unit square as two triangles along its diagonal (0,0)-(1,1).
        let out = TriMesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        let input = vec![DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0), DVec3::X, DVec3::Y];
        let on = crease_distance(&input, &[[0, 1]], &out, 0.1).unwrap();
        assert!(on.max < 1e-12, "{on:?}");
        // The other diagonal, from (1,0) to (0,1), crosses the faces: at (1 − t, t) it is
        // min(t, 1 − t, |2t − 1|/√2) from the edges, at most 1/(2 + √2) ≈ 0.293 (t ≈ 0.293);
        // of the points every 1/15 of it, t = 4/15 comes nearest: 0.267.
        let across = crease_distance(&input, &[[2, 3]], &out, 0.1).unwrap();
        assert!((across.max - 4.0 / 15.0).abs() < 1e-9, "{across:?}");
        assert_eq!(across.points, 16);
        assert!(crease_distance(&input, &[], &out, 0.1).is_none());
    }
}
