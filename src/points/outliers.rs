//! Outlier removal for point sets: a point is dropped when the distance to its k-th nearest
//! neighbour is far above the set's typical one (globally) or its neighbours' (locally).
//!
//! Source: statistical outlier removal (Rusu, Marton, Blodow, Dolha, Beetz 2008, "Towards 3D
//! point cloud based object maps for household environments", Sec. 4) for the global test, and
//! the local outlier factor (Breunig, Kriegel, Ng, Sander 2000) simplified to one ratio of
//! k-distances for the local one. [`off_surface`] finds the points on no sheet of data at a
//! given scale (strands of flying pixels) and the near outliers off the plane of their
//! neighbours.

use glam::DVec3;
use rayon::prelude::*;

use super::normals::plane_normal;
use crate::spatial::StaticTree;

/// Neighbours whose distance measures a point's isolation.
pub const OUTLIER_NEIGHBORS: usize = 8;

/// A point is an outlier when its k-distance is more than this many times the median
/// k-distance of the reference set: a far outlier, wherever it is.
pub const GLOBAL_FACTOR: f64 = 6.0;

/// A point is an outlier when its k-distance is more than this many times the median
/// k-distance of its own k neighbours: a point off a surface that is denser than it. A surface
/// point where the sampling thins out (a grazing scan) has neighbours about as sparse as
/// itself; Gaussian noise of the order of the spacing moves the ratio by well under 2.
pub const LOCAL_FACTOR: f64 = 3.0;

/// Outlier tests against a fixed reference set (any units; the tests are scale-free).
pub struct OutlierFilter {
    tree: StaticTree,
    /// Each reference point's k-distance (to its k-th nearest other point).
    k_distance: Vec<f64>,
    /// `GLOBAL_FACTOR` times the median k-distance.
    global_cutoff: f64,
}

impl OutlierFilter {
    /// The filter of `reference`, a uniformly random subset of the point set (or all of it).
    /// With fewer than `OUTLIER_NEIGHBORS + 2` points nothing is an outlier.
    pub fn new(reference: &[DVec3]) -> Self {
        let tree = StaticTree::new(reference);
        let k_distance: Vec<f64> = reference
            .par_iter()
            .map_init(Vec::new, |found, &p| k_distance(&tree, p, found))
            .collect();
        let mut sorted: Vec<f64> = k_distance
            .iter()
            .copied()
            .filter(|d| d.is_finite())
            .collect();
        let global_cutoff = if reference.len() < OUTLIER_NEIGHBORS + 2 || sorted.is_empty() {
            f64::INFINITY
        } else {
            let mid = sorted.len() / 2;
            GLOBAL_FACTOR * *sorted.select_nth_unstable_by(mid, f64::total_cmp).1
        };
        OutlierFilter {
            tree,
            k_distance,
            global_cutoff,
        }
    }

    /// Whether `p` is an outlier of the reference set (a point of the set itself is compared
    /// with the others).
    pub fn is_outlier(&self, p: DVec3, found: &mut Vec<(u32, f64)>) -> bool {
        if !self.global_cutoff.is_finite() {
            return false;
        }
        let d = k_distance(&self.tree, p, found);
        if d > self.global_cutoff {
            return true;
        }
        let mut near: Vec<f64> = found
            .iter()
            .filter(|&&(_, d2)| d2 > 0.0)
            .map(|&(j, _)| self.k_distance[j as usize])
            .collect();
        if near.is_empty() {
            return false;
        }
        let mid = near.len() / 2;
        let local = *near.select_nth_unstable_by(mid, f64::total_cmp).1;
        d > LOCAL_FACTOR * local
    }

    /// Per item of `items` (positions by `position`), whether it is not an outlier (in parallel).
    fn keep_flags<T: Sync>(
        &self,
        items: &[T],
        position: &(impl Fn(&T) -> DVec3 + Sync),
    ) -> Vec<bool> {
        items
            .par_iter()
            .map_init(Vec::new, |found, t| !self.is_outlier(position(t), found))
            .collect()
    }

    /// Keeps the items of `items` (positions by `position`) that are not outliers, in order;
    /// returns how many were dropped. Deterministic.
    pub fn retain<T: Send + Sync>(
        &self,
        items: &mut Vec<T>,
        position: impl Fn(&T) -> DVec3 + Sync,
    ) -> usize {
        let keep = self.keep_flags(items, &position);
        let before = items.len();
        let mut i = 0;
        items.retain(|_| {
            i += 1;
            keep[i - 1]
        });
        before - items.len()
    }

