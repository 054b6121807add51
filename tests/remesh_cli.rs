//! Runs the `remesh` binary on the shared models and checks the guarantees of issue 2 on its JSON
//! report: vertex count within 1% of --points, manifold, closed where the input is closed, the
//! input's boundary loops kept where it is open.

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

mod common;

fn shared(name: &str) -> PathBuf {
    common::model(name)
}

/// Runs `remesh INPUT OUT --points N --report R` plus `extra`, returns the parsed report and the
/// output path.
fn run(input: &str, out_name: &str, points: usize, extra: &[&str], dir: &Path) -> (Value, PathBuf) {
    let out = dir.join(out_name);
    let report = dir.join(format!("{out_name}.json"));
    let status = Command::new(env!("CARGO_BIN_EXE_remesh"))
        .arg(shared(input))
        .arg(&out)
        .args(["--points", &points.to_string(), "-q", "--report"])
        .arg(&report)
        .args(extra)
        .status()
        .expect("run remesh");
    assert!(status.success(), "remesh {input} failed: {status}");
    let json: Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    (json, out)
}

fn int(v: &Value, path: &[&str]) -> i64 {
    let mut x = v;
    for p in path {
        x = &x[*p];
    }
    x.as_i64()
        .unwrap_or_else(|| panic!("{path:?} is not an integer: {x}"))
}

fn float(v: &Value, path: &[&str]) -> f64 {
    let mut x = v;
    for p in path {
        x = &x[*p];
    }
    x.as_f64()
        .unwrap_or_else(|| panic!("{path:?} is not a number: {x}"))
}

/// Count within 1%, no non-manifold edge or vertex, consistently oriented.
fn assert_manifold_with_count(r: &Value, target: usize, name: &str) {
    let v = int(r, &["topology", "vertices"]);
    assert!(
        (v as f64 - target as f64).abs() <= 0.01 * target as f64,
        "{name}: {v} vertices for --points {target}"
    );
    assert_eq!(int(r, &["topology", "non_manifold_edges"]), 0, "{name}");
    assert_eq!(int(r, &["topology", "non_manifold_vertices"]), 0, "{name}");
    assert_eq!(
        int(r, &["topology", "inconsistent_orientation_edges"]),
        0,
        "{name}"
    );
    assert_eq!(int(r, &["topology", "degenerate_faces"]), 0, "{name}");
    assert_eq!(int(r, &["topology", "duplicate_faces"]), 0, "{name}");
    assert_invariants_hold(r, name);
}

/// The report's invariant check (issue 6): no self-intersection, nothing violated.
fn assert_invariants_hold(r: &Value, name: &str) {
    assert_eq!(int(r, &["self_intersections", "pairs"]), 0, "{name}");
    assert_eq!(
        r["invariant_violations"].as_array().map(|a| a.len()),
        Some(0),
        "{name}: {}",
        r["invariant_violations"]
    );
}

fn assert_closed_genus_0(r: &Value, name: &str) {
    assert_eq!(int(r, &["topology", "boundary_edges"]), 0, "{name}");
    assert_eq!(int(r, &["topology", "euler_characteristic"]), 2, "{name}");
    assert_eq!(int(r, &["topology", "components"]), 1, "{name}");
}

/// The paper's Table 1 Horse row (Öztireli et al. 2010, 8,600 points): θmin, θmin,ave, Qmin,
/// Qave, %θ<30.
const PAPER_HORSE: [f64; 5] = [32.52, 53.01, 0.5844, 0.9057, 0.0];

/// The horse acceptance at seeds 1 to 5, each seed on its own, against the paper's Table 1 Horse
/// row:
/// - no angle below 30° (the row's %θ<30 = 0; so θmin ≥ 30°, where the paper's seed has 32.52);
/// - Qmin at least the row's 0.5844;
/// - θmin,ave within 1° of the row's 53.01 and Qave within 0.01 of its 0.9057 (ours sit about
///   0.4° and 0.004 below them);
/// - closed genus 0, manifold, count within 1%, every invariant;
/// - Hausdorff at most σ_p / 2 (no point of either surface farther than half the sampling
///   spacing from the other) and RMS at most σ_p / 20, in bbox-100 units.
#[test]
#[ignore = "needs ../shared: .ci/run runs it"]
fn shared_horse_at_8600_meets_the_table_1_row_at_seeds_1_to_5() {
    let dir = tempfile::tempdir().unwrap();
    let [_theta_min, theta_min_ave, q_min, q_ave, pct] = PAPER_HORSE;
    for seed in 1..=5 {
        let name = format!("horse-{seed}.obj");
        let (r, _) = run(
            "horse.obj",
            &name,
            8600,
            &["--seed", &seed.to_string()],
            dir.path(),
        );
        let what = format!("horse seed {seed}");
        assert_manifold_with_count(&r, 8600, &what);
        assert_closed_genus_0(&r, &what);
        let t = &r["triangles"];
        let get = |k: &str| float(&r, &["triangles", k]);
        assert_eq!(get("pct_theta_below_30"), pct, "{what}: {t}");
        assert!(get("theta_min") >= 30.0, "{what}: {t}");
        assert!(get("q_min") >= q_min, "{what}: {t}");
        assert!(get("theta_min_ave") >= theta_min_ave - 1.0, "{what}: {t}");
        assert!(get("q_ave") >= q_ave - 0.01, "{what}: {t}");
        let sigma_p = float(&r, &["extra", "sigma_p"]);
        let d = &r["distance"];
        assert!(
            float(&r, &["distance", "hausdorff"]) <= 0.5 * sigma_p,
            "{what}: {d}"
        );
        assert!(
            float(&r, &["distance", "rms"]) <= 0.05 * sigma_p,
            "{what}: {d}"
        );
    }
}

