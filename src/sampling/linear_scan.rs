//! Simplification by randomized linear scan (Sec. 6.1, Algorithm 1).

use crate::geometry::morton::morton_code;
use crate::kernel::{Kernel, KernelPoint, SUPPORT_RADIUS};
use crate::measure::{spectral_measure, MeasureWorkspace, DEFAULT_EPSILON};
use crate::sampling::sizing::SizingField;
use crate::spatial::DynamicTree;
use crate::surface::SurfaceSample;
use glam::DVec3;
use rayon::prelude::*;

/// Parameters of the linear scan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearScanParams {
    /// Acceptance threshold: a candidate joins the output when s(x) > epsilon (default 0.5,
    /// Sec. 6.3).
    pub epsilon: f64,
    /// Neighbourhood radius in kernel units (default 2.5, Sec. 6.3).
    pub support_radius: f64,
}

impl Default for LinearScanParams {
    fn default() -> Self {
        LinearScanParams {
            epsilon: DEFAULT_EPSILON,
            support_radius: SUPPORT_RADIUS,
        }
    }
}

/// The output of a linear scan.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearScanResult {
    /// The output set O: the initial samples first, then the accepted candidates in the order
    /// they were accepted.
    pub samples: Vec<SurfaceSample>,
    /// How many of `samples` are the initial ones.
    pub initial: usize,
    /// Candidates rejected by their nearest output sample alone (s <= 1 - k(x, x_1)^2 <= epsilon,
    /// no kernel matrix needed).
    pub rejected_by_nearest: usize,
    /// Candidates whose measure was evaluated with the iterative inversion of eq. 10.
    pub measured: usize,
}

/// Per-thread buffers of the rejection tests.
struct Buffers {
    /// The sample that last rejected a candidate alone (`u32::MAX`: none). Candidates are visited
    /// in spatial order, so it often rejects the next one too, without a kd-tree query.
    last_rejecter: u32,
    found: Vec<(u32, f64)>,
    neighbors: Vec<(f64, KernelPoint)>,
    ws: MeasureWorkspace,
}

impl Default for Buffers {
    fn default() -> Self {
        Buffers {
            last_rejecter: u32::MAX,
            found: Vec::new(),
            neighbors: Vec::new(),
            ws: MeasureWorkspace::default(),
        }
    }
}

/// Why a candidate was rejected before its full neighbourhood was looked at.
#[derive(Clone, Copy, PartialEq, Eq)]
enum QuickReject {
    /// Its nearest output sample alone gives s <= epsilon.
    Nearest,
    /// The measure over its few nearest output samples is <= epsilon.
    Few,
}

/// Output samples the second quick test uses.
const FEW: usize = 4;

/// The quick tests of Algorithm 1 against the output set (`tree`, `embedded`). Both only prove
/// rejections: s can only fall as points join the output set, so a candidate rejected against
/// any subset of it is rejected against all of it.
fn quick_reject(
    kernel: &Kernel,
    params: &LinearScanParams,
    tree: &DynamicTree,
    embedded: &[KernelPoint],
    position: DVec3,
    x: &KernelPoint,
    b: &mut Buffers,
) -> Option<QuickReject> {
    // Any one sample y of O bounds s(x) <= 1 - k(x, y)^2: first the last one that rejected a
    // candidate on its own, then the nearest.
    if let Some(y) = embedded.get(b.last_rejecter as usize) {
        let k = kernel.eval(x, y);
        if k * k >= 1.0 - params.epsilon {
            return Some(QuickReject::Nearest);
        }
    }
    let (j, _) = tree.nearest(position)?;
    let k1 = kernel.eval(x, &embedded[j as usize]);
    if k1 * k1 >= 1.0 - params.epsilon {
        b.last_rejecter = j;
        return Some(QuickReject::Nearest);
    }
    tree.nearest_n(position, FEW, &mut b.found);
    gather_neighbors(params, embedded, x, b);
    if b.neighbors.len() < 2 {
        return None;
    }
    b.neighbors.sort_by(|a, c| a.0.total_cmp(&c.0));
    let m = spectral_measure(
        kernel,
        x,
        b.neighbors.iter().map(|n| n.1),
        params.epsilon,
        &mut b.ws,
    );
    (m.s <= params.epsilon).then_some(QuickReject::Few)
}

