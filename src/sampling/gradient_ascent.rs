//! Resampling by iterative gradient ascent on the spectral measure (Sec. 6.2, eq. 11), each move
//! projected back onto the input surface.

use rayon::prelude::*;

use crate::geometry::morton::morton_order_in_cells;
use crate::kernel::{Kernel, KernelPoint, SUPPORT_RADIUS};
use crate::measure::{measure_and_gradient, MeasureWorkspace};
use crate::sampling::crease_band::CreaseBand;
use crate::sampling::sizing::SizingField;
use crate::sampling::sweep::{Batches, MAX_BATCH};
use crate::spatial::StaticTree;
use crate::surface::Projection;
use crate::surface::SurfaceSample;

/// Type of one thread's buffers for [`move_one`].
type Scratch = (MeasureWorkspace, Vec<(f64, KernelPoint)>, Vec<KernelPoint>);

thread_local! {
    /// Each thread's buffers for [`move_one`], kept from one batch to the next (a batch is a few
    /// dozen moves: fresh buffers each time would be allocated and grown thousands of times).
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Default::default());
}

/// Parameters of the gradient ascent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GradientAscentParams {
    /// Number of sweeps over all samples (default 10, Sec. 6.3).
    pub iterations: usize,
    /// Step of eq. 11, x ← x + step ∇s(x), in kernel units (default 0.55; eq. 11 prints 0.5):
    /// a little better triangles than 0.5, while 0.6 gave a worse worst triangle and 1.0 and
    /// above oscillate (`docs/decisions/gradient-ascent-step.md`).
    pub step: f64,
    /// Largest move of one sample in one sweep, in units of sigma_p (default 0.25): a guard
    /// against a sample jumping across a thin part of the model.
    pub max_move_sigma_p: f64,
    /// Neighbourhood radius in kernel units (default 2.5, Sec. 6.3).
    pub support_radius: f64,
    /// Move samples one at a time in a seeded random order, each seeing the moves before it
    /// (Sec. 6.2; default true). Runs of consecutive samples in that order of which no two are
    /// neighbours are moved in parallel, with the same result. When false, all samples move at
    /// once from the positions at the start of the sweep, in parallel; that form needs a smaller
    /// step (0.25) to converge and converges more slowly
    /// (`docs/decisions/gradient-ascent-order.md`).
    pub sequential: bool,
    /// Halvings of a step that would lower s (with the neighbours held fixed) before it is taken
    /// anyway (default 0: every step is taken, as in eq. 11): at the default step every step
    /// already raises s, and at larger ones the gain was small for twice the cost of a sweep
    /// (`docs/decisions/gradient-ascent-step.md`).
    pub backtracking: usize,
    /// Samples per window of the sequential sweeps' order (default 4096): the moving samples
    /// are kept along a Z-curve and each sweep takes windows of this many consecutive ones in
    /// a random order, each window's samples in a random order (`sweep_order`), so that the
    /// samples and the input a window reads stay in cache. 1 visits windows of one sample: a
    /// random order over the Z-curve's order.
    pub window: usize,
    /// Moving samples from which the sweeps keep them along a Z-curve and visit them window by
    /// window (default 65,536, about where the samples and the input near them outgrow the
    /// cache: at 8,600 samples on the horse the two orders took the same time). Below, each
    /// sweep visits them in a seeded random permutation of the last sweep's order, the order
    /// before issue 57, and gives the same bytes as before.
    pub cache_order_from: usize,
}

impl Default for GradientAscentParams {
    fn default() -> Self {
        GradientAscentParams {
            iterations: 10,
            step: 0.55,
            max_move_sigma_p: 0.25,
            support_radius: SUPPORT_RADIUS,
            sequential: true,
            backtracking: 0,
            window: 4096,
            cache_order_from: 65_536,
        }
    }
}

/// What the gradient ascent did.
#[derive(Debug, Clone, PartialEq)]
pub struct GradientAscentResult {
    /// Per sweep, the mean distance a sample moved, after projection (bbox-100 units on a
    /// surface; the point set's own units in R^d, `resample_manifold`).
    pub mean_move: Vec<f64>,
    /// Per sweep, the mean and the minimum of s over the moved samples before the sweep's moves.
    pub mean_s: Vec<f64>,
    /// Minimum s per sweep.
    pub min_s: Vec<f64>,
}

