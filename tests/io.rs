//! Integration tests of the crate's mesh reading and writing (`read_mesh`, `write_mesh`): the
//! shared test models, round trips through every output format, and malformed inputs.

use std::fs;
use std::path::{Path, PathBuf};

use glam::DVec3;
use spectral_remesh::{read_mesh, write_mesh, Error, MeshFormat, ReadStats, TriMesh};

mod common;

fn model(name: &str) -> PathBuf {
    common::model(name)
}

fn read(name: &str) -> (TriMesh, ReadStats) {
    let path = model(name);
    read_mesh(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The file an error names.
fn error_path(e: &Error) -> Option<&Path> {
    match e {
        Error::Io { path, .. }
        | Error::UnsupportedFormat { path }
        | Error::Parse { path, .. }
        | Error::InvalidMesh { path, .. }
        | Error::Write { path, .. } => Some(path),
        _ => None,
    }
}

/// Reads `path`, expecting an error that names it.
fn expect_err(path: &Path) -> Error {
    match read_mesh(path) {
        Ok((m, _)) => panic!(
            "{}: read {} vertices / {} triangles, expected an error",
            path.display(),
            m.vertex_count(),
            m.face_count()
        ),
        Err(e) => {
            assert_eq!(
                error_path(&e),
                Some(path),
                "error does not name the file: {e}"
            );
            e
        }
    }
}

fn assert_counts(name: &str, vertices: usize, faces: usize) -> (TriMesh, ReadStats) {
    let (m, s) = read(name);
    assert_eq!(m.vertex_count(), vertices, "{name}: vertices");
    assert_eq!(m.face_count(), faces, "{name}: faces");
    assert!(m.check_indices().is_none());
    (m, s)
}

/// Triangles as position triples in a canonical cyclic rotation (orientation kept), sorted;
/// positions mapped through `key`.
fn triangle_set(m: &TriMesh, key: impl Fn(usize) -> usize) -> Vec<[usize; 3]> {
    let mut out: Vec<[usize; 3]> = m
        .triangles
        .iter()
        .map(|t| {
            let k = t.map(|i| key(i as usize));
            let r = (0..3).min_by_key(|&j| k[j]).unwrap();
            [k[r], k[(r + 1) % 3], k[(r + 2) % 3]]
        })
        .collect();
    out.sort_unstable();
    out
}

/// For every vertex of `b`, the vertex of `a` within `tol` of it (asserting there is exactly
/// one such, and that the map is a bijection).
fn match_vertices(a: &TriMesh, b: &TriMesh, tol: f64) -> Vec<usize> {
    assert_eq!(a.vertex_count(), b.vertex_count());
    // Sort `a` along x to search a window.
    let mut order: Vec<usize> = (0..a.vertex_count()).collect();
    order.sort_by(|&i, &j| a.positions[i].x.total_cmp(&a.positions[j].x));
    let xs: Vec<f64> = order.iter().map(|&i| a.positions[i].x).collect();
    let mut used = vec![false; a.vertex_count()];
    b.positions
        .iter()
        .map(|p| {
            let lo = xs.partition_point(|&x| x < p.x - tol);
            let hi = xs.partition_point(|&x| x <= p.x + tol);
            let hits: Vec<usize> = order[lo..hi]
                .iter()
                .copied()
                .filter(|&i| a.positions[i].distance(*p) <= tol)
                .collect();
            assert_eq!(hits.len(), 1, "vertex {p} matches {hits:?}");
            assert!(!used[hits[0]], "vertex {p} matched twice");
            used[hits[0]] = true;
            hits[0]
        })
        .collect()
}

fn assert_same_mesh_within(a: &TriMesh, b: &TriMesh, rel_tol: f64) {
    assert_eq!(a.vertex_count(), b.vertex_count());
    assert_eq!(a.face_count(), b.face_count());
    let tol = rel_tol * a.bbox().unwrap().diagonal();
    let map = match_vertices(a, b, tol);
    assert_eq!(triangle_set(a, |i| i), triangle_set(b, |i| map[i]));
}

// ---------------------------------------------------------------------------------------------
// The shared models

#[test]
#[ignore = "needs ../shared: .ci/run runs it"]
fn shared_horse_obj_and_ply_are_the_same_mesh() {
    let (obj, so) = assert_counts("horse.obj", 48_485, 96_966);
    let (ply, sp) = assert_counts("horse.ply", 48_485, 96_966);
    assert_eq!(so.format, MeshFormat::Obj);
    assert_eq!(sp.format, MeshFormat::Ply);
    for s in [&so, &sp] {
        assert_eq!(s.vertices_read, 48_485);
        assert_eq!(s.faces_read, 96_966);
        assert_eq!(s.polygons_triangulated, 0);
        assert_eq!(s.welded_vertices, 0);
        assert_eq!(s.unreferenced_vertices_removed, 0);
    }
    // The PLY stores f32; the OBJ holds decimals of about 7 significant digits: the same
    // positions to within f32 precision, in the same order.
    let diag = ply.bbox().unwrap().diagonal();
    let mut worst = 0.0f64;
    for (a, b) in obj.positions.iter().zip(&ply.positions) {
        worst = worst.max(a.distance(*b));
    }
    assert!(worst < 1e-6 * diag, "largest difference {worst}");
    assert_eq!(obj.triangles, ply.triangles);
}

#[test]
#[ignore = "needs ../shared: .ci/run runs it"]
fn shared_stanford_bunny_drops_its_unreferenced_vertices() {
    let (_, s) = assert_counts("stanford-bunny.obj", 34_834, 69_451);
    assert_eq!(s.vertices_read, 35_947);
    assert_eq!(s.unreferenced_vertices_removed, 1_113);
    assert_eq!(s.welded_vertices, 0);
    assert_eq!(s.faces_read, 69_451);
}

#[test]
#[ignore = "needs ../shared: .ci/run runs it"]
fn shared_fandisk_cow_counts() {
    let (_, s) = assert_counts("fandisk.obj", 6_475, 12_946);
    assert_eq!((s.vertices_read, s.faces_read), (6_475, 12_946));
    let (_, s) = assert_counts("cow.obj", 2_903, 5_804);
    assert_eq!((s.vertices_read, s.faces_read), (2_903, 5_804));
}

#[test]
fn spot_obj_and_glb_are_the_same_mesh() {
    let (obj, so) = assert_counts("spot.obj", 2_930, 5_856);
    let (glb, sg) = assert_counts("spot.glb", 2_930, 5_856);
    assert_eq!(sg.format, MeshFormat::Glb);
    assert_eq!((so.vertices_read, so.faces_read), (2_930, 5_856));
    assert_eq!((sg.vertices_read, sg.faces_read), (2_930, 5_856));
    assert_eq!(sg.skipped_primitives, 0);
    // f32 in the GLB, 6-decimal text in the OBJ.
    assert_same_mesh_within(&obj, &glb, 1e-5);
}

#[test]
fn beetle_counts_and_triangulation() {
    // The shared beetle.obj holds 1,148 vertices and 2,053 faces, all of them triangles
    // (its README line says 1,254 vertices and "some polygons"; the file does not).
    let path = model("beetle.obj");
    let (m, s) = read("beetle.obj");
    let text = fs::read_to_string(&path).unwrap();
    let corners: Vec<usize> = text
        .lines()
        .filter(|l| l.starts_with("f "))
        .map(|l| l.split_whitespace().count() - 1)
        .collect();
    let expected: usize = corners.iter().map(|c| c - 2).sum();
    assert_eq!(s.faces_read, corners.len());
    assert_eq!(
        s.polygons_triangulated,
        corners.iter().filter(|&&c| c > 3).count()
    );
    assert_eq!(m.face_count(), expected);
    assert_eq!((m.vertex_count(), m.face_count()), (1_148, 2_053));
    assert_eq!(s.polygons_triangulated, 0);
}

// ---------------------------------------------------------------------------------------------
// Writing and reading back

/// The normals of a written file, by format.
fn written_normals(path: &Path) -> Vec<DVec3> {
    match MeshFormat::from_path(path).unwrap() {
        MeshFormat::Obj => fs::read_to_string(path)
            .unwrap()
            .lines()
            .filter_map(|l| l.strip_prefix("vn "))
            .map(|l| {
                let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
                DVec3::new(v[0], v[1], v[2])
            })
            .collect(),
        MeshFormat::Ply => {
            let bytes = fs::read(path).unwrap();
            let text = String::from_utf8_lossy(&bytes);
            let end = text.find("end_header\n").unwrap() + "end_header\n".len();
            let nv: usize = text
                .lines()
                .find_map(|l| l.strip_prefix("element vertex "))
                .unwrap()
                .parse()
                .unwrap();
            let f =
                |at: usize| f64::from(f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()));
            (0..nv)
                .map(|i| {
                    // x y z as double (24 bytes), then nx ny nz as float.
                    let at = end + i * 36 + 24;
                    DVec3::new(f(at), f(at + 4), f(at + 8))
                })
                .collect()
        }
        MeshFormat::Stl | MeshFormat::Off => panic!("{path:?}: the format has no vertex normals"),
        MeshFormat::Glb | MeshFormat::Gltf => {
            let (doc, buffers, _) = gltf::import(path).unwrap();
            let mesh = doc.meshes().next().unwrap();
            let prim = mesh.primitives().next().unwrap();
            let reader = prim.reader(|b| Some(&buffers[b.index()]));
            reader
                .read_normals()
                .unwrap()
                .map(|n| DVec3::from_array(n.map(f64::from)))
                .collect()
        }
    }
}

#[test]
fn round_trips_keep_the_mesh() {
    let (spot, _) = read("spot.obj");
    let dir = tempfile::tempdir().unwrap();
    for ext in ["obj", "ply", "glb", "gltf"] {
        let path = dir.path().join(format!("spot-out.{ext}"));
        write_mesh(&path, &spot).unwrap();
        let (back, s) = read_mesh(&path).unwrap();
        assert_eq!(back.vertex_count(), spot.vertex_count(), "{ext}");
        assert_eq!(
            back.triangles, spot.triangles,
            "{ext}: same triangles, same order"
        );
        assert_eq!((s.welded_vertices, s.unreferenced_vertices_removed), (0, 0));
        if ext == "obj" || ext == "ply" {
            assert_eq!(back.positions, spot.positions, "{ext} positions are exact");
        } else {
            // f32 offsets from the node translation (the bbox centre rounded to f32).
            for (a, b) in back.positions.iter().zip(&spot.positions) {
                assert!(
                    (*a - *b).abs().max_element() < 1e-6,
                    "{ext}: positions within f32 precision: {a} vs {b}"
                );
            }
        }
        let normals = written_normals(&path);
        assert_eq!(normals.len(), spot.vertex_count(), "{ext}");
        for n in &normals {
            assert!(
                (n.length() - 1.0).abs() < 1e-6,
                "{ext}: normal {n} is not unit"
            );
        }
    }
    // Nothing but the outputs in the directory (no temporary files left).
    let mut names: Vec<String> = fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "spot-out.glb",
            "spot-out.gltf",
            "spot-out.obj",
            "spot-out.ply"
        ]
    );
}

