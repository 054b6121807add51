//! The input point set shuffled into random bucket files (pass 1 of the out-of-core linear
//! scan, Sec. 6.1): its bounding box and far isolated points found on the way, every point
//! written to a bucket chosen at random, so that each bucket is a uniform random subset.

use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::Path;

use glam::DVec3;
use rand::seq::SliceRandom;
use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use super::outliers::{far_isolated, flagged};
use super::source::PointSource;
use super::stream::{decode_record, encode_record, Point, RECORD_BYTES};
use crate::error::{Error, Result};
use crate::io::temporaries::temporary_error;
use crate::mesh::{Aabb, Normalization};

/// Bucket `b`'s points in `dir` as written (model units, in file order), the first `limit`.
fn read_bucket(dir: &Path, b: usize, limit: usize) -> Result<Vec<Point>> {
    let mut bytes = Vec::new();
    let most = limit.saturating_mul(RECORD_BYTES) as u64;
    File::open(dir.join(format!("{b}.bin")))
        .and_then(|f| BufReader::new(f).take(most).read_to_end(&mut bytes))
        .map_err(|e| temporary_error(dir, "the points' bucket files", true, e))?;
    Ok(bytes
        .chunks_exact(RECORD_BYTES)
        .map(decode_record)
        .collect())
}

/// Points of the first bucket the far-isolation test compares with (see [`far_isolated`]).
const FAR_REFERENCE_POINTS: usize = 1 << 16;

/// The most bucket files of one run: open files and their write buffers are bounded whatever
/// the input's size (512 files of 2^20 points hold 2^29 points; larger inputs get larger buckets).
const MAX_BUCKETS: u64 = 512;

/// The input, bucket-shuffled into temporary files (pass 1 of [`simplify_out_of_core`](super::out_of_core::simplify_out_of_core)).
pub(crate) struct Buckets {
    pub(crate) dir: tempfile::TempDir,
    /// The folder on the list an interrupted run removes.
    pub(crate) _registered: crate::io::temporaries::Registered,
    /// Number of bucket files.
    pub(crate) count: usize,
    /// Points kept (read, less the far isolated ones).
    pub(crate) total: u64,
    pub(crate) had_normals: bool,
    pub(crate) normalization: Normalization,
    /// The box (model units) of the points kept, when far isolated points were left out
    /// ([`far_isolated`]): points outside it are not loaded.
    pub(crate) keep: Option<Aabb>,
    /// Far isolated points left out.
    pub(crate) far_points: u64,
}

/// Points with the most extreme coordinate along each of the six axis directions, the most
/// extreme first: the candidates of [`far_isolated`].
struct Extremes {
    lists: [Vec<(f64, DVec3)>; 6],
}

impl Extremes {
    /// How many points each direction keeps.
    const PER_DIRECTION: usize = 16;

    fn new() -> Self {
        Extremes {
            lists: Default::default(),
        }
    }

    fn offer(&mut self, p: DVec3) {
        for (d, list) in self.lists.iter_mut().enumerate() {
            let v = if d % 2 == 0 { p[d / 2] } else { -p[d / 2] };
            if list.len() < Self::PER_DIRECTION || list.last().is_some_and(|&(w, _)| v > w) {
                let at = list.partition_point(|&(w, _)| w >= v);
                list.insert(at, (v, p));
                list.truncate(Self::PER_DIRECTION);
            }
        }
    }

    /// The box of the points without those `far` says are far isolated: on each side, the
    /// most extreme candidate that is not far. `None` when no candidate is far, or when every
    /// candidate of some direction is (too many far points to tell the box).
    fn box_without(&self, far: impl Fn(DVec3) -> bool) -> Option<Aabb> {
        let mut any = false;
        let mut bound = [0.0f64; 6];
        for (d, list) in self.lists.iter().enumerate() {
            any |= list.iter().any(|&(_, p)| far(p));
            let &(v, _) = list.iter().find(|&&(_, p)| !far(p))?;
            bound[d] = if d % 2 == 0 { v } else { -v };
        }
        any.then(|| Aabb {
            min: DVec3::new(bound[1], bound[3], bound[5]),
            max: DVec3::new(bound[0], bound[2], bound[4]),
        })
    }
}

/// Far isolated points are looked for in point sets of at least this many points (in a
/// handful of points every point is far from the others).
const FAR_MIN_POINTS: u64 = 1000;

