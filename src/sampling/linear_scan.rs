//! Simplification by randomized linear scan (Sec. 6.1, Algorithm 1).

use super::SurfaceSample;
use crate::kernel::{Kernel, KernelPoint, SUPPORT_RADIUS};
use crate::measure::{spectral_measure, MeasureWorkspace, DEFAULT_EPSILON};
use crate::spatial::DynamicTree;

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
    let mut embedded: Vec<KernelPoint> = Vec::with_capacity(samples.capacity());
    let mut tree = DynamicTree::new();
    for s in initial {
        tree.add(s.position, samples.len() as u32);
        embedded.push(kernel.embed(s.position, s.normal));
        samples.push(*s);
    }

    let r_pos = params.support_radius * kernel.sigma_p();
    let r_pos_2 = r_pos * r_pos;
    let r_kernel_2 = params.support_radius * params.support_radius;
    // s <= 1 - k_1^2 for any single neighbour; reject when that bound is <= epsilon.
    let reject_k2 = 1.0 - params.epsilon;
    let mut ws = MeasureWorkspace::new();
    let mut found: Vec<(u32, f64)> = Vec::new();
    let mut neighbors: Vec<(f64, KernelPoint)> = Vec::new();
    let mut rejected_by_nearest = 0;
    let mut measured = 0;

    for c in candidates {
        let x = kernel.embed(c.position, c.normal);
        let accept = match tree.nearest(c.position) {
            None => true,
            Some((j, _)) => {
                let k1 = kernel.eval(&x, &embedded[j as usize]);
                if k1 * k1 >= reject_k2 {
                    rejected_by_nearest += 1;
                    false
                } else {
                    tree.within(c.position, r_pos_2, &mut found);
                    neighbors.clear();
                    for &(j, _) in &found {
                        let y = embedded[j as usize];
                        let d2 = x.dist2(&y);
                        if d2 <= r_kernel_2 {
                            neighbors.push((d2, y));
                        }
                    }
                    if neighbors.is_empty() {
                        true
                    } else {
                        if !kernel.is_isotropic() {
                            // Nearest first in kernel space (positions alone order them otherwise).
                            neighbors.sort_by(|a, b| a.0.total_cmp(&b.0));
                        }
                        measured += 1;
                        let m = spectral_measure(
                            kernel,
                            &x,
                            neighbors.iter().map(|n| n.1),
                            params.epsilon,
                            &mut ws,
                        );
                        m.s > params.epsilon
                    }
                }
            }
        };
        if accept {
            tree.add(c.position, samples.len() as u32);
            embedded.push(x);
            samples.push(*c);
        }
    }
    LinearScanResult {
        samples,
        initial: initial.len(),
        rejected_by_nearest,
        measured,
    }
}