/// Issue 16: the formats CAD parts come in. OFF keeps the mesh exactly (vertices, triangles and
/// their order); binary STL keeps the triangles corner for corner at `f32` precision, its
/// corners welded back into the same vertices.
#[test]
fn stl_and_off_round_trips_keep_the_mesh() {
    let (spot, _) = read("spot.obj");
    let dir = tempfile::tempdir().unwrap();
    let off = dir.path().join("spot.off");
    write_mesh(&off, &spot).unwrap();
    let (back, s) = read_mesh(&off).unwrap();
    assert_eq!(back, spot);
    assert_eq!(s.format, MeshFormat::Off);
    let stl = dir.path().join("spot.stl");
    write_mesh(&stl, &spot).unwrap();
    assert_eq!(
        fs::metadata(&stl).unwrap().len(),
        84 + 50 * spot.face_count() as u64
    );
    let (back, s) = read_mesh(&stl).unwrap();
    assert_eq!(s.format, MeshFormat::Stl);
    assert_eq!(s.vertices_read, 3 * spot.face_count());
    assert_eq!(back.vertex_count(), spot.vertex_count(), "welded back");
    assert_eq!(back.face_count(), spot.face_count());
    for f in 0..spot.face_count() {
        for (a, b) in back.corners(f).iter().zip(spot.corners(f)) {
            assert!((*a - b).abs().max_element() < 1e-6, "{a} vs {b}");
        }
    }
}

/// The unit cube [0, 1]³: corner i at (i & 1, i >> 1 & 1, i >> 2), 12 faces facing out.
fn unit_cube() -> TriMesh {
    TriMesh::new(
        (0..8)
            .map(|i| DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2) as f64))
            .collect(),
        vec![
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ],
    )
}

