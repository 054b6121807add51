//! Meshes built in code, shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Output;

use glam::DVec3;
use spectral_remesh::TriMesh;

/// The path of a test model: `data/NAME` when the checkout has it (spot, beetle), else the
/// shared model `../shared/data/NAME` beside the checkout, which only the tests marked
/// `#[ignore = "needs ../shared"]` read; a missing one fails the test, with its path.
pub fn model(name: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let own = root.join("data").join(name);
    if own.is_file() {
        return own;
    }
    let p = root.join("../shared/data").join(name);
    assert!(
        p.is_file(),
        "{} is missing: this test needs the shared models beside the checkout",
        p.display()
    );
    p
}

/// data/spot.obj written as binary PLY into `dir` (`spot.ply`), as `remesh` writes PLY.
pub fn spot_ply(dir: &Path) -> PathBuf {
    let (spot, _) = spectral_remesh::read_mesh(&model("spot.obj")).unwrap();
    let path = dir.join("spot.ply");
    spectral_remesh::write_mesh(&path, &spot).unwrap();
    path
}

/// Flips every face whose normal points towards the origin (for convex meshes around it).
pub fn orient_outward(mut m: TriMesh) -> TriMesh {
    for f in 0..m.triangles.len() {
        let [a, b, c] = m.corners(f);
        if m.face_cross(f).dot(a + b + c) < 0.0 {
            m.triangles[f].swap(1, 2);
        }
    }
    m
}

/// The regular icosahedron with edge length 2 (V 12, E 30, F 20), outward oriented.
pub fn icosahedron() -> TriMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let positions = vec![
        DVec3::new(-1.0, t, 0.0),
        DVec3::new(1.0, t, 0.0),
        DVec3::new(-1.0, -t, 0.0),
        DVec3::new(1.0, -t, 0.0),
        DVec3::new(0.0, -1.0, t),
        DVec3::new(0.0, 1.0, t),
        DVec3::new(0.0, -1.0, -t),
        DVec3::new(0.0, 1.0, -t),
        DVec3::new(t, 0.0, -1.0),
        DVec3::new(t, 0.0, 1.0),
        DVec3::new(-t, 0.0, -1.0),
        DVec3::new(-t, 0.0, 1.0),
    ];
    let triangles = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    orient_outward(TriMesh::new(positions, triangles))
}

/// The icosahedron subdivided `level` times (each triangle into 4), projected onto the unit
/// sphere: 20·4^level faces.
pub fn icosphere(level: u32) -> TriMesh {
    let mut m = icosahedron();
    for p in &mut m.positions {
        *p = p.normalize();
    }
    for _ in 0..level {
        let mut mid: rustc_hash::FxHashMap<(u32, u32), u32> = Default::default();
        let mut tris = Vec::with_capacity(4 * m.triangles.len());
        let mut midpoint = |a: u32, b: u32, pos: &mut Vec<DVec3>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                pos.push((0.5 * (pos[a as usize] + pos[b as usize])).normalize());
                (pos.len() - 1) as u32
            })
        };
        for t in m.triangles.clone() {
            let ab = midpoint(t[0], t[1], &mut m.positions);
            let bc = midpoint(t[1], t[2], &mut m.positions);
            let ca = midpoint(t[2], t[0], &mut m.positions);
            tris.extend([[t[0], ab, ca], [t[1], bc, ab], [t[2], ca, bc], [ab, bc, ca]]);
        }
        m.triangles = tris;
    }
    m
}

/// A closed axis-aligned box from `lo` to `hi`, each face an `n × n` grid, faces outward.
pub fn grid_box(lo: DVec3, hi: DVec3, n: usize) -> TriMesh {
    grid_box_counts(lo, hi, [n; 3])
}

/// [`grid_box`] with `counts[k]` grid steps along axis k.
pub fn grid_box_counts(lo: DVec3, hi: DVec3, counts: [usize; 3]) -> TriMesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let size = hi - lo;
    // Each face: an origin corner and two edge vectors whose cross product points outward.
    let faces = [
        (
            lo,
            DVec3::new(0.0, size.y, 0.0),
            DVec3::new(size.x, 0.0, 0.0),
        ),
        (
            DVec3::new(lo.x, lo.y, hi.z),
            DVec3::new(size.x, 0.0, 0.0),
            DVec3::new(0.0, size.y, 0.0),
        ),
        (
            lo,
            DVec3::new(size.x, 0.0, 0.0),
            DVec3::new(0.0, 0.0, size.z),
        ),
        (
            DVec3::new(lo.x, hi.y, lo.z),
            DVec3::new(0.0, 0.0, size.z),
            DVec3::new(size.x, 0.0, 0.0),
        ),
        (
            lo,
            DVec3::new(0.0, 0.0, size.z),
            DVec3::new(0.0, size.y, 0.0),
        ),
        (
            DVec3::new(hi.x, lo.y, lo.z),
            DVec3::new(0.0, size.y, 0.0),
            DVec3::new(0.0, 0.0, size.z),
        ),
    ];
    let steps = |d: DVec3| counts[(0..3).find(|&k| d[k] != 0.0).unwrap_or(0)];
    for (origin, u, v) in faces {
        let base = positions.len() as u32;
        let (nu, nv) = (steps(u), steps(v));
        for j in 0..=nv {
            for i in 0..=nu {
                positions.push(origin + u * (i as f64 / nu as f64) + v * (j as f64 / nv as f64));
            }
        }
        let id = |i: usize, j: usize| base + (j * (nu + 1) + i) as u32;
        for j in 0..nv {
            for i in 0..nu {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
    }
    // The faces' shared edges are welded by position.
    let mut mesh = TriMesh::new(positions, triangles);
    mesh.weld_identical_positions();
    mesh
}

/// The run failed with `code` and printed exactly one line on stderr, `remesh: error: …`, that
/// contains every one of `mentions` and no panic.
pub fn assert_one_line_error(o: &Output, code: i32, mentions: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(code), "stderr: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
    assert!(err.starts_with("remesh: error: "), "{err}");
    for m in mentions {
        assert!(err.contains(m), "{err:?} does not mention {m:?}");
    }
    assert!(!err.contains("panicked"), "{err}");
}