    /// Keeps the first `want` items of `items` that are not outliers, in order (all of them when
    /// there are fewer), testing only as many as that takes; returns how many of those tested
    /// were dropped. Deterministic: the same as [`retain`](Self::retain) then truncating to
    /// `want`.
    pub fn retain_first<T: Send + Sync>(
        &self,
        items: &mut Vec<T>,
        want: usize,
        position: impl Fn(&T) -> DVec3 + Sync,
    ) -> usize {
        // items[..kept] are kept; items[kept..tested] were dropped.
        let (mut kept, mut tested, mut dropped) = (0, 0, 0);
        while kept < want && tested < items.len() {
            let need = want - kept;
            let chunk = (need + need / 8 + 64).min(items.len() - tested);
            let keep = self.keep_flags(&items[tested..tested + chunk], &position);
            for (j, k) in keep.into_iter().enumerate() {
                if k {
                    items.swap(kept, tested + j);
                    kept += 1;
                } else {
                    dropped += 1;
                }
            }
            tested += chunk;
        }
        items.truncate(kept.min(want));
        dropped
    }
}

/// Neighbours within the radius that put a point on a sheet (see [`off_surface`]).
pub const SHEET_NEIGHBORS: usize = 6;

/// The sheet test of [`off_surface`] on a point's nearest neighbours `found` (itself included,
/// nearest first): whether fewer than `SHEET_NEIGHBORS` other points lie within `radius` of it,
/// so that the point is on no two-dimensional sheet of data at that scale. A point inside a
/// hexagonal lattice of spacing up to `radius` has six neighbours within it; a point
/// with fewer lies on a strand or alone, as the flying pixels a range scanner leaves along depth
/// discontinuities (strands along the view rays, a few spacings apart), which a surface through
/// them would bridge.
fn is_off_sheet(found: &[(u32, f64)], radius: f64) -> bool {
    // The point itself is among them (distance 0), and so are exact duplicates.
    let near = found
        .iter()
        .filter(|&&(_, d2)| d2 <= radius * radius)
        .count();
    near < SHEET_NEIGHBORS + 1
}

/// Neighbours whose least-squares plane a point is compared with (see [`off_surface`]).
pub const PLANE_NEIGHBORS: usize = 16;

/// A point farther from its neighbours' plane than this many times their own RMS distance to
/// it is off the surface (see [`off_surface`]).
pub const PLANE_FACTOR: f64 = 4.0;

/// The sheet test's radius is never below this many times the data's median distance from a
/// point to its sixth nearest neighbour (see [`off_surface`]): data sparser than the radius asks
/// for (5,000 points of a model meshed at 4,000) is a sheet at its own spacing, not strands.
/// For uniformly random points of density ρ the median m₆ has ρπm₆² ≈ 5.67 (the median of a
/// Gamma(6, 1) variable), so a disc of radius 1.9 m₆ holds about 20.5 of them on average, and
/// fewer than `SHEET_NEIGHBORS` with probability about 5e-5. A dense support (4 points per
/// sigma_p²) has m₆ ≈ 0.67 sigma_p, and the radius the point pipeline asks for (3 sigma_p)
/// stands. Flying pixels, a few in a thousand, do not move the median.
pub const SHEET_RADIUS_SIXTH_NEIGHBORS: f64 = 1.9;

/// Points whose sixth-neighbour distance estimates the data's median one (every k-th point,
/// deterministic).
const SPACING_PROBES: usize = 4096;

/// `radius`, widened to `SHEET_RADIUS_SIXTH_NEIGHBORS` times the median sixth-neighbour
/// distance of `positions` (estimated on at most `SPACING_PROBES` of them) where that is wider.
fn sheet_radius_for(tree: &StaticTree, positions: &[DVec3], radius: f64) -> f64 {
    if positions.len() <= SHEET_NEIGHBORS {
        return radius;
    }
    let step = positions.len().div_ceil(SPACING_PROBES);
    let mut found = Vec::new();
    let mut sixth: Vec<f64> = positions
        .iter()
        .step_by(step)
        .map(|&p| {
            tree.nearest_n(p, SHEET_NEIGHBORS + 1, &mut found);
            found.last().map_or(0.0, |&(_, d2)| d2.sqrt())
        })
        .collect();
    let mid = sixth.len() / 2;
    let (_, median, _) = sixth.select_nth_unstable_by(mid, f64::total_cmp);
    radius.max(SHEET_RADIUS_SIXTH_NEIGHBORS * *median)
}

