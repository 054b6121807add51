//! The memory budget of a `remesh` job: its peak resident memory estimated from the input's
//! size and the output's, checked against a limit before the work starts.
//!
//! The estimate is a measured upper bound, not a count of allocations: peak RSS
//! (`/usr/bin/time -v`, release build, 2026-11) of these jobs, and the model above each:
//!
//! | job | input faces | output points | peak RSS | model |
//! |---|---|---|---|---|
//! | spot → 2000 | 5,856 | 2,000 | 12 MB | 19 MB |
//! | spot → 50,000 | 5,856 | 50,000 | 122 MB | 134 MB |
//! | beetle → 3000 | 2,053 | 3,000 | 13 MB | 19 MB |
//! | horse → 2000 | 96,966 | 2,000 | 74 MB | 88 MB |
//! | horse → 2000, with the distance | 96,966 | 2,000 | 95 MB | 120 MB |
//! | horse → 100,000 | 96,966 | 100,000 | 288 MB | 323 MB |
//! | a 200k-face horse → 10,000 | 199,996 | 10,000 | 149 MB | 184 MB |
//!
//! The per-point cost is the candidate pool (10 candidates per output point), the samples, the
//! kd-trees and the triangulation's umbrellas; the per-face cost is the input mesh, its BVH and
//! its normalized copy.

use std::path::Path;

use crate::error::{Error, Result};

/// Bytes of resident memory a job takes before any input: the program, its threads and buffers.
pub const BASE_BYTES: u64 = 10 << 20;
/// Bytes per input face (the mesh as read, its normalized copy, the BVH of the closest-point
/// queries, the boundary and winding structures).
pub const BYTES_PER_INPUT_FACE: u64 = 750;
/// Bytes per output point (10 candidates each, the samples, kd-trees, triangulation, the output
/// mesh and its checks).
pub const BYTES_PER_OUTPUT_POINT: u64 = 2_400;
/// Bytes the report's distance measurement adds (200,000 samples a side and their queries).
pub const DISTANCE_BYTES: u64 = 32 << 20;

/// The estimated peak resident memory, in bytes, of remeshing an input of `input_faces` faces
/// to `output_points` points, with the distance measurement of the report or without (see the
/// module's table for the measurements behind it).
pub fn estimate_remesh_bytes(input_faces: u64, output_points: f64, measure_distance: bool) -> u64 {
    let points = output_points.clamp(0.0, 1e15) as u64;
    BASE_BYTES
        .saturating_add(input_faces.saturating_mul(BYTES_PER_INPUT_FACE))
        .saturating_add(points.saturating_mul(BYTES_PER_OUTPUT_POINT))
        .saturating_add(if measure_distance { DISTANCE_BYTES } else { 0 })
}

/// `bytes` for a message: MB or GB with three significant figures.
pub fn format_bytes(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= 1e9 {
        format!("{:.3} GB", b / 1e9)
    } else {
        format!("{:.3} MB", b / 1e6)
    }
}

/// The machine's physical memory (`MemTotal` of `/proc/meminfo`), the default limit of a job;
/// `None` where it cannot be read (then no limit applies unless one is given).
pub fn physical_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// Refuses, before it is read, an input file larger than `limit` bytes: its faces take far more
/// memory than their bytes on disk (750 bytes each against about 15 to 100 in OBJ, PLY and glTF
/// files), so such a file cannot be remeshed within the limit whatever the output. The full
/// estimate ([`check_remesh_budget`]) follows the reading.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `--max-memory`, the file and both sizes.
pub fn check_input_size(path: &Path, limit: u64) -> Result<()> {
    let Ok(meta) = std::fs::metadata(path) else {
        // The reader gives the error.
        return Ok(());
    };
    if meta.len() > limit {
        return Err(Error::InvalidParameter {
            name: "--max-memory",
            message: format!(
                "{}: a file of {} cannot be remeshed within the limit of {} (its faces take \
                 several times their file size in memory); raise --max-memory",
                path.display(),
                format_bytes(meta.len()),
                format_bytes(limit)
            ),
        });
    }
    Ok(())
}

/// Refuses a job whose estimate ([`estimate_remesh_bytes`]) exceeds `limit` bytes.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `--max-memory`, the estimate, the sizes it comes from and
/// the limit.
pub fn check_remesh_budget(
    input_faces: u64,
    output_points: f64,
    measure_distance: bool,
    limit: u64,
) -> Result<()> {
    let need = estimate_remesh_bytes(input_faces, output_points, measure_distance);
    if need > limit {
        return Err(Error::InvalidParameter {
            name: "--max-memory",
            message: format!(
                "remeshing {input_faces} input faces to about {output_points:.0} points needs \
                 about {}, more than the limit of {}; ask for fewer points or raise --max-memory",
                format_bytes(need),
                format_bytes(limit)
            ),
        });
    }
    Ok(())
}

/// Parses a memory size: a number with an optional unit `K`, `M`, `G`, `T` (powers of 1000,
/// also written `KB`, `MB`, ...) or `KiB`, `MiB`, `GiB`, `TiB` (powers of 1024); no unit means
/// bytes. Case-insensitive.
///
/// # Errors
/// A message for the command line when the text is not such a size.
pub fn parse_bytes(text: &str) -> std::result::Result<u64, String> {
    let t = text.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let value: f64 = number
        .parse()
        .map_err(|_| format!("{text:?} is not a memory size (e.g. 512M, 8G, 2GiB)"))?;
    let scale: f64 = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 1.0,
        "k" | "kb" => 1e3,
        "m" | "mb" => 1e6,
        "g" | "gb" => 1e9,
        "t" | "tb" => 1e12,
        "kib" => 1024.0,
        "mib" => 1024.0 * 1024.0,
        "gib" => 1024.0 * 1024.0 * 1024.0,
        "tib" => 1024.0 * 1024.0 * 1024.0 * 1024.0,
        _ => {
            return Err(format!(
                "{text:?}: unknown unit (use K, M, G, T, KiB, MiB, GiB or TiB)"
            ))
        }
    };
    let bytes = value * scale;
    if !(1.0..1.8e19).contains(&bytes) {
        return Err(format!(
            "{text:?} is not a memory size between 1 byte and 18 EB"
        ));
    }
    Ok(bytes as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_and_without_units() {
        assert_eq!(parse_bytes("512M"), Ok(512_000_000));
        assert_eq!(parse_bytes("2GiB"), Ok(2 << 30));
        assert_eq!(parse_bytes("1.5gb"), Ok(1_500_000_000));
        assert_eq!(parse_bytes("4096"), Ok(4096));
        assert!(parse_bytes("lots").is_err());
        assert!(parse_bytes("5X").is_err());
        assert!(parse_bytes("0").is_err());
    }

    #[test]
    fn the_estimate_grows_with_input_and_output_and_saturates() {
        let small = estimate_remesh_bytes(1000, 1000.0, false);
        assert!(estimate_remesh_bytes(2000, 1000.0, false) > small);
        assert!(estimate_remesh_bytes(1000, 2000.0, false) > small);
        assert!(estimate_remesh_bytes(1000, 1000.0, true) > small);
        assert_eq!(estimate_remesh_bytes(u64::MAX, 1e300, true), u64::MAX);
        assert!(check_remesh_budget(1000, 1000.0, false, small).is_ok());
        let e = check_remesh_budget(1000, 1000.0, false, small - 1).unwrap_err();
        assert!(e.to_string().contains("--max-memory"), "{e}");
    }
}
