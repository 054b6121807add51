//! Shared by the point-set reader targets: the bytes go to a file with the format's extension,
//! its header is checked (what the memory limit reads) and its points are read in chunks. An
//! error is fine; a panic, an abort or memory beyond libFuzzer's `-rss_limit_mb` is a finding:
//! a declared size must be checked against the file before it is allocated.

use spectral_remesh::internal::{PointReader, ReadPoints};
use spectral_remesh::PointSource;

#[path = "common.rs"]
mod common;

/// Reads `data` as a point-set file with extension `ext`; the points read must be finite, no
/// more than the header announced, and their normals unit or zero.
pub fn read_points(data: &[u8], ext: &str) {
    let path = common::scratch(ext);
    if std::fs::write(&path, data).is_err() {
        return;
    }
    let size = PointSource::File(path.clone()).input_size();
    let Ok(mut reader) = PointReader::open(&path) else {
        return;
    };
    let announced = reader.count();
    let mut chunk = Vec::new();
    let mut read = 0u64;
    while let Ok(n) = reader.read_chunk(&mut chunk, 4096) {
        if n == 0 {
            break;
        }
        read += n as u64;
        for p in &chunk {
            assert!(p.position.is_finite(), "a non-finite position was read");
            let l = p.normal.length();
            assert!(l == 0.0 || (l - 1.0).abs() < 1e-6, "a normal of length {l}");
        }
    }
    assert!(read <= announced, "{read} points read, {announced} announced");
    if let Ok(size) = size {
        assert!(size.points.is_none_or(|p| read <= p), "more points than the header checked");
    }
}
