//! The whole `remesh` job as the fuzz targets run it (small_meshes.rs, messy_point_sets.rs) and
//! the checks every run must pass, whatever its input.

use std::path::Path;

use spectral_remesh::{
    run_remesh, Density, Error, QualityReport, RemeshJob, RemeshParams, Violation,
};

/// Runs `remesh input output --points points --seed seed` (no distance measured) and checks what
/// every run must keep: no panic (the caller sees it), never an internal error, no output left
/// by an error, and on success an output written whose only broken invariant, if any, is faces
/// that cross (thin parts are issue 15's subject). Returns the run's result for the caller's own
/// checks.
pub fn run_whole_job(
    input: &Path,
    output: &Path,
    points: usize,
    seed: u64,
) -> Result<QualityReport, Error> {
    let _ = std::fs::remove_file(output);
    let job = RemeshJob {
        input: input.to_path_buf(),
        output: output.to_path_buf(),
        params: RemeshParams {
            density: Density::Points(points),
            seed,
            ..RemeshParams::default()
        },
        measure_distance: false,
        strict: false,
        max_memory: None,
        as_points: false,
        viewpoint: None,
        report: None,
        format: None,
    };
    let result = run_remesh(&job, &|_| {});
    match &result {
        Err(Error::Internal { stage, message }) => {
            panic!("internal error at {stage}: {message}")
        }
        Err(e) => assert!(!output.exists(), "an error with an output written: {e}"),
        Ok(report) => {
            assert!(output.exists(), "no output written");
            for v in &report.invariant_violations {
                assert!(
                    matches!(v, Violation::Crossing { .. }),
                    "the output breaks an invariant: {v}"
                );
            }
        }
    }
    result
}