/// The state of Algorithm 1 as points stream past: the output set O (embedded in kernel space,
/// in a dynamic kd-tree over positions) and the statistics. [`linear_scan`] drives it over a
/// slice; the out-of-core scan drives it over a file. Positions are in bbox-100 units.
pub struct LinearScanner {
    kernel: Kernel,
    params: LinearScanParams,
    tree: DynamicTree,
    embedded: Vec<KernelPoint>,
    buffers: Buffers,
    /// Whether a point of width below 1 (a graded kernel) has been seen: neighbours are then
    /// ordered by the kernel's exponent, not by position.
    graded: bool,
    /// Candidates rejected by their nearest output sample alone.
    pub rejected_by_nearest: usize,
    /// Candidates rejected by the measure over their few nearest output samples.
    pub rejected_by_few: usize,
    /// Candidates whose measure was evaluated with eq. 10 over their whole neighbourhood.
    pub measured: usize,
}

impl LinearScanner {
    /// An empty output set.
    pub fn new(kernel: &Kernel, params: &LinearScanParams) -> Self {
        LinearScanner {
            kernel: *kernel,
            params: *params,
            tree: DynamicTree::new(),
            embedded: Vec::new(),
            buffers: Buffers::default(),
            graded: false,
            rejected_by_nearest: 0,
            rejected_by_few: 0,
            measured: 0,
        }
    }

    /// The number of points in O.
    pub fn len(&self) -> usize {
        self.embedded.len()
    }

    /// Whether O is empty.
    pub fn is_empty(&self) -> bool {
        self.embedded.is_empty()
    }

    /// Puts a point into O without testing it (an initial sample).
    pub fn insert(&mut self, position: DVec3, normal: DVec3) {
        self.insert_graded(position, normal, 1.0);
    }

    /// [`LinearScanner::insert`] with the point's relative kernel width (see
    /// [`Kernel`](crate::internal::Kernel)).
    pub fn insert_graded(&mut self, position: DVec3, normal: DVec3, width: f64) {
        let x = self.kernel.embed_graded(position, normal, width);
        self.graded |= width != 1.0;
        self.add(position, x);
    }

    /// One step of Algorithm 1: adds the point to O and returns true when s(x) > epsilon against
    /// its neighbours in O (or it has none). Quick tests first (see `quick_reject`): the nearest
    /// output sample alone (s <= 1 - k(x, x_1)^2), then the few nearest.
    pub fn offer(&mut self, position: DVec3, normal: DVec3) -> bool {
        self.offer_graded(position, normal, 1.0)
    }

    /// [`LinearScanner::offer`] with the point's relative kernel width (see
    /// [`Kernel`](crate::internal::Kernel)).
    pub fn offer_graded(&mut self, position: DVec3, normal: DVec3, width: f64) -> bool {
        self.graded |= width != 1.0;
        let kernel = &self.kernel;
        let x = kernel.embed_graded(position, normal, width);
        let quick = quick_reject(
            kernel,
            &self.params,
            &self.tree,
            &self.embedded,
            position,
            &x,
            &mut self.buffers,
        );
        let accept = match quick {
            Some(why) => {
                self.count(why);
                false
            }
            None => self.full_measure_accepts(position, &x),
        };
        if accept {
            self.add(position, x);
        }
        accept
    }

    /// Puts an embedded point into O.
    fn add(&mut self, position: DVec3, x: KernelPoint) {
        self.tree.add(position, self.embedded.len() as u32);
        self.embedded.push(x);
    }

    /// Algorithm 1 over `batch` in order, as [`LinearScanner::offer`] one by one would do it (the
    /// same decisions), with the tests of each chunk of candidates run in parallel against O as
    /// it stands at the chunk's start. Pushes the indices (into `batch`) of the accepted points
    /// to `accepted`.
    ///
    /// Why the decisions are the same: s(x) can only fall as O grows, so a rejection against
    /// O at the chunk's start stands. An acceptance stands when no sample the chunk has added so
    /// far lies within the support radius of the candidate (its neighbourhood, and so s(x), is
    /// unchanged); otherwise the candidate is tested again against O as it is then.
    ///
    /// A chunk's tests run in Morton order of the positions (nearby candidates query the same
    /// parts of the kd-tree, which then stay in cache, and a sample that rejected one candidate
    /// alone is tried first on the next). Chunks grow as acceptances become rare: the next chunk
    /// is sized so that it is expected to add about 2% to O (between 8k and 1M candidates).
    pub fn offer_batch(&mut self, batch: &[(DVec3, DVec3)], accepted: &mut Vec<usize>) {
        self.offer_batch_graded(batch, None, accepted);
    }