#[test]
fn spot_obj_and_glb_give_the_same_closed_manifold() {
    let dir = tempfile::tempdir().unwrap();
    let (a, out_a) = run("spot.obj", "a.obj", 3000, &["--no-distance"], dir.path());
    let (b, out_b) = run("spot.glb", "b.obj", 3000, &["--no-distance"], dir.path());
    assert_manifold_with_count(&a, 3000, "spot.obj");
    assert_closed_genus_0(&a, "spot.obj");
    assert_eq!(a["topology"], b["topology"]);
    for key in [
        "theta_min",
        "theta_min_ave",
        "q_min",
        "q_ave",
        "pct_theta_below_30",
    ] {
        let (x, y) = (
            float(&a, &["triangles", key]),
            float(&b, &["triangles", key]),
        );
        assert!((x - y).abs() <= 1e-5 * (1.0 + x.abs()), "{key}: {x} vs {y}");
    }
    // The .glb holds the same surface in f32: the outputs have the same faces and positions that
    // agree to 1e-4 of the diagonal (the input's f32 rounding, about 1e-7 of it, passes through
    // the relaxation's and the fit's 13 steps of projections onto the input).
    let (ma, _) = spectral_remesh::read_mesh(&out_a).unwrap();
    let (mb, _) = spectral_remesh::read_mesh(&out_b).unwrap();
    assert_eq!(ma.triangles, mb.triangles);
    let diag = ma.bbox().unwrap().diagonal();
    for (p, q) in ma.positions.iter().zip(&mb.positions) {
        assert!(p.distance(*q) <= 1e-4 * diag, "{p} vs {q}");
    }
}

#[test]
fn the_same_seed_gives_the_same_bytes_and_another_seed_does_not() {
    let dir = tempfile::tempdir().unwrap();
    let (_, a) = run(
        "spot.obj",
        "s1.ply",
        1500,
        &["--seed", "7", "--no-distance"],
        dir.path(),
    );
    let (_, b) = run(
        "spot.obj",
        "s2.ply",
        1500,
        &["--seed", "7", "--no-distance"],
        dir.path(),
    );
    let (_, c) = run(
        "spot.obj",
        "s3.ply",
        1500,
        &["--seed", "8", "--no-distance"],
        dir.path(),
    );
    let (a, b, c) = (
        std::fs::read(a).unwrap(),
        std::fs::read(b).unwrap(),
        std::fs::read(c).unwrap(),
    );
    assert_eq!(a, b);
    assert_ne!(a, c);
}

#[test]
#[ignore = "needs ../shared: .ci/run runs it"]
fn shared_bunny_keeps_its_five_holes_as_five_boundary_loops() {
    let dir = tempfile::tempdir().unwrap();
    let (r, _) = run(
        "stanford-bunny.obj",
        "bunny.obj",
        9635,
        &["--no-distance"],
        dir.path(),
    );
    assert_manifold_with_count(&r, 9635, "bunny");
    assert_eq!(int(&r, &["topology", "boundary_loops"]), 5);
    assert_eq!(int(&r, &["topology", "components"]), 1);
    // A sphere with five holes.
    assert_eq!(int(&r, &["topology", "euler_characteristic"]), -3);
}

#[test]
#[ignore = "needs ../shared: .ci/run runs it"]
fn shared_fandisk_at_6000_is_a_closed_manifold() {
    let dir = tempfile::tempdir().unwrap();
    let (r, _) = run(
        "fandisk.obj",
        "fandisk.obj",
        6000,
        &["--no-distance"],
        dir.path(),
    );
    assert_manifold_with_count(&r, 6000, "fandisk");
    assert_closed_genus_0(&r, "fandisk");
}

