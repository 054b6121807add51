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

/// Found by the remesh fuzz target (issue 36's run): a thin box with a vertex pulled 10^12 out
/// and a copy passing through it. Its sliver faces' creases are 100 bbox-100 units long while the
/// count asks for a sigma_p of about 10^-6: the sigma_p search placed every crease's samples
/// before counting them, and took 8 GB. A sigma_p whose curves would take four times the limit
/// is now answered from their lengths.
#[test]
fn fuzz_regression_a_long_crease_at_a_tiny_sigma_p_filled_the_memory() {
    let data = include_bytes!("fuzz/remesh-sliver-crease-memory.bin");
    let dir = tempfile::tempdir().unwrap();
    small_meshes::assert_remesh_is_sound(data, dir.path());
}

/// Found by the remesh fuzz target (issue 36's run): an open box corner whose other faces are
/// slivers at one point. The buried-point test's BVH held two faces, numbered 0 and 2; parry's
/// builder assumes two leaves are numbered 0 and 1 and panicked ("key not present", issue 36's
/// item 1 by another road). BVHs are built through `geometry::bvh::bvh_of` now.
#[test]
fn fuzz_regression_a_bvh_of_two_faces_not_numbered_0_and_1_panicked() {
    let data = include_bytes!("fuzz/remesh-two-leaf-bvh.bin");
    let dir = tempfile::tempdir().unwrap();
    small_meshes::assert_remesh_is_sound(data, dir.path());
}

/// Issue 76, found by the `read_las` target: a LAZ whose LASzip record lists no point items
/// made the laz crate panic ("There should be at least one LazItem"), and a LAS 1.4 extended
/// record announcing 10^19 bytes made the las crate's reservation overflow, and a table of
/// variable-size chunks listing fewer points than the header made the laz crate index past it
/// (a header whose size field is short of its version's hid a LASzip record of no items, and an
/// item declared shorter than its type made the crate split the record past its end);
/// now each is an error naming the file, `remesh` and `simplify` alike.
#[test]
fn fuzz_regression_las_records_the_file_cannot_hold_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&[u8], &str); 7] = [
        (
            include_bytes!("fuzz/read_las-laszip-record-of-no-items.laz"),
            "LASzip record",
        ),
        (
            include_bytes!("fuzz/read_las-extended-record-past-the-end.laz"),
            "extended record",
        ),
        // A table of variable-size chunks listing fewer points than the header: the laz crate
        // indexed past it ("index out of bounds: the len is 0").
        (
            include_bytes!("fuzz/read_las-chunk-table-of-fewer-points.laz"),
            "chunk table lists 0 points",
        ),
        // A LAS 1.2 header whose size field says 226: the crate reads 227 bytes and found a
        // LASzip record of no items one byte past where the check looked.
        (
            include_bytes!("fuzz/read_las-header-size-short-of-its-version.laz"),
            "LASzip record",
        ),
        // A wave packet item declared 20 bytes (its type has 29): the laz crate split the
        // record past its end ("mid > len").
        (
            include_bytes!("fuzz/read_las-item-size-not-its-types.laz"),
            "that type has 29",
        ),
        // Chunks of variable size with the pointwise compressor (no chunk table): the laz
        // crate panicked ("Variable-size chunks, but no chunk table").
        (
            include_bytes!("fuzz/read_las-variable-chunks-without-a-table.laz"),
            "chunks of variable size",
        ),
        // Corrupt compressed extra bytes: the laz crate's arithmetic decoder indexed its table
        // past its end ("index out of bounds: the len is 66 but the index is 96").
        (
            include_bytes!("fuzz/read_las-corrupt-extra-bytes-stream.laz"),
            "compressed points are corrupt",
        ),
    ];
    for (bytes, says) in cases {
        let input = dir.path().join("records.laz");
        std::fs::write(&input, bytes).unwrap();
        let out = dir.path().join("out.ply");
        let (i, o) = (input.to_str().unwrap(), out.to_str().unwrap());
        for args in [
            vec![i, o, "--points", "100"],
            vec!["simplify", i, o, "--points", "10"],
        ] {
            let run = std::process::Command::new(env!("CARGO_BIN_EXE_remesh"))
                .args(&args)
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&run.stderr);
            assert_eq!(run.status.code(), Some(3), "{err}");
            assert!(err.contains("records.laz") && err.contains(says), "{err}");
            assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        }
    }
}

/// Found by the `remesh` target's fixed sample once the sizing field was on by default (and at
/// seed 2 without it): a folded sliver box whose seam corners (vertices 5 and 8) lie a rounding
/// apart, unwelded (the edges at them are slivers). The crease curves along the two coincident
/// edges put a sample of each at the same places; the output wrote them as two vertices, which
/// a reader welds, and the file held a duplicate face and two non-manifold edges. Curve samples
/// that coincide are now one.
#[test]
fn fuzz_regression_curves_along_coincident_edges_gave_duplicate_faces() {
    let dir = tempfile::tempdir().unwrap();
    let input = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz/remesh-coincident-seam-curves.obj");
    let output = dir.path().join("out.obj");
    for seed in 1..=4 {
        // Only crossings may remain (the input passes through itself).
        let _ = small_meshes::run_whole_job(&input, &output, 161, seed);
    }
}
