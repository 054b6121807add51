//! Issue 14, items 5 and 6: near-degenerate inputs and extreme parameters run in bounded time and
//! memory. Each input is made here; each run ends with a valid mesh or a one-line error naming
//! what is wrong, and the sample counts that bound the memory are checked against the target.
//!
//! | case | outcome |
//! |---|---|
//! | a strip of nearly colinear faces (area 1e-11, boundary 200 long) | input error, at once |
//! | one sliver triangle of height 1e-7, 10 000 points | result; boundary samples bounded by the target |
//! | a sphere plus one triangle reaching 1e6 away | result; the samples bounded by the target |
//! | a sphere plus one triangle reaching 1e30 away | input error, at once |
//! | `--sigma-p` too small for the boundary curves of a sliver | usage error naming the smallest |
//! | `--sigma-n 1e-4` (a count floor above the target) | result after a few search evaluations |
//! | the binary on each of the above, and the sliver at 100 000 points | ends within a generous timeout (a hang guard) |

mod common;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use glam::DVec3;
use spectral_remesh::{
    check_invariants, remesh, Density, Error, RemeshOutput, RemeshParams, TriMesh,
};

/// A zigzag strip of 18 faces along x in [0, 100], `width` across: its faces are nearly colinear
/// when the width is tiny (area about 100 · width, boundary about 200 long).
fn colinear_strip(width: f64) -> TriMesh {
    let n = 20;
    let positions = (0..n)
        .map(|i| {
            DVec3::new(
                i as f64 * 100.0 / (n - 1) as f64,
                (i % 2) as f64 * width,
                0.0,
            )
        })
        .collect();
    let triangles = (0..n as u32 - 2)
        .map(|i| {
            if i % 2 == 0 {
                [i, i + 1, i + 2]
            } else {
                [i + 1, i, i + 2]
            }
        })
        .collect();
    TriMesh::new(positions, triangles)
}

/// One triangle with base 1 and height `height`.
fn sliver(height: f64) -> TriMesh {
    TriMesh::new(
        vec![DVec3::ZERO, DVec3::X, DVec3::new(0.5, height, 0.0)],
        vec![[0, 1, 2]],
    )
}

/// A unit icosphere (642 vertices) plus one separate triangle from near the sphere to `far`
/// along x.
fn sphere_and_far_triangle(far: f64) -> TriMesh {
    let mut m = common::icosphere(3);
    let k = m.positions.len() as u32;
    m.positions.extend([
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(2.0, 1.0, 0.0),
        DVec3::new(far, 0.0, 0.0),
    ]);
    m.triangles.push([k, k + 1, k + 2]);
    m
}

fn points(n: usize) -> RemeshParams {
    RemeshParams {
        density: Density::Points(n),
        ..RemeshParams::default()
    }
}

/// The output holds the invariants, and the sample counts that bound the run's memory are bounded
/// by the target: the first sigma_p guess expects at most twice the target (from the area alone
/// it gave hundreds of thousands of boundary samples on a sliver), and the boundary samples kept
/// are at most four times the target.
fn assert_bounded_result(out: &RemeshOutput, target: usize) {
    assert!(!out.mesh.triangles.is_empty());
    let violations = check_invariants(&out.mesh);
    assert!(violations.is_empty(), "{violations:?}");
    let first = out.search_history[0].1;
    assert!(
        first <= 2 * target,
        "the first guess gave {first} samples for a target of {target}: {:?}",
        out.search_history
    );
    assert!(
        out.boundary_samples <= 4 * target,
        "{}",
        out.boundary_samples
    );
    assert!(out.samples <= 4 * target, "{}", out.samples);
}

/// The error is an input error whose one-line message says the surface has almost no area.
fn assert_no_area_error(r: Result<RemeshOutput, Error>) {
    match r {
        Err(e @ Error::InvalidMesh { .. }) => {
            let msg = e.to_string();
            assert_eq!(msg.lines().count(), 1, "{msg}");
            assert!(msg.contains("almost no area"), "{msg}");
            assert!(msg.contains("boundary curves"), "{msg}");
        }
        Err(e) => panic!("wrong error: {e}"),
        Ok(o) => panic!(
            "a mesh of {} faces from a degenerate input",
            o.mesh.triangles.len()
        ),
    }
}

#[test]
fn nearly_colinear_faces_are_an_input_error_at_once() {
    // Before: the sigma_p guess from the area (1e-11) put about 2e8 samples on the boundary
    // curves (12.6 GB in 120 s). The error comes before any sampling.
    assert_no_area_error(remesh(
        &colinear_strip(1e-13),
        &RemeshParams::default(),
        &|_| {},
    ));
    assert_no_area_error(remesh(
        &colinear_strip(1e-13),
        &RemeshParams {
            density: Density::InputVertices,
            ..RemeshParams::default()
        },
        &|_| {},
    ));
}

