#![no_main]
//! The whole `remesh` job (read, sample, triangulate, optimize, untangle, check, write) on small
//! messy meshes shaped by the fuzzer's bytes (small_meshes.rs): reversed regions, polygons,
//! near-degenerate and zero-area faces, holes, duplicate faces, far vertices. No panic, no
//! internal error, a manifold oriented output with every topology change noted; time and memory
//! per run are bounded by libFuzzer's `-timeout` and `-rss_limit_mb` (README).

use libfuzzer_sys::fuzz_target;

#[path = "small_meshes.rs"]
mod small_meshes;

fuzz_target!(|data: &[u8]| {
    let base = if std::path::Path::new("/dev/shm").is_dir() {
        std::path::PathBuf::from("/dev/shm")
    } else {
        std::env::temp_dir()
    };
    let dir = base.join(format!("remesh-fuzz-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    small_meshes::assert_remesh_is_sound(data, &dir);
});
