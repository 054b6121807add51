//! The pairs of non-adjacent triangles of an indexed triangle set that share a point, found
//! through a bounding-volume hierarchy (parry's) and decided by exact predicates
//! ([`triangles_intersect`]).

use glam::DVec3;
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};
use rayon::prelude::*;

use super::triangle::is_degenerate_face;
use super::triangle_intersection::triangles_intersect;

/// Faces per sequential run of the search (fixed, so the result does not depend on the number
/// of threads).
const CHUNK: usize = 1024;

/// The pairs of non-adjacent triangles of `triangles` (indices into `positions`) whose closed
/// triangles share at least one point (they cross, or touch at a point, along an edge or in a
/// common area), as `[f, g]` with f < g in lexicographic order, and the number of exact tests
/// made (pairs of non-adjacent faces whose bounding boxes overlap).
///
/// Triangles with an index out of range, a non-finite corner or zero area
/// ([`is_degenerate_face`]) are left out (the invariant check reports them on their own), and so
/// are pairs that share a vertex index, since adjacent triangles meet by construction.
///
/// # Runtime
/// The bounding boxes go into a BVH; each triangle queries it with its own box, and every
/// overlapping pair is decided by [`triangles_intersect`], which is exact. O(F log F) for a mesh
/// whose triangles are small against the model; parallel (rayon) in fixed chunks, so the result
/// is deterministic.
pub fn intersecting_pairs_counted(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> (Vec<[u32; 2]>, usize) {
    let n = positions.len();
    let corners = |f: usize| triangles[f].map(|i| positions[i as usize]);
    let valid = |f: usize| {
        let t = triangles[f];
        t.iter().all(|&i| (i as usize) < n)
            && t.iter().all(|&i| positions[i as usize].is_finite())
            && !is_degenerate_face(positions, t)
    };
    let boxes: Vec<(usize, Aabb)> = (0..triangles.len())
        .filter(|&f| valid(f))
        .map(|f| {
            let [a, b, c] = corners(f);
            (f, Aabb::new(a.min(b).min(c), a.max(b).max(c)))
        })
        .collect();
    if boxes.len() < 2 {
        return (Vec::new(), 0);
    }
    let bvh = Bvh::from_iter(BvhBuildStrategy::Binned, boxes.iter().copied());
    let per_chunk: Vec<(Vec<[u32; 2]>, usize)> = boxes
        .par_chunks(CHUNK)
        .map(|chunk| {
            let (mut pairs, mut candidates) = (Vec::new(), 0);
            let mut found = Vec::new();
            for &(f, aabb) in chunk {
                let tf = triangles[f];
                found.clear();
                found.extend(
                    bvh.intersect_aabb(&aabb)
                        .map(|g| g as usize)
                        .filter(|&g| g > f && !tf.iter().any(|i| triangles[g].contains(i))),
                );
                found.sort_unstable();
                for &g in &found {
                    candidates += 1;
                    if triangles_intersect(corners(f), corners(g)) {
                        pairs.push([f as u32, g as u32]);
                    }
                }
            }
            (pairs, candidates)
        })
        .collect();
    let mut pairs = Vec::new();
    let mut candidates = 0;
    for (p, c) in per_chunk {
        pairs.extend(p);
        candidates += c;
    }
    pairs.sort_unstable();
    (pairs, candidates)
}

/// The intersecting pairs of [`intersecting_pairs_counted`], without the count of tests.
pub fn intersecting_pairs(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    intersecting_pairs_counted(positions, triangles).0
}
