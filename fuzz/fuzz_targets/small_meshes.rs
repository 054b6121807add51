//! The inputs of the `remesh` target, shared with the regression tests
//! (tests/fuzz_regressions.rs) so that a finding replays exactly: a small mesh (a sphere, a
//! torus, an open sheet, a box, two spheres some gap apart, a sharp cone) made messy as the bytes
//! say (noise, regions of reversed faces, quads and pentagons as polygons, near-degenerate and
//! zero-area faces, holes, duplicate faces, a vertex pulled far out; then, from a last byte, a
//! second copy passing through it, every face again reversed (a double-sided export), a
//! zero-area face first), written as OBJ text; the whole `remesh` job run on it; and what every
//! run must keep.

use std::f64::consts::{PI, TAU};
use std::path::Path;

#[path = "whole_job.rs"]
mod whole_job;
pub use whole_job::run_whole_job;

/// Bytes read in order (0x5a once they run out).
struct Bytes<'a>(&'a [u8], usize);

impl Bytes<'_> {
    fn byte(&mut self) -> u8 {
        let b = self.0.get(self.1).copied().unwrap_or(0x5a);
        self.1 += 1;
        b
    }

    /// A number in [0, 1) from two bytes.
    fn unit(&mut self) -> f64 {
        let v = (self.byte() as u32) << 8 | self.byte() as u32;
        v as f64 / 65536.0
    }

    /// An integer in `0..n`.
    fn below(&mut self, n: usize) -> usize {
        ((self.unit() * n as f64) as usize).min(n - 1)
    }
}

type Faces = Vec<Vec<usize>>;

fn sphere(p: &mut Vec<[f64; 3]>, f: &mut Faces, centre: [f64; 3], r: f64, rings: usize) {
    let segments = 2 * rings;
    let base = p.len();
    p.push([centre[0], centre[1], centre[2] + r]);
    for i in 1..rings {
        let t = PI * i as f64 / rings as f64;
        for j in 0..segments {
            let u = TAU * j as f64 / segments as f64;
            p.push([
                centre[0] + r * t.sin() * u.cos(),
                centre[1] + r * t.sin() * u.sin(),
                centre[2] + r * t.cos(),
            ]);
        }
    }
    p.push([centre[0], centre[1], centre[2] - r]);
    let ring = |i: usize, j: usize| base + 1 + (i - 1) * segments + j % segments;
    let bottom = p.len() - 1;
    for j in 0..segments {
        f.push(vec![base, ring(1, j), ring(1, j + 1)]);
        f.push(vec![bottom, ring(rings - 1, j + 1), ring(rings - 1, j)]);
        for i in 1..rings - 1 {
            f.push(vec![ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)]);
            f.push(vec![ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)]);
        }
    }
}