/// With `--feature-angle`, the report says what was found and kept, in the notes and in
/// `extra.features`; by default a part's creases are found and kept the same way, a scan's folds
/// are found and left out with a note saying why; with `--no-features`, nothing is said of
/// creases.
#[test]
#[ignore = "needs ../shared: .ci/run runs it"]
fn shared_the_report_states_the_sharp_features_found_and_kept() {
    let dir = tempfile::tempdir().unwrap();
    let notes = |r: &Value| -> Vec<String> {
        r["notes"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|n| n.as_str().map(str::to_string))
            .collect()
    };
    for (name, args) in [
        (
            "fandisk-features.obj",
            &["--no-distance", "--feature-angle", "20"][..],
        ),
        ("fandisk-auto.obj", &["--no-distance"][..]),
    ] {
        let (r, _) = run("fandisk.obj", name, 6000, args, dir.path());
        let notes = notes(&r);
        let note = notes
            .iter()
            .find(|n| n.starts_with("sharp features at 20°"))
            .unwrap_or_else(|| panic!("{name}: no sharp-feature note in {notes:?}"));
        let edges = int(&r, &["extra", "features", "edges"]);
        assert!(
            edges > 0 && note.contains(&format!("{edges} crease edges")),
            "{note}"
        );
        let sampled = int(&r, &["extra", "features", "sampled_edges"]);
        assert_eq!(int(&r, &["extra", "features", "kept_edges"]), sampled);
        assert!(
            note.contains(&format!("all {sampled} crease edges")),
            "{note}"
        );
    }
    // A scan: its folds are found, said, and not sampled.
    let (r, _) = run(
        "spot.obj",
        "spot-auto.obj",
        2000,
        &["--no-distance"],
        dir.path(),
    );
    let spot_notes = notes(&r);
    assert!(
        spot_notes
            .iter()
            .any(|n| n.starts_with("sharp features (automatic") && n.contains("a scan's folds")),
        "{spot_notes:?}"
    );
    assert!(int(&r, &["extra", "features", "edges"]) > 0);
    assert_eq!(int(&r, &["extra", "features", "sampled_edges"]), 0);
    assert_eq!(r["extra"]["features"]["automatic_kept"], Value::Bool(false));
    let (r, _) = run(
        "fandisk.obj",
        "fandisk-plain.obj",
        2000,
        &["--no-distance", "--no-features"],
        dir.path(),
    );
    assert!(notes(&r).iter().all(|n| !n.contains("sharp features")));
    assert_eq!(int(&r, &["extra", "features", "edges"]), 0);
}

/// What already holds on cow: a manifold within 1% of the count with no boundary edge, and the
/// input's non-manifold vertex said in the notes.
#[test]
#[ignore = "needs ../shared: .ci/run runs it"]
fn shared_cow_at_3000_is_manifold_without_holes_and_reports_its_non_manifold_vertex() {
    let dir = tempfile::tempdir().unwrap();
    let (r, _) = run("cow.obj", "cow.obj", 3000, &["--no-distance"], dir.path());
    assert_manifold_with_count(&r, 3000, "cow");
    assert_eq!(int(&r, &["topology", "boundary_edges"]), 0);
    assert_eq!(int(&r, &["input_topology", "non_manifold_vertices"]), 1);
    let notes = r["notes"].to_string();
    assert!(notes.contains("non-manifold"), "{notes}");
}

/// Seeds 1 to 5, at 2000 and 3000 points: the horns and ears, thin parts close together, no
/// longer come out in pieces with crossing faces (the restricted Delaunay triangulation, issue
/// 15), and the tail stays joined to the rump: one part, as the input is (issue 75). The tail is
/// its own closed shell in the input, sunk into the rump (71 pairs of input faces cross there)
/// and joined to it at one non-manifold vertex; where the restricted Voronoi cells there are
/// not discs, samples are inserted (the topological ball property). Without those insertions
/// the tail came out as one or two shells of its own at seeds 1, 2, 4 and 5 of 3000.
#[test]
#[ignore = "needs ../shared: .ci/run runs it"]
fn shared_cow_at_3000_is_a_closed_manifold_without_crossings() {
    let dir = tempfile::tempdir().unwrap();
    for n in [2000, 3000] {
        for seed in 1..=5 {
            let name = format!("cow-{n}-{seed}.obj");
            let s = seed.to_string();
            let (r, _) = run(
                "cow.obj",
                &name,
                n,
                &["--no-distance", "--seed", &s],
                dir.path(),
            );
            assert_manifold_with_count(&r, n, &name);
            assert_eq!(int(&r, &["topology", "boundary_edges"]), 0, "{name}");
            assert_eq!(int(&r, &["topology", "components"]), 1, "{name}");
            assert_eq!(int(&r, &["topology", "euler_characteristic"]), 2, "{name}");
            assert_eq!(int(&r, &["self_intersections", "pairs"]), 0, "{name}");
        }
    }
}

