//! Inputs the fuzz targets (fuzz/) found failing, kept as tests named after the bug. The reader
//! findings live beside the other reader tests (tests/io.rs, `fuzz_regression_*`).

#[path = "../fuzz/fuzz_targets/noisy_points.rs"]
mod noisy_points;

#[path = "../fuzz/fuzz_targets/small_meshes.rs"]
mod small_meshes;

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

/// The `remesh` fuzz target's checks on 24 inputs of its generator, drawn from a fixed stream of
/// bytes (every shape, with noise and mutations): the whole job on messy small meshes keeps
/// its guarantees (no panic or internal error, a manifold oriented output without degenerate or
/// duplicate faces, every topology change in a note). The fuzz runs found no failing input; these
/// keep the target's checks in the test suite.
#[test]
fn the_remesh_target_checks_hold_on_a_fixed_sample_of_its_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    for _ in 0..24 {
        let data: Vec<u8> = (0..64)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 24) as u8
            })
            .collect();
        small_meshes::assert_remesh_is_sound(&data, dir.path());
    }
}
