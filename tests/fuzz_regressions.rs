//! Inputs the fuzz targets (fuzz/) found failing, kept as tests named after the bug. The reader
//! findings live beside the other reader tests (tests/io.rs, `fuzz_regression_*`).

#[path = "../fuzz/fuzz_targets/noisy_points.rs"]
mod noisy_points;

use noisy_points::{assert_triangulation_is_clean, noisy_points as fuzz_points};

/// Found by the triangulate fuzz target: hundreds of samples at the same few positions (the
/// input bytes ran out, so every later point repeated one placement) gave a face with zero area.
#[test]
fn fuzz_regression_coincident_samples_gave_a_degenerate_face() {
    let data = include_bytes!("fuzz/triangulate-coincident-samples.bin");
    let (p, n) = fuzz_points(data);
    assert_triangulation_is_clean(p, &n);
}

/// Found by the triangulate fuzz target: samples on a line (the bytes placed several points at the
/// same (u, v) with noise along one axis) left a hole of three collinear samples, which the
/// clean-up closed with a flat triangle.
#[test]
fn fuzz_regression_collinear_hole_was_closed_by_a_flat_triangle() {
    let data = include_bytes!("fuzz/triangulate-collinear-hole.bin");
    let (p, n) = fuzz_points(data);
    assert_triangulation_is_clean(p, &n);
}
