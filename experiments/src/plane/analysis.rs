//! Blue-noise measures of point sets on the periodic unit square: the normalized Poisson-disk
//! radius (Lagae and Dutré 2008), the periodogram and its radially averaged power and anisotropy
//! (Ulichney 1987, "Digital Halftoning"), as used for the paper's Fig. 11 (Sec. 7.1).
//!
//! References:
//! - A. Lagae, P. Dutré, "A comparison of methods for generating Poisson disk distributions",
//!   Computer Graphics Forum 27(1), 2008, doi:10.1111/j.1467-8659.2007.01100.x.
//! - R. Ulichney, "Digital Halftoning", MIT Press 1987 (radially averaged power spectrum and
//!   anisotropy).
//! - T. Schlömer, "PSA: Point Set Analysis" (2011): frequencies in units of sqrt(n).

use glam::DVec2;
use rayon::prelude::*;
use serde::Serialize;

use super::torus::{dist2, TorusGrid};

/// d_max = sqrt(2 / (sqrt(3) n)): the distance between neighbours when `n` points form the
/// densest (hexagonal) packing of the unit square (Lagae and Dutré 2008, twice their r_max).
pub fn max_min_distance(n: usize) -> f64 {
    (2.0 / (3f64.sqrt() * n as f64)).sqrt()
}

/// The smallest toroidal distance between two of `points` (infinite for fewer than two).
/// A uniform grid with cells about d_max wide finds every pair closer than a cell side; when no
/// pair is that close, all pairs are compared.
pub fn min_toroidal_distance(points: &[DVec2]) -> f64 {
    let n = points.len();
    if n < 2 {
        return f64::INFINITY;
    }
    let side = max_min_distance(n);
    let grid = TorusGrid::with_points(points, side);
    let cell = 1.0 / grid.cells() as f64;
    let mut best2 = f64::INFINITY;
    for (i, &p) in points.iter().enumerate() {
        grid.for_each_near(p, |j| {
            if j as usize != i {
                best2 = best2.min(dist2(p, points[j as usize]));
            }
        });
    }
    if best2 > cell * cell {
        for i in 0..n {
            for j in i + 1..n {
                best2 = best2.min(dist2(points[i], points[j]));
            }
        }
    }
    best2.sqrt()
}

/// The normalized Poisson-disk radius rho = d_min / d_max (Lagae and Dutré 2008): the smallest
/// toroidal distance relative to that of the hexagonal packing ([`max_min_distance`]). 1 for a
/// hexagonal lattice, about 0.75 for good Poisson-disk sets, near 0 for uniform random points.
/// 0 for fewer than two points.
pub fn normalized_poisson_disk_radius(points: &[DVec2]) -> f64 {
    if points.len() < 2 {
        return 0.0;
    }
    min_toroidal_distance(points) / max_min_distance(points.len())
}

/// A periodogram over the integer frequency vectors f = (fx, fy) with |fx|, |fy| <= half_width,
/// normalized so that uniform random points have expected power 1 at every f != 0:
/// P(f) = |Σ_k exp(-2πi f·x_k)|² / n (Ulichney 1987; Lagae and Dutré 2008).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Periodogram {
    /// F: frequencies run over -F..=F on each axis.
    pub half_width: usize,
    /// (2F + 1)² values, row-major: `values[(fy + F) * (2F + 1) + (fx + F)]`. The DC term
    /// (f = 0, where P = n) is excluded: stored as 0.
    pub values: Vec<f64>,
    /// How many point sets were averaged (1 for a single periodogram).
    pub sets: usize,
}

impl Periodogram {
    /// Side of the square array, 2F + 1.
    pub fn side(&self) -> usize {
        2 * self.half_width + 1
    }

    /// P(fx, fy); `None` outside the window.
    pub fn at(&self, fx: i64, fy: i64) -> Option<f64> {
        let f = self.half_width as i64;
        if fx.abs() > f || fy.abs() > f {
            return None;
        }
        Some(self.values[((fy + f) * (2 * f + 1) + fx + f) as usize])
    }

    /// The values as rows (fy = -F first), for JSON and plotting.
    pub fn rows(&self) -> Vec<Vec<f64>> {
        self.values
            .chunks(self.side())
            .map(|r| r.to_vec())
            .collect()
    }
}

