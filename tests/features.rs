//! Issue 16: sharp features. With `--feature-angle`, the creases of a part are sampled evenly
//! and come out as output edges, so the part's edges are kept instead of chamfered.

mod common;

use common::grid_box_counts;
use glam::DVec3;
use spectral_remesh::internal::{
    CurvatureParams, FeatureDetection, CAD_FEATURE_ANGLE_DEG, FIT_ITERATIONS,
};
use spectral_remesh::{remesh, Density, FeatureStats, RemeshParams, TriMesh};

/// A remesh at `points` with the CAD feature angle, at `seed`.
fn cad(points: usize, seed: u64) -> RemeshParams {
    RemeshParams {
        density: Density::Points(points),
        features: FeatureDetection::Angle(CAD_FEATURE_ANGLE_DEG),
        seed,
        // The samples on the input (the fit is measured against this by its own test).
        fit_iterations: 0,
        ..Default::default()
    }
}

/// Creases were sampled and every sampled crease edge is an output edge.
fn assert_every_crease_edge_kept(f: &FeatureStats, seed: u64) {
    assert!(
        f.sampled_edges > 0 && f.kept_edges == f.sampled_edges,
        "seed {seed}: {f:?}"
    );
}

/// The mean length of `mesh`'s face edges (each interior edge counted from both faces), in its
/// units.
fn mean_edge(mesh: &TriMesh) -> f64 {
    let p = |v: u32| mesh.positions[v as usize];
    let total: f64 = mesh
        .triangles
        .iter()
        .map(|t| p(t[0]).distance(p(t[1])) + p(t[1]).distance(p(t[2])) + p(t[2]).distance(p(t[0])))
        .sum();
    total / (3 * mesh.triangles.len()) as f64
}

/// The largest distance from points along the box's 12 edges (20 per edge) to the nearest
/// edge of `mesh`.
fn box_edges_to_mesh_edges(lo: DVec3, hi: DVec3, mesh: &TriMesh) -> f64 {
    let corner = |k: usize| {
        DVec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        )
    };
    let mut segments = Vec::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a < b {
                segments.push((mesh.positions[a as usize], mesh.positions[b as usize]));
            }
        }
    }
    let mut worst: f64 = 0.0;
    for a in 0..8usize {
        for axis in [1usize, 2, 4] {
            if a & axis != 0 {
                continue;
            }
            let (p, q) = (corner(a), corner(a | axis));
            for i in 0..=20 {
                let x = p.lerp(q, i as f64 / 20.0);
                let d = segments
                    .iter()
                    .map(|&(s, e)| {
                        let se = e - s;
                        let t = ((x - s).dot(se) / se.length_squared()).clamp(0.0, 1.0);
                        x.distance(s + se * t)
                    })
                    .fold(f64::INFINITY, f64::min);
                worst = worst.max(d);
            }
        }
    }
    worst
}

#[test]
fn a_boxs_edges_are_output_edges_at_every_seed_with_the_feature_angle() {
    let (lo, hi) = (DVec3::ZERO, DVec3::new(100.0, 60.0, 40.0));
    let input = grid_box_counts(lo, hi, [20, 12, 8]);
    for seed in 1..=5 {
        let params = cad(2000, seed);
        let out = remesh(&input, &params, &|_| {}).expect("remesh");
        let f = &out.features;
        assert_eq!((f.curves, f.corners), (12, 8), "seed {seed}: {f:?}");
        assert_every_crease_edge_kept(f, seed);
        let v = out.mesh.positions.len() as f64;
        assert!((v - 2000.0).abs() <= 20.0, "seed {seed}: {v} vertices");
        let d = box_edges_to_mesh_edges(lo, hi, &out.mesh);
        assert!(
            d < 1e-9,
            "seed {seed}: a box edge is {d} from the output's edges"
        );
    }
    // Without the features the edges are cut across (the check above means something).
    let out = remesh(
        &input,
        &RemeshParams {
            density: Density::Points(2000),
            features: FeatureDetection::Off,
            ..Default::default()
        },
        &|_| {},
    )
    .expect("remesh");
    assert_eq!(out.features.curves, 0);
    assert!(box_edges_to_mesh_edges(lo, hi, &out.mesh) > 0.1);
}

