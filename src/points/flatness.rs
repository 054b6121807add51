//! How flat a point set is at the output's scale: the share of its local covariance in the
//! direction of least spread (the surface variation of Pauly, Gross and Kobbelt 2002,
//! "Efficient simplification of point-sampled surfaces", Sec. 3.1: λ0 / (λ0 + λ1 + λ2)). Points
//! near a surface give a value near 0 at a scale well above their noise; points filling a
//! volume give about 1/3 (a ball's three equal spreads). The median over the samples tells
//! apart data a surface can be fitted to from data that is not near one (uniform noise in a
//! cube), before the optimization spends its time on a surface that is not there.

use glam::DVec3;

use super::rimls::Rimls;

/// Neighbours queried per probe (those within the radius count).
const NEIGHBORS: usize = 64;

/// A probe with fewer neighbours within the radius gives no value.
const MIN_NEIGHBORS: usize = 10;

/// At most this many probes (evenly spaced in the list).
const MAX_PROBES: usize = 1000;

/// The median surface variation of the support of `rimls` around `probes` (any units, as the
/// surface's), each over its support points within `radius` (up to [`NEIGHBORS`] nearest):
/// `None` when no probe has [`MIN_NEIGHBORS`] of them. In [0, 1/3]. Deterministic.
pub fn median_surface_variation(rimls: &Rimls, probes: &[DVec3], radius: f64) -> Option<f64> {
    let step = probes.len().div_ceil(MAX_PROBES).max(1);
    let mut found = Vec::new();
    let mut values: Vec<f64> = Vec::new();
    for &p in probes.iter().step_by(step) {
        rimls.nearest_n(p, NEIGHBORS, &mut found);
        let near: Vec<DVec3> = found
            .iter()
            .filter(|&&(_, d2)| d2 <= radius * radius)
            .map(|&(i, _)| rimls.positions()[i as usize])
            .collect();
        if near.len() >= MIN_NEIGHBORS {
            values.push(surface_variation(&near));
        }
    }
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    Some(values[values.len() / 2])
}

/// λ0 / (λ0 + λ1 + λ2) of the covariance of `points` (λ0 the smallest eigenvalue); 0 for
/// points all at one place.
fn surface_variation(points: &[DVec3]) -> f64 {
    let n = points.len() as f64;
    let mean = points.iter().copied().sum::<DVec3>() / n;
    let mut c = nalgebra::Matrix3::<f64>::zeros();
    for p in points {
        let d = *p - mean;
        let v = nalgebra::Vector3::new(d.x, d.y, d.z);
        c += v * v.transpose();
    }
    let eig = c.symmetric_eigenvalues();
    let total = eig.sum();
    if total > 0.0 {
        (eig.min() / total).max(0.0)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn a_plane_is_flat_and_a_volume_is_not() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let plane: Vec<DVec3> = (0..400)
            .map(|_| DVec3::new(rng.random(), rng.random(), 0.001 * rng.random::<f64>()))
            .collect();
        let cube: Vec<DVec3> = (0..400)
            .map(|_| DVec3::new(rng.random(), rng.random(), rng.random()))
            .collect();
        assert!(surface_variation(&plane) < 0.01);
        let v = surface_variation(&cube);
        assert!(v > 0.25 && v <= 1.0 / 3.0 + 1e-12, "{v}");
        assert_eq!(surface_variation(&[DVec3::ONE; 12]), 0.0);
    }
}