/// The periodogram of `points` (positions in [0, 1)²) over |fx|, |fy| <= `half_width`.
///
/// Computed as a product of the per-axis factors exp(-2πi fx x) exp(-2πi fy y): O(n F²) complex
/// multiply-adds, rows in parallel; only fy >= 0 is computed, P(-f) = P(f) gives the rest.
pub fn periodogram(points: &[DVec2], half_width: usize) -> Periodogram {
    let f = half_width;
    let side = 2 * f + 1;
    let n = points.len();
    let tau = std::f64::consts::TAU;
    // Per point, exp(-2πi fx x) for fx = -F..=F (real and imaginary parts apart, for SIMD).
    let mut ex_re = vec![0.0; n * side];
    let mut ex_im = vec![0.0; n * side];
    for (k, p) in points.iter().enumerate() {
        for c in 0..side {
            let fx = c as f64 - f as f64;
            let (s, co) = (-tau * fx * p.x).sin_cos();
            ex_re[k * side + c] = co;
            ex_im[k * side + c] = s;
        }
    }
    let mut values = vec![0.0; side * side];
    let inv_n = if n > 0 { 1.0 / n as f64 } else { 0.0 };
    let upper: Vec<Vec<f64>> = (0..=f)
        .into_par_iter()
        .map(|fy| {
            let (mut re, mut im) = (vec![0.0; side], vec![0.0; side]);
            for (k, p) in points.iter().enumerate() {
                let (b, a) = (-tau * fy as f64 * p.y).sin_cos();
                let xr = &ex_re[k * side..(k + 1) * side];
                let xi = &ex_im[k * side..(k + 1) * side];
                for c in 0..side {
                    re[c] += a * xr[c] - b * xi[c];
                    im[c] += a * xi[c] + b * xr[c];
                }
            }
            re.iter()
                .zip(&im)
                .map(|(r, i)| (r * r + i * i) * inv_n)
                .collect()
        })
        .collect();
    for (fy, row) in upper.iter().enumerate() {
        for c in 0..side {
            values[(fy + f) * side + c] = row[c];
            // P(-fx, -fy) = P(fx, fy).
            values[(f - fy) * side + (side - 1 - c)] = row[c];
        }
    }
    values[f * side + f] = 0.0;
    Periodogram {
        half_width: f,
        values,
        sets: 1,
    }
}

/// The mean of periodograms over the same window (`None` when empty or the windows differ).
pub fn mean_periodogram(ps: &[Periodogram]) -> Option<Periodogram> {
    let first = ps.first()?;
    if ps.iter().any(|p| p.half_width != first.half_width) {
        return None;
    }
    let mut values = vec![0.0; first.values.len()];
    let sets: usize = ps.iter().map(|p| p.sets).sum();
    for p in ps {
        let w = p.sets as f64 / sets as f64;
        for (v, x) in values.iter_mut().zip(&p.values) {
            *v += w * x;
        }
    }
    Some(Periodogram {
        half_width: first.half_width,
        values,
        sets,
    })
}

/// The radially averaged power spectrum and anisotropy of a (mean) periodogram (Ulichney 1987):
/// annulus k (k = 1, 2, ..., F - 1) holds the frequencies f with round(|f|) = k, so every
/// annulus lies wholly inside the window.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RadialSpectrum {
    /// The annulus radius k in integer-frequency units.
    pub radius: Vec<usize>,
    /// k / sqrt(n): frequency in units of sqrt(n) (Schlömer's PSA), where the principal peak of
    /// a hexagonal-like set sits near 1.07 (sqrt(2 / sqrt(3))).
    pub frequency: Vec<f64>,
    /// Mean power over the annulus (white noise: 1).
    pub power: Vec<f64>,
    /// 10 log10(variance / mean²) over the annulus (sample variance, divisor count - 1), in dB;
    /// for an isotropic spectrum averaged over K sets this is about 10 log10(1 / K), the noise
    /// floor (-10 dB at K = 10). `None` for annuli with fewer than 2 values or zero mean.
    pub anisotropy_db: Vec<Option<f64>>,
    /// Frequencies in the annulus.
    pub count: Vec<usize>,
}

