//! Building parry's bounding volume hierarchy from boxes keyed by arbitrary indices (face
//! numbers with some faces left out, edit-mesh slots).
//!
//! parry 0.31's builder special-cases one and two leaves and then assumes their indices are 0
//! and 1 (`bvh_tree.rs`, "key not present"): a BVH of two faces numbered 0 and 5 (a mesh whose
//! other faces have no area) panicked. [`bvh_of`] pads such a set with leaves far outside any
//! model, so that the builder takes its general path; no query near a model meets them.

use glam::DVec3;
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};

/// Where the padding leaves are: far beyond any model (coordinates are bbox-100 units or model
/// units of at most about 1e30 here), yet finite, so the builder's centroids stay finite.
const FAR: f64 = 1e300;

/// The BVH (binned build) of `boxes`, `(leaf index, box)`. With fewer than three boxes whose
/// indices are not `0..n`, leaves indexed past the largest given one are added at [`FAR`]
/// (their boxes meet no query of a model); a query's leaf indices are the given ones.
pub(crate) fn bvh_of(boxes: impl IntoIterator<Item = (usize, Aabb)>) -> Bvh {
    let mut boxes: Vec<(usize, Aabb)> = boxes.into_iter().collect();
    let consecutive = boxes.iter().enumerate().all(|(i, &(k, _))| i == k);
    if boxes.len() < 3 && !consecutive {
        let next = boxes.iter().map(|&(k, _)| k + 1).max().unwrap_or(0);
        for k in 0..3 - boxes.len() {
            let c = FAR * (1.0 + k as f64 * 1e-3);
            boxes.push((next + k, Aabb::new(DVec3::splat(c), DVec3::splat(c))));
        }
    }
    Bvh::from_iter(BvhBuildStrategy::Binned, boxes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box(x: f64) -> Aabb {
        Aabb::new(DVec3::new(x, 0.0, 0.0), DVec3::new(x + 1.0, 1.0, 1.0))
    }

    #[test]
    fn one_or_two_leaves_with_any_indices_build_and_answer_with_their_own() {
        for keys in [vec![5], vec![0, 5], vec![3, 1], vec![7, 8]] {
            let boxes: Vec<(usize, Aabb)> = keys
                .iter()
                .enumerate()
                .map(|(i, &k)| (k, unit_box(3.0 * i as f64)))
                .collect();
            let bvh = bvh_of(boxes.iter().copied());
            for (k, b) in &boxes {
                let hits: Vec<u32> = bvh.intersect_aabb(b).collect();
                assert_eq!(hits, vec![*k as u32], "{keys:?}");
            }
        }
    }
}
