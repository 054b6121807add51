//! Out-of-core simplification of a point set by the randomized linear scan (Sec. 6.1,
//! Algorithm 1): memory bounded by the output set plus a fixed buffer, not by the input.
//!
//! The two passes are described on [`simplify_out_of_core`].

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::DVec3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::buckets::{Bucketed, Buckets};
use super::far_groups::{FarGroups, SeparateParts};
use super::normals::{estimate_normals, NormalOrientation};
use super::outliers::{off_surface, OutlierFilter};
use super::rimls::{Rimls, RimlsParams};
use super::source::PointSource;
use super::stream::Point;
use crate::error::{Error, Result};
use crate::kernel::Kernel;
use crate::mesh::Normalization;
use crate::sampling::gradient_ascent::{gradient_ascent, GradientAscentParams};
use crate::sampling::linear_scan::{LinearScanParams, LinearScanner};
use crate::sampling::sizing::Uniform;
use crate::sampling::target_count::{find_sigma_p, TargetCountParams};
use crate::surface::SurfaceSample;

/// Parameters of [`simplify_out_of_core`].
#[derive(Debug, Clone, PartialEq)]
pub struct OutOfCoreParams {
    /// The output density: `Some(n)` searches sigma_p for about n samples.
    pub target: Option<usize>,
    /// sigma_p in bbox-100 units, used when `target` and `edge_length` are `None`.
    pub sigma_p: f64,
    /// Output edges about this long, in model units, when `target` is `None`: sigma_p is that
    /// length in bbox-100 units (the points' bounding box, known once they are read) over the
    /// mean edge a point set's sampling gives per sigma_p (1.2:
    /// `sampling::spacing::POINT_SET_EDGE_PER_SIGMA`).
    pub edge_length: Option<f64>,
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
    /// Gradient-ascent sweeps after the scan (Sec. 6.2), each move projected onto the RIMLS
    /// surface of the input (default 0: none; see [`simplify_out_of_core`]).
    pub resample: usize,
    /// How normals estimated for an input without them are oriented.
    pub orientation: NormalOrientation,
}

impl Default for OutOfCoreParams {
    fn default() -> Self {
        OutOfCoreParams {
            target: None,
            sigma_p: 1.0,
            edge_length: None,
            sigma_n: f64::INFINITY,
            scan: LinearScanParams::default(),
            bucket_points: 1 << 20,
            seed: 1,
            temp_dir: None,
            resample: 0,
            orientation: NormalOrientation::SpanningTree,
        }
    }
}

/// The result of [`simplify_out_of_core`].
#[derive(Debug, Clone)]
pub struct OutOfCoreResult {
    /// The output set O in the input's units, in the order the scan accepted it.
    pub samples: Vec<Point>,
    /// Points read, less the coincident and the far ones.
    pub input_points: u64,
    /// Points of far groups left out (`points::far_groups`): they would have set the scale.
    pub far_points: u64,
    /// Points merged into another at the same position.
    pub duplicate_points: u64,
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
    /// Seconds: reading and bucketing, the sigma_p search, the scan, and the normals and
    /// resampling after it.
    pub seconds: [f64; 4],
}

