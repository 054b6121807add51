//! The input point set shuffled into random bucket files (pass 1 of the out-of-core linear
//! scan, Sec. 6.1): every point written to a bucket chosen by a seeded hash of its position,
//! so that each bucket is a uniform random subset and coincident points share a bucket; then
//! each bucket once more, merging coincident points and leaving out far groups
//! ([`far_groups`]), which also gives the bounding box of what is kept.

use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::Path;

use glam::DVec3;
use rand::seq::SliceRandom;
use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use super::far_groups::{far_groups, separate_parts, FarGroups, SeparateParts};
use super::source::PointSource;
use super::stream::{decode_record, encode_record, Point, RECORD_BYTES};
use crate::error::{Error, Result};
use crate::io::temporaries::temporary_error;
use crate::mesh::{Aabb, Normalization};
use std::sync::Arc;

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

/// Points of the first bucket the far-group test groups (see [`far_groups`]).
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
    /// Points kept (read, less the coincident and the far ones).
    pub(crate) total: u64,
    pub(crate) had_normals: bool,
    pub(crate) normalization: Normalization,
    /// Points of far groups left out ([`far_groups`]).
    pub(crate) far_points: u64,
    /// Points merged into another at the same position (bit for bit; the first read is kept).
    pub(crate) duplicate_points: u64,
    /// What is kept when far groups were left out.
    pub(crate) far_groups: Option<FarGroups>,
}

/// Points with the most extreme coordinate along each of the six axis directions, the most
/// extreme first: grouped by [`far_groups`] with a random subset, since a far group is where
/// the box is decided.
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
}

/// A point's position as bits (-0 as +0): coincident points have equal keys.
fn position_key(p: DVec3) -> [u64; 3] {
    (p + DVec3::ZERO).to_array().map(f64::to_bits)
}

/// A seeded hash of a point's position (coincident points hash alike; splitmix64's mixer).
fn position_hash(p: DVec3, salt: u64) -> u64 {
    let mix = |mut z: u64| {
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    };
    position_key(p)
        .iter()
        .fold(salt, |h, &k| mix(h.wrapping_add(0x9e37_79b9_7f4a_7c15) ^ k))
}

/// What [`Buckets::write`] made of a point set.
pub(crate) enum Bucketed {
    /// The points, bucketed.
    Buckets(Buckets),
    /// Parts far apart compared with their sizes, which one scale cannot hold: nothing is
    /// bucketed.
    Parts(Arc<SeparateParts>),
}

impl Bucketed {
    /// The buckets, or the parts' refusal naming `source` for a caller that does not mesh each
    /// part on its own.
    pub(crate) fn or_refuse(self, source: &Path) -> Result<Buckets> {
        match self {
            Bucketed::Buckets(b) => Ok(b),
            Bucketed::Parts(parts) => Err(Error::invalid_mesh(source, parts.refusal())),
        }
    }
}

/// Far groups are looked for in point sets of at least this many points (in a handful of
/// points every point is far from the others).
const FAR_MIN_POINTS: u64 = 1000;

impl Buckets {
    /// Streams `source` once: its bounding box, and every point to a random bucket file; or,
    /// when the points are parts far apart ([`separate_parts`]), those parts.
    pub(crate) fn write(
        source: &PointSource,
        bucket_points: usize,
        temp_dir: Option<&Path>,
        rng: &mut ChaCha8Rng,
    ) -> Result<Bucketed> {
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
        let mut extremes = Extremes::new();
        let mut chunk = Vec::new();
        let mut staged: Vec<Vec<u8>> = vec![Vec::new(); count];
        // The bucket of a point: a hash of its position salted by the seed (a uniformly
        // random subset per bucket; coincident points in the same one).
        let salt: u64 = rng.random();
        while reader.read_chunk(&mut chunk, 1 << 16)? > 0 {
            for p in &chunk {
                extremes.offer(p.position);
                let b = (position_hash(p.position, salt) % count as u64) as usize;
                encode_record(p, &mut staged[b]);
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
        // Far groups (a stray `0 0 0`, or a small cluster, in a scan at UTM coordinates) do
        // not set the scale: they are left out, judged on a random subset of the points (the
        // first bucket's) and the most extreme ones.
        let mut far = None;
        if total >= FAR_MIN_POINTS {
            let mut grouped: Vec<DVec3> = read_bucket(dir.path(), 0, FAR_REFERENCE_POINTS)?
                .into_iter()
                .map(|p| p.position)
                .collect();
            grouped.extend(extremes.lists.iter().flatten().map(|&(_, p)| p));
            grouped.sort_unstable_by_key(|p| position_key(*p));
            grouped.dedup_by_key(|p| position_key(*p));
            far = far_groups(&grouped);
            // Parts far apart compared with their own size (two objects 10^6 apart, each 10
            // across) cannot share one scale: the caller meshes each on its own, or refuses.
            if let Some(parts) = separate_parts(&grouped, far.as_ref()) {
                return Ok(Bucketed::Parts(Arc::new(parts)));
            }
        }
        // Each bucket again: coincident points merged, far groups left out (the bucket file
        // rewritten when that changed it), the box of what is kept.
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        let (mut far_points, mut duplicate_points) = (0u64, 0u64);
        for b in 0..count {
            let mut pts = read_bucket(dir.path(), b, usize::MAX)?;
            let read = pts.len();
            let mut order: Vec<u32> = (0..read as u32).collect();
            order.sort_unstable_by_key(|&i| (position_key(pts[i as usize].position), i));
            let mut keep = vec![true; read];
            for w in order.windows(2) {
                if position_key(pts[w[0] as usize].position)
                    == position_key(pts[w[1] as usize].position)
                {
                    keep[w[1] as usize] = false;
                }
            }
            let unique = keep.iter().filter(|&&k| k).count();
            duplicate_points += (read - unique) as u64;
            let mut flags = keep.into_iter();
            pts.retain(|_| flags.next().unwrap_or(false));
            if let Some(f) = &far {
                pts.retain(|p| f.contains(p.position));
                far_points += (unique - pts.len()) as u64;
            }
            for p in &pts {
                lo = lo.min(p.position);
                hi = hi.max(p.position);
            }
            if pts.len() < read {
                let mut bytes = Vec::with_capacity(pts.len() * RECORD_BYTES);
                for p in &pts {
                    encode_record(p, &mut bytes);
                }
                std::fs::write(dir.path().join(format!("{b}.bin")), bytes).map_err(io_err)?;
            }
        }
        let bbox = Aabb { min: lo, max: hi };
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
        Ok(Bucketed::Buckets(Buckets {
            _registered: registered,
            dir,
            count,
            total: total - far_points - duplicate_points,
            had_normals,
            normalization,
            far_points,
            duplicate_points,
            far_groups: far,
        }))
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
            .map(|p| Point {
                position: self.normalization.apply(p.position),
                normal: p.normal,
            })
            .collect();
        pts.shuffle(rng);
        Ok(pts)
    }
}
