//! The boundary of a point set's surface, where the data ends (an open scan's outline and its
//! holes), found from the points alone and sampled as a mesh's boundary curves are
//! ([`BoundarySamples`]: samples at the boundary spacing and the directed edges between them).
//!
//! **The edge seen from a point.** A point x of the surface (unit normal n) sees the data through
//! a Gaussian of width h, exp(-d²/h²). The weighted centroid of the points, moved into the
//! tangent plane, lies at x where the data surrounds x, and moves inward near an edge. For data
//! of uniform density ending at a straight edge a distance e from x (positive: x inside), the
//! centroid's offset is σ φ(e/σ) / Φ(e/σ), with σ = h/√2: the mean of a normal distribution cut
//! at the edge (the inverse Mills ratio). One evaluation and the inverse of that function give
//! the edge's distance and direction ([`DataEdges::edge`]); two more at the estimated edge
//! remove most of the straight-edge model's error. This is the boundary test of point-set
//! surfaces (the centroid's shift, as in Guennebaud and Gross, "Algebraic point set surfaces",
//! SIGGRAPH 2007, Sec. 4.3, and Adamson and Alexa, "Anisotropic point set surfaces", 2006),
//! turned into a distance.
//!
//! **Which points are on an edge.** The points within `CANDIDATE_DEPTH` widths inside an edge are
//! taken to it, and an edge point is kept when the half-disc beyond it is empty: at most one
//! point within h of it and more than `MARGIN` h outside, more than h/2 off its tangent plane
//! or facing away from it (the other side of a part thinner than h, round whose rim the surface
//! folds: a closed ear's rim is no edge). Where the data goes on, that region
//! holds about 1.1 ρ h² points (ρ points per unit area): at the least width of
//! `WIDTH_SPACINGS` local spacings (the distance to the 8th nearest point, about
//! √(8/(πρ))), 16 expected, and at most one with probability about 1e-6.
//!
//! **Curves.** The kept edge points are averaged with their neighbours along the edge (the band
//! of estimates collapses to its middle), thinned, and linked into chains: each to its nearest
//! point ahead along the edge when that one's nearest behind is it. Chains of fewer than
//! `MIN_CHAIN` points go (a chance gap in the data is not an edge). The chains are smoothed and
//! resampled at equal arc length, as near the asked spacing as a whole number of steps allows,
//! each sample projected onto the surface. The edges run with the surface on their left, seen
//! from the normals' side.

use glam::DVec3;
use rayon::prelude::*;

use crate::points::rimls::Rimls;
use crate::sampling::curves::BoundarySamples;
use crate::spatial::{DynamicTree, StaticTree};
use crate::surface::SurfaceSample;

/// Least width h of the centroid's Gaussian, in sigma_p.
pub const WIDTH_SIGMA_P: f64 = 2.0;

/// Least width h of the centroid's Gaussian, in local spacings of the data (the distance from a
/// point to its `SPACING_NEIGHBOURS`th nearest): sparse data is seen through a wider window.
pub const WIDTH_SPACINGS: f64 = 2.5;

/// The neighbour whose distance is a point's local spacing.
pub const SPACING_NEIGHBOURS: usize = 8;

/// Points at most this many widths inside the edge are taken to it.
const CANDIDATE_DEPTH: f64 = 0.75;

/// The half-disc test counts points more than this many widths outside the estimated edge.
const MARGIN: f64 = 0.35;

/// The most points the half-disc beyond an edge point may hold.
const MAX_OUTSIDE: usize = 1;

/// The fewest points the half-disc inside an edge point must hold: a strand of stray points
/// (a range scan's flying pixels along a depth jump) is no surface with an edge. Where the data
/// goes on, that half-disc holds about 0.9 ρ h², 14 or more at the least width.
const MIN_INSIDE: usize = 6;

/// Chains of fewer thinned points than this are no edge.
const MIN_CHAIN: usize = 4;