/// Simplifies the point set in the file `input` (PLY or XYZ/CSV, see
/// [`PointReader`](crate::internal::PointReader)) out of core: memory bounded by the output set
/// plus a fixed buffer, not by the input. Peak memory: the output set, two buckets, and a 1 MiB
/// write buffer per bucket.
///
/// Two passes over the data:
/// 1. The input is streamed once: its bounding box is taken (for the bbox-100 frame of Sec. 7) and
///    every point goes to one of `B` temporary bucket files chosen at random (a bucket shuffle: the
///    visit order is random without the input ever being in memory).
/// 2. Each bucket in turn is loaded (about `bucket_points` points), shuffled, and streamed through
///    the linear scan, whose output set O lives in one dynamic kd-tree.
///
/// With `--points N` the sigma_p is found first on the first bucket alone: a uniformly random
/// subset as dense as the output needs gives the same count (the count depends on sigma_p and the
/// surface, not on the input's density).
///
/// The samples always have unit normals: for an input without them, normals are estimated on the
/// output (PCA over 10 neighbours, oriented by `params.orientation`). With `params.resample = K >
/// 0` the samples then move by K sweeps of gradient ascent on the spectral measure (Sec. 6.2), each
/// move projected onto the RIMLS surface (same sigma_p and sigma_n) of the samples and the first
/// bucket's points, a uniformly random subset of the input, so memory stays bounded by a bucket (up
/// to 3 of its points per sample are used, see `RIMLS_POINTS_PER_SAMPLE`). Their normals are then
/// the RIMLS surface's.
///
/// # Errors
/// Errors of the PLY reader (naming the file); [`Error::InvalidMesh`] for an empty input or one
/// whose bounding box has no extent; [`Error::Io`] when the temporary files fail.
pub fn simplify_out_of_core(input: &Path, params: &OutOfCoreParams) -> Result<OutOfCoreResult> {
    let t0 = Instant::now();
    let support_per_sample = if params.resample > 0 {
        RIMLS_POINTS_PER_SAMPLE - 1
    } else {
        0
    };
    let source = PointSource::File(input.to_path_buf());
    let scan = scan_out_of_core(&source, params, false, support_per_sample)?;
    let t3 = Instant::now();
    let ScanOutput {
        mut samples,
        support,
        input_points,
        far_points,
        duplicate_points,
        had_normals,
        sigma_p,
        normalization,
        rejected_by_nearest,
        measured,
        seconds: [read, search, _],
        ..
    } = scan;
    let kernel = Kernel::new(sigma_p, params.sigma_n)?;
    // The samples are in the bbox-100 frame here, a viewpoint in model units.
    let params = &OutOfCoreParams {
        orientation: params.orientation.in_frame(&normalization),
        ..params.clone()
    };
    if params.resample > 0 {
        resample_on_rimls(&kernel, &mut samples, support, had_normals, params)?;
    } else if !had_normals {
        estimate_sample_normals(&mut samples, params.orientation);
    }
    for p in &mut samples {
        p.position = normalization.invert(p.position);
    }
    let t4 = Instant::now();
    Ok(OutOfCoreResult {
        samples,
        input_points,
        far_points,
        duplicate_points,
        had_normals,
        sigma_p,
        normalization,
        rejected_by_nearest,
        measured,
        seconds: [
            read,
            search,
            (t3 - t0).as_secs_f64() - read - search,
            (t4 - t3).as_secs_f64(),
        ],
    })
}

/// The out-of-core linear scan of [`simplify_out_of_core`] (its passes 1 and 2), before normals
/// and resampling, in bbox-100 units.
pub(crate) struct ScanOutput {
    /// The output set O, bbox-100 units, in the order the scan accepted it; normals as read
    /// (zero without them).
    pub samples: Vec<Point>,
    /// The first bucket's points, shuffled (a uniformly random subset of the input), up to
    /// `support_per_sample` per sample, bbox-100 units.
    pub support: Vec<Point>,
    /// Points read, less the coincident and the far ones.
    pub input_points: u64,
    /// Points of far groups left out (`points::far_groups`).
    pub far_points: u64,
    /// Points merged into another at the same position.
    pub duplicate_points: u64,
    /// What is kept when far groups were left out (for measuring against the points kept).
    pub far_groups: Option<FarGroups>,
    /// Whether the input had normals.
    pub had_normals: bool,
    /// The sigma_p used, bbox-100 units.
    pub sigma_p: f64,
    /// Model units ↔ bbox-100 units.
    pub normalization: Normalization,
    /// Candidates rejected by their nearest output sample alone, and measured with eq. 10.
    pub rejected_by_nearest: usize,
    /// Candidates whose measure was evaluated.
    pub measured: usize,
    /// Outliers ([`OutlierFilter`]) dropped from the samples and the support.
    pub outliers_removed: usize,
    /// Seconds: reading and bucketing, the sigma_p search (and the outlier filter), the scan.
    pub seconds: [f64; 3],
}