impl Buckets {
    /// Streams `source` once: its bounding box, and every point to a random bucket file.
    pub(crate) fn write(
        source: &PointSource,
        bucket_points: usize,
        temp_dir: Option<&Path>,
        rng: &mut ChaCha8Rng,
    ) -> Result<Buckets> {
        let input = source.name();
        let mut reader = source.open()?;
        let total = reader.count();
        if total == 0 {
            return Err(Error::invalid_mesh(input, "the point set is empty"));
        }
        let had_normals = reader.has_normals();
        // At most MAX_BUCKETS files open at once (beyond 2^29 points the buckets grow instead).
        let count = total
            .div_ceil(bucket_points.max(1) as u64)
            .clamp(1, MAX_BUCKETS) as usize;
        // Where the buckets cannot go is the environment's fault: an output error naming the
        // temporary directory (`TMPDIR`), not the input.
        let tmpdir = temp_dir.map_or_else(std::env::temp_dir, Path::to_path_buf);
        let dir = tempfile::Builder::new()
            .prefix("remesh-buckets")
            .tempdir_in(&tmpdir)
            .map_err(|e| {
                temporary_error(&tmpdir, "the points' bucket folder", temp_dir.is_none(), e)
            })?;
        // On the list from the start: an interrupt while bucketing removes it too.
        let registered = crate::io::temporaries::register(dir.path());
        let io_err = |e: std::io::Error| {
            temporary_error(
                dir.path(),
                "the points' bucket files",
                temp_dir.is_none(),
                e,
            )
        };
        let mut writers: Vec<BufWriter<File>> = (0..count)
            .map(|b| {
                File::create(dir.path().join(format!("{b}.bin")))
                    .map(|f| BufWriter::with_capacity(1 << 16, f))
            })
            .collect::<std::io::Result<_>>()
            .map_err(io_err)?;
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        let mut extremes = Extremes::new();
        let mut chunk = Vec::new();
        let mut staged: Vec<Vec<u8>> = vec![Vec::new(); count];
        while reader.read_chunk(&mut chunk, 1 << 16)? > 0 {
            for p in &chunk {
                lo = lo.min(p.position);
                hi = hi.max(p.position);
                extremes.offer(p.position);
                encode_record(p, &mut staged[rng.random_range(0..count)]);
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
        // Far isolated points (a stray `0 0 0` in a scan at UTM coordinates) do not set the
        // scale: they are left out, judged against a random subset of the points (the first
        // bucket's).
        let mut keep = None;
        let mut far_points = 0;
        if total >= FAR_MIN_POINTS {
            let reference: Vec<DVec3> = read_bucket(dir.path(), 0, FAR_REFERENCE_POINTS)?
                .into_iter()
                .map(|p| p.position)
                .collect();
            let candidates: Vec<DVec3> = extremes.lists.iter().flatten().map(|&(_, p)| p).collect();
            let far_set = flagged(&candidates, &far_isolated(&candidates, &reference));
            keep = extremes.box_without(|p| far_set.contains(&p.to_array().map(f64::to_bits)));
            if let Some(b) = keep {
                for k in 0..count {
                    far_points += read_bucket(dir.path(), k, usize::MAX)?
                        .iter()
                        .filter(|p| !b.contains(p.position))
                        .count() as u64;
                }
            }
        }
        let bbox = keep.unwrap_or(Aabb { min: lo, max: hi });
        let normalization = Normalization::for_bbox(&bbox).ok_or_else(|| {
            Error::invalid_mesh(
                input,
                Normalization::refusal(&bbox).replacen(
                    "the bounding box",
                    "the points' bounding box",
                    1,
                ),
            )
        })?;
        Ok(Buckets {
            _registered: registered,
            dir,
            count,
            total: total - far_points,
            had_normals,
            normalization,
            keep,
            far_points,
        })
    }

    /// Calls `f` with each bucket's points in turn (bbox-100 units, shuffled), loading the next
    /// bucket on another thread meanwhile. The shuffles draw from `rng` in bucket order.
    pub(crate) fn for_each(
        &self,
        rng: &mut ChaCha8Rng,
        mut f: impl FnMut(Vec<Point>),
    ) -> Result<()> {
        std::thread::scope(|scope| {
            let spawn = |b: usize, mut r: ChaCha8Rng| {
                scope.spawn(move || {
                    let pts = self.load(b, &mut r);
                    (pts, r)
                })
            };
            let mut next = Some(spawn(0, rng.clone()));
            let mut b = 0;
            while let Some(loader) = next.take() {
                let (pts, r) = loader.join().map_err(|_| {
                    Error::io(
                        self.dir.path(),
                        std::io::Error::other("a bucket loader panicked"),
                    )
                })?;
                *rng = r;
                let pts = pts?;
                b += 1;
                if b < self.count {
                    next = Some(spawn(b, rng.clone()));
                }
                f(pts);
            }
            Ok(())
        })
    }

    /// Bucket `b`'s points in bbox-100 units, shuffled.
    pub(crate) fn load(&self, b: usize, rng: &mut ChaCha8Rng) -> Result<Vec<Point>> {
        let mut pts: Vec<Point> = read_bucket(self.dir.path(), b, usize::MAX)?
            .into_iter()
            .filter(|p| self.keep.is_none_or(|k| k.contains(p.position)))
            .map(|p| Point {
                position: self.normalization.apply(p.position),
                normal: p.normal,
            })
            .collect();
        pts.shuffle(rng);
        Ok(pts)
    }
}