/// At seed 1 only: at 3000 points, seeds 2 and 3 leave crossing faces (issue 15).
#[test]
fn beetle_comes_out_without_violated_invariants() {
    // Open, 47 non-manifold edges, 32 pairs of its own faces crossing: at its own vertex count
    // and at 3000 the output is manifold, oriented and free of self-intersections. (Not under
    // --strict: a non-manifold input's counts are not a manifold output's, so its topology
    // changes are listed, and --strict would refuse them.)
    let dir = tempfile::tempdir().unwrap();
    for n in [1148, 3000] {
        let (r, out) = run(
            "beetle.obj",
            &format!("beetle-{n}.obj"),
            n,
            &["--no-distance"],
            dir.path(),
        );
        assert_invariants_hold(&r, "beetle");
        assert_eq!(int(&r, &["topology", "non_manifold_edges"]), 0);
        assert!(out.exists());
    }
}

/// Two open square sheets through each other, as an OBJ: sheet A in the plane y = 0
/// (x, z in [-1, 1]), sheet B in the plane x = 0 (y in [-1, 1], z in [-0.5, 0.5]), so B's
/// boundary edges pass through A's interior. The sheets share no vertex (21 and 20 cells a side),
/// and any two surfaces close to them must still cross: every faithful output breaks the
/// no-self-intersection invariant.
fn crossing_sheets_obj() -> String {
    let mut obj = String::new();
    let mut base = 1;
    let mut grid = |n: usize, at: &dyn Fn(f64, f64) -> [f64; 3]| {
        for i in 0..=n {
            for j in 0..=n {
                let p = at(i as f64 / n as f64, j as f64 / n as f64);
                obj += &format!("v {} {} {}\n", p[0], p[1], p[2]);
            }
        }
        for i in 0..n {
            for j in 0..n {
                let a = base + i * (n + 1) + j;
                let (b, c) = (a + 1, a + n + 1);
                obj += &format!("f {a} {c} {b}\nf {b} {c} {}\n", c + 1);
            }
        }
        base += (n + 1) * (n + 1);
    };
    grid(21, &|u, v| [2.0 * u - 1.0, 0.0, 2.0 * v - 1.0]);
    grid(20, &|u, v| [0.0, 2.0 * u - 1.0, v - 0.5]);
    obj
}