/// A grid of `n × m` cells over `(u, v)` in [0, 1]², mapped by `at`, wrapping in u and v when
/// asked (a torus wraps both).
fn grid(
    p: &mut Vec<[f64; 3]>,
    f: &mut Faces,
    n: usize,
    m: usize,
    wrap: bool,
    at: impl Fn(f64, f64) -> [f64; 3],
) {
    let base = p.len();
    let (nu, nv) = if wrap { (n, m) } else { (n + 1, m + 1) };
    for i in 0..nu {
        for j in 0..nv {
            p.push(at(i as f64 / n as f64, j as f64 / m as f64));
        }
    }
    let id = |i: usize, j: usize| base + (i % nu) * nv + j % nv;
    for i in 0..n {
        for j in 0..m {
            f.push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            f.push(vec![id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
}

fn cuboid(p: &mut Vec<[f64; 3]>, f: &mut Faces, lo: [f64; 3], hi: [f64; 3]) {
    let base = p.len();
    for k in 0..8 {
        p.push([
            if k & 1 == 0 { lo[0] } else { hi[0] },
            if k & 2 == 0 { lo[1] } else { hi[1] },
            if k & 4 == 0 { lo[2] } else { hi[2] },
        ]);
    }
    for q in [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ] {
        f.push(vec![base + q[0], base + q[1], base + q[2]]);
        f.push(vec![base + q[0], base + q[2], base + q[3]]);
    }
}

/// A small mesh shaped by `data`, as OBJ text, and the `--points` and `--seed` to remesh it
/// with.
pub fn small_mesh(data: &[u8]) -> (String, usize, u64) {
    let mut b = Bytes(data, 0);
    let mut p: Vec<[f64; 3]> = Vec::new();
    let mut f: Faces = Vec::new();
    match b.below(6) {
        0 => sphere(&mut p, &mut f, [0.0; 3], 1.0, 3 + b.below(8)),
        1 => {
            let (big, small) = (1.0, 0.05 + 0.6 * b.unit());
            let (n, m) = (6 + b.below(20), 3 + b.below(10));
            grid(&mut p, &mut f, n, m, true, |u, v| {
                let (u, v) = (u * TAU, v * TAU);
                let r = big + small * v.cos();
                [r * u.cos(), r * u.sin(), small * v.sin()]
            });
        }
        2 => {
            let bend = b.unit();
            let (n, m) = (1 + b.below(12), 1 + b.below(12));
            grid(&mut p, &mut f, n, m, false, |u, v| {
                [u, v, bend * (u * PI).sin() * (v * 2.0).cos()]
            });
        }
        3 => {
            let thin = 10f64.powf(-3.0 * b.unit());
            cuboid(&mut p, &mut f, [0.0; 3], [1.0, 1.0, thin]);
        }
        4 => {
            let gap = 10f64.powf(-2.0 + 2.5 * b.unit());
            let rings = 3 + b.below(6);
            sphere(&mut p, &mut f, [0.0; 3], 1.0, rings);
            sphere(&mut p, &mut f, [2.0 + gap, 0.0, 0.0], 1.0, rings);
        }
        _ => {
            // A cone of apex half-angle 0.5° to 30° on a disc.
            let half = (0.5 + 29.5 * b.unit()).to_radians();
            let n = 3 + b.below(30);
            p.push([0.0, 0.0, 1.0]);
            p.push([0.0, 0.0, 0.0]);
            for j in 0..n {
                let u = TAU * j as f64 / n as f64;
                p.push([half.tan() * u.cos(), half.tan() * u.sin(), 0.0]);
            }
            for j in 0..n {
                let (a, c) = (2 + j, 2 + (j + 1) % n);
                f.push(vec![0, a, c]);
                f.push(vec![1, c, a]);
            }
        }
    }
    // Noise on every vertex: none, or up to 10^-4 to 10^-1.
    let noise = match b.below(4) {
        0 => 0.0,
        k => 10f64.powi(-(5 - k as i32)),
    };
    if noise > 0.0 {
        for v in p.iter_mut() {
            for c in v.iter_mut() {
                *c += noise * (2.0 * b.unit() - 1.0);
            }
        }
    }
    // Up to 6 mutations.
    for _ in 0..b.below(7) {
        if f.is_empty() {
            break;
        }
        let face = b.below(f.len());
        match b.below(7) {
            0 => {
                // Reverse every face near a vertex of this one.
                let centre = p[f[face][0]];
                let r2 = (0.1 + b.unit()).powi(2);
                for t in f.iter_mut() {
                    let q = p[t[0]];
                    let d2: f64 = (0..3).map(|k| (q[k] - centre[k]).powi(2)).sum();
                    if d2 < r2 {
                        t.reverse();
                    }
                }
            }
            1 => {
                // Merge this triangle with a neighbour across an edge into one polygon.
                let t = f[face].clone();
                if t.len() == 3 {
                    if let Some(g) = (0..f.len()).find(|&g| {
                        g != face && f[g].len() == 3 && f[g].contains(&t[0]) && f[g].contains(&t[1])
                    }) {
                        if let Some(&other) = f[g].iter().find(|&&i| i != t[0] && i != t[1]) {
                            f[face] = vec![t[0], other, t[1], t[2]];
                            f.swap_remove(g);
                        }
                    }
                }
            }
            2 => {
                // Pull a vertex almost onto another of its face: near-degenerate faces.
                let t = &f[face];
                let (a, c) = (t[0], t[1]);
                let s = 10f64.powf(-1.0 - 12.0 * b.unit());
                let towards = p[c];
                for (v, t) in p[a].iter_mut().zip(towards) {
                    *v = t + s * (*v - t);
                }
            }
            3 => {
                // A hole.
                f.swap_remove(face);
            }
            4 => {
                // A duplicate face, in either orientation.
                let mut t = f[face].clone();
                if b.byte() & 1 == 1 {
                    t.reverse();
                }
                f.push(t);
            }
            5 => {
                // A vertex pulled far out (up to 1000 times the model's size).
                let a = f[face][0];
                let s = 10f64.powf(3.0 * b.unit());
                for c in p[a].iter_mut() {
                    *c *= s;
                }
            }
            _ => {
                // Every point of the face at the same position (a zero-area face, kept).
                let t = f[face].clone();
                let q = p[t[0]];
                let n = p.len();
                p.push(q);
                p.push(q);
                f.push(vec![t[0], n, n + 1]);
            }
        }
    }
    let points = 20 + b.below(400);
    let seed = b.byte() as u64 % 5 + 1;
    // Scene-level changes from one more byte, read so that an input without it (the byte
    // reads 0x5a past the end) changes nothing, and earlier inputs replay as they were.
    let extras = b.byte() ^ 0x5a;
    if extras & 1 != 0 {
        // A second copy of the mesh passing through the first (a scene's parts that overlap),
        // moved by up to the model's size along x.
        let shift = 0.2 + 1.5 * b.unit();
        let n = p.len();
        p.extend_from_within(..);
        for v in &mut p[n..] {
            v[0] += shift;
        }
        let copies: Faces = f
            .iter()
            .map(|t| t.iter().map(|i| i + n).collect())
            .collect();
        f.extend(copies);
    }
    if extras & 2 != 0 {
        // Exported double-sided: every face again, reversed.
        let back: Faces = f
            .iter()
            .map(|t| t.iter().rev().copied().collect())
            .collect();
        f.extend(back);
    }
    if extras & 4 != 0 && !f.is_empty() {
        // A zero-area face first (parry's BVH once panicked on one that led the list).
        let q = p[f[0][0]];
        let n = p.len();
        p.push([q[0] + 1.0, q[1], q[2]]);
        p.push([q[0] + 2.0, q[1], q[2]]);
        f.insert(0, vec![f[0][0], n, n + 1]);
    }
    let mut obj = String::new();
    for v in &p {
        obj += &format!("v {} {} {}\n", v[0], v[1], v[2]);
    }
    for t in &f {
        obj += "f";
        for i in t {
            obj += &format!(" {}", i + 1);
        }
        obj += "\n";
    }
    (obj, points, seed)
}

/// Runs the whole `remesh` job on the mesh of `data`, in `dir`, and checks what every run must
/// keep: no panic (the caller sees it), an input error or a usage error but never an internal
/// one, and an output that is edge- and vertex-manifold, consistently oriented, free of
/// degenerate and duplicate faces, written, with every change of topology listed in a note.
/// Faces that cross are allowed: thin parts are issue 15's subject.
pub fn assert_remesh_is_sound(data: &[u8], dir: &Path) {
    let (obj, points, seed) = small_mesh(data);
    let input = dir.join("in.obj");
    std::fs::write(&input, obj).expect("writing the input");
    if let Ok(report) = run_whole_job(&input, &dir.join("out.obj"), points, seed) {
        if !report.topology_changes.is_empty() {
            assert!(
                report
                    .notes
                    .iter()
                    .any(|n| n.contains("topology differs from the input's")),
                "a topology change without a note"
            );
        }
    }
}
