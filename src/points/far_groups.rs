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

/// Which points of an input a run kept: not in a far group, and in a part when the points were
/// parts far apart meshed each on its own. For measuring the output's distance to them.
#[derive(Debug, Clone, Default)]
pub struct KeptPoints {
    parts: Option<std::sync::Arc<SeparateParts>>,
    /// Each part's far groups (one entry when there are no parts).
    far: Vec<Option<FarGroups>>,
    /// The parts left out whole (none kept; empty when there are no parts).
    left_out: Vec<bool>,
}

impl KeptPoints {
    /// The points of a run over the whole input, `far` left out.
    pub fn whole(far: Option<FarGroups>) -> Self {
        KeptPoints {
            parts: None,
            far: vec![far],
            left_out: Vec::new(),
        }
    }

    /// The points in `parts`, each part's own far groups (`far`, in the parts' order) left out,
    /// and the parts `left_out` whole.
    pub fn in_parts(
        parts: std::sync::Arc<SeparateParts>,
        far: Vec<Option<FarGroups>>,
        left_out: Vec<bool>,
    ) -> Self {
        KeptPoints {
            parts: Some(parts),
            far,
            left_out,
        }
    }

    /// The far groups of a run over one scene (no parts).
    pub(crate) fn far_of_whole(&self) -> Option<FarGroups> {
        match self.parts {
            None => self.far.first().cloned().flatten(),
            Some(_) => None,
        }
    }

    /// Whether `p` was kept.
    pub fn contains(&self, p: DVec3) -> bool {
        let k = match &self.parts {
            Some(parts) => match parts.part_of(p) {
                Some(k) => k,
                None => return false,
            },
            None => 0,
        };
        if self.left_out.get(k).copied().unwrap_or(false) {
            return false;
        }
        self.far
            .get(k)
            .and_then(Option::as_ref)
            .is_none_or(|f| f.contains(p))
    }
}

/// Parts of a point set far apart are meshed each on its own when some part's diagonal is
/// under this share of the whole's: one scale cannot hold them all (a sample spacing of a
/// part's size is below the precision of the whole's tolerances). Two objects 10^6 apart, each
/// 10 across, are 1e-5.
pub const SEPARATE_PARTS_RATIO: f64 = 1e-3;

/// The grid's cell when parts far apart are told apart, as a share of the whole's diagonal:
/// single linkage over neighbouring cells joins points up to 2√3 cells apart, so at
/// [`FAR_GAP`] three parts evenly spaced along a line were one group (the middle one's points
/// straddle a cell boundary next to the first's); parts each within
/// [`SEPARATE_PARTS_RATIO`] of the diagonal lie within two cells of this size, and parts more
/// than 3.5% of the diagonal apart are told apart.
pub const SEPARATE_PARTS_CELL: f64 = 0.01;

/// The fewest points of the grouped subset a part far apart holds: fewer, and the groups are
/// the isolated points of a sparse set, not parts.
pub const MIN_PART_POINTS: usize = 8;

/// One part of [`SeparateParts`], as the grouped subset saw it (model units).
#[derive(Debug, Clone)]
pub struct PartEstimate {
    /// Points of the grouped subset in the part.
    pub subset_points: usize,
    /// The bounding box of those points.
    pub bbox: Aabb,
    /// A guess of the part's surface area (model units²): the occupied cells of a grid over the
    /// subset's points, as the sigma_p search starts from; it shares the count out.
    pub area: f64,
}

/// The parts of a point set far apart compared with their own sizes (some part's diagonal
/// under [`SEPARATE_PARTS_RATIO`] of the whole's: two objects 10^6 apart, each 10 across), found
/// on a random subset of its points with the far groups left out: which part a point is in.
#[derive(Debug)]
pub struct SeparateParts {
    origin: DVec3,
    cell: f64,
    /// Each part's cells and their 26 neighbours, with the part's index.
    cells: HashMap<[i64; 3], usize>,
    /// The parts, the largest (most subset points) first.
    pub parts: Vec<PartEstimate>,
    /// The box of all the parts (model units).
    pub whole: Aabb,
}

impl SeparateParts {
    /// The part `p` is in (in, or next to, a cell of the part's points), `None` for a point in
    /// none (a far group's).
    pub fn part_of(&self, p: DVec3) -> Option<usize> {
        let c = ((p - self.origin) / self.cell).floor();
        if !c.is_finite() || c.abs().max_element() > 1e15 {
            return None;
        }
        self.cells
            .get(&[c.x as i64, c.y as i64, c.z as i64])
            .copied()
    }