/// Moves each of `samples[fixed..]` along the gradient of its spectral measure (eq. 11) and
/// projects it onto `surface` (see [`Projection`]), for `params.iterations` sweeps.
/// `samples[..fixed]` (for example samples on the input's boundary curves) act as neighbours but do
/// not move.
///
/// Neighbourhoods are found once with a kd-tree and kept for all sweeps (Sec. 6.3). By default each
/// sweep visits the samples one at a time in a seeded random order, each move seeing the ones
/// before it (Sec. 6.2; a run of consecutive samples none of which is another's neighbour moves in
/// parallel, which changes nothing); with `sequential = false` all moves of a sweep are computed in
/// parallel from the positions at its start. Either way the result depends only on `seed` (the
/// caller's seed of every random choice: `RemeshParams::seed` in the pipeline).
///
/// The gradient is taken with respect to the position part of x with the sample's normal held
/// fixed; the projection then gives the new position and the normal of the input triangle it lands
/// on. Units: positions in bbox-100 units.
///
/// The kernel is graded by the sizing `field`: each sample's width is its value at the sample's
/// position, taken again after each of its moves ([`Uniform`](crate::sampling::sizing::Uniform):
/// one sigma_p, eq. 11 as printed). The field is treated as locally constant (the pipeline's is
/// piecewise constant, so its gradient is zero almost everywhere): the step is that of
/// [`measure_and_gradient`] with ∇w = 0, scaled by w² (the gradient of s grows as 1/w where the
/// kernel is w times narrower, and a step should be w times shorter), and the largest move is
/// `max_move_sigma_p` · w · sigma_p. With a `band` (the sampled sharp-feature curves), a move into
/// it towards a feature curve is not taken ([`CreaseBand::refuses`]), so no sample reaches or
/// crosses a crease.
#[allow(clippy::too_many_arguments)] // the field and the band beside eq. 11's inputs
pub fn gradient_ascent<S: Projection + ?Sized>(
    kernel: &Kernel,
    surface: &S,
    samples: &mut [SurfaceSample],
    fixed: usize,
    field: &dyn SizingField,
    band: Option<&CreaseBand>,
    params: &GradientAscentParams,
    seed: u64,
) -> GradientAscentResult {
    let uniform = field.is_uniform();
    let embed = |s: &SurfaceSample| {
        if uniform {
            kernel.embed(s.position, s.normal)
        } else {
            kernel.embed_graded(s.position, s.normal, field.width(s.position))
        }
    };
    let n = samples.len();
    let fixed = fixed.min(n);
    let sigma_p = kernel.sigma_p();
    let r_pos = params.support_radius * sigma_p;

    let mut result = GradientAscentResult {
        mean_move: Vec::new(),
        mean_s: Vec::new(),
        min_s: Vec::new(),
    };
    if params.sequential {
        use rand::SeedableRng;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        // From `cache_order_from` moving samples, they are renumbered along a Z-curve over
        // cells of side sigma_p (`local[k]` is `samples[perm[k]]`): a move reads its neighbours
        // and the input near it, and in this numbering both sit together in memory (in the
        // caller's order, often the scan's random one, each of a million moves missed the cache
        // about twenty times).
        let cached = n - fixed >= params.cache_order_from;
        let perm: Vec<u32> = if cached {
            cache_order(samples, fixed, sigma_p)
        } else {
            (0..n as u32).collect()
        };
        let mut local: Vec<SurfaceSample> = perm.iter().map(|&i| samples[i as usize]).collect();
        // Neighbour lists, fixed for all sweeps.
        let lists = neighbour_lists(&local, fixed, r_pos);
        let mut embedded: Vec<KernelPoint> = local.iter().map(embed).collect();
        let mut batches = Batches::new(n, MAX_BATCH);
        let mut order: Vec<usize> = (fixed..n).collect();
        for _ in 0..params.iterations {
            next_sweep(&mut order, cached, fixed, params.window, &mut rng);
            let (mut total_move, mut total_s, mut min_s) = (0.0, 0.0, f64::INFINITY);
            // The samples are taken in `order`, in batches of consecutive ones of which no two
            // are neighbours (`sampling::sweep`).
            let neighbours = |i: usize| lists[i - fixed].as_slice();
            let sweep = batches.sweep(&order, neighbours, |members| {
                // Each move with its sample's new embedding (the field read in parallel too).
                let moves: Vec<((SurfaceSample, f64, f64), KernelPoint)> = members
                    .par_iter()
                    .map(|&i| {
                        let moved = SCRATCH.with_borrow_mut(|(ws, near, sorted)| {
                            move_one(
                                kernel,
                                surface,
                                &embedded,
                                &lists[i - fixed],
                                i,
                                local[i],
                                band,
                                params,
                                ws,
                                near,
                                sorted,
                            )
                        });
                        let x = embed(&moved.0);
                        (moved, x)
                    })
                    .collect();
                for (&i, ((moved, dist, s), x)) in members.iter().zip(moves) {
                    local[i] = moved;
                    embedded[i] = x;
                    total_move += dist;
                    total_s += s;
                    min_s = f64::min(min_s, s);
                }
                Ok::<(), std::convert::Infallible>(())
            });
            if let Err(never) = sweep {
                match never {}
            }
            let m = order.len().max(1) as f64;
            result.mean_move.push(total_move / m);
            result.mean_s.push(total_s / m);
            result.min_s.push(min_s);
        }
        for (k, &i) in perm.iter().enumerate() {
            samples[i as usize] = local[k];
        }
        return result;
    }
    // Neighbour lists, fixed for all sweeps.
    let lists = neighbour_lists(samples, fixed, r_pos);
    for _ in 0..params.iterations {
        let embedded: Vec<KernelPoint> = samples.par_iter().map(embed).collect();
        let moves: Vec<(SurfaceSample, f64, f64)> = (fixed..n)
            .into_par_iter()
            .map_init(
                || {
                    (
                        MeasureWorkspace::new(),
                        Vec::<(f64, KernelPoint)>::new(),
                        Vec::<KernelPoint>::new(),
                    )
                },
                |(ws, near, sorted), i| {
                    let old = samples[i];
                    let r = move_one(
                        kernel,
                        surface,
                        &embedded,
                        &lists[i - fixed],
                        i,
                        old,
                        band,
                        params,
                        ws,
                        near,
                        sorted,
                    );
                    (r.0, r.1, r.2)
                },
            )
            .collect();
        let m = moves.len().max(1) as f64;
        result
            .mean_move
            .push(moves.iter().map(|x| x.1).sum::<f64>() / m);
        result
            .mean_s
            .push(moves.iter().map(|x| x.2).sum::<f64>() / m);
        result
            .min_s
            .push(moves.iter().map(|x| x.2).fold(f64::INFINITY, f64::min));
        for (k, (s, _, _)) in moves.into_iter().enumerate() {
            samples[fixed + k] = s;
        }
    }
    result
}

