//! Issue 6: the table of bad and awkward inputs, each run through the `remesh` binary with its
//! expected outcome. Either a correct result (exit 0, an output whose invariants hold) or a
//! one-line error naming the file and the problem, with the exit code of its kind: 2 usage, 3
//! input, 4 output, 1 internal. Never a panic, a hang, a half-written or clobbered file.
//!
//! | case | outcome |
//! |---|---|
//! | empty file (.obj, .ply, .glb) | input error |
//! | truncated binary PLY, truncated .glb | input error |
//! | content that does not match the extension | input error |
//! | NaN or infinite coordinates | input error |
//! | face index out of range | input error |
//! | negative (relative) OBJ indices | result, identical to the positive-index file's |
//! | quads and n-gons | result, closed genus 0 |
//! | concave polygons (an L-shaped prism with 6-gon caps), OBJ and PLY | read without overlap;
//! result closed genus 0, no "passes through itself" note |
//! | degenerate and zero-area faces | result, closed genus 0 |
//! | duplicate vertices and duplicate faces | result, closed genus 0 |
//! | non-manifold edges and vertices | result, manifold |
//! | open boundaries | result with the input's boundary loops |
//! | many components, some of a few triangles | result, invariants hold, what was dropped noted |
//! | bounding box 1e-6 and 1e6 across | result in the input's units and place |
//! | glTF with several meshes and nested node transforms | result, the same as the flattened OBJ |
//! | `--points` 0, 1, 3 | usage error |
//! | `--points` over the limit (20 million) | usage error |
//! | `--points` 100 times the input's vertex count | result within 1% of the count |
//! | `--points` 5000 on a single triangle | result within 1%, one boundary loop |
//! | output in a missing directory, or under a file | output error, nothing written |
//! | output path equal to the input path | usage error, input untouched |
//! | `--sigma-p` too small for memory (issue 14) | usage error naming the smallest it takes, at
//! once |
//! | `--points` or `--sigma-p` giving no triangle (issue 14) | usage error, nothing written (not an
//! empty file) |
//! | an unsupported output extension (issue 14) | usage error before any work |
//! | `remesh points` or `simplify` to a non-.ply output (issue 14) | usage error, nothing written |
//! | `quality --ref` of a reference without area (issue 14) | input error naming the reference |
//! | glTF nodes listed as a child twice or by two parents (issue 14) | input error, at once |
//! | `remesh points --count` above 10^9 (issue 14) | usage error, nothing written |
//! | a model at UTM coordinates written as .ply, .glb, .gltf (issue 14) | the file as written is
//! faithful |
//! | a truncated point file for `simplify` (issue 14) | input error giving the points read and
//! promised |
//! | subnormal coordinates, a model scaled by 1e-310 (issue 14) | result in the input's units and
//! place, with a note; glTF output a usage error |
//! | an internal failure (a panic) | internal error, one line (injected in `app::catch_panics`'s
//! unit test; the binary runs every job through it) |

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use glam::DVec3;
use serde_json::Value;

fn shared(name: &str) -> PathBuf {
    common::model(name)
}

fn remesh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_remesh"))
        .args(args)
        .output()
        .expect("run remesh")
}

/// The run failed with `code`, printed exactly one line on stderr that contains every one of
/// `mentions`, and left `output` absent.
fn assert_error(o: &Output, code: i32, mentions: &[&str], output: &Path) {
    common::assert_one_line_error(o, code, mentions);
    assert!(!output.exists(), "{} was written", output.display());
}

/// Remeshes `input` to `output` with `--report` and `--strict`, expecting success (so the
/// invariants hold and the topology is the input's); returns the report.
fn assert_result(input: &Path, output: &Path, extra: &[&str]) -> Value {
    let r = assert_remeshed(input, output, &[&["--strict"], extra].concat());
    assert_eq!(r["topology_changes"].as_array().unwrap().len(), 0, "{r}");
    r
}

/// Remeshes `input` to `output` with `--report`, expecting success and the output's invariants
/// to hold; returns the report.
fn assert_remeshed(input: &Path, output: &Path, extra: &[&str]) -> Value {
    let report = output.with_extension("json");
    let mut args = vec![
        input.to_str().unwrap(),
        output.to_str().unwrap(),
        "-q",
        "--no-distance",
        "--report",
        report.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = remesh(&args);
    assert!(
        o.status.success(),
        "{}: {}",
        input.display(),
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(output.exists());
    let r: Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["self_intersections"]["pairs"], 0);
    assert_eq!(r["invariant_violations"].as_array().unwrap().len(), 0);
    r
}

fn topo(r: &Value, key: &str) -> i64 {
    r["topology"][key].as_i64().unwrap()
}

fn assert_closed_genus_0(r: &Value) {
    assert_eq!(topo(r, "boundary_edges"), 0, "{}", r["topology"]);
    assert_eq!(topo(r, "components"), 1, "{}", r["topology"]);
    assert_eq!(topo(r, "euler_characteristic"), 2, "{}", r["topology"]);
}

mod common;

/// An icosphere of radius 1 (the icosahedron subdivided `levels` times, outward faces) as plain
/// coordinates and faces.
fn icosphere(levels: u32) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let m = common::icosphere(levels);
    (
        m.positions.iter().map(|p| p.to_array()).collect(),
        m.triangles.iter().map(|t| t.map(|v| v as usize)).collect(),
    )
}

/// OBJ text of polygons (1-based indices, or relative ones counted from the end).
fn obj(p: &[[f64; 3]], faces: &[Vec<usize>], relative: bool) -> String {
    let mut s = String::new();
    for v in p {
        s += &format!("v {:?} {:?} {:?}\n", v[0], v[1], v[2]);
    }
    for f in faces {
        s += "f";
        for &i in f {
            if relative {
                s += &format!(" {}", i as i64 - p.len() as i64);
            } else {
                s += &format!(" {}", i + 1);
            }
        }
        s += "\n";
    }
    s
}

fn tri_faces(f: &[[usize; 3]]) -> Vec<Vec<usize>> {
    f.iter().map(|t| t.to_vec()).collect()
}

fn write(dir: &Path, name: &str, content: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, content).unwrap();
    p
}