    /// How many parts.
    pub fn len(&self) -> usize {
        self.parts.len()
    }

    /// Never: there are two parts or more.
    pub fn is_empty(&self) -> bool {
        self.parts.is_empty()
    }

    /// Why the parts cannot be meshed together, in one line: for the commands that do not mesh
    /// each part on its own.
    pub fn refusal(&self) -> String {
        let largest = self
            .parts
            .iter()
            .map(|g| g.bbox.diagonal())
            .fold(0.0f64, f64::max);
        format!(
            "the points form {} parts far apart ({} across in all, the largest part {} across): one scale cannot hold them; give each part on its own",
            self.len(),
            short(self.whole.diagonal()),
            short(largest),
        )
    }
}

/// A length for a message: 4 significant digits, in scientific notation when large or small.
fn short(x: f64) -> String {
    if x != 0.0 && !(1e-3..1e5).contains(&x.abs()) {
        format!("{x:.3e}")
    } else {
        format!("{x:.4}")
    }
}

/// The parts of `points` (the subset [`far_groups`] grouped; model units) far apart compared
/// with their sizes, once `far` is left out; `None` when the kept points are one part or the
/// parts are near enough to share one scale. Deterministic.
pub fn separate_parts(points: &[DVec3], far: Option<&FarGroups>) -> Option<SeparateParts> {
    let kept: Vec<DVec3> = points
        .iter()
        .copied()
        .filter(|&p| p.is_finite() && far.is_none_or(|f| f.contains(p)))
        .collect();
    let bbox = Aabb::of(&kept)?;
    let whole_diagonal = bbox.diagonal();
    if !(whole_diagonal > 0.0 && whole_diagonal.is_finite()) {
        return None;
    }
    let cell = SEPARATE_PARTS_CELL * whole_diagonal;
    let (groups, count) = group(&kept, bbox.min, cell);
    if count < 2 {
        return None;
    }
    let mut members: Vec<Vec<DVec3>> = vec![Vec::new(); count];
    for (&p, &g) in kept.iter().zip(&groups) {
        members[g].push(p);
    }
    // Largest first (ties in the order of first appearance).
    members.sort_by_key(|m| std::cmp::Reverse(m.len()));
    let boxes: Vec<Aabb> = members
        .iter()
        .map(|m| Aabb::of(m).expect("a group has points"))
        .collect();
    // One scale holds the parts when each is large enough for it; one part below the share is
    // lost at the whole's scale (a sphere 2 across beside one 2000 across, 10^6 away, took one
    // sample and was dropped), so then each part is meshed on its own.
    let smallest = boxes
        .iter()
        .map(Aabb::diagonal)
        .fold(f64::INFINITY, f64::min);
    if smallest >= SEPARATE_PARTS_RATIO * whole_diagonal {
        return None;
    }
    // A part holds a surface's points: on the fine grid, isolated points of a sparse set (200
    // points on a sphere) are groups of one, and are not parts.
    if members.iter().any(|m| m.len() < MIN_PART_POINTS) {
        return None;
    }
    let mut cells = HashMap::new();
    for (k, m) in members.iter().enumerate() {
        for &p in m {
            let c = ((p - bbox.min) / cell).floor();
            let [x, y, z] = [c.x as i64, c.y as i64, c.z as i64];
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        // A cell next to two parts goes to the larger.
                        cells.entry([x + dx, y + dy, z + dz]).or_insert(k);
                    }
                }
            }
        }
    }
    let parts = members
        .iter()
        .zip(boxes)
        .map(|(m, bbox)| PartEstimate {
            subset_points: m.len(),
            area: area_guess(m, &bbox),
            bbox,
        })
        .collect();
    Some(SeparateParts {
        origin: bbox.min,
        cell,
        cells,
        parts,
        whole: bbox,
    })
}