/// For each sample of `samples[from..]`, the indices of the other samples within `radius` of it
/// (bbox-100 units). Parallel; each list in the tree's order, so deterministic.
fn neighbour_lists(samples: &[SurfaceSample], from: usize, radius: f64) -> Vec<Vec<u32>> {
    let positions: Vec<_> = samples.iter().map(|s| s.position).collect();
    let tree = StaticTree::new(&positions);
    (from..samples.len())
        .into_par_iter()
        .map_init(Vec::new, |found, i| {
            tree.within(positions[i], radius * radius, found);
            found
                .iter()
                .map(|x| x.0)
                .filter(|&j| j as usize != i)
                .collect()
        })
        .collect()
}

/// The order in which the sequential sweeps keep the samples: `samples[..fixed]` as they are,
/// then the moving ones along a Z-curve over cells of side `cell` (bbox-100 units; the sweeps
/// take sigma_p), in index order within a cell. Entry k is the index in `samples` of the k-th
/// sample kept.
///
/// The cells are coarse (about one sample each) and on a grid fixed to multiples of `cell`, so
/// that the order does not turn on the last bits of the positions: the same surface given in
/// f32 and in f64 (a `.glb` and an `.obj`) puts its samples in the same order unless one lies
/// within the rounding of a cell's side (at the finest Morton grid, 2^21 cells over the box, a
/// sample's f32 rounding crosses a cell's side about once in five).
fn cache_order(samples: &[SurfaceSample], fixed: usize, cell: f64) -> Vec<u32> {
    let moving: Vec<glam::DVec3> = samples[fixed..].iter().map(|s| s.position).collect();
    (0..fixed as u32)
        .chain(
            morton_order_in_cells(&moving, cell)
                .into_iter()
                .map(|k| k + fixed as u32),
        )
        .collect()
}

