//! The search for the sigma_p that gives a target number of samples.
//!
//! On a surface the count of a linear scan grows like sigma_p^-2 (on a manifold of dimension m,
//! like sigma_p^-m), so the search works on log sigma_p against log count: a first step with
//! slope -m, then secant steps on the two
//! closest evaluations, kept inside the bracket found so far (bisection in log space when a
//! secant step leaves it).

use crate::geometry::tolerance::{LOG_BRACKET_TOLERANCE, LOG_COUNT_TOLERANCE};

/// A count that falls slower than `sigma_p^-FLAT_SLOPE` between two evaluations on the same side
/// of the target, `FLAT_STEP` or more apart in log sigma_p, has stopped answering to sigma_p (on
/// a surface it falls like sigma_p^-2, like sigma_p^-1 where boundary curves dominate): the
/// samples are held by something else (a tiny sigma_n makes every direction of the normal its
/// own neighbourhood), and the search stops there instead of crawling towards a target it
/// cannot reach, with evaluations that grow dearer as sigma_p grows.
const FLAT_SLOPE: f64 = 0.5;

/// See [`FLAT_SLOPE`]: the least step in log sigma_p over which a slope is trusted (counts
/// wobble by a fraction of a percent).
const FLAT_STEP: f64 = 0.1;

/// Parameters of the search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TargetCountParams {
    /// The count wanted.
    pub target: usize,
    /// Relative tolerance: the search stops once |count - target| <= tolerance · target
    /// (default 0.005, half of the 1% the command line promises, so that the few samples the
    /// triangulation may set aside keep the result within 1%).
    pub tolerance: f64,
    /// Most evaluations (default 16).
    pub max_evaluations: usize,
    /// The dimension m of the sampled manifold (default 2, a surface): the count is taken to
    /// fall like sigma_p^-m for the first step; the secant steps after it measure the slope.
    pub dimension: f64,
    /// The largest sigma_p tried (default infinity): when the count there is still above the
    /// target, the search stops there, not reached (a sizing field that bounds the spacing on
    /// most of the surface holds a count sigma_p cannot bring down).
    pub max_sigma: f64,
}

impl TargetCountParams {
    /// Default tolerance and evaluation budget for `target`.
    pub fn new(target: usize) -> Self {
        TargetCountParams {
            target,
            tolerance: 0.005,
            max_evaluations: 16,
            dimension: 2.0,
            max_sigma: f64::INFINITY,
        }
    }
}

/// The outcome of the search.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetCountResult<T> {
    /// The sigma_p whose count is closest to the target.
    pub sigma_p: f64,
    /// That count.
    pub count: usize,
    /// Whatever the evaluation returned for that sigma_p.
    pub value: T,
    /// Whether the count is within the tolerance; when false, `sigma_p` is the best found.
    pub reached: bool,
    /// Every evaluation as (sigma_p, count), in order.
    pub history: Vec<(f64, usize)>,
}