/// A wedge: the triangular prism over a triangle with a 20° corner (sides 100 from it, the
/// other two corners 80°), 30 high, its faces cut into triangles about 2.5 across; centred on
/// the origin and oriented outward. Its two caps each have a corner where two creases meet at
/// 20°.
fn wedge() -> TriMesh {
    let k = 40usize;
    let rows = 12usize;
    let apex = 20f64.to_radians();
    let (a, b, c) = (
        DVec3::ZERO,
        DVec3::new(100.0, 0.0, 0.0),
        DVec3::new(100.0 * apex.cos(), 100.0 * apex.sin(), 0.0),
    );
    // The point (i, j) of the triangle's barycentric grid at height z: the same arithmetic
    // wherever a cap and a side share it, so shared vertices weld exactly.
    let at = |i: usize, j: usize, z: f64| {
        a + (b - a) * (i as f64 / k as f64) + (c - a) * (j as f64 / k as f64) + DVec3::Z * z
    };
    let mut soup: Vec<[DVec3; 3]> = Vec::new();
    for z in [0.0, 30.0] {
        for j in 0..k {
            for i in 0..k - j {
                soup.push([at(i, j, z), at(i + 1, j, z), at(i, j + 1, z)]);
                if i + j + 1 < k {
                    soup.push([at(i + 1, j, z), at(i + 1, j + 1, z), at(i, j + 1, z)]);
                }
            }
        }
    }
    // The three sides, each a grid of k × rows quads.
    let sides: [&dyn Fn(usize) -> (usize, usize); 3] =
        [&|s| (s, 0), &|s| (k - s, s), &|s| (0, k - s)];
    for side in sides {
        for s in 0..k {
            for r in 0..rows {
                let (z0, z1) = (
                    30.0 * r as f64 / rows as f64,
                    30.0 * (r + 1) as f64 / rows as f64,
                );
                let ((i0, j0), (i1, j1)) = (side(s), side(s + 1));
                let (p, q) = (at(i0, j0, z0), at(i1, j1, z0));
                let (pu, qu) = (at(i0, j0, z1), at(i1, j1, z1));
                soup.push([p, q, qu]);
                soup.push([p, qu, pu]);
            }
        }
    }
    let mut index = std::collections::HashMap::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for t in soup {
        triangles.push(t.map(|p| {
            *index
                .entry([p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
                .or_insert_with(|| {
                    positions.push(p);
                    positions.len() as u32 - 1
                })
        }));
    }
    let centre = positions.iter().copied().sum::<DVec3>() / positions.len() as f64;
    for p in &mut positions {
        *p -= centre;
    }
    common::orient_outward(TriMesh::new(positions, triangles))
}

/// Where two creases leave a corner at 20° (the wedge's caps), both are kept up to the corner
/// (found there, sampled towards it, put in the triangulation where its cells crowd each other
/// out, and kept by the optimization), and the triangles near them stay within 3/4 of the
/// corner's angle: the corner's own triangle has that angle (20°), which no triangle there can
/// exceed, and the graded samples' short steps give the sheet across each crease triangles a
/// little thinner (15.5–17.8° at seeds 1–5). Before the grading, one of the two creases was
/// left out (Hausdorff 0.72).
#[test]
fn creases_meeting_at_a_small_angle_are_kept_up_to_their_corner_with_its_angle() {
    let input = wedge();
    assert!(spectral_remesh::topology(&input).is_closed_manifold());
    for seed in 1..=5 {
        let params = cad(3000, seed);
        let out = remesh(&input, &params, &|_| {}).expect("remesh");
        let f = &out.features;
        assert_eq!((f.curves, f.corners), (9, 6), "seed {seed}: {f:?}");
        assert_every_crease_edge_kept(f, seed);
        let d = f.crease_distance.expect("creases").max;
        assert!(
            d < 1e-6,
            "seed {seed}: a crease is {d} from the output's edges"
        );
        let q = spectral_remesh::internal::triangle_quality(&out.mesh);
        assert!(q.theta_min >= 15.0, "seed {seed}: θmin {}", q.theta_min);
        assert!(spectral_remesh::topology(&out.mesh).is_closed_manifold());
        // The triangles below 30° are all within the graded reach of the two 20° corners
        // (spacing / (2 sin 10°), the spacing 1.15 sigma_p): elsewhere every angle is 30° or more.
        let min_x = input
            .positions
            .iter()
            .map(|p| p.x)
            .fold(f64::INFINITY, f64::min);
        let (z0, z1) = input
            .positions
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.z), hi.max(p.z))
            });
        let apexes: Vec<DVec3> = input
            .positions
            .iter()
            .copied()
            .filter(|p| p.x == min_x && (p.z == z0 || p.z == z1))
            .collect();
        assert_eq!(apexes.len(), 2);
        // The output is in the input's units; sigma_p is in bbox-100 units.
        let bbox = spectral_remesh::internal::Aabb::of(&input.positions).expect("bbox");
        let to_model = (bbox.max - bbox.min).max_element() / 100.0;
        let spacing = 1.15 * out.sigma_p * to_model;
        let reach = spacing / (2.0 * 10f64.to_radians().sin());
        for f in 0..out.mesh.triangles.len() {
            let p = out.mesh.corners(f);
            let smallest = (0..3)
                .map(|k| {
                    let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
                    (b - a).angle_between(c - a).to_degrees()
                })
                .fold(f64::INFINITY, f64::min);
            if smallest < 30.0 {
                let centroid = (p[0] + p[1] + p[2]) / 3.0;
                let near = apexes.iter().any(|a| a.distance(centroid) < reach);
                assert!(
                    near,
                    "seed {seed}: face {f} has {smallest:.1}° at {centroid}, beyond {reach} of the corners"
                );
            }
        }
    }
}