/// Passes 1 and 2 of [`simplify_out_of_core`] ([`ScannedInput::open`] and
/// [`ScannedInput::scan`] at the sigma_p found or given).
pub(crate) fn scan_out_of_core(
    input: &PointSource,
    params: &OutOfCoreParams,
    drop_outliers: bool,
    support_per_sample: usize,
) -> Result<ScanOutput> {
    let mut source = match ScannedInput::open(input, params, drop_outliers)? {
        Opened::Input(s) => *s,
        Opened::Parts(parts) => return Err(Error::invalid_mesh(input.name(), parts.refusal())),
    };
    let sigma_p = source.sigma_p;
    let mut out = source.scan(sigma_p, support_per_sample)?;
    // The search ran on a subset, and a scan's count wobbles with its random order (about 2% at
    // 200 samples): while the count misses by more than COUNT_TOLERANCE, the scan runs again at
    // the mean of the sigma_p each scan so far points to (sigma_p · sqrt(count / N): the count
    // goes as sigma_p^-2), keeping the closest.
    if let Some(n) = params.target {
        let n = n as f64;
        let miss = |o: &ScanOutput| (o.samples.len() as f64 - n).abs();
        let mut aims = Vec::new();
        let mut last = (out.sigma_p, out.samples.len());
        for _ in 1..MAX_SCANS {
            if miss(&out) <= COUNT_TOLERANCE * n || last.1 == 0 {
                break;
            }
            aims.push(last.0 * (last.1 as f64 / n).sqrt());
            let s = aims.iter().sum::<f64>() / aims.len() as f64;
            let again = source.scan(s, support_per_sample)?;
            last = (s, again.samples.len());
            if miss(&again) < miss(&out) {
                out = again;
            }
        }
    }
    Ok(out)
}

/// The relative miss of `--points N` past which the scan runs again (the README's promise).
const COUNT_TOLERANCE: f64 = 0.02;

/// Scans of the input at most for one count (see [`scan_out_of_core`]).
const MAX_SCANS: usize = 4;

/// A point set bucketed for out-of-core linear scans (pass 1 of [`simplify_out_of_core`]), with
/// its sigma_p for the target count, ready to be scanned (pass 2) at any sigma_p, more than once.
pub(crate) struct ScannedInput {
    buckets: Buckets,
    rng: ChaCha8Rng,
    params: OutOfCoreParams,
    filter: Option<OutlierFilter>,
    /// The sigma_p for `params.target` (bbox-100 units), or `params.sigma_p`.
    pub sigma_p: f64,
    /// Seconds: reading and bucketing; the sigma_p search and the outlier filter.
    seconds: [f64; 2],
}

/// What [`ScannedInput::open`] made of a point set.
pub(crate) enum Opened {
    /// The input, ready to be scanned.
    Input(Box<ScannedInput>),
    /// Parts far apart compared with their sizes: each is to be meshed on its own.
    Parts(std::sync::Arc<SeparateParts>),
}

impl ScannedInput {
    /// Pass 1 and the sigma_p search; or the parts far apart the points form (see
    /// [`Bucketed::Parts`]), nothing scanned. With `drop_outliers`, an [`OutlierFilter`] of the first
    /// bucket's points removes outliers from the sigma_p search's subset, and later from each
    /// scan's samples and support (so isolated points neither raise the count the search sees
    /// nor become samples).
    pub(crate) fn open(
        input: &PointSource,
        params: &OutOfCoreParams,
        drop_outliers: bool,
    ) -> Result<Opened> {
        let t0 = Instant::now();
        let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
        let buckets = match Buckets::write(
            input,
            params.bucket_points,
            params.temp_dir.as_deref(),
            &mut rng,
        )? {
            Bucketed::Buckets(b) => b,
            Bucketed::Parts(parts) => return Ok(Opened::Parts(parts)),
        };
        let t1 = Instant::now();
        // sigma_p: given (as itself or as an edge length in model units), or searched on a
        // scaled-down problem (see `search_sigma_p`).
        let given = params.edge_length.map_or(params.sigma_p, |l| {
            l * buckets.normalization.scale / crate::sampling::spacing::POINT_SET_EDGE_PER_SIGMA
        });
        let mut filter = None;
        let sigma_p = if params.target.is_none() && !drop_outliers {
            given
        } else {
            let mut first = buckets.load(0, &mut rng)?;
            if drop_outliers {
                // The filter's reference: a random subset of the first bucket (already shuffled).
                let reference: Vec<DVec3> = first
                    .iter()
                    .take(FILTER_REFERENCE_POINTS)
                    .map(|p| p.position)
                    .collect();
                let f = OutlierFilter::new(&reference);
                if let Some(n) = params.target {
                    first.truncate(search_subset_len(first.len(), buckets.total, n));
                }
                f.retain(&mut first, |p| p.position);
                filter = Some(f);
            }
            match params.target {
                None => given,
                Some(n) => search_sigma_p(&first, buckets.total, n, params)?,
            }
        };
        let t2 = Instant::now();
        Ok(Opened::Input(Box::new(ScannedInput {
            buckets,
            rng,
            params: params.clone(),
            filter,
            sigma_p,
            seconds: [(t1 - t0).as_secs_f64(), (t2 - t1).as_secs_f64()],
        })))
    }

