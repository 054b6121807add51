//! Checks the crate's glTF output with the Khronos glTF-Validator: writes spot and horse (from
//! `../shared/data`) as `.glb` and `.gltf`, and a mesh with an isolated vertex and a degenerate
//! triangle as `odd.glb`, into `OUT_DIR`, then runs `node eval/validate_gltf.mjs` on them (see
//! that script for installing the validator, an npm package outside the repository).
//!
//! `cargo run --release --example validate_gltf -- OUT_DIR`
//!
//! Exit code: the script's (0 when no file has a validation error; 2 when the validator is not
//! installed), or 1 when the files cannot be written or `node` cannot be run. Not a test: it
//! needs Node.js and the validator, which `cargo test` does not.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use glam::DVec3;
use spectral_remesh::{read_mesh, write_mesh, TriMesh};

fn write_files(out: &Path) -> Result<Vec<PathBuf>, spectral_remesh::Error> {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data");
    let mut written = Vec::new();
    for (name, stem) in [("spot.obj", "spot"), ("horse.ply", "horse")] {
        let (mesh, _) = read_mesh(&data.join(name))?;
        for ext in ["glb", "gltf"] {
            let path = out.join(format!("{stem}.{ext}"));
            write_mesh(&path, &mesh)?;
            written.push(path);
        }
    }
    // An isolated vertex (normal +Z) and a degenerate triangle.
    let odd = TriMesh::new(
        vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::splat(5.0),
            DVec3::new(2.0, 0.0, 0.0),
        ],
        vec![[0, 1, 2], [0, 1, 4]],
    );
    let path = out.join("odd.glb");
    write_mesh(&path, &odd)?;
    written.push(path);
    Ok(written)
}

fn main() -> ExitCode {
    let Some(out) = std::env::args_os().nth(1).map(PathBuf::from) else {
        eprintln!("usage: cargo run --release --example validate_gltf -- OUT_DIR");
        return ExitCode::from(1);
    };
    if let Err(e) = std::fs::create_dir_all(&out) {
        eprintln!("validate_gltf: cannot create {}: {e}", out.display());
        return ExitCode::from(1);
    }
    let files = match write_files(&out) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("validate_gltf: {e}");
            return ExitCode::from(1);
        }
    };
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("eval/validate_gltf.mjs");
    match Command::new("node").arg(&script).args(&files).status() {
        Ok(status) => ExitCode::from(status.code().unwrap_or(1).clamp(0, 255) as u8),
        Err(e) => {
            eprintln!(
                "validate_gltf: wrote {} files to {}, but cannot run node ({e})",
                files.len(),
                out.display()
            );
            ExitCode::from(1)
        }
    }
}