/// Issue 16's bound on fandisk at 6000 points with the CAD feature angle, at seeds 1–5:
/// Hausdorff distance at most 0.18 (bbox-100 units; MeshLab's is 0.24 and CGAL's with its
/// sharp edges constrained 0.18 at the same count), every sampled crease edge an output edge,
/// the output closed, manifold and of genus 0 like the input. (Without the creases the
/// distance is 0.80–0.87.)
#[test]
#[ignore = "needs ../shared: .ci/run runs it"]
fn shared_fandisk_keeps_its_creases_within_the_hausdorff_bound_at_every_seed() {
    let input = spectral_remesh::read_mesh(&common::model("fandisk.obj"))
        .expect("fandisk")
        .0;
    for seed in 1..=5 {
        let params = cad(6000, seed);
        let out = remesh(&input, &params, &|_| {}).expect("remesh");
        let f = &out.features;
        assert_every_crease_edge_kept(f, seed);
        let d = spectral_remesh::internal::surface_distance(
            &out.mesh_normalized,
            &out.input_normalized,
            200_000,
            seed,
        )
        .expect("distance");
        assert!(
            d.hausdorff <= 0.18,
            "seed {seed}: Hausdorff {}",
            d.hausdorff
        );
        let t = spectral_remesh::topology(&out.mesh);
        assert!(
            t.is_closed_manifold() && t.genus == Some(0),
            "seed {seed}: {t:?}"
        );
    }
}