    /// Pass 2 at `sigma_p` (bbox-100 units), keeping up to `support_per_sample` points per
    /// sample as the support: the first bucket's first points that are not outliers. A scan
    /// after the first draws other shuffles.
    pub(crate) fn scan(&mut self, sigma_p: f64, support_per_sample: usize) -> Result<ScanOutput> {
        let t2 = Instant::now();
        let params = &self.params;
        let kernel = Kernel::new(sigma_p, params.sigma_n)?;
        let mut scanner = LinearScanner::new(&kernel, &params.scan);
        // The samples in bbox-100 units, and the first bucket when asked for.
        let mut samples: Vec<Point> = Vec::new();
        let mut support: Vec<Point> = Vec::new();
        let mut accepted = Vec::new();
        self.buckets.for_each(&mut self.rng, |pts| {
            let batch: Vec<(DVec3, DVec3)> = pts.iter().map(|p| (p.position, p.normal)).collect();
            accepted.clear();
            scanner.offer_batch(&batch, &mut accepted);
            samples.extend(accepted.iter().map(|&i| pts[i]));
            if support_per_sample > 0 && support.is_empty() {
                support = pts;
            }
        })?;
        let mut outliers_removed = self.buckets.far_points as usize;
        if let Some(f) = &self.filter {
            outliers_removed += f.retain(&mut samples, |p| p.position);
        }
        // The first points of the bucket that are not outliers: the support is as dense as asked
        // for whenever the data has that many points (filtering after truncating would leave it
        // thinner by the outliers' share, and read as sparse data).
        let want = support_per_sample.saturating_mul(samples.len());
        match &self.filter {
            Some(f) => outliers_removed += f.retain_first(&mut support, want, |p| p.position),
            None => support.truncate(want),
        }
        let t3 = Instant::now();
        Ok(ScanOutput {
            samples,
            support,
            input_points: self.buckets.total,
            far_points: self.buckets.far_points,
            duplicate_points: self.buckets.duplicate_points,
            far_groups: self.buckets.far_groups.clone(),
            had_normals: self.buckets.had_normals,
            sigma_p,
            normalization: self.buckets.normalization,
            rejected_by_nearest: scanner.rejected_by_nearest,
            measured: scanner.measured,
            outliers_removed,
            seconds: [self.seconds[0], self.seconds[1], (t3 - t2).as_secs_f64()],
        })
    }
}

/// PCA normals for points without them (10 neighbours), oriented by `orientation`.
fn estimate_sample_normals(points: &mut [Point], orientation: NormalOrientation) {
    let positions: Vec<DVec3> = points.iter().map(|p| p.position).collect();
    for (p, n) in points
        .iter_mut()
        .zip(estimate_normals(&positions, 10, orientation))
    {
        p.normal = n;
    }
}

/// What was mended of a file's normals before the RIMLS surface was fitted to them
/// ([`rimls_of`]), among the surface's support points.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct NormalRepairs {
    /// Normals missing (NaN or zero) that were fitted from the points near them.
    pub filled: usize,
    /// Normals turned because the file's were not consistently oriented.
    pub turned: usize,
}

/// Points per sample in the point set whose RIMLS surface the resampling projects onto: the
/// samples and a random subset of the input, measured against 1 and 2 per sample and against the
/// whole input (see `docs/decisions/simplify-resample.md`).
const RIMLS_POINTS_PER_SAMPLE: usize = 4;