/// Issue 59: a CAD export repeats a seam's corners with positions a rounding apart (2.7e-16 of
/// the model on a real part); read bit for bit those seams are cracks, and a closed part reads
/// as one with boundary loops. A unit cube as an ascii STL whose top face's corners are written
/// 1e-16 off reads as the closed cube: 8 vertices, no boundary edge.
#[test]
fn an_stl_whose_seam_corners_are_a_rounding_apart_reads_closed() {
    let cube = unit_cube();
    let mut text = String::from("solid cube\n");
    for (f, t) in cube.triangles.iter().enumerate() {
        text.push_str(" facet normal 0 0 0\n  outer loop\n");
        for &i in t {
            let mut p = cube.positions[i as usize];
            // The top face's two triangles write their corners a rounding off.
            if f == 2 || f == 3 {
                p += DVec3::new(1e-16, -1e-16, 2e-16);
            }
            text.push_str(&format!("   vertex {:e} {:e} {:e}\n", p.x, p.y, p.z));
        }
        text.push_str("  endloop\n endfacet\n");
    }
    text.push_str("endsolid cube\n");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("seams.stl");
    fs::write(&path, text).unwrap();
    let (m, s) = read_mesh(&path).unwrap();
    assert_eq!(s.vertices_read, 36);
    assert_eq!(m.vertex_count(), 8, "welded into the cube's corners");
    assert_eq!(s.welded_vertices, 28);
    assert_eq!(m.face_count(), 12);
    let t = spectral_remesh::topology(&m);
    assert_eq!((t.boundary_edges, t.euler_characteristic), (0, 2), "{t:?}");
}

/// The weld's distance scales with the model, but a stray triangle 10^12 away (which makes the
/// bounding box's diagonal 10^12) does not weld a unit cube's corners together: the cube reads
/// with its 8 corners and 12 faces, the stray triangle with its own 3.
#[test]
fn a_stray_far_triangle_does_not_weld_a_part_into_a_point() {
    let TriMesh {
        mut positions,
        mut triangles,
    } = unit_cube();
    positions.extend([1e12, 1e12 + 1.0, 1e12 + 2.0].map(|x| DVec3::new(x, 0.0, (x - 1e12) * 0.5)));
    triangles.push([8, 9, 10]);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("stray.obj");
    write_mesh(&path, &TriMesh::new(positions, triangles)).unwrap();
    let (m, s) = read_mesh(&path).unwrap();
    assert_eq!(
        (m.vertex_count(), m.face_count(), s.welded_vertices),
        (11, 13, 0)
    );
}

#[test]
fn obj_round_trip_is_exact_for_arbitrary_f64() {
    let m = TriMesh::new(
        vec![
            DVec3::new(0.1, 1.0 / 3.0, -2.5e-17),
            DVec3::new(1e-300, 12345.678901234567, std::f64::consts::PI),
            DVec3::new(-0.0, 7e22, 1.0),
            DVec3::new(5.0, 5.0, 5.0), // isolated: its normal must still be unit (+Z)
        ],
        vec![[0, 1, 2]],
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("exact.obj");
    write_mesh(&path, &m).unwrap();
    let text = fs::read_to_string(&path).unwrap();
    assert!(text.starts_with("# written by spectral-remesh"));
    assert!(text.contains("f 1//1 2//2 3//3"));
    let normals = written_normals(&path);
    assert_eq!(normals[3], DVec3::Z);
    let (back, s) = read_mesh(&path).unwrap();
    assert_eq!(s.unreferenced_vertices_removed, 1);
    assert_eq!(back.positions, m.positions[..3]);
    assert_eq!(back.triangles, m.triangles);
}

#[test]
fn glb_output_is_well_formed() {
    let (spot, _) = read("spot.glb");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("spot.glb");
    write_mesh(&path, &spot).unwrap();
    let bytes = fs::read(&path).unwrap();
    assert_eq!(&bytes[0..4], b"glTF");
    assert_eq!(u32::from_le_bytes(bytes[4..8].try_into().unwrap()), 2);
    assert_eq!(
        u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize,
        bytes.len()
    );
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    assert_eq!(json_len % 4, 0);
    assert_eq!(&bytes[16..20], b"JSON");
    let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    assert_eq!(json["asset"]["version"], "2.0");
    assert_eq!(json["asset"]["generator"], "spectral-remesh");
    assert_eq!(json["bufferViews"][0]["target"], 34962);
    assert_eq!(json["bufferViews"][2]["target"], 34963);
    assert_eq!(json["accessors"][2]["componentType"], 5125);
    let bin_at = 20 + json_len;
    let bin_len = u32::from_le_bytes(bytes[bin_at..bin_at + 4].try_into().unwrap()) as usize;
    assert_eq!(bin_len % 4, 0);
    assert_eq!(&bytes[bin_at + 4..bin_at + 8], b"BIN\0");
    assert_eq!(bin_at + 8 + bin_len, bytes.len());
    // And the gltf crate (with its validation) accepts it.
    gltf::Gltf::from_slice(&bytes).unwrap();
}

#[test]
fn write_to_a_missing_directory_fails_cleanly() {
    let (spot, _) = read("spot.obj");
    let dir = tempfile::tempdir().unwrap();
    for ext in ["obj", "ply", "glb"] {
        let target = dir.path().join("no-such-dir").join(format!("out.{ext}"));
        let e = write_mesh(&target, &spot).unwrap_err();
        assert!(matches!(e, Error::Write { .. }), "{e}");
        assert_eq!(error_path(&e), Some(target.as_path()));
        assert!(!target.exists());
    }
    // The target is a directory: the rename fails, and the temporary file is removed.
    let target = dir.path().join("taken.obj");
    fs::create_dir(&target).unwrap();
    let e = write_mesh(&target, &spot).unwrap_err();
    assert!(matches!(e, Error::Write { .. }), "{e}");
    assert_eq!(
        fs::read_dir(dir.path()).unwrap().count(),
        1,
        "only taken.obj/"
    );
    // Unknown output extension.
    let e = write_mesh(&dir.path().join("out.3mf"), &spot).unwrap_err();
    assert!(matches!(e, Error::UnsupportedFormat { .. }), "{e}");
}

#[test]
fn writing_replaces_an_existing_file() {
    let (spot, _) = read("spot.obj");
    let dir = tempfile::tempdir().unwrap();
    for ext in ["obj", "ply", "glb"] {
        let path = dir.path().join(format!("old.{ext}"));
        fs::write(&path, b"old content that is not a mesh").unwrap();
        write_mesh(&path, &spot).unwrap();
        let (back, _) = read_mesh(&path).unwrap();
        assert_eq!(back.face_count(), spot.face_count());
    }
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 3);
}

