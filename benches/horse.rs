//! Benchmark of issue 2: horse at 8600 points, load to write, with the split per stage.
//!
//! `cargo bench --bench horse` (or `-- RUNS MODEL N` to change the defaults 5,
//! ../shared/data/horse.obj, 8600). Runs the whole job (read, remesh, write; no distance
//! measurement) RUNS times and prints the median, minimum and maximum of the total and the
//! median of each stage, in seconds. Wall-clock time on a shared machine is noisy: compare
//! medians, not single runs.

use std::path::PathBuf;
use std::time::Instant;

use spectral_remesh::app::{run_remesh, RemeshJob};
use spectral_remesh::pipeline::{Density, RemeshParams};

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn main() {
    // `cargo bench` passes `--bench`; keep only our positional arguments.
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let runs: usize = args.first().and_then(|s| s.parse().ok()).unwrap_or(5);
    let model = args.get(1).map(PathBuf::from).unwrap_or_else(|| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data/horse.obj")
    });
    let points: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(8600);
    if !model.exists() {
        eprintln!("bench horse: {} not found; skipped", model.display());
        return;
    }
    let dir = std::env::temp_dir().join(format!("spectral-remesh-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary directory");
    let job = RemeshJob {
        input: model.clone(),
        output: dir.join("out.obj"),
        params: RemeshParams {
            density: Density::Points(points),
            ..Default::default()
        },
        strict: false,
        measure_distance: false,
    };
    let mut totals = Vec::new();
    let mut stages: Vec<(String, Vec<f64>)> = Vec::new();
    let mut vertices = 0;
    for _ in 0..runs {
        let t = Instant::now();
        let report = run_remesh(&job, &|_| {}).expect("remesh");
        totals.push(t.elapsed().as_secs_f64());
        vertices = report.topology.vertices;
        for s in &report.stages {
            match stages.iter_mut().find(|x| x.0 == s.stage) {
                Some(x) => x.1.push(s.seconds),
                None => stages.push((s.stage.clone(), vec![s.seconds])),
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    let (lo, hi) = (
        totals.iter().copied().fold(f64::INFINITY, f64::min),
        totals.iter().copied().fold(0.0, f64::max),
    );
    println!(
        "{} --points {points}: {vertices} vertices, {runs} runs",
        model.display()
    );
    println!(
        "load to write: median {:.3} s (min {lo:.3}, max {hi:.3})",
        median(&mut totals)
    );
    for (name, mut v) in stages {
        println!("  {name:<18} {:>7.3} s (median)", median(&mut v));
    }
}