#[test]
fn unreadable_inputs_are_one_line_input_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.obj");
    let spot_ply = std::fs::read(common::spot_ply(dir.path())).unwrap();
    let spot_glb = std::fs::read(shared("spot.glb")).unwrap();
    let cases: Vec<(PathBuf, &str)> = vec![
        (write(dir.path(), "empty.obj", ""), "empty"),
        (write(dir.path(), "empty.ply", ""), "empty"),
        (write(dir.path(), "empty.glb", ""), "empty"),
        (
            write(dir.path(), "cut.ply", &spot_ply[..spot_ply.len() / 2]),
            "cut.ply",
        ),
        (
            write(dir.path(), "cut.glb", &spot_glb[..spot_glb.len() / 2]),
            "cut.glb",
        ),
        (write(dir.path(), "ply-inside.obj", &spot_ply), "PLY"),
        (
            write(
                dir.path(),
                "nan.obj",
                "v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n",
            ),
            "non-finite",
        ),
        (
            write(
                dir.path(),
                "inf.obj",
                "v 0 0 0\nv 1 0 inf\nv 0 1 0\nf 1 2 3\n",
            ),
            "non-finite",
        ),
        (
            write(
                dir.path(),
                "range.obj",
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
            ),
            "names vertex 9",
        ),
    ];
    for (path, problem) in cases {
        let o = remesh(&[path.to_str().unwrap(), out.to_str().unwrap(), "-q"]);
        let name = path.file_name().unwrap().to_str().unwrap();
        assert_error(&o, 3, &[name, problem], &out);
    }
    // An existing output is not clobbered by a failed run.
    std::fs::write(&out, "keep").unwrap();
    let o = remesh(&[
        dir.path().join("nan.obj").to_str().unwrap(),
        out.to_str().unwrap(),
        "-q",
    ]);
    assert_eq!(o.status.code(), Some(3));
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "keep");
}

#[test]
fn relative_obj_indices_give_the_same_output_as_absolute_ones() {
    let dir = tempfile::tempdir().unwrap();
    let (p, f) = icosphere(3);
    let a = write(dir.path(), "abs.obj", obj(&p, &tri_faces(&f), false));
    let b = write(dir.path(), "rel.obj", obj(&p, &tri_faces(&f), true));
    let (oa, ob) = (dir.path().join("a.obj"), dir.path().join("b.obj"));
    let ra = assert_result(&a, &oa, &["--points", "300"]);
    assert_result(&b, &ob, &["--points", "300"]);
    assert_closed_genus_0(&ra);
    assert_eq!(std::fs::read(&oa).unwrap(), std::fs::read(&ob).unwrap());
}

#[test]
fn quads_and_ngons_are_triangulated() {
    // A cube of quads, and a hexagonal prism with hexagon caps.
    let dir = tempfile::tempdir().unwrap();
    let cube_p = vec![
        [0., 0., 0.],
        [1., 0., 0.],
        [1., 1., 0.],
        [0., 1., 0.],
        [0., 0., 1.],
        [1., 0., 1.],
        [1., 1., 1.],
        [0., 1., 1.],
    ];
    let cube_f = vec![
        vec![0, 3, 2, 1],
        vec![4, 5, 6, 7],
        vec![0, 1, 5, 4],
        vec![1, 2, 6, 5],
        vec![2, 3, 7, 6],
        vec![3, 0, 4, 7],
    ];
    let cube = write(dir.path(), "cube.obj", obj(&cube_p, &cube_f, false));
    let r = assert_result(
        &cube,
        &dir.path().join("cube-out.obj"),
        &["--points", "400"],
    );
    assert_closed_genus_0(&r);
    let mut prism_p = Vec::new();
    for z in [0.0, 2.0] {
        for k in 0..6 {
            let a = std::f64::consts::TAU * k as f64 / 6.0;
            prism_p.push([a.cos(), a.sin(), z]);
        }
    }
    let mut prism_f = vec![(0..6).rev().collect::<Vec<_>>(), (6..12).collect()];
    for k in 0..6 {
        let n = (k + 1) % 6;
        prism_f.push(vec![k, n, n + 6, k + 6]);
    }
    let prism = write(dir.path(), "prism.obj", obj(&prism_p, &prism_f, false));
    let r = assert_result(
        &prism,
        &dir.path().join("prism-out.obj"),
        &["--points", "500"],
    );
    assert_closed_genus_0(&r);
}

#[test]
fn degenerate_zero_area_and_duplicate_faces_and_vertices_are_absorbed() {
    let dir = tempfile::tempdir().unwrap();
    let (mut p, f) = icosphere(3);
    let mut faces = tri_faces(&f);
    // A face repeating an index, a zero-area face of three distinct collinear points, and a
    // duplicate of an existing face.
    let a = p.len();
    p.push([0.0, 0.0, 0.5]);
    p.push([0.1, 0.0, 0.5]);
    p.push([0.2, 0.0, 0.5]);
    faces.push(vec![0, 0, 1]);
    faces.push(vec![a, a + 1, a + 2]);
    faces.push(faces[5].clone());
    let messy = write(dir.path(), "messy.obj", obj(&p, &faces, false));
    let r = assert_result(
        &messy,
        &dir.path().join("messy-out.obj"),
        &["--points", "400"],
    );
    assert_closed_genus_0(&r);
    // Every face with its own three vertices (no sharing), and every vertex also repeated.
    let mut q = Vec::new();
    let mut split = Vec::new();
    for t in &f {
        split.push(vec![q.len(), q.len() + 1, q.len() + 2]);
        q.extend(t.iter().map(|&i| p[i]));
    }
    let soup = write(dir.path(), "soup.obj", obj(&q, &split, false));
    let r = assert_result(
        &soup,
        &dir.path().join("soup-out.obj"),
        &["--points", "400"],
    );
    assert_closed_genus_0(&r);
}

/// Two icospheres (level 2) touching at one vertex (a non-manifold vertex), and with `fin`, a
/// third triangle on an edge of the lower one (a non-manifold edge). Its χ is 3 (2 + 2 − 1 for
/// the shared vertex; the fin adds 1 − 2 + 1 = 0): odd, so no manifold closed output has it.
fn spheres_touching_at_a_vertex(fin: bool) -> (Vec<[f64; 3]>, Vec<Vec<usize>>) {
    let (p, f) = icosphere(2);
    let top = (0..p.len())
        .max_by(|&a, &b| p[a][2].total_cmp(&p[b][2]))
        .unwrap();
    let mut q = p.clone();
    let off = q.len();
    // The second sphere, moved up so that its lowest vertex lands on the first's highest.
    let low = (0..p.len())
        .min_by(|&a, &b| p[a][2].total_cmp(&p[b][2]))
        .unwrap();
    let shift = [
        p[top][0] - p[low][0],
        p[top][1] - p[low][1],
        p[top][2] - p[low][2],
    ];
    q.extend(
        p.iter()
            .map(|v| [v[0] + shift[0], v[1] + shift[1], v[2] + shift[2]]),
    );
    let mut faces = tri_faces(&f);
    faces.extend(f.iter().map(|t| {
        t.iter()
            .map(|&i| if i == low { top } else { i + off })
            .collect::<Vec<_>>()
    }));
    if fin {
        // The fin stands out sideways from the lower sphere's face farthest along -x.
        let side = f
            .iter()
            .min_by(|s, t| {
                let x = |t: &[usize; 3]| t.iter().map(|&i| p[i][0]).sum::<f64>();
                x(s).total_cmp(&x(t))
            })
            .unwrap();
        let [a, b, _] = *side;
        q.push([-2.0, (p[a][1] + p[b][1]) / 2.0, (p[a][2] + p[b][2]) / 2.0]);
        faces.push(vec![a, b, q.len() - 1]);
    }
    (q, faces)
}

