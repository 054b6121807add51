//! Measures of one triangle given by its corners: the zero-area test, the interior angles and
//! the shape quality Q of the paper's Table 1.
//!
//! Source: Öztireli, Alexa, Gross 2010, Sec. 7.1; P. J. Frey, H. Borouchaki, *Surface mesh
//! quality evaluation*, Int. J. Numer. Meth. Engng 45, 1999 (shape measures `S / (p h)`).

use glam::DVec3;

use super::tolerance::DEGENERATE_AREA_TOLERANCE;

/// Whether a triangle with corners `p` is degenerate (has zero area):
/// `|(b-a)×(c-a)| <= DEGENERATE_AREA_TOLERANCE · h²`, `h` the longest edge. Triangles with a
/// non-finite coordinate count as degenerate too (the comparison is written so that NaN fails
/// the "has area" test). Coincident corners give a zero cross product and are degenerate.
#[inline]
pub fn is_degenerate_triangle(p: [DVec3; 3]) -> bool {
    let cross = (p[1] - p[0]).cross(p[2] - p[0]).length();
    let h2 = (p[1] - p[0])
        .length_squared()
        .max((p[2] - p[1]).length_squared())
        .max((p[0] - p[2]).length_squared());
    // Written so that NaN counts as degenerate.
    !matches!(
        cross.partial_cmp(&(DEGENERATE_AREA_TOLERANCE * h2)),
        Some(std::cmp::Ordering::Greater)
    )
}

/// The vertices of the indexed face `t` sorted: the same key for a face and every copy of it,
/// in any order of its corners and either winding (a duplicate face, the second sheet of a
/// double-sided export). How reading drops duplicate faces
/// ([`TriMesh::remove_duplicate_and_zero_area_faces`](crate::mesh::TriMesh::remove_duplicate_and_zero_area_faces))
/// and the crossing search counts them once ([`classified_pairs`](super::classified_pairs)).
#[inline]
pub fn face_key(mut t: [u32; 3]) -> [u32; 3] {
    t.sort_unstable();
    t
}

/// Whether the indexed triangle `t` over `positions` is degenerate: it repeats a vertex index, or
/// its corners fail [`is_degenerate_triangle`]. A triangle with an out-of-range index is not
/// judged here (it is `false` unless it also repeats an index); the invariant check
/// ([`check_invariants`](crate::check_invariants)) reports such faces.
pub fn is_degenerate_face(positions: &[DVec3], t: [u32; 3]) -> bool {
    if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
        return true;
    }
    if t.iter().any(|&i| i as usize >= positions.len()) {
        return false;
    }
    is_degenerate_triangle(t.map(|i| positions[i as usize]))
}

/// The three interior angles of a triangle, in degrees, at corners `p[0]`, `p[1]`, `p[2]`.
///
/// Each angle is `atan2(|e1 × e2|, e1 · e2)` with `e1`, `e2` the two edge vectors leaving the
/// corner: accurate for angles near 0° and 180°, where `acos` of a normalized dot product loses
/// half the digits. At a corner with a zero-length edge the formula gives `atan2(0, 0) = 0°`.
#[inline]
pub fn triangle_angles_deg(p: [DVec3; 3]) -> [f64; 3] {
    std::array::from_fn(|k| {
        let e1 = p[(k + 1) % 3] - p[k];
        let e2 = p[(k + 2) % 3] - p[k];
        e1.cross(e2).length().atan2(e1.dot(e2)).to_degrees()
    })
}

/// The smallest of [`triangle_angles_deg`], degrees.
#[inline]
pub fn triangle_min_angle_deg(p: [DVec3; 3]) -> f64 {
    let a = triangle_angles_deg(p);
    a[0].min(a[1]).min(a[2])
}

/// The shape quality of a triangle, `Q = 6 S / (√3 p h)` with `S` its area, `p` its
/// half-perimeter and `h` its longest edge: 1 for the equilateral triangle, tending to 0 as the
/// triangle degenerates; dimensionless. A degenerate triangle ([`is_degenerate_triangle`]) has
/// `Q = 0` exactly.
///
/// Source: Öztireli et al. 2010, Sec. 7.1 (the measure of Frey & Borouchaki 1999, as used by
/// Yan et al. 2009 and Valette et al. 2008).
#[inline]
pub fn triangle_q(p: [DVec3; 3]) -> f64 {
    if is_degenerate_triangle(p) {
        return 0.0;
    }
    let s = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
    let l = [
        (p[1] - p[0]).length(),
        (p[2] - p[1]).length(),
        (p[0] - p[2]).length(),
    ];
    let half_perimeter = 0.5 * (l[0] + l[1] + l[2]);
    let h = l[0].max(l[1]).max(l[2]);
    6.0 * s / (3f64.sqrt() * half_perimeter * h)
}

/// Bounds on a triangle's angles, degrees: what the last pass of the optimization works towards
/// and what the least-squares fit keeps (a face within them stays so, one outside gets no worse).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AngleBounds {
    /// The smallest angle kept, degrees.
    pub min_deg: f64,
    /// The largest angle kept, degrees.
    pub max_deg: f64,
}

impl AngleBounds {
    /// The face's angle score: min(θmin, `min_deg` + `max_deg` − θmax), below `min_deg` exactly
    /// when an angle is out of bounds.
    pub fn score(&self, corners: [DVec3; 3]) -> f64 {
        let a = triangle_angles_deg(corners);
        let (lo, hi) = (a[0].min(a[1]).min(a[2]), a[0].max(a[1]).max(a[2]));
        lo.min(self.min_deg + self.max_deg - hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angles_are_accurate_near_zero_and_180() {
        let eps = 1e-9;
        let p = [DVec3::ZERO, DVec3::X, DVec3::new(0.5, eps, 0.0)];
        let a = triangle_angles_deg(p);
        let expected_small = (2.0 * eps).atan().to_degrees();
        assert!((a[0] - expected_small).abs() < 1e-20);
        assert!((a[1] - expected_small).abs() < 1e-20);
        assert!((a[0] + a[1] + a[2] - 180.0).abs() < 1e-10);
        // A zero-length edge gives 0° at its corners.
        let z = triangle_angles_deg([DVec3::ZERO, DVec3::ZERO, DVec3::X]);
        assert_eq!(z[0], 0.0);
        assert_eq!(z[1], 0.0);
    }

    #[test]
    fn q_of_equilateral_is_one_and_degenerate_is_zero() {
        let p = [
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(0.5, 3f64.sqrt() / 2.0, 0.0),
        ];
        assert!((triangle_q(p) - 1.0).abs() < 1e-15);
        assert_eq!(triangle_q([DVec3::ZERO, DVec3::X, 2.0 * DVec3::X]), 0.0);
        assert!(is_degenerate_triangle([
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(f64::NAN, 0.0, 0.0)
        ]));
        assert!(is_degenerate_triangle([DVec3::ONE; 3]));
    }
}