/// Gradient-ascent resampling of `samples` (bbox-100 units) projected onto the RIMLS surface of
/// the samples and part of `support` (see [`simplify_out_of_core`]).
fn resample_on_rimls(
    kernel: &Kernel,
    samples: &mut [Point],
    support: Vec<Point>,
    had_normals: bool,
    params: &OutOfCoreParams,
) -> Result<()> {
    let (rimls, _) = rimls_of(
        RimlsParams::new(kernel.sigma_p(), kernel.sigma_n()),
        samples,
        support,
        RimlsSupport {
            points_per_sample: RIMLS_POINTS_PER_SAMPLE,
            samples_in_support: true,
            sheet_radius: None,
        },
        had_normals,
        params.orientation,
    )?;
    let mut moving: Vec<SurfaceSample> = samples
        .iter()
        .map(|p| SurfaceSample {
            position: p.position,
            normal: p.normal,
            face: 0,
        })
        .collect();
    let ascent = GradientAscentParams {
        iterations: params.resample,
        ..Default::default()
    };
    // Each move's projection gives the surface's normal there (a sample the projection never
    // moved keeps its own).
    gradient_ascent(
        kernel,
        &rimls,
        &mut moving,
        0,
        &Uniform,
        None,
        &ascent,
        params.seed,
    );
    for (p, m) in samples.iter_mut().zip(&moving) {
        p.position = m.position;
        p.normal = m.normal;
    }
    Ok(())
}

/// Which points carry the RIMLS surface of [`rimls_of`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct RimlsSupport {
    /// Points per sample.
    pub points_per_sample: usize,
    /// Whether the samples are among them.
    pub samples_in_support: bool,
    /// Whether the points on no sheet at this radius and those off their neighbours' plane
    /// ([`off_surface`](super::outliers::off_surface)) are left out.
    pub sheet_radius: Option<f64>,
}

/// The RIMLS surface (`params`) of `samples` and the first
/// `(points_per_sample - 1) · samples.len()` points of `support` (a uniformly random subset of
/// the input), bbox-100 units; with `samples_in_support` false, of the first
/// `points_per_sample · samples.len()` points of `support` alone (a sample off the surface, a
/// near outlier, then projects onto the others' surface instead of carrying a bubble of its
/// own); both from `which`. Without input normals (`had_normals` false), normals are estimated
/// on that set (PCA over 10 neighbours, oriented by `orientation`) and given to the samples as
/// well when they are in it. With `sheet_radius` the points on no sheet at that radius and those
/// off their neighbours' plane ([`off_surface`](super::outliers::off_surface)) are left out of
/// the surface (the samples keep their entries).
///
/// With input normals, those missing at some points are fitted there and normals of random
/// signs oriented again (`points::normals::fill_missing_normals`, `orient_given_normals`):
/// the counts are returned with the surface.
///
/// # Errors
/// Those of [`Rimls::new`] (no points, a non-finite position or a zero normal).
pub(crate) fn rimls_of(
    params: RimlsParams,
    samples: &mut [Point],
    support: Vec<Point>,
    which: RimlsSupport,
    had_normals: bool,
    orientation: NormalOrientation,
) -> Result<(Rimls, NormalRepairs)> {
    let RimlsSupport {
        points_per_sample,
        samples_in_support,
        sheet_radius,
    } = which;
    let mut support = support;
    let mut repairs = NormalRepairs::default();
    if samples_in_support {
        support.truncate(points_per_sample.saturating_sub(1) * samples.len());
        support.extend_from_slice(samples);
    } else {
        support.truncate(points_per_sample.saturating_mul(samples.len()));
    }
    if !had_normals {
        estimate_sample_normals(&mut support, orientation);
        if samples_in_support {
            let from = support.len() - samples.len();
            samples.copy_from_slice(&support[from..]);
        }
    } else {
        // A file's normals may be missing at some points (NaN or zero): those are fitted and
        // turned to agree with the given ones near them. And they may be unoriented (random
        // signs): then their signs are set as estimated normals' are.
        let positions: Vec<DVec3> = support.iter().map(|p| p.position).collect();
        let mut normals: Vec<DVec3> = support.iter().map(|p| p.normal).collect();
        repairs.filled = super::normals::fill_missing_normals(&positions, &mut normals, 10);
        repairs.turned =
            super::normals::orient_given_normals(&positions, &mut normals, 10, orientation);
        if repairs.filled + repairs.turned > 0 {
            for (p, n) in support.iter_mut().zip(normals) {
                p.normal = n;
            }
            if samples_in_support {
                let from = support.len() - samples.len();
                samples.copy_from_slice(&support[from..]);
            }
        }
    }
    let (mut positions, mut normals): (Vec<DVec3>, Vec<DVec3>) =
        support.iter().map(|p| (p.position, p.normal)).unzip();
    drop(support);
    if let Some(radius) = sheet_radius {
        let off = off_surface(&positions, Some(radius));
        let mut keep = off.iter().map(|&o| !o);
        positions.retain(|_| keep.next().unwrap_or(true));
        let mut keep = off.iter().map(|&o| !o);
        normals.retain(|_| keep.next().unwrap_or(true));
        if positions.is_empty() && !off.is_empty() {
            // Every point is on no sheet at this radius: the data is sparser than the output
            // asked for (or holds no surface at all). The caller names the file.
            let n = off.len();
            return Err(Error::invalid_mesh(
                "",
                if n <= super::outliers::SHEET_NEIGHBORS {
                    format!(
                        "{n} points are too few to hold a surface: a point on one needs {} \
                         others around it",
                        super::outliers::SHEET_NEIGHBORS
                    )
                } else {
                    format!(
                        "no surface at this density: none of its {n} points has enough \
                         neighbours within {radius:.3} (bbox-100 units, from the output's \
                         spacing); ask for fewer output points than the input has"
                    )
                },
            ));
        }
    }
    // In Morton order: a RIMLS evaluation sums over a point's neighbours, which are then
    // neighbours in memory too (the scan leaves them in its own order).
    let order = crate::geometry::morton::morton_order(&positions);
    let positions = order.iter().map(|&i| positions[i as usize]).collect();
    let normals = order.iter().map(|&i| normals[i as usize]).collect();
    Ok((Rimls::new(positions, normals, params)?, repairs))
}

