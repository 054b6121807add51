use super::*;
use crate::mesh::{Normalization, TriMesh};
use crate::surface::MeshSurface;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::HashMap;

/// A uniformly distributed unit vector (Archimedes: z uniform in [-1, 1]).
fn random_unit(rng: &mut ChaCha8Rng) -> DVec3 {
    let z: f64 = rng.random_range(-1.0..=1.0);
    let phi: f64 = rng.random_range(0.0..std::f64::consts::TAU);
    let s = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(s * phi.cos(), s * phi.sin(), z)
}

/// Mean, 95th percentile and maximum of `v` (sorted here).
fn stats(v: &mut [f64]) -> (f64, f64, f64) {
    v.sort_by(f64::total_cmp);
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    let p95 = v[((v.len() as f64 * 0.95) as usize).min(v.len() - 1)];
    (mean, p95, v[v.len() - 1])
}

/// [`Rimls::project`] of every query (in parallel), the number of projections that ran out
/// of steps, and the most Newton steps taken.
fn project_counted(
    rimls: &Rimls,
    queries: &[DVec3],
) -> (Vec<Option<(DVec3, DVec3)>>, usize, usize) {
    let detailed: Vec<Option<RimlsProjection>> = queries
        .par_iter()
        .map(|&q| rimls.project_detailed(q))
        .collect();
    let not_converged = detailed.iter().flatten().filter(|p| !p.converged).count();
    let most_steps = detailed
        .iter()
        .flatten()
        .map(|p| p.steps)
        .max()
        .unwrap_or(0);
    let projected = detailed
        .iter()
        .map(|p| p.map(|p| (p.position, p.normal)))
        .collect();
    (projected, not_converged, most_steps)
}

#[test]
fn a_mass_counts_as_coincident_copies_and_a_zero_mass_as_absence() {
    // 400 points on a bumpy patch with noisy normals; queries near it.
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let mut p = Vec::new();
    let mut n = Vec::new();
    for _ in 0..400 {
        let (x, y): (f64, f64) = (rng.random_range(-4.0..4.0), rng.random_range(-4.0..4.0));
        p.push(DVec3::new(x, y, 0.3 * (x * 0.7).sin() * (y * 0.5).cos()));
        n.push((DVec3::Z + 0.3 * random_unit(&mut rng)).normalize());
    }
    let params = RimlsParams::new(1.0, 0.75);
    let mut masses: Vec<f64> = (0..400).map(|_| rng.random_range(0.5..2.0)).collect();
    masses[7] = 2.0;
    masses[11] = 0.0;
    let weighted = Rimls::with_masses(p.clone(), n.clone(), masses.clone(), params).unwrap();
    // The same set with point 7 twice at mass 1 each, point 11 left out.
    let mut p2 = p.clone();
    let mut n2 = n.clone();
    let mut m2 = masses.clone();
    m2[7] = 1.0;
    p2.push(p[7]);
    n2.push(n[7]);
    m2.push(1.0);
    p2.remove(11);
    n2.remove(11);
    m2.remove(11);
    let copied = Rimls::with_masses(p2, n2, m2, params).unwrap();
    let scaled = Rimls::with_masses(
        p.clone(),
        n.clone(),
        masses.iter().map(|m| 3.0 * m).collect(),
        params,
    )
    .unwrap();
    let unweighted = Rimls::new(p.clone(), n.clone(), params).unwrap();
    let mut differs = 0;
    for _ in 0..200 {
        let q = DVec3::new(
            rng.random_range(-3.0..3.0),
            rng.random_range(-3.0..3.0),
            rng.random_range(-0.5..0.5),
        );
        let (f, g) = weighted.value_and_gradient(q).unwrap();
        for other in [&copied, &scaled] {
            let (f2, g2) = other.value_and_gradient(q).unwrap();
            assert!(
                (f - f2).abs() < 1e-10 && (g - g2).length() < 1e-9,
                "{q}: {f} vs {f2}"
            );
        }
        let (f0, _) = unweighted.value_and_gradient(q).unwrap();
        if (f - f0).abs() > 1e-4 {
            differs += 1;
        }
    }
    // The masses matter.
    assert!(differs > 100, "{differs}");
    // Bad masses.
    assert!(Rimls::with_masses(p.clone(), n.clone(), vec![1.0; 399], params).is_err());
    for bad in [-1.0, f64::NAN, f64::INFINITY] {
        let mut m = vec![1.0; 400];
        m[5] = bad;
        assert!(Rimls::with_masses(p.clone(), n.clone(), m, params).is_err());
    }
    assert!(Rimls::with_masses(p, n, vec![0.0; 400], params).is_err());
}

