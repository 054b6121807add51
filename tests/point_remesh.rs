//! Issue 19: point sets in, meshes out. A point set sampled from a closed surface (with or
//! without normals, clean or with noise and outliers, in one bucket or many) becomes a closed,
//! manifold, consistently oriented mesh of the surface's genus whose vertices lie on it; the
//! command line's jobs take PLY files without faces and XYZ text as point sets.

mod common;

use std::io::Write;
use std::path::{Path, PathBuf};

use glam::DVec3;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use spectral_remesh::internal::{is_point_set, write_surface_points};
use spectral_remesh::{
    check_invariants, remesh_point_set, remesh_points, run_remesh, topology, write_mesh, Density,
    Error, PointRemeshOutput, PointRemeshParams, PointSource, RemeshJob, RemeshParams, TriMesh,
};

/// A torus around the z axis (radii `big` and `small`), `n` × `m` quads split in two, outward.
fn torus(big: f64, small: f64, n: usize, m: usize) -> TriMesh {
    let mut positions = Vec::new();
    for i in 0..n {
        let u = i as f64 / n as f64 * std::f64::consts::TAU;
        for j in 0..m {
            let v = j as f64 / m as f64 * std::f64::consts::TAU;
            let r = big + small * v.cos();
            positions.push(DVec3::new(r * u.cos(), r * u.sin(), small * v.sin()));
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as u32;
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..m {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    TriMesh::new(positions, triangles)
}

/// Writes `points` (and `normals` if given) as XYZ text, one point per line.
fn write_xyz(path: &Path, points: &[DVec3], normals: Option<&[DVec3]>) {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    for (i, p) in points.iter().enumerate() {
        match normals {
            Some(n) => writeln!(
                f,
                "{} {} {} {} {} {}",
                p.x, p.y, p.z, n[i].x, n[i].y, n[i].z
            ),
            None => writeln!(f, "{} {} {}", p.x, p.y, p.z),
        }
        .unwrap();
    }
}

/// `count` points uniformly on the unit sphere (Archimedes), with their normals.
fn sphere_points(count: usize, rng: &mut ChaCha8Rng) -> (Vec<DVec3>, Vec<DVec3>) {
    let points: Vec<DVec3> = (0..count)
        .map(|_| {
            let z: f64 = rng.random_range(-1.0..=1.0);
            let phi: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            let s = (1.0 - z * z).sqrt();
            DVec3::new(s * phi.cos(), s * phi.sin(), z)
        })
        .collect();
    (points.clone(), points)
}

fn params(points: usize, seed: u64) -> PointRemeshParams {
    PointRemeshParams {
        remesh: RemeshParams {
            density: Density::Points(points),
            seed,
            ..RemeshParams::default()
        },
        ..PointRemeshParams::default()
    }
}

/// Asserts the output is closed, manifold, oriented, one part, of genus `genus`, with about
/// `points` vertices (within 2%).
fn assert_closed(out: &PointRemeshOutput, genus: i64, points: usize) {
    let t = topology(&out.mesh);
    assert!(t.is_closed_manifold(), "{t:?}");
    assert_eq!(t.components, 1, "{t:?}");
    assert_eq!(t.genus, Some(genus), "{t:?}");
    let violations = check_invariants(&out.mesh);
    assert!(violations.is_empty(), "{violations:?}");
    let v = out.mesh.vertex_count() as f64;
    assert!(
        (v - points as f64).abs() <= 0.02 * points as f64,
        "{v} vertices for {points}"
    );
}

/// The largest |distance(v) - 1| over the vertices (for a unit sphere: distance to the origin).
fn worst_off(mesh: &TriMesh, distance: impl Fn(DVec3) -> f64) -> f64 {
    mesh.positions
        .iter()
        .map(|&p| (distance(p)).abs())
        .fold(0.0, f64::max)
}

/// Points in memory are read as the same points in a file: the same mesh, bit for bit, with
/// normals and without.
#[test]
fn a_point_source_in_memory_reads_as_its_file() {
    use spectral_remesh::internal::PointReader;
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("sphere.ply");
    write_surface_points(&common::icosphere(3), 20_000, 5, &input).unwrap();
    let mut reader = PointReader::open(&input).unwrap();
    let mut points = Vec::new();
    let mut chunk = Vec::new();
    while reader.read_chunk(&mut chunk, 4096).unwrap() > 0 {
        points.extend_from_slice(&chunk);
    }
    let positions: Vec<_> = points.iter().map(|p| p.position).collect();
    let normals: Vec<_> = points.iter().map(|p| p.normal).collect();
    let from_file = remesh_points(&PointSource::File(input), &params(600, 2), &|_| {}).unwrap();
    let memory = PointSource::memory("sphere points", &positions, Some(&normals));
    let from_memory = remesh_points(&memory, &params(600, 2), &|_| {}).unwrap();
    assert_eq!(from_file.mesh, from_memory.mesh);
    assert!(from_file.had_normals && from_memory.had_normals);
    // Without normals: estimated the same way as from a text file of the same positions (each
    // written in the shortest form that reads back to the same number).
    let xyz = dir.path().join("sphere.xyz");
    let text: String = positions
        .iter()
        .map(|p| format!("{} {} {}\n", p.x, p.y, p.z))
        .collect();
    std::fs::write(&xyz, text).unwrap();
    let from_text = remesh_points(&PointSource::File(xyz), &params(600, 2), &|_| {}).unwrap();
    let bare = PointSource::memory("sphere points", &positions, None);
    let from_bare = remesh_points(&bare, &params(600, 2), &|_| {}).unwrap();
    assert!(!from_text.had_normals && !from_bare.had_normals);
    assert_eq!(from_text.mesh, from_bare.mesh);
    assert_ne!(from_bare.mesh, from_memory.mesh);
}

#[test]
fn sphere_points_with_normals_become_a_closed_sphere() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("sphere.ply");
    write_surface_points(&common::icosphere(5), 60_000, 3, &input).unwrap();
    let out = remesh_points(&PointSource::File(input.clone()), &params(1500, 1), &|_| {}).unwrap();
    assert!(out.had_normals);
    assert_closed(&out, 0, 1500);
    // On the sphere: the RIMLS bias sigma_p^2 / (2R) is 0.2% of R at this count.
    let off = worst_off(&out.mesh, |p| p.length() - 1.0);
    assert!(off < 0.01, "a vertex {off} off the unit sphere");
    // Facing outward.
    assert!(out.mesh.signed_volume() > 0.0);
}

#[test]
fn torus_points_without_normals_keep_the_genus() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = torus(1.0, 0.4, 120, 48);
    let (big, small) = (1.0, 0.4);
    let input = dir.path().join("torus.ply");
    write_surface_points(&mesh, 80_000, 5, &input).unwrap();
    // The same points as XYZ text without normals.
    let mut reader = spectral_remesh::internal::PointReader::open(&input).unwrap();
    let mut pts = Vec::new();
    reader.read_chunk(&mut pts, 1 << 20).unwrap();
    let xyz = dir.path().join("torus.xyz");
    let positions: Vec<DVec3> = pts.iter().map(|p| p.position).collect();
    write_xyz(&xyz, &positions, None);
    for seed in 1..=2 {
        let out = remesh_points(
            &PointSource::File(xyz.clone()),
            &params(2000, seed),
            &|_| {},
        )
        .unwrap();
        assert!(!out.had_normals);
        assert_closed(&out, 1, 2000);
        let off = worst_off(&out.mesh, |p| {
            let ring = DVec3::new(p.x, p.y, 0.0).normalize_or_zero() * big;
            (p - ring).length() - small
        });
        assert!(off < 0.02, "seed {seed}: a vertex {off} off the torus");
        assert!(out.mesh.signed_volume() > 0.0);
    }
}

#[test]
fn noise_and_outliers_still_give_the_closed_surface() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let (mut points, _) = sphere_points(100_000, &mut rng);
    // Gaussian noise of 0.1% of the diagonal (2 sqrt 3), by Box-Muller.
    let sigma = 0.001 * 2.0 * 3f64.sqrt();
    for p in &mut points {
        let (u, v): (f64, f64) = (rng.random_range(1e-12..1.0), rng.random_range(0.0..1.0));
        let g = (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos();
        *p *= 1.0 + sigma * g;
    }
    // 1% outliers uniform in the bounding box, at least 0.1 off the sphere.
    let mut outliers = 0;
    while outliers < 1000 {
        let p = DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        if (p.length() - 1.0).abs() > 0.1 {
            points.push(p);
            outliers += 1;
        }
    }
    let input = dir.path().join("noisy.xyz");
    write_xyz(&input, &points, None);
    let out = remesh_points(&PointSource::File(input.clone()), &params(1500, 1), &|_| {}).unwrap();
    assert!(
        out.outliers_removed >= 900,
        "{} outliers removed",
        out.outliers_removed
    );
    assert_closed(&out, 0, 1500);
    let off = worst_off(&out.mesh, |p| p.length() - 1.0);
    assert!(off < 0.02, "a vertex {off} off the unit sphere");
}

/// The height of the wavy patch over [-1, 1]² of [`wavy_patch`].
fn wavy_height(x: f64, y: f64) -> f64 {
    0.1 * (2.0 * x).sin() * (1.5 * y).cos()
}

/// 60,000 uniform points (by x and y) of the wavy patch z = [`wavy_height`] over [-1, 1]², none
/// where `in_hole(x, y)`, with their unit normals (+z side); from rng seed `seed`.
fn wavy_patch(seed: u64, in_hole: impl Fn(f64, f64) -> bool) -> (Vec<DVec3>, Vec<DVec3>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (mut points, mut normals) = (Vec::new(), Vec::new());
    while points.len() < 60_000 {
        let (x, y): (f64, f64) = (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        if in_hole(x, y) {
            continue;
        }
        points.push(DVec3::new(x, y, wavy_height(x, y)));
        let (hx, hy) = (
            0.2 * (2.0 * x).cos() * (1.5 * y).cos(),
            -0.15 * (2.0 * x).sin() * (1.5 * y).sin(),
        );
        normals.push(DVec3::new(-hx, -hy, 1.0).normalize());
    }
    (points, normals)
}

/// The point file `input` remeshed at 1500 vertices with `seed`, checked manifold and free of
/// invariant violations.
fn remesh_valid_patch(input: &Path, seed: u64) -> PointRemeshOutput {
    let out = remesh_points(
        &PointSource::File(input.to_path_buf()),
        &params(1500, seed),
        &|_| {},
    )
    .unwrap();
    let t = topology(&out.mesh);
    assert!(t.is_manifold(), "seed {seed}: {t:?}");
    assert!(check_invariants(&out.mesh).is_empty(), "seed {seed}");
    out
}

#[test]
fn an_open_patch_keeps_its_boundary_and_its_hole() {
    // A wavy square patch 2 × 2 with a round hole of radius 0.3 in the middle, 60,000 points
    // with normals: at 1500 vertices the spacing is about 0.05, the hole 12 spacings wide.
    let dir = tempfile::tempdir().unwrap();
    let (points, normals) = wavy_patch(21, |x, y| x.hypot(y) < 0.3);
    let input = dir.path().join("patch.xyz");
    write_xyz(&input, &points, Some(&normals));
    for seed in 1..=2 {
        let out = remesh_valid_patch(&input, seed);
        let t = topology(&out.mesh);
        assert_eq!(t.components, 1, "seed {seed}: {t:?}");
        assert_eq!(t.boundary_loops, 2, "seed {seed}: {t:?}");
        // No face over the hole, none beyond the square (up to a spacing).
        for tri in &out.mesh.triangles {
            let c = tri
                .iter()
                .map(|&i| out.mesh.positions[i as usize])
                .sum::<DVec3>()
                / 3.0;
            assert!(c.x.hypot(c.y) > 0.25, "seed {seed}: a face at {c}");
            assert!(
                c.x.abs().max(c.y.abs()) < 1.05,
                "seed {seed}: a face at {c}"
            );
        }
        // On the surface.
        let off = worst_off(&out.mesh, |p| p.z - wavy_height(p.x, p.y));
        assert!(off < 0.01, "seed {seed}: a vertex {off} off the patch");
    }
}

#[test]
fn no_output_face_spans_a_gap_in_the_data() {
    // A wavy patch 2 × 2 with eight small round holes (radius 0.12, about five spacings across
    // at 1500 vertices), 60,000 points with normals: every output face's centroid and edge
    // midpoints lie within the gap rule's reach (OPEN_GAP_SIGMA_P sigma_p) of an input point,
    // after the finishing as after the umbrellas.
    let dir = tempfile::tempdir().unwrap();
    let holes: Vec<(f64, f64)> = (0..8)
        .map(|k| {
            let a = k as f64 * std::f64::consts::FRAC_PI_4;
            (0.55 * a.cos(), 0.55 * a.sin())
        })
        .collect();
    let (points, normals) = wavy_patch(23, |x, y| {
        holes.iter().any(|&(hx, hy)| (x - hx).hypot(y - hy) < 0.12)
    });
    let input = dir.path().join("holes.xyz");
    write_xyz(&input, &points, Some(&normals));
    for seed in 1..=3 {
        let out = remesh_valid_patch(&input, seed);
        let reach = spectral_remesh::OPEN_GAP_SIGMA_P * out.sigma_p / out.normalization.scale
            * (1.0 + 1e-9);
        let m = &out.mesh;
        for tri in &m.triangles {
            let [a, b, c] = tri.map(|i| m.positions[i as usize]);
            for probe in [
                (a + b + c) / 3.0,
                (a + b) / 2.0,
                (b + c) / 2.0,
                (c + a) / 2.0,
            ] {
                assert!(
                    points.iter().any(|p| p.distance(probe) <= reach),
                    "seed {seed}: a face over a hole at {probe} (reach {reach})"
                );
            }
        }
    }
}

#[test]
fn many_buckets_give_the_same_guarantees_as_one() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("sphere.ply");
    write_surface_points(&common::icosphere(5), 60_000, 9, &input).unwrap();
    for bucket_points in [1 << 20, 7_000] {
        let out = remesh_points(
            &PointSource::File(input.clone()),
            &PointRemeshParams {
                bucket_points,
                temp_dir: Some(dir.path().to_path_buf()),
                ..params(1500, 2)
            },
            &|_| {},
        )
        .unwrap();
        assert_closed(&out, 0, 1500);
        let off = worst_off(&out.mesh, |p| p.length() - 1.0);
        assert!(off < 0.01, "{bucket_points}: a vertex {off} off the sphere");
    }
    // The buckets are gone.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn a_point_set_needs_a_count() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("sphere.ply");
    write_surface_points(&common::icosphere(3), 5_000, 1, &input).unwrap();
    let p = PointRemeshParams {
        remesh: RemeshParams {
            density: Density::InputVertices,
            ..RemeshParams::default()
        },
        ..PointRemeshParams::default()
    };
    match remesh_points(&PointSource::File(input.clone()), &p, &|_| {}) {
        Err(Error::InvalidParameter { name, message }) => {
            assert_eq!(name, "points");
            assert!(message.contains("sphere.ply"), "{message}");
        }
        other => panic!("{other:?}"),
    }
}

fn job(input: PathBuf, output: PathBuf, as_points: bool) -> RemeshJob {
    RemeshJob {
        input,
        output,
        format: None,
        params: RemeshParams {
            density: Density::Points(800),
            ..RemeshParams::default()
        },
        measure_distance: true,
        strict: true,
        max_memory: None,
        as_points,
        viewpoint: None,
        report: None,
    }
}

#[test]
fn the_remesh_job_takes_point_files_and_keeps_meshes_meshes() {
    let dir = tempfile::tempdir().unwrap();
    let sphere = common::icosphere(4);
    // A PLY without faces and XYZ text are point sets; a PLY mesh and an OBJ are not.
    let points = dir.path().join("points.ply");
    write_surface_points(&sphere, 30_000, 2, &points).unwrap();
    let mesh_ply = dir.path().join("mesh.ply");
    write_mesh(&mesh_ply, &sphere).unwrap();
    let mesh_obj = dir.path().join("mesh.obj");
    write_mesh(&mesh_obj, &sphere).unwrap();
    let xyz = dir.path().join("points.xyz");
    let (p, n) = sphere_points(30_000, &mut ChaCha8Rng::seed_from_u64(4));
    write_xyz(&xyz, &p, Some(&n));
    assert!(is_point_set(&points).unwrap());
    assert!(is_point_set(&xyz).unwrap());
    assert!(!is_point_set(&mesh_ply).unwrap());
    assert!(!is_point_set(&mesh_obj).unwrap());

    for input in [&points, &xyz] {
        let output = dir.path().join("out.obj");
        let report = run_remesh(&job(input.clone(), output.clone(), false), &|_| {}).unwrap();
        assert_eq!(report.extra["input_points"], 30_000, "{input:?}");
        assert!(report.topology.is_closed_manifold());
        assert_eq!(report.topology.genus, Some(0));
        // Distances to the points (the unit sphere is radius 50 in bbox-100 units): each
        // point's exact distance to the output is the chords' sag, well under 1 at 800
        // vertices; the output's distance to the nearest point adds up to about the points'
        // spacing (1 here).
        let d = report.distance.expect("distance");
        assert!(d.backward_hausdorff < 1.0, "{input:?}: {d:?}");
        assert!(d.forward_hausdorff < 3.0, "{input:?}: {d:?}");
        let (written, _) = spectral_remesh::read_mesh(&output).unwrap();
        assert_eq!(written.vertex_count(), report.topology.vertices);
    }
    // The mesh PLY is remeshed as a mesh; with --as-points its faces are ignored.
    let output = dir.path().join("out2.obj");
    let as_mesh = run_remesh(&job(mesh_ply.clone(), output.clone(), false), &|_| {}).unwrap();
    assert!(as_mesh.extra.get("input_points").is_none());
    assert!(as_mesh.input_topology.is_some());
    let as_points = run_remesh(&job(mesh_ply, output, true), &|_| {}).unwrap();
    assert_eq!(
        as_points.extra["input_points"],
        sphere.vertex_count() as u64
    );
}

/// Points held in memory (`remesh_point_set`, the Python module's path) give the mesh `remesh`
/// gives on a text file of the same points, bit for bit, with and without normals; and its
/// errors name the points, not the temporary file behind them.
#[test]
fn points_in_memory_give_the_file_jobs_mesh_and_name_themselves_in_errors() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let (points, normals) = sphere_points(20_000, &mut rng);
    // Scaled and moved: the values are not round numbers.
    let points: Vec<DVec3> = points
        .iter()
        .map(|p| *p * 3.7 + DVec3::new(0.1, -2.3, 5.0))
        .collect();
    for (with_normals, seed) in [(true, 1), (false, 2)] {
        let n = with_normals.then_some(&normals[..]);
        let input = dir
            .path()
            .join(if with_normals { "p.xyzn" } else { "p.xyz" });
        write_xyz(&input, &points, n);
        let output = dir.path().join("out.ply");
        let mut file_job = job(input, output.clone(), false);
        file_job.params.seed = seed;
        file_job.strict = false;
        let file_report = run_remesh(&file_job, &|_| {}).unwrap();
        let (from_file, _) = spectral_remesh::read_mesh(&output).unwrap();
        let got = remesh_point_set(
            &points,
            n,
            &file_job.params,
            None,
            true,
            false,
            None,
            &|_| {},
        )
        .unwrap();
        assert_eq!(
            got.mesh.positions, from_file.positions,
            "normals {with_normals}"
        );
        assert_eq!(
            got.mesh.triangles, from_file.triangles,
            "normals {with_normals}"
        );
        assert_eq!(got.report.distance, file_report.distance);
        assert!(check_invariants(&got.mesh).is_empty());
    }
    let params = job(PathBuf::new(), PathBuf::new(), false).params;
    let call = |p: &[DVec3], n: Option<&[DVec3]>, params: &RemeshParams| {
        remesh_point_set(p, n, params, None, false, false, None, &|_| {})
            .unwrap_err()
            .to_string()
    };
    let mut bad = points[..100].to_vec();
    bad[7].y = f64::NAN;
    assert!(call(&bad, None, &params).contains("point 7"));
    let mut zero = normals[..100].to_vec();
    zero[3] = DVec3::ZERO;
    assert!(call(&points[..100], Some(&zero), &params).contains("normal 3"));
    assert!(call(&points[..100], Some(&normals[..99]), &params).contains("99 normals"));
    assert!(call(&[], None, &params).contains("no points"));
    // An error from the pipeline itself: sigma_n needs normals.
    let sigma_n = RemeshParams {
        sigma_n: 0.8,
        ..params
    };
    let e = call(&points, None, &sigma_n);
    assert!(e.contains("input points"), "{e}");
    assert!(!e.contains(".xyz"), "{e}");
}