#[test]
fn meshes_that_cannot_be_written_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let bad_index = TriMesh::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], vec![[0, 1, 3]]);
    let nan = TriMesh::new(
        vec![DVec3::ZERO, DVec3::X, DVec3::new(f64::NAN, 0.0, 0.0)],
        vec![[0, 1, 2]],
    );
    for (name, mesh) in [
        ("a.obj", &bad_index),
        ("b.ply", &nan),
        ("c.glb", &TriMesh::default()),
    ] {
        let path = dir.path().join(name);
        let e = write_mesh(&path, mesh).unwrap_err();
        assert!(matches!(e, Error::Write { .. }), "{e}");
        assert!(!path.exists());
    }
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
}

// ---------------------------------------------------------------------------------------------
// Formats in detail

#[test]
fn format_from_extension() {
    assert_eq!(
        MeshFormat::from_path(Path::new("a/B.OBJ")).unwrap(),
        MeshFormat::Obj
    );
    assert_eq!(
        MeshFormat::from_path(Path::new("x.Ply")).unwrap(),
        MeshFormat::Ply
    );
    assert_eq!(
        MeshFormat::from_path(Path::new("x.gltf")).unwrap(),
        MeshFormat::Gltf
    );
    assert_eq!(
        MeshFormat::from_path(Path::new("x.GLB")).unwrap(),
        MeshFormat::Glb
    );
    for bad in ["x.xyz", "x", "obj", "x.obj.gz"] {
        let e = MeshFormat::from_path(Path::new(bad)).unwrap_err();
        assert!(matches!(e, Error::UnsupportedFormat { .. }), "{bad}");
    }
}

#[test]
fn stats_serialize() {
    let (_, s) = read("spot.obj");
    let json = serde_json::to_value(&s).unwrap();
    assert_eq!(json["format"], "obj");
    assert_eq!(json["vertices_read"], 2930);
    assert_eq!(json["faces_read"], 5856);
}

#[test]
fn obj_polygons_relative_indices_and_groups() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("poly.obj");
    fs::write(
        &path,
        "mtllib missing.mtl\n\
         # a quad, a pentagon and a triangle in two groups\r\n\
         o first\n\
         v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
         vt 0 0\nvn 0 0 1\n\
         usemtl nothing\n\
         f -4/1/1 -3/1/1 -2/1/1 -1/1/1\n\
         g second\n\
         v 2 0 0\nv 3 0 0\nv 3 1 0\nv 2.5 2 0\nv 2 1 0   # trailing comment\n\
         f 5//1 6//1 7//1 8//1 \\\n   9//1\n\
         l 1 2\n\
         p 3\n\
         f 1 2\n\
         f 2 6 3\n",
    )
    .unwrap();
    let (m, s) = read_mesh(&path).unwrap();
    assert_eq!(s.vertices_read, 9);
    assert_eq!(s.faces_read, 3);
    assert_eq!(s.polygons_triangulated, 2);
    assert_eq!(
        m.triangles,
        vec![
            [0, 1, 2],
            [0, 2, 3],
            [4, 5, 6],
            [4, 6, 8],
            [6, 7, 8],
            [1, 5, 2]
        ]
    );
    assert_eq!(m.positions[7], DVec3::new(2.5, 2.0, 0.0));

    // Classic Mac OS line ends.
    let path = dir.path().join("cr.obj");
    fs::write(&path, "v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r").unwrap();
    let (m, _) = read_mesh(&path).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2]]);
}

#[test]
fn ascii_ply_polygons_are_triangulated() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("poly.ply");
    fs::write(
        &path,
        "ply\n\
         format ascii 1.0\n\
         comment a quad, a pentagon and a triangle; ushort indices, double and int coordinates\n\
         element vertex 9\n\
         property double x\n\
         property int y\n\
         property float z\n\
         property uchar red\n\
         element face 3\n\
         property list uchar ushort vertex_index\n\
         property float quality\n\
         end_header\n\
         0 0 0 1\n1 0 0 1\n1 1 0 1\n0 1 0 1\n\
         2.5 0 0 1\n3 0 0 1\n3 1 0 1\n2.5 2 0.5 1\n2 1 0 1\n\
         4 0 1 2 3 0.5\n\
         5 4 5 6 7 8 0.5\n\
         3 1 5 2 0.5\n",
    )
    .unwrap();
    let (m, s) = read_mesh(&path).unwrap();
    assert_eq!(s.format, MeshFormat::Ply);
    assert_eq!(
        (s.vertices_read, s.faces_read, s.polygons_triangulated),
        (9, 3, 2)
    );
    assert_eq!(
        m.triangles,
        vec![
            [0, 1, 2],
            [0, 2, 3],
            [4, 5, 6],
            [4, 6, 8],
            [6, 7, 8],
            [1, 5, 2]
        ]
    );
    assert_eq!(m.positions[7], DVec3::new(2.5, 2.0, 0.5));
}

#[test]
fn big_endian_ply_with_int_indices() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("be.ply");
    let mut bytes = b"ply\nformat binary_big_endian 1.0\nelement vertex 4\n\
        property float x\nproperty float y\nproperty float z\n\
        element face 1\nproperty list uchar uint vertex_indices\nend_header\n"
        .to_vec();
    for p in [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ] {
        for c in p {
            bytes.extend_from_slice(&c.to_be_bytes());
        }
    }
    bytes.push(4);
    for i in [0u32, 1, 2, 3] {
        bytes.extend_from_slice(&i.to_be_bytes());
    }
    fs::write(&path, &bytes).unwrap();
    let (m, s) = read_mesh(&path).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(s.polygons_triangulated, 1);
    assert_eq!(m.positions[2], DVec3::new(1.0, 1.0, 0.0));
}

