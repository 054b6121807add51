//! Nearest-neighbour queries: a thin layer over kiddo's kd-trees so the rest of the crate uses one
//! vocabulary (indices into the caller's point list, squared distances named `*_2`). The trees
//! over points of R^K ([`DynamicKdTree`], [`StaticKdTree`]) serve point sets of any dimension;
//! [`DynamicTree`] and [`StaticTree`] are those trees over 3D points in a rotated frame.

use std::num::NonZeroUsize;

use glam::DVec3;
use kiddo::{ImmutableKdTree, MutableKdTree, SquaredEuclidean};

/// Points are stored in a fixed, generic rotation of the model frame. CAD models put thousands of
/// points on one axis-aligned plane; a kd-tree bucket whose points all share the coordinate it
/// must split on cannot split, and kiddo's mutable tree then refuses the point. A rotation keeps
/// every distance (to rounding, about 1e-15 relative) and removes those ties.
#[inline]
fn arr(p: DVec3) -> [f64; 3] {
    // Rows of the rotation by the unit quaternion (0.8, 0.3, 0.4, 0.34)/|.|, precomputed.
    const R: [[f64; 3]; 3] = rotation();
    [
        R[0][0] * p.x + R[0][1] * p.y + R[0][2] * p.z,
        R[1][0] * p.x + R[1][1] * p.y + R[1][2] * p.z,
        R[2][0] * p.x + R[2][1] * p.y + R[2][2] * p.z,
    ]
}

