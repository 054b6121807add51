//! Runs `spectral-experiments blue-noise` and checks its JSON report: the shapes a plotting script relies on,
//! the same seed giving the same sets, and bad parameters giving a one-line usage error.

use std::path::Path;
use std::process::Command;

use serde_json::Value;

fn run(args: &[&str], out: &Path) -> Value {
    let o = Command::new(env!("CARGO_BIN_EXE_spectral-experiments"))
        .arg("blue-noise")
        .args(args)
        .arg("--output")
        .arg(out)
        .arg("-q")
        .output()
        .expect("run spectral-experiments");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_str(&std::fs::read_to_string(out).unwrap()).unwrap()
}

#[test]
fn blue_noise_writes_a_report_with_plottable_shapes_and_repeats_for_a_seed() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "--method", "ours", "--n", "400", "--sets", "2", "--seed", "5",
    ];
    let a = run(&args, &dir.path().join("a.json"));
    let b = run(&args, &dir.path().join("b.json"));
    let f = a["half_width"].as_u64().unwrap() as usize;
    assert_eq!(f, 40); // round(2 sqrt(400))
    let rows = a["periodogram"].as_array().unwrap();
    assert_eq!(rows.len(), 2 * f + 1);
    assert!(rows
        .iter()
        .all(|r| r.as_array().unwrap().len() == 2 * f + 1));
    assert_eq!(rows[f][f].as_f64(), Some(0.0), "DC term excluded");
    assert_eq!(a["first_set"].as_array().unwrap().len(), 400);
    assert_eq!(a["rho"].as_array().unwrap().len(), 2);
    let radial = &a["radial"];
    let k = radial["power"].as_array().unwrap().len();
    assert_eq!(k, f - 1);
    assert_eq!(radial["frequency"].as_array().unwrap().len(), k);
    assert_eq!(radial["anisotropy_db"].as_array().unwrap().len(), k);
    assert_eq!(a["first_set"], b["first_set"]);
    assert_eq!(a["rho"], b["rho"]);
    assert_eq!(a["periodogram"], b["periodogram"]);
    let c = run(
        &[
            "--method", "ours", "--n", "400", "--sets", "2", "--seed", "6",
        ],
        &dir.path().join("c.json"),
    );
    assert_ne!(a["first_set"], c["first_set"]);
}

#[test]
fn too_few_points_for_the_kernel_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.json");
    let o = Command::new(env!("CARGO_BIN_EXE_spectral-experiments"))
        .args(["blue-noise", "--method", "ours", "--n", "30", "--output"])
        .arg(&out)
        .output()
        .expect("run spectral-experiments");
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("support radius"), "{err}");
    assert!(!out.exists());
}
