//! Morton (Z-order) codes of points in 3D. Sorting points by their code visits them along a
//! Z-curve, so neighbours in the order are mostly neighbours in space: the linear scan's chunks
//! and the distance queries of the report run in this order to keep the kd-tree and the BVH in
//! cache.

use glam::DVec3;

/// Bits per coordinate of [`morton_code`]: 3 × 21 = 63 bits of the code.
pub const MORTON_BITS: u32 = 21;

/// The largest coordinate [`morton_code`] distinguishes: 2^21 − 1.
pub const MORTON_MAX: f64 = ((1u64 << MORTON_BITS) - 1) as f64;

/// The Morton code of `q`, a point already scaled to grid units in `[0, 2^21)`: the integer parts
/// of x, y and z (clamped to `[0, 2^21 − 1]`; NaN counts as 0) with their bits interleaved, x in
/// the lowest bit.
pub fn morton_code(q: DVec3) -> u64 {
    fn spread(v: f64) -> u64 {
        let mut x = (v.max(0.0) as u64).min((1 << MORTON_BITS) - 1);
        x = (x | x << 32) & 0x1f00000000ffff;
        x = (x | x << 16) & 0x1f0000ff0000ff;
        x = (x | x << 8) & 0x100f00f00f00f00f;
        x = (x | x << 4) & 0x10c30c30c30c30c3;
        (x | x << 2) & 0x1249249249249249
    }
    spread(q.x) | spread(q.y) << 1 | spread(q.z) << 2
}

/// The scale that maps coordinates spanning `extent` (the largest side of the points' bounding
/// box) onto the grid of [`morton_code`]: `MORTON_MAX / extent`, or 0 when `extent` is not a
/// positive finite number (every point then gets code 0).
pub fn morton_scale(extent: f64) -> f64 {
    if extent > 0.0 && extent.is_finite() {
        MORTON_MAX / extent
    } else {
        0.0
    }
}

/// The indices of `points` in Morton (Z-curve) order over their bounding box, the points that
/// are not finite last; ties in index order. Queries issued in this order keep a search
/// structure's nodes in cache.
pub fn morton_order(points: &[DVec3]) -> Vec<u32> {
    let finite = || points.iter().filter(|p| p.is_finite());
    let lo = finite().fold(DVec3::splat(f64::INFINITY), |a, p| a.min(*p));
    let hi = finite().fold(DVec3::splat(f64::NEG_INFINITY), |a, p| a.max(*p));
    let scale = morton_scale((hi - lo).max_element());
    by_code(points, |p| morton_code((p - lo) * scale))
}

/// The indices of `points` sorted by `code` of each finite point (ties in index order), the
/// points that are not finite last.
fn by_code(points: &[DVec3], code: impl Fn(DVec3) -> u64) -> Vec<u32> {
    let mut order: Vec<(u64, u32)> = points
        .iter()
        .enumerate()
        .map(|(i, &p)| (if p.is_finite() { code(p) } else { u64::MAX }, i as u32))
        .collect();
    order.sort_unstable();
    order.into_iter().map(|(_, i)| i).collect()
}

/// The indices of `points` in Morton (Z-curve) order over cells of side `cell` (same units; a
/// grid at multiples of `cell`, so that a point's cell does not move with the other points),
/// in index order within a cell, the points that are not finite last. Coarse cells keep the
/// order from turning on the last bits of the positions (the same surface in f32 and in f64
/// gives the same order unless a point lies within the rounding of a cell's side). `cell` not
/// a positive finite number counts as 1.
pub fn morton_order_in_cells(points: &[DVec3], cell: f64) -> Vec<u32> {
    let cell = if cell > 0.0 && cell.is_finite() {
        cell
    } else {
        1.0
    };
    let lo = points
        .iter()
        .filter(|p| p.is_finite())
        .fold(DVec3::splat(f64::INFINITY), |a, p| a.min(*p));
    let origin = if lo.is_finite() {
        (lo / cell).floor() * cell
    } else {
        DVec3::ZERO
    };
    by_code(points, |p| morton_code((p - origin) / cell))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_interleave_the_coordinates_and_clamp() {
        assert_eq!(morton_code(DVec3::new(1.0, 0.0, 0.0)), 0b001);
        assert_eq!(morton_code(DVec3::new(0.0, 1.0, 0.0)), 0b010);
        assert_eq!(morton_code(DVec3::new(0.0, 0.0, 1.0)), 0b100);
        assert_eq!(morton_code(DVec3::new(3.0, 0.0, 1.0)), 0b1101);
        assert_eq!(morton_code(DVec3::splat(-5.0)), 0);
        let top = morton_code(DVec3::splat(MORTON_MAX));
        assert_eq!(top, (1u64 << 63) - 1);
        assert_eq!(morton_code(DVec3::splat(1e30)), top);
        assert_eq!(morton_code(DVec3::splat(f64::NAN)), 0);
        assert_eq!(morton_scale(0.0), 0.0);
        assert_eq!(morton_scale(f64::NAN), 0.0);
    }
}