#[test]
fn bad_input_is_an_error_value() {
    let p = vec![DVec3::ZERO, DVec3::X];
    let n = vec![DVec3::Z, DVec3::Z];
    let ok = RimlsParams::new(1.0, 0.75);
    assert!(Rimls::new(p.clone(), n.clone(), ok).is_ok());
    assert!(Rimls::new(vec![], vec![], ok).is_err());
    assert!(Rimls::new(p.clone(), vec![DVec3::Z], ok).is_err());
    assert!(Rimls::new(p.clone(), vec![DVec3::Z, DVec3::ZERO], ok).is_err());
    assert!(Rimls::new(p.clone(), vec![DVec3::Z, DVec3::splat(f64::NAN)], ok).is_err());
    assert!(Rimls::new(
        vec![DVec3::ZERO, DVec3::splat(f64::INFINITY)],
        n.clone(),
        ok
    )
    .is_err());
    for params in [
        RimlsParams::new(0.0, 0.75),
        RimlsParams::new(-1.0, 0.75),
        RimlsParams::new(f64::NAN, 0.75),
        RimlsParams::new(f64::INFINITY, 0.75),
        RimlsParams::new(1.0, 0.0),
        RimlsParams::new(1.0, f64::NAN),
        RimlsParams { sigma_r: 0.0, ..ok },
        RimlsParams {
            support_radius_sigma_p: f64::INFINITY,
            ..ok
        },
        RimlsParams {
            max_projection_steps: 0,
            ..ok
        },
        RimlsParams {
            tolerance: 0.0,
            ..ok
        },
    ] {
        assert!(
            Rimls::new(p.clone(), n.clone(), params).is_err(),
            "{params:?} accepted"
        );
    }
    assert!(Rimls::new(p, n, RimlsParams::new(1.0, f64::INFINITY)).is_ok());
}

#[test]
fn outside_the_support_there_is_no_value() {
    let r = Rimls::new(
        vec![DVec3::ZERO],
        vec![DVec3::Z],
        RimlsParams::new(1.0, 0.75),
    )
    .unwrap();
    assert!(r.value_and_gradient(DVec3::new(0.0, 0.0, 3.1)).is_none());
    assert!(r.value_and_gradient(DVec3::splat(f64::NAN)).is_none());
    assert!(r.project(DVec3::new(5.0, 0.0, 0.0)).is_none());
    // One point: f is the signed distance to its tangent plane.
    let (f, g) = r.value_and_gradient(DVec3::new(0.5, 0.2, 0.7)).unwrap();
    assert!((f - 0.7).abs() < 1e-12 && (g - DVec3::Z).length() < 1e-12);
}

/// Oracle: without refitting (plain implicit MLS) the gradient formula is the exact
/// derivative of f, so central differences must agree with it.
#[test]
fn gradient_without_refitting_matches_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let positions: Vec<DVec3> = (0..400)
        .map(|_| 4.0 * random_unit(&mut rng) + 0.05 * random_unit(&mut rng))
        .collect();
    let normals: Vec<DVec3> = positions
        .iter()
        .map(|p| (p.normalize() + 0.2 * random_unit(&mut rng)).normalize())
        .collect();
    let params = RimlsParams {
        max_refit: 0,
        ..RimlsParams::new(0.8, 0.75)
    };
    let r = Rimls::new(positions, normals, params).unwrap();
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let x = 4.0 * random_unit(&mut rng) + 0.5 * random_unit(&mut rng);
        let (_, g) = r.value_and_gradient(x).unwrap();
        let fd = DVec3::from_array(std::array::from_fn(|k| {
            let e = DVec3::from_array(std::array::from_fn(|j| if j == k { h } else { 0.0 }));
            let fp = r.value_and_gradient(x + e).unwrap().0;
            let fm = r.value_and_gradient(x - e).unwrap().0;
            (fp - fm) / (2.0 * h)
        }));
        worst = worst.max((g - fd).length());
    }
    println!("max |analytic - finite-difference gradient| = {worst:.2e}");
    assert!(worst < 1e-5, "{worst}");
}