/// Issue 39: open surfaces of points without normals end where their data ends, as boundary
/// loops along it: `n` uniform points of `surface(u, v)` over the unit square, meshed at `count`,
/// give one part with `loops` boundary loops, no crossing, and θmin ≥ 30° (the angle bounds hold
/// along the boundary too).
fn assert_open_points(
    name: &str,
    surface: impl Fn(f64, f64) -> DVec3,
    n: usize,
    count: usize,
    loops: usize,
) {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(39);
    let points: Vec<DVec3> = (0..n)
        .map(|_| surface(rng.random_range(0.0..1.0), rng.random_range(0.0..1.0)))
        .collect();
    let input = dir.path().join(format!("{name}.xyz"));
    write_xyz(&input, &points, None);
    for seed in 1..=2 {
        let out = remesh_points(
            &PointSource::File(input.clone()),
            &params(count, seed),
            &|_| {},
        )
        .unwrap();
        let t = topology(&out.mesh);
        assert!(t.is_manifold(), "{name}, seed {seed}: {t:?}");
        assert_eq!(t.components, 1, "{name}, seed {seed}: {t:?}");
        assert_eq!(t.boundary_loops, loops, "{name}, seed {seed}: {t:?}");
        assert!(
            check_invariants(&out.mesh).is_empty(),
            "{name}, seed {seed}"
        );
        let q = spectral_remesh::QualityReport::new(&out.mesh_normalized);
        assert!(
            q.triangles.theta_min >= 30.0,
            "{name}, seed {seed}: θmin {}",
            q.triangles.theta_min
        );
    }
}