/// A closed disc-shaped cylinder round the z axis, radius `r`, height `h`: `sides` facets round,
/// `rings` bands, the caps as rings of triangles `rings_cap` deep to the centre. Oriented
/// outward.
fn disc(r: f64, h: f64, sides: usize, rings: usize, rings_cap: usize) -> TriMesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let ring = |z: f64, radius: f64, positions: &mut Vec<DVec3>| -> u32 {
        let start = positions.len() as u32;
        for i in 0..sides {
            let a = std::f64::consts::TAU * i as f64 / sides as f64;
            positions.push(DVec3::new(radius * a.cos(), radius * a.sin(), z));
        }
        start
    };
    let band = |a: u32, b: u32, triangles: &mut Vec<[u32; 3]>| {
        // Quads between ring a (below / outside) and ring b, split along a diagonal.
        for i in 0..sides as u32 {
            let j = (i + 1) % sides as u32;
            triangles.push([a + i, a + j, b + j]);
            triangles.push([a + i, b + j, b + i]);
        }
    };
    // The side, bottom to top.
    let side: Vec<u32> = (0..=rings)
        .map(|k| ring(h * k as f64 / rings as f64, r, &mut positions))
        .collect();
    for k in 0..rings {
        band(side[k], side[k + 1], &mut triangles);
    }
    // The caps: rings inward, then a fan to the centre.
    for (z, outer, up) in [(h, side[rings], true), (0.0, side[0], false)] {
        let mut prev = outer;
        for k in 1..rings_cap {
            let next = ring(z, r * (1.0 - k as f64 / rings_cap as f64), &mut positions);
            let start = triangles.len();
            band(prev, next, &mut triangles);
            if !up {
                for t in &mut triangles[start..] {
                    t.swap(1, 2);
                }
            }
            prev = next;
        }
        let centre = positions.len() as u32;
        positions.push(DVec3::new(0.0, 0.0, z));
        for i in 0..sides as u32 {
            let j = (i + 1) % sides as u32;
            triangles.push(if up {
                [prev + i, prev + j, centre]
            } else {
                [prev + j, prev + i, centre]
            });
        }
    }
    TriMesh::new(positions, triangles)
}

#[test]
fn with_the_chord_error_a_curved_side_gets_finer_samples_and_a_closer_surface() {
    // A disc of radius 40 and height 10: a curved side between two large flat caps.
    let (r, h) = (40.0, 10.0);
    let input = disc(r, h, 240, 6, 24);
    // The mean and the largest distance of an output face's centroid on the side from the true
    // cylinder (the chord error there; the input's facets are within 0.004 of it), and the
    // side's share of the vertices (a vertex within 0.04 of the cylinder, the facets' sag being
    // 0.0034).
    let side = |mesh: &TriMesh| -> (f64, f64, f64) {
        let scale = 100.0 / (2.0 * r);
        let mut worst: f64 = 0.0;
        let (mut sum, mut count) = (0.0, 0.0);
        for f in 0..mesh.triangles.len() {
            let p = mesh.corners(f);
            let on_side = p
                .iter()
                .all(|q| (q.truncate().length() - r).abs() < 1e-3 * r);
            if on_side {
                let c = (p[0] + p[1] + p[2]) / 3.0;
                let e = (r - c.truncate().length()) * scale;
                worst = worst.max(e);
                sum += e;
                count += 1.0;
            }
        }
        let on_side = mesh
            .positions
            .iter()
            .filter(|q| (q.truncate().length() - r).abs() < 1e-3 * r)
            .count();
        (
            sum / count,
            worst,
            on_side as f64 / mesh.positions.len() as f64,
        )
    };
    for seed in 1..=3 {
        let base = cad(3000, seed);
        let graded = RemeshParams {
            curvature: Some(CurvatureParams::default()),
            ..base
        };
        let even = remesh(&input, &base, &|_| {}).expect("remesh");
        let fine = remesh(&input, &graded, &|_| {}).expect("remesh");
        let (mean_even, worst_even, share_even) = side(&even.mesh);
        let (mean_fine, worst_fine, share_fine) = side(&fine.mesh);
        // The side takes more of the samples, and its chord error falls (the count is the
        // same: the samples come from the caps, which have no chord error at any spacing). A
        // chord's sag goes as h², and h² as 1 / the side's share, so the mean sag should fall
        // to about share_even / share_fine (1 / 1.3 at most); the worst face, which depends on
        // one face's luck, must at least not be worse.
        assert!(
            share_fine > 1.3 * share_even,
            "seed {seed}: side share {share_even} -> {share_fine}"
        );
        assert!(
            mean_fine < 0.8 * mean_even,
            "seed {seed}: mean chord error {mean_even} -> {mean_fine}"
        );
        assert!(
            worst_fine < worst_even,
            "seed {seed}: largest chord error {worst_even} -> {worst_fine}"
        );
        let v = fine.mesh.positions.len() as f64;
        assert!((v - 3000.0).abs() <= 30.0, "seed {seed}: {v} vertices");
        // The rims stay output edges.
        let f = &fine.features;
        assert_eq!(f.curves, 2, "seed {seed}: {f:?}");
        assert!(f.kept_edges == f.sampled_edges, "seed {seed}: {f:?}");
    }
}

