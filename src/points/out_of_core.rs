//! Out-of-core simplification of a point set by the randomized linear scan (Sec. 6.1,
//! Algorithm 1): memory bounded by the output set plus a fixed buffer, not by the input.
//!
//! Two passes over the data:
//! 1. The input is streamed once: its bounding box is taken (for the bbox-100 frame of Sec. 7) and
//!    every point goes to one of `B` temporary bucket files chosen at random (a bucket shuffle:
//!    the visit order is random without the input ever being in memory).
//! 2. Each bucket in turn is loaded (about `bucket_points` points), shuffled, and streamed
//!    through the linear scan, whose output set O lives in one dynamic kd-tree.
//!
//! With `--points N` the sigma_p is found first on the first bucket alone: a uniformly random
//! subset as dense as the output needs gives the same count (the count depends on sigma_p and the
//! surface, not on the input's density).

use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::DVec3;
use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::stream::{encode_record, Point, PointReader, RECORD_BYTES};
use crate::error::{Error, Result};
use crate::kernel::Kernel;
use crate::mesh::{Aabb, Normalization};
use crate::sampling::linear_scan::{LinearScanParams, LinearScanner};
use crate::sampling::target_count::{find_sigma_p, TargetCountParams};

/// Parameters of [`simplify_out_of_core`].
#[derive(Debug, Clone, PartialEq)]
pub struct OutOfCoreParams {
    /// The output density: `Some(n)` searches sigma_p for about n samples.
    pub target: Option<usize>,
    /// sigma_p in bbox-100 units, used when `target` is `None`.
    pub sigma_p: f64,
    /// sigma_n (infinity: positions only).
    pub sigma_n: f64,
    /// The linear scan's epsilon and support radius.
    pub scan: LinearScanParams,
    /// Points per bucket (the fixed buffer; default 2^20).
    pub bucket_points: usize,
    /// Seed of the bucket assignment and the shuffles.
    pub seed: u64,
    /// Where the bucket files go (default: the system's temporary folder).
    pub temp_dir: Option<PathBuf>,
}

impl Default for OutOfCoreParams {
    fn default() -> Self {
        OutOfCoreParams {
            target: None,
            sigma_p: 1.0,
            sigma_n: f64::INFINITY,
            scan: LinearScanParams::default(),
            bucket_points: 1 << 20,
            seed: 1,
            temp_dir: None,
        }
    }
}

/// The result of [`simplify_out_of_core`].
#[derive(Debug, Clone)]
pub struct OutOfCoreResult {
    /// The output set O in the input's units, in the order the scan accepted it.
    pub samples: Vec<Point>,
    /// Points read.
    pub input_points: u64,
    /// Whether the input had normals (without them the kernel uses positions only).
    pub had_normals: bool,
    /// The sigma_p used, bbox-100 units.
    pub sigma_p: f64,
    /// Model units ↔ bbox-100 units.
    pub normalization: Normalization,
    /// Candidates rejected by their nearest output sample alone, and measured with eq. 10.
    pub rejected_by_nearest: usize,
    /// Candidates whose measure was evaluated.
    pub measured: usize,
    /// Seconds: reading and bucketing, the sigma_p search (with the scan of the buckets it
    /// used), the scan of the other buckets.
    pub seconds: [f64; 3],
}

/// Input points per wanted sample in the subset the sigma_p search runs on.
const SEARCH_POINTS_PER_SAMPLE: f64 = 4.0;

fn decode(b: &[u8]) -> Point {
    let f = |k: usize| {
        f64::from(f32::from_le_bytes(
            b[4 * k..4 * k + 4].try_into().unwrap_or([0; 4]),
        ))
    };
    Point {
        position: DVec3::new(f(0), f(1), f(2)),
        normal: DVec3::new(f(3), f(4), f(5)),
    }
}