#[test]
fn non_manifold_inputs_give_manifold_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let (q, faces) = spheres_touching_at_a_vertex(true);
    let input = write(dir.path(), "nonmanifold.obj", obj(&q, &faces, false));
    let r = assert_remeshed(&input, &dir.path().join("nm-out.obj"), &["--points", "600"]);
    assert_eq!(topo(&r, "non_manifold_edges"), 0);
    assert_eq!(topo(&r, "non_manifold_vertices"), 0);
    let input_t = &r["input_topology"];
    assert!(
        input_t["non_manifold_vertices"].as_i64().unwrap() >= 1,
        "{input_t}"
    );
    assert!(
        input_t["non_manifold_edges"].as_i64().unwrap() >= 1,
        "{input_t}"
    );
}

/// Issue 14, item 4: the report compares the output's components, χ and boundary loops with
/// the input's and lists every difference; `--strict` makes a difference an error. The input
/// (two spheres sharing a vertex, and a fin on a non-manifold edge, χ = 3) cannot come out with
/// its own topology: every closed manifold has an even χ. Without the fin (issue 75) the two
/// spheres are compared apart, as a manifold output must have them: no change, and a note.
#[test]
fn a_topology_change_is_a_note_and_under_strict_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let (q, faces) = spheres_touching_at_a_vertex(false);
    let input = write(dir.path(), "pinched.obj", obj(&q, &faces, false));
    let r = assert_remeshed(&input, &dir.path().join("apart.obj"), &["--points", "600"]);
    assert_eq!(r["input_topology"]["components"], 1, "{r}");
    assert_eq!(r["topology"]["components"], 2, "{r}");
    assert_eq!(r["topology_changes"].as_array().unwrap().len(), 0, "{r}");
    assert!(
        r["notes"]
            .to_string()
            .contains("touch at a vertex come out apart"),
        "{r}"
    );
    let (q, faces) = spheres_touching_at_a_vertex(true);
    let input = write(dir.path(), "touching.obj", obj(&q, &faces, false));
    let r = assert_remeshed(&input, &dir.path().join("out.obj"), &["--points", "600"]);
    assert_eq!(r["input_topology"]["euler_characteristic"], 3, "{r}");
    let changes = r["topology_changes"].as_array().unwrap();
    // Exactly the counts that differ, each with both values.
    for (kind, key) in [
        ("Components", "components"),
        ("EulerCharacteristic", "euler_characteristic"),
        ("BoundaryLoops", "boundary_loops"),
    ] {
        let (a, b) = (&r["input_topology"][key], &r["topology"][key]);
        let listed: Vec<&Value> = changes.iter().filter(|c| c["kind"] == kind).collect();
        if a == b {
            assert!(listed.is_empty(), "{kind}: {r}");
        } else {
            assert_eq!(listed.len(), 1, "{kind}: {r}");
            assert_eq!((&listed[0]["input"], &listed[0]["output"]), (a, b));
        }
    }
    assert!(changes.iter().any(|c| c["kind"] == "EulerCharacteristic"));
    let notes = r["notes"].as_array().unwrap();
    assert!(
        notes.iter().any(|n| n
            .as_str()
            .unwrap()
            .contains("topology differs from the input's")
            && n.as_str().unwrap().contains("where the input has 3")),
        "{r}"
    );
    let strict = dir.path().join("strict.obj");
    let o = remesh(&[
        input.to_str().unwrap(),
        strict.to_str().unwrap(),
        "--points",
        "600",
        "--strict",
        "-q",
        "--no-distance",
    ]);
    assert_error(
        &o,
        1,
        &[
            "topology differs from the input's",
            "not written (--strict)",
        ],
        &strict,
    );
}

#[test]
fn open_boundaries_are_kept() {
    // The upper half of a sphere: one boundary loop.
    let dir = tempfile::tempdir().unwrap();
    let (p, f) = icosphere(3);
    let upper: Vec<Vec<usize>> = f
        .iter()
        .filter(|t| t.iter().all(|&i| p[i][2] > -0.01))
        .map(|t| t.to_vec())
        .collect();
    let input = write(dir.path(), "dome.obj", obj(&p, &upper, false));
    let r = assert_result(
        &input,
        &dir.path().join("dome-out.obj"),
        &["--points", "400"],
    );
    assert_eq!(topo(&r, "boundary_loops"), 1);
    assert_eq!(topo(&r, "components"), 1);
}

#[test]
fn many_components_including_tiny_ones() {
    let dir = tempfile::tempdir().unwrap();
    // A sphere and five single triangles far from it.
    let (mut p, f) = icosphere(3);
    let mut faces = tri_faces(&f);
    for k in 0..5 {
        let x = 3.0 + k as f64;
        let a = p.len();
        p.extend([[x, 0.0, 0.0], [x + 0.1, 0.0, 0.0], [x, 0.1, 0.0]]);
        faces.push(vec![a, a + 1, a + 2]);
    }
    let input = write(dir.path(), "parts.obj", obj(&p, &faces, false));
    let r = assert_result(
        &input,
        &dir.path().join("parts-out.obj"),
        &["--points", "400"],
    );
    assert!(topo(&r, "components") >= 1);
    // The beetle: 33 parts glued along non-manifold edges, open, crossing itself (its
    // topology as a non-manifold complex is not one a manifold output can have: no --strict).
    let r = assert_remeshed(
        &shared("beetle.obj"),
        &dir.path().join("beetle-out.obj"),
        &[],
    );
    assert_eq!(topo(&r, "non_manifold_edges"), 0);
}

#[test]
fn tiny_and_huge_models_come_back_in_their_own_units() {
    let dir = tempfile::tempdir().unwrap();
    let (p, f) = icosphere(3);
    for (scale, offset) in [(0.5e-6, 3.0e-6), (0.5e6, -2.0e6)] {
        let q: Vec<[f64; 3]> = p
            .iter()
            .map(|v| [v[0] * scale + offset, v[1] * scale, v[2] * scale])
            .collect();
        let name = format!("s{scale:e}.obj");
        let input = write(dir.path(), &name, obj(&q, &tri_faces(&f), false));
        let out = dir.path().join(format!("out-{name}"));
        let r = assert_result(&input, &out, &["--points", "400"]);
        assert_closed_genus_0(&r);
        // Every output vertex lies on the input's sphere (radius `scale` around (offset, 0, 0)),
        // to within the chord error of the input's faces.
        let text = std::fs::read_to_string(&out).unwrap();
        let mut n = 0;
        for line in text.lines().filter(|l| l.starts_with("v ")) {
            let c: Vec<f64> = line[2..]
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect();
            let d = ((c[0] - offset).powi(2) + c[1] * c[1] + c[2] * c[2]).sqrt();
            assert!((d / scale - 1.0).abs() < 0.02, "{line}: {}", d / scale);
            n += 1;
        }
        assert!((396..=404).contains(&n), "{n}");
    }
}

