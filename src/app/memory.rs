//! The memory budget of a `remesh` job: its peak resident memory estimated from the input's
//! size and the output's, checked against a limit before the work starts.
//!
//! The estimate is a measured upper bound, not a count of allocations: peak RSS of jobs from
//! 2,000 to 1,000,000 output points on inputs of 1,280 to 200,000 faces, each below its
//! estimate (the table and its commands: `docs/decisions/memory-estimate.md`). The per-point
//! cost is the candidate pool (10 candidates per output point), the samples, the kd-trees, the
//! restricted Delaunay triangulation's refined copy of the input and the output mesh with its
//! checks; the per-face cost is the input mesh, its BVH and its normalized copy. Upsampling a
//! coarse input costs the most per point and sets the constant; downsampling costs less, where
//! the estimate is loose.

use std::path::Path;

use crate::error::{Error, Result};

/// Bytes of resident memory a job takes before any input: the program, its threads and buffers.
pub const BASE_BYTES: u64 = 10 << 20;
/// Bytes per input face (the mesh as read, its normalized copy, the BVH of the closest-point
/// queries, the boundary and winding structures).
pub const BYTES_PER_INPUT_FACE: u64 = 750;
/// Bytes per output point (10 candidates each, the samples, kd-trees, triangulation, the output
/// mesh and its checks), set by upsampling a coarse input (see the module's doc).
pub const BYTES_PER_OUTPUT_POINT: u64 = 4_400;
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

/// The default limit of a job: the smallest of the machine's physical memory
/// ([`physical_memory`]) and the limits the process is held to (`process_limit`: its control
/// group's memory limit, its address-space limit less a reserve). Under such a limit a job too
/// large is refused before it starts instead of aborting when an allocation fails. `None` when
/// none can be read.
pub fn memory_limit() -> Option<u64> {
    [physical_memory(), process_limit().map(|(bytes, _)| bytes)]
        .into_iter()
        .flatten()
        .min()
}

/// The limit of a job that asks for `given` bytes (`--max-memory`; `None`: [`memory_limit`]):
/// `given`, but never more than the process may take (`process_limit`), since a job past its
/// address-space or control-group limit aborts when an allocation fails whatever it was
/// allowed. A `given` above the machine's physical memory stands (swap may hold it).
pub fn effective_memory_limit(given: Option<u64>) -> Option<u64> {
    match given {
        None => memory_limit(),
        Some(bytes) => Some(process_limit().map_or(bytes, |(most, _)| bytes.min(most))),
    }
}

/// What holds the process to a memory limit of its own ([`process_limit`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ProcessLimit {
    /// The soft `RLIMIT_AS` (`ulimit -v`) of `soft` bytes, less `reserve` bytes kept for what
    /// is mapped without being resident ([`ADDRESS_SPACE_RESERVE_PER_THREAD`]).
    AddressSpace {
        /// The limit, in bytes.
        soft: u64,
        /// The reserve taken off it, in bytes.
        reserve: u64,
    },
    /// The memory limit of the process's control group (cgroup v2 `memory.max` or v1
    /// `memory.limit_in_bytes`, along its path).
    ControlGroup,
}

/// The most memory the process may take whatever a job asks, and what sets it: the smaller of
/// its control group's memory limit and its address-space limit (`RLIMIT_AS`, `ulimit -v`) less
/// a reserve for what is mapped without being resident (thread stacks, the allocator's
/// per-thread arenas: 128 MiB per core and as much again). `None` when neither is set or
/// readable.
pub(crate) fn process_limit() -> Option<(u64, ProcessLimit)> {
    let address_space = address_space_limit().map(|(soft, reserve)| {
        (
            soft.saturating_sub(reserve),
            ProcessLimit::AddressSpace { soft, reserve },
        )
    });
    let group = cgroup_limit().map(|bytes| (bytes, ProcessLimit::ControlGroup));
    [address_space, group]
        .into_iter()
        .flatten()
        .min_by_key(|&(bytes, _)| bytes)
}

/// How a refusal over `limit` bytes names the limit and what would lift it: the limit given
/// (`max_memory`), or, where the process's own limit ([`process_limit`]) sets it, that one,
/// since raising `max_memory` cannot help then. Returns (the limit in words, what to raise).
fn limit_words(limit: u64) -> (String, &'static str) {
    match process_limit() {
        Some((bytes, ProcessLimit::AddressSpace { soft, reserve })) if bytes == limit => (
            format!(
                "the {} this process may take (its address-space limit, `ulimit -v`, of {} \
                 less {} kept for thread stacks and allocator arenas)",
                format_bytes(limit),
                format_bytes(soft),
                format_bytes(reserve)
            ),
            "raise the address-space limit (`ulimit -v`; raising `max_memory` cannot help)",
        ),
        Some((bytes, ProcessLimit::ControlGroup)) if bytes == limit => (
            format!(
                "the {} this process may take (its control group's memory limit)",
                format_bytes(limit)
            ),
            "raise the control group's memory limit (raising `max_memory` cannot help)",
        ),
        _ => (
            format!("the limit of {}", format_bytes(limit)),
            "raise `max_memory`",
        ),
    }
}

