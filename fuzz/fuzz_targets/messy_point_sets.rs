//! The inputs of the `point_sets` target, kept apart from it so that a regression test can replay
//! a finding exactly (as small_meshes.rs is for `remesh`): a scan-like point set shaped by the
//! bytes, written as XYZ text, and the whole `remesh` job run on it.
//!
//! The set: a base of 50 to 3000 points on a sphere, a torus or a bent plane patch (radius or
//! half-width 0.01 to 1000, with noise or none), then, as the bytes say: far clusters (1 to 3
//! groups of 1 to 50 points, spread or all at one position, 0.1 to 10^7 away) or a second copy of
//! the shape far away; points uniform in a cube around the shape (from a few up to as many as the
//! base); exact duplicate lines (every point, or a subset, repeated 1 to 1000 times, next to the
//! original or at the end; at most 100 000 extra lines); the lines shuffled; a UTM-like offset
//! (hundreds of kilometres east, up to 10^7 north) added to every point; normals (noisy, some
//! flipped) or none. The bytes after the parameters place the first points themselves; the rest
//! come from a generator seeded by the bytes.

use std::f64::consts::{PI, TAU};
use std::fmt::Write as _;
use std::path::Path;

use glam::DVec3;
use spectral_remesh::{check_invariants, read_mesh, Violation};

#[path = "whole_job.rs"]
mod whole_job;
use whole_job::run_whole_job;

/// Bytes read in order (0x5a once they run out).
struct Bytes<'a>(&'a [u8], usize);

impl Bytes<'_> {
    fn byte(&mut self) -> u8 {
        let b = self.0.get(self.1).copied().unwrap_or(0x5a);
        self.1 += 1;
        b
    }

    /// A number in [0, 1) from one byte.
    fn unit(&mut self) -> f64 {
        self.byte() as f64 / 256.0
    }

    /// A number in [0, 1] from one byte.
    fn full(&mut self) -> f64 {
        self.byte() as f64 / 255.0
    }

    /// A number in [0, 1) from two bytes.
    fn fine(&mut self) -> f64 {
        let v = (self.byte() as u32) << 8 | self.byte() as u32;
        v as f64 / 65536.0
    }

    fn left(&self) -> usize {
        self.0.len().saturating_sub(self.1)
    }
}

/// splitmix64: the placements the bytes do not give.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A number in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A number in [-1, 1).
    fn signed(&mut self) -> f64 {
        2.0 * self.unit() - 1.0
    }

    /// An integer in `0..n`.
    fn below(&mut self, n: usize) -> usize {
        ((self.unit() * n as f64) as usize).min(n - 1)
    }

    /// A unit vector, uniform on the sphere.
    fn direction(&mut self) -> DVec3 {
        let z = self.signed();
        let u = TAU * self.unit();
        let s = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(s * u.cos(), s * u.sin(), z)
    }
}

/// A point of the set and its normal (unit length).
type Point = (DVec3, DVec3);

/// The point at (u, v) in [0, 1)² of the base shape (size about 1), and its unit normal.
fn on_shape(shape: usize, param: f64, u: f64, v: f64) -> Point {
    match shape {
        0 => {
            let z = 2.0 * v - 1.0;
            let s = (1.0 - z * z).max(0.0).sqrt();
            let n = DVec3::new(s * (TAU * u).cos(), s * (TAU * u).sin(), z);
            (n, n)
        }
        1 => {
            // Radii 1 and 0.05 to 0.7.
            let small = 0.05 + 0.65 * param;
            let (a, w) = (TAU * u, TAU * v);
            let n = DVec3::new(w.cos() * a.cos(), w.cos() * a.sin(), w.sin());
            (DVec3::new(a.cos(), a.sin(), 0.0) + n * small, n)
        }
        _ => {
            // A patch 2 × 2·aspect (aspect 0.1 to 1), bent up to 0.5.
            let aspect = 0.1 + 0.9 * (param * 7.0).fract();
            let bend = 0.5 * param;
            let (x, y) = (2.0 * u - 1.0, aspect * (2.0 * v - 1.0));
            let z = bend * (x * PI).sin() * (y * 2.0).cos();
            let dzdx = bend * PI * (x * PI).cos() * (y * 2.0).cos();
            let dzdy = -2.0 * bend * (x * PI).sin() * (y * 2.0).sin();
            (
                DVec3::new(x, y, z),
                DVec3::new(-dzdx, -dzdy, 1.0).normalize(),
            )
        }
    }
}