/// The next sweep's visiting `order` of the samples `fixed..` in place: [`sweep_order`] when
/// the samples are kept in cache order (`cached`), else a seeded shuffle of the last order.
fn next_sweep(
    order: &mut Vec<usize>,
    cached: bool,
    fixed: usize,
    window: usize,
    rng: &mut rand_chacha::ChaCha8Rng,
) {
    if cached {
        *order = sweep_order(fixed, fixed + order.len(), window, rng);
    } else {
        use rand::seq::SliceRandom;
        order.shuffle(rng);
    }
}

/// One sweep's visiting order of the samples `fixed..n` (kept in [`cache_order`]): a windowed
/// random order. The samples are cut into windows of `window` consecutive ones (a patch of the
/// surface each), the windows taken in a random order and the samples within each in a random
/// order. Every sample is visited once; the order depends only on `rng`.
fn sweep_order(
    fixed: usize,
    n: usize,
    window: usize,
    rng: &mut rand_chacha::ChaCha8Rng,
) -> Vec<usize> {
    use rand::seq::SliceRandom;
    let window = window.max(1);
    let mut starts: Vec<usize> = (fixed..n).step_by(window).collect();
    starts.shuffle(rng);
    let mut order = Vec::with_capacity(n - fixed.min(n));
    for start in starts {
        let from = order.len();
        order.extend(start..(start + window).min(n));
        order[from..].shuffle(rng);
    }
    order
}