    /// [`LinearScanner::offer_batch`] with each point's relative kernel width (`widths[k]` for
    /// `batch[k]`, in (0, 1]; `None`: all 1). The decisions are those of
    /// [`LinearScanner::offer_graded`] one by one: s(x) still only falls as O grows, and every
    /// pair's support lies within the global support radius (widths are at most 1).
    pub fn offer_batch_graded(
        &mut self,
        batch: &[(DVec3, DVec3)],
        widths: Option<&[f64]>,
        accepted: &mut Vec<usize>,
    ) {
        let width = |k: usize| widths.map_or(1.0, |w| w[k]);
        self.graded |= widths.is_some_and(|w| w.iter().any(|&w| w != 1.0));
        const MIN_CHUNK: usize = 8192;
        const MAX_CHUNK: usize = 1 << 20;
        let mut verdicts: Vec<Verdict> = Vec::new();
        let mut order: Vec<(u64, u32)> = Vec::new();
        let (mut start, mut chunk_len) = (0, MIN_CHUNK);
        let r_pos = self.params.support_radius * self.kernel.sigma_p();
        while start < batch.len() {
            let chunk = &batch[start..(start + chunk_len).min(batch.len())];
            let chunk_widths = widths.map(|w| &w[start..start + chunk.len()]);
            self.parallel_tests(chunk, chunk_widths, &mut order, &mut verdicts);
            let size_at_start = self.embedded.len();
            for (k, (&(p, n), verdict)) in chunk.iter().zip(&verdicts).enumerate() {
                let take = match *verdict {
                    Verdict::Quick(why) => {
                        self.count(why);
                        false
                    }
                    Verdict::Measured(false) => {
                        self.measured += 1;
                        false
                    }
                    Verdict::Measured(true) | Verdict::Alone => {
                        self.measured += usize::from(*verdict != Verdict::Alone);
                        // Still accepted when the chunk added nothing near it.
                        let unchanged = self.embedded.len() == size_at_start || {
                            let found = &mut self.buffers.found;
                            self.tree.within(p, r_pos * r_pos, found);
                            found.iter().all(|&(j, _)| (j as usize) < size_at_start)
                        };
                        if unchanged {
                            self.insert_graded(p, n, width(start + k));
                            true
                        } else {
                            self.offer_graded(p, n, width(start + k))
                        }
                    }
                };
                if take {
                    accepted.push(start + k);
                }
            }
            let added = (self.embedded.len() - size_at_start) as f64;
            let rate = (added + 1.0) / chunk.len() as f64;
            start += chunk.len();
            chunk_len =
                ((0.02 * self.embedded.len() as f64 / rate) as usize).clamp(MIN_CHUNK, MAX_CHUNK);
        }
    }

    /// The tests of `chunk` against O as it stands, in parallel, visited in Morton order of the
    /// positions; `verdicts[k]` is candidate k's.
    fn parallel_tests(
        &self,
        chunk: &[(DVec3, DVec3)],
        widths: Option<&[f64]>,
        order: &mut Vec<(u64, u32)>,
        verdicts: &mut Vec<Verdict>,
    ) {
        let (kernel, params, tree, embedded, graded) = (
            &self.kernel,
            &self.params,
            &self.tree,
            &self.embedded,
            self.graded,
        );
        let (lo, hi) = chunk.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), c| (lo.min(c.0), hi.max(c.0)),
        );
        let scale = (1u64 << 21) as f64 / (hi - lo).max_element().max(f64::MIN_POSITIVE);
        order.clear();
        chunk
            .par_iter()
            .enumerate()
            .map(|(k, c)| (morton_code((c.0 - lo) * scale), k as u32))
            .collect_into_vec(order);
        order.par_sort_unstable();
        let found: Vec<Verdict> = order
            .par_iter()
            .map_init(Buffers::default, |b, &(_, k)| {
                let (p, n) = chunk[k as usize];
                let x = kernel.embed_graded(p, n, widths.map_or(1.0, |w| w[k as usize]));
                match quick_reject(kernel, params, tree, embedded, p, &x, b) {
                    Some(why) => Verdict::Quick(why),
                    None => match full_measure(kernel, params, tree, embedded, graded, p, &x, b) {
                        Some(accept) => Verdict::Measured(accept),
                        None => Verdict::Alone,
                    },
                }
            })
            .collect();
        verdicts.clear();
        verdicts.resize(chunk.len(), Verdict::Alone);
        for (&(_, k), v) in order.iter().zip(found) {
            verdicts[k as usize] = v;
        }
    }

    fn count(&mut self, why: QuickReject) {
        match why {
            QuickReject::Nearest => self.rejected_by_nearest += 1,
            QuickReject::Few => self.rejected_by_few += 1,
        }
    }

    /// The measure over the whole neighbourhood within the support radius: accepts when
    /// s > epsilon or there is no neighbour.
    fn full_measure_accepts(&mut self, position: DVec3, x: &KernelPoint) -> bool {
        let r = full_measure(
            &self.kernel,
            &self.params,
            &self.tree,
            &self.embedded,
            self.graded,
            position,
            x,
            &mut self.buffers,
        );
        self.measured += usize::from(r.is_some());
        r.unwrap_or(true)
    }
}