#[test]
fn strict_refuses_to_write_a_mesh_that_breaks_its_invariants() {
    // Without --strict the report lists the crossing pairs and the mesh is written; with it,
    // exit 1 (internal), one line, nothing written.
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("sheets.obj");
    std::fs::write(&input, crossing_sheets_obj()).unwrap();
    let out = dir.path().join("out.obj");
    let report = dir.path().join("out.json");
    let status = Command::new(env!("CARGO_BIN_EXE_remesh"))
        .arg(&input)
        .arg(&out)
        .args(["--points", "2000", "--no-distance", "-q", "--report"])
        .arg(&report)
        .status()
        .unwrap();
    assert!(status.success());
    let r: Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let pairs = int(&r, &["self_intersections", "pairs"]);
    let violations = r["invariant_violations"].as_array().unwrap();
    assert!(pairs > 0, "{r}");
    assert_eq!(violations.len(), 1, "{r}");
    assert_eq!(violations[0]["kind"], "Crossing");
    assert_eq!(int(&violations[0], &["count"]), pairs);
    assert!(out.exists());
    let notes = r["notes"].as_array().unwrap();
    assert!(notes
        .iter()
        .any(|n| n.as_str().unwrap().contains("breaks its invariants")));
    let strict_out = dir.path().join("strict.obj");
    let o = Command::new(env!("CARGO_BIN_EXE_remesh"))
        .arg(&input)
        .arg(&strict_out)
        .args(["--points", "2000", "--no-distance", "--strict", "-q"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("invariant check") && err.contains("not written"),
        "{err}"
    );
    assert!(!strict_out.exists());
    // The input, the first run's mesh and report, no temporary file.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 3);
}

#[test]
fn bad_input_is_a_one_line_error_with_a_nonzero_exit_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nf 1 2 3\n").unwrap();
    let out = dir.path().join("out.obj");
    let o = Command::new(env!("CARGO_BIN_EXE_remesh"))
        .arg(&bad)
        .arg(&out)
        .args(["--points", "100"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(3));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("bad.obj"), "{err}");
    assert!(!out.exists());
    // The output path equal to the input path is refused.
    let o = Command::new(env!("CARGO_BIN_EXE_remesh"))
        .arg(shared("spot.obj"))
        .arg(shared("spot.obj"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn points_subcommand_writes_a_point_set_on_the_surface() {
    use spectral_remesh::internal::PointReader;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("spot-points.ply");
    let status = Command::new(env!("CARGO_BIN_EXE_remesh"))
        .args(["points"])
        .arg(shared("spot.obj"))
        .arg(&out)
        .args(["--count", "2000", "--seed", "5"])
        .status()
        .unwrap();
    assert!(status.success());
    let mut r = PointReader::open(&out).unwrap();
    assert_eq!(r.count(), 2000);
    assert!(r.has_normals());
    let mut pts = Vec::new();
    assert_eq!(r.read_chunk(&mut pts, 5000).unwrap(), 2000);
    // On the surface: each point within float precision of the input mesh.
    let (mesh, _) = spectral_remesh::read_mesh(&shared("spot.obj")).unwrap();
    let surface = spectral_remesh::internal::MeshSurface::new(&mesh).unwrap();
    for p in &pts {
        let sp = surface.closest_point(p.position).unwrap();
        assert!(
            sp.distance < 1e-5,
            "{:?} is {} off",
            p.position,
            sp.distance
        );
        assert!((p.normal.length() - 1.0).abs() < 1e-5);
    }
}

#[test]
fn simplify_a_point_set_without_normals_estimates_outward_normals() {
    use spectral_remesh::internal::PointReader;
    let dir = tempfile::tempdir().unwrap();
    let (mesh, _) = spectral_remesh::read_mesh(&shared("spot.obj")).unwrap();
    // Dense points without normals: 40k surface points, written as ascii PLY with x y z only.
    let dense = dir.path().join("dense.ply");
    spectral_remesh::internal::write_surface_points(&mesh, 40_000, 2, &dense).unwrap();
    let mut r = PointReader::open(&dense).unwrap();
    let mut pts = Vec::new();
    r.read_chunk(&mut pts, 100_000).unwrap();
    let input = dir.path().join("xyz.ply");
    let mut text = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\nend_header\n",
        pts.len()
    );
    for p in &pts {
        text.push_str(&format!(
            "{} {} {}\n",
            p.position.x, p.position.y, p.position.z
        ));
    }
    std::fs::write(&input, text).unwrap();
    let out = dir.path().join("out.ply");
    let o = Command::new(env!("CARGO_BIN_EXE_remesh"))
        .arg("simplify")
        .arg(&input)
        .arg(&out)
        .args(["--points", "2000", "-q"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut r = PointReader::open(&out).unwrap();
    let n = r.count() as usize;
    assert!((1700..=2300).contains(&n), "{n} samples");
    let mut samples = Vec::new();
    r.read_chunk(&mut samples, n).unwrap();
    let surface = spectral_remesh::internal::MeshSurface::new(&mesh).unwrap();
    let outward = samples
        .iter()
        .filter(|p| {
            let sp = surface.closest_point(p.position).unwrap();
            (p.normal.length() - 1.0).abs() < 1e-4 && p.normal.dot(surface.smooth_normal(&sp)) > 0.5
        })
        .count();
    assert!(
        outward as f64 >= 0.99 * n as f64,
        "{outward} of {n} outward"
    );
}

#[test]
fn simplify_levels_from_xyz_text_writes_a_level_attribute() {
    use spectral_remesh::internal::PointReader;
    let dir = tempfile::tempdir().unwrap();
    let (mesh, _) = spectral_remesh::read_mesh(&shared("spot.obj")).unwrap();
    let dense = dir.path().join("dense.ply");
    spectral_remesh::internal::write_surface_points(&mesh, 30_000, 4, &dense).unwrap();
    let mut pts = Vec::new();
    PointReader::open(&dense)
        .unwrap()
        .read_chunk(&mut pts, 100_000)
        .unwrap();
    // XYZ text with normals: x y z nx ny nz per line.
    let input = dir.path().join("spot.xyz");
    let mut text = String::from("# spot, 30k points\n");
    for p in &pts {
        let (a, n) = (p.position, p.normal);
        text += &format!("{} {} {} {} {} {}\n", a.x, a.y, a.z, n.x, n.y, n.z);
    }
    std::fs::write(&input, text).unwrap();
    let out = dir.path().join("levels.ply");
    let o = Command::new(env!("CARGO_BIN_EXE_remesh"))
        .arg("simplify")
        .arg(&input)
        .arg(&out)
        .args(["--levels", "2,6,3.5"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    // The file: a uchar level after x y z (double) and nx ny nz (float), non-decreasing from 1
    // to 3.
    let bytes = std::fs::read(&out).unwrap();
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let header = String::from_utf8_lossy(&bytes[..end]);
    assert!(header.contains("property uchar level\n"), "{header}");
    let records = &bytes[end..];
    assert_eq!(records.len() % 37, 0);
    let levels: Vec<u8> = records.chunks_exact(37).map(|r| r[36]).collect();
    assert_eq!(levels[0], 1);
    assert_eq!(*levels.last().unwrap(), 3);
    assert!(levels.windows(2).all(|w| w[0] <= w[1]));
    // Each level's size as reported: |P_l| = the samples of level <= l.
    for l in 1..=3u8 {
        let size = levels.iter().filter(|&&v| v <= l).count();
        let line = format!("|P{l}| = {size} ");
        assert!(stdout.contains(&line), "{line} not in:\n{stdout}");
    }
    // The standard reader skips the level and reads the points.
    let r = PointReader::open(&out).unwrap();
    assert_eq!(r.count() as usize, levels.len());
    assert!(r.has_normals());
    // --levels with --points is a usage error.
    let o = Command::new(env!("CARGO_BIN_EXE_remesh"))
        .arg("simplify")
        .arg(&input)
        .arg(&out)
        .args(["--levels", "2,1", "--points", "100"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}

/// Runs `remesh` with `args`, returning its output (stdout and stderr captured, not a terminal).
fn remesh_output(args: &[&std::ffi::OsStr]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_remesh"))
        .args(args)
        .output()
        .expect("run remesh")
}

/// Issue 14, item 10: `-` as the output writes the mesh to standard output, OBJ unless
/// `--format` asks for another format, with the report on standard error so that standard
/// output holds the mesh only; the bytes are the ones a file gets. `--strict` writes nothing
/// there when it fails, and point sets (streamed to a file) refuse `-` as a usage error.
#[test]
fn a_dash_output_writes_the_mesh_to_standard_output() {
    use std::ffi::OsStr;
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("sphere.obj");
    let sphere = common::icosphere(3);
    std::fs::write(&input, sphere_obj(&sphere)).unwrap();
    let args = ["--points", "300", "--no-distance", "--seed", "3"].map(OsStr::new);
    for (format, ext) in [
        (None, "obj"),
        (Some("ply"), "ply"),
        (Some("glb"), "glb"),
        (Some("stl"), "stl"),
        (Some("off"), "off"),
    ] {
        let file = dir.path().join(format!("file.{ext}"));
        let o = remesh_output(
            &[
                &[input.as_os_str(), file.as_os_str(), OsStr::new("-q")],
                &args[..],
            ]
            .concat(),
        );
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let mut dash: Vec<&OsStr> = vec![input.as_os_str(), OsStr::new("-")];
        dash.extend_from_slice(&args);
        if let Some(f) = format {
            dash.extend([OsStr::new("--format"), OsStr::new(f)]);
        }
        let o = remesh_output(&dash);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        // The report went to standard error, the mesh alone to standard output.
        assert!(err.contains("-> standard output"), "{err}");
        assert!(err.contains("Triangles (Table 1)"), "{err}");
        assert_eq!(
            o.stdout,
            std::fs::read(&file).unwrap(),
            "--format {format:?}"
        );
        // And the crate's reader reads it back as the file's mesh.
        let piped = dir.path().join(format!("piped.{ext}"));
        std::fs::write(&piped, &o.stdout).unwrap();
        let (a, _) = spectral_remesh::read_mesh(&piped).unwrap();
        let (b, _) = spectral_remesh::read_mesh(&file).unwrap();
        assert_eq!(a, b);
        assert!(
            (295..=305).contains(&a.vertex_count()),
            "{}",
            a.vertex_count()
        );
    }
    // --format with a file must agree with its extension.
    let o = remesh_output(&[
        input.as_os_str(),
        dir.path().join("x.obj").as_os_str(),
        OsStr::new("--format"),
        OsStr::new("ply"),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--format ply contradicts"));
    // --strict on a mesh that breaks its invariants: nothing on standard output.
    let sheets = dir.path().join("sheets.obj");
    std::fs::write(&sheets, crossing_sheets_obj()).unwrap();
    let o = remesh_output(
        &["--points", "2000", "--no-distance", "--strict", "-q"]
            .map(OsStr::new)
            .iter()
            .copied()
            .chain([sheets.as_os_str(), OsStr::new("-")])
            .collect::<Vec<_>>(),
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(o.stdout.is_empty(), "{} bytes written", o.stdout.len());
    // Point sets need a file.
    for sub in ["points", "simplify"] {
        let mut a = vec![OsStr::new(sub), input.as_os_str(), OsStr::new("-")];
        a.extend(if sub == "points" {
            ["--count", "10"].map(OsStr::new)
        } else {
            ["--points", "10"].map(OsStr::new)
        });
        let o = remesh_output(&a);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{sub}: {err}");
        assert!(err.contains("standard output"), "{sub}: {err}");
        assert!(o.stdout.is_empty());
    }
}

/// `mesh` as OBJ text.
fn sphere_obj(mesh: &spectral_remesh::TriMesh) -> String {
    let mut s = String::new();
    for p in &mesh.positions {
        s += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    for t in &mesh.triangles {
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

/// Waits (up to 60 s) until `dir` holds an entry whose name `wanted` accepts; its name.
fn wait_for_entry(dir: &Path, wanted: impl Fn(&str) -> bool) -> String {
    let start = std::time::Instant::now();
    while start.elapsed().as_secs() < 60 {
        if let Some(name) = std::fs::read_dir(dir)
            .unwrap()
            .filter_map(|e| e.ok()?.file_name().into_string().ok())
            .find(|n| wanted(n))
        {
            return name;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    panic!("nothing appeared in {}", dir.display());
}

/// Sends `signal` (`INT`, `TERM`) to the child and waits for it; its exit code.
fn signal_and_wait(child: &mut std::process::Child, signal: &str) -> Option<i32> {
    let sent = Command::new("kill")
        .args([format!("-{signal}"), child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    child.wait().unwrap().code()
}

/// Issue 14, item 8: an interrupted run left its temporary output (`remesh points`) or its
/// bucket folder (`remesh simplify`) behind. On SIGINT or SIGTERM both are removed, the target
/// stays absent, and the exit code is 130.
#[test]
fn an_interrupted_run_leaves_no_temporary_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("points.ply");
    // 10^8 points take far longer than the interrupt.
    let mut child = Command::new(env!("CARGO_BIN_EXE_remesh"))
        .args(["points", shared("spot.obj").to_str().unwrap()])
        .arg(&out)
        .args(["--count", "100000000"])
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let tmp = wait_for_entry(dir.path(), |n| n.ends_with(".tmp"));
    assert_eq!(signal_and_wait(&mut child, "INT"), Some(130), "{tmp}");
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "{tmp} left"
    );

    // simplify: the buckets go to TMPDIR, here a folder of the test's own.
    let input = dir.path().join("input.ply");
    let made = Command::new(env!("CARGO_BIN_EXE_remesh"))
        .args(["points", shared("spot.obj").to_str().unwrap()])
        .arg(&input)
        .args(["--count", "3000000"])
        .status()
        .unwrap();
    assert!(made.success());
    let scratch = dir.path().join("scratch");
    std::fs::create_dir(&scratch).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_remesh"))
        .env("TMPDIR", &scratch)
        .arg("simplify")
        .arg(&input)
        .arg(dir.path().join("simplified.ply"))
        .args(["--points", "20000", "-q"])
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let buckets = wait_for_entry(&scratch, |n| n.starts_with("remesh-buckets"));
    assert_eq!(signal_and_wait(&mut child, "TERM"), Some(130), "{buckets}");
    assert_eq!(
        std::fs::read_dir(&scratch).unwrap().count(),
        0,
        "{buckets} left"
    );
    // The input and the scratch folder: no output, no temporary file.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
}

/// Issue 17's bounds at default settings, seeds 1–5, where they hold today (the rest are in
/// `eval/bounds.py`'s table, `eval/results/bounds/bounds.md`): Qave ≥ 0.94 on horse at 8600 and
/// spot at 3000; every angle in [35°, 100°] on spot, bracket at 4000 and flange at 6000, θmin ≥
/// 35° on horse and the bunny at 9635, θmax ≤ 100° on horse and the bunny; Hausdorff within 0.2%
/// of the diagonal on the CAD parts (their creases found and kept by default), fandisk at 6000
/// included; the count within 1% everywhere. Without the finishing relaxation (`--smooth 0`)
/// horse has Qave 0.901–0.903 and fails; without the last pass's compass move the bunny has
/// θmin 32.8 at seeds 3 and 5; without features (`--no-features`) bracket's Hausdorff is
/// 1.08–1.13 against 0.29.
#[test]
#[ignore = "needs ../shared: .ci/run runs it"]
fn shared_the_finishing_stage_meets_issue_17s_angle_and_quality_bounds_at_seeds_1_to_5() {
    let dir = tempfile::tempdir().unwrap();
    // (model, count, Qave bound, θmin bound, θmax bound, whether Hausdorff is bounded)
    let cases: [(&str, usize, f64, f64, f64, bool); 6] = [
        ("horse.obj", 8600, 0.94, 35.0, 100.0, false),
        ("spot.obj", 3000, 0.94, 35.0, 100.0, false),
        ("stanford-bunny.obj", 9635, 0.0, 35.0, 100.0, false),
        ("bracket.obj", 4000, 0.0, 35.0, 100.0, true),
        ("flange.obj", 6000, 0.0, 35.0, 100.0, true),
        // Its input has a 19.5° corner between two creases, which the output keeps.
        ("fandisk.obj", 6000, 0.0, 0.0, 180.0, true),
    ];
    for (model, n, q_ave, theta_min, theta_max, bounded) in cases {
        // The input's bounding-box diagonal in bbox-100 units (the report's distance units).
        let (input, _) = spectral_remesh::read_mesh(&shared(model)).unwrap();
        let bbox = input.bbox().unwrap();
        let extent = bbox.max - bbox.min;
        let diagonal = 100.0 * extent.length() / extent.max_element();
        for seed in 1..=5 {
            let name = format!("{model}-{seed}.obj");
            let seed = seed.to_string();
            let mut args = vec!["--seed", &seed];
            if !bounded {
                args.push("--no-distance");
            }
            let (r, _) = run(model, &name, n, &args, dir.path());
            let what = format!("{model} seed {seed}");
            let t = &r["triangles"];
            assert!(float(&r, &["triangles", "q_ave"]) >= q_ave, "{what}: {t}");
            assert!(
                float(&r, &["triangles", "theta_min"]) >= theta_min,
                "{what}: {t}"
            );
            assert!(
                float(&r, &["triangles", "theta_max"]) <= theta_max,
                "{what}: {t}"
            );
            if bounded {
                let h = float(&r, &["distance", "hausdorff"]);
                assert!(
                    h <= 0.002 * diagonal,
                    "{what}: Hausdorff {h}, diagonal {diagonal}"
                );
            }
            let v = int(&r, &["topology", "vertices"]) as f64;
            assert!(
                (v - n as f64).abs() <= 0.01 * n as f64,
                "{what}: {v} vertices"
            );
        }
    }
}

/// Issue 76: `--edge-length L` (model units) gives output edges about L long, the count it
/// implies in the notes, on a mesh and on a point set (sigma_p = L / 1.2 there, its area being
/// known only once its surface is); it excludes `--points`, and a length that is not positive
/// is a usage error.
#[test]
fn edge_length_gives_edges_about_that_long() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("sphere.obj");
    // A sphere of radius 2 (area about 50.3): edges 0.25 give about 929 points.
    let mut mesh = common::icosphere(4);
    for p in &mut mesh.positions {
        *p *= 2.0;
    }
    spectral_remesh::write_mesh(&input, &mesh).unwrap();
    let (out, report) = (dir.path().join("out.obj"), dir.path().join("r.json"));
    let run = |extra: &[&str]| {
        let mut args = vec![input.to_str().unwrap(), out.to_str().unwrap(), "-q"];
        args.extend_from_slice(extra);
        std::process::Command::new(env!("CARGO_BIN_EXE_remesh"))
            .args(&args)
            .output()
            .unwrap()
    };
    let o = run(&[
        "--edge-length",
        "0.25",
        "--no-distance",
        "--report",
        report.to_str().unwrap(),
    ]);
    // The written mesh's mean edge is within 10% of 0.25, and the notes say `note`.
    let check = |what: &str, note: &str| {
        let (written, _) = spectral_remesh::read_mesh(&out).unwrap();
        let lengths: Vec<f64> = written
            .triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k] as usize, t[(k + 1) % 3] as usize)))
            .map(|(a, b)| written.positions[a].distance(written.positions[b]))
            .collect();
        let mean = lengths.iter().sum::<f64>() / lengths.len() as f64;
        assert!((mean - 0.25).abs() < 0.025, "{what}: mean edge {mean}");
        let r: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
        assert!(
            r["notes"].to_string().contains(note),
            "{what}: {}",
            r["notes"]
        );
    };
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    check("mesh", "--edge-length 0.25: about");
    // The same sphere as points with normals (20,000 drawn on it, a fixed sequence).
    let points = dir.path().join("sphere.xyzn");
    let mut text = String::new();
    let mut state = 1u64;
    let mut uniform = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..20_000 {
        let z = 2.0 * uniform() - 1.0;
        let phi = std::f64::consts::TAU * uniform();
        let r = (1.0 - z * z).sqrt();
        let n = [r * phi.cos(), r * phi.sin(), z];
        text += &format!(
            "{} {} {} {} {} {}\n",
            2.0 * n[0],
            2.0 * n[1],
            2.0 * n[2],
            n[0],
            n[1],
            n[2]
        );
    }
    std::fs::write(&points, text).unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_remesh"))
        .args([
            points.to_str().unwrap(),
            out.to_str().unwrap(),
            "-q",
            "--edge-length",
            "0.25",
        ])
        .args(["--no-distance", "--report", report.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    check("point set", "--edge-length 0.25: sigma_p");
    for bad in [
        &["--edge-length", "0"][..],
        &["--edge-length", "0.25", "--points", "100"],
    ] {
        let o = run(bad);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

/// Issue 76: every crossing pair of the output lies where the input's own faces cross (both
/// faces within one output spacing of the input's crossing curve). The corpus runs that left
/// pairs of their own before the refinement of crossing faces (`finish/refine.rs`): box.STL
/// (walls of its parts 0.001 to 0.005 apart where the spacing is 0.32; 11 and 14 pairs at seeds
/// 1 and 2) and counter.unitsmm.STL (2 pairs at seed 3).
#[test]
#[ignore = "needs ../shared: .ci/run runs it"]
fn shared_corpus_files_whose_parts_lie_closer_than_the_spacing_keep_no_crossing_of_their_own() {
    let dir = tempfile::tempdir().unwrap();
    for (file, seed) in [("box.STL", 1), ("box.STL", 2), ("counter.unitsmm.STL", 3)] {
        let name = format!("{file}-{seed}.obj");
        let s = seed.to_string();
        let (r, _) = run(
            &format!("../corpus/trimesh-models/{file}"),
            &name,
            3000,
            &["--no-distance", "--seed", &s],
            dir.path(),
        );
        let pairs = int(&r, &["extra", "output_crossings", "pairs"]);
        let theirs = int(&r, &["extra", "output_crossings", "where_input_crosses"]);
        assert_eq!(
            pairs - theirs,
            0,
            "{name}: {pairs} pairs, {theirs} the input's"
        );
    }
}