#[test]
fn a_flat_square_of_points_is_a_disc() {
    // 5,000 points -> 500: before the data's boundary was found, the assembly closed the outer
    // loop with a cap and wrote a pillow of zero thickness.
    assert_open_points("square", |u, v| DVec3::new(u, v, 0.0), 5000, 500, 1);
}

#[test]
fn an_open_band_of_points_has_two_loops() {
    let band = |u: f64, v: f64| {
        let a = u * std::f64::consts::TAU;
        DVec3::new(a.cos(), a.sin(), v)
    };
    assert_open_points("band", band, 20_000, 1000, 2);
}

/// A range map (a PLY with the scanner's `camera` before its points, as MeshLab writes them)
/// without normals: the estimated normals, and so the output's faces, point towards the
/// camera, here below the patch, where the spanning tree's rule (the highest point's normal up)
/// would turn them away from it.
#[test]
fn a_range_maps_camera_orients_its_points() {
    let dir = tempfile::tempdir().unwrap();
    let (points, _) = wavy_patch(5, |_, _| false);
    let camera = DVec3::new(0.2, -0.1, -4.0);
    let mut text = format!(
        "ply\nformat ascii 1.0\nelement camera 1\nproperty float view_px\nproperty float \
         view_py\nproperty float view_pz\nproperty float focal\nelement vertex {}\nproperty \
         double x\nproperty double y\nproperty double z\nend_header\n{} {} {} 14\n",
        points.len(),
        camera.x,
        camera.y,
        camera.z
    );
    for p in &points {
        text.push_str(&format!("{} {} {}\n", p.x, p.y, p.z));
    }
    let input = dir.path().join("range.ply");
    std::fs::write(&input, text).unwrap();
    let output = dir.path().join("out.obj");
    let report = run_remesh(&job(input, output.clone(), false), &|_| {}).unwrap();
    let (mesh, _) = spectral_remesh::read_mesh(&output).unwrap();
    assert!(mesh.triangles.len() > 1000);
    for tri in &mesh.triangles {
        let [a, b, c] = tri.map(|i| mesh.positions[i as usize]);
        let normal = (b - a).cross(c - a);
        assert!(
            normal.dot(camera - (a + b + c) / 3.0) > 0.0,
            "a face at {} turned away from the camera",
            (a + b + c) / 3.0
        );
    }
    assert!(
        report
            .notes
            .iter()
            .any(|n| n.contains("oriented towards the sensor the file gives")),
        "{:?}",
        report.notes
    );
}