/// A candidate's test against O at the start of its chunk.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Verdict {
    /// Rejected by a quick test.
    Quick(QuickReject),
    /// Measured over its neighbourhood: whether s > epsilon.
    Measured(bool),
    /// No neighbour in O.
    Alone,
}

/// The samples of `b.found` (indices into `embedded`) within the support radius of `x` in kernel
/// space (the pair's exponent, [`KernelPoint::pair_dist2`]), with that exponent, into
/// `b.neighbors` (in `b.found`'s order).
fn gather_neighbors(
    params: &LinearScanParams,
    embedded: &[KernelPoint],
    x: &KernelPoint,
    b: &mut Buffers,
) {
    let r_kernel_2 = params.support_radius * params.support_radius;
    b.neighbors.clear();
    for &(j, _) in &b.found {
        let y = embedded[j as usize];
        let d2 = x.pair_dist2(&y);
        if d2 <= r_kernel_2 {
            b.neighbors.push((d2, y));
        }
    }
}

/// The measure of `x` over its whole neighbourhood in O (`tree`, `embedded`) within the support
/// radius, nearest first (by the kernel's exponent when `graded`): `Some(s > epsilon)`, or `None`
/// when it has no neighbour.
#[allow(clippy::too_many_arguments)]
fn full_measure(
    kernel: &Kernel,
    params: &LinearScanParams,
    tree: &DynamicTree,
    embedded: &[KernelPoint],
    graded: bool,
    position: DVec3,
    x: &KernelPoint,
    b: &mut Buffers,
) -> Option<bool> {
    let r_pos = params.support_radius * kernel.sigma_p();
    tree.within(position, r_pos * r_pos, &mut b.found);
    gather_neighbors(params, embedded, x, b);
    if b.neighbors.is_empty() {
        return None;
    }
    if !kernel.is_isotropic() || graded {
        // Nearest first in kernel space (positions alone order them otherwise).
        b.neighbors.sort_by(|a, c| a.0.total_cmp(&c.0));
    }
    let m = spectral_measure(
        kernel,
        x,
        b.neighbors.iter().map(|n| n.1),
        params.epsilon,
        &mut b.ws,
    );
    Some(m.s > params.epsilon)
}