#[test]
fn gltf_with_several_meshes_and_nested_transforms_equals_its_flattened_obj() {
    let dir = tempfile::tempdir().unwrap();
    // Mesh 0: a tetrahedron; mesh 1: an octahedron. Node tree: root (translate 10, 0, 0) with
    // children A (scale 2, mesh 0) and B (rotate 90 degrees about z, translate 0, 5, 0) whose
    // child C (mesh 1) is translated by (1, 0, 0).
    let tet: Vec<[f32; 3]> = vec![[1., 1., 1.], [1., -1., -1.], [-1., 1., -1.], [-1., -1., 1.]];
    let tet_i: Vec<u16> = vec![0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2];
    let oct: Vec<[f32; 3]> = vec![
        [1., 0., 0.],
        [-1., 0., 0.],
        [0., 1., 0.],
        [0., -1., 0.],
        [0., 0., 1.],
        [0., 0., -1.],
    ];
    let oct_i: Vec<u16> = vec![
        0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5,
    ];
    let mut buf = Vec::new();
    let push_f32 = |v: &[[f32; 3]], buf: &mut Vec<u8>| {
        for p in v {
            for c in p {
                buf.extend_from_slice(&c.to_le_bytes());
            }
        }
    };
    push_f32(&tet, &mut buf); // 0..48
    for i in &tet_i {
        buf.extend_from_slice(&i.to_le_bytes()); // 48..72
    }
    push_f32(&oct, &mut buf); // 72..144
    for i in &oct_i {
        buf.extend_from_slice(&i.to_le_bytes()); // 144..192
    }
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let gltf = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [
            {"translation": [10.0, 0.0, 0.0], "children": [1, 2]},
            {"scale": [2.0, 2.0, 2.0], "mesh": 0},
            {"rotation": [0.0, 0.0, s, s], "translation": [0.0, 5.0, 0.0], "children": [3]},
            {"translation": [1.0, 0.0, 0.0], "mesh": 1}
        ],
        "meshes": [
            {"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]},
            {"primitives": [{"attributes": {"POSITION": 2}, "indices": 3}]}
        ],
        "buffers": [{"byteLength": buf.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 24},
            {"buffer": 0, "byteOffset": 72, "byteLength": 72},
            {"buffer": 0, "byteOffset": 144, "byteLength": 48}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [-1.0, -1.0, -1.0], "max": [1.0, 1.0, 1.0]},
            {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"},
            {"bufferView": 2, "componentType": 5126, "count": 6, "type": "VEC3",
             "min": [-1.0, -1.0, -1.0], "max": [1.0, 1.0, 1.0]},
            {"bufferView": 3, "componentType": 5123, "count": 24, "type": "SCALAR"}
        ]
    });
    // Binary glTF: the header, the JSON chunk (padded with spaces), the BIN chunk.
    let mut json = serde_json::to_string(&gltf).unwrap().into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut glb = Vec::new();
    glb.extend_from_slice(b"glTF");
    glb.extend_from_slice(&2u32.to_le_bytes());
    glb.extend_from_slice(&((12 + 8 + json.len() + 8 + buf.len()) as u32).to_le_bytes());
    glb.extend_from_slice(&(json.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"JSON");
    glb.extend_from_slice(&json);
    glb.extend_from_slice(&(buf.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"BIN\0");
    glb.extend_from_slice(&buf);
    let g = write(dir.path(), "scene.glb", glb);
    // The same geometry flattened by hand: tetrahedron * 2 + (10, 0, 0); octahedron moved by
    // (1, 0, 0), rotated 90 degrees about z ((x, y) -> (-y, x)), moved by (0, 5, 0) and (10, 0, 0).
    let mut p: Vec<[f64; 3]> = tet
        .iter()
        .map(|v| {
            [
                2.0 * v[0] as f64 + 10.0,
                2.0 * v[1] as f64,
                2.0 * v[2] as f64,
            ]
        })
        .collect();
    let mut faces: Vec<Vec<usize>> = tet_i
        .chunks(3)
        .map(|c| c.iter().map(|&i| i as usize).collect())
        .collect();
    let off = p.len();
    p.extend(oct.iter().map(|v| {
        let (x, y, z) = (v[0] as f64 + 1.0, v[1] as f64, v[2] as f64);
        [-y + 10.0, x + 5.0, z]
    }));
    faces.extend(
        oct_i
            .chunks(3)
            .map(|c| c.iter().map(|&i| i as usize + off).collect()),
    );
    let o = write(dir.path(), "scene.obj", obj(&p, &faces, false));
    let (og, oo) = (dir.path().join("g.obj"), dir.path().join("o.obj"));
    // Without crease detection: the solids' edges are creases a part keeps (automatic detection
    // keeps them), and a crease's sample count, its length over the spacing rounded, can be
    // tipped by one by the float32 rounding of the glTF positions.
    let rg = assert_result(&g, &og, &["--points", "600", "--no-features"]);
    let ro = assert_result(&o, &oo, &["--points", "600", "--no-features"]);
    assert_eq!(topo(&rg, "components"), 2);
    assert_eq!(rg["topology"], ro["topology"]);
    let (a, b) = (
        std::fs::read_to_string(&og).unwrap(),
        std::fs::read_to_string(&oo).unwrap(),
    );
    // The same samples up to float32 rounding of the glTF positions: compare vertex by vertex.
    let coords = |t: &str| -> Vec<f64> {
        t.lines()
            .filter(|l| l.starts_with("v "))
            .flat_map(|l| {
                l[2..]
                    .split_whitespace()
                    .map(|x| x.parse::<f64>().unwrap())
                    .collect::<Vec<_>>()
            })
            .collect()
    };
    let (ca, cb) = (coords(&a), coords(&b));
    assert_eq!(ca.len(), cb.len());
    let worst = ca
        .iter()
        .zip(&cb)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-4, "{worst}");
}