/// Issue 14, item 11: PLY `tristrips` (the Georgia Tech archive's models: `element tristrips 1`,
/// `property list int int vertex_indices`, strips separated by -1) was read as "no faces". The
/// strips give their triangles with the alternating winding (every triangle facing +z here),
/// the degenerate stitching triangles left out, in ascii and binary files.
#[test]
fn ply_triangle_strips_are_read_with_alternating_winding() {
    let dir = tempfile::tempdir().unwrap();
    // Two rows of four vertices, x = 0..3: even indices at y = 0, odd ones at y = 1.
    let positions: Vec<[f32; 3]> = (0..8)
        .map(|i| [(i / 2) as f32, (i % 2) as f32, 0.0])
        .collect();
    // One strip over the first two quads, then -1 and a second strip over the third quad that
    // starts with two degenerate (stitching) triangles.
    let strips: [i32; 13] = [1, 0, 3, 2, 5, 4, -1, 4, 4, 5, 4, 7, 6];
    let header = |format: &str| {
        format!(
            "ply\nformat {format} 1.0\ncomment a strip mesh\nelement vertex 8\n\
             property float x\nproperty float y\nproperty float z\nelement tristrips 1\n\
             property list int int vertex_indices\nend_header\n"
        )
    };
    let mut ascii = header("ascii");
    for p in &positions {
        ascii += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    ascii += &format!("{}", strips.len());
    for i in strips {
        ascii += &format!(" {i}");
    }
    ascii += "\n";
    let mut binary = header("binary_little_endian").into_bytes();
    for c in positions.iter().flatten() {
        binary.extend_from_slice(&c.to_le_bytes());
    }
    binary.extend_from_slice(&(strips.len() as i32).to_le_bytes());
    for i in strips {
        binary.extend_from_slice(&i.to_le_bytes());
    }
    for (name, bytes) in [("ascii.ply", ascii.into_bytes()), ("binary.ply", binary)] {
        let path = dir.path().join(name);
        fs::write(&path, &bytes).unwrap();
        let (m, s) = read_mesh(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            m.triangles,
            vec![
                [1, 0, 3],
                [3, 0, 2],
                [3, 2, 5],
                [5, 2, 4],
                [5, 4, 7],
                [7, 4, 6]
            ],
            "{name}"
        );
        assert_eq!((s.vertices_read, s.faces_read), (8, 6), "{name}");
        for f in 0..m.face_count() {
            assert!(
                m.face_normal(f).distance(DVec3::Z) < 1e-12,
                "{name} face {f}"
            );
        }
    }
    // An index that is neither -1 nor a vertex names the strip record.
    let path = dir.path().join("bad.ply");
    fs::write(
        &path,
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nelement tristrips 1\nproperty list int int vertex_indices\n\
         end_header\n0 0 0\n1 0 0\n0 1 0\n4 0 1 -2 2\n",
    )
    .unwrap();
    let e = expect_err(&path);
    assert!(e.to_string().contains("tristrips record 0"), "{e}");
    assert!(e.to_string().contains("vertex -2"), "{e}");
}

/// Standard base64 with padding, as data URIs hold it.
fn base64(data: &[u8]) -> String {
    use base64::Engine;
    base64::engine::general_purpose::STANDARD.encode(data)
}

/// A .gltf with one triangle mesh (plus a point primitive) placed twice: under a parent with
/// translation and scale and a child with a rotation, and under a mirroring node.
#[test]
fn gltf_node_transforms_are_composed() {
    let positions: [[f32; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let bin: Vec<u8> = positions
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    let h = std::f32::consts::FRAC_1_SQRT_2;
    let doc = serde_json::json!({
        "asset": { "version": "2.0" },
        "scene": 0,
        "scenes": [ { "nodes": [0, 2] } ],
        "nodes": [
            { "translation": [10.0, 0.0, 0.0], "scale": [2.0, 2.0, 2.0], "children": [1] },
            { "rotation": [0.0, 0.0, h, h], "mesh": 0 },
            { "scale": [-1.0, 1.0, 1.0], "translation": [0.0, 0.0, 5.0], "mesh": 0 }
        ],
        "meshes": [ { "primitives": [
            { "attributes": { "POSITION": 0 } },
            { "attributes": { "POSITION": 0 }, "mode": 0 }
        ] } ],
        "accessors": [ { "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                         "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 1.0] } ],
        "bufferViews": [ { "buffer": 0, "byteLength": 36 } ],
        "buffers": [ { "byteLength": 36,
                       "uri": format!("data:application/octet-stream;base64,{}", base64(&bin)) } ]
    });
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("nested.gltf");
    fs::write(&path, serde_json::to_vec_pretty(&doc).unwrap()).unwrap();
    let (m, s) = read_mesh(&path).unwrap();
    assert_eq!(s.format, MeshFormat::Gltf);
    assert_eq!(
        s.skipped_primitives, 2,
        "the point primitive, once per instance"
    );
    assert_eq!((s.vertices_read, s.faces_read), (6, 2));
    assert_eq!(m.vertex_count(), 6);
    // First instance: p -> T(10,0,0) * S(2) * Rz(90°) * p.
    let expected = [
        DVec3::new(10.0, 2.0, 0.0),
        DVec3::new(8.0, 0.0, 0.0),
        DVec3::new(10.0, 0.0, 2.0),
        // Second instance: mirrored in x, moved up 5.
        DVec3::new(-1.0, 0.0, 5.0),
        DVec3::new(0.0, 1.0, 5.0),
        DVec3::new(0.0, 0.0, 6.0),
    ];
    for (got, want) in m.positions.iter().zip(expected) {
        assert!(got.distance(want) < 1e-6, "{got} != {want}");
    }
    assert_eq!(m.triangles[0], [0, 1, 2]);
    // The rotation keeps the orientation (normal (1,1,1) rotated); the mirror reverses the
    // winding so that the normal is the mirrored one, (-1,1,1), not its opposite.
    let n0 = m.face_normal(0);
    assert!(
        n0.distance(DVec3::new(-1.0, 1.0, 1.0).normalize()) < 1e-6,
        "{n0}"
    );
    let n1 = m.face_normal(1);
    assert!(
        n1.distance(DVec3::new(-1.0, 1.0, 1.0).normalize()) < 1e-6,
        "{n1}"
    );
}

/// Node transforms are read in `f64` from the JSON, as written: a matrix and a translation with
/// digits past `f32`'s (mode5.gltf writes its matrices with 16) place the vertices where the
/// numbers say, not where their `f32` roundings would (4e-7 away here).
#[test]
fn gltf_node_transforms_keep_the_digits_written() {
    let positions: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let bin: Vec<u8> = positions
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    let (x, y) = (-12.15649276676408_f64, 38.16685478814292_f64);
    assert!(
        (f64::from(x as f32) - x).abs() > 1e-7,
        "the test case: digits past f32"
    );
    let doc = serde_json::json!({
        "asset": { "version": "2.0" },
        "scene": 0,
        "scenes": [ { "nodes": [0, 1] } ],
        "nodes": [
            { "matrix": [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0,
                         x, y, 0.0, 1.0], "mesh": 0 },
            { "translation": [x, y, 5.0], "rotation": [0.0, 0.0, 0.0, 1.0], "mesh": 0 }
        ],
        "meshes": [ { "primitives": [ { "attributes": { "POSITION": 0 } } ] } ],
        "accessors": [ { "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                         "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0] } ],
        "bufferViews": [ { "buffer": 0, "byteLength": 36 } ],
        "buffers": [ { "byteLength": 36,
                       "uri": format!("data:application/octet-stream;base64,{}", base64(&bin)) } ]
    });
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("digits.gltf");
    fs::write(&path, serde_json::to_vec_pretty(&doc).unwrap()).unwrap();
    let (m, _) = read_mesh(&path).unwrap();
    assert_eq!(m.vertex_count(), 6);
    for (k, z) in [(0, 0.0), (3, 5.0)] {
        let got = m.positions[k];
        assert!(
            got.distance(DVec3::new(x, y, z)) < 1e-12,
            "{got} != ({x}, {y}, {z})"
        );
    }
}

#[test]
fn gltf_strips_fans_and_scene_less_files() {
    // Four vertices of a unit square; a strip and a fan over them, u8 indices; no scene.
    let mut bin: Vec<u8> = [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ]
    .iter()
    .flatten()
    .flat_map(|c| c.to_le_bytes())
    .collect();
    bin.extend_from_slice(&[0, 1, 2, 3]); // strip: (0,1,2), (1,3,2)
    bin.extend_from_slice(&[0, 1, 3, 2]); // fan: (1,3,0), (3,2,0)
    let doc = serde_json::json!({
        "asset": { "version": "2.0" },
        "meshes": [ { "primitives": [
            { "attributes": { "POSITION": 0 }, "indices": 1, "mode": 5 },
            { "attributes": { "POSITION": 0 }, "indices": 2, "mode": 6 },
            { "attributes": { "POSITION": 0 }, "mode": 1 }
        ] } ],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
              "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0] },
            { "bufferView": 1, "componentType": 5121, "count": 4, "type": "SCALAR" },
            { "bufferView": 1, "byteOffset": 4, "componentType": 5121, "count": 4,
              "type": "SCALAR" }
        ],
        "bufferViews": [
            { "buffer": 0, "byteLength": 48 },
            { "buffer": 0, "byteOffset": 48, "byteLength": 8 }
        ],
        "buffers": [ { "byteLength": 56, "uri": "square.bin" } ]
    });
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("square.gltf");
    fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    // The external buffer is missing: an I/O error naming the .gltf.
    let e = expect_err(&path);
    assert!(matches!(e, Error::Io { .. }), "{e}");
    fs::write(dir.path().join("square.bin"), &bin).unwrap();
    let (m, s) = read_mesh(&path).unwrap();
    assert_eq!(s.skipped_primitives, 1);
    assert_eq!(s.faces_read, 4);
    // Both primitives share positions; welding makes them one square with 4 triangles.
    assert_eq!(s.welded_vertices, 4);
    assert_eq!(m.vertex_count(), 4);
    assert_eq!(
        m.triangles,
        vec![[0, 1, 2], [1, 3, 2], [1, 3, 0], [3, 2, 0]]
    );
    for f in 0..4 {
        assert!(m.face_normal(f).distance(DVec3::Z) < 1e-12);
    }
}