/// See [`RadialSpectrum`]. `n` is the number of points (the mean count for sets of different
/// sizes), for the frequency unit sqrt(n).
pub fn radial_spectrum(p: &Periodogram, n: f64) -> RadialSpectrum {
    let f = p.half_width as i64;
    let kmax = p.half_width.saturating_sub(1);
    let mut sums = vec![(0.0f64, 0.0f64, 0usize); kmax + 1];
    for fy in -f..=f {
        for fx in -f..=f {
            let k = ((fx * fx + fy * fy) as f64).sqrt().round() as usize;
            if k == 0 || k > kmax {
                continue;
            }
            let v = p.at(fx, fy).unwrap_or(0.0);
            let s = &mut sums[k];
            s.0 += v;
            s.1 += v * v;
            s.2 += 1;
        }
    }
    let mut out = RadialSpectrum {
        radius: Vec::new(),
        frequency: Vec::new(),
        power: Vec::new(),
        anisotropy_db: Vec::new(),
        count: Vec::new(),
    };
    let unit = n.max(1.0).sqrt();
    for (k, &(sum, sum2, c)) in sums.iter().enumerate().skip(1) {
        let mean = sum / c.max(1) as f64;
        let aniso = if c >= 2 && mean > 0.0 {
            let var = ((sum2 - c as f64 * mean * mean) / (c - 1) as f64).max(0.0);
            Some(10.0 * (var / (mean * mean)).log10())
        } else {
            None
        };
        out.radius.push(k);
        out.frequency.push(k as f64 / unit);
        out.power.push(mean);
        out.anisotropy_db.push(aniso.filter(|a| a.is_finite()));
        out.count.push(c);
    }
    out
}

/// The figures the summary table reports for one radial spectrum.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpectrumSummary {
    /// The largest radial power at frequencies below 0.5 sqrt(n) (the low-frequency band a
    /// blue-noise set keeps empty).
    pub low_frequency_max: f64,
    /// The frequency (units of sqrt(n)) of the principal peak: the largest radial power.
    pub peak_frequency: f64,
    /// The power there.
    pub peak_power: f64,
    /// The anisotropy noise floor 10 log10(1 / sets) in dB (Ulichney 1987).
    pub noise_floor_db: f64,
    /// The smallest and largest anisotropy (dB) over the annuli beyond the principal peak.
    pub anisotropy_beyond_peak_db: (f64, f64),
}

