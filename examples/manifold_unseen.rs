//! Checks of the R^d sampler on manifolds that were not used to choose anything in it (the
//! step, the projection, the sweeps): a trefoil knot in R^3 (a curve whose curvature varies), a
//! flat 3-torus in R^6 and S⁴ in R^5. Seeds 1–5, the library's defaults: the linear scan, then
//! 10 sweeps projected onto the points.
//!
//! `cargo run --release --example manifold_unseen -- trefoil|t3r6|s4r5`
//!
//! Prints per seed the dimension estimated, the count, and the figure after the scan and after
//! resampling: on the knot the gap ratio along arc length (largest gap over smallest), on the
//! others the normalized Poisson-disk radius ρ with geodesic distances (as
//! tests/manifold_sampling.rs defines it; d_max of the densest packing: (√2 V / n)^(1/3) in 3
//! dimensions, (2 V / n)^(1/4) in 4, the D4 lattice).

use std::f64::consts::{PI, TAU};

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use spectral_remesh::{
    resample_manifold, sample_manifold, DataProjection, ManifoldResampleParams,
    ManifoldSampleParams, PointSet,
};

/// `count` samples by the linear scan, then resampled; the scan's samples, the resampled ones
/// and the dimension estimated.
fn run(points: &PointSet, count: usize, seed: u64) -> (PointSet, PointSet, Option<usize>) {
    let params = ManifoldSampleParams {
        count: Some(count),
        seed,
        ..Default::default()
    };
    let picked = sample_manifold(points, &params).expect("sample");
    let scanned = points.subset(&picked.indices);
    let projection = DataProjection::new(points, picked.dimension, seed).expect("projection");
    let params = ManifoldResampleParams {
        seed,
        ..ManifoldResampleParams::new(picked.sigma_p)
    };
    let (out, _) = resample_manifold(&scanned, &projection, &params).expect("resample");
    (scanned, out, picked.dimension)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The smallest `dist` over all pairs of `set`.
fn min_pair(set: &PointSet, dist: &dyn Fn(&[f64], &[f64]) -> f64) -> f64 {
    let mut best = f64::INFINITY;
    for i in 0..set.len() {
        for j in i + 1..set.len() {
            best = best.min(dist(set.position(i), set.position(j)));
        }
    }
    best
}

/// The trefoil (sin t + 2 sin 2t, cos t - 2 cos 2t, -sin 3t).
fn trefoil(t: f64) -> [f64; 3] {
    [
        t.sin() + 2.0 * (2.0 * t).sin(),
        t.cos() - 2.0 * (2.0 * t).cos(),
        -(3.0 * t).sin(),
    ]
}

fn knot(seed: u64) {
    // Arc length on a fine table of the parameter.
    let m = 1_000_000;
    let at = |k: usize| trefoil(TAU * k as f64 / m as f64);
    let mut table = vec![0.0; m + 1];
    for k in 1..=m {
        let (a, b) = (at(k - 1), at(k));
        table[k] = table[k - 1] + (0..3).map(|c| (a[c] - b[c]).powi(2)).sum::<f64>().sqrt();
    }
    let length = table[m];
    let mut rng = ChaCha8Rng::seed_from_u64(900 + seed);
    let x: Vec<f64> = (0..100_000)
        .flat_map(|_| {
            let s: f64 = rng.random_range(0.0..length);
            at(table.partition_point(|&v| v < s).min(m))
        })
        .collect();
    let points = PointSet::new(3, x, None).expect("points");
    let (scanned, out, dim) = run(&points, 200, seed);
    // A sample's arc length: that of the nearest table point.
    let arc = |p: &[f64]| {
        let nearest = (0..m)
            .min_by(|&a, &b| {
                let d = |k: usize| (0..3).map(|c| (p[c] - at(k)[c]).powi(2)).sum::<f64>();
                d(a).total_cmp(&d(b))
            })
            .unwrap_or(0);
        table[nearest]
    };
    let ratio = |set: &PointSet| {
        let mut s: Vec<f64> = (0..set.len()).map(|i| arc(set.position(i))).collect();
        s.sort_by(f64::total_cmp);
        let mut gaps: Vec<f64> = s.windows(2).map(|w| w[1] - w[0]).collect();
        gaps.push(s[0] + length - s[s.len() - 1]);
        gaps.iter().copied().fold(0.0, f64::max) / gaps.iter().copied().fold(length, f64::min)
    };
    println!(
        "trefoil seed {seed}: dim {dim:?}, {} samples, gap ratio {:.3} after the scan, {:.3} resampled",
        out.len(),
        ratio(&scanned),
        ratio(&out)
    );
}

fn blue_noise(which: &str, seed: u64) {
    let mut rng = ChaCha8Rng::seed_from_u64(900 + seed);
    let (d, m, volume, n) = match which {
        "s4r5" => (5, 4, 8.0 * PI * PI / 3.0, 400_000),
        _ => (6, 3, (TAU / 3f64.sqrt()).powi(3), 400_000),
    };
    let r = 1.0 / 3f64.sqrt();
    let mut x = Vec::with_capacity(n * d);
    while x.len() < n * d {
        if which == "s4r5" {
            let v: [f64; 5] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
            let l2 = dot(&v, &v);
            if (1e-6..=1.0).contains(&l2) {
                x.extend(v.map(|c| c / l2.sqrt()));
            }
        } else {
            for _ in 0..3 {
                let a: f64 = rng.random_range(0.0..TAU);
                x.extend([r * a.cos(), r * a.sin()]);
            }
        }
    }
    let points = PointSet::new(d, x, None).expect("points");
    let (scanned, out, dim) = run(&points, 1000, seed);
    let wrap = |a: f64| {
        let a = a.rem_euclid(TAU);
        a.min(TAU - a)
    };
    let geodesic = |p: &[f64], q: &[f64]| -> f64 {
        if which == "s4r5" {
            (dot(p, q) / (dot(p, p) * dot(q, q)).sqrt())
                .clamp(-1.0, 1.0)
                .acos()
        } else {
            let angle = |v: &[f64], k: usize| v[2 * k + 1].atan2(v[2 * k]);
            r * (0..3)
                .map(|k| wrap(angle(p, k) - angle(q, k)).powi(2))
                .sum::<f64>()
                .sqrt()
        }
    };
    let rho = |set: &PointSet| {
        let k = set.len() as f64;
        let d_max = if m == 3 {
            (2f64.sqrt() * volume / k).cbrt()
        } else {
            (2.0 * volume / k).powf(0.25)
        };
        min_pair(set, &geodesic) / d_max
    };
    println!(
        "{which} seed {seed}: dim {dim:?}, {} samples, rho {:.3} after the scan, {:.3} resampled",
        out.len(),
        rho(&scanned),
        rho(&out)
    );
}

fn main() {
    let which = std::env::args().nth(1).unwrap_or_else(|| "t3r6".into());
    for seed in 1..=5 {
        match which.as_str() {
            "trefoil" => knot(seed),
            "t3r6" | "s4r5" => blue_noise(&which, seed),
            other => {
                eprintln!("unknown manifold {other}: trefoil, t3r6 or s4r5");
                std::process::exit(2);
            }
        }
    }
}
