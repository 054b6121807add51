//! Simplification by randomized linear scan (Sec. 6.1, Algorithm 1).

use super::SurfaceSample;
use crate::kernel::{Kernel, KernelPoint, SUPPORT_RADIUS};
use crate::measure::{spectral_measure, MeasureWorkspace, DEFAULT_EPSILON};
use crate::spatial::DynamicTree;
use glam::DVec3;

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

/// The state of Algorithm 1 as points stream past: the output set O (embedded in kernel space,
/// in a dynamic kd-tree over positions) and the statistics. [`linear_scan`] drives it over a
/// slice; the out-of-core scan drives it over a file. Positions are in bbox-100 units.
pub struct LinearScanner<'k> {
    kernel: &'k Kernel,
    params: LinearScanParams,
    tree: DynamicTree,
    embedded: Vec<KernelPoint>,
    ws: MeasureWorkspace,
    found: Vec<(u32, f64)>,
    neighbors: Vec<(f64, KernelPoint)>,
    /// Candidates rejected by their nearest output sample alone.
    pub rejected_by_nearest: usize,
    /// Candidates rejected by the measure over their few nearest output samples.
    pub rejected_by_few: usize,
    /// Candidates whose measure was evaluated with eq. 10 over their whole neighbourhood.
    pub measured: usize,
}

impl<'k> LinearScanner<'k> {
    /// An empty output set.
    pub fn new(kernel: &'k Kernel, params: &LinearScanParams) -> Self {
        LinearScanner {
            kernel,
            params: *params,
            tree: DynamicTree::new(),
            embedded: Vec::new(),
            ws: MeasureWorkspace::new(),
            found: Vec::new(),
            neighbors: Vec::new(),
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

    /// Whether s(x) over the `FEW` nearest points of O (those within the support) is already
    /// <= epsilon.
    fn few_nearest_reject(&mut self, position: DVec3, x: &KernelPoint, r_kernel_2: f64) -> bool {
        const FEW: usize = 4;
        self.tree.nearest_n(position, FEW, &mut self.found);
        self.neighbors.clear();
        for &(j, _) in &self.found {
            let y = self.embedded[j as usize];
            let d2 = x.dist2(&y);
            if d2 <= r_kernel_2 {
                self.neighbors.push((d2, y));
            }
        }
        if self.neighbors.len() < 2 {
            return false;
        }
        self.neighbors.sort_by(|a, b| a.0.total_cmp(&b.0));
        let m = spectral_measure(
            self.kernel,
            x,
            self.neighbors.iter().map(|n| n.1),
            self.params.epsilon,
            &mut self.ws,
        );
        m.s <= self.params.epsilon
    }

    /// Puts a point into O without testing it (an initial sample).
    pub fn insert(&mut self, position: DVec3, normal: DVec3) {
        self.tree.add(position, self.embedded.len() as u32);
        self.embedded.push(self.kernel.embed(position, normal));
    }

    /// One step of Algorithm 1: adds the point to O and returns true when s(x) > epsilon against
    /// its neighbours in O (or it has none). A candidate whose nearest output sample alone gives
    /// s <= 1 - k(x, x_1)^2 <= epsilon is rejected without a kernel matrix.
    pub fn offer(&mut self, position: DVec3, normal: DVec3) -> bool {
        let kernel = self.kernel;
        let x = kernel.embed(position, normal);
        let r_pos = self.params.support_radius * kernel.sigma_p();
        let r_kernel_2 = self.params.support_radius * self.params.support_radius;
        let accept = match self.tree.nearest(position) {
            None => true,
            Some((j, _)) => {
                let k1 = kernel.eval(&x, &self.embedded[j as usize]);
                if k1 * k1 >= 1.0 - self.params.epsilon {
                    self.rejected_by_nearest += 1;
                    false
                } else if self.few_nearest_reject(position, &x, r_kernel_2) {
                    // s over a few nearest neighbours is already <= epsilon; s can only fall as
                    // neighbours are added, so the full neighbourhood would reject too.
                    self.rejected_by_few += 1;
                    false
                } else {
                    self.tree.within(position, r_pos * r_pos, &mut self.found);
                    self.neighbors.clear();
                    for &(j, _) in &self.found {
                        let y = self.embedded[j as usize];
                        let d2 = x.dist2(&y);
                        if d2 <= r_kernel_2 {
                            self.neighbors.push((d2, y));
                        }
                    }
                    if self.neighbors.is_empty() {
                        true
                    } else {
                        if !kernel.is_isotropic() {
                            // Nearest first in kernel space (positions alone order them otherwise).
                            self.neighbors.sort_by(|a, b| a.0.total_cmp(&b.0));
                        }
                        self.measured += 1;
                        let m = spectral_measure(
                            kernel,
                            &x,
                            self.neighbors.iter().map(|n| n.1),
                            self.params.epsilon,
                            &mut self.ws,
                        );
                        m.s > self.params.epsilon
                    }
                }
            }
        };
        if accept {
            self.tree.add(position, self.embedded.len() as u32);
            self.embedded.push(x);
        }
        accept
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
    for c in candidates {
        if scanner.offer(c.position, c.normal) {
            samples.push(*c);
        }
    }
    LinearScanResult {
        samples,
        initial: initial.len(),
        rejected_by_nearest: scanner.rejected_by_nearest,
        measured: scanner.measured,
    }
}
