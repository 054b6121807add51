//! The dimension of the manifold a point set lies near, by the maximum-likelihood estimate of
//! E. Levina and P. J. Bickel, *Maximum likelihood estimation of intrinsic dimension*, NIPS 2004,
//! averaged over points as D. J. C. MacKay and Z. Ghahramani propose (*Comments on "Maximum
//! likelihood estimation of intrinsic dimension"*, 2005): with T_j(x) the distance from x to its
//! j-th nearest other point,
//!
//! m̂ = [ mean over x of 1/(k-1) Σ_{j<k} ln(T_k(x) / T_j(x)) ]^-1.
//!
//! The count search's first step and the projection onto the data use it when the caller does
//! not give the dimension.

use super::{random_probes, with_kernel_dim, PointSet};
use crate::spatial::StaticKdTree;

/// The neighbours k of each point the estimate uses.
pub const DIMENSION_NEIGHBOURS: usize = 10;

/// The most points the estimate is averaged over (a seeded random subset of a larger set).
const DIMENSION_PROBES: usize = 2000;

/// The estimate of [`estimate_dimension`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DimensionEstimate {
    /// m̂, a real number (NaN when no point had k distinct neighbours).
    pub value: f64,
    /// The points it was averaged over.
    pub points: usize,
}

impl DimensionEstimate {
    /// m̂ rounded to a whole dimension from 1 to `space_dim` (1 when there was no estimate).
    pub fn round_dimension(&self, space_dim: usize) -> usize {
        if self.value.is_finite() {
            (self.value.round() as usize).clamp(1, space_dim.max(1))
        } else {
            1
        }
    }
}

/// The dimension of the manifold `points` lie near (Levina and Bickel's estimate, see the module
/// docs), over at most 2000 of them chosen with `seed`, each with its
/// [`DIMENSION_NEIGHBOURS`] nearest others by position (normals are not used). Points with a
/// duplicate among their neighbours are left out. Costs one kd-tree and 2000 queries.
pub fn estimate_dimension(points: &PointSet, seed: u64) -> DimensionEstimate {
    let d = points.dim();
    with_kernel_dim!(d, K => estimate::<K>(points, seed), DimensionEstimate {
        value: f64::NAN,
        points: 0,
    })
}

fn estimate<const K: usize>(points: &PointSet, seed: u64) -> DimensionEstimate {
    let (rows, tree) = points.position_tree::<K>();
    estimate_in(&rows, &tree, seed)
}

/// [`estimate_dimension`] over positions `rows` already in a kd-tree `tree`
/// ([`PointSet::position_tree`], any K at least the space's dimension).
pub(super) fn estimate_in<const K: usize>(
    rows: &[[f64; K]],
    tree: &StaticKdTree<K>,
    seed: u64,
) -> DimensionEstimate {
    let probe = random_probes(rows.len(), DIMENSION_PROBES, seed);
    let k = DIMENSION_NEIGHBOURS;
    let mut found = Vec::new();
    let (mut sum, mut used) = (0.0, 0usize);
    for &i in &probe {
        // The point itself comes first, at distance 0.
        tree.nearest_n(&rows[i], k + 1, &mut found);
        if found.len() < k + 1 {
            continue;
        }
        let t: Vec<f64> = found[1..].iter().map(|f| f.1.sqrt()).collect();
        if !(t[0] > 0.0) {
            continue;
        }
        let tk = t[k - 1].ln();
        sum += t[..k - 1].iter().map(|tj| tk - tj.ln()).sum::<f64>() / (k - 1) as f64;
        used += 1;
    }
    DimensionEstimate {
        value: if used > 0 && sum > 0.0 {
            used as f64 / sum
        } else {
            f64::NAN
        },
        points: used,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// `n` points uniform in the unit cube of R^m, embedded in R^d by a fixed rotation-like map
    /// (the first m coordinates, then sums of them).
    fn cube(n: usize, m: usize, d: usize, seed: u64) -> PointSet {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut xs = Vec::new();
        for _ in 0..n {
            let u: Vec<f64> = (0..m).map(|_| rng.random_range(0.0..1.0)).collect();
            for c in 0..d {
                xs.push(if c < m {
                    u[c]
                } else {
                    0.3 * u[c % m] + 0.2 * u[(c + 1) % m]
                });
            }
        }
        PointSet::new(d, xs, None).unwrap()
    }

    #[test]
    fn the_dimension_of_flat_pieces_is_found() {
        for (m, d) in [(1, 2), (2, 3), (2, 6), (3, 4), (4, 8)] {
            let e = estimate_dimension(&cube(20_000, m, d, 7), 1);
            assert_eq!(e.round_dimension(d), m, "m {m} in R^{d}: {}", e.value);
            assert!(e.points > 1000);
        }
    }

    #[test]
    fn duplicates_are_left_out_and_no_estimate_gives_one() {
        let p = PointSet::new(2, vec![1.0; 40], None).unwrap();
        let e = estimate_dimension(&p, 1);
        assert_eq!(e.points, 0);
        assert!(e.value.is_nan());
        assert_eq!(e.round_dimension(2), 1);
    }
}