#[test]
fn project_all_is_project_in_order() {
    let mut rng = ChaCha8Rng::seed_from_u64(6);
    let normals: Vec<DVec3> = (0..3000).map(|_| random_unit(&mut rng)).collect();
    let positions: Vec<DVec3> = normals.iter().map(|n| 10.0 * *n).collect();
    let r = Rimls::new(positions, normals, RimlsParams::new(1.0, 0.75)).unwrap();
    let xs: Vec<DVec3> = (0..500)
        .map(|_| rng.random_range(8.0..12.0) * random_unit(&mut rng))
        .chain([DVec3::ZERO, DVec3::splat(100.0)])
        .collect();
    let all = r.project_all(&xs);
    let one: Vec<_> = xs.iter().map(|&x| r.project(x)).collect();
    assert_eq!(all, one);
    assert!(all[all.len() - 1].is_none());
    assert!(all[..500].iter().all(Option::is_some));
}

/// Robustness: points pulled off a plane (outliers) move the plain IMLS surface; the
/// residual term of RIMLS keeps it on the plane.
#[test]
fn residual_weights_reject_outliers() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut positions = Vec::new();
    for _ in 0..20_000 {
        let mut p = DVec3::new(
            rng.random_range(-20.0..20.0),
            rng.random_range(-20.0..20.0),
            0.0,
        );
        if rng.random::<f64>() < 0.1 {
            p.z = 1.5;
        }
        positions.push(p);
    }
    let normals = vec![DVec3::Z; positions.len()];
    let xs: Vec<DVec3> = (0..200)
        .map(|_| {
            DVec3::new(
                rng.random_range(-10.0..10.0),
                rng.random_range(-10.0..10.0),
                0.5,
            )
        })
        .collect();
    let worst = |params: RimlsParams| {
        let r = Rimls::new(positions.clone(), normals.clone(), params).unwrap();
        r.project_all(&xs)
            .iter()
            .map(|p| p.expect("projects").0.z.abs())
            .fold(0.0, f64::max)
    };
    let plain = worst(RimlsParams {
        max_refit: 0,
        ..RimlsParams::new(1.0, f64::INFINITY)
    });
    let robust = worst(RimlsParams {
        max_refit: 10,
        ..RimlsParams::new(1.0, f64::INFINITY)
    });
    println!("10% outliers at 1.5 sigma_p: max |z| plain IMLS {plain:.4}, RIMLS {robust:.4}");
    assert!(plain > 0.02, "{plain}");
    assert!(robust < 0.25 * plain, "{robust} vs {plain}");
}