#[test]
fn the_least_squares_fit_lowers_the_sag_and_leaves_rims_and_flat_caps_in_place() {
    let (r, h) = (40.0, 10.0);
    let input = disc(r, h, 240, 6, 24);
    let scale = 100.0 / (2.0 * r);
    // The largest distance of a side face's centroid from the cylinder, in bbox-100 units.
    let sag = |mesh: &TriMesh| -> f64 {
        let mut worst: f64 = 0.0;
        for f in 0..mesh.triangles.len() {
            let p = mesh.corners(f);
            if p.iter().all(|q| q.z > 1e-9 && q.z < h - 1e-9)
                || p.iter().all(|q| (q.truncate().length() - r).abs() < 0.5)
            {
                let c = (p[0] + p[1] + p[2]) / 3.0;
                worst = worst.max((c.truncate().length() - r).abs() * scale);
            }
        }
        worst
    };
    for seed in 1..=3 {
        let base = cad(3000, seed);
        let fitted = RemeshParams {
            fit_iterations: FIT_ITERATIONS,
            ..base
        };
        let plain = remesh(&input, &base, &|_| {}).expect("remesh");
        let fit = remesh(&input, &fitted, &|_| {}).expect("remesh");
        // The same samples and faces, moved: the fit comes after the connectivity is final.
        assert_eq!(plain.mesh.triangles, fit.mesh.triangles, "seed {seed}");
        let stats = fit.fit.expect("fit stats");
        assert!(stats.moved > 0, "seed {seed}");
        // On the side, the sag of a face falls to about 2/3 (a chord's peak minus its mean).
        let (s0, s1) = (sag(&plain.mesh), sag(&fit.mesh));
        assert!(s1 < 0.8 * s0, "seed {seed}: sag {s0} -> {s1}");
        for (p, q) in plain.mesh.positions.iter().zip(&fit.mesh.positions) {
            let on_rim = (p.truncate().length() - r).abs() < 1e-3 * r
                && (p.z.abs() < 1e-9 || (p.z - h).abs() < 1e-9);
            let on_cap = p.z.abs() < 1e-9 || (p.z - h).abs() < 1e-9;
            if on_rim {
                // A crease sample stays where it was.
                assert_eq!(p, q, "seed {seed}");
            } else if on_cap {
                // A flat cap's vertex stays in its plane.
                assert!((p.z - q.z).abs() < 1e-9, "seed {seed}: {p} -> {q}");
            }
        }
    }
}

/// A gear made in code (issue 59): `teeth` trapezoidal teeth between radii 18 and 22 (each tooth
/// a root, a flank up, a tip land and a flank down), extruded 8 high, the caps fanned from the
/// axis. Its creases are short straight pieces from junction to junction: the flanks, lands and
/// roots, each a few sample spacings long or less at 2,000 vertices.
fn gear(teeth: usize) -> TriMesh {
    let mut ring = Vec::new();
    for k in 0..teeth {
        let w = std::f64::consts::TAU / teeth as f64;
        for (frac, r) in [
            (0.0, 18.0),
            (0.25, 18.0),
            (0.4, 22.0),
            (0.6, 22.0),
            (0.75, 18.0),
        ] {
            let a = (k as f64 + frac) * w;
            ring.push((r * a.cos(), r * a.sin()));
        }
    }
    let n = ring.len() as u32;
    let mut positions: Vec<DVec3> = Vec::new();
    for z in [0.0, 8.0] {
        positions.extend(ring.iter().map(|&(x, y)| DVec3::new(x, y, z)));
    }
    positions.push(DVec3::ZERO);
    positions.push(DVec3::new(0.0, 0.0, 8.0));
    let (bottom, top) = (2 * n, 2 * n + 1);
    let mut triangles = Vec::new();
    for i in 0..n {
        let j = (i + 1) % n;
        triangles.push([bottom, j, i]);
        triangles.push([top, n + i, n + j]);
        triangles.push([i, j, n + j]);
        triangles.push([i, n + j, n + i]);
    }
    TriMesh::new(positions, triangles)
}

