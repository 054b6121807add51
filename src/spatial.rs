//! Nearest-neighbour queries over 3D points: a thin layer over kiddo's kd-trees so the rest of the
//! crate uses one vocabulary (indices into the caller's point list, squared distances named `*_2`).

use std::num::NonZeroUsize;

use glam::DVec3;
use kiddo::{ImmutableKdTree, MutableKdTree, SquaredEuclidean};

#[inline]
fn arr(p: DVec3) -> [f64; 3] {
    [p.x, p.y, p.z]
}

/// A kd-tree that grows one point at a time (the output set of the linear scan, Sec. 6.3).
pub struct DynamicTree {
    tree: MutableKdTree<f64, 3>,
    len: usize,
}

impl Default for DynamicTree {
    fn default() -> Self {
        Self::new()
    }
}

impl DynamicTree {
    /// An empty tree.
    pub fn new() -> Self {
        DynamicTree {
            tree: MutableKdTree::default(),
            len: 0,
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the tree is empty.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Adds point `p` with index `index`. Returns false if the tree refused it (a degenerate
    /// split: many points with the same coordinate); such a point is then absent from queries.
    pub fn add(&mut self, p: DVec3, index: u32) -> bool {
        let ok = self.tree.add(&arr(p), index).is_ok();
        if ok {
            self.len += 1;
        }
        ok
    }

    /// The nearest point to `p` as `(index, squared distance)`; `None` when empty.
    pub fn nearest(&self, p: DVec3) -> Option<(u32, f64)> {
        if self.len == 0 {
            return None;
        }
        let r = self
            .tree
            .query(&arr(p))
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        Some((r.item, r.distance))
    }

    /// All points within squared distance `radius_2` of `p`, nearest first, into `out` as
    /// `(index, squared distance)`.
    pub fn within(&self, p: DVec3, radius_2: f64, out: &mut Vec<(u32, f64)>) {
        out.clear();
        if self.len == 0 {
            return;
        }
        let r = self
            .tree
            .query(&arr(p))
            .within::<SquaredEuclidean<f64>>(radius_2)
            .execute();
        out.extend(r.into_iter().map(|q| (q.item, q.distance)));
    }
}

/// A kd-tree built once over a fixed point list.
pub struct StaticTree {
    tree: Option<ImmutableKdTree<f64, 3>>,
}

impl StaticTree {
    /// A tree over `points`; index `i` of a result is `points[i]`.
    pub fn new(points: &[DVec3]) -> Self {
        let entries: Vec<[f64; 3]> = points.iter().map(|&p| arr(p)).collect();
        let tree = if entries.is_empty() {
            None
        } else {
            ImmutableKdTree::new_from_slice(&entries).ok()
        };
        StaticTree { tree }
    }

    /// Points within squared distance `radius_2` of `p`, nearest first, as `(index, squared
    /// distance)`.
    pub fn within(&self, p: DVec3, radius_2: f64, out: &mut Vec<(u32, f64)>) {
        out.clear();
        if let Some(t) = &self.tree {
            let r = t
                .query(&arr(p))
                .within::<SquaredEuclidean<f64>>(radius_2)
                .execute();
            out.extend(r.into_iter().map(|q| (q.item as u32, q.distance)));
        }
    }

    /// The `k` nearest points to `p`, nearest first, as `(index, squared distance)`.
    pub fn nearest_n(&self, p: DVec3, k: usize, out: &mut Vec<(u32, f64)>) {
        out.clear();
        let (Some(t), Some(k)) = (&self.tree, NonZeroUsize::new(k)) else {
            return;
        };
        let r = t
            .query(&arr(p))
            .nearest_n::<SquaredEuclidean<f64>>(k)
            .execute();
        out.extend(r.into_iter().map(|q| (q.item as u32, q.distance)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    fn brute(points: &[DVec3], p: DVec3, r2: f64) -> Vec<u32> {
        let mut v: Vec<(u32, f64)> = points
            .iter()
            .enumerate()
            .map(|(i, q)| (i as u32, q.distance_squared(p)))
            .filter(|(_, d)| *d <= r2)
            .collect();
        v.sort_by(|a, b| a.1.total_cmp(&b.1));
        v.into_iter().map(|x| x.0).collect()
    }

    #[test]
    fn trees_agree_with_brute_force() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let pts: Vec<DVec3> = (0..2000)
            .map(|_| DVec3::new(rng.random(), rng.random(), rng.random()) * 10.0)
            .collect();
        let mut dynamic = DynamicTree::new();
        for (i, p) in pts.iter().enumerate() {
            assert!(dynamic.add(*p, i as u32));
        }
        let fixed = StaticTree::new(&pts);
        let mut out = Vec::new();
        for _ in 0..200 {
            let q = DVec3::new(rng.random(), rng.random(), rng.random()) * 10.0;
            let expect = brute(&pts, q, 1.5);
            dynamic.within(q, 1.5, &mut out);
            assert_eq!(out.iter().map(|x| x.0).collect::<Vec<_>>(), expect);
            fixed.within(q, 1.5, &mut out);
            assert_eq!(out.iter().map(|x| x.0).collect::<Vec<_>>(), expect);
            let (i, d) = dynamic.nearest(q).unwrap();
            let all = brute(&pts, q, f64::INFINITY);
            assert_eq!(i, all[0]);
            assert!((d - pts[i as usize].distance_squared(q)).abs() < 1e-12);
            fixed.nearest_n(q, 7, &mut out);
            assert_eq!(
                out.iter().map(|x| x.0).collect::<Vec<_>>(),
                all[..7].to_vec()
            );
        }
    }
}