/// For each of `positions`, whether it is off the surface its neighbours describe (the plane
/// test, `is_off_plane`) or, with `sheet_radius`, on no sheet of data at that radius (the sheet
/// test, `is_off_sheet`; the radius is widened to the data's own spacing where that is wider,
/// see [`SHEET_RADIUS_SIXTH_NEIGHBORS`]): the two tests on one kd-tree and one neighbour query
/// per point. Any units; deterministic (parallel).
pub fn off_surface(positions: &[DVec3], sheet_radius: Option<f64>) -> Vec<bool> {
    let tree = StaticTree::new(positions);
    let sheet_radius = sheet_radius.map(|r| sheet_radius_for(&tree, positions, r));
    let k = (PLANE_NEIGHBORS + 1).max(SHEET_NEIGHBORS + 1);
    positions
        .par_iter()
        .enumerate()
        .map_init(
            || (Vec::new(), Vec::new()),
            |(found, near), (i, &p)| {
                tree.nearest_n(p, k, found);
                sheet_radius.is_some_and(|r| is_off_sheet(found, r))
                    || (positions.len() > PLANE_NEIGHBORS
                        && is_off_plane(positions, i, found, near))
            },
        )
        .collect()
}

/// The plane test of [`off_surface`] for point `i` on its nearest neighbours `found` (itself
/// among them; `near` is a buffer): whether it lies off the surface its `PLANE_NEIGHBORS`
/// nearest others describe, farther from their least-squares plane than `PLANE_FACTOR` times
/// their RMS distance to it. Of a noisy surface's points this drops a few in a thousand (0.3% of
/// a sphere's with noise at a tenth of the spacing: a random thinning); curvature and a crease
/// raise the neighbours' RMS as much as the point's offset, so they pass. A near outlier (a few
/// noise widths off the surface, too close for the k-distance tests, which a surface through it
/// would bulge to) does not.
fn is_off_plane(
    positions: &[DVec3],
    i: usize,
    found: &[(u32, f64)],
    near: &mut Vec<DVec3>,
) -> bool {
    near.clear();
    near.extend(
        found
            .iter()
            .filter(|&&(j, _)| j as usize != i)
            .take(PLANE_NEIGHBORS)
            .map(|&(j, _)| positions[j as usize]),
    );
    let c = near.iter().sum::<DVec3>() / near.len() as f64;
    let n = plane_normal(near);
    if n == DVec3::ZERO {
        return false;
    }
    let ms = near.iter().map(|q| (*q - c).dot(n).powi(2)).sum::<f64>() / near.len() as f64;
    // A floor for neighbours exactly on a plane: a millionth of their reach.
    let reach = found.last().map_or(0.0, |&(_, d2)| d2.sqrt());
    let rms = ms.sqrt().max(1e-6 * reach);
    (positions[i] - c).dot(n).abs() > PLANE_FACTOR * rms
}