/// A remesh of `input` at `points`, seed 1, with the default (automatic) crease detection.
fn automatic(input: &TriMesh, points: usize) -> spectral_remesh::RemeshOutput {
    automatic_at(input, points, 1)
}

/// [`automatic`] at `seed`.
fn automatic_at(input: &TriMesh, points: usize, seed: u64) -> spectral_remesh::RemeshOutput {
    let params = RemeshParams {
        density: Density::Points(points),
        seed,
        ..Default::default()
    };
    remesh(input, &params, &|_| {}).expect("remesh")
}

#[test]
fn a_gears_short_creases_are_judged_a_parts_and_kept() {
    // The default (automatic) detection: the long curves alone fall short of the share, the
    // curves from junction to junction make it, and nothing gentler bends beside them.
    let f = &automatic(&gear(20), 2000).features;
    assert_eq!(f.automatic_kept, Some(true), "{f:?}");
    assert!(f.long_curve_share < 0.9, "{f:?}");
    assert!(f.junction_curve_share.is_some_and(|s| s >= 0.9), "{f:?}");
    assert!(f.crease_density.is_some_and(|d| d <= 1.0), "{f:?}");
    assert!(f.gap_ratio.is_some_and(|r| r <= 1.3), "{f:?}");
    assert_every_crease_edge_kept(f, 1);
}

#[test]
fn a_surface_crumpled_at_the_spacing_keeps_no_creases() {
    // A sphere whose vertices are moved in and out by up to 8% of its radius: a crease along
    // most of its edges at the spacing, from junction to junction (short pieces that pass the
    // junction share) but far closer than a spacing apart: a scan's noise, not a part.
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let mut m = common::icosphere(4);
    for p in &mut m.positions {
        *p *= 1.0 + rng.random_range(-0.08..0.08);
    }
    let f = &automatic(&m, 1500).features;
    assert!(f.junction_curve_share.is_some_and(|s| s >= 0.9), "{f:?}");
    assert!(f.crease_density.is_some_and(|d| d > 1.0), "{f:?}");
    assert_eq!(f.automatic_kept, Some(false), "{f:?}");
    assert_eq!(f.sampled_edges, 0, "{f:?}");
}

/// Issue 59: the beetle (a scan) at 13,000 vertices has 84% of its folds' length in long curves
/// and 93% in those or between junctions, more than a spacing apart: only the gentler bends
/// beside them (detection at 10° finds 1.6 times the length) tell them from a part's creases.
#[test]
fn the_beetles_folds_stay_a_scans_where_only_the_gap_tells() {
    let input = spectral_remesh::read_mesh(&common::model("beetle.obj"))
        .expect("beetle")
        .0;
    let f = &automatic(&input, 13_000).features;
    assert!(f.junction_curve_share.is_some_and(|s| s >= 0.9), "{f:?}");
    assert!(f.crease_density.is_some_and(|d| d <= 1.0), "{f:?}");
    assert!(f.gap_ratio.is_some_and(|r| r > 1.3), "{f:?}");
    assert_eq!(f.automatic_kept, Some(false), "{f:?}");
    assert_eq!(f.sampled_edges, 0, "{f:?}");
}