/// The result of [`simplify_progressive`].
#[derive(Debug, Clone)]
pub struct ProgressiveResult {
    /// The nested sets P_1 ⊂ P_2 ⊂ …, coarsest first, in the input's units: P_l is
    /// `samples[..level_ends[l - 1]]`.
    pub samples: Vec<Point>,
    /// The level of each sample: 1 for P_1, l for the samples P_l adds to P_(l-1).
    pub levels: Vec<u8>,
    /// Per level, the size of P_l.
    pub level_ends: Vec<usize>,
    /// Per level, its sigma_p (bbox-100 units), largest first.
    pub sigma_p: Vec<f64>,
    /// Points read, less the coincident and the far ones.
    pub input_points: u64,
    /// Points of far groups left out (`points::far_groups`).
    pub far_points: u64,
    /// Points merged into another at the same position.
    pub duplicate_points: u64,
    /// Whether the input had normals.
    pub had_normals: bool,
    /// Model units ↔ bbox-100 units.
    pub normalization: Normalization,
    /// Seconds: reading and bucketing, then one entry per level.
    pub seconds: Vec<f64>,
}

/// Progressive sampling (Sec. 6.4, coarse to fine): a linear scan of the whole input with the
/// largest sigma_p gives P_1; each smaller sigma_p scans the whole input again with O starting
/// as the previous set, so P_1 ⊂ P_2 ⊂ … ⊂ P_L and each P_l is a complete linear scan at its
/// sigma_p (no input point has s > epsilon against it). Out of core like
/// [`simplify_out_of_core`]: one pass over the buckets per level; memory bounded by P_L plus a
/// bucket. `sigma_ps` (bbox-100 units) may come in any order; `params.target`,
/// `params.sigma_p` and `params.resample` are not used. For an input without normals, normals
/// are estimated on the output as in [`simplify_out_of_core`].
///
/// # Errors
/// [`Error::InvalidParameter`] for no levels, more than 255, or a sigma_p that is not finite
/// and positive; the errors of [`simplify_out_of_core`].
pub fn simplify_progressive(
    input: &Path,
    sigma_ps: &[f64],
    params: &OutOfCoreParams,
) -> Result<ProgressiveResult> {
    let invalid = |message: String| Error::InvalidParameter {
        name: "levels",
        message,
    };
    if sigma_ps.is_empty() || sigma_ps.len() > 255 {
        return Err(invalid(format!(
            "give 1 to 255 sigma_p values, not {}",
            sigma_ps.len()
        )));
    }
    if let Some(bad) = sigma_ps.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
        return Err(invalid(format!("sigma_p {bad} is not a positive number")));
    }
    let mut sigma_p = sigma_ps.to_vec();
    sigma_p.sort_by(|a, b| b.total_cmp(a));
    sigma_p.dedup();
    let t0 = Instant::now();
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let buckets = Buckets::write(
        &PointSource::File(input.to_path_buf()),
        params.bucket_points,
        params.temp_dir.as_deref(),
        &mut rng,
    )?
    .or_refuse(input)?;
    let mut seconds = vec![t0.elapsed().as_secs_f64()];
    let norm = buckets.normalization;
    // P_l in bbox-100 units (for the next level's O) and in the input's units (the output).
    let mut scaled: Vec<(DVec3, DVec3)> = Vec::new();
    let (mut samples, mut levels, mut level_ends) = (Vec::new(), Vec::new(), Vec::new());
    let mut accepted = Vec::new();
    for (l, &s) in sigma_p.iter().enumerate() {
        let t = Instant::now();
        let kernel = Kernel::new(s, params.sigma_n)?;
        let mut scanner = LinearScanner::new(&kernel, &params.scan);
        for &(p, n) in &scaled {
            scanner.insert(p, n);
        }
        buckets.for_each(&mut rng, |pts| {
            let batch: Vec<(DVec3, DVec3)> = pts.iter().map(|p| (p.position, p.normal)).collect();
            accepted.clear();
            scanner.offer_batch(&batch, &mut accepted);
            for &i in &accepted {
                scaled.push(batch[i]);
                samples.push(Point {
                    position: norm.invert(pts[i].position),
                    normal: pts[i].normal,
                });
                levels.push((l + 1) as u8);
            }
        })?;
        level_ends.push(samples.len());
        seconds.push(t.elapsed().as_secs_f64());
    }
    if !buckets.had_normals {
        estimate_sample_normals(&mut samples, params.orientation);
    }
    Ok(ProgressiveResult {
        samples,
        levels,
        level_ends,
        sigma_p,
        input_points: buckets.total,
        far_points: buckets.far_points,
        duplicate_points: buckets.duplicate_points,
        had_normals: buckets.had_normals,
        normalization: norm,
        seconds,
    })
}