#[test]
fn a_sliver_triangle_gets_boundary_samples_bounded_by_the_target() {
    // Before: 9e5 boundary samples at the first guess, and the run did not end.
    let target = 10_000;
    let out = remesh(&sliver(1e-7), &points(target), &|_| {}).unwrap();
    assert_bounded_result(&out, target);
    assert!(out.target_reached, "{:?}", out.search_history);
    let v = out.mesh.vertex_count() as f64;
    assert!((v - target as f64).abs() <= 0.01 * target as f64, "{v}");
}

#[test]
fn a_sphere_with_a_far_triangle_is_bounded() {
    // 1e6 away: a valid remesh whose sampling is dominated by the long thin triangle (the
    // sphere is 2e-4 across in bbox-100 units, far below the spacing, and the topology table
    // shows it gone). Before: boundary samples from the area-only guess.
    let target = 3000;
    let out = remesh(&sphere_and_far_triangle(1e6), &points(target), &|_| {}).unwrap();
    assert_bounded_result(&out, target);
    // 1e30 away: everything is thinner than rounding in bbox-100 units. Before: an allocation of
    // 2.8e17 bytes aborted the process.
    assert_no_area_error(remesh(
        &sphere_and_far_triangle(1e30),
        &points(target),
        &|_| {},
    ));
}

#[test]
fn sigma_p_too_small_for_the_boundary_curves_is_a_usage_error() {
    // The sliver's area (5e-4 in bbox-100 units) alone would take 5e6 samples at sigma_p 1e-5,
    // within the limit; its boundary curves (200 long) take 2e7 more. Before: the boundary
    // samples were placed, gigabytes of them.
    let params = RemeshParams {
        density: Density::SigmaP(1e-5),
        ..RemeshParams::default()
    };
    match remesh(&sliver(1e-7), &params, &|_| {}) {
        Err(Error::InvalidParameter { name, message }) => {
            assert_eq!(name, "sigma_p");
            assert!(message.contains("smallest sigma_p"), "{message}");
        }
        Err(e) => panic!("wrong error: {e}"),
        Ok(_) => panic!("ran"),
    }
}

fn obj(mesh: &TriMesh) -> String {
    let mut s = String::new();
    for p in &mesh.positions {
        s += &format!("v {:e} {:e} {:e}\n", p.x, p.y, p.z);
    }
    for t in &mesh.triangles {
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

/// Runs the binary with `args`; returns its exit code and stderr. (No wall-clock limit: a test
/// does not depend on the machine's load. The sliver at 100,000 points, once 80 s, is timed in
/// `benches/degenerate.rs`.)
fn run(args: &[&str]) -> (Option<i32>, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_remesh"))
        .args(args)
        .stdout(Stdio::null())
        .output()
        .expect("run remesh");
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn write(dir: &Path, name: &str, mesh: &TriMesh) -> PathBuf {
    let path = dir.join(name);
    std::fs::File::create(&path)
        .and_then(|mut f| f.write_all(obj(mesh).as_bytes()))
        .unwrap();
    path
}

#[test]
fn the_degenerate_inputs_end_through_the_binary() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.obj");
    // The sliver at 100 000 points is all boundary samples: before, every sample's umbrella
    // walked the whole boundary chain (80 s; now 7 s: benches/degenerate.rs).
    let cases: [(&str, TriMesh, &[&str], i32); 5] = [
        ("strip.obj", colinear_strip(1e-13), &[], 3),
        ("sliver.obj", sliver(1e-7), &["--points", "10000"], 0),
        ("sliver100k.obj", sliver(1e-7), &["--points", "100000"], 0),
        ("far6.obj", sphere_and_far_triangle(1e6), &[], 0),
        ("far30.obj", sphere_and_far_triangle(1e30), &[], 3),
    ];
    for (name, mesh, extra, code) in cases {
        let input = write(dir.path(), name, &mesh);
        let mut args = vec![input.to_str().unwrap(), out.to_str().unwrap(), "-q"];
        args.extend_from_slice(extra);
        args.push("--no-distance");
        let (status, err) = run(&args);
        assert_eq!(status, Some(code), "{name}: {err}");
        if code != 0 {
            assert_eq!(err.trim_end().lines().count(), 1, "{name}: {err}");
            assert!(
                err.contains(name) && err.contains("almost no area"),
                "{err}"
            );
        }
    }
}

#[test]
fn a_tiny_sigma_n_ends_after_a_few_evaluations() {
    // sigma_n 1e-4: every face normal of the icosphere is its own neighbourhood, so the count
    // has a floor above the target that no sigma_p goes below. Before: 3 × 16 evaluations, each
    // dearer than the last as sigma_p grew (fandisk: 29 s; now 4 s).
    let params = RemeshParams {
        density: Density::Points(500),
        sigma_n: 1e-4,
        ..RemeshParams::default()
    };
    let out = remesh(&common::icosphere(3), &params, &|_| {}).unwrap();
    assert!(
        out.search_history.len() <= 8,
        "{} evaluations: {:?}",
        out.search_history.len(),
        out.search_history
    );
    assert!(!out.mesh.triangles.is_empty());
}