/// Summarizes `r`, a radial spectrum of a periodogram averaged over `sets` point sets.
pub fn summarize(r: &RadialSpectrum, sets: usize) -> SpectrumSummary {
    let low = r
        .frequency
        .iter()
        .zip(&r.power)
        .filter(|(f, _)| **f < 0.5)
        .map(|(_, p)| *p)
        .fold(0.0, f64::max);
    let peak = (0..r.power.len())
        .max_by(|&a, &b| r.power[a].total_cmp(&r.power[b]))
        .unwrap_or(0);
    let beyond = r
        .anisotropy_db
        .iter()
        .skip(peak + 1)
        .flatten()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &a| {
            (lo.min(a), hi.max(a))
        });
    SpectrumSummary {
        low_frequency_max: low,
        peak_frequency: r.frequency.get(peak).copied().unwrap_or(0.0),
        peak_power: r.power.get(peak).copied().unwrap_or(0.0),
        noise_floor_db: -10.0 * (sets.max(1) as f64).log10(),
        anisotropy_beyond_peak_db: beyond,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plane::spectral::uniform_random;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// `rows` rows of `cols` points of a hexagonal lattice fitted to the unit square
    /// (rows even, so it is periodic; nearly equilateral when rows / cols ≈ 2 / sqrt(3)).
    fn hex_lattice(cols: usize, rows: usize) -> Vec<DVec2> {
        let mut v = Vec::new();
        for j in 0..rows {
            for i in 0..cols {
                let x = (i as f64 + 0.5 * (j % 2) as f64) / cols as f64;
                v.push(DVec2::new(x, j as f64 / rows as f64));
            }
        }
        v
    }

    #[test]
    fn rho_of_a_hexagonal_lattice_is_near_one_and_of_random_points_near_zero() {
        // 60 × 70 = 4200 points; spacing 1/60 horizontally, rows sqrt(3)/2 · (1/60) ≈ 1/69.3.
        let hex = hex_lattice(60, 70);
        let rho = normalized_poisson_disk_radius(&hex);
        assert!(
            rho > 0.98 && rho <= 1.0 + 1e-9,
            "hexagonal lattice rho {rho}"
        );
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let random = uniform_random(4096, &mut rng);
        let r = normalized_poisson_disk_radius(&random);
        assert!(r < 0.1, "random rho {r}");
        // The grid search agrees with all pairs.
        let small = &random[..600];
        let mut brute = f64::INFINITY;
        for i in 0..small.len() {
            for j in i + 1..small.len() {
                brute = brute.min(dist2(small[i], small[j]).sqrt());
            }
        }
        assert_eq!(min_toroidal_distance(small), brute);
    }

    #[test]
    fn min_distance_wraps_around_the_square() {
        let pts = [
            DVec2::new(0.001, 0.5),
            DVec2::new(0.999, 0.5),
            DVec2::new(0.5, 0.5),
            DVec2::new(0.5, 0.2),
        ];
        assert!((min_toroidal_distance(&pts) - 0.002).abs() < 1e-12);
    }

    #[test]
    fn periodogram_of_uniform_random_points_averages_one() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let sets: Vec<Periodogram> = (0..4)
            .map(|_| periodogram(&uniform_random(1024, &mut rng), 40))
            .collect();
        let mean = mean_periodogram(&sets).unwrap();
        let side = mean.side();
        let total: f64 = mean.values.iter().sum();
        let avg = total / (side * side - 1) as f64;
        assert!((avg - 1.0).abs() < 0.03, "mean power {avg}");
        assert_eq!(mean.at(0, 0), Some(0.0));
        let r = radial_spectrum(&mean, 1024.0);
        for (p, c) in r.power.iter().zip(&r.count) {
            if *c >= 100 {
                assert!((p - 1.0).abs() < 0.25, "radial power {p} over {c}");
            }
        }
        // Isotropic white noise over 4 sets: anisotropy near the noise floor 10 log10(1/4) =
        // -6 dB. Single annuli scatter (P(f) = P(-f), so an annulus of c values holds c/2
        // independent ones): the median over the well-filled annuli is within 1 dB.
        let s = summarize(&r, 4);
        assert!((s.noise_floor_db + 6.02).abs() < 0.01);
        let mut a: Vec<f64> = r
            .anisotropy_db
            .iter()
            .zip(&r.count)
            .filter(|(_, c)| **c >= 100)
            .map(|(a, _)| a.unwrap())
            .collect();
        a.sort_by(f64::total_cmp);
        let median = a[a.len() / 2];
        assert!(
            (median - s.noise_floor_db).abs() < 1.0,
            "median anisotropy {median} dB"
        );
        assert!(
            a.iter().all(|x| (x - s.noise_floor_db).abs() < 4.0),
            "{a:?}"
        );
    }

    #[test]
    fn periodogram_matches_the_direct_sum_and_is_symmetric() {
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        let pts = uniform_random(50, &mut rng);
        let p = periodogram(&pts, 6);
        for (fx, fy) in [(1i64, 0i64), (-3, 2), (5, -6), (0, 4), (-6, -6)] {
            let (mut re, mut im) = (0.0, 0.0);
            for q in &pts {
                let a = -std::f64::consts::TAU * (fx as f64 * q.x + fy as f64 * q.y);
                re += a.cos();
                im += a.sin();
            }
            let direct = (re * re + im * im) / pts.len() as f64;
            let got = p.at(fx, fy).unwrap();
            assert!((got - direct).abs() < 1e-9 * (1.0 + direct), "({fx},{fy})");
            assert_eq!(p.at(-fx, -fy).unwrap(), got);
        }
    }

    #[test]
    fn lattice_spectrum_has_no_low_frequency_power_and_a_peak_near_one() {
        let hex = hex_lattice(60, 70);
        let n = hex.len() as f64;
        let r = radial_spectrum(&periodogram(&hex, 130), n);
        let s = summarize(&r, 1);
        assert!(s.low_frequency_max < 1e-9, "{}", s.low_frequency_max);
        // The lattice's first ring: |f| = 60 (and 69.3 / cos 30° ≈ 70 / 0.866...), 1/sqrt(n) units.
        assert!(
            s.peak_frequency > 0.85 && s.peak_frequency < 1.25,
            "{}",
            s.peak_frequency
        );
    }
}