/// Issue 14, item 11: glTF files that use Draco without requiring it, and index accessors of
/// u8 (with or without the `normalized` flag), gave parser jargon. The plain accessors beside a
/// Draco stream are read; a file whose geometry only Draco holds (required, or no fallback) is
/// one line naming the compression; u8 indices are read as integers; what glTF does not allow
/// as indices (signed, floating point) is named plainly.
#[test]
fn gltf_draco_fallbacks_and_u8_indices() {
    let dir = tempfile::tempdir().unwrap();
    // A tetrahedron: 4 f32 positions and 12 u8 indices (padded to 4 bytes).
    let positions = [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let faces: [[u8; 3]; 4] = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let mut bin: Vec<u8> = positions
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    bin.extend(faces.iter().flatten());
    let uri = format!("data:application/octet-stream;base64,{}", base64(&bin));
    const DRACO: &str = "KHR_draco_mesh_compression";
    // `used`/`required`: the extension lists; `fallback`: whether the accessors have data.
    let doc = |used: bool, required: bool, fallback: bool, index_accessor: serde_json::Value| {
        let mut primitive = serde_json::json!({ "attributes": { "POSITION": 0 }, "indices": 1 });
        let mut accessors = serde_json::json!([
            { "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
              "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 1.0] },
            index_accessor
        ]);
        if used {
            primitive["extensions"] =
                serde_json::json!({ DRACO: { "bufferView": 1, "attributes": { "POSITION": 0 } } });
        }
        if !fallback {
            for a in accessors.as_array_mut().unwrap() {
                a.as_object_mut().unwrap().remove("bufferView");
            }
        }
        let mut d = serde_json::json!({
            "asset": { "version": "2.0" },
            "scene": 0, "scenes": [ { "nodes": [0] } ], "nodes": [ { "mesh": 0 } ],
            "meshes": [ { "primitives": [primitive] } ],
            "accessors": accessors,
            "bufferViews": [ { "buffer": 0, "byteLength": 48 },
                             { "buffer": 0, "byteOffset": 48, "byteLength": 12 } ],
            "buffers": [ { "byteLength": 60, "uri": uri } ]
        });
        if used {
            d["extensionsUsed"] = serde_json::json!([DRACO]);
        }
        if required {
            d["extensionsRequired"] = serde_json::json!([DRACO]);
        }
        serde_json::to_vec(&d).unwrap()
    };
    let indices = |component_type: u32, normalized: bool| {
        serde_json::json!({ "bufferView": 1, "componentType": component_type, "count": 12,
                            "type": "SCALAR", "normalized": normalized })
    };
    let write = |name: &str, bytes: Vec<u8>| {
        let path = dir.path().join(name);
        fs::write(&path, bytes).unwrap();
        path
    };
    let expected: Vec<[u32; 3]> = faces.iter().map(|f| f.map(u32::from)).collect();
    // Read: u8 indices, u8 indices flagged `normalized`, Draco used with plain fallbacks.
    for (name, bytes) in [
        ("u8.gltf", doc(false, false, true, indices(5121, false))),
        (
            "u8-normalized.gltf",
            doc(false, false, true, indices(5121, true)),
        ),
        (
            "draco-used.gltf",
            doc(true, false, true, indices(5121, false)),
        ),
    ] {
        let path = write(name, bytes);
        let (m, s) = read_mesh(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.triangles, expected, "{name}");
        assert_eq!(m.vertex_count(), 4, "{name}");
        assert_eq!(s.faces_read, 4, "{name}");
    }
    // Refused in one line naming the file and the problem.
    for (name, bytes, says) in [
        (
            "draco-required.gltf",
            doc(true, true, false, indices(5121, false)),
            "uses Draco compression (KHR_draco_mesh_compression), which this reader does not decode",
        ),
        (
            "draco-no-fallback.gltf",
            doc(true, false, false, indices(5121, false)),
            "uses Draco compression (KHR_draco_mesh_compression), which this reader does not decode",
        ),
        (
            "i8.gltf",
            doc(false, false, true, indices(5120, false)),
            "index accessor 1 holds signed 8-bit integers; glTF indices are unsigned",
        ),
    ] {
        let e = expect_err(&write(name, bytes));
        let line = e.to_string();
        assert!(line.contains(says), "{name}: {line}");
        assert_eq!(line.lines().count(), 1, "{line}");
    }
    // The `gltf` crate's validation findings, in words: a missing required property.
    let e = expect_err(&write(
        "no-count.gltf",
        br#"{"asset":{"version":"2.0"},"accessors":[{"componentType":5126,"type":"VEC3"}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]}"#.to_vec(),
    ));
    assert!(!e.to_string().contains("Missing data"), "{e}");
}

// ---------------------------------------------------------------------------------------------
// Errors

#[test]
fn missing_file_and_unknown_extension() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nothing-here.obj");
    assert!(matches!(expect_err(&missing), Error::Io { .. }));
    let xyz = dir.path().join("points.xyz");
    fs::write(&xyz, "0 0 0\n").unwrap();
    assert!(matches!(expect_err(&xyz), Error::UnsupportedFormat { .. }));
}

#[test]
fn empty_files_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    for ext in ["obj", "ply", "glb", "gltf", "stl", "off"] {
        let path = dir.path().join(format!("empty.{ext}"));
        fs::write(&path, b"").unwrap();
        let e = expect_err(&path);
        assert!(e.to_string().contains("the file is empty"), "{e}");
    }
}