/// A point set shaped by `data`, as XYZ text (`x y z`, or `x y z nx ny nz` with normals), and
/// the `--points` and `--seed` to remesh it with.
pub fn point_set(data: &[u8]) -> (String, usize, u64) {
    let mut b = Bytes(data, 0);
    // The parameters, one byte each, all read first (the bytes after them place points), the
    // weightiest first so that the short inputs libFuzzer starts with already choose them. The
    // extras from the first byte, so that an input without it (0x5a) has none.
    let extras = b.byte() ^ 0x5a;
    let shape = b.byte() as usize % 3;
    // Counts weighted towards the small (and fast) end.
    let n = 50 + (2950.0 * b.full().powi(2)) as usize;
    let points = 20 + (580.0 * b.full().powi(2)) as usize;
    let seed = b.byte() as u64 % 5 + 1;
    let scale = 10f64.powf(-2.0 + 5.0 * b.full());
    let noise = match b.byte() % 4 {
        0 => 0.0,
        k => 10f64.powi(k as i32 - 4),
    };
    let param = b.unit();
    let far_copy = b.byte() & 1 == 1;
    let far_groups = 1 + b.byte() as usize % 3;
    let far_count = 1 + b.byte() as usize % 50;
    let far_distance = 10f64.powf(-1.0 + 8.0 * b.full());
    let far_spread = match b.byte() % 3 {
        0 => 0.0,
        _ => scale * 10f64.powf(-4.0 * b.full()),
    };
    let volume_count = ((n as f64 * 10f64.powf(-3.0 * b.full())).ceil() as usize).clamp(3, n);
    let volume_margin = 1.0 + b.unit();
    let duplicate_all = b.byte() & 1 == 1;
    let duplicate_adjacent = b.byte() & 1 == 1;
    let duplicate_times = (10f64.powf(3.0 * b.full()).round() as usize).clamp(1, 1000);
    let duplicate_share = b.full();
    let normal_noise = b.unit().powi(2);
    let flipped = match b.byte() % 3 {
        0 => 0.0,
        1 => 0.5 * b.full(),
        _ => 1.0,
    };
    let east = 1.0e5 + 8.0e5 * b.unit();
    let north = 1.0e7 * b.full();
    let up = 3000.0 * b.unit();
    // The other placements from every byte (FNV-1a), so that any change moves them.
    let mut rng = Rng(data.iter().fold(0xcbf2_9ce4_8422_2325_u64, |h, &x| {
        (h ^ x as u64).wrapping_mul(0x0100_0000_01b3)
    }));

    // The base: the first points where the bytes place them, the others at random.
    let mut set: Vec<Point> = Vec::with_capacity(n);
    for _ in 0..n {
        let (u, v) = if b.left() >= 4 {
            (b.fine(), b.fine())
        } else {
            (rng.unit(), rng.unit())
        };
        let (p, nrm) = on_shape(shape, param, u, v);
        let jitter = DVec3::new(rng.signed(), rng.signed(), rng.signed());
        set.push((
            (p + jitter * noise) * scale,
            (nrm + jitter * normal_noise).normalize_or(nrm),
        ));
    }
    let base = set.len();
    let (lo, hi) = set.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), (p, _)| (lo.min(*p), hi.max(*p)),
    );
    let centre = (lo + hi) / 2.0;

    if extras & 1 != 0 {
        // Far away: a second copy of the shape, or small clusters.
        if far_copy {
            let offset = rng.direction() * far_distance;
            set.extend_from_within(..base);
            for (p, _) in &mut set[base..] {
                *p += offset;
            }
        } else {
            for _ in 0..far_groups {
                let at = centre + rng.direction() * far_distance;
                for _ in 0..far_count {
                    let p = at + rng.direction() * far_spread * rng.unit();
                    set.push((p, rng.direction()));
                }
            }
        }
    }
    if extras & 2 != 0 {
        // Uniform in a cube around the shape.
        let half = (hi - lo).max_element() / 2.0 * volume_margin;
        for _ in 0..volume_count {
            let p = centre + DVec3::new(rng.signed(), rng.signed(), rng.signed()) * half;
            set.push((p, rng.direction()));
        }
    }
    if extras & 4 != 0 {
        // Exact duplicate lines: each point of a subset (or every point) repeated.
        let len = set.len();
        let chosen: Vec<bool> = (0..len)
            .map(|_| duplicate_all || rng.unit() < duplicate_share)
            .collect();
        let k = chosen.iter().filter(|&&c| c).count().max(1);
        let times = duplicate_times.min(100_000 / k).max(1);
        if duplicate_adjacent {
            let mut out = Vec::with_capacity(len + k * times);
            for (i, &p) in set.iter().enumerate() {
                out.push(p);
                if chosen[i] {
                    out.extend(std::iter::repeat_n(p, times));
                }
            }
            set = out;
        } else {
            for _ in 0..times {
                for i in 0..len {
                    if chosen[i] {
                        set.push(set[i]);
                    }
                }
            }
        }
    }
    if extras & 8 != 0 {
        // The lines in random order (a scan's order is not the surface's).
        for i in (1..set.len()).rev() {
            set.swap(i, rng.below(i + 1));
        }
    }
    if extras & 16 != 0 {
        // UTM-like coordinates.
        let offset = DVec3::new(east, north, up);
        for (p, _) in &mut set {
            *p += offset;
        }
    }
    let normals = extras & 32 != 0;
    let mut text = String::with_capacity(set.len() * 64);
    for (i, (p, nrm)) in set.iter().enumerate() {
        if normals {
            // A share of the normals flipped (a scan's estimates, unoriented).
            let nrm = if (i as f64 + 0.5) / set.len() as f64 <= flipped {
                -*nrm
            } else {
                *nrm
            };
            let _ = writeln!(
                text,
                "{} {} {} {} {} {}",
                p.x, p.y, p.z, nrm.x, nrm.y, nrm.z
            );
        } else {
            let _ = writeln!(text, "{} {} {}", p.x, p.y, p.z);
        }
    }
    (text, points, seed)
}