/// One step of eq. 11 for sample `i`: the gradient of s at x_i over its neighbours `list`, a
/// bounded step along it, and the projection onto the surface. Returns the moved sample, the
/// distance moved and s before the move.
#[allow(clippy::too_many_arguments)]
fn move_one<S: Projection + ?Sized>(
    kernel: &Kernel,
    surface: &S,
    embedded: &[KernelPoint],
    list: &[u32],
    i: usize,
    old: SurfaceSample,
    band: Option<&CreaseBand>,
    params: &GradientAscentParams,
    ws: &mut MeasureWorkspace,
    near: &mut Vec<(f64, KernelPoint)>,
    sorted: &mut Vec<KernelPoint>,
) -> (SurfaceSample, f64, f64) {
    let sigma_p = kernel.sigma_p();
    let r_kernel_2 = params.support_radius * params.support_radius;
    let x = embedded[i];
    near.clear();
    for &j in list {
        let y = embedded[j as usize];
        let d2 = x.pair_dist2(&y);
        if d2 <= r_kernel_2 {
            near.push((d2, y));
        }
    }
    near.sort_by(|a, b| a.0.total_cmp(&b.0));
    sorted.clear();
    sorted.extend(near.iter().map(|p| p.1));
    let (s, g) = measure_and_gradient(kernel, &x, [0.0; 3], sorted, ws);
    // Kernel units to position units: Δp = sigma_p · step · w² · ∇_x s (w = 1: eq. 11).
    let w = x.width;
    let mut delta = glam::DVec3::new(g[0], g[1], g[2]) * (params.step * sigma_p * w * w);
    let len = delta.length();
    let max_move = params.max_move_sigma_p * sigma_p * w;
    if len > max_move {
        delta *= max_move / len;
    }
    // The old position is on the surface: the search starts from it.
    let project = |delta: glam::DVec3| {
        surface
            .project_from(old.position + delta, &old)
            .unwrap_or(old)
    };
    let mut moved = project(delta);
    for _ in 0..params.backtracking {
        // Keep the move only if it does not lower s (with the neighbours held where they are).
        let y = kernel.embed_graded(moved.position, moved.normal, w);
        let m = crate::measure::spectral_measure(kernel, &y, sorted.iter().copied(), -1.0, ws);
        if m.s >= s {
            break;
        }
        delta *= 0.5;
        moved = project(delta);
    }
    if band.is_some_and(|b| b.refuses(old.position, moved.position, w)) {
        return (old, 0.0, s);
    }
    (moved, moved.position.distance(old.position), s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes;
    use crate::sampling::sizing::Uniform;
    use crate::surface::candidates::surface_candidates;
    use crate::surface::MeshSurface;
    use rand::SeedableRng;

    /// The sweeps one sample at a time, as Sec. 6.2 writes them, in the sweeps' order
    /// ([`cache_order`], [`sweep_order`]): the reference the batched sweeps must equal.
    fn one_at_a_time(
        kernel: &Kernel,
        surface: &MeshSurface,
        samples: &mut [SurfaceSample],
        params: &GradientAscentParams,
        seed: u64,
    ) {
        let n = samples.len();
        let cached = n >= params.cache_order_from;
        let perm: Vec<u32> = if cached {
            cache_order(samples, 0, kernel.sigma_p())
        } else {
            (0..n as u32).collect()
        };
        let mut local: Vec<SurfaceSample> = perm.iter().map(|&i| samples[i as usize]).collect();
        let lists = neighbour_lists(&local, 0, params.support_radius * kernel.sigma_p());
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut embedded: Vec<KernelPoint> = local
            .iter()
            .map(|s| kernel.embed(s.position, s.normal))
            .collect();
        let (mut ws, mut near, mut sorted) = (MeasureWorkspace::new(), Vec::new(), Vec::new());
        let mut order: Vec<usize> = (0..n).collect();
        for _ in 0..params.iterations {
            next_sweep(&mut order, cached, 0, params.window, &mut rng);
            for &i in &order {
                let (moved, _, _) = move_one(
                    kernel,
                    surface,
                    &embedded,
                    &lists[i],
                    i,
                    local[i],
                    None,
                    params,
                    &mut ws,
                    &mut near,
                    &mut sorted,
                );
                local[i] = moved;
                embedded[i] = kernel.embed(moved.position, moved.normal);
            }
        }
        for (k, &i) in perm.iter().enumerate() {
            samples[i as usize] = local[k];
        }
    }

    /// A sweep's order visits every moving sample once, window by window: each run of `window`
    /// visits is one window's samples, and different seeds give different orders.
    #[test]
    fn the_sweep_order_visits_each_sample_once_window_by_window() {
        let (fixed, n, window) = (7, 7 + 1000, 64);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let order = sweep_order(fixed, n, window, &mut rng);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (fixed..n).collect::<Vec<_>>());
        // The windows start at fixed, fixed + 64, ...; the last holds the 1000 mod 64 = 40 left.
        let mut at = 0;
        while at < order.len() {
            let w = (order[at] - fixed) / window;
            let len = window.min(n - fixed - w * window);
            assert!(
                order[at..at + len]
                    .iter()
                    .all(|&i| (i - fixed) / window == w),
                "window {w} is not visited in one run"
            );
            at += len;
        }
        let again = sweep_order(
            fixed,
            n,
            window,
            &mut rand_chacha::ChaCha8Rng::seed_from_u64(3),
        );
        assert_eq!(order, again);
        let other = sweep_order(
            fixed,
            n,
            window,
            &mut rand_chacha::ChaCha8Rng::seed_from_u64(4),
        );
        assert_ne!(order, other);
    }

    /// The sweeps give the samples of the one-at-a-time order exactly, on one thread and on
    /// several.
    #[test]
    fn the_parallel_sweeps_equal_the_one_at_a_time_order() {
        let mesh = test_meshes::uv_sphere(10.0, 24, 48);
        let surface = MeshSurface::new(&mesh).unwrap();
        let kernel = Kernel::new(2.0, f64::INFINITY).unwrap();
        let start: Vec<SurfaceSample> = surface_candidates(&mesh, 400, 3);
        // The caller's order; cache order in one window, and in windows of 64 samples.
        for (window, cache_order_from) in [(4096, usize::MAX), (4096, 0), (64, 0)] {
            let params = GradientAscentParams {
                window,
                cache_order_from,
                ..Default::default()
            };
            let mut reference = start.clone();
            one_at_a_time(&kernel, &surface, &mut reference, &params, 5);
            assert!(reference
                .iter()
                .zip(&start)
                .all(|(a, b)| a.position != b.position));
            for threads in [1, 2, 3] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let mut samples = start.clone();
                pool.install(|| {
                    gradient_ascent(
                        &kernel,
                        &surface,
                        &mut samples,
                        0,
                        &Uniform,
                        None,
                        &params,
                        5,
                    )
                });
                assert!(
                    samples
                        .iter()
                        .zip(&reference)
                        .all(|(a, b)| a.position == b.position && a.normal == b.normal),
                    "{threads} threads, window {window}, from {cache_order_from}"
                );
            }
        }
    }
}
