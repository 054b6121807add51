//! Uniform random subsampling.

use rand::seq::index::sample;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// `count` distinct indices of `0..n` chosen uniformly at random (all of them, in a random
/// order, when `count >= n`), in increasing order. Deterministic for a `seed`.
pub fn random_subsample(n: usize, count: usize, seed: u64) -> Vec<usize> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = sample(&mut rng, n, count.min(n)).into_vec();
    out.sort_unstable();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distinct_in_range_and_repeatable() {
        let a = random_subsample(1000, 100, 3);
        assert_eq!(a.len(), 100);
        assert!(a.windows(2).all(|w| w[0] < w[1]) && a[99] < 1000);
        assert_eq!(a, random_subsample(1000, 100, 3));
        assert_ne!(a, random_subsample(1000, 100, 4));
        assert_eq!(random_subsample(10, 20, 1), (0..10).collect::<Vec<_>>());
    }
}