/// A washer round the z axis: outer radius `r`, a hole of radius `ri`, thickness `h`; `sides`
/// facets round and `k` rings across each of its four faces, as one closed loop of rings
/// (top inward, hole downward, bottom outward, rim upward) banded together.
fn washer(r: f64, ri: f64, h: f64, sides: usize, k: usize) -> TriMesh {
    let mut rings: Vec<(f64, f64)> = Vec::new();
    let t = |i: usize| i as f64 / k as f64;
    rings.extend((0..k).map(|i| (h, r + (ri - r) * t(i))));
    rings.extend((0..k).map(|i| (h * (1.0 - t(i)), ri)));
    rings.extend((0..k).map(|i| (0.0, ri + (r - ri) * t(i))));
    rings.extend((0..k).map(|i| (h * t(i), r)));
    let mut positions = Vec::new();
    for &(z, radius) in &rings {
        for i in 0..sides {
            let a = std::f64::consts::TAU * i as f64 / sides as f64;
            positions.push(DVec3::new(radius * a.cos(), radius * a.sin(), z));
        }
    }
    let n = rings.len();
    let at = |ring: usize, i: usize| ((ring % n) * sides + i % sides) as u32;
    let mut triangles = Vec::new();
    for ring in 0..n {
        for i in 0..sides {
            let (a, b, c, d) = (
                at(ring, i),
                at(ring, i + 1),
                at(ring + 1, i + 1),
                at(ring + 1, i),
            );
            triangles.push([a, c, b]);
            triangles.push([a, d, c]);
        }
    }
    TriMesh::new(positions, triangles)
}

/// Asserts that the creases `out` measured lie within a tenth of its mean edge (in bbox-100
/// units, the input's bounding box `size` long) of its edges.
fn assert_creases_within_a_tenth_of_an_edge(
    out: &spectral_remesh::RemeshOutput,
    size: f64,
    seed: u64,
) {
    let h = mean_edge(&out.mesh) * 100.0 / size;
    let d = out.features.crease_distance.as_ref().expect("measured").max;
    assert!(
        d <= 0.1 * h,
        "seed {seed}: creases within {d} of the edges, h {h}"
    );
}

#[test]
fn a_tight_rim_is_followed_within_a_tenth_of_an_edge() {
    // The hole's rims have a radius near the output's spacing: at an even crease spacing their
    // chords would stand a tenth of an edge or more off them; the spacing along them follows
    // their curvature (sampling::crease_curvature).
    let input = washer(20.0, 2.0, 4.0, 96, 4);
    for seed in [1, 2] {
        let out = automatic_at(&input, 1000, seed);
        let f = &out.features;
        assert_eq!(f.automatic_kept, Some(true), "{f:?}");
        assert_every_crease_edge_kept(f, seed);
        // The input's bounding box is 40 across.
        assert_creases_within_a_tenth_of_an_edge(&out, 40.0, seed);
    }
}

/// A wedge of length `l` along x, width `w` along y, `t` thick at its base (x = 0) and sharp at
/// its tip (x = l): its top and bottom faces meet at the tip at atan(t / l), its two ends are
/// triangles of that angle. 8 triangles, outward.
fn thin_wedge(l: f64, w: f64, t: f64) -> TriMesh {
    let positions = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, t),
        DVec3::new(l, 0.0, 0.0),
        DVec3::new(0.0, w, 0.0),
        DVec3::new(0.0, w, t),
        DVec3::new(l, w, 0.0),
    ];
    let triangles = vec![
        [0, 2, 1], // end y = 0
        [3, 4, 5], // end y = w
        [0, 3, 5], // bottom
        [0, 5, 2],
        [1, 2, 5], // top
        [1, 5, 4],
        [0, 1, 4], // base x = 0
        [0, 4, 3],
    ];
    common::orient_outward(TriMesh::new(positions, triangles))
}