#[test]
fn sphere_projections_lie_on_the_sphere() {
    const R: f64 = 50.0;
    let sigma_p = 1.0;
    let count = 250_000;
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let normals: Vec<DVec3> = (0..count).map(|_| random_unit(&mut rng)).collect();
    let positions: Vec<DVec3> = normals.iter().map(|n| R * *n).collect();
    let queries: Vec<DVec3> = (0..3000)
        .map(|_| {
            R * random_unit(&mut rng) + rng.random_range(-sigma_p..=sigma_p) * random_unit(&mut rng)
        })
        .collect();
    let mut worst = Vec::new();
    for sigma_n in [0.75, f64::INFINITY] {
        let rimls = Rimls::new(
            positions.clone(),
            normals.clone(),
            RimlsParams::new(sigma_p, sigma_n),
        )
        .unwrap();
        let mut radial = Vec::new();
        let mut angle = Vec::new();
        let (projected, not_converged, most_steps) = project_counted(&rimls, &queries);
        for (q, r) in queries.iter().zip(projected) {
            let (p, n) = r.unwrap_or_else(|| panic!("{q} did not project"));
            radial.push((p.length() - R).abs());
            angle.push(n.angle_between(p.normalize()).to_degrees());
        }
        let (mean, _, max) = stats(&mut radial);
        let (mean_angle, _, max_angle) = stats(&mut angle);
        println!(
            "sphere R = {R}, {count} points, sigma_p = {sigma_p}, sigma_n = {sigma_n}: \
             | |p| - R | mean {mean:.2e}, max {max:.2e} = {:.2e} R \
             (planar-fit bias sigma_p^2/(2R) = {:.2e}); normal mean {mean_angle:.3}, max {max_angle:.3} deg; \
             {not_converged} not converged, at most {most_steps} Newton steps",
            max / R,
            sigma_p * sigma_p / (2.0 * R)
        );
        worst.push((sigma_n, max, max_angle, not_converged));
    }
    for (sigma_n, max, max_angle, not_converged) in worst {
        assert_eq!(not_converged, 0, "sigma_n {sigma_n}");
        assert!(max <= 1e-3 * R, "sigma_n {sigma_n}: max radial error {max}");
        assert!(
            max_angle < 1.5,
            "sigma_n {sigma_n}: max normal error {max_angle} deg"
        );
    }
}

#[test]
fn closest_point_queries_on_a_sphere_go_to_the_sphere() {
    use crate::surface::SurfaceQuery;
    const R: f64 = 20.0;
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let normals: Vec<DVec3> = (0..40_000).map(|_| random_unit(&mut rng)).collect();
    let positions: Vec<DVec3> = normals.iter().map(|n| R * *n).collect();
    let rimls = Rimls::new(positions, normals, RimlsParams::new(1.0, f64::INFINITY)).unwrap();
    // RIMLS lies off a sphere by about sigma_p^2 (k1 + k2) / 4 = 0.025 (the module's bias).
    let within = 2.0 * 0.025;
    for _ in 0..200 {
        let u = random_unit(&mut rng);
        let p = (R + rng.random_range(-1.0..=1.0)) * u;
        let sp = SurfaceQuery::closest_point(&rimls, p).unwrap();
        assert!(
            (sp.position.length() - R).abs() < within,
            "{}",
            sp.position.length()
        );
        assert!(sp.position.normalize().angle_between(u) < 1e-3);
        assert!((sp.distance - sp.position.distance(p)).abs() < 1e-12);
        assert!(rimls.smooth_normal(&sp).angle_between(u).to_degrees() < 1.0);
        // Farther than max_dist: none; and the midpoint of two surface points about 2 apart
        // goes back.
        assert!(rimls.closest_point_within(p, 0.5 * sp.distance).is_none());
        let q = R * (u + 0.1 * random_unit(&mut rng)).normalize();
        let mid = rimls.closest_point_to_midpoint(sp.position, q);
        assert!((mid.unwrap().position.length() - R).abs() < within);
    }
    // Outside the support (no point within 3 sigma_p): none, not a far-off guess.
    assert!(SurfaceQuery::closest_point(&rimls, DVec3::splat(1000.0)).is_none());
    assert!(SurfaceQuery::closest_point(&rimls, DVec3::NAN).is_none());
}

