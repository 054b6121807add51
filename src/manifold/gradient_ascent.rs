//! Resampling a point set in R^d by gradient ascent on the spectral measure (Sec. 6.2, eq. 11),
//! each move projected onto the manifold by a [`ManifoldProjection`].
//!
//! With α = K^-1 k over a sample's neighbours, s = 1 - k·α and ∇s = 4 Σ_i α_i k_i (x - x_i)
//! (the surface sampler's formula, `measure_and_gradient`), taken over the position part of x
//! with the normal held fixed; the projection gives the new position and normal.

use rand::seq::SliceRandom;
use rand::SeedableRng;
use rayon::prelude::*;

use super::{check_widths, tree_frame, ManifoldProjection, ManifoldResampleParams, PointSet};
use crate::error::{Error, Result};
use crate::kernel::GaussianKernel;
use crate::measure::{solve_alpha, MeasureWorkspace};
use crate::sampling::gradient_ascent::GradientAscentResult;
use crate::sampling::sweep::{Batches, MAX_BATCH};
use crate::spatial::StaticKdTree;

/// One thread's buffers for [`step`]: the measure's workspace, the neighbours with their squared
/// distances, the neighbours nearest first.
type Scratch<const K: usize> = (
    MeasureWorkspace<[f64; K]>,
    Vec<(f64, [f64; K])>,
    Vec<[f64; K]>,
);

/// The parameters checked against the samples (see [`super::resample_manifold`]'s errors).
pub(super) fn check_params(
    samples: &PointSet,
    projection: &dyn ManifoldProjection,
    params: &ManifoldResampleParams,
) -> Result<()> {
    check_widths(samples, params.sigma_p, params.sigma_n)?;
    let bad = |name, message: String| Err(Error::InvalidParameter { name, message });
    for (name, v) in [
        ("step", params.step),
        ("max_move_sigma_p", params.max_move_sigma_p),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return bad(name, format!("must be a finite number >= 0, got {v}"));
        }
    }
    if !(params.support_radius.is_finite() && params.support_radius > 0.0) {
        return bad(
            "support_radius",
            format!("must be a positive number, got {}", params.support_radius),
        );
    }
    if projection.dim() != samples.dim() {
        return bad(
            "project",
            format!(
                "projects points of R^{}, the samples are in R^{}",
                projection.dim(),
                samples.dim()
            ),
        );
    }
    Ok(())
}

/// One sample's step of eq. 11 in kernel units over the position part (the first `d`
/// coordinates), bounded by `max_move`, and s before it.
fn step<const K: usize>(
    x: &[f64; K],
    near: &[[f64; K]],
    d: usize,
    params: &ManifoldResampleParams,
    ws: &mut MeasureWorkspace<[f64; K]>,
) -> ([f64; K], f64) {
    let q = solve_alpha(&GaussianKernel::<K>, x, near, ws);
    let mut g = [0.0; K];
    for (j, alpha, k) in ws.alpha_rows() {
        let c = 4.0 * alpha * k;
        for (gc, (xc, yc)) in g[..d].iter_mut().zip(x.iter().zip(&near[j])) {
            *gc += c * (xc - yc);
        }
    }
    let mut len2 = 0.0;
    for gc in &mut g[..d] {
        *gc *= params.step;
        len2 += *gc * *gc;
    }
    let len = len2.sqrt();
    if len > params.max_move_sigma_p {
        let f = params.max_move_sigma_p / len;
        g[..d].iter_mut().for_each(|gc| *gc *= f);
    }
    (g, (1.0 - q).clamp(0.0, 1.0))
}