/// Algorithm 1: visits `candidates` in the order given (pass them shuffled) and adds each to the
/// output set O when its spectral measure s(x) (eq. 9) against its neighbours in O exceeds
/// epsilon, or when it has no neighbour in O. `initial` samples (for example samples placed on the
/// input's boundary curves) start O.
///
/// The kernel is graded by the sizing `field` (each point's relative width, see
/// [`Kernel`](crate::internal::Kernel); [`Uniform`](crate::sampling::sizing::Uniform): one
/// sigma_p, as in the paper). `candidate_widths[k]`, when given, is the field at `candidates[k]`
/// (the caller takes them once for the scans that share them); else they are taken here.
///
/// Neighbours are the points of O within `support_radius` in kernel space, taken nearest first;
/// the evaluation stops as soon as s <= epsilon (Sec. 6.1). O is kept in a dynamic kd-tree over
/// positions: a point within r in kernel space is within r sigma_p in position.
///
/// Units: positions in bbox-100 units, `kernel` as given. Runs in O(|candidates| log |O|) plus the
/// inversions of the candidates that are not rejected by their nearest neighbour.
pub fn linear_scan(
    kernel: &Kernel,
    candidates: &[SurfaceSample],
    candidate_widths: Option<&[f64]>,
    initial: &[SurfaceSample],
    field: &dyn SizingField,
    params: &LinearScanParams,
) -> LinearScanResult {
    let uniform = field.is_uniform();
    let taken: Option<Vec<f64>> = (!uniform && candidate_widths.is_none()).then(|| {
        candidates
            .par_iter()
            .map(|c| field.width(c.position))
            .collect()
    });
    let candidate_widths = candidate_widths.or(taken.as_deref());
    let mut samples: Vec<SurfaceSample> = Vec::with_capacity(initial.len() + candidates.len() / 8);
    let mut scanner = LinearScanner::new(kernel, params);
    for s in initial {
        let w = if uniform {
            1.0
        } else {
            field.width(s.position)
        };
        scanner.insert_graded(s.position, s.normal, w);
        samples.push(*s);
    }
    let batch: Vec<(DVec3, DVec3)> = candidates.iter().map(|c| (c.position, c.normal)).collect();
    let mut accepted = Vec::new();
    scanner.offer_batch_graded(&batch, candidate_widths, &mut accepted);
    samples.extend(accepted.iter().map(|&i| candidates[i]));
    LinearScanResult {
        samples,
        initial: initial.len(),
        rejected_by_nearest: scanner.rejected_by_nearest,
        measured: scanner.measured,
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// Points on a unit-ish sphere of radius 20 with outward normals, some bumps in the normals.
    pub(crate) fn sphere_points(n: usize, seed: u64) -> Vec<(DVec3, DVec3)> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                let v = DVec3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                )
                .normalize_or(DVec3::Z);
                let bump = DVec3::new(0.0, (7.0 * v.x).sin() * 0.3, 0.0);
                (20.0 * v, (v + bump).normalize())
            })
            .collect()
    }

    #[test]
    fn a_batch_makes_the_decisions_of_one_by_one_offers() {
        for (sigma_n, seed) in [(f64::INFINITY, 1), (0.75, 2)] {
            let kernel = Kernel::new(1.0, sigma_n).unwrap();
            let params = LinearScanParams::default();
            let points = sphere_points(60_000, seed);
            let initial = sphere_points(50, seed + 10);
            let mut one = LinearScanner::new(&kernel, &params);
            let mut batch = LinearScanner::new(&kernel, &params);
            for &(p, n) in &initial {
                one.insert(p, n);
                batch.insert(p, n);
            }
            let by_one: Vec<usize> = (0..points.len())
                .filter(|&i| one.offer(points[i].0, points[i].1))
                .collect();
            let mut by_batch = Vec::new();
            batch.offer_batch(&points, &mut by_batch);
            assert!(by_one.len() > 1000, "{} accepted", by_one.len());
            assert_eq!(by_one, by_batch, "sigma_n {sigma_n}");
            assert_eq!(one.len(), batch.len());
        }
    }

    #[test]
    fn a_graded_batch_makes_the_decisions_of_one_by_one_offers() {
        // Widths from 0.3 to 1 varying over the sphere: a band of finer spacing.
        let width = |p: DVec3| (0.3 + 0.7 * (p.z / 20.0).abs()).min(1.0);
        for (sigma_n, seed) in [(f64::INFINITY, 3), (0.75, 4)] {
            let kernel = Kernel::new(1.0, sigma_n).unwrap();
            let params = LinearScanParams::default();
            let points = sphere_points(40_000, seed);
            let widths: Vec<f64> = points.iter().map(|p| width(p.0)).collect();
            let mut one = LinearScanner::new(&kernel, &params);
            let mut batch = LinearScanner::new(&kernel, &params);
            let by_one: Vec<usize> = (0..points.len())
                .filter(|&i| one.offer_graded(points[i].0, points[i].1, widths[i]))
                .collect();
            let mut by_batch = Vec::new();
            batch.offer_batch_graded(&points, Some(&widths), &mut by_batch);
            assert_eq!(by_one, by_batch, "sigma_n {sigma_n}");
            // The band near z = 0 is sampled finer than the caps: more samples per area.
            let near = |lo: f64, hi: f64| {
                by_one
                    .iter()
                    .filter(|&&i| (lo..hi).contains(&points[i].0.z.abs()))
                    .count()
            };
            // Equal areas on a sphere: |z| in [0, 4) and [16, 20).
            assert!(
                near(0.0, 4.0) > 3 * near(16.0, 20.0),
                "{} vs {}",
                near(0.0, 4.0),
                near(16.0, 20.0)
            );
        }
    }
}
