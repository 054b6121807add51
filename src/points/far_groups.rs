//! Far groups of a point set: points (one, a few, or a small cluster) far from the bulk of
//! the data, which would set its bounding box and so the scale of everything (a stray `0 0 0`,
//! five of them, or a 17-point cluster near the origin of a scan at UTM coordinates).
//!
//! The points are grouped by single linkage on a grid whose cells are [`FAR_GAP`] of the
//! bounding box's diagonal: points in the same or in neighbouring cells are joined, so groups
//! closer than one cell are one group and groups in different groups are more than one cell
//! apart. Groups holding less than [`FAR_GROUP_SHARE`] of the points are left out, the box
//! shrinks to what is left, and the grouping is repeated at the smaller cell until nothing
//! more is left out (a far group inflates the first box, hiding a second one nearer in).

use std::collections::HashMap;

use glam::DVec3;

use crate::disjoint_sets::Dsu;
use crate::mesh::Aabb;

/// The grid's cell, as a share of the bounding box's diagonal (of the points kept so far): a
/// group more than this far from the rest is a group of its own.
pub const FAR_GAP: f64 = 0.25;

/// A group holding less than this share of the points is far and left out (when it is not
/// the only group). A part of a scene with 1% of the points or more is kept.
pub const FAR_GROUP_SHARE: f64 = 0.01;

/// At most this many rounds of grouping and shrinking the box.
const MAX_ROUNDS: usize = 8;

/// What is kept of a point set once its far groups are left out: the grid cells (and their
/// neighbours) of the groups kept at the last round that left something out.
#[derive(Debug, Clone)]
pub struct FarGroups {
    origin: DVec3,
    cell: f64,
    /// The kept groups' cells and their 26 neighbours.
    cells: std::collections::HashSet<[i64; 3]>,
    /// Far groups left out, over all rounds.
    pub groups_left_out: usize,
}

impl FarGroups {
    /// Whether `p` belongs with the kept points (it lies in, or next to, a cell of a kept
    /// group).
    pub fn contains(&self, p: DVec3) -> bool {
        let c = ((p - self.origin) / self.cell).floor();
        // Far outside the grid: not kept (and no overflow converting to integers).
        if !c.is_finite() || c.abs().max_element() > 1e15 {
            return false;
        }
        self.cells.contains(&[c.x as i64, c.y as i64, c.z as i64])
    }
}

/// The groups of `points` at cell size `cell` (single linkage over the 26 neighbouring cells):
/// each point's group id and the number of groups. Deterministic.
fn group(points: &[DVec3], origin: DVec3, cell: f64) -> (Vec<usize>, usize) {
    let key = |p: DVec3| {
        let c = ((p - origin) / cell).floor();
        [c.x as i64, c.y as i64, c.z as i64]
    };
    let mut ids: HashMap<[i64; 3], usize> = HashMap::new();
    let point_cell: Vec<usize> = points
        .iter()
        .map(|&p| {
            let n = ids.len();
            *ids.entry(key(p)).or_insert(n)
        })
        .collect();
    let mut dsu = Dsu::new(ids.len());
    for (&[x, y, z], &i) in &ids {
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(&j) = ids.get(&[x + dx, y + dy, z + dz]) {
                        dsu.union(i, j, false);
                    }
                }
            }
        }
    }
    // Group ids in the order of the points' first appearance (deterministic).
    let mut root_id: HashMap<usize, usize> = HashMap::new();
    let groups: Vec<usize> = point_cell
        .iter()
        .map(|&c| {
            let root = dsu.find(c).0;
            let n = root_id.len();
            *root_id.entry(root).or_insert(n)
        })
        .collect();
    (groups, root_id.len())
}

/// The far groups of `points` (a uniformly random subset of a point set, or all of it, with
/// the points that decide its bounding box; any units, no duplicates needed): `None` when
/// none is left out. Groups holding less than [`FAR_GROUP_SHARE`] of `points` are left out
/// when they are more than [`FAR_GAP`] of the box's diagonal from the rest (see the module's
/// documentation). Deterministic.
pub fn far_groups(points: &[DVec3]) -> Option<FarGroups> {
    let mut kept: Vec<DVec3> = points.iter().copied().filter(|p| p.is_finite()).collect();
    let mut result: Option<FarGroups> = None;
    for _ in 0..MAX_ROUNDS {
        let bbox = Aabb::of(&kept)?;
        let diagonal = bbox.diagonal();
        if !(diagonal > 0.0 && diagonal.is_finite()) {
            break;
        }
        let cell = FAR_GAP * diagonal;
        let (groups, count) = group(&kept, bbox.min, cell);
        if count < 2 {
            break;
        }
        let mut sizes = vec![0usize; count];
        for &g in &groups {
            sizes[g] += 1;
        }
        let small = |g: usize| (sizes[g] as f64) < FAR_GROUP_SHARE * kept.len() as f64;
        let left_out = (0..count).filter(|&g| small(g)).count();
        if left_out == 0 || left_out == count {
            break;
        }
        kept = kept
            .iter()
            .zip(&groups)
            .filter(|&(_, &g)| !small(g))
            .map(|(&p, _)| p)
            .collect();
        let mut cells = std::collections::HashSet::new();
        for &p in &kept {
            let c = ((p - bbox.min) / cell).floor();
            let [x, y, z] = [c.x as i64, c.y as i64, c.z as i64];
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        cells.insert([x + dx, y + dy, z + dz]);
                    }
                }
            }
        }
        let before = result.as_ref().map_or(0, |r| r.groups_left_out);
        result = Some(FarGroups {
            origin: bbox.min,
            cell,
            cells,
            groups_left_out: before + left_out,
        });
    }
    result
}