/// For each sample, the others within `radius` (kernel units) by position alone (the position
/// part of `embedded`, the first `d` coordinates): a superset of its kernel-space neighbourhood.
fn neighbour_lists<const K: usize>(embedded: &[[f64; K]], d: usize, radius: f64) -> Vec<Vec<u32>> {
    let at: Vec<[f64; K]> = embedded
        .iter()
        .map(|x| {
            let mut p = [0.0; K];
            p[..d].copy_from_slice(&x[..d]);
            tree_frame(&p)
        })
        .collect();
    let tree = StaticKdTree::<K>::new(&at);
    (0..at.len())
        .into_par_iter()
        .map_init(Vec::new, |found, i| {
            tree.within(&at[i], radius * radius, found);
            found
                .iter()
                .map(|f| f.0)
                .filter(|&j| j as usize != i)
                .collect()
        })
        .collect()
}

/// [`super::resample_manifold`] in kernel dimension K (checked parameters).
pub(super) fn resample<const K: usize>(
    samples: &PointSet,
    projection: &dyn ManifoldProjection,
    params: &ManifoldResampleParams,
) -> Result<(PointSet, GradientAscentResult)> {
    resample_in_batches::<K>(samples, projection, params, MAX_BATCH)
}

/// [`resample`] moving at most `max_batch` samples together.
fn resample_in_batches<const K: usize>(
    samples: &PointSet,
    projection: &dyn ManifoldProjection,
    params: &ManifoldResampleParams,
    max_batch: usize,
) -> Result<(PointSet, GradientAscentResult)> {
    let d = samples.dim();
    let n = samples.len();
    let (sigma_p, sigma_n) = (params.sigma_p, params.sigma_n);
    let mut positions = samples.positions().to_vec();
    let mut normals = samples.normals().map(<[f64]>::to_vec);
    let mut embedded: Vec<[f64; K]> = samples.embed::<K>(sigma_p, sigma_n);
    let embed_one = |p: &[f64], nrm: Option<&[f64]>| {
        let mut x = [0.0; K];
        for (c, v) in x.iter_mut().zip(p) {
            *c = v / sigma_p;
        }
        if let (Some(nrm), true) = (nrm, sigma_n.is_finite()) {
            for (c, v) in x[d..].iter_mut().zip(nrm) {
                *c = v / sigma_n;
            }
        }
        x
    };
    let r2 = params.support_radius * params.support_radius;
    let mut result = GradientAscentResult {
        mean_move: Vec::new(),
        mean_s: Vec::new(),
        min_s: Vec::new(),
    };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(params.seed);
    let mut order: Vec<usize> = (0..n).collect();
    let mut batches = Batches::new(n, max_batch);
    let (mut moved, mut moved_normals) = (Vec::new(), Vec::new());
    for _ in 0..params.iterations {
        // Neighbourhoods found again at each sweep's start. Sec. 6.3 keeps them for all sweeps
        // (the samples start near their optimum); over more sweeps two samples just outside
        // each other's lists drift together unseen (Clifford torus, 1000 samples, 20 sweeps:
        // rho 0.27 at one seed of five). A move is at most max_move_sigma_p, so a pair outside
        // the radius at a sweep's start stays beyond 2 in kernel units through the sweep.
        let lists = neighbour_lists::<K>(&embedded, d, params.support_radius);
        order.shuffle(&mut rng);
        let (mut total_move, mut total_s, mut min_s) = (0.0, 0.0, f64::INFINITY);
        // Batches of consecutive samples of which no two are neighbours (`sampling::sweep`):
        // their moves read only samples outside the batch, so together they equal one at a time
        // (and a batch is projected in one call).
        batches.sweep(
            &order,
            |i| lists[i].as_slice(),
            |members| {
                let steps: Vec<([f64; K], f64)> = members
                    .par_iter()
                    .map_init(
                        || (MeasureWorkspace::new(), Vec::new(), Vec::new()),
                        |(ws, near, sorted): &mut Scratch<K>, &i| {
                            let x = embedded[i];
                            near.clear();
                            for &j in &lists[i] {
                                let y = embedded[j as usize];
                                let d2 = GaussianKernel::<K>::dist2(&x, &y);
                                if d2 <= r2 {
                                    near.push((d2, y));
                                }
                            }
                            near.sort_by(|a, b| a.0.total_cmp(&b.0));
                            sorted.clear();
                            sorted.extend(near.iter().map(|p| p.1));
                            step(&x, sorted, d, params, ws)
                        },
                    )
                    .collect();
                moved.clear();
                for (&i, (delta, _)) in members.iter().zip(&steps) {
                    moved.extend((0..d).map(|c| positions[i * d + c] + sigma_p * delta[c]));
                }
                moved_normals.clear();
                if let Some(nrm) = &normals {
                    for &i in members {
                        moved_normals.extend_from_slice(&nrm[i * d..(i + 1) * d]);
                    }
                }
                let with_normals = normals.is_some().then_some(&mut moved_normals[..]);
                projection.project(&mut moved, with_normals)?;
                for (k, (&i, (_, s))) in members.iter().zip(&steps).enumerate() {
                    let p = &moved[k * d..(k + 1) * d];
                    if let Some(c) = p.iter().position(|c| !c.is_finite()) {
                        return Err(Error::InvalidParameter {
                            name: "project",
                            message: format!(
                                "the projection gave sample {i} a coordinate that is not finite \
                             (column {c})"
                            ),
                        });
                    }
                    let dist = p
                        .iter()
                        .zip(&positions[i * d..(i + 1) * d])
                        .map(|(a, b)| (a - b) * (a - b))
                        .sum::<f64>()
                        .sqrt();
                    positions[i * d..(i + 1) * d].copy_from_slice(p);
                    if let Some(nrm) = &mut normals {
                        let m = &mut moved_normals[k * d..(k + 1) * d];
                        let len = m.iter().map(|c| c * c).sum::<f64>().sqrt();
                        if !(len.is_finite() && len > 0.0) {
                            return Err(Error::InvalidParameter {
                                name: "project",
                                message: format!(
                                    "the projection gave sample {i} a normal with no direction"
                                ),
                            });
                        }
                        m.iter_mut().for_each(|c| *c /= len);
                        nrm[i * d..(i + 1) * d].copy_from_slice(m);
                    }
                    embedded[i] = embed_one(
                        &positions[i * d..(i + 1) * d],
                        normals.as_deref().map(|nrm| &nrm[i * d..(i + 1) * d]),
                    );
                    total_move += dist;
                    total_s += s;
                    min_s = f64::min(min_s, *s);
                }
                Ok(())
            },
        )?;
        let m = n.max(1) as f64;
        result.mean_move.push(total_move / m);
        result.mean_s.push(total_s / m);
        result.min_s.push(min_s);
    }
    let out = PointSet::new(d, positions, normals)?;
    Ok((out, result))
}