#[test]
fn torus_projections_lie_on_the_torus() {
    const MAJOR: f64 = 35.0;
    const MINOR: f64 = 15.0;
    let sigma_p = 0.5;
    let count = 400_000;
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    // (u, v) with density ∝ the area element (MAJOR + MINOR cos v), by rejection.
    let torus_point = |rng: &mut ChaCha8Rng| loop {
        let u: f64 = rng.random_range(0.0..std::f64::consts::TAU);
        let v: f64 = rng.random_range(0.0..std::f64::consts::TAU);
        if rng.random::<f64>() * (MAJOR + MINOR) <= MAJOR + MINOR * v.cos() {
            let n = DVec3::new(v.cos() * u.cos(), v.cos() * u.sin(), v.sin());
            let centre = DVec3::new(MAJOR * u.cos(), MAJOR * u.sin(), 0.0);
            break (centre + MINOR * n, n);
        }
    };
    let (positions, normals): (Vec<DVec3>, Vec<DVec3>) =
        (0..count).map(|_| torus_point(&mut rng)).unzip();
    let queries: Vec<DVec3> = (0..3000)
        .map(|_| {
            torus_point(&mut rng).0 + rng.random_range(-sigma_p..=sigma_p) * random_unit(&mut rng)
        })
        .collect();
    // Signed distance and outward normal of the true torus.
    let truth = |p: DVec3| {
        let ring = DVec3::new(p.x, p.y, 0.0).normalize() * MAJOR;
        ((p - ring).length() - MINOR, (p - ring).normalize())
    };
    let mut worst = Vec::new();
    for sigma_n in [0.75, f64::INFINITY] {
        let rimls = Rimls::new(
            positions.clone(),
            normals.clone(),
            RimlsParams::new(sigma_p, sigma_n),
        )
        .unwrap();
        let mut dist = Vec::new();
        let mut angle = Vec::new();
        let (projected, not_converged, most_steps) = project_counted(&rimls, &queries);
        for (q, r) in queries.iter().zip(projected) {
            let (p, n) = r.unwrap_or_else(|| panic!("{q} did not project"));
            let (d, true_n) = truth(p);
            dist.push(d.abs());
            angle.push(n.angle_between(true_n).to_degrees());
        }
        let (mean, _, max) = stats(&mut dist);
        let (mean_angle, _, max_angle) = stats(&mut angle);
        println!(
            "torus {MAJOR}/{MINOR}, {count} points, sigma_p = {sigma_p}, sigma_n = {sigma_n}: \
             distance mean {mean:.2e}, max {max:.2e} = {:.2e} minor = {:.2e} major radius \
             (planar-fit bias sigma_p^2 (k1+k2)/4 <= {:.2e}); normal mean {mean_angle:.3}, max {max_angle:.3} deg; \
             {not_converged} not converged, at most {most_steps} Newton steps",
            max / MINOR,
            max / MAJOR,
            sigma_p * sigma_p * (1.0 / MINOR + 1.0 / (MAJOR + MINOR)) / 4.0
        );
        worst.push((sigma_n, max, max_angle, not_converged));
    }
    for (sigma_n, max, max_angle, not_converged) in worst {
        assert_eq!(not_converged, 0, "sigma_n {sigma_n}");
        assert!(max <= 1e-3 * MINOR, "sigma_n {sigma_n}: max distance {max}");
        assert!(
            max_angle < 1.5,
            "sigma_n {sigma_n}: max normal error {max_angle} deg"
        );
    }
}

/// Points drawn uniformly by area on `mesh`, with the index of their face.
fn surface_samples(mesh: &TriMesh, count: usize, rng: &mut ChaCha8Rng) -> Vec<(DVec3, usize)> {
    let faces = crate::surface::area_sampler::AreaSampler::new(mesh).unwrap();
    (0..count)
        .map(|_| {
            let s = faces.draw(mesh, rng);
            (s.position, s.face)
        })
        .collect()
}

