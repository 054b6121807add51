//! Point sets for the unit tests.

use glam::DVec3;

/// `n` nearly evenly spread unit vectors: the Fibonacci spiral (z from 1 to -1, longitude
/// advancing by the golden angle).
pub fn fibonacci_sphere(n: usize) -> Vec<DVec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let s = (1.0 - z * z).sqrt();
            let a = golden * i as f64;
            DVec3::new(s * a.cos(), s * a.sin(), z)
        })
        .collect()
}