/// Points of the first bucket the outlier filter compares with (a random subset: the tests are
/// scale-free, so a sparser reference only coarsens them).
const FILTER_REFERENCE_POINTS: usize = 1 << 18;

/// The length of the prefix of a bucket of `available` points that [`search_sigma_p`] scans
/// for `target` samples from `total` input points.
fn search_subset_len(available: usize, total: u64, target: usize) -> usize {
    let target = target.max(1);
    let density = (total as f64 / target as f64).min(SEARCH_MAX_DENSITY);
    let small_target = target.min(SEARCH_SAMPLES);
    ((density * small_target as f64).ceil() as usize).min(available)
}

/// Most samples the scaled-down search problem aims at.
const SEARCH_SAMPLES: usize = 10_000;

/// Input points per sample above which the scan's count hardly depends on the input's density.
const SEARCH_MAX_DENSITY: f64 = 50.0;

/// The sigma_p (bbox-100 units) for about `target` samples from `total` input points, searched
/// on a scaled-down problem: a random subset of `sample` (uniformly random input points) with
/// the input's points per sample (up to [`SEARCH_MAX_DENSITY`]) and a target of at most
/// [`SEARCH_SAMPLES`]. On a surface the count goes as sigma_p^-2 at a fixed points-per-sample
/// ratio, so the subset's sigma_p' for target' gives sigma_p = sigma_p' sqrt(target' / target).
fn search_sigma_p(
    sample: &[Point],
    total: u64,
    target: usize,
    params: &OutOfCoreParams,
) -> Result<f64> {
    let target = target.max(1);
    let subset = search_subset_len(sample.len(), total, target);
    let small_target = target.min(SEARCH_SAMPLES).min(subset);
    let batch: Vec<(DVec3, DVec3)> = sample[..subset]
        .iter()
        .map(|p| (p.position, p.normal))
        .collect();
    let start =
        (super::area_guess::surface_area_guess(&sample[..subset]) / small_target as f64).sqrt();
    let search = TargetCountParams {
        tolerance: 0.01,
        ..TargetCountParams::new(small_target)
    };
    let mut failure = None;
    let mut accepted = Vec::new();
    let r = find_sigma_p(&search, start, |s| {
        let count = match Kernel::new(s, params.sigma_n) {
            Ok(kernel) => {
                let mut scanner = LinearScanner::new(&kernel, &params.scan);
                accepted.clear();
                scanner.offer_batch(&batch, &mut accepted);
                scanner.len()
            }
            Err(e) => {
                failure = Some(e);
                0
            }
        };
        (count, ())
    });
    if let Some(e) = failure {
        return Err(e);
    }
    Ok(r.sigma_p * (small_target as f64 / target as f64).sqrt())
}