/// Curves shorter than this many spacings are no edge: a hole that small (under about 1.6
/// spacings across) is no gap the output must keep, and a short chain on a closed surface is the
/// noise of a few points (horse, 1M points without normals -> 10k, seed 3: a chain of 4 samples
/// where the estimated normals turn, which left a hole). At 8 spacings face000 lost chains
/// along its slits and kept a crossing pair at one seed of five.
const MIN_CURVE_SPACINGS: f64 = 5.0;

/// Smoothing passes over each chain (each moves a point halfway to its neighbours' mean). With
/// `AVERAGE_SPACINGS`, measured on a square of 20,000 points: samples 0.1 sigma_p from its sides
/// on average, 0.3 at most (4 passes and 1 spacing: 0.37 at most).
const SMOOTHING_PASSES: usize = 8;

/// Edge points are averaged with those within this many spacings.
const AVERAGE_SPACINGS: f64 = 1.5;

/// The Gaussian is cut off at this many widths (its weight there is exp(-6.25) ≈ 0.002). At
/// 2.0 the stage took 5.3 s instead of 6.8 of 14M points -> 300k, but a corner of the square of
/// 5,000 points (seed 1) got boundary samples half a sigma_p outside it and a 16° angle.
const CUTOFF_WIDTHS: f64 = 2.5;

/// The data's edge as seen from a point of the surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeView {
    /// The distance to the edge along `inward` (position units): positive inside the data,
    /// negative outside; infinite where the centroid does not move.
    pub distance: f64,
    /// The unit tangent direction into the data.
    pub inward: DVec3,
}

/// The edges of the data of a RIMLS surface (its support points and their outward normals).
pub struct DataEdges<'a> {
    rimls: &'a Rimls,
    /// Per support point: the data's local spacing there ([`local_spacings`]).
    spacings: &'a [f64],
    /// The least width of the centroid's Gaussian (position units).
    least_width: f64,
}

/// The data's local spacing at each of `rimls`'s points: the distance to its
/// `SPACING_NEIGHBOURS`th nearest (position units; about √(8/(πρ)) for ρ points per unit area).
pub fn local_spacings(rimls: &Rimls) -> Vec<f64> {
    rimls
        .positions()
        .par_iter()
        .map_init(Vec::new, |scratch, &p| {
            rimls.nearest_n(p, SPACING_NEIGHBOURS + 1, scratch);
            scratch.last().map_or(0.0, |&(_, d2)| d2.sqrt())
        })
        .collect()
}

/// 1 - erf(x) for x ≥ 0 (Abramowitz and Stegun 7.1.26, error below 1.5e-7), without the
/// factor exp(-x²).
fn erfc_scaled(x: f64) -> f64 {
    let k = 1.0 / (1.0 + 0.327_591_1 * x);
    k * (0.254_829_592
        + k * (-0.284_496_736 + k * (1.421_413_741 + k * (-1.453_152_027 + k * 1.061_405_429))))
}

/// φ(t) / Φ(t), the standard normal's density over its distribution function (decreasing in t;
/// about -t for t far below 0, going to 0 above).
fn inverse_mills(t: f64) -> f64 {
    let phi0 = 1.0 / (2.0 * std::f64::consts::PI).sqrt();
    let x = t.abs() / std::f64::consts::SQRT_2;
    if t <= 0.0 {
        // Φ(t) = erfc(x)/2 = erfc_scaled(x) exp(-t²/2) / 2: the exponentials cancel.
        phi0 / (0.5 * erfc_scaled(x))
    } else {
        phi0 * (-0.5 * t * t).exp() / (1.0 - 0.5 * erfc_scaled(x) * (-x * x).exp())
    }
}

