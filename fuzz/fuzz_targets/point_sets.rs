#![no_main]
//! The whole `remesh` job on scan-like point sets shaped by the fuzzer's bytes
//! (messy_point_sets.rs): a sphere, a torus or a plane patch with noise, exact duplicate lines,
//! far clusters or a far copy, points uniform in a volume around the shape, UTM-like offsets,
//! normals or none, as XYZ text. No panic, no internal error, an error of one line, and an
//! output with faces that is manifold and consistently oriented; time and memory per run are
//! bounded by libFuzzer's `-timeout` and `-rss_limit_mb`.

use libfuzzer_sys::fuzz_target;

#[path = "messy_point_sets.rs"]
mod messy_point_sets;

fuzz_target!(|data: &[u8]| {
    let base = if std::path::Path::new("/dev/shm").is_dir() {
        std::path::PathBuf::from("/dev/shm")
    } else {
        std::env::temp_dir()
    };
    let dir = base.join(format!("point-sets-fuzz-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    messy_point_sets::assert_point_remesh_is_sound(data, &dir);
});