/// [`surface_area_guess`](super::area_guess::surface_area_guess) of `points` (model units,
/// within `bbox`) in the part's own bbox-100 frame, back in model units².
fn area_guess(points: &[DVec3], bbox: &Aabb) -> f64 {
    let side = bbox.longest_side();
    if !(side > 0.0 && side.is_finite()) {
        return 0.0;
    }
    let scale = 100.0 / side;
    let scaled: Vec<super::stream::Point> = points
        .iter()
        .map(|&p| super::stream::Point {
            position: (p - bbox.min) * scale,
            normal: DVec3::ZERO,
        })
        .collect();
    super::area_guess::surface_area_guess(&scaled) / (scale * scale)
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
    fn three_parts_far_apart_are_three_parts() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let set: Vec<DVec3> = (0..3)
            .flat_map(|k| sphere(1000, DVec3::new(k as f64 * 1e6, 0.0, 0.0), 1.0, &mut rng))
            .collect();
        assert!(far_groups(&set).is_none());
        let parts = separate_parts(&set, None).expect("three parts far apart");
        assert_eq!(parts.len(), 3, "{parts:?}");
    }

    #[test]
    fn parts_of_comparable_size_are_kept_however_far() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        // Two spheres 10^6 apart, and a third part with 2% of the points 2·10^3 from the first.
        let a = sphere(3000, DVec3::ZERO, 5.0, &mut rng);
        let b = sphere(3000, DVec3::new(1e6, 0.0, 0.0), 5.0, &mut rng);
        let c = sphere(130, DVec3::new(0.0, 2e3, 0.0), 1.0, &mut rng);
        let set = [a.clone(), b, c].concat();
        assert!(far_groups(&set).is_none());
        // Two groups 10^6 apart: the first sphere with the third (2·10^3 across, 2 thousandths
        // of the whole) and the second sphere (10^-5 of the whole, under the share: at one
        // scale a part that small may take no sample), so each group is meshed on its own, and
        // the third sphere stays with the first.
        let groups = separate_parts(&set, None).expect("two groups");
        assert_eq!(groups.len(), 2, "{groups:?}");
        assert_eq!(groups.parts[0].subset_points, 3130);
        assert_eq!(groups.parts[1].subset_points, 3000);
        // Without the third, two parts each 10^-5 of the whole: separate, every point in one.
        let two = [a, sphere(3000, DVec3::new(1e6, 0.0, 0.0), 5.0, &mut rng)].concat();
        let parts = separate_parts(&two, None).expect("parts far apart");
        assert_eq!(parts.len(), 2, "{parts:?}");
        assert_eq!(
            parts.parts[0].subset_points + parts.parts[1].subset_points,
            two.len()
        );
        // Issue 76 (R11): the refusal reads as one sentence (it had a run of spaces).
        let refusal = parts.refusal();
        assert!(
            refusal.starts_with("the points form 2 parts far apart"),
            "{refusal}"
        );
        assert!(!refusal.contains("  "), "{refusal:?}");
    }

    #[test]
    fn parts_far_apart_are_told_apart_with_their_share() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        // A sphere of radius 5 and one of radius 10, 10^6 apart, and a stray point more than a
        // grid cell (a quarter of the diagonal) from both.
        let a = sphere(3000, DVec3::ZERO, 5.0, &mut rng);
        let b = sphere(3000, DVec3::new(1e6, 0.0, 0.0), 10.0, &mut rng);
        let stray = DVec3::new(5e5, 1e6, 0.0);
        let set = [a.clone(), b.clone(), vec![stray]].concat();
        let far = far_groups(&set);
        let parts = separate_parts(&set, far.as_ref()).expect("two parts far apart");
        assert_eq!(parts.len(), 2);
        let (ka, kb) = (parts.part_of(a[0]).unwrap(), parts.part_of(b[0]).unwrap());
        assert_ne!(ka, kb);
        assert!(a.iter().all(|&p| parts.part_of(p) == Some(ka)));
        assert!(b.iter().all(|&p| parts.part_of(p) == Some(kb)));
        assert!(far.is_some_and(|f| !f.contains(stray)));
        assert_eq!(parts.part_of(stray), None);
        // The larger sphere has 4 times the area: its guess is about 4 times the other's.
        let ratio = parts.parts[kb].area / parts.parts[ka].area;
        assert!((2.5..6.0).contains(&ratio), "area ratio {ratio}");
        // Parts near enough to share a scale are not separate.
        let near = [a, sphere(3000, DVec3::new(100.0, 0.0, 0.0), 5.0, &mut rng)].concat();
        assert!(separate_parts(&near, None).is_none());
    }
}