#[test]
fn point_counts_out_of_range_are_usage_errors_and_large_ones_work() {
    let dir = tempfile::tempdir().unwrap();
    let (p, f) = icosphere(0);
    let ico = write(dir.path(), "ico.obj", obj(&p, &tri_faces(&f), false));
    let out = dir.path().join("out.obj");
    for n in ["0", "1", "3", "20000001"] {
        let o = remesh(&[ico.to_str().unwrap(), out.to_str().unwrap(), "--points", n]);
        assert_error(&o, 2, &["--points"], &out);
    }
    // 100 times the input's 12 vertices.
    let r = assert_result(&ico, &out, &["--points", "1200"]);
    let v = topo(&r, "vertices");
    assert!((1188..=1212).contains(&v), "{v}");
    assert_closed_genus_0(&r);
    // Far more points than the input has: a single triangle remeshed with 5000 vertices.
    let tri = write(
        dir.path(),
        "tri.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    );
    let r = assert_result(&tri, &dir.path().join("tri-out.obj"), &["--points", "5000"]);
    let v = topo(&r, "vertices");
    assert!((4950..=5050).contains(&v), "{v}");
    assert_eq!((topo(&r, "components"), topo(&r, "boundary_loops")), (1, 1));
}

#[test]
fn outputs_that_cannot_be_written_are_output_errors() {
    let dir = tempfile::tempdir().unwrap();
    let input = shared("spot.obj");
    let missing = dir.path().join("no/such/dir/out.obj");
    let o = remesh(&[input.to_str().unwrap(), missing.to_str().unwrap(), "-q"]);
    assert_error(&o, 4, &["out.obj"], &missing);
    // A path under a regular file: no directory can be made there, whoever runs the test.
    let file = write(dir.path(), "plain", "x");
    let under = file.join("out.obj");
    let o = remesh(&[input.to_str().unwrap(), under.to_str().unwrap(), "-q"]);
    assert_error(&o, 4, &["out.obj"], &under);
    // The same for the report.
    let out = dir.path().join("ok.obj");
    let o = remesh(&[
        input.to_str().unwrap(),
        out.to_str().unwrap(),
        "-q",
        "--no-distance",
        "--report",
        under.to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(4),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    // Nothing but the mesh and no temporary file beside it.
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert!(
        left.iter().all(|n| n == "plain" || n == "ok.obj"),
        "{left:?}"
    );
}

#[test]
fn the_input_is_never_the_output() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("spot.obj");
    std::fs::copy(shared("spot.obj"), &input).unwrap();
    let before = std::fs::read(&input).unwrap();
    let o = remesh(&[input.to_str().unwrap(), input.to_str().unwrap(), "-q"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("is the input file"));
    assert_eq!(std::fs::read(&input).unwrap(), before);
    // Through another spelling of the same path.
    let other = dir.path().join(".").join("spot.obj");
    let o = remesh(&[input.to_str().unwrap(), other.to_str().unwrap(), "-q"]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(std::fs::read(&input).unwrap(), before);
}

/// Issue 14, item 6: `--sigma-p 0.01` on spot asked for about 2e8 samples and aborted with a
/// failed allocation of 11.9 GB and a backtrace; it is now a usage error before any work.
#[test]
fn sigma_p_too_small_for_memory_is_a_usage_error_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.obj");
    let input = shared("spot.obj");
    let t = std::time::Instant::now();
    let o = remesh(&[
        input.to_str().unwrap(),
        out.to_str().unwrap(),
        "--sigma-p",
        "0.01",
    ]);
    assert_error(&o, 2, &["--sigma-p", "smallest sigma_p"], &out);
    assert!(t.elapsed().as_secs_f64() < 10.0, "{:?}", t.elapsed());
}

/// Issue 14, item 11: `--points 5` and `--sigma-p 1000` said "error: : no triangle ..." with an
/// empty file name (exit 3), and with `--no-distance` wrote an empty mesh (exit 0). Where no
/// triangle forms (the umbrellas, which insert no sample) it is a usage error naming the flag,
/// nothing written (or, where the count search ends at a density the umbrellas triangulate, a
/// closed sphere). Issue 75: the restricted Delaunay triangulation (the default) inserts the
/// samples the surface's topology needs, so spot at 5 points comes out a closed sphere (with a
/// note saying how many were inserted where any were); with `--strict` a count that needed
/// them is refused, nothing written (a torus at 5 points).
#[test]
fn a_density_too_small_for_the_surface_keeps_its_topology_or_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.obj");
    let input = shared("spot.obj");
    for (flag, value) in [("--points", "5"), ("--sigma-p", "1000")] {
        for extra in [&[][..], &["--no-distance"][..]] {
            let mut args = vec![input.to_str().unwrap(), out.to_str().unwrap(), flag, value];
            args.extend_from_slice(&["--triangulation", "umbrellas"]);
            args.extend_from_slice(extra);
            let o = remesh(&args);
            if flag == "--points" && o.status.success() {
                // The count search found a density the umbrellas triangulate (a retry with
                // more samples): then the output keeps the input's topology.
                std::fs::remove_file(&out).unwrap();
                let r = assert_remeshed(&input, &out, &args[2..6]);
                assert_eq!(r["topology_changes"].as_array().unwrap().len(), 0, "{r}");
                assert_eq!(
                    (topo(&r, "components"), topo(&r, "euler_characteristic")),
                    (1, 2)
                );
                std::fs::remove_file(&out).unwrap();
            } else {
                assert_error(&o, 2, &[flag, "no triangle"], &out);
            }
        }
    }
    for (flag, value) in [("--points", "5"), ("--sigma-p", "1000")] {
        let r = assert_remeshed(&input, &out, &[flag, value]);
        assert_eq!(r["topology_changes"].as_array().unwrap().len(), 0, "{r}");
        assert_eq!(
            (topo(&r, "components"), topo(&r, "euler_characteristic")),
            (1, 2)
        );
        // At sigma_p 1000 (no search) the cells of the few samples are not discs: samples
        // are inserted. (At --points 5 the search may end at 4 samples whose cells are.)
        let notes = r["notes"].to_string();
        if flag == "--sigma-p" {
            assert!(notes.contains("samples were inserted"), "{notes}");
        }
        std::fs::remove_file(&out).unwrap();
    }
    // A torus takes 7 vertices at least: at 5 points samples are always inserted, which
    // `--strict` refuses.
    let torus = dir.path().join("torus.obj");
    std::fs::write(&torus, torus_obj(24, 12)).unwrap();
    let o = remesh(&[
        torus.to_str().unwrap(),
        out.to_str().unwrap(),
        "--points",
        "5",
        "--strict",
    ]);
    assert_error(
        &o,
        1,
        &["5 points are too few to keep the input's topology"],
        &out,
    );
}

/// A torus (radii 3 and 1) as OBJ text, `n` by `m` quads split in two triangles each.
fn torus_obj(n: usize, m: usize) -> String {
    use std::f64::consts::TAU;
    let mut s = String::new();
    for i in 0..n {
        for j in 0..m {
            let (u, v) = (TAU * i as f64 / n as f64, TAU * j as f64 / m as f64);
            let r = 3.0 + v.cos();
            s += &format!("v {} {} {}\n", r * u.cos(), r * u.sin(), v.sin());
        }
    }
    let at = |i: usize, j: usize| (i % n) * m + (j % m) + 1;
    for i in 0..n {
        for j in 0..m {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            s += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
        }
    }
    s
}

/// Issue 14, item 11: an unsupported output extension was an input error (3), found after the
/// whole remesh; `remesh points … out.obj` wrote PLY bytes under the .obj name.
#[test]
fn outputs_of_a_format_the_command_cannot_write_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let input = shared("spot.obj");
    let unknown = dir.path().join("out.3mf");
    let t = std::time::Instant::now();
    let o = remesh(&[
        input.to_str().unwrap(),
        unknown.to_str().unwrap(),
        "--points",
        "2000",
    ]);
    assert_error(&o, 2, &["out.3mf", "unsupported output format"], &unknown);
    // Before the remesh, not after it.
    assert!(t.elapsed().as_secs_f64() < 10.0, "{:?}", t.elapsed());
    let points_obj = dir.path().join("points.obj");
    let o = remesh(&[
        "points",
        input.to_str().unwrap(),
        points_obj.to_str().unwrap(),
        "--count",
        "100",
    ]);
    assert_error(&o, 2, &["points.obj", ".ply"], &points_obj);
    // simplify too (its input is checked after the output's format).
    let ply = dir.path().join("points.ply");
    let o = remesh(&[
        "points",
        input.to_str().unwrap(),
        ply.to_str().unwrap(),
        "--count",
        "100",
    ]);
    assert_eq!(o.status.code(), Some(0));
    let simplified = dir.path().join("simplified.xyz");
    let o = remesh(&[
        "simplify",
        ply.to_str().unwrap(),
        simplified.to_str().unwrap(),
        "--points",
        "10",
    ]);
    assert_error(&o, 2, &["simplified.xyz", ".ply"], &simplified);
}

/// Issue 14, item 11: `quality MESH --ref REF` with a reference the distance cannot use named
/// MESH; each side's error names its own file.
#[test]
fn quality_names_the_reference_when_the_reference_is_bad() {
    let dir = tempfile::tempdir().unwrap();
    // Three collinear vertices: a face, but no area.
    let flat = write(
        dir.path(),
        "flat-ref.obj",
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
    );
    let mesh = shared("spot.obj");
    let o = remesh(&[
        "quality",
        mesh.to_str().unwrap(),
        "--ref",
        flat.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("flat-ref.obj"), "{err}");
    assert!(!err.contains("spot.obj"), "{err}");
}

/// A glTF (JSON, buffer as a data URI) of one triangle mesh (mesh 0) and the given `nodes`
/// array, whose scene's root is node 0.
fn gltf_with_nodes(nodes: &str) -> String {
    use base64::Engine;
    let mut bin: Vec<u8> = [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    for i in [0u32, 1, 2] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    let data = base64::engine::general_purpose::STANDARD.encode(&bin);
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
        "nodes":{nodes},
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
                      "min":[0,0,0],"max":[1,1,0]}},
                     {{"bufferView":1,"componentType":5125,"count":3,"type":"SCALAR"}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":12}}],
        "buffers":[{{"byteLength":48,"uri":"data:application/octet-stream;base64,{data}"}}]}}"#
    )
}