/// The distance from `p` to its `OUTLIER_NEIGHBORS`-th nearest point of `tree` other than
/// itself (points at distance 0 are skipped); infinity when there are not that many. `found`
/// is left holding the neighbours.
fn k_distance(tree: &StaticTree, p: DVec3, found: &mut Vec<(u32, f64)>) -> f64 {
    tree.nearest_n(p, OUTLIER_NEIGHBORS + 1, found);
    if found.first().is_some_and(|&(_, d2)| d2 == 0.0) {
        found.remove(0);
    } else {
        found.truncate(OUTLIER_NEIGHBORS);
    }
    if found.len() < OUTLIER_NEIGHBORS {
        return f64::INFINITY;
    }
    found[OUTLIER_NEIGHBORS - 1].1.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Points on the unit sphere, with `noise` Gaussian-ish jitter (sum of uniforms).
    fn sphere(n: usize, noise: f64, rng: &mut ChaCha8Rng) -> Vec<DVec3> {
        (0..n)
            .map(|_| {
                let z: f64 = rng.random_range(-1.0..=1.0);
                let phi: f64 = rng.random_range(0.0..std::f64::consts::TAU);
                let s = (1.0 - z * z).sqrt();
                let r = 1.0 + noise * (0..4).map(|_| rng.random_range(-1.0..1.0)).sum::<f64>();
                DVec3::new(s * phi.cos(), s * phi.sin(), z) * r
            })
            .collect()
    }

    /// `n` points uniform in the cube [-1.5, 1.5]³ around the unit sphere, each at least 0.2 off
    /// it.
    fn cube_outliers(n: usize, rng: &mut ChaCha8Rng) -> Vec<DVec3> {
        let mut out = Vec::with_capacity(n);
        while out.len() < n {
            let p = DVec3::new(
                rng.random_range(-1.5..1.5),
                rng.random_range(-1.5..1.5),
                rng.random_range(-1.5..1.5),
            );
            if (p.length() - 1.0).abs() > 0.2 {
                out.push(p);
            }
        }
        out
    }

    #[test]
    fn far_points_go_and_the_surface_stays() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut points = sphere(20_000, 0.005, &mut rng);
        let surface = points.len();
        // 1% outliers, at least 0.2 off the sphere (10 spacings).
        points.extend(cube_outliers(200, &mut rng));
        let filter = OutlierFilter::new(&points);
        let mut kept: Vec<(usize, DVec3)> = points.iter().copied().enumerate().collect();
        let dropped = filter.retain(&mut kept, |&(_, p)| p);
        let surface_dropped = surface - kept.iter().filter(|(i, _)| *i < surface).count();
        let outliers_kept = kept.iter().filter(|(i, _)| *i >= surface).count();
        assert_eq!(outliers_kept, 0, "outliers kept");
        assert!(
            surface_dropped <= surface / 1000,
            "{surface_dropped} surface points dropped"
        );
        assert_eq!(dropped, surface_dropped + 200);
    }

    #[test]
    fn retain_first_keeps_what_retain_keeps_up_to_the_count() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut points = sphere(5_000, 0.0, &mut rng);
        // Outliers spread through the list (every 50th item).
        for (k, p) in cube_outliers(100, &mut rng).into_iter().enumerate() {
            points.insert(k * 50, p);
        }
        let filter = OutlierFilter::new(&points);
        let mut all: Vec<(usize, DVec3)> = points.iter().copied().enumerate().collect();
        filter.retain(&mut all, |&(_, p)| p);
        assert!(all.len() < points.len() - 90, "{} kept", all.len());
        for want in [0, 1, 1_000, 3_000, all.len(), points.len()] {
            let mut first: Vec<(usize, DVec3)> = points.iter().copied().enumerate().collect();
            let dropped = filter.retain_first(&mut first, want, |&(_, p)| p);
            let expected = &all[..want.min(all.len())];
            assert_eq!(first.len(), expected.len(), "want {want}");
            assert!(
                first.iter().zip(expected).all(|(a, b)| a.0 == b.0),
                "want {want}"
            );
            // The dropped ones among those tested: at least those before the last kept.
            let last = first.last().map_or(0, |f| f.0 + 1);
            assert!(dropped >= (0..last).filter(|i| !all.iter().any(|a| a.0 == *i)).count());
        }
    }

    #[test]
    fn a_sparser_part_of_the_surface_is_not_an_outlier() {
        // Half the sphere sampled 16 times sparser (spacing 4x): the local test compares with
        // neighbours as sparse, the global one allows up to GLOBAL_FACTOR.
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let points: Vec<DVec3> = sphere(40_000, 0.0, &mut rng)
            .into_iter()
            .enumerate()
            .filter(|(i, p)| p.z > 0.0 || i % 16 == 0)
            .map(|(_, p)| p)
            .collect();
        let filter = OutlierFilter::new(&points);
        let mut kept = points.clone();
        let dropped = filter.retain(&mut kept, |&p| p);
        assert!(dropped <= points.len() / 500, "{dropped} dropped");
    }

    #[test]
    fn tiny_sets_have_no_outliers() {
        let points = vec![DVec3::ZERO, DVec3::X, DVec3::splat(100.0)];
        let filter = OutlierFilter::new(&points);
        let mut found = Vec::new();
        assert!(!filter.is_outlier(DVec3::splat(1e6), &mut found));
    }

    #[test]
    fn sparse_random_points_are_a_sheet_at_their_own_spacing() {
        // 2,000 uniformly random points of a 100 x 100 square: their sixth neighbour is about 3
        // away, so almost none has six others within the asked radius of 1. The radius widens
        // to their spacing and the interior points are on the sheet; a strand of points 6
        // apart leaving the square's centre along its normal is still off it.
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        let mut points: Vec<DVec3> = (0..2000)
            .map(|_| {
                DVec3::new(
                    rng.random_range(0.0..100.0),
                    rng.random_range(0.0..100.0),
                    0.0,
                )
            })
            .collect();
        let strand: Vec<DVec3> = (1..=8)
            .map(|k| DVec3::new(50.0, 50.0, 6.0 * k as f64))
            .collect();
        points.extend_from_slice(&strand);
        let off = off_surface(&points, Some(1.0));
        let interior = |p: &DVec3| p.x.min(p.y).min(100.0 - p.x).min(100.0 - p.y) > 8.0;
        let off_interior = points[..2000]
            .iter()
            .zip(&off)
            .filter(|(p, &o)| interior(p) && o)
            .count();
        assert_eq!(off_interior, 0, "interior points off the sheet");
        assert!(
            off[2000..].iter().all(|&o| o),
            "a strand point is on a sheet"
        );
    }

    #[test]
    fn a_strand_off_a_plane_is_off_sheet_and_the_plane_is_not() {
        // A 30 x 30 grid of spacing 1 (corners and edges included) and a strand of points 2
        // apart leaving it along its normal, as flying pixels do.
        let mut points: Vec<DVec3> = (0..900)
            .map(|i| DVec3::new((i % 30) as f64, (i / 30) as f64, 0.0))
            .collect();
        let strand: Vec<DVec3> = (1..=10)
            .map(|k| DVec3::new(15.0, 15.0, 2.0 * k as f64))
            .collect();
        points.extend_from_slice(&strand);
        let off = off_surface(&points, Some(3.0));
        assert!(
            off[..900].iter().all(|&o| !o),
            "a grid point is off the sheet"
        );
        // The strand's points farther than the radius from the plane see at most two others.
        for (k, &o) in off[900..].iter().enumerate() {
            if strand[k].z > 3.0 {
                assert!(o, "strand point {k} is on a sheet");
            }
        }
        // Duplicates are neighbours: a point repeated seven times is on a sheet of itself.
        let dup = vec![DVec3::ONE; 7];
        assert!(off_surface(&dup, Some(0.5)).iter().all(|&o| !o));
        assert!(off_surface(&dup[..6], Some(0.5)).iter().all(|&o| o));
    }

    #[test]
    fn points_off_their_neighbours_plane_are_found_and_noisy_curved_ones_kept() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        // A noisy unit sphere (noise about 0.003, the spacing about 0.02)...
        let mut points = sphere(30_000, 0.002, &mut rng);
        // ... and 30 near outliers, 0.05 outside it: a few spacings, many noise widths.
        let far: Vec<DVec3> = sphere(30, 0.0, &mut rng)
            .into_iter()
            .map(|p| p * 1.05)
            .collect();
        points.extend_from_slice(&far);
        let off = off_surface(&points, None);
        let kept_wrongly = off[30_000..].iter().filter(|&&o| !o).count();
        assert!(kept_wrongly <= 1, "{kept_wrongly} of 30 near outliers kept");
        let dropped = off[..30_000].iter().filter(|&&o| o).count();
        assert!(dropped <= 300, "{dropped} of 30000 sphere points dropped");
        // A cube's corner and edges (creases) are on their neighbours' planes as well as the
        // neighbours are.
        let mut cube = Vec::new();
        for i in 0..40 {
            for j in 0..40 {
                let (u, v) = (i as f64 / 39.0, j as f64 / 39.0);
                cube.extend([
                    DVec3::new(u, v, 0.0),
                    DVec3::new(u, 0.0, v),
                    DVec3::new(0.0, u, v),
                ]);
            }
        }
        let off = off_surface(&cube, None);
        assert_eq!(off.iter().filter(|&&o| o).count(), 0);
    }
}
