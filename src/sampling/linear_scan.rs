//! Simplification by randomized linear scan (Sec. 6.1, Algorithm 1).

use super::SurfaceSample;
use crate::kernel::{Kernel, KernelPoint, SUPPORT_RADIUS};
use crate::measure::{spectral_measure, MeasureWorkspace, DEFAULT_EPSILON};
use crate::spatial::DynamicTree;
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
#[derive(Default)]
struct Buffers {
    found: Vec<(u32, f64)>,
    neighbors: Vec<(f64, KernelPoint)>,
    ws: MeasureWorkspace,
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
    let (j, _) = tree.nearest(position)?;
    let k1 = kernel.eval(x, &embedded[j as usize]);
    if k1 * k1 >= 1.0 - params.epsilon {
        return Some(QuickReject::Nearest);
    }
    let r_kernel_2 = params.support_radius * params.support_radius;
    tree.nearest_n(position, FEW, &mut b.found);
    b.neighbors.clear();
    for &(j, _) in &b.found {
        let y = embedded[j as usize];
        let d2 = x.dist2(&y);
        if d2 <= r_kernel_2 {
            b.neighbors.push((d2, y));
        }
    }
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
        let x = self.kernel.embed(position, normal);
        self.add(position, x);
    }

    /// One step of Algorithm 1: adds the point to O and returns true when s(x) > epsilon against
    /// its neighbours in O (or it has none). Quick tests first (see [`quick_reject`]): the nearest
    /// output sample alone (s <= 1 - k(x, x_1)^2), then the few nearest.
    pub fn offer(&mut self, position: DVec3, normal: DVec3) -> bool {
        let kernel = &self.kernel;
        let x = kernel.embed(position, normal);
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
    /// same decisions), but with the quick rejection tests of each chunk run in parallel against
    /// the output set as it stands at the chunk's start. Pushes the indices (into `batch`) of the
    /// accepted points to `accepted`.
    pub fn offer_batch(&mut self, batch: &[(DVec3, DVec3)], accepted: &mut Vec<usize>) {
        const CHUNK: usize = 8192;
        let mut verdicts: Vec<Option<QuickReject>> = Vec::with_capacity(CHUNK);
        for (c, chunk) in batch.chunks(CHUNK).enumerate() {
            let (kernel, params, tree, embedded) =
                (&self.kernel, &self.params, &self.tree, &self.embedded);
            chunk
                .par_iter()
                .map_init(Buffers::default, |b, &(p, n)| {
                    quick_reject(kernel, params, tree, embedded, p, &kernel.embed(p, n), b)
                })
                .collect_into_vec(&mut verdicts);
            let size_at_start = self.embedded.len();
            for (k, (&(p, n), verdict)) in chunk.iter().zip(&verdicts).enumerate() {
                let take = match verdict {
                    Some(why) => {
                        self.count(*why);
                        false
                    }
                    // O as the quick tests saw it: straight to the full measure.
                    None if self.embedded.len() == size_at_start => {
                        let x = self.kernel.embed(p, n);
                        let accept = self.full_measure_accepts(p, &x);
                        if accept {
                            self.add(p, x);
                        }
                        accept
                    }
                    None => self.offer(p, n),
                };
                if take {
                    accepted.push(c * CHUNK + k);
                }
            }
        }
    }

    fn count(&mut self, why: QuickReject) {
        match why {
            QuickReject::Nearest => self.rejected_by_nearest += 1,
            QuickReject::Few => self.rejected_by_few += 1,
        }
    }

    /// The measure over the whole neighbourhood within the support radius, nearest first.
    fn full_measure_accepts(&mut self, position: DVec3, x: &KernelPoint) -> bool {
        let kernel = &self.kernel;
        let r_pos = self.params.support_radius * kernel.sigma_p();
        let r_kernel_2 = self.params.support_radius * self.params.support_radius;
        let b = &mut self.buffers;
        self.tree.within(position, r_pos * r_pos, &mut b.found);
        b.neighbors.clear();
        for &(j, _) in &b.found {
            let y = self.embedded[j as usize];
            let d2 = x.dist2(&y);
            if d2 <= r_kernel_2 {
                b.neighbors.push((d2, y));
            }
        }
        if b.neighbors.is_empty() {
            return true;
        }
        if !kernel.is_isotropic() {
            // Nearest first in kernel space (positions alone order them otherwise).
            b.neighbors.sort_by(|a, c| a.0.total_cmp(&c.0));
        }
        self.measured += 1;
        let m = spectral_measure(
            kernel,
            x,
            b.neighbors.iter().map(|n| n.1),
            self.params.epsilon,
            &mut b.ws,
        );
        m.s > self.params.epsilon
    }
}

/// Algorithm 1: visits `candidates` in the order given (pass them shuffled) and adds each to the
/// output set O when its spectral measure s(x) (eq. 9) against its neighbours in O exceeds
/// epsilon, or when it has no neighbour in O. `initial` samples (for example samples placed on the
/// input's boundary curves) start O.
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
    initial: &[SurfaceSample],
    params: &LinearScanParams,
) -> LinearScanResult {
    let mut samples: Vec<SurfaceSample> = Vec::with_capacity(initial.len() + candidates.len() / 8);
    let mut scanner = LinearScanner::new(kernel, params);
    for s in initial {
        scanner.insert(s.position, s.normal);
        samples.push(*s);
    }
    let batch: Vec<(DVec3, DVec3)> = candidates.iter().map(|c| (c.position, c.normal)).collect();
    let mut accepted = Vec::new();
    scanner.offer_batch(&batch, &mut accepted);
    samples.extend(accepted.iter().map(|&i| candidates[i]));
    LinearScanResult {
        samples,
        initial: initial.len(),
        rejected_by_nearest: scanner.rejected_by_nearest,
        measured: scanner.measured,
    }
}