#[cfg(test)]
mod tests {
    use super::super::{resample_manifold, sample_manifold, ManifoldSampleParams};
    use super::*;
    use crate::measure::spectral_measure;
    use rand::RngExt;

    /// Oracle: the step is 0.55 times the gradient of s, which finite differences of the
    /// measure (eq. 10, another code path) confirm, in R^4 with and without a normal part.
    #[test]
    fn the_step_follows_the_gradient_of_the_measure() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let params = ManifoldResampleParams {
            max_move_sigma_p: f64::INFINITY,
            ..ManifoldResampleParams::new(1.0)
        };
        let mut ws = MeasureWorkspace::new();
        for trial in 0..20 {
            // d = 2 positions and a 2-vector of normal part, in kernel units.
            let pts: Vec<[f64; 4]> = (0..15)
                .map(|_| {
                    [
                        rng.random_range(-2.0..2.0),
                        rng.random_range(-2.0..2.0),
                        rng.random_range(-0.3..0.3),
                        rng.random_range(-0.3..0.3),
                    ]
                })
                .collect();
            let x = [
                rng.random_range(-0.5..0.5),
                rng.random_range(-0.5..0.5),
                0.1,
                0.0,
            ];
            let (g, s) = step(&x, &pts, 2, &params, &mut ws);
            let k = GaussianKernel::<4>;
            let at = |x: [f64; 4], ws: &mut MeasureWorkspace<[f64; 4]>| {
                spectral_measure(&k, &x, pts.iter().copied(), -1.0, ws).s
            };
            assert!((s - at(x, &mut ws)).abs() < 1e-9);
            let h = 1e-6;
            for c in 0..2 {
                let (mut xp, mut xm) = (x, x);
                xp[c] += h;
                xm[c] -= h;
                let fd = (at(xp, &mut ws) - at(xm, &mut ws)) / (2.0 * h);
                let want = params.step * fd;
                assert!(
                    (g[c] - want).abs() < 1e-5 * (1.0 + want.abs()),
                    "trial {trial} axis {c}: {} vs {want}",
                    g[c]
                );
            }
            // The normal part does not move.
            assert_eq!((g[2], g[3]), (0.0, 0.0));
        }
    }

    /// The projection of a unit sphere in R^d: divide by the norm (normals: the position).
    struct Sphere(usize);

    impl ManifoldProjection for Sphere {
        fn dim(&self) -> usize {
            self.0
        }
        fn project(&self, p: &mut [f64], n: Option<&mut [f64]>) -> Result<()> {
            for row in p.chunks_mut(self.0) {
                let len = row.iter().map(|c| c * c).sum::<f64>().sqrt();
                row.iter_mut().for_each(|c| *c /= len);
            }
            if let Some(n) = n {
                n.copy_from_slice(p);
            }
            Ok(())
        }
    }

    /// The sweeps of batches equal one sample at a time (batches of one), on one thread and on
    /// several: every sample the same to the bit, normals included.
    #[test]
    fn batched_sweeps_equal_one_sample_at_a_time() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let xyz: Vec<f64> = (0..3000)
            .flat_map(|_| {
                let v: [f64; 3] = [
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                ];
                let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                v.map(|c| c / l)
            })
            .collect();
        let data = PointSet::new(3, xyz.clone(), Some(xyz)).unwrap();
        let params = ManifoldResampleParams {
            sigma_n: 2.0,
            ..ManifoldResampleParams::new(0.12)
        };
        let picked = sample_manifold(
            &data,
            &ManifoldSampleParams {
                sigma_p: Some(0.12),
                sigma_n: 2.0,
                ..Default::default()
            },
        )
        .unwrap();
        let start = data.subset(&picked.indices);
        let (reference, _) = resample_in_batches::<6>(&start, &Sphere(3), &params, 1).unwrap();
        assert_ne!(reference, start);
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let (got, _) = pool.install(|| resample_manifold(&start, &Sphere(3), &params).unwrap());
            assert_eq!(got, reference, "{threads} threads");
        }
    }

    /// A projection's failure and a non-finite result are errors, not panics.
    #[test]
    fn a_failing_projection_is_an_error() {
        struct Broken(bool);
        impl ManifoldProjection for Broken {
            fn dim(&self) -> usize {
                2
            }
            fn project(&self, p: &mut [f64], _: Option<&mut [f64]>) -> Result<()> {
                if self.0 {
                    return Err(Error::InvalidParameter {
                        name: "project",
                        message: "refused".into(),
                    });
                }
                p[0] = f64::NAN;
                Ok(())
            }
        }
        let pts = PointSet::new(2, vec![0.0, 0.0, 0.1, 0.0, 0.0, 0.1], None).unwrap();
        let params = ManifoldResampleParams::new(0.1);
        let e = resample_manifold(&pts, &Broken(true), &params).unwrap_err();
        assert!(e.to_string().contains("refused"));
        let e = resample_manifold(&pts, &Broken(false), &params).unwrap_err();
        assert!(e.to_string().contains("not finite"), "{e}");
        assert!(resample_manifold(&pts, &Sphere(3), &params).is_err());
    }
}