/// Simplifies the point set in the PLY file `input` out of core (see the module documentation).
/// Peak memory: the output set, one bucket, and a 1 MiB write buffer per bucket.
///
/// # Errors
/// Errors of the PLY reader (naming the file); [`Error::InvalidMesh`] for an empty input or one
/// whose bounding box has no extent; [`Error::Io`] when the temporary files fail.
pub fn simplify_out_of_core(input: &Path, params: &OutOfCoreParams) -> Result<OutOfCoreResult> {
    let t0 = Instant::now();
    let mut reader = PointReader::open(input)?;
    let total = reader.count();
    if total == 0 {
        return Err(Error::invalid_mesh(input, "the point set is empty"));
    }
    let had_normals = reader.has_normals();
    let buckets = total.div_ceil(params.bucket_points.max(1) as u64).max(1) as usize;
    let dir = tempfile::Builder::new()
        .prefix("remesh-buckets")
        .tempdir_in(params.temp_dir.clone().unwrap_or_else(std::env::temp_dir))
        .map_err(|e| Error::io(input, e))?;
    let io_err = |e: std::io::Error| Error::io(dir.path(), e);
    let mut writers: Vec<BufWriter<File>> = (0..buckets)
        .map(|b| {
            File::create(dir.path().join(format!("{b}.bin")))
                .map(|f| BufWriter::with_capacity(1 << 20, f))
        })
        .collect::<std::io::Result<_>>()
        .map_err(io_err)?;
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    let mut chunk = Vec::new();
    let mut staged: Vec<Vec<u8>> = vec![Vec::new(); buckets];
    while reader.read_chunk(&mut chunk, 1 << 16)? > 0 {
        for p in &chunk {
            lo = lo.min(p.position);
            hi = hi.max(p.position);
            encode_record(p, &mut staged[rng.random_range(0..buckets)]);
        }
        for (w, bytes) in writers.iter_mut().zip(staged.iter_mut()) {
            w.write_all(bytes).map_err(io_err)?;
            bytes.clear();
        }
    }
    for w in &mut writers {
        w.flush().map_err(io_err)?;
    }
    drop(writers);
    let normalization = Normalization::for_bbox(&Aabb { min: lo, max: hi })
        .ok_or_else(|| Error::invalid_mesh(input, "the points' bounding box has no extent"))?;
    let t1 = Instant::now();

    let load = |b: usize, rng: &mut ChaCha8Rng| -> Result<Vec<Point>> {
        let mut bytes = Vec::new();
        File::open(dir.path().join(format!("{b}.bin")))
            .and_then(|f| BufReader::new(f).read_to_end(&mut bytes))
            .map_err(io_err)?;
        let mut pts: Vec<Point> = bytes
            .chunks_exact(RECORD_BYTES)
            .map(|r| {
                let p = decode(r);
                Point {
                    position: normalization.apply(p.position),
                    normal: p.normal,
                }
            })
            .collect();
        pts.shuffle(rng);
        Ok(pts)
    };

    // sigma_p: given, or searched on the first buckets: enough of them for SEARCH_POINTS_PER_SAMPLE
    // input points per wanted sample (a sparser subset leaves gaps the full scan fills).
    let search_buckets = match params.target {
        None => 1,
        Some(n) => ((SEARCH_POINTS_PER_SAMPLE * n as f64 / params.bucket_points.max(1) as f64)
            .ceil() as usize)
            .clamp(1, buckets),
    };
    let mut first: Option<Vec<Point>> = None;
    for b in 0..search_buckets {
        let pts = load(b, &mut rng)?;
        first.get_or_insert_with(Vec::new).extend(pts);
    }

    // The scanner that has seen the first buckets: the search's best evaluation, or a fresh scan.
    let first = first.unwrap_or_default();
    let batch: Vec<(DVec3, DVec3)> = first.iter().map(|p| (p.position, p.normal)).collect();
    let scan_first = |sigma_p: f64| -> Result<(LinearScanner, Vec<usize>)> {
        let kernel = Kernel::new(sigma_p, params.sigma_n)?;
        let mut scanner = LinearScanner::new(&kernel, &params.scan);
        let mut accepted = Vec::new();
        scanner.offer_batch(&batch, &mut accepted);
        Ok((scanner, accepted))
    };
    let (sigma_p, (mut scanner, first_accepted)) = match params.target {
        None => (params.sigma_p, scan_first(params.sigma_p)?),
        Some(n) => {
            let area_guess = surface_area_guess(&first);
            let start = (area_guess / n.max(1) as f64).sqrt();
            // The subset's count is itself about 5% below the full scan's: 2% is precise enough.
            let search = TargetCountParams {
                tolerance: 0.02,
                ..TargetCountParams::new(n)
            };
            let mut failure = None;
            let r = find_sigma_p(&search, start, |s| match scan_first(s) {
                Ok(v) => (v.0.len(), Some(v)),
                Err(e) => {
                    failure = Some(e);
                    (0, None)
                }
            });
            match (failure, r.value) {
                (Some(e), _) => return Err(e),
                (None, Some(v)) => (r.sigma_p, v),
                (None, None) => (r.sigma_p, scan_first(r.sigma_p)?),
            }
        }
    };
    let t2 = Instant::now();

    let to_model = |p: &Point| Point {
        position: normalization.invert(p.position),
        normal: p.normal,
    };
    let mut samples: Vec<Point> = first_accepted
        .iter()
        .map(|&i| to_model(&first[i]))
        .collect();
    drop(batch);
    drop(first);
    let mut accepted = Vec::new();
    for b in search_buckets..buckets {
        let pts = load(b, &mut rng)?;
        let batch: Vec<(DVec3, DVec3)> = pts.iter().map(|p| (p.position, p.normal)).collect();
        accepted.clear();
        scanner.offer_batch(&batch, &mut accepted);
        samples.extend(accepted.iter().map(|&i| to_model(&pts[i])));
    }
    let t3 = Instant::now();
    Ok(OutOfCoreResult {
        samples,
        input_points: total,
        had_normals,
        sigma_p,
        normalization,
        rejected_by_nearest: scanner.rejected_by_nearest,
        measured: scanner.measured,
        seconds: [
            (t1 - t0).as_secs_f64(),
            (t2 - t1).as_secs_f64(),
            (t3 - t2).as_secs_f64(),
        ],
    })
}

/// A first guess of the surface area (bbox-100 units²) of a uniformly random point subset, for
/// the start of the sigma_p search: the number of occupied cells of a grid of cell size h, times
/// h² / 1.5 (a plane of area A with unit normal n crosses about A (|n_x| + |n_y| + |n_z|) / h²
/// cells, 1.5 A / h² on average over orientations).
fn surface_area_guess(points: &[Point]) -> f64 {
    let h = 2.0;
    let mut cells: Vec<[i32; 3]> = points
        .iter()
        .map(|p| (p.position / h).floor().as_ivec3().to_array())
        .collect();
    cells.sort_unstable();
    cells.dedup();
    (cells.len() as f64 * h * h / 1.5).max(1.0)
}