#[test]
fn content_that_does_not_match_the_extension_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let ply = common::spot_ply(dir.path());
    let copy = |from: &str, to: &str| {
        let path = dir.path().join(to);
        let from = if from == "spot.ply" {
            ply.clone()
        } else {
            model(from)
        };
        fs::copy(from, &path).unwrap();
        path
    };
    for (from, to, says) in [
        ("spot.ply", "ply-content.obj", "the content is PLY"),
        ("spot.glb", "glb-content.obj", "the content is binary glTF"),
        ("spot.glb", "glb-content.ply", "the content is binary glTF"),
        ("spot.obj", "obj-content.ply", "not a PLY file"),
        ("spot.obj", "obj-content.glb", "not a binary glTF file"),
    ] {
        let e = expect_err(&copy(from, to));
        let text = e.to_string();
        assert!(text.contains(says), "{to}: {text}");
        assert_eq!(text.lines().count(), 1, "{text}");
    }
    // A binary glTF under .gltf is still read.
    assert!(read_mesh(&copy("spot.glb", "binary.gltf")).is_ok());
}

#[test]
fn bad_obj_content() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &str); 8] = [
        ("range", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n"),
        ("nan", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"),
        ("inf", "v 0 0 0\nv 1 0 0\nv 0 1e999 0\nf 1 2 3\n"),
        ("zero", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
        ("relative", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n"),
        ("word", "v 0 0 0\nv 1 0 0\nv 0 1 zero\nf 1 2 3\n"),
        ("short", "v 0 0\nf 1 1 1\n"),
        ("points only", "v 0 0 0\nv 1 0 0\np 1\nl 1 2\n"),
    ];
    for (name, text) in cases {
        let path = dir.path().join(format!("{name}.obj"));
        fs::write(&path, text).unwrap();
        let e = expect_err(&path);
        match name {
            "range" => {
                assert!(matches!(e, Error::InvalidMesh { .. }), "{e}");
                assert!(e.to_string().contains("line 5"), "{e}");
                assert!(e.to_string().contains("vertex 4"), "{e}");
            }
            "nan" | "inf" => {
                assert!(matches!(e, Error::InvalidMesh { .. }), "{e}");
                assert!(e.to_string().contains("vertex 2") || e.to_string().contains("vertex 3"));
            }
            "points only" => assert!(e.to_string().contains("no faces"), "{e}"),
            _ => assert!(
                matches!(e, Error::Parse { line: Some(_), .. }),
                "{name}: {e}"
            ),
        }
    }
}

#[test]
fn bad_ply_content() {
    let dir = tempfile::tempdir().unwrap();
    // A truncated binary PLY.
    let ply = fs::read(common::spot_ply(dir.path())).unwrap();
    for cut in [10, 200, 400, ply.len() / 2, ply.len() - 1] {
        let path = dir.path().join(format!("cut{cut}.ply"));
        fs::write(&path, &ply[..cut]).unwrap();
        assert!(matches!(expect_err(&path), Error::Parse { .. }));
    }
    let header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                  property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                  end_header\n";
    let cases = [
        ("range", format!("{header}0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n")),
        (
            "negative",
            format!("{header}0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n"),
        ),
        (
            "short list",
            format!("{header}0 0 0\n1 0 0\n0 1 0\n3 0 1\n"),
        ),
        (
            "no z",
            header.replace("property float z\n", "") + "0 0\n1 0\n0 1\n3 0 1 2\n",
        ),
        (
            "float list",
            header.replace("uchar int", "uchar float") + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
        ),
        (
            "no faces",
            header.replace(
                "element face 1\nproperty list uchar int vertex_indices\n",
                "",
            ) + "0 0 0\n1 0 0\n0 1 0\n",
        ),
        (
            "obj inside",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_string(),
        ),
    ];
    for (name, text) in cases {
        let path = dir.path().join(format!("{name}.ply"));
        fs::write(&path, text).unwrap();
        let e = expect_err(&path);
        let invalid = matches!(name, "range" | "negative" | "no faces");
        assert_eq!(
            matches!(e, Error::InvalidMesh { .. }),
            invalid,
            "{name}: {e}"
        );
    }
    // A NaN coordinate (binary; the ascii grammar refuses "nan" as a number already).
    let mut bytes = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\n\
        property float x\nproperty float y\nproperty float z\n\
        element face 1\nproperty list uchar int vertex_indices\nend_header\n"
        .to_vec();
    for c in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, f32::NAN, 0.0] {
        bytes.extend_from_slice(&c.to_le_bytes());
    }
    bytes.push(3);
    for i in [0i32, 1, 2] {
        bytes.extend_from_slice(&i.to_le_bytes());
    }
    let path = dir.path().join("nan.ply");
    fs::write(&path, &bytes).unwrap();
    let e = expect_err(&path);
    assert!(matches!(e, Error::InvalidMesh { .. }), "{e}");
    assert!(e.to_string().contains("vertex 2"), "{e}");
}

/// Found by the read_gltf fuzz target: a primitive whose POSITION names an accessor the file does
/// not have made gltf-json's validation panic (an unchecked index); now a one-line error.
#[test]
fn fuzz_regression_gltf_position_accessor_out_of_range() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("no-accessors.gltf");
    fs::write(
        &path,
        r#"{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]}"#,
    )
    .unwrap();
    let e = expect_err(&path);
    assert!(e.to_string().contains("uses accessor 0"), "{e}");
    let path = dir.path().join("indices-out-of-range.gltf");
    fs::write(
        &path,
        r#"{"asset":{"version":"2.0"},"accessors":[{"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,1]}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":7}]}]}"#,
    )
    .unwrap();
    let e = expect_err(&path);
    assert!(e.to_string().contains("uses accessor 7"), "{e}");
    // The fuzzer's own input.
    let found = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fuzz"))
        .join("read_gltf-position-accessor-out-of-range.gltf");
    expect_err(&found);
}

#[test]
fn bad_gltf_content() {
    let dir = tempfile::tempdir().unwrap();
    let spot = fs::read(model("spot.glb")).unwrap();
    let write = |name: &str, bytes: &[u8]| {
        let path = dir.path().join(name);
        fs::write(&path, bytes).unwrap();
        path
    };
    // Truncated GLB files, and a GLB header whose length is below the header's own size.
    for cut in [3, 11, 12, 19, 30, 1000, spot.len() - 4] {
        expect_err(&write(&format!("cut{cut}.glb"), &spot[..cut]));
    }
    let mut short = spot.clone();
    short[8..12].copy_from_slice(&4u32.to_le_bytes());
    expect_err(&write("short.glb", &short));
    let mut huge = spot.clone();
    huge[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    expect_err(&write("huge.glb", &huge));
    // Other content under a glTF extension.
    expect_err(&write("obj.glb", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
    expect_err(&write(
        "garbage.gltf",
        &[0xff, 0xfe, 0x00, 0x42, 0x13, 0x37],
    ));
    // An index out of range, a cycle, an accessor past its buffer, a bad URI.
    let base = |nodes: &str, count: u32, uri: &str| {
        format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
            "nodes":{nodes},
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":{count},"type":"VEC3",
                          "min":[0,0,0],"max":[1,1,0]}},
                         {{"bufferView":1,"componentType":5125,"count":3,"type":"SCALAR"}}],
            "bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":12}}],
            "buffers":[{{"byteLength":48,"uri":"{uri}"}}]}}"#
        )
    };
    let mut bin: Vec<u8> = [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    for i in [0u32, 1, 7] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    let uri = format!("data:application/octet-stream;base64,{}", base64(&bin));
    let e = expect_err(&write(
        "range.gltf",
        base(r#"[{"mesh":0}]"#, 3, &uri).as_bytes(),
    ));
    assert!(matches!(e, Error::InvalidMesh { .. }), "{e}");
    assert!(e.to_string().contains("index 7"), "{e}");
    let cycle = r#"[{"children":[1]},{"children":[0],"mesh":0}]"#;
    let e = expect_err(&write("cycle.gltf", base(cycle, 3, &uri).as_bytes()));
    assert!(e.to_string().contains("cycle"), "{e}");
    let e = expect_err(&write(
        "past.gltf",
        base(r#"[{"mesh":0}]"#, 4, &uri).as_bytes(),
    ));
    assert!(matches!(e, Error::Parse { .. }), "{e}");
    let e = expect_err(&write(
        "uri.gltf",
        base(r#"[{"mesh":0}]"#, 3, "%FF%FE.bin").as_bytes(),
    ));
    assert!(matches!(e, Error::Parse { .. }), "{e}");
}

#[test]
fn garbage_never_panics() {
    let dir = tempfile::tempdir().unwrap();
    let spot_glb = fs::read(model("spot.glb")).unwrap();
    let spot_obj = fs::read(model("spot.obj")).unwrap();
    let mut ply = Vec::new();
    {
        let (m, _) = read("spot.obj");
        let p = dir.path().join("src.ply");
        write_mesh(&p, &m).unwrap();
        ply.extend(fs::read(&p).unwrap());
    }
    // Deterministic pseudo-random corruption: flip bytes, cut files, swap extensions.
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let sources: [&[u8]; 3] = [&spot_glb, &spot_obj, &ply];
    let mut n = 0;
    for round in 0..60 {
        let src = sources[round % 3];
        let mut bytes = src[..(next() as usize % src.len()).max(1)].to_vec();
        if round % 2 == 0 {
            for _ in 0..8 {
                let at = next() as usize % bytes.len();
                bytes[at] = next() as u8;
            }
        }
        for ext in ["obj", "ply", "glb", "stl", "off"] {
            let path = dir.path().join(format!("g{n}.{ext}"));
            n += 1;
            fs::write(&path, &bytes).unwrap();
            if let Err(e) = read_mesh(&path) {
                assert_eq!(error_path(&e), Some(path.as_path()), "{e}");
            }
        }
    }
}

#[test]
fn gltf_extensions_quantized_positions_and_missing_bounds() {
    // Three i16 positions with a byte stride of 8, as KHR_mesh_quantization allows; no
    // min/max; non-geometric required extensions are fine.
    let mut bin = Vec::new();
    for p in [[0i16, 0, 0], [300, 0, 0], [0, -200, 7]] {
        for c in p {
            bin.extend_from_slice(&c.to_le_bytes());
        }
        bin.extend_from_slice(&[0, 0]);
    }
    let doc = |required: &str| {
        serde_json::json!({
            "asset": { "version": "2.0" },
            "extensionsUsed": [required],
            "extensionsRequired": ["KHR_mesh_quantization", required],
            "scenes": [ { "nodes": [0] } ],
            "nodes": [ { "mesh": 0 } ],
            "meshes": [ { "primitives": [ { "attributes": { "POSITION": 0 } } ] } ],
            "accessors": [ { "bufferView": 0, "componentType": 5122, "count": 3,
                             "type": "VEC3" } ],
            "bufferViews": [ { "buffer": 0, "byteLength": 24, "byteStride": 8,
                               "target": 34962 } ],
            "buffers": [ { "byteLength": 24, "uri": format!(
                "data:application/octet-stream;base64,{}", base64(&bin)) } ]
        })
    };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("quantized.gltf");
    fs::write(&path, doc("KHR_materials_unlit").to_string()).unwrap();
    let (m, _) = read_mesh(&path).unwrap();
    assert_eq!(
        m.positions,
        vec![
            DVec3::ZERO,
            DVec3::new(300.0, 0.0, 0.0),
            DVec3::new(0.0, -200.0, 7.0)
        ]
    );
    let path = dir.path().join("draco.gltf");
    fs::write(&path, doc("KHR_draco_mesh_compression").to_string()).unwrap();
    let e = expect_err(&path);
    assert!(e.to_string().contains("KHR_draco_mesh_compression"), "{e}");
}
