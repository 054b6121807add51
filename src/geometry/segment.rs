//! Points along a segment at a bounded step.

use glam::DVec3;

/// The points of the segment `p`–`q` at equal steps of at most `step` (any units, `step` > 0):
/// ⌈|pq| / step⌉ steps (at least one), both ends included and exact (`p` first, `q` last).
pub fn points_along(p: DVec3, q: DVec3, step: f64) -> impl Iterator<Item = DVec3> {
    let n = (p.distance(q) / step).ceil().max(1.0) as usize;
    (0..=n).map(move |k| p.lerp(q, k as f64 / n as f64))
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
}