/// Address space mapped per thread beyond resident memory (a glibc malloc arena reserves 64
/// MiB, a stack 2 to 8 MiB), for the reserve of [`memory_limit`].
pub const ADDRESS_SPACE_RESERVE_PER_THREAD: u64 = 128 << 20;

/// The soft `RLIMIT_AS` (`Max address space` of `/proc/self/limits`) and the reserve to take
/// off it, or `None` when unlimited or unreadable.
fn address_space_limit() -> Option<(u64, u64)> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    let soft: u64 = line
        .trim_start_matches("Max address space")
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()) as u64 + 1;
    Some((
        soft,
        threads.saturating_mul(ADDRESS_SPACE_RESERVE_PER_THREAD),
    ))
}

/// The smallest memory limit of the process's control group and its ancestors, or `None`
/// when there is none (`max`, or a v1 value of 2^62 and above) or it cannot be read.
fn cgroup_limit() -> Option<u64> {
    let groups = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let mut files = Vec::new();
    for line in groups.lines() {
        let mut parts = line.splitn(3, ':');
        let (Some(id), Some(controllers), Some(path)) = (parts.next(), parts.next(), parts.next())
        else {
            continue;
        };
        let (root, file) = if id == "0" && controllers.is_empty() {
            ("/sys/fs/cgroup", "memory.max")
        } else if controllers.split(',').any(|c| c == "memory") {
            ("/sys/fs/cgroup/memory", "memory.limit_in_bytes")
        } else {
            continue;
        };
        // The group and its ancestors; in a container the group is often the mount's root.
        let mut dir = std::path::PathBuf::from(format!("{root}{path}"));
        loop {
            files.push(dir.join(file));
            if dir.as_os_str().len() <= root.len() || !dir.pop() {
                break;
            }
        }
        files.push(Path::new(root).join(file));
    }
    files
        .iter()
        .filter_map(|f| std::fs::read_to_string(f).ok()?.trim().parse::<u64>().ok())
        .filter(|&v| v < 1 << 62)
        .min()
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
        let (limit, raise) = limit_words(limit);
        return Err(Error::InvalidParameter {
            name: "max_memory",
            message: format!(
                "{}: a file of {} cannot be remeshed within {limit}: its faces take several \
                 times their file size in memory; {raise}",
                path.display(),
                format_bytes(meta.len()),
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
        let (limit, raise) = limit_words(limit);
        return Err(Error::InvalidParameter {
            name: "max_memory",
            message: format!(
                "remeshing {input_faces} input faces to about {output_points:.0} points needs \
                 about {}, more than {limit}; ask for fewer points or {raise}",
                format_bytes(need),
            ),
        });
    }
    Ok(())
}

/// Bytes per input point of a point set besides what its reader holds: the out-of-core scan's
/// buckets and chunks, the outlier and far-group passes. Peak RSS of `remesh F OUT --points
/// 3000 -q --no-distance` on points on a sphere: XYZ 99 and 130 MB at 0.5 and 1 million points
/// (62 bytes a point more); binary PCD 98, 178 and 216 MB at 0.5, 1 and 2 million, against
/// this estimate with the PCD reader's bytes 103, 183 and 343 MB.
pub const BYTES_PER_INPUT_POINT: u64 = 64;

/// [`check_remesh_budget`] for a point set of `input_points` points whose reader holds
/// `reader_bytes` (a PCD or E57 file is read whole: `PointSource::input_size`) besides the
/// pipeline's work for `output_points`.
///
/// # Errors
/// As [`check_remesh_budget`], the message naming what the reading holds.
pub fn check_point_set_budget(
    input_points: u64,
    reader_bytes: u64,
    output_points: f64,
    measure_distance: bool,
    limit: u64,
) -> Result<()> {
    let input_bytes = input_points
        .saturating_mul(BYTES_PER_INPUT_POINT)
        .saturating_add(reader_bytes);
    let need =
        estimate_remesh_bytes(0, output_points, measure_distance).saturating_add(input_bytes);
    if need > limit {
        let (limit, raise) = limit_words(limit);
        return Err(Error::InvalidParameter {
            name: "max_memory",
            message: format!(
                "reading {input_points} points (about {}) and remeshing them to about {output_points:.0} \
                 points needs about {}, more than {limit}; ask for fewer points or {raise}",
                format_bytes(input_bytes),
                format_bytes(need),
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
        assert!(e.to_string().contains("`max_memory`"), "{e}");
    }
}
