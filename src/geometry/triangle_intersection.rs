//! Whether two triangles share a point, decided exactly (Shewchuk's orientation predicates, the
//! `robust` crate).

use glam::DVec3;
use robust::{orient2d, orient3d, Coord, Coord3D};

fn c3(p: DVec3) -> Coord3D<f64> {
    Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

/// The sign of orient3d(a, b, c, d): exact (Shewchuk's adaptive predicate, the `robust` crate).
/// Nonzero exactly when the four points are not coplanar; two points d, e lie strictly on the
/// same side of the plane through a, b, c exactly when orient(a, b, c, d) == orient(a, b, c, e)
/// != 0.
pub(crate) fn orient(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
    let v = orient3d(c3(a), c3(b), c3(c), c3(d));
    if v > 0.0 {
        1
    } else if v < 0.0 {
        -1
    } else {
        0
    }
}

/// The sign of orient3d(a, b, c, d) when the floating-point determinant decides it (Shewchuk's
/// first stage: its magnitude above the error bound `(7 + 56 ε) ε` times the permanent), `None`
/// when only the exact stages can: the corners are nearly coplanar.
fn orient_if_certain(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Option<i8> {
    const EPS: f64 = f64::EPSILON * 0.5;
    const BOUND: f64 = (7.0 + 56.0 * EPS) * EPS;
    let (ad, bd, cd) = (a - d, b - d, c - d);
    let (bdxcdy, cdxbdy) = (bd.x * cd.y, cd.x * bd.y);
    let (cdxady, adxcdy) = (cd.x * ad.y, ad.x * cd.y);
    let (adxbdy, bdxady) = (ad.x * bd.y, bd.x * ad.y);
    let det = ad.z * (bdxcdy - cdxbdy) + bd.z * (cdxady - adxcdy) + cd.z * (adxbdy - bdxady);
    let permanent = (bdxcdy.abs() + cdxbdy.abs()) * ad.z.abs()
        + (cdxady.abs() + adxcdy.abs()) * bd.z.abs()
        + (adxbdy.abs() + bdxady.abs()) * cd.z.abs();
    if det > BOUND * permanent {
        Some(1)
    } else if -det > BOUND * permanent {
        Some(-1)
    } else {
        None
    }
}

/// Whether all of `signs` are certain and strictly on one side.
fn certainly_one_side(signs: [Option<i8>; 3]) -> bool {
    signs.iter().all(|&s| s == Some(1)) || signs.iter().all(|&s| s == Some(-1))
}

/// Whether the closed triangles `a` and `b` (non-degenerate) share at least one point, decided
/// exactly for the given coordinates (no tolerance: touching counts).
///
/// Two triangles that are not coplanar meet in a segment whose ends lie on the edges of one or
/// the other, so they intersect exactly when an edge of one meets the other triangle
/// ([`segment_meets_triangle`], 6 tests); coplanar triangles are compared in 2D, projected along
/// their normal's largest component (a projection that keeps incidence for points of one
/// plane).
///
/// Source: the orientation-predicate formulation of triangle–triangle tests (P. Guigue,
/// O. Devillers, *Fast and Robust Triangle-Triangle Overlap Test Using Orientation Predicates*,
/// Journal of Graphics Tools 8(1), 2003), with J. R. Shewchuk's exact predicates (*Adaptive
/// Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates*, Discrete Comput.
/// Geom. 18, 1997).
pub fn triangles_intersect(a: [DVec3; 3], b: [DVec3; 3]) -> bool {
    // The floating-point determinants first: one triangle certainly on one side of the other's
    // plane.
    let fb = b.map(|p| orient_if_certain(a[0], a[1], a[2], p));
    let fa = a.map(|p| orient_if_certain(b[0], b[1], b[2], p));
    if certainly_one_side(fb) || certainly_one_side(fa) {
        return false;
    }
    // Nearly coplanar: projections that are apart (see `segment_meets_triangle`) are apart.
    if fb.iter().chain(&fa).any(Option::is_none) {
        let axis = drop_axis(a);
        let (a2, b2) = (a.map(|v| project(v, axis)), b.map(|v| project(v, axis)));
        if orient_2d(a2[0], a2[1], a2[2]) != 0
            && orient_2d(b2[0], b2[1], b2[2]) != 0
            && !triangles_meet_2d(a2, b2)
        {
            return false;
        }
    }
    // Both of b's corners strictly on one side of a's plane (or the reverse): apart.
    let sb = b.map(|p| orient(a[0], a[1], a[2], p));
    if sb.iter().all(|&s| s > 0) || sb.iter().all(|&s| s < 0) {
        return false;
    }
    let sa = a.map(|p| orient(b[0], b[1], b[2], p));
    if sa.iter().all(|&s| s > 0) || sa.iter().all(|&s| s < 0) {
        return false;
    }
    if sb.iter().all(|&s| s == 0) {
        return coplanar_triangles_intersect(a, b);
    }
    (0..3).any(|k| segment_meets_triangle(a[k], a[(k + 1) % 3], b))
        || (0..3).any(|k| segment_meets_triangle(b[k], b[(k + 1) % 3], a))
}

/// Whether the closed triangles `a` and `b` (non-degenerate) share a point
/// ([`triangles_intersect`], exact) or come within `near` of each other (any length unit; `near`
/// ≤ 0 is the exact test alone). Two triangles that do not meet are nearest between a corner of
/// one and the other triangle or between two edges, so the distance is the least of those 15;
/// it is computed only when no plane of either triangle has the other's corners all farther
/// than `near` on one side.
///
/// This is the test for faces that touch once rounded: a mesh mapped into another frame or
/// written as `f32` moves each corner by up to its rounding, so faces nearer than that may share
/// a point in the file though not before.
pub(crate) fn triangles_within(a: [DVec3; 3], b: [DVec3; 3], near: f64) -> bool {
    if triangles_intersect(a, b) {
        return true;
    }
    if near.is_nan() || near <= 0.0 {
        return false;
    }
    for (s, t) in [(a, b), (b, a)] {
        if let Some(n) = (s[1] - s[0]).cross(s[2] - s[0]).try_normalize() {
            let d = t.map(|p| n.dot(p - s[0]));
            if d.iter().all(|&x| x > near) || d.iter().all(|&x| x < -near) {
                return false;
            }
        }
    }
    triangle_distance(a, b) <= near
}

/// The distance between the closed triangles `a` and `b` (non-degenerate): 0 when they meet
/// ([`triangles_intersect`], exact), else the least distance from a corner of one to the other
/// triangle and between an edge of one and an edge of the other.
pub(crate) fn triangles_distance(a: [DVec3; 3], b: [DVec3; 3]) -> f64 {
    if triangles_intersect(a, b) {
        0.0
    } else {
        triangle_distance(a, b)
    }
}

/// The distance between the closed triangles `a` and `b`, which do not meet: the least distance
/// from a corner of one to the other triangle and between an edge of one and an edge of the
/// other.
fn triangle_distance(a: [DVec3; 3], b: [DVec3; 3]) -> f64 {
    let corners = a
        .iter()
        .map(|&p| point_triangle_distance(p, b))
        .chain(b.iter().map(|&p| point_triangle_distance(p, a)));
    let edges = (0..3).flat_map(|i| {
        (0..3).map(move |j| segment_distance(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3]))
    });
    corners.chain(edges).fold(f64::INFINITY, f64::min)
}

/// The distance from point `p` to the closed triangle `t` (parry's point query).
pub(crate) fn point_triangle_distance(p: DVec3, t: [DVec3; 3]) -> f64 {
    use parry3d_f64::query::PointQuery;
    parry3d_f64::shape::Triangle::new(t[0], t[1], t[2]).distance_to_local_point(p, true)
}

/// The distance between the closed segments `p0 p1` and `q0 q1` (parry's closest points).
fn segment_distance(p0: DVec3, p1: DVec3, q0: DVec3, q1: DVec3) -> f64 {
    use parry3d_f64::query::closest_points::closest_points_segment_segment_with_locations_nD;
    use parry3d_f64::shape::Segment;
    let (la, lb) = closest_points_segment_segment_with_locations_nD((&p0, &p1), (&q0, &q1));
    Segment::new(p0, p1)
        .point_at(&la)
        .distance(Segment::new(q0, q1).point_at(&lb))
}

/// The distance between the closed segment `p q` and the closed triangle `t` (non-degenerate):
/// 0 when they meet ([`segment_meets_triangle`], exact), else the least distance from an end of
/// the segment to the triangle or from the segment to an edge of the triangle.
pub(crate) fn segment_triangle_distance(p: DVec3, q: DVec3, t: [DVec3; 3]) -> f64 {
    if segment_meets_triangle(p, q, t) {
        return 0.0;
    }
    let ends = [p, q].map(|x| point_triangle_distance(x, t));
    let edges = (0..3).map(|k| segment_distance(p, q, t[k], t[(k + 1) % 3]));
    ends.into_iter().chain(edges).fold(f64::INFINITY, f64::min)
}

/// Whether the closed segment `p q` comes within `near` of the closed triangle `t`
/// (non-degenerate) that it does not meet (`segment_meets_triangle` false): as
/// `segment_triangle_distance(p, q, t) <= near`, without its distances where both ends lie on
/// one side of the triangle's plane and farther from it than `near` (with a margin far above
/// the rounding of either computation, 1e-9 of the lengths involved): the plane's distance is a
/// lower bound of the triangle's.
pub(crate) fn apart_segment_within(p: DVec3, q: DVec3, t: [DVec3; 3], near: f64) -> bool {
    let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
    let (dp, dq) = ((p - t[0]).dot(n), (q - t[0]).dot(n));
    let scale = (p - t[0]).length() + (q - t[0]).length() + (t[1] - t[0]).length();
    let margin = near + 1e-9 * scale;
    if n != DVec3::ZERO && ((dp > margin && dq > margin) || (dp < -margin && dq < -margin)) {
        return false;
    }
    let ends = [p, q].map(|x| point_triangle_distance(x, t));
    let edges = (0..3).map(|k| segment_distance(p, q, t[k], t[(k + 1) % 3]));
    ends.into_iter().chain(edges).fold(f64::INFINITY, f64::min) <= near
}

/// Whether `r` and `s`, coplanar with the segment `p q` (`orient(p, q, r, s) == 0`, `p q r` a
/// non-degenerate triangle), lie strictly on the same side of the line through `p` and `q`,
/// decided exactly: in the plane's projection along the largest component of its normal, which
/// keeps incidence and orientation up to sign.
pub(crate) fn same_side_in_plane(p: DVec3, q: DVec3, r: DVec3, s: DVec3) -> bool {
    let axis = drop_axis([p, q, r]);
    let [p2, q2, r2, s2] = [p, q, r, s].map(|x| project(x, axis));
    let (or, os) = (orient_2d(p2, q2, r2), orient_2d(p2, q2, s2));
    or != 0 && or == os
}

/// Whether the closed segment `p q` meets the closed triangle `t` (non-degenerate), exactly.
pub fn segment_meets_triangle(p: DVec3, q: DVec3, t: [DVec3; 3]) -> bool {
    let (fp, fq) = (
        orient_if_certain(t[0], t[1], t[2], p),
        orient_if_certain(t[0], t[1], t[2], q),
    );
    if fp.is_some() && fp == fq && fp != Some(0) {
        return false;
    }
    // A point the two share projects to a point their projections share, so projections that
    // are apart (a coordinate dropped: exact) decide it with 2D predicates, which are fast where
    // the 3D ones are slowest: the nearly coplanar corners of a flat region's faces, which take
    // orient3d's exact stages (a flat part's mend spent 65% of its time there).
    if fp.is_none() || fq.is_none() {
        let axis = drop_axis(t);
        let t2 = t.map(|v| project(v, axis));
        if orient_2d(t2[0], t2[1], t2[2]) != 0
            && !segment_meets_triangle_2d(project(p, axis), project(q, axis), t2)
        {
            return false;
        }
    }
    let sp = orient(t[0], t[1], t[2], p);
    let sq = orient(t[0], t[1], t[2], q);
    if sp != 0 && sp == sq {
        return false;
    }
    if sp == 0 && sq == 0 {
        // The segment lies in the triangle's plane.
        let axis = drop_axis(t);
        let (p2, q2, t2) = (
            project(p, axis),
            project(q, axis),
            t.map(|v| project(v, axis)),
        );
        return segment_meets_triangle_2d(p2, q2, t2);
    }
    // The segment crosses (or touches) the plane once: the line p q passes through the closed
    // triangle when it sees the three edges turning the same way (or along one of them).
    let s = [
        orient(p, q, t[0], t[1]),
        orient(p, q, t[1], t[2]),
        orient(p, q, t[2], t[0]),
    ];
    !(s.iter().any(|&x| x > 0) && s.iter().any(|&x| x < 0))
}

/// The coordinate to drop when projecting points of the plane of `t` to 2D: the largest
/// component of its normal (any nonzero one keeps incidence and orientation up to sign).
fn drop_axis(t: [DVec3; 3]) -> usize {
    let n = (t[1] - t[0]).cross(t[2] - t[0]).abs();
    if n.x >= n.y && n.x >= n.z {
        0
    } else if n.y >= n.z {
        1
    } else {
        2
    }
}

fn project(p: DVec3, axis: usize) -> [f64; 2] {
    match axis {
        0 => [p.y, p.z],
        1 => [p.z, p.x],
        _ => [p.x, p.y],
    }
}

fn orient_2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i8 {
    let v = orient2d(
        Coord { x: a[0], y: a[1] },
        Coord { x: b[0], y: b[1] },
        Coord { x: c[0], y: c[1] },
    );
    if v > 0.0 {
        1
    } else if v < 0.0 {
        -1
    } else {
        0
    }
}

/// Whether the corners `p` are collinear (the triangle has exactly zero area), decided exactly:
/// its projections onto the three coordinate planes all have orientation 0. Coincident corners
/// are collinear. Stricter than the toleranced zero-area test
/// ([`is_degenerate_triangle`](super::triangle::is_degenerate_triangle)), which also takes
/// triangles of almost no area.
pub(crate) fn collinear(p: [DVec3; 3]) -> bool {
    (0..3).all(|axis| {
        let [a, b, c] = p.map(|v| project(v, axis));
        orient_2d(a, b, c) == 0
    })
}

/// Whether point `p` lies in the closed 2D triangle `t` (non-degenerate).
fn point_in_triangle_2d(p: [f64; 2], t: [[f64; 2]; 3]) -> bool {
    let s = [
        orient_2d(t[0], t[1], p),
        orient_2d(t[1], t[2], p),
        orient_2d(t[2], t[0], p),
    ];
    !(s.iter().any(|&x| x > 0) && s.iter().any(|&x| x < 0))
}

/// Whether the closed 2D segments `a b` and `c d` share a point.
fn segments_meet_2d(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let (o1, o2) = (orient_2d(a, b, c), orient_2d(a, b, d));
    let (o3, o4) = (orient_2d(c, d, a), orient_2d(c, d, b));
    if o1 != o2 && o3 != o4 && o1 * o2 <= 0 && o3 * o4 <= 0 {
        return true;
    }
    // Collinear cases: an end of one on the other.
    let on = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        orient_2d(p, q, r) == 0
            && r[0] >= p[0].min(q[0])
            && r[0] <= p[0].max(q[0])
            && r[1] >= p[1].min(q[1])
            && r[1] <= p[1].max(q[1])
    };
    on(a, b, c) || on(a, b, d) || on(c, d, a) || on(c, d, b)
}