const fn rotation() -> [[f64; 3]; 3] {
    // q = (w, x, y, z) with w² + x² + y² + z² = 1: 0.8² + 0.3² + 0.4² + z² = 1 → z² = 0.11.
    let (w, x, y) = (0.8, 0.3, 0.4);
    let z = 0.331_662_479_035_539_95; // sqrt(0.11)
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// A kd-tree that grows one point at a time, over points of R^K (the output set of the linear
/// scan, Sec. 6.3). Points are stored as given: a caller whose points may share coordinates
/// exactly (an axis-aligned plane) rotates them first, as the 3D trees do.
pub struct DynamicKdTree<const K: usize> {
    tree: MutableKdTree<f64, K>,
    /// Points the kd-tree refused (exact ties it cannot split, for example duplicates); searched
    /// by brute force so that no point is ever missing from a query.
    overflow: Vec<([f64; K], u32)>,
    len: usize,
}

impl<const K: usize> Default for DynamicKdTree<K> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const K: usize> DynamicKdTree<K> {
    /// An empty tree.
    pub fn new() -> Self {
        DynamicKdTree {
            tree: MutableKdTree::default(),
            overflow: Vec::new(),
            len: 0,
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the tree holds no point.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Adds point `q` with index `index`. A point the kd-tree cannot take (a bucket of exact
    /// coordinate ties) goes to a small list searched by brute force.
    pub fn add(&mut self, q: &[f64; K], index: u32) {
        if self.tree.add(q, index).is_err() {
            self.overflow.push((*q, index));
        }
        self.len += 1;
    }

    /// The nearest point to `q` as `(index, squared distance)`; `None` when empty.
    pub fn nearest(&self, q: &[f64; K]) -> Option<(u32, f64)> {
        if self.len == 0 {
            return None;
        }
        let mut best = (u32::MAX, f64::INFINITY);
        if self.len > self.overflow.len() {
            let r = self
                .tree
                .query(q)
                .nearest_one::<SquaredEuclidean<f64>>()
                .execute();
            best = (r.item, r.distance);
        }
        for &(o, i) in &self.overflow {
            let d = dist2(&o, q);
            if d < best.1 || (d == best.1 && i < best.0) {
                best = (i, d);
            }
        }
        Some(best)
    }

    /// The `k` nearest points to `q`, nearest first, into `out` as `(index, squared distance)`.
    pub fn nearest_n(&self, q: &[f64; K], k: usize, out: &mut Vec<(u32, f64)>) {
        out.clear();
        let Some(k_nz) = NonZeroUsize::new(k) else {
            return;
        };
        if self.len == 0 {
            return;
        }
        if self.len > self.overflow.len() {
            let r = self
                .tree
                .query(q)
                .nearest_n::<SquaredEuclidean<f64>>(k_nz)
                .execute();
            out.extend(r.into_iter().map(|n| (n.item, n.distance)));
        }
        if !self.overflow.is_empty() {
            out.extend(self.overflow.iter().map(|&(o, i)| (i, dist2(&o, q))));
            out.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
            out.truncate(k);
        }
    }

    /// All points within squared distance `radius_2` of `q`, nearest first, into `out` as
    /// `(index, squared distance)`.
    pub fn within(&self, q: &[f64; K], radius_2: f64, out: &mut Vec<(u32, f64)>) {
        out.clear();
        if self.len == 0 {
            return;
        }
        let r = self
            .tree
            .query(q)
            .within::<SquaredEuclidean<f64>>(radius_2)
            .execute();
        out.extend(r.into_iter().map(|n| (n.item, n.distance)));
        if !self.overflow.is_empty() {
            out.extend(
                self.overflow
                    .iter()
                    .map(|&(o, i)| (i, dist2(&o, q)))
                    .filter(|x| x.1 <= radius_2),
            );
            out.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        }
    }
}

/// A kd-tree over 3D points that grows one point at a time (the output set of the linear scan,
/// Sec. 6.3), in a fixed generic rotation of the model frame so that axis-aligned ties do not
/// arise.
#[derive(Default)]
pub struct DynamicTree {
    tree: DynamicKdTree<3>,
}

impl DynamicTree {
    /// An empty tree.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of points.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.tree.len()
    }

    /// Adds point `p` with index `index` (see [`DynamicKdTree::add`]).
    pub fn add(&mut self, p: DVec3, index: u32) {
        self.tree.add(&arr(p), index);
    }

    /// The nearest point to `p` as `(index, squared distance)`; `None` when empty.
    pub fn nearest(&self, p: DVec3) -> Option<(u32, f64)> {
        self.tree.nearest(&arr(p))
    }

    /// The `k` nearest points to `p`, nearest first, into `out` as `(index, squared distance)`.
    pub fn nearest_n(&self, p: DVec3, k: usize, out: &mut Vec<(u32, f64)>) {
        self.tree.nearest_n(&arr(p), k, out);
    }

    /// All points within squared distance `radius_2` of `p`, nearest first, into `out` as
    /// `(index, squared distance)`.
    pub fn within(&self, p: DVec3, radius_2: f64, out: &mut Vec<(u32, f64)>) {
        self.tree.within(&arr(p), radius_2, out);
    }
}

#[inline]
fn dist2<const K: usize>(a: &[f64; K], b: &[f64; K]) -> f64 {
    let mut d = 0.0;
    for k in 0..K {
        d += (a[k] - b[k]).powi(2);
    }
    d
}

/// A kd-tree built once over a fixed list of points of R^K.
pub struct StaticKdTree<const K: usize> {
    tree: Option<ImmutableKdTree<f64, K>>,
}

impl<const K: usize> StaticKdTree<K> {
    /// A tree over `points`; index `i` of a result is `points[i]`.
    pub fn new(points: &[[f64; K]]) -> Self {
        let tree = if points.is_empty() {
            None
        } else {
            ImmutableKdTree::new_from_slice(points).ok()
        };
        StaticKdTree { tree }
    }

    /// Points within squared distance `radius_2` of `q`, nearest first, as `(index, squared
    /// distance)`.
    pub fn within(&self, q: &[f64; K], radius_2: f64, out: &mut Vec<(u32, f64)>) {
        out.clear();
        if let Some(t) = &self.tree {
            let r = t
                .query(q)
                .within::<SquaredEuclidean<f64>>(radius_2)
                .execute();
            out.extend(r.into_iter().map(|q| (q.item, q.distance)));
        }
    }

    /// Points within squared distance `radius_2` of `q`, in no particular order (cheaper than
    /// [`StaticKdTree::within`]), as `(index, squared distance)`.
    pub fn within_unsorted(&self, q: &[f64; K], radius_2: f64, out: &mut Vec<(u32, f64)>) {
        out.clear();
        if let Some(t) = &self.tree {
            t.query(q)
                .within::<SquaredEuclidean<f64>>(radius_2)
                .unsorted()
                .visit(|q| out.push((q.item, q.distance)));
        }
    }

    /// Calls `visit(index, squared distance)` for the points within squared distance
    /// `radius_2` of `q`, in no particular order, without collecting them.
    pub fn visit_within(&self, q: &[f64; K], radius_2: f64, mut visit: impl FnMut(u32, f64)) {
        if let Some(t) = &self.tree {
            t.query(q)
                .within::<SquaredEuclidean<f64>>(radius_2)
                .unsorted()
                .visit(|q| visit(q.item, q.distance));
        }
    }

    /// The nearest point to `q` as `(index, squared distance)`; `None` when the tree is empty.
    pub fn nearest(&self, q: &[f64; K]) -> Option<(u32, f64)> {
        let r = self
            .tree
            .as_ref()?
            .query(q)
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        Some((r.item, r.distance))
    }

    /// The `k` nearest points to `q`, nearest first, as `(index, squared distance)`.
    pub fn nearest_n(&self, q: &[f64; K], k: usize, out: &mut Vec<(u32, f64)>) {
        out.clear();
        let (Some(t), Some(k)) = (&self.tree, NonZeroUsize::new(k)) else {
            return;
        };
        let r = t.query(q).nearest_n::<SquaredEuclidean<f64>>(k).execute();
        out.extend(r.into_iter().map(|q| (q.item, q.distance)));
    }
}

/// A kd-tree built once over a fixed list of 3D points, in a fixed generic rotation of the model
/// frame (no axis-aligned ties).
pub struct StaticTree {
    tree: StaticKdTree<3>,
}

impl StaticTree {
    /// A tree over `points`; index `i` of a result is `points[i]`.
    pub fn new(points: &[DVec3]) -> Self {
        let entries: Vec<[f64; 3]> = points.iter().map(|&p| arr(p)).collect();
        StaticTree {
            tree: StaticKdTree::new(&entries),
        }
    }

    /// Points within squared distance `radius_2` of `p`, nearest first, as `(index, squared
    /// distance)`.
    pub fn within(&self, p: DVec3, radius_2: f64, out: &mut Vec<(u32, f64)>) {
        self.tree.within(&arr(p), radius_2, out);
    }

    /// Points within squared distance `radius_2` of `p`, in no particular order (cheaper than
    /// [`StaticTree::within`]), as `(index, squared distance)`.
    pub fn within_unsorted(&self, p: DVec3, radius_2: f64, out: &mut Vec<(u32, f64)>) {
        self.tree.within_unsorted(&arr(p), radius_2, out);
    }

    /// Calls `visit(index, squared distance)` for the points within squared distance
    /// `radius_2` of `p`, in no particular order, without collecting them.
    pub fn visit_within(&self, p: DVec3, radius_2: f64, visit: impl FnMut(u32, f64)) {
        self.tree.visit_within(&arr(p), radius_2, visit);
    }

    /// The nearest point to `p` as `(index, squared distance)`; `None` when the tree is empty.
    pub fn nearest(&self, p: DVec3) -> Option<(u32, f64)> {
        self.tree.nearest(&arr(p))
    }

    /// The `k` nearest points to `p`, nearest first, as `(index, squared distance)`.
    pub fn nearest_n(&self, p: DVec3, k: usize, out: &mut Vec<(u32, f64)>) {
        self.tree.nearest_n(&arr(p), k, out);
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
            dynamic.add(*p, i as u32);
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
            fixed.within_unsorted(q, 1.5, &mut out);
            let mut unsorted: Vec<u32> = out.iter().map(|x| x.0).collect();
            unsorted.sort_by(|a, b| {
                pts[*a as usize]
                    .distance_squared(q)
                    .total_cmp(&pts[*b as usize].distance_squared(q))
            });
            assert_eq!(unsorted, expect);
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

    /// Thousands of points on one axis-aligned plane and on one axis-aligned line (a CAD face and
    /// edge), plus exact duplicates: no point may be missing from a query.
    #[test]
    fn axis_aligned_ties_are_all_found() {
        let mut pts = Vec::new();
        for j in 0..60 {
            for i in 0..60 {
                pts.push(DVec3::new(i as f64 * 0.5, j as f64 * 0.5, 25.55));
            }
        }
        for i in 0..500 {
            pts.push(DVec3::new(3.0, 4.0, i as f64 * 0.01));
        }
        for _ in 0..40 {
            pts.push(DVec3::new(1.0, 1.0, 25.55));
        }
        let mut dynamic = DynamicTree::new();
        for (i, p) in pts.iter().enumerate() {
            dynamic.add(*p, i as u32);
        }
        assert_eq!(dynamic.len(), pts.len());
        let fixed = StaticTree::new(&pts);
        let mut out = Vec::new();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for _ in 0..300 {
            let q =
                DVec3::new(rng.random(), rng.random(), rng.random()) * DVec3::new(30.0, 30.0, 26.0);
            let mut expect = brute(&pts, q, 2.0);
            expect.sort_unstable();
            for found in [
                {
                    dynamic.within(q, 2.0, &mut out);
                    out.clone()
                },
                {
                    fixed.within(q, 2.0, &mut out);
                    out.clone()
                },
            ] {
                let mut got: Vec<u32> = found.iter().map(|x| x.0).collect();
                assert!(
                    found.windows(2).all(|w| w[0].1 <= w[1].1),
                    "not nearest first"
                );
                got.sort_unstable();
                assert_eq!(got, expect);
            }
            let (_, d) = dynamic.nearest(q).unwrap();
            let best = pts
                .iter()
                .map(|p| p.distance_squared(q))
                .fold(f64::INFINITY, f64::min);
            assert!((d - best).abs() < 1e-9);
        }
    }
}
