//! Issue 75: the triangulation checks what the sampling promises. Where a sample's restricted
//! Voronoi cell is not a disc or two cells meet twice (a hole, a gap or a wall narrower than the
//! spacing), samples are inserted there and the sampling runs again finer around them, so that
//! the output keeps the input's topology; the report says how many were inserted, and
//! `--strict` refuses a count too small to keep it.

use std::collections::HashMap;

use spectral_remesh::internal::{self_intersections, FeatureDetection};
use spectral_remesh::{remesh, topology, Density, RemeshParams, TriMesh};

use glam::DVec3;

/// The closed surface of a set of boxes on a grid with the given ticks along x, y and z
/// (`filled(i, j, k)`: whether the box between ticks i..i+1, j..j+1, k..k+1 is solid): the
/// faces between a solid box and an empty one (or the outside), as two triangles each, facing
/// out. The solid must not meet itself along an edge only.
fn boxes(ticks: [&[f64]; 3], filled: impl Fn(usize, usize, usize) -> bool) -> TriMesh {
    let n = [ticks[0].len() - 1, ticks[1].len() - 1, ticks[2].len() - 1];
    let solid = |c: [i64; 3]| {
        (0..3).all(|a| c[a] >= 0 && (c[a] as usize) < n[a])
            && filled(c[0] as usize, c[1] as usize, c[2] as usize)
    };
    let mut index: HashMap<[usize; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut vertex = |g: [usize; 3]| {
        *index.entry(g).or_insert_with(|| {
            positions.push(DVec3::new(ticks[0][g[0]], ticks[1][g[1]], ticks[2][g[2]]));
            (positions.len() - 1) as u32
        })
    };
    let mut triangles = Vec::new();
    for i in 0..n[0] {
        for j in 0..n[1] {
            for k in 0..n[2] {
                let c = [i as i64, j as i64, k as i64];
                if !solid(c) {
                    continue;
                }
                for axis in 0..3 {
                    for dir in [-1i64, 1] {
                        let mut d = c;
                        d[axis] += dir;
                        if solid(d) {
                            continue;
                        }
                        // The face's four corners, counter-clockwise seen from outside.
                        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                        let base = [i, j, k];
                        let mut corner = |du: usize, dv: usize| {
                            let mut g = base;
                            g[axis] += usize::from(dir > 0);
                            g[u] += du;
                            g[v] += dv;
                            vertex(g)
                        };
                        let q = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
                        if dir > 0 {
                            triangles.push([q[0], q[1], q[2]]);
                            triangles.push([q[0], q[2], q[3]]);
                        } else {
                            triangles.push([q[0], q[2], q[1]]);
                            triangles.push([q[0], q[3], q[2]]);
                        }
                    }
                }
            }
        }
    }
    TriMesh::new(positions, triangles)
}

/// A plate 100 × 100 × 2 with a square hole `w` wide through its middle.
fn plate_with_hole(w: f64) -> TriMesh {
    let mut ticks: Vec<f64> = (0..=10).map(|i| 10.0 * i as f64).collect();
    ticks.retain(|&t| (t - 50.0).abs() > w);
    ticks.extend([50.0 - w / 2.0, 50.0 + w / 2.0]);
    ticks.sort_by(f64::total_cmp);
    let hole = ticks.iter().position(|&t| t == 50.0 - w / 2.0).unwrap();
    boxes([&ticks, &ticks, &[0.0, 2.0]], |i, j, _| {
        !(i == hole && j == hole)
    })
}

fn run(mesh: &TriMesh, points: usize, seed: u64, features: FeatureDetection) -> TriMesh {
    let params = RemeshParams {
        density: Density::Points(points),
        seed,
        features,
        ..RemeshParams::default()
    };
    remesh(mesh, &params, &|_| {}).expect("remesh").mesh
}

#[test]
fn the_plate_is_a_closed_torus() {
    let t = topology(&plate_with_hole(2.0));
    assert_eq!(
        (
            t.components,
            t.euler_characteristic,
            t.boundary_edges,
            t.non_manifold_edges
        ),
        (1, 0, 0, 0)
    );
}

/// A hole 2 wide through a plate 2 thick, at counts whose spacing (about 4.5 at 1000 points)
/// is twice the hole's width and more: the cells around the hole wrap around its walls, and
/// samples inserted there keep it open. With creases kept (the default's automatic detection)
/// and without.
#[test]
fn a_hole_narrower_than_the_spacing_stays_open_at_every_seed() {
    let plate = plate_with_hole(2.0);
    for features in [FeatureDetection::Auto, FeatureDetection::Off] {
        for points in [600, 1000] {
            for seed in 1..=3 {
                let out = run(&plate, points, seed, features);
                let t = topology(&out);
                let at = format!("{features:?}, {points} points, seed {seed}: {t:?}");
                assert_eq!(
                    (t.components, t.euler_characteristic, t.boundary_edges),
                    (1, 0, 0),
                    "{at}"
                );
                assert_eq!(t.non_manifold_edges + t.non_manifold_vertices, 0, "{at}");
                assert_eq!(self_intersections(&out).pairs, 0, "{at}");
            }
        }
    }
}