#[test]
#[ignore = "needs ../shared: .ci/run runs it"]
fn shared_sharp_edges_of_fandisk_are_kept_with_finite_sigma_n() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/fandisk.obj");
    let (model, _) = crate::io::read_mesh(&path).expect("fandisk.obj reads");
    let mesh = Normalization::for_bbox(&model.bbox().expect("vertices"))
        .expect("a bounding box")
        .apply_mesh(&model);
    let surface = MeshSurface::new(&mesh).expect("a surface");
    let sigma_p = 1.0;
    let area = mesh.area();
    // About 15 points within sigma_p of any point.
    let count = (15.0 * area / (std::f64::consts::PI * sigma_p * sigma_p)) as usize;
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let (positions, normals): (Vec<DVec3>, Vec<DVec3>) = surface_samples(&mesh, count, &mut rng)
        .into_iter()
        .map(|(p, f)| (p, mesh.face_normal(f)))
        .unzip();

    // Sharp edges: two faces whose normals differ by more than 30 degrees.
    let mut faces_of_edge: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (f, t) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            faces_of_edge
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push(f);
        }
    }
    let mut sharp: Vec<(u32, u32)> = faces_of_edge
        .iter()
        .filter(|(_, fs)| {
            fs.len() == 2
                && mesh
                    .face_normal(fs[0])
                    .angle_between(mesh.face_normal(fs[1]))
                    > 30f64.to_radians()
        })
        .map(|(&e, _)| e)
        .collect();
    sharp.sort_unstable();
    assert!(!sharp.is_empty());
    // The sharp edges sampled every sigma_p / 20, for distance queries.
    let mut edge_points = Vec::new();
    let mut edge_length = 0.0;
    for &(a, b) in &sharp {
        let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
        let steps = ((pa - pb).length() / (0.05 * sigma_p)).ceil() as usize;
        edge_points.extend((0..=steps).map(|s| pa.lerp(pb, s as f64 / steps as f64)));
        edge_length += (pa - pb).length();
    }
    let edge_tree = StaticTree::new(&edge_points);

    // Surface points within sigma_p of a sharp edge, moved off the surface by up to
    // sigma_p / 2 in a random direction.
    let mut nearest = Vec::new();
    let queries: Vec<DVec3> = surface_samples(&mesh, 200_000, &mut rng)
        .into_iter()
        .filter(|&(p, _)| {
            edge_tree.nearest_n(p, 1, &mut nearest);
            nearest[0].1 <= sigma_p * sigma_p
        })
        .take(3000)
        .map(|(p, _)| p + rng.random_range(-0.5 * sigma_p..=0.5 * sigma_p) * random_unit(&mut rng))
        .collect();
    assert_eq!(queries.len(), 3000);

    let mut figures = Vec::new();
    for sigma_n in [0.75, f64::INFINITY] {
        let rimls = Rimls::new(
            positions.clone(),
            normals.clone(),
            RimlsParams::new(sigma_p, sigma_n),
        )
        .unwrap();
        let (projected, not_converged, most_steps) = project_counted(&rimls, &queries);
        let failed = projected.iter().filter(|p| p.is_none()).count();
        let mut dist: Vec<f64> = projected
            .iter()
            .flatten()
            .map(|&(p, _)| surface.closest_point(p).expect("finite").distance)
            .collect();
        let (mean, p95, max) = stats(&mut dist);
        println!(
            "fandisk (bbox 100), {count} points, {} sharp edges ({edge_length:.0} long), \
             {} queries within sigma_p of them, sigma_p = {sigma_p}, sigma_n = {sigma_n}: \
             distance to the mesh mean {mean:.4}, 95% {p95:.4}, max {max:.4}; {failed} failed, \
             {not_converged} not converged, at most {most_steps} Newton steps",
            sharp.len(),
            queries.len()
        );
        assert!(failed <= queries.len() / 100, "{failed} projections failed");
        assert!(
            not_converged <= queries.len() / 100,
            "{not_converged} projections did not converge"
        );
        figures.push((mean, p95, max));
    }
    let (sharp_fit, smooth_fit) = (figures[0], figures[1]);
    assert!(
        sharp_fit.0 < 0.5 * smooth_fit.0,
        "mean {sharp_fit:?} vs {smooth_fit:?}"
    );
    assert!(
        sharp_fit.1 < 0.5 * smooth_fit.1,
        "95% {sharp_fit:?} vs {smooth_fit:?}"
    );
    assert!(
        sharp_fit.2 < 0.75 * smooth_fit.2,
        "max {sharp_fit:?} vs {smooth_fit:?}"
    );
}