/// Issue 14, item 7: a 3 KB glTF whose 18 nodes each list their child twice instantiated 2^18
/// meshes (12.5 GB). A node listed as a child more than once, by one parent or by two, is now an
/// input error, found before any geometry is read.
#[test]
fn gltf_nodes_with_several_parents_are_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.obj");
    let chain: Vec<String> = (0..18)
        .map(|i| format!(r#"{{"children":[{0},{0}]}}"#, i + 1))
        .chain([r#"{"mesh":0}"#.to_string()])
        .collect();
    let doubled = write(
        dir.path(),
        "doubled.gltf",
        gltf_with_nodes(&format!("[{}]", chain.join(","))),
    );
    let t = std::time::Instant::now();
    let o = remesh(&[
        doubled.to_str().unwrap(),
        out.to_str().unwrap(),
        "--points",
        "100",
    ]);
    assert_error(
        &o,
        3,
        &["doubled.gltf", "node 1", "listed as a child 2 times"],
        &out,
    );
    assert!(t.elapsed().as_secs_f64() < 10.0, "{:?}", t.elapsed());
    // Two parents of one node.
    let two = write(
        dir.path(),
        "two-parents.gltf",
        gltf_with_nodes(r#"[{"children":[1,2]},{"children":[3]},{"children":[3]},{"mesh":0}]"#),
    );
    let o = remesh(&[
        two.to_str().unwrap(),
        out.to_str().unwrap(),
        "--points",
        "100",
    ]);
    assert_error(&o, 3, &["two-parents.gltf", "node 3"], &out);
    // The same tree without the shared child reads (and is too small to remesh: a usage error
    // of another kind, not an input error).
    let tree = write(
        dir.path(),
        "tree.gltf",
        gltf_with_nodes(r#"[{"children":[1]},{"children":[2]},{"mesh":0}]"#),
    );
    let o = remesh(&["quality", tree.to_str().unwrap()]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Issue 14, item 8: `remesh points --count 99999999999` filled the disk at about 11 GB a
/// minute; counts above the documented limit (10^9) are a usage error before anything is
/// written.
#[test]
fn a_point_count_above_the_limit_is_refused_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("many.ply");
    let input = shared("spot.obj");
    let t = std::time::Instant::now();
    let o = remesh(&[
        "points",
        input.to_str().unwrap(),
        out.to_str().unwrap(),
        "--count",
        "99999999999",
    ]);
    assert_error(&o, 2, &["--count", "1000000000"], &out);
    assert!(t.elapsed().as_secs_f64() < 10.0, "{:?}", t.elapsed());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// `remesh quality MESH --ref REF --json`, expecting success; returns the report.
fn quality(mesh: &Path, reference: &Path) -> Value {
    let o = remesh(&[
        "quality",
        mesh.to_str().unwrap(),
        "--ref",
        reference.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// Issue 14 item 1: a sphere of radius 5 at UTM coordinates (5e5, 5e6). PLY and glTF used to
/// store `f32` world positions (a step of 0.5 at 5e6): the written file's Hausdorff distance to
/// the input was 2.46 (bbox 100; 0.36 as OBJ) while the report, which checked the `f64` mesh,
/// was clean. PLY now stores `double`, glTF positions relative to a node
/// translation, and the report checks the mesh as written.
#[test]
fn utm_coordinates_survive_ply_and_glb_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let (p, f) = icosphere(4);
    let centre = [512_345.678, 5_012_345.678, 123.4];
    let q: Vec<[f64; 3]> = p
        .iter()
        .map(|v| [0, 1, 2].map(|k| v[k] * 5.0 + centre[k]))
        .collect();
    let input = write(dir.path(), "utm.obj", obj(&q, &tri_faces(&f), false));
    for ext in ["obj", "ply", "glb", "gltf"] {
        let out = dir.path().join(format!("out.{ext}"));
        let r = assert_result(&input, &out, &["--points", "1000"]);
        assert_closed_genus_0(&r);
        let w = quality(&out, &input);
        assert_eq!(
            w["invariant_violations"].as_array().unwrap().len(),
            0,
            "{ext}: {w}"
        );
        assert_eq!(w["self_intersections"]["pairs"], 0, "{ext}");
        let h = w["distance"]["hausdorff"].as_f64().unwrap();
        assert!(h < 1.0, "{ext}: Hausdorff {h} (bbox 100)");
    }
}

/// The glTF output places its mesh by a node translation at the bounding box's centre, and
/// reading it back gives world coordinates (those of the same run written as OBJ).
#[test]
fn gltf_output_is_recentred_by_a_node_translation() {
    let dir = tempfile::tempdir().unwrap();
    let (p, f) = icosphere(3);
    let centre = [5.0e5, 5.0e6, -120.0];
    let q: Vec<[f64; 3]> = p
        .iter()
        .map(|v| [0, 1, 2].map(|k| v[k] * 50.0 + centre[k]))
        .collect();
    let input = write(dir.path(), "utm.obj", obj(&q, &tri_faces(&f), false));
    let (gltf, reference) = (dir.path().join("o.gltf"), dir.path().join("o.obj"));
    for out in [&gltf, &reference] {
        assert_result(&input, out, &["--points", "500", "--seed", "3"]);
    }
    let json: Value = serde_json::from_slice(&std::fs::read(&gltf).unwrap()).unwrap();
    let t = json["nodes"][0]["translation"]
        .as_array()
        .expect("a translation");
    for k in 0..3 {
        let c = t[k].as_f64().unwrap();
        assert!((c - centre[k]).abs() < 5.0, "translation {t:?}");
    }
    let min = json["accessors"][0]["min"].as_array().unwrap();
    assert!(
        min.iter().all(|m| m.as_f64().unwrap().abs() < 60.0),
        "{min:?}"
    );
    let (back, _) = spectral_remesh::read_mesh(&gltf).unwrap();
    let (exact, _) = spectral_remesh::read_mesh(&reference).unwrap();
    assert_eq!(back.positions.len(), exact.positions.len());
    for (a, b) in back.positions.iter().zip(&exact.positions) {
        assert!(
            (*a - *b).abs().max_element() <= 1e-6 * b.length(),
            "{a} vs {b}"
        );
    }
}

/// An L-shaped prism (height 1 over the L of the unit squares (0,0), (1,0), (0,1)) as two
/// concave 6-gon caps and six quad sides: positions and outward faces. The caps start at a
/// corner whose fan overlaps (the reflex corner is the fan's third corner).
fn l_prism() -> (Vec<[f64; 3]>, Vec<Vec<usize>>) {
    let l = [[2., 0.], [2., 1.], [1., 1.], [1., 2.], [0., 2.], [0., 0.]];
    let mut p = Vec::new();
    for z in [0.0, 1.0] {
        for [x, y] in l {
            p.push([x, y, z]);
        }
    }
    // The L is counter-clockwise about +z: the bottom cap goes the other way.
    let mut f = vec![(0..6).rev().collect::<Vec<_>>(), (6..12).collect()];
    for k in 0..6 {
        let n = (k + 1) % 6;
        f.push(vec![k, n, n + 6, k + 6]);
    }
    (p, f)
}

#[test]
fn concave_polygon_caps_are_triangulated_without_overlap() {
    use spectral_remesh::internal::self_intersections;
    use spectral_remesh::{check_invariants, read_mesh, topology};
    let dir = tempfile::tempdir().unwrap();
    let (p, f) = l_prism();
    let as_obj = write(dir.path(), "l.obj", obj(&p, &f, false));
    let mut ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\n\
         property double z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        p.len(),
        f.len()
    );
    for [x, y, z] in &p {
        ply += &format!("{x} {y} {z}\n");
    }
    for face in &f {
        ply += &format!("{}", face.len());
        for v in face {
            ply += &format!(" {v}");
        }
        ply += "\n";
    }
    let as_ply = write(dir.path(), "l.ply", ply);
    for input in [&as_obj, &as_ply] {
        let (m, s) = read_mesh(input).unwrap();
        assert_eq!(s.polygons_triangulated, 8);
        // 2 caps of 4 triangles, 6 sides of 2.
        assert_eq!(m.triangles.len(), 20);
        assert_eq!(self_intersections(&m).pairs, 0, "{}", input.display());
        assert!(
            check_invariants(&m).is_empty(),
            "{:?}",
            check_invariants(&m)
        );
        let t = topology(&m);
        assert_eq!(
            (
                t.components,
                t.boundary_edges,
                t.non_manifold_edges,
                t.genus
            ),
            (1, 0, 0, Some(0)),
            "{t:?}"
        );
        // The volume of the L (3), by the divergence theorem: the caps cover the L once.
        let volume: f64 = m
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| m.positions[v as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        assert!((volume - 3.0).abs() < 1e-12, "volume {volume}");

        let out = dir.path().join(format!(
            "out-{}.obj",
            input.extension().unwrap().to_str().unwrap()
        ));
        let r = assert_result(input, &out, &["--points", "1500"]);
        assert_closed_genus_0(&r);
        let notes = r["notes"].as_array().unwrap();
        assert!(
            notes
                .iter()
                .all(|n| !n.as_str().unwrap().contains("passes through itself")),
            "{notes:?}"
        );
    }
}

/// Issue 14, item 9: a job whose estimated peak memory is over `--max-memory` is refused at
/// once (exit 2, one line with the estimate and the limit, nothing written): 5 million points
/// would otherwise run for many minutes and take about 12 GB. An input file larger than the
/// limit is refused before it is read. A job within the limit runs.
#[test]
fn a_job_over_the_memory_limit_fails_fast_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let (p, f) = icosphere(3);
    let input = write(dir.path(), "sphere.obj", obj(&p, &tri_faces(&f), false));
    let out = dir.path().join("out.obj");
    let arg = |s: &Path| s.to_str().unwrap().to_string();
    let t = std::time::Instant::now();
    let o = remesh(&[
        &arg(&input),
        &arg(&out),
        "--points",
        "5000000",
        "--max-memory",
        "1G",
    ]);
    assert_error(&o, 2, &["--max-memory", "GB", "1.000 GB"], &out);
    // A hang guard, not a speed test: the job itself would take many minutes.
    assert!(t.elapsed().as_secs_f64() < 20.0, "{:?}", t.elapsed());
    // --sigma-p: the count it gives (the surface's area over sigma_p², about 3.3 million here).
    let o = remesh(&[
        &arg(&input),
        &arg(&out),
        "--sigma-p",
        "0.05",
        "--max-memory",
        "2GiB",
    ]);
    assert_error(&o, 2, &["--max-memory", "points"], &out);
    // The file alone is larger than the limit.
    let size = std::fs::metadata(&input).unwrap().len();
    let o = remesh(&[
        &arg(&input),
        &arg(&out),
        "--points",
        "400",
        "--max-memory",
        &(size - 1).to_string(),
    ]);
    assert_error(
        &o,
        2,
        &["--max-memory", "sphere.obj", "cannot be remeshed"],
        &out,
    );
    // Not a size.
    let o = remesh(&[&arg(&input), &arg(&out), "--max-memory", "lots"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!out.exists());
    // Within the limit.
    assert_result(&input, &out, &["--points", "400", "--max-memory", "1G"]);
}

/// Issue 14, item 11: a point file cut short said "the file ends after 0" when 100 of its
/// points were there (the count before the chunk being read). The message gives the count the
/// header promised and how many the file can hold, for binary and ascii PLY.
#[test]
fn a_truncated_point_file_gives_the_points_read_and_the_points_promised() {
    let dir = tempfile::tempdir().unwrap();
    let header = |format: &str| {
        format!(
            "ply\nformat {format} 1.0\nelement vertex 200\nproperty float x\nproperty float y\n\
             property float z\nend_header\n"
        )
    };
    let point = |k: usize| [k as f32, (k * k % 17) as f32, (k % 5) as f32];
    let mut binary = header("binary_little_endian").into_bytes();
    let mut ascii = header("ascii");
    for k in 0..100 {
        for c in point(k) {
            binary.extend_from_slice(&c.to_le_bytes());
        }
        let [x, y, z] = point(k);
        ascii += &format!("{x} {y} {z}\n");
    }
    // Half a record more in the binary file: still 100 complete points.
    binary.extend_from_slice(&[0; 6]);
    for (name, content) in [("binary.ply", binary), ("ascii.ply", ascii.into_bytes())] {
        let input = write(dir.path(), name, content);
        let out = dir.path().join(format!("out-{name}"));
        let o = remesh(&[
            "simplify",
            input.to_str().unwrap(),
            out.to_str().unwrap(),
            "--points",
            "20",
            "-q",
        ]);
        // Found from the file's length (issue 36, item 4): exact for binary records, a bound
        // for ascii ones (at least a character and a blank per value).
        let says = if name == "binary.ply" {
            "announces 200 points, the file holds at most 100"
        } else {
            "announces 200 points, the file holds at most"
        };
        assert_error(&o, 3, &[name, says], &out);
    }
}

/// Issue 14, item 11: a model scaled by 1e-310 (subnormal coordinates) was refused with "the
/// bounding box has zero size": `100 / side` overflows `f64`. It is now scaled up by a power
/// of two (exact) for the work and the output scaled back, in the input's units and place, with
/// a note; `remesh quality` measures it the same way. glTF (`f32` positions) cannot hold it: a
/// usage error saying so. A model of one point still has zero size, and says so.
#[test]
fn subnormal_coordinates_are_remeshed_in_their_own_units() {
    let dir = tempfile::tempdir().unwrap();
    let (p, f) = icosphere(3);
    let (scale, offset) = (1e-310, 3e-310);
    let q: Vec<[f64; 3]> = p
        .iter()
        .map(|v| [v[0] * scale + offset, v[1] * scale, v[2] * scale])
        .collect();
    let input = write(dir.path(), "subnormal.obj", obj(&q, &tri_faces(&f), false));
    let out = dir.path().join("out.obj");
    let r = assert_result(&input, &out, &["--points", "400"]);
    assert_closed_genus_0(&r);
    let notes = r["notes"].as_array().unwrap();
    assert!(
        notes.iter().any(|n| n
            .as_str()
            .unwrap()
            .contains("subnormal numbers (bounding box 2e-310")),
        "{notes:?}"
    );
    // Every output vertex lies on the input's sphere (radius 1e-310 around (3e-310, 0, 0)), to
    // within the chord error of the input's faces and the rounding of subnormal numbers.
    let text = std::fs::read_to_string(&out).unwrap();
    let mut n = 0;
    for line in text.lines().filter(|l| l.starts_with("v ")) {
        let c: Vec<f64> = line[2..]
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        // In units of `scale` (squares of subnormal numbers underflow).
        let d = DVec3::new((c[0] - offset) / scale, c[1] / scale, c[2] / scale).length();
        assert!((d - 1.0).abs() < 0.02, "{line}: {d}");
        n += 1;
    }
    assert!((396..=404).contains(&n), "{n}");
    // The written file measured against the input: clean, close.
    let q = quality(&out, &input);
    assert_eq!(
        q["invariant_violations"].as_array().unwrap().len(),
        0,
        "{q}"
    );
    assert!(
        q["distance"]["hausdorff"].as_f64().unwrap() < 2.0,
        "{}",
        q["distance"]
    );
    // glTF stores f32: refused before any work, nothing written.
    let glb = dir.path().join("out.glb");
    let o = remesh(&[input.to_str().unwrap(), glb.to_str().unwrap(), "-q"]);
    assert_error(&o, 2, &["out.glb", "32-bit floats", "subnormal.obj"], &glb);
    // A model of one point has zero size, and says so.
    let point: Vec<[f64; 3]> = p.iter().map(|_| [1.0, 2.0, 3.0]).collect();
    let input = write(dir.path(), "point.obj", obj(&point, &tri_faces(&f), false));
    let none = dir.path().join("none.obj");
    let o = remesh(&[input.to_str().unwrap(), none.to_str().unwrap(), "-q"]);
    assert_error(&o, 3, &["point.obj"], &none);
}

/// Issue 14, item 1 (its last part): `remesh simplify` kept its bucket files in f32, so a point
/// set at UTM coordinates (x ≈ 5e5, y ≈ 5e6, where the f32 step is 0.5) came out moved by up
/// to a quarter unit. The buckets now hold the positions as f64: every output point is an input
/// point, exactly on the radius-5 sphere the input was drawn on.
#[test]
fn simplify_keeps_utm_coordinates() {
    let dir = tempfile::tempdir().unwrap();
    let centre = [512_345.678, 5_012_345.678, 123.4];
    let mut text = String::new();
    let n = 20_000;
    for i in 0..n {
        // A Fibonacci sphere of radius 5.
        let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
        let r = (1.0 - z * z).sqrt();
        let a = i as f64 * 2.399_963_229_728_653;
        let p = [r * a.cos(), r * a.sin(), z].map(|c| c * 5.0);
        text += &format!(
            "{} {} {}\n",
            p[0] + centre[0],
            p[1] + centre[1],
            p[2] + centre[2]
        );
    }
    let input = write(dir.path(), "utm.xyz", text);
    let out = dir.path().join("out.ply");
    let o = remesh(&[
        "simplify",
        input.to_str().unwrap(),
        out.to_str().unwrap(),
        "--points",
        "1000",
        "-q",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut reader = spectral_remesh::internal::PointReader::open(&out).unwrap();
    let mut chunk = Vec::new();
    let mut seen = 0;
    while reader.read_chunk(&mut chunk, 4096).unwrap() > 0 {
        for p in &chunk {
            let d = (p.position - glam::DVec3::from(centre)).length();
            assert!((d - 5.0).abs() < 1e-6, "a point {} off the sphere", d - 5.0);
            seen += 1;
        }
    }
    assert!(seen > 500, "{seen} points");
}