/// Runs the whole `remesh` job on the point set of `data`, in `dir`, and checks what every run
/// must keep: no panic (the caller sees it); an error that is not an internal one, has a
/// message of one non-empty line, and leaves no output; or an output written with at least one
/// face, edge- and vertex-manifold, consistently oriented, free of degenerate and duplicate
/// faces (as the report's check finds it and as the file reads back). Faces that cross are
/// allowed (the report lists them; issue 15's subject).
pub fn assert_point_remesh_is_sound(data: &[u8], dir: &Path) {
    let (text, points, seed) = point_set(data);
    let input = dir.join("in.xyz");
    let output = dir.join("out.obj");
    std::fs::write(&input, text).expect("writing the input");
    match run_whole_job(&input, &output, points, seed) {
        Err(e) => {
            let message = e.to_string();
            assert!(!message.trim().is_empty(), "an error without a message");
            assert!(
                !message.contains('\n'),
                "an error of more than one line: {message:?}"
            );
        }
        Ok(report) => {
            assert!(report.topology.faces > 0, "a success with no faces");
            let (mesh, _) = read_mesh(&output).expect("the output reads back");
            assert_eq!(
                mesh.triangles.len(),
                report.topology.faces,
                "the file holds other faces than the report's"
            );
            for v in check_invariants(&mesh) {
                assert!(
                    matches!(v, Violation::Crossing { .. }),
                    "the output as written breaks an invariant: {v}"
                );
            }
        }
    }
}