fn segment_meets_triangle_2d(p: [f64; 2], q: [f64; 2], t: [[f64; 2]; 3]) -> bool {
    point_in_triangle_2d(p, t)
        || point_in_triangle_2d(q, t)
        || (0..3).any(|k| segments_meet_2d(p, q, t[k], t[(k + 1) % 3]))
}

fn coplanar_triangles_intersect(a: [DVec3; 3], b: [DVec3; 3]) -> bool {
    let axis = drop_axis(a);
    triangles_meet_2d(a.map(|v| project(v, axis)), b.map(|v| project(v, axis)))
}

/// Whether the closed 2D triangles `a` (non-degenerate) and `b` share a point.
fn triangles_meet_2d(a: [[f64; 2]; 3], b: [[f64; 2]; 3]) -> bool {
    (0..3).any(|k| segment_meets_triangle_2d(a[k], a[(k + 1) % 3], b))
        || point_in_triangle_2d(b[0], a)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The plane's bound leaves the answer of the distances: segments apart from a triangle,
    /// on one side of its plane, across it, in it, and at distances around `near`.
    #[test]
    fn the_plane_bound_answers_as_the_distances_do() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let t = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.1, 0.0),
            DVec3::new(0.2, 0.9, 0.0),
        ];
        let (mut within, mut apart) = (0, 0);
        for k in 0..20_000 {
            let near = [1e-3, 0.05, 0.3][k % 3];
            let lift = [0.0, 1.0, 0.1, 1e-3][k % 4];
            let mut at = |z: f64| {
                DVec3::new(
                    rng.random_range(-0.5..1.5),
                    rng.random_range(-0.5..1.5),
                    z * rng.random_range(-1.0..1.0),
                )
            };
            let (p, q) = (at(lift), at(lift));
            if segment_meets_triangle(p, q, t) {
                continue;
            }
            let expected = segment_triangle_distance(p, q, t) <= near;
            assert_eq!(
                apart_segment_within(p, q, t, near),
                expected,
                "{p} {q} {near}"
            );
            if expected {
                within += 1;
            } else {
                apart += 1;
            }
        }
        assert!(within > 500 && apart > 500, "{within} {apart}");
    }

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    #[test]
    fn triangles_within_a_distance_of_each_other() {
        let a = [v(0., 0., 0.), v(4., 0., 0.), v(0., 4., 0.)];
        let h = 1e-6;
        // A corner h above a's interior: the corner's distance decides.
        let b = [v(1., 1., h), v(3., 3., 2.), v(1., 3., 2.)];
        assert!(!triangles_intersect(a, b));
        assert!(triangles_within(a, b, 2.0 * h));
        assert!(!triangles_within(a, b, 0.5 * h));
        assert!(!triangles_within(a, b, 0.0));
        // An edge of b passing h over a's edge on the x axis, every corner of b farther than 1
        // from a (b lies in the plane x = 2, and below a's plane only where y < 0): the edges'
        // distance, h / sqrt 2, decides.
        let b = [v(2., -1., h - 1.), v(2., 1., h + 1.), v(2., -1., h + 3.)];
        assert!(!triangles_intersect(a, b));
        assert!(triangles_within(a, b, 0.75 * h));
        assert!(!triangles_within(a, b, 0.65 * h));
        // Crossing triangles are within any distance, apart ones within none short of theirs.
        let c = [v(1., 1., -1.), v(1., 1., 1.), v(2., 1., 0.)];
        assert!(triangles_within(a, c, 0.0));
        let far = a.map(|p| p + v(0., 0., 3.));
        assert!(!triangles_within(a, far, 2.9));
        assert!(triangles_within(a, far, 3.1));
    }

    #[test]
    fn crossing_touching_and_apart_triangles() {
        let a = [v(0., 0., 0.), v(4., 0., 0.), v(0., 4., 0.)];
        // Pierces a's interior.
        assert!(triangles_intersect(
            a,
            [v(1., 1., -1.), v(1., 1., 1.), v(2., 1., 1.)]
        ));
        // Above it.
        assert!(!triangles_intersect(
            a,
            [v(1., 1., 0.5), v(1., 2., 1.), v(2., 1., 1.)]
        ));
        // A corner touching a's interior from above.
        assert!(triangles_intersect(
            a,
            [v(1., 1., 0.), v(1., 2., 1.), v(2., 1., 1.)]
        ));
        // A corner touching a's edge.
        assert!(triangles_intersect(
            a,
            [v(2., 0., 0.), v(2., -1., 1.), v(3., -1., 1.)]
        ));
        // Crosses a's plane outside a.
        assert!(!triangles_intersect(
            a,
            [v(3., 3., -1.), v(3., 3., 1.), v(4., 3., 1.)]
        ));
        // Coplanar: overlapping, one inside the other, touching at a corner, apart.
        assert!(triangles_intersect(
            a,
            [v(1., 1., 0.), v(5., 1., 0.), v(1., 5., 0.)]
        ));
        assert!(triangles_intersect(
            a,
            [v(0.5, 0.5, 0.), v(1., 0.5, 0.), v(0.5, 1., 0.)]
        ));
        assert!(triangles_intersect(
            a,
            [v(4., 0., 0.), v(5., 0., 0.), v(5., 1., 0.)]
        ));
        assert!(!triangles_intersect(
            a,
            [v(3., 3., 0.), v(5., 3., 0.), v(3., 5., 0.)]
        ));
        // An edge lying in a's plane across it, the third corner above.
        assert!(triangles_intersect(
            a,
            [v(-1., 1., 0.), v(5., 1., 0.), v(2., 2., 3.)]
        ));
        // Symmetric.
        let b = [v(1., 1., -1.), v(1., 1., 1.), v(2., 1., 1.)];
        assert_eq!(triangles_intersect(a, b), triangles_intersect(b, a));
    }

    #[test]
    fn exact_at_a_grazing_contact() {
        // b's edge passes through a's edge at a point, at 1e-17-scale offsets that a
        // floating-point plane test would get wrong.
        let a = [v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.)];
        let t = 0.1 + 0.2; // 0.30000000000000004
        let b = [v(t, 0., -1.), v(t, 0., 1.), v(t, -1., 0.)];
        assert!(triangles_intersect(a, b));
        let b2 = [v(t, -1e-300, -1.), v(t, -1e-300, 1.), v(t, -1., 0.)];
        assert!(!triangles_intersect(a, b2));
    }

    /// The tests without the floating-point and projection filters: orient3d's signs alone.
    fn segment_meets_triangle_exact(p: DVec3, q: DVec3, t: [DVec3; 3]) -> bool {
        let (sp, sq) = (orient(t[0], t[1], t[2], p), orient(t[0], t[1], t[2], q));
        if sp != 0 && sp == sq {
            return false;
        }
        if sp == 0 && sq == 0 {
            let axis = drop_axis(t);
            let t2 = t.map(|v| project(v, axis));
            return segment_meets_triangle_2d(project(p, axis), project(q, axis), t2);
        }
        let s = [
            orient(p, q, t[0], t[1]),
            orient(p, q, t[1], t[2]),
            orient(p, q, t[2], t[0]),
        ];
        !(s.iter().any(|&x| x > 0) && s.iter().any(|&x| x < 0))
    }

    fn triangles_intersect_exact(a: [DVec3; 3], b: [DVec3; 3]) -> bool {
        let sb = b.map(|p| orient(a[0], a[1], a[2], p));
        let sa = a.map(|p| orient(b[0], b[1], b[2], p));
        let one_side = |s: [i8; 3]| s.iter().all(|&x| x > 0) || s.iter().all(|&x| x < 0);
        if one_side(sb) || one_side(sa) {
            return false;
        }
        if sb.iter().all(|&x| x == 0) {
            return coplanar_triangles_intersect(a, b);
        }
        (0..3).any(|k| segment_meets_triangle_exact(a[k], a[(k + 1) % 3], b))
            || (0..3).any(|k| segment_meets_triangle_exact(b[k], b[(k + 1) % 3], a))
    }

    #[test]
    fn the_filters_give_the_exact_answers_on_nearly_coplanar_faces() {
        // Faces of a tilted plane (corners rounded off it, as a flat part's are) and faces a
        // rounding or a hair off it: the floating-point determinant is uncertain there, and the
        // projection filter must agree with orient3d's exact stages.
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let (u, w) = (v(1.0, 0.3, 0.7).normalize(), v(-0.2, 1.0, 0.4));
        let w = (w - u * u.dot(w)).normalize();
        let n = u.cross(w);
        let point = |rng: &mut ChaCha8Rng, off: f64| {
            let (x, y) = (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            u * x + w * y + n * off * rng.random_range(-1.0..1.0)
        };
        let (mut met, mut apart, mut uncertain) = (0, 0, 0);
        for i in 0..4000 {
            let off = [0.0, 1e-17, 1e-12, 1e-3][i % 4];
            let a = [0; 3].map(|_| point(&mut rng, off));
            let b = [0; 3].map(|_| point(&mut rng, off));
            if b.iter()
                .any(|&p| orient_if_certain(a[0], a[1], a[2], p).is_none())
            {
                uncertain += 1;
            }
            for p in b {
                if let Some(s) = orient_if_certain(a[0], a[1], a[2], p) {
                    assert_eq!(s, orient(a[0], a[1], a[2], p));
                }
            }
            let exact = triangles_intersect_exact(a, b);
            assert_eq!(triangles_intersect(a, b), exact, "{a:?} {b:?}");
            for k in 0..3 {
                let (p, q) = (b[k], b[(k + 1) % 3]);
                let e = segment_meets_triangle_exact(p, q, a);
                assert_eq!(segment_meets_triangle(p, q, a), e, "{p:?} {q:?} {a:?}");
            }
            if exact {
                met += 1;
            } else {
                apart += 1;
            }
        }
        assert!(
            met > 500 && apart > 500 && uncertain > 1500,
            "{met} {apart} {uncertain}"
        );
    }

    #[test]
    fn random_pairs_agree_with_parrys_distance() {
        // Oracle: parry's triangle–triangle distance (GJK, floating point), trusted where it is
        // clearly positive or where the pair clearly crosses.
        use parry3d_f64::math::Pose;
        use parry3d_f64::query::distance;
        use parry3d_f64::shape::Triangle;
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut r = || {
            v(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
        };
        let id = Pose::IDENTITY;
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..2000 {
            let a = [r(), r(), r()];
            let b = [r(), r(), r()];
            let d = distance(
                &id,
                &Triangle::new(a[0], a[1], a[2]),
                &id,
                &Triangle::new(b[0], b[1], b[2]),
            )
            .unwrap()
            .distance;
            if d > 1e-9 {
                assert!(!triangles_intersect(a, b), "{a:?} {b:?} apart by {d}");
                misses += 1;
            } else {
                assert!(triangles_intersect(a, b), "{a:?} {b:?} at distance {d}");
                hits += 1;
            }
        }
        assert!(hits > 100 && misses > 100, "{hits} {misses}");
    }
}
