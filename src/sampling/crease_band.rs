//! The band along the sampled sharp-feature curves that the gradient ascent keeps surface
//! samples out of (issue 16: "gradient ascent never moves a surface sample across a feature
//! curve"). The projection onto the input takes every point beyond a convex crease to the crease
//! line itself, so a surface sample pushed towards a crease would land on it, between two crease
//! samples: the crease edge there could then only be put in as a sliver. A move that ends within
//! [`CREASE_BAND_PER_SPACING`] local spacings of a feature edge, and nearer to it than where the
//! sample was, is not taken; crossing a crease means passing through its band, wider than the
//! longest move (`GradientAscentParams::max_move_sigma_p`, 0.25 spacing), so it is refused too.

use glam::DVec3;

use crate::geometry::segment::points_along;
use crate::spatial::StaticTree;

/// The half-width of the band, in units of the local spacing w · sigma_p: a sample at that
/// distance from the middle of a crease edge of 1.15 spacings sees it under 2 · atan(0.35 /
/// 0.575) = 63°, and the triangle it makes with the edge has 31° at the edge's ends; a sample
/// where the sampling puts it (an equilateral triangle on the edge) is 1.0 spacing away.
pub const CREASE_BAND_PER_SPACING: f64 = 0.35;

/// Points along the feature edges of a sample set, for the distance to them.
pub struct CreaseBand {
    tree: StaticTree,
    /// The feature curves' spacing where the width is 1 (bbox-100 units).
    spacing: f64,
    /// The largest gap between consecutive points along an edge (the distance is low by at
    /// most half of it).
    step: f64,
}

impl CreaseBand {
    /// The band of the segments `edges` (index pairs into `positions`, bbox-100 units), sampled
    /// at `spacing` where the kernel width is 1 (w · `spacing` where it is w), with points along
    /// each edge at most `step` apart. `None` without edges or for a step that is not positive.
    pub fn new(positions: &[DVec3], edges: &[[u32; 2]], spacing: f64, step: f64) -> Option<Self> {
        if edges.is_empty() || !(step > 0.0) {
            return None;
        }
        let points: Vec<DVec3> = edges
            .iter()
            .flat_map(|&[a, b]| points_along(positions[a as usize], positions[b as usize], step))
            .collect();
        Some(CreaseBand {
            tree: StaticTree::new(&points),
            spacing,
            step,
        })
    }

    /// The distance from `x` to the nearest feature edge (bbox-100 units), to within half the
    /// step.
    pub fn distance(&self, x: DVec3) -> f64 {
        self.tree
            .nearest(x)
            .map_or(f64::INFINITY, |(_, d2)| d2.sqrt())
    }

    /// Whether a move from `from` to `to` of a sample of relative kernel width `width` is
    /// refused: it ends inside the band (half-width [`CREASE_BAND_PER_SPACING`] · `width` ·
    /// spacing) and nearer to a feature edge than it started.
    ///
    /// Most moves end far from every crease: the distance at `to` is searched only within the
    /// band (a little wider, against rounding), where it is the nearest point's as
    /// [`CreaseBand::distance`] gives it; beyond, the move is taken without the search of
    /// everything.
    pub fn refuses(&self, from: DVec3, to: DVec3, width: f64) -> bool {
        let band = CREASE_BAND_PER_SPACING * width * self.spacing;
        let mut nearest_2 = f64::INFINITY;
        self.tree
            .visit_within(to, band * band * (1.0 + 1e-9), |_, d2| {
                nearest_2 = nearest_2.min(d2);
            });
        let d = nearest_2.sqrt();
        d < band && d < self.distance(from) - 0.5 * self.step
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moves_into_the_band_are_refused_and_moves_out_of_it_taken() {
        // A crease along the x axis from 0 to 4, sampled at 1.
        let positions: Vec<DVec3> = (0..5).map(|i| DVec3::new(i as f64, 0.0, 0.0)).collect();
        let edges = [[0, 1], [1, 2], [2, 3], [3, 4]];
        let band = CreaseBand::new(&positions, &edges, 1.0, 0.01).unwrap();
        assert!((band.distance(DVec3::new(1.5, 0.3, 0.0)) - 0.3).abs() < 0.01);
        let spacing = 1.0;
        // At half the width, the band is half as wide.
        assert!(!band.refuses(DVec3::new(2.5, 0.5, 0.0), DVec3::new(2.5, 0.2, 0.0), 0.5));
        // Towards the crease and into the band: refused.
        assert!(band.refuses(
            DVec3::new(2.5, 0.5, 0.0),
            DVec3::new(2.5, 0.2, 0.0),
            spacing
        ));
        // Onto it, from outside: refused.
        assert!(band.refuses(
            DVec3::new(2.5, 0.4, 0.0),
            DVec3::new(2.5, 0.0, 0.0),
            spacing
        ));
        // Across it: refused.
        assert!(band.refuses(
            DVec3::new(2.5, 0.4, 0.0),
            DVec3::new(2.5, -0.3, 0.0),
            spacing
        ));
        // Along it outside the band, or away from it inside the band: taken.
        assert!(!band.refuses(
            DVec3::new(1.5, 0.5, 0.0),
            DVec3::new(2.5, 0.5, 0.0),
            spacing
        ));
        assert!(!band.refuses(
            DVec3::new(2.5, 0.1, 0.0),
            DVec3::new(2.5, 0.2, 0.0),
            spacing
        ));
        // No edges, no band.
        assert!(CreaseBand::new(&positions, &[], 1.0, 0.01).is_none());
    }

    /// The search within the band decides as the distances to the nearest point do, on moves
    /// that end inside, at the edge of and beyond the band around a bent crease.
    #[test]
    fn the_search_within_the_band_decides_as_the_distances_do() {
        use rand::{RngExt, SeedableRng};
        let positions: Vec<DVec3> = (0..12)
            .map(|i| {
                let t = i as f64 * 0.5;
                DVec3::new(t, (0.7 * t).sin(), 0.2 * t)
            })
            .collect();
        let edges: Vec<[u32; 2]> = (0..11).map(|i| [i, i + 1]).collect();
        let band = CreaseBand::new(&positions, &edges, 1.0, 0.05).unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let (mut refused, mut taken) = (0, 0);
        for _ in 0..4000 {
            let at = |rng: &mut rand_chacha::ChaCha8Rng| {
                DVec3::new(
                    rng.random_range(-0.5..6.0),
                    rng.random_range(-1.5..1.5),
                    rng.random_range(-0.5..1.5),
                )
            };
            let from = at(&mut rng);
            let to = from + 0.3 * (at(&mut rng) - from).normalize_or_zero();
            let width = rng.random_range(0.2..1.0);
            let d = band.distance(to);
            let by_distances = d < CREASE_BAND_PER_SPACING * width * band.spacing
                && d < band.distance(from) - 0.5 * band.step;
            assert_eq!(
                band.refuses(from, to, width),
                by_distances,
                "{from} {to} {width}"
            );
            if by_distances {
                refused += 1;
            } else {
                taken += 1;
            }
        }
        assert!(refused > 50 && taken > 50, "{refused} {taken}");
    }
}