/// The t with `inverse_mills(t) = m`, within [-8, 8] (bisection).
fn inverse_mills_inverse(m: f64) -> f64 {
    let (mut lo, mut hi) = (-8.0_f64, 8.0_f64);
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        if inverse_mills(mid) > m {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

impl<'a> DataEdges<'a> {
    /// The edges of `rimls`'s data, its points' local spacings `spacings` ([`local_spacings`]),
    /// at a width of at least `WIDTH_SIGMA_P · sigma_p` (position units).
    pub fn new(rimls: &'a Rimls, spacings: &'a [f64], sigma_p: f64) -> Self {
        DataEdges {
            rimls,
            spacings,
            least_width: WIDTH_SIGMA_P * sigma_p,
        }
    }

    /// The centroid's width at support point `i`.
    fn width(&self, i: usize) -> f64 {
        (WIDTH_SPACINGS * self.spacings[i]).max(self.least_width)
    }

    /// The centroid's width at `x`: that of the nearest support point.
    pub fn width_at(&self, x: DVec3) -> Option<f64> {
        self.rimls.nearest(x).map(|(i, _)| self.width(i as usize))
    }

    /// The edge seen from `x` (normal `n`, unit) at the width there ([`DataEdges::width_at`]).
    pub fn edge_at(&self, x: DVec3, n: DVec3) -> Option<EdgeView> {
        self.edge(x, n, self.width_at(x)?)
    }

    /// The edge seen from `x` (normal `n`, unit) through a Gaussian of width `h`. `None` when no
    /// point lies within the cut-off.
    pub fn edge(&self, x: DVec3, n: DVec3, h: f64) -> Option<EdgeView> {
        let inv_h2 = 1.0 / (h * h);
        let (mut sum_w, mut sum) = (0.0, DVec3::ZERO);
        let positions = self.rimls.positions();
        self.rimls
            .visit_within(x, (CUTOFF_WIDTHS * h).powi(2), |i, d2| {
                let w = (-d2 * inv_h2).exp();
                sum_w += w;
                sum += w * (positions[i as usize] - x);
            });
        if !(sum_w > 0.0) {
            return None;
        }
        let v = sum / sum_w;
        let tangent = v - v.dot(n) * n;
        let m = tangent.length();
        let Some(inward) = tangent.try_normalize() else {
            return Some(EdgeView {
                distance: f64::INFINITY,
                inward: n.any_orthonormal_vector(),
            });
        };
        let sigma = h / std::f64::consts::SQRT_2;
        Some(EdgeView {
            distance: sigma * inverse_mills_inverse(m / sigma),
            inward,
        })
    }

    /// The points within `h` of `q` (normal `n`) beyond it: more than `MARGIN · h` outside it
    /// (along `-inward`), more than `h / 2` off its tangent plane (a crease, a tip or a thick
    /// part's other side, which the tangent plane sees edge-on, has points there; a smooth
    /// surface's bend over `h` is far less where `h` is below its radius), or facing away from
    /// `n` (the other side of a part thinner than `h`, an ear or a horn, whose rim is no edge of
    /// the data: the surface folds round it; a smooth sheet's normals turn by far less than
    /// 90° within `h`).
    /// Also returns the points within `h` more than `MARGIN · h` inside and near the tangent
    /// plane: the data the edge bounds.
    fn half_disc_counts(&self, q: DVec3, n: DVec3, inward: DVec3, h: f64) -> (usize, usize) {
        let (positions, normals) = (self.rimls.positions(), self.rimls.normals());
        let (mut outside, mut inside) = (0, 0);
        self.rimls.visit_within(q, h * h, |i, _| {
            let d = positions[i as usize] - q;
            let along = d.dot(inward);
            if along < -MARGIN * h || d.dot(n).abs() > 0.5 * h || normals[i as usize].dot(n) < -0.5
            {
                outside += 1;
            } else if along > MARGIN * h {
                inside += 1;
            }
        });
        (outside, inside)
    }

    /// The edge point a support point near an edge is taken to, with its normal and inward
    /// direction; `None` for a point inside the data or one whose half-disc test fails.
    fn edge_point(&self, i: usize) -> Option<(DVec3, DVec3, DVec3)> {
        let (p, n, h) = (
            self.rimls.positions()[i],
            self.rimls.normals()[i],
            self.width(i),
        );
        let view = self.edge(p, n, h)?;
        if !(view.distance < CANDIDATE_DEPTH * h) {
            return None;
        }
        let mut q = p - view.distance * view.inward;
        let mut inward = view.inward;
        for _ in 0..2 {
            let v = self.edge(q, n, h)?;
            if !(v.distance.abs() <= h) {
                return None;
            }
            q -= v.distance * v.inward;
            inward = v.inward;
        }
        let (outside, inside) = self.half_disc_counts(q, n, inward, h);
        (outside <= MAX_OUTSIDE && inside >= MIN_INSIDE).then_some((q, n, inward))
    }

    /// The data's boundary curves, sampled at `spacing` (position units), on the surface, and
    /// how many curves there are (closed loops and open chains). Deterministic.
    pub fn boundary_samples(&self, spacing: f64) -> (BoundarySamples, usize) {
        let found: Vec<(DVec3, DVec3, DVec3)> = (0..self.rimls.len())
            .into_par_iter()
            .filter_map(|i| self.edge_point(i))
            .collect();
        if found.is_empty() {
            return (BoundarySamples::default(), 0);
        }
        // The band of estimates averaged to its middle: each with the points within a spacing
        // that face the same way.
        let positions: Vec<DVec3> = found.iter().map(|f| f.0).collect();
        let tree = StaticTree::new(&positions);
        let averaged: Vec<(DVec3, DVec3, DVec3)> = found
            .par_iter()
            .map_init(Vec::new, |near, &(q, n, u)| {
                tree.within_unsorted(q, (AVERAGE_SPACINGS * spacing).powi(2), near);
                let (mut sq, mut sn, mut su, mut c) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO, 0.0);
                for &(j, _) in near.iter() {
                    let (qj, nj, uj) = found[j as usize];
                    if uj.dot(u) > 0.5 && nj.dot(n) > 0.5 {
                        sq += qj;
                        sn += nj;
                        su += uj;
                        c += 1.0;
                    }
                }
                let n = sn.try_normalize().unwrap_or(n);
                let u = su - su.dot(n) * n;
                (sq / c, n, u.try_normalize().unwrap_or(u))
            })
            .collect();
        // Thinned in Morton order: none within 0.75 spacing of another.
        let order = crate::geometry::morton::morton_order(
            &averaged.iter().map(|a| a.0).collect::<Vec<_>>(),
        );
        let mut kept: Vec<(DVec3, DVec3, DVec3)> = Vec::new();
        let mut thin = DynamicTree::new();
        let r2 = (0.75 * spacing).powi(2);
        for &i in &order {
            let a = averaged[i as usize];
            if thin.nearest(a.0).is_some_and(|(_, d2)| d2 < r2) {
                continue;
            }
            thin.add(a.0, kept.len() as u32);
            kept.push(a);
        }
        let chains = link_chains(&kept, spacing);
        let mut curves = 0;
        let mut out = BoundarySamples::default();
        for (chain, closed) in chains {
            let pts = smooth(
                &chain.iter().map(|&k| kept[k].0).collect::<Vec<_>>(),
                closed,
            );
            let length: f64 = pts.windows(2).map(|w| w[0].distance(w[1])).sum::<f64>()
                + if closed {
                    pts[pts.len() - 1].distance(pts[0])
                } else {
                    0.0
                };
            if length < MIN_CURVE_SPACINGS * spacing {
                continue;
            }
            curves += 1;
            let normal_of = |k: usize| kept[chain[k.min(chain.len() - 1)]].1;
            resample(&pts, closed, spacing, &mut out, |x, k| {
                match self.rimls.project(x) {
                    Some((p, nn)) if p.distance(x) <= spacing => (p, nn),
                    _ => (x, normal_of(k)),
                }
            });
        }
        (out, curves)
    }
}

/// Links the thinned edge points (position, normal, inward) into chains: each to its nearest
/// point ahead along the edge (direction inward × normal, within 2.5 spacings and a 60° cone,
/// facing the same way) when that point's nearest behind is it. Returns the chains of at least
/// `MIN_CHAIN` points, in order, each with whether it closes.
fn link_chains(kept: &[(DVec3, DVec3, DVec3)], spacing: f64) -> Vec<(Vec<usize>, bool)> {
    let n = kept.len();
    let tree = StaticTree::new(&kept.iter().map(|k| k.0).collect::<Vec<_>>());
    let tangent = |k: usize| kept[k].2.cross(kept[k].1);
    let reach2 = (2.5 * spacing).powi(2);
    let nearest = |i: usize, ahead: bool| -> Option<usize> {
        let mut near = Vec::new();
        tree.within(kept[i].0, reach2, &mut near);
        let t = tangent(i);
        near.iter().map(|&(j, _)| j as usize).find(|&j| {
            let d = kept[j].0 - kept[i].0;
            let along = d.dot(t) * if ahead { 1.0 } else { -1.0 };
            j != i && along > 0.5 * d.length() && tangent(j).dot(t) > 0.5
        })
    };
    let next: Vec<Option<usize>> = (0..n).into_par_iter().map(|i| nearest(i, true)).collect();
    let prev: Vec<Option<usize>> = (0..n).into_par_iter().map(|i| nearest(i, false)).collect();
    let link: Vec<Option<usize>> = (0..n)
        .map(|i| next[i].filter(|&j| prev[j] == Some(i)))
        .collect();
    let mut has_prev = vec![false; n];
    for j in link.iter().flatten() {
        has_prev[*j] = true;
    }
    let mut used = vec![false; n];
    let mut chains = Vec::new();
    let walk = |start: usize, used: &mut Vec<bool>| -> (Vec<usize>, bool) {
        let mut chain = vec![start];
        used[start] = true;
        let mut at = start;
        while let Some(j) = link[at] {
            if j == start {
                return (chain, true);
            }
            if used[j] {
                break;
            }
            used[j] = true;
            chain.push(j);
            at = j;
        }
        (chain, false)
    };
    // Open chains from their first points, then what is left: loops.
    for i in 0..n {
        if !used[i] && !has_prev[i] {
            chains.push(walk(i, &mut used));
        }
    }
    for i in 0..n {
        if !used[i] {
            chains.push(walk(i, &mut used));
        }
    }
    chains.retain(|(c, _)| c.len() >= MIN_CHAIN);
    chains
}

/// `SMOOTHING_PASSES` passes of x ← x/2 + (previous + next)/4 over a chain (an open chain's ends
/// stay).
fn smooth(points: &[DVec3], closed: bool) -> Vec<DVec3> {
    let mut p = points.to_vec();
    let m = p.len();
    for _ in 0..SMOOTHING_PASSES {
        let q = p.clone();
        for k in 0..m {
            let (a, b) = match (closed, k) {
                (true, _) => ((k + m - 1) % m, (k + 1) % m),
                (false, 0) => continue,
                (false, k) if k == m - 1 => continue,
                (false, k) => (k - 1, k + 1),
            };
            p[k] = 0.5 * q[k] + 0.25 * (q[a] + q[b]);
        }
    }
    p
}

/// Resamples the polyline `points` (closed or open) at equal arc-length steps as near `spacing`
/// as a whole number allows (a loop at least 3), placing each through `place(x, k)` (k the
/// polyline point before x), and appends the samples and the edges between them to `out`.
fn resample(
    points: &[DVec3],
    closed: bool,
    spacing: f64,
    out: &mut BoundarySamples,
    place: impl Fn(DVec3, usize) -> (DVec3, DVec3),
) {
    let m = points.len();
    let segments = if closed { m } else { m - 1 };
    let seg = |k: usize| (points[k], points[(k + 1) % m]);
    let lengths: Vec<f64> = (0..segments).map(|k| seg(k).0.distance(seg(k).1)).collect();
    let total: f64 = lengths.iter().sum();
    if !(total > 0.0) {
        return;
    }
    let steps = ((total / spacing).round() as usize).max(if closed { 3 } else { 1 });
    let count = if closed { steps } else { steps + 1 };
    let step = total / steps as f64;
    let base = out.samples.len() as u32;
    let (mut k, mut walked) = (0usize, 0.0);
    for s in 0..count {
        let target = (s as f64 * step).min(total);
        while k + 1 < segments && walked + lengths[k] < target {
            walked += lengths[k];
            k += 1;
        }
        let (a, b) = seg(k);
        let f = if lengths[k] > 0.0 {
            ((target - walked) / lengths[k]).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let (position, normal) = place(a.lerp(b, f), k);
        out.samples.push(SurfaceSample {
            position,
            normal,
            face: 0,
        });
    }
    for s in 0..steps {
        let a = base + s as u32;
        let b = base + ((s + 1) % count) as u32;
        out.edges.push([a, b]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::points::rimls::RimlsParams;
    use rand::{RngExt, SeedableRng};

    #[test]
    fn the_inverse_mills_ratio_inverts() {
        // Φ(0) = 1/2: φ(0)/Φ(0) = 2/√(2π).
        let at0 = inverse_mills(0.0);
        assert!((at0 - 2.0 / (2.0 * std::f64::consts::PI).sqrt()).abs() < 1e-6);
        for t in [-5.0, -1.0, -0.2, 0.0, 0.3, 1.0, 3.0] {
            let back = inverse_mills_inverse(inverse_mills(t));
            assert!((back - t).abs() < 1e-6, "{t} -> {back}");
        }
        // Far below 0 it goes as -t.
        assert!((inverse_mills(-6.0) - 6.0).abs() < 0.2);
    }

    /// `n` uniform points of the unit square in the plane z = 0, normals +z.
    fn square(n: usize, seed: u64) -> Rimls {
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let p: Vec<DVec3> = (0..n)
            .map(|_| DVec3::new(rng.random::<f64>(), rng.random::<f64>(), 0.0))
            .collect();
        let normals = vec![DVec3::Z; n];
        let sigma_p = (1.0 / n as f64).sqrt() * 2.0;
        Rimls::new(p, normals, RimlsParams::new(sigma_p, f64::INFINITY)).unwrap()
    }

    #[test]
    fn the_edge_is_found_from_inside_and_outside() {
        let rimls = square(20_000, 1);
        let sigma_p = rimls.params().sigma_p;
        let spacings = local_spacings(&rimls);
        let edges = DataEdges::new(&rimls, &spacings, sigma_p);
        let h = edges.width_at(DVec3::new(0.5, 0.5, 0.0)).unwrap();
        // The middle of the left side, from half a width inside and from a third outside.
        for x in [0.5 * h, -0.3 * h] {
            let v = edges.edge(DVec3::new(x, 0.5, 0.0), DVec3::Z, h).unwrap();
            assert!((v.distance - x).abs() < 0.25 * h, "{x}: {v:?}, h {h}");
            assert!(v.inward.dot(DVec3::X) > 0.9, "{v:?}");
        }
        // The middle is no candidate for an edge.
        let v = edges.edge(DVec3::new(0.5, 0.5, 0.0), DVec3::Z, h).unwrap();
        assert!(v.distance > CANDIDATE_DEPTH * h, "{v:?}");
    }

    #[test]
    fn a_square_of_points_has_one_loop_along_its_sides() {
        let rimls = square(20_000, 2);
        let sigma_p = rimls.params().sigma_p;
        let spacings = local_spacings(&rimls);
        let edges = DataEdges::new(&rimls, &spacings, sigma_p);
        let (b, curves) = edges.boundary_samples(sigma_p);
        assert_eq!(curves, 1);
        let h = edges.width_at(DVec3::new(0.5, 0.5, 0.0)).unwrap();
        let m = b.samples.len();
        // One closed loop: every sample starts one edge and ends one.
        assert_eq!(b.edges.len(), m, "{m} samples, {} edges", b.edges.len());
        let mut ends = vec![(0, 0); m];
        for &[a, c] in &b.edges {
            ends[a as usize].0 += 1;
            ends[c as usize].1 += 1;
        }
        assert!(ends.iter().all(|&e| e == (1, 1)));
        // About the perimeter at the spacing (the corners cut).
        let expected = 4.0 / sigma_p;
        assert!(
            (m as f64) > 0.9 * expected && (m as f64) < 1.05 * expected,
            "{m} vs {expected}"
        );
        // Every sample away from the corners (rounded over about a width) near a side: within
        // 0.4 sigma_p of it, and 0.15 sigma_p on average.
        let (mut worst, mut sum, mut counted) = (0.0f64, 0.0, 0.0);
        for s in &b.samples {
            let p = s.position;
            let to_side = p.x.min(1.0 - p.x).abs().min(p.y.min(1.0 - p.y).abs());
            if p.x.min(1.0 - p.x) < 1.5 * h && p.y.min(1.0 - p.y) < 1.5 * h {
                continue;
            }
            worst = worst.max(to_side);
            sum += to_side;
            counted += 1.0;
        }
        assert!(
            worst < 0.4 * sigma_p,
            "a sample {worst} from its side (sigma_p {sigma_p})"
        );
        assert!(
            sum / counted < 0.15 * sigma_p,
            "mean {} (sigma_p {sigma_p})",
            sum / counted
        );
        // The surface on the left, seen from +z: the loop runs counter-clockwise.
        let area: f64 = b
            .edges
            .iter()
            .map(|&[a, c]| {
                let (p, q) = (
                    b.samples[a as usize].position,
                    b.samples[c as usize].position,
                );
                p.x * q.y - q.x * p.y
            })
            .sum();
        assert!(area > 0.0, "signed area {area}");
    }

    /// The boundary samples found in `p` (normals `normals`) at `sigma_p`.
    fn boundary_of(p: Vec<DVec3>, normals: Vec<DVec3>, sigma_p: f64) -> BoundarySamples {
        let rimls = Rimls::new(p, normals, RimlsParams::new(sigma_p, f64::INFINITY)).unwrap();
        let spacings = local_spacings(&rimls);
        DataEdges::new(&rimls, &spacings, sigma_p)
            .boundary_samples(sigma_p)
            .0
    }

    #[test]
    fn a_closed_surface_has_no_boundary() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let n = 20_000;
        // Uniform on the sphere: points of the ball, normalized.
        let mut p: Vec<DVec3> = Vec::with_capacity(n);
        while p.len() < n {
            let q = DVec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - 1.0;
            if q.length_squared() <= 1.0 && q.length_squared() > 1e-6 {
                p.push(q.normalize());
            }
        }
        let normals = p.clone();
        let sigma_p = (4.0 * std::f64::consts::PI / n as f64).sqrt() * 2.0;
        let b = boundary_of(p, normals, sigma_p);
        assert!(b.samples.is_empty(), "{} boundary samples", b.samples.len());
    }

    #[test]
    fn a_cube_of_points_has_no_boundary_at_its_creases() {
        // 4,000 points per face of the unit cube, each with its face's normal: the tangent plane
        // of a point near a crease sees the next face edge-on.
        let mut rng = rand::rngs::StdRng::seed_from_u64(4);
        let (mut p, mut normals) = (Vec::new(), Vec::new());
        for axis in 0..3 {
            for side in [0.0, 1.0] {
                let mut n = DVec3::ZERO;
                n[axis] = 2.0 * side - 1.0;
                for _ in 0..4000 {
                    let mut q = DVec3::new(rng.random(), rng.random(), rng.random());
                    q[axis] = side;
                    p.push(q);
                    normals.push(n);
                }
            }
        }
        let sigma_p = (6.0 / 4000.0f64).sqrt() * 2.0;
        let b = boundary_of(p, normals, sigma_p);
        assert!(b.samples.is_empty(), "{} boundary samples", b.samples.len());
    }

    #[test]
    fn a_thin_closed_plate_has_no_boundary_at_its_rim() {
        // Both sides of a closed plate thinner than the kernel (an ear, a horn seen from its
        // side): 10,000 points on each, normals outward. From one side the data ends at the
        // rim within the tangent plane, but the other side lies there, facing away.
        let mut rng = rand::rngs::StdRng::seed_from_u64(5);
        let n = 10_000;
        let sigma_p = (1.0 / n as f64).sqrt() * 2.0;
        let thickness = 0.25 * sigma_p;
        let (mut p, mut normals) = (Vec::new(), Vec::new());
        for (z, normal) in [(0.0, -DVec3::Z), (thickness, DVec3::Z)] {
            for _ in 0..n {
                p.push(DVec3::new(rng.random(), rng.random(), z));
                normals.push(normal);
            }
        }
        let b = boundary_of(p, normals, sigma_p);
        assert!(b.samples.is_empty(), "{} boundary samples", b.samples.len());
    }
}
