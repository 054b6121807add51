//! Points along a segment at a bounded step, and a point's distance to a segment.

use glam::DVec3;

/// The points of the segment `p`–`q` at equal steps of at most `step` (any units, `step` > 0):
/// ⌈|pq| / step⌉ steps (at least one), both ends included and exact (`p` first, `q` last).
pub fn points_along(p: DVec3, q: DVec3, step: f64) -> impl Iterator<Item = DVec3> {
    let n = (p.distance(q) / step).ceil().max(1.0) as usize;
    (0..=n).map(move |k| p.lerp(q, k as f64 / n as f64))
}

/// The distance from `p` to the segment `a`–`b` (any units); to `a` when the segment is a point.
pub fn distance_to_segment(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 {
        ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + t * ab)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_steps_are_equal_at_most_the_step_and_the_ends_exact() {
        let (p, q) = (DVec3::new(0.1, 0.2, 0.3), DVec3::new(1.7, -0.4, 2.9));
        let pts: Vec<DVec3> = points_along(p, q, 0.5).collect();
        assert_eq!(pts[0], p);
        assert_eq!(*pts.last().unwrap(), q);
        let steps: Vec<f64> = pts.windows(2).map(|w| w[0].distance(w[1])).collect();
        assert!(steps
            .iter()
            .all(|&s| s <= 0.5 && (s - steps[0]).abs() < 1e-12));
        assert_eq!(points_along(p, p, 0.5).count(), 2);
    }

    #[test]
    fn the_distance_to_a_segment_is_to_its_nearest_point() {
        let (a, b) = (DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0));
        assert_eq!(distance_to_segment(DVec3::new(1.0, 3.0, 4.0), a, b), 5.0);
        assert_eq!(distance_to_segment(DVec3::new(-3.0, 4.0, 0.0), a, b), 5.0);
        assert_eq!(distance_to_segment(DVec3::new(5.0, 0.0, 4.0), a, b), 5.0);
        assert_eq!(distance_to_segment(DVec3::new(0.0, 3.0, 4.0), a, a), 5.0);
    }
}
