//! Shared by the reader targets: the bytes go to a file with the format's extension (the readers
//! take paths), and a mesh that is read must be one the pipeline can take.

use std::path::PathBuf;

use spectral_remesh::read_mesh;

/// A file of this process in shared memory (or the temp folder), with extension `ext`.
pub fn scratch(ext: &str) -> PathBuf {
    let base = if std::path::Path::new("/dev/shm").is_dir() {
        PathBuf::from("/dev/shm")
    } else {
        std::env::temp_dir()
    };
    base.join(format!("remesh-fuzz-{}.{ext}", std::process::id()))
}

/// Reads `data` as a file with extension `ext`: an error is fine, a panic is a bug, and a mesh
/// that reads must have faces, indices in range and finite coordinates.
pub fn read_bytes(data: &[u8], ext: &str) {
    let path = scratch(ext);
    if std::fs::write(&path, data).is_err() {
        return;
    }
    if let Ok((mesh, _)) = read_mesh(&path) {
        assert!(!mesh.triangles.is_empty(), "a mesh without faces was read");
        assert!(
            mesh.check_indices().is_none(),
            "an index out of range was read"
        );
        assert!(
            mesh.positions.iter().all(|p| p.is_finite()),
            "a non-finite coordinate was read"
        );
    }
}
