//! The reconstruction experiment (Sec. 7.2, Table 2) end to end on a small case: spot at one
//! σ_p from a dense point set.

use std::path::Path;

use spectral_experiments::reconstruction_eval::{
    evaluate_model, input_points, read_normalized_outward, PointSource, ReconstructionEvalParams,
};
use spectral_experiments::subsample::Subsampler;
use spectral_remesh::internal::NormalField;

mod common;

use common::model;

#[test]
fn spot_pipeline_reconstructs_the_input_and_every_subsampler_hits_the_count() {
    let sigma_p = 2.0;
    let params = ReconstructionEvalParams {
        sigma_p: vec![sigma_p],
        source: PointSource::Surface {
            spacing: 0.5,
            normals: NormalField::Smooth,
        },
        distance_samples: 50_000,
        repeats: 1,
        ..Default::default()
    };
    let r = evaluate_model(&model("spot.obj"), &params, &|_| {}).unwrap();
    assert_eq!(r.model, "spot");
    assert!(!r.flipped, "spot is oriented outward");
    // 77,386 points: area / 0.5².
    assert!((r.input_points as f64 / (r.area / 0.25) - 1.0).abs() < 1e-3);
    let s = &r.sigmas[0];

    // The surface of all points is closed and close to the input mesh: RIMLS (a planar fit)
    // is offset by about σ_p² κ / 4 on curved parts.
    assert_eq!(s.all_points.boundary_edges, 0);
    assert_eq!(s.all_points.components, 1);
    let d = s.all_points_to_input.as_ref().unwrap();
    assert!(
        d.rms < 0.1 * sigma_p && d.hausdorff < 0.5 * sigma_p,
        "{d:?}"
    );

    // Every subsampler: the linear scan's count within the tolerance (random: exactly).
    assert_eq!(s.methods.len(), 4);
    let ours = &s.methods[0];
    assert_eq!(ours.method, "ours");
    assert!(
        ours.points > 1000 && ours.points < r.input_points / 10,
        "{}",
        ours.points
    );
    for m in &s.methods {
        assert_eq!(m.target, ours.points);
        let off = (m.points as f64 / ours.points as f64 - 1.0).abs();
        assert!(
            m.reached && off <= 0.005,
            "{}: {} points",
            m.method,
            m.points
        );
        if m.method == "random" {
            assert_eq!(m.points, ours.points);
        }
        let d = m.distance.as_ref().unwrap();
        assert!(
            d.rms.is_finite() && d.hausdorff >= d.rms,
            "{}: {d:?}",
            m.method
        );
    }
    // The spectral sampling reproduces the all-points surface better than a random subset of
    // the same size (0.022 against 0.069 when this was written).
    let rms = |name: &str| {
        s.methods
            .iter()
            .find(|m| m.method == name)
            .and_then(|m| m.distance.as_ref())
            .unwrap()
            .rms
    };
    assert!(
        rms("ours") < 0.5 * rms("random"),
        "{} vs {}",
        rms("ours"),
        rms("random")
    );
    // With the weights of the points it dropped as masses (Sec. 5), every subset is
    // reconstructed a second time; ours then follows the all-points surface more closely still
    // (RMS 0.018 against 0.023 unweighted when this was written; random 0.070).
    let weighted_rms = |name: &str| {
        let m = s.methods.iter().find(|m| m.method == name).unwrap();
        let w = m.weighted.as_ref().unwrap();
        assert!(
            w.weight_range.0 >= 0.0 && w.weight_range.1 > 1.0,
            "{name}: {w:?}"
        );
        w.distance.as_ref().unwrap().rms
    };
    assert!(
        weighted_rms("ours") < rms("ours"),
        "{} vs {}",
        weighted_rms("ours"),
        rms("ours")
    );
    assert!(weighted_rms("ours") < 0.5 * weighted_rms("random"));
}

#[test]
#[ignore = "needs ../shared: .ci/run runs it"]
fn shared_horse_is_flipped_outward_and_vertices_keep_their_normals() {
    let (mesh, flipped) = read_normalized_outward(&model("horse.obj")).unwrap();
    assert!(flipped, "horse.obj is oriented inward");
    assert!(mesh.signed_volume() > 0.0);
    let bbox = mesh.bbox().unwrap();
    assert!((bbox.longest_side() - 100.0).abs() < 1e-9);
    let (p, n) = input_points(&mesh, PointSource::Vertices, 1).unwrap();
    assert_eq!(p.len(), mesh.positions.len());
    // Outward: the normals point away from the centre on average.
    let outward = p
        .iter()
        .zip(&n)
        .filter(|(p, n)| (**p - bbox.center()).dot(**n) > 0.0)
        .count();
    assert!(
        outward as f64 > 0.7 * p.len() as f64,
        "{outward} of {}",
        p.len()
    );
}

#[test]
fn bad_parameters_are_errors() {
    let path = model("spot.obj");
    let no_scan = ReconstructionEvalParams {
        methods: vec![Subsampler::UniformRandom],
        ..Default::default()
    };
    assert!(evaluate_model(&path, &no_scan, &|_| {}).is_err());
    let bad_sigma = ReconstructionEvalParams {
        sigma_p: vec![0.0],
        ..Default::default()
    };
    assert!(evaluate_model(&path, &bad_sigma, &|_| {}).is_err());
    let bad_spacing = ReconstructionEvalParams {
        source: PointSource::Surface {
            spacing: 0.0,
            normals: NormalField::Smooth,
        },
        ..Default::default()
    };
    assert!(evaluate_model(&path, &bad_spacing, &|_| {}).is_err());
    let bad_crease = ReconstructionEvalParams {
        source: PointSource::Surface {
            spacing: 1.0,
            normals: NormalField::Crease {
                angle_deg: f64::NAN,
            },
        },
        ..Default::default()
    };
    assert!(evaluate_model(&path, &bad_crease, &|_| {}).is_err());
    let bad_domain = ReconstructionEvalParams {
        domain: f64::NAN,
        ..Default::default()
    };
    assert!(evaluate_model(&path, &bad_domain, &|_| {}).is_err());
    assert!(evaluate_model(Path::new("/nonexistent.obj"), &Default::default(), &|_| {}).is_err());
}