/// Finds sigma_p with `evaluate(sigma_p).0` (a count that decreases with sigma_p) within the
/// tolerance of the target, starting from `sigma_start` (> 0). `evaluate` returns the count and
/// any value the caller wants back for the chosen sigma_p (for example the samples).
pub fn find_sigma_p<T>(
    params: &TargetCountParams,
    sigma_start: f64,
    mut evaluate: impl FnMut(f64) -> (usize, T),
) -> TargetCountResult<T> {
    let target = params.target.max(1) as f64;
    let ln_target = target.ln();
    let within = |c: usize| (c as f64 - target).abs() <= params.tolerance * target;
    let mut history: Vec<(f64, usize)> = Vec::new();
    let mut best: Option<(f64, usize, T)> = None;
    // Bracket in log sigma: lo has count > target, hi has count < target.
    let mut lo: Option<(f64, f64)> = None; // (ln sigma, ln count)
    let mut hi: Option<(f64, f64)> = None;
    let ln_max = params.max_sigma.ln();
    let mut ln_sigma = sigma_start.ln().min(ln_max);
    let mut previous: Option<(f64, f64)> = None; // (ln sigma, ln count) of the last evaluation
    for _ in 0..params.max_evaluations.max(1) {
        let sigma = ln_sigma.exp();
        let (count, value) = evaluate(sigma);
        history.push((sigma, count));
        let better = best
            .as_ref()
            .is_none_or(|b| (count as f64 - target).abs() < (b.1 as f64 - target).abs());
        if better {
            best = Some((sigma, count, value));
        }
        if within(count) || (ln_sigma >= ln_max && count as f64 > target) {
            break;
        }
        let ln_count = (count.max(1) as f64).ln();
        if let Some((ls, lc)) = previous {
            let same_side = lo.is_none() || hi.is_none();
            let step = ln_sigma - ls;
            if same_side
                && step.abs() >= FLAT_STEP
                && (ln_count - lc) / step > -FLAT_SLOPE
                && ((count as f64) > target) == (lc > ln_target)
            {
                break;
            }
        }
        previous = Some((ln_sigma, ln_count));
        if (count as f64) > target {
            if lo.is_none_or(|l| ln_sigma > l.0) {
                lo = Some((ln_sigma, ln_count));
            }
        } else if hi.is_none_or(|h| ln_sigma < h.0) {
            hi = Some((ln_sigma, ln_count));
        }
        // Next guess: secant across the bracket, or slope -m from the last point.
        let mut next = match (lo, hi) {
            (Some(l), Some(h)) if (h.1 - l.1).abs() > LOG_COUNT_TOLERANCE => {
                l.0 + (ln_target - l.1) * (h.0 - l.0) / (h.1 - l.1)
            }
            _ => ln_sigma + (ln_count - ln_target) / params.dimension,
        };
        if let (Some(l), Some(h)) = (lo, hi) {
            // Stay strictly inside the bracket; bisect when the secant lands near its ends.
            let width = h.0 - l.0;
            if !(next > l.0 + 0.05 * width && next < h.0 - 0.05 * width) {
                next = 0.5 * (l.0 + h.0);
            }
            if width.abs() < LOG_BRACKET_TOLERANCE {
                break;
            }
        }
        ln_sigma = next.min(ln_max);
    }
    let (sigma_p, count, value) = best.expect("at least one evaluation");
    TargetCountResult {
        sigma_p,
        count,
        value,
        reached: within(count),
        history,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_sigma_for_an_inverse_square_law_with_noise() {
        // count = A / sigma^2 with a deterministic wobble of ±0.4%.
        for &target in &[100usize, 3000, 8600, 100_000] {
            let f = |s: f64| {
                let base = 12_345.0 / (s * s);
                let wobble = 1.0 + 0.004 * ((s * 1e4).sin());
                ((base * wobble).round() as usize, s)
            };
            let r = find_sigma_p(&TargetCountParams::new(target), 1.0, f);
            assert!(r.reached, "target {target}: {:?}", r.history);
            assert!((r.count as f64 - target as f64).abs() <= 0.005 * target as f64);
            assert_eq!(r.value, r.sigma_p);
            assert!(r.history.len() <= 8, "{} evaluations", r.history.len());
        }
    }

    #[test]
    fn stops_when_the_count_no_longer_answers_to_sigma() {
        // A floor of 6500 above the target (a tiny sigma_n): the count flattens out, and the
        // search stops after a few evaluations instead of crawling through all 16.
        let f = |s: f64| ((6500.0 + 20_000.0 / (s * s)).round() as usize, ());
        let r = find_sigma_p(&TargetCountParams::new(6000), 1.0, f);
        assert!(!r.reached);
        assert!(r.history.len() <= 6, "{:?}", r.history);
        assert_eq!(r.count, r.history.iter().map(|h| h.1).min().unwrap());
    }

    #[test]
    fn reports_the_best_when_the_target_cannot_be_reached() {
        // A step function that jumps over the target.
        let f = |s: f64| (if s < 2.0 { 1000 } else { 10 }, ());
        let r = find_sigma_p(&TargetCountParams::new(500), 1.0, f);
        assert!(!r.reached);
        assert!(r.count == 1000 || r.count == 10);
        assert!(r.history.len() <= 16);
    }

    #[test]
    fn stops_at_the_largest_sigma_when_the_count_there_is_still_above() {
        // A count held above the target by a bounded part (3000 samples whatever sigma_p) and a
        // free part of 4000 at sigma_p 1: the target 4000 needs sigma_p ≈ 2, past the bound 1.5.
        let f = |s: f64| ((3000.0 + 4000.0 / (s * s)).round() as usize, s);
        let params = TargetCountParams {
            max_sigma: 1.5,
            ..TargetCountParams::new(4000)
        };
        let r = find_sigma_p(&params, 1.0, f);
        assert!(!r.reached);
        assert!(r.history.iter().all(|h| h.0 <= 1.5), "{:?}", r.history);
        assert_eq!(r.sigma_p, 1.5, "{:?}", r.history);
        // Without the bound, the same search reaches it.
        let r = find_sigma_p(&TargetCountParams::new(4000), 1.0, f);
        assert!(r.reached, "{:?}", r.history);
        assert!(r.sigma_p > 1.5);
    }
}
