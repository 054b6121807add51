//! Runs `spectral-experiments reconstruct-eval` on a small case and checks its JSON report, the
//! meshes it writes, and the usage error for an unknown method.

use std::process::Command;

use serde_json::Value;

mod common;

use common::model;

fn float(v: &Value, path: &[&str]) -> f64 {
    let mut x = v;
    for p in path {
        x = &x[*p];
    }
    x.as_f64()
        .unwrap_or_else(|| panic!("{path:?} is not a number: {x}"))
}

#[test]
fn reconstruct_eval_writes_json_and_meshes_and_refuses_an_unknown_method() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("r.json");
    let meshes = dir.path().join("meshes");
    let status = Command::new(env!("CARGO_BIN_EXE_spectral-experiments"))
        .args(["reconstruct-eval", "-q", "--sigma-p", "3", "--spacing", "1"])
        .args([
            "--repeats",
            "1",
            "--samples",
            "10000",
            "--methods",
            "ours,random",
        ])
        .arg(model("spot.obj"))
        .arg("--json")
        .arg(&json)
        .arg("--meshes")
        .arg(&meshes)
        .status()
        .expect("run spectral-experiments");
    assert!(status.success());
    let r: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let methods = &r[0]["sigmas"][0]["methods"];
    assert_eq!(methods.as_array().map(Vec::len), Some(2));
    assert_eq!(methods[0]["method"], "ours");
    assert_eq!(methods[0]["points"], methods[1]["points"]);
    assert!(float(&methods[0], &["distance", "rms"]) < float(&methods[1], &["distance", "rms"]));
    for name in ["all", "ours", "random", "ours-points"] {
        assert!(
            meshes.join(format!("spot-s3-{name}.ply")).exists(),
            "{name}"
        );
    }

    let out = Command::new(env!("CARGO_BIN_EXE_spectral-experiments"))
        .args(["reconstruct-eval", "--methods", "ours,lloyd"])
        .arg(model("spot.obj"))
        .output()
        .expect("run spectral-experiments");
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--methods") && err.lines().count() == 1,
        "{err}"
    );
}