#[test]
fn a_thin_wedges_rims_are_both_followed_up_to_its_tip() {
    // A 1° wedge under half a spacing thick at its base: its ends' two long rims run closer than
    // their samples' gap all along and meet at the 1° tip, the base's two rims as close. Left
    // out for crowding, one rim of each pair was the wedge's thickness off the output's edges
    // (1.4 in bbox-100 units); sampled as a ladder beside the other (sampling::crease_ladder),
    // every crease is an output edge.
    let l = 20.0;
    let input = thin_wedge(l, 16.0, l * 1f64.to_radians().tan());
    for seed in [1, 2] {
        let out = automatic_at(&input, 1000, seed);
        let f = &out.features;
        assert_eq!(f.automatic_kept, Some(true), "{f:?}");
        assert_every_crease_edge_kept(f, seed);
        // The input's bounding box is 20 long.
        assert_creases_within_a_tenth_of_an_edge(&out, l, seed);
        let topology = spectral_remesh::topology(&out.mesh);
        assert_eq!(
            (topology.components, topology.euler_characteristic),
            (1, 2),
            "seed {seed}"
        );
    }
}

/// eval/cad_parts.py's part with a 1° fin (`dihedral_part`) with noise of 1e-4 of its diagonal in
/// its positions (`dihedral_part~1e-4`: Gaussian, seed 1), as eval/features makes it.
fn noisy_fin_part() -> TriMesh {
    let positions: Vec<DVec3> = [
        [
            0.0018936737292586264,
            0.004502163957599978,
            0.0018106731288918597,
        ],
        [
            -0.007140820301525691,
            0.004961015751633842,
            10.002445967785865,
        ],
        [14.997057694596599, 0.003184312572106632, 10.13290096609301],
        [
            0.0016117374423579025,
            20.000155743384514,
            0.002995785235449742,
        ],
        [-0.004035496383754613, 19.999107313656605, 9.997358164239703],
        [15.003281456058383, 20.00021766247744, 10.129300689043635],
        [
            29.9957154304281,
            -0.0014093184833460632,
            4.461614188526882e-05,
        ],
        [29.998489797874278, 2.0070909917339352, 2.0055164774091954],
        [29.98514383099674, 1.9896489051286237, 2.348143618496422],
        [49.99768655248271, 2.0011706847161785, 2.0011908439130575],
        [30.011604974143303, -0.006093463049101919, 9.997930864031249],
        [30.011193633901108, 20.00354369355619, 0.0036333423748363086],
        [29.997183434933987, 17.990969156788548, 2.0009176449443964],
        [30.00059735693636, 17.993274564071385, 2.3453574752545747],
        [49.99960522724479, 17.994823110054384, 1.999461516872676],
        [30.000523211723397, 20.00019499943511, 9.997225708713804],
    ]
    .iter()
    .map(|&[x, y, z]| DVec3::new(x, y, z))
    .collect();
    let triangles = vec![
        [3, 0, 1],
        [0, 6, 2],
        [0, 11, 6],
        [0, 2, 1],
        [4, 1, 2],
        [5, 2, 10],
        [3, 11, 0],
        [3, 5, 11],
        [3, 1, 4],
        [4, 2, 5],
        [3, 4, 5],
        [6, 7, 8],
        [6, 8, 10],
        [11, 7, 6],
        [10, 8, 13],
        [6, 10, 2],
        [11, 12, 7],
        [11, 13, 12],
        [11, 15, 13],
        [15, 10, 13],
        [5, 10, 15],
        [11, 5, 15],
        [9, 8, 7],
        [9, 13, 8],
        [14, 9, 7],
        [14, 7, 12],
        [14, 12, 13],
        [14, 13, 9],
    ];
    TriMesh::new(positions, triangles)
}

#[test]
fn a_noisy_fin_parts_crease_edges_are_all_output_edges_at_every_seed() {
    // The fin's two base edges run 0.35 apart (a third of an output edge at 3000): the
    // triangulation can tuck a crease sample of one under a face that spans the crease, and
    // the edge to its neighbour is then put in by flips.
    let input = noisy_fin_part();
    for seed in 1..=5 {
        let out = automatic_at(&input, 3000, seed);
        assert_eq!(out.features.automatic_kept, Some(true), "seed {seed}");
        assert_every_crease_edge_kept(&out.features, seed);
    }
}