/// The groups of `points` once `far` (what [`far_groups`] gave for them) is left out: how
/// many, and each one's bounding box, largest group first. For telling apart parts of a scene
/// far from each other compared with their sizes (two objects 10^6 apart, each 10 across).
pub fn kept_groups(points: &[DVec3], far: Option<&FarGroups>) -> Vec<(usize, Aabb)> {
    let kept: Vec<DVec3> = points
        .iter()
        .copied()
        .filter(|&p| p.is_finite() && far.is_none_or(|f| f.contains(p)))
        .collect();
    let Some(bbox) = Aabb::of(&kept) else {
        return Vec::new();
    };
    let diagonal = bbox.diagonal();
    if !(diagonal > 0.0 && diagonal.is_finite()) {
        return vec![(kept.len(), bbox)];
    }
    let (groups, count) = group(&kept, bbox.min, FAR_GAP * diagonal);
    let mut out: Vec<(usize, Aabb)> = (0..count)
        .map(|g| {
            let members: Vec<DVec3> = kept
                .iter()
                .zip(&groups)
                .filter(|&(_, &h)| h == g)
                .map(|(&p, _)| p)
                .collect();
            (
                members.len(),
                Aabb::of(&members).expect("a group has points"),
            )
        })
        .collect();
    out.sort_by_key(|g| std::cmp::Reverse(g.0));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// `n` points on the sphere of `radius` around `center`.
    fn sphere(n: usize, center: DVec3, radius: f64, rng: &mut ChaCha8Rng) -> Vec<DVec3> {
        (0..n)
            .map(|_| {
                let z: f64 = rng.random_range(-1.0..=1.0);
                let phi: f64 = rng.random_range(0.0..std::f64::consts::TAU);
                let s = (1.0 - z * z).sqrt();
                center + radius * DVec3::new(s * phi.cos(), s * phi.sin(), z)
            })
            .collect()
    }

    const UTM: DVec3 = DVec3::new(5e5, 4e6, 100.0);

    #[test]
    fn a_scan_alone_has_no_far_group() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        assert!(far_groups(&sphere(3000, UTM, 5.0, &mut rng)).is_none());
    }

    #[test]
    fn one_stray_point_and_a_small_far_cluster_are_left_out() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let bulk = sphere(5000, UTM, 5.0, &mut rng);
        // A stray point; a 17-point cluster of radius 0.01 at the origin; both, with the
        // cluster nearer in (hidden by the stray point's box at first).
        let stray = vec![DVec3::ZERO];
        let cluster = sphere(17, DVec3::ZERO, 0.01, &mut rng);
        let near = sphere(20, UTM + DVec3::new(300.0, 0.0, 0.0), 0.5, &mut rng);
        for far in [stray.clone(), cluster.clone(), [stray, near].concat()] {
            let set = [bulk.clone(), far.clone()].concat();
            let f = far_groups(&set).expect("a far group");
            assert!(bulk.iter().all(|&p| f.contains(p)), "a bulk point left out");
            assert!(far.iter().all(|&p| !f.contains(p)), "a far point kept");
        }
    }

    #[test]
    fn parts_of_comparable_size_are_kept_however_far() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        // Two spheres 10^6 apart, and a third part with 2% of the points.
        let a = sphere(3000, DVec3::ZERO, 5.0, &mut rng);
        let b = sphere(3000, DVec3::new(1e6, 0.0, 0.0), 5.0, &mut rng);
        let c = sphere(130, DVec3::new(0.0, 1e3, 0.0), 1.0, &mut rng);
        let set = [a, b, c].concat();
        assert!(far_groups(&set).is_none());
        let groups = kept_groups(&set, None);
        assert_eq!(groups.len(), 2, "{groups:?}");
        assert_eq!(groups[0].0 + groups[1].0, set.len());
    }
}
