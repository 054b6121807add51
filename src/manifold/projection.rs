//! What the gradient ascent in R^d projects its samples onto (Sec. 6.2: "moved ... and projected
//! onto the surface"): a [`ManifoldProjection`]. The library's own, [`DataProjection`], projects
//! onto the point set itself by a local quadratic fit: the nearest data points' centroid c and
//! principal directions (local PCA) give m tangent and d - m normal directions, the normal
//! offsets of the neighbours are fitted by least squares as a quadratic function of their tangent
//! coordinates, and the point goes to that graph above its own tangent coordinates; taken again
//! at the projected point. On a dense sampling of a smooth manifold this is the closest point to
//! within O(r³) for a neighbourhood of radius r (a plane through c alone sags κ r² / 2: 0.006 on
//! the unit 3-sphere from 100k points).

use nalgebra::{DMatrix, SymmetricEigen};
use rayon::prelude::*;

use super::{estimate_dimension, tree_frame, with_kernel_dim, PointSet};
use crate::error::{Error, Result};
use crate::spatial::StaticKdTree;

/// Rounds of the local fit per projection: the neighbourhood is found again around the point
/// projected by the round before.
pub const PROJECTION_ITERATIONS: usize = 2;

/// Projects points of R^d onto a manifold, in place. Implemented by [`DataProjection`] (onto a
/// point set) and by callers that know their manifold exactly (a sphere: divide by the norm).
pub trait ManifoldProjection {
    /// The dimension d of the points it projects.
    fn dim(&self) -> usize;

    /// Projects each row of `positions` (`m × dim()` values, row-major, the point set's units)
    /// onto the manifold; with `normals` (the same shape), writes each row's unit normal at its
    /// projected position.
    ///
    /// # Errors
    /// Whatever stops the projection (a caller's own projection may fail); the gradient ascent
    /// returns it.
    fn project(&self, positions: &mut [f64], normals: Option<&mut [f64]>) -> Result<()>;
}

/// Coordinates of x - c along some of the local fit's axes: `coords(x, axes)`.
type AxisCoords<'a> = dyn Fn(&[f64], &[usize]) -> Vec<f64> + 'a;

/// The k nearest data points of a query, by position, in the kd-tree of the right dimension.
trait NearestRows: Send + Sync {
    /// The `k` nearest data points to `p` (d coordinates), nearest first, into `out` as
    /// `(index, squared distance)`.
    fn nearest_n(&self, p: &[f64], k: usize, out: &mut Vec<(u32, f64)>);
}

/// A kd-tree over the data's positions in R^K (K = d), in the frame of [`tree_frame`].
struct Rows<const K: usize>(StaticKdTree<K>);

impl<const K: usize> NearestRows for Rows<K> {
    fn nearest_n(&self, p: &[f64], k: usize, out: &mut Vec<(u32, f64)>) {
        let mut q = [0.0; K];
        q.copy_from_slice(p);
        self.0.nearest_n(&tree_frame(&q), k, out);
    }
}

/// The projection onto a point set near an m-dimensional manifold in R^d by a local quadratic
/// fit (see the module docs): each round takes the nearest `neighbours` data points (2^(m+2), at
/// most 64: 8 on a curve, 16 on a surface, 32 on a 3-manifold), their centroid c, the m
/// eigenvectors U of their covariance with the largest eigenvalues and the d - m others N, fits
/// the neighbours' normal offsets N^T (x - c) as a quadratic h(t) of t = U^T (x - c) (least
/// squares; a plane, h = 0, where the neighbours are fewer than twice the quadratic's
/// coefficients), and moves p to c + U t_p + N h(t_p), t_p = U^T (p - c). The normal of a
/// projected point is that of the nearest data point.
pub struct DataProjection {
    dim: usize,
    manifold_dim: usize,
    neighbours: usize,
    positions: Vec<f64>,
    normals: Option<Vec<f64>>,
    tree: Box<dyn NearestRows>,
}

impl DataProjection {
    /// The projection onto `data`, near a manifold of dimension `manifold_dim` (`None`: estimated
    /// with [`estimate_dimension`], seeded by `seed`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when `manifold_dim` is not from 1 to the space's dimension.
    pub fn new(data: &PointSet, manifold_dim: Option<usize>, seed: u64) -> Result<Self> {
        let d = data.dim();
        let m = match manifold_dim {
            Some(m) if m == 0 || m > d => {
                return Err(Error::InvalidParameter {
                    name: "dim",
                    message: format!(
                        "the manifold's dimension must be from 1 to the space's {d}, got {m}"
                    ),
                })
            }
            Some(m) => m,
            None => estimate_dimension(data, seed).round_dimension(d),
        };
        let tree: Box<dyn NearestRows> = with_kernel_dim!(d, K => {
            Box::new(Rows::<K>(data.position_tree::<K>().1))
        }, return Err(Error::Internal {
            stage: "projection",
            message: format!("no kd-tree built for dimension {d}"),
        }));
        Ok(DataProjection {
            dim: d,
            manifold_dim: m,
            neighbours: (1usize << (m + 2).min(6)).min(data.len()),
            positions: data.positions().to_vec(),
            normals: data.normals().map(<[f64]>::to_vec),
            tree,
        })
    }

    /// The dimension m of the manifold it projects onto (given or estimated).
    pub fn manifold_dim(&self) -> usize {
        self.manifold_dim
    }

    /// One point projected in place; its normal written to `normal` when given.
    fn project_one(&self, p: &mut [f64], normal: Option<&mut [f64]>, found: &mut Vec<(u32, f64)>) {
        let d = self.dim;
        let row = |i: u32| &self.positions[i as usize * d..(i as usize + 1) * d];
        if self.manifold_dim < d {
            for _ in 0..PROJECTION_ITERATIONS {
                self.tree.nearest_n(p, self.neighbours, found);
                let k = found.len() as f64;
                let mut c = vec![0.0; d];
                for &(i, _) in found.iter() {
                    c.iter_mut().zip(row(i)).for_each(|(c, x)| *c += x / k);
                }
                let mut cov = DMatrix::<f64>::zeros(d, d);
                for &(i, _) in found.iter() {
                    let r = row(i);
                    for a in 0..d {
                        for b in 0..d {
                            cov[(a, b)] += (r[a] - c[a]) * (r[b] - c[b]);
                        }
                    }
                }
                let eig = SymmetricEigen::new(cov);
                let mut axes: Vec<usize> = (0..d).collect();
                axes.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
                let (tangent, normal) = axes.split_at(self.manifold_dim);
                // Coordinates of x - c along the given axes.
                let coords = |x: &[f64], along: &[usize]| -> Vec<f64> {
                    along
                        .iter()
                        .map(|&a| {
                            let u = eig.eigenvectors.column(a);
                            (0..d).map(|k| u[k] * (x[k] - c[k])).sum()
                        })
                        .collect()
                };
                let t_p = coords(p, tangent);
                let h_p = self.fitted_offsets(found, &coords, tangent, normal, &t_p);
                p.copy_from_slice(&c);
                for (&a, v) in tangent.iter().chain(normal).zip(t_p.iter().chain(&h_p)) {
                    let u = eig.eigenvectors.column(a);
                    for k in 0..d {
                        p[k] += v * u[k];
                    }
                }
            }
        }
        if let (Some(out), Some(normals)) = (normal, &self.normals) {
            self.tree.nearest_n(p, 1, found);
            if let Some(&(i, _)) = found.first() {
                out.copy_from_slice(&normals[i as usize * d..(i as usize + 1) * d]);
            }
        }
    }
}

impl DataProjection {
    /// The normal offsets at tangent coordinates `t_p` of the quadratic fitted by least squares
    /// to the neighbours `found` (tangent coordinates `coords(x, tangent)`, normal offsets
    /// `coords(x, normal)`); zeros (the plane through the centroid) when the neighbours are
    /// fewer than twice the quadratic's coefficients.
    fn fitted_offsets(
        &self,
        found: &[(u32, f64)],
        coords: &AxisCoords<'_>,
        tangent: &[usize],
        normal: &[usize],
        t_p: &[f64],
    ) -> Vec<f64> {
        let d = self.dim;
        let m = tangent.len();
        let features = 1 + m + m * (m + 1) / 2;
        if normal.is_empty() || found.len() < 2 * features {
            return vec![0.0; normal.len()];
        }
        let row = |i: u32| &self.positions[i as usize * d..(i as usize + 1) * d];
        let t: Vec<Vec<f64>> = found
            .iter()
            .map(|&(i, _)| coords(row(i), tangent))
            .collect();
        // Tangent coordinates in units of the neighbourhood's radius: features of order 1 at
        // any scale of the data.
        let radius = t
            .iter()
            .map(|t| t.iter().map(|t| t * t).sum::<f64>())
            .fold(0.0, f64::max)
            .sqrt();
        if !(radius > 0.0) {
            return vec![0.0; normal.len()];
        }
        let phi = |t: &[f64]| {
            let t: Vec<f64> = t.iter().map(|t| t / radius).collect();
            let mut f = Vec::with_capacity(features);
            f.push(1.0);
            f.extend_from_slice(&t);
            for a in 0..m {
                for b in a..m {
                    f.push(t[a] * t[b]);
                }
            }
            f
        };
        let mut design = DMatrix::<f64>::zeros(found.len(), features);
        let mut offsets = DMatrix::<f64>::zeros(found.len(), normal.len());
        for (r, (&(i, _), t)) in found.iter().zip(&t).enumerate() {
            for (col, v) in phi(t).into_iter().enumerate() {
                design[(r, col)] = v;
            }
            for (col, v) in coords(row(i), normal).into_iter().enumerate() {
                offsets[(r, col)] = v;
            }
        }
        let Ok(w) = design.svd(true, true).solve(&offsets, 1e-12) else {
            return vec![0.0; normal.len()];
        };
        let f = phi(t_p);
        (0..normal.len())
            .map(|col| (0..features).map(|r| f[r] * w[(r, col)]).sum())
            .collect()
    }
}

impl ManifoldProjection for DataProjection {
    fn dim(&self) -> usize {
        self.dim
    }

    /// Each row projected as the type's docs say, rows in parallel. Rows of a point set without
    /// normals keep the normals given.
    fn project(&self, positions: &mut [f64], normals: Option<&mut [f64]>) -> Result<()> {
        let d = self.dim;
        match normals {
            Some(n) => positions
                .par_chunks_mut(d)
                .zip(n.par_chunks_mut(d))
                .for_each_init(Vec::new, |found, (p, n)| {
                    self.project_one(p, Some(n), found)
                }),
            None => positions
                .par_chunks_mut(d)
                .for_each_init(Vec::new, |found, p| self.project_one(p, None, found)),
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    #[test]
    fn points_off_a_dense_circle_come_back_onto_it() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let xy: Vec<f64> = (0..50_000)
            .flat_map(|_| {
                let t: f64 = rng.random_range(0.0..std::f64::consts::TAU);
                [t.cos(), t.sin()]
            })
            .collect();
        let normals = xy.clone();
        let data = PointSet::new(2, xy, Some(normals)).unwrap();
        let proj = DataProjection::new(&data, None, 1).unwrap();
        assert_eq!(proj.manifold_dim(), 1);
        let mut worst: f64 = 0.0;
        for k in 0..200 {
            let t = k as f64 * 0.0314;
            let r = 1.0 + 0.01 * ((k % 5) as f64 - 2.0);
            let mut p = [r * t.cos(), r * t.sin()];
            let mut n = [0.0, 0.0];
            proj.project(&mut p, Some(&mut n)).unwrap();
            let radius = (p[0] * p[0] + p[1] * p[1]).sqrt();
            worst = worst.max((radius - 1.0).abs());
            // The tangential position is kept: the angle moves by far less than the offset.
            let dt = (p[1].atan2(p[0]) - t.sin().atan2(t.cos())).abs();
            assert!(dt < 1e-3, "angle moved {dt}");
            // The normal is the radial direction there.
            assert!(n[0] * p[0] + n[1] * p[1] > 0.999);
        }
        // The data's spacing is 1.3e-4; eight neighbours span about 5e-4.
        assert!(worst < 1e-9, "{worst}");
    }

    #[test]
    fn a_dimension_out_of_range_is_an_error() {
        let data = PointSet::new(2, vec![0.0, 0.0, 1.0, 0.0], None).unwrap();
        assert!(DataProjection::new(&data, Some(3), 1).is_err());
        assert!(DataProjection::new(&data, Some(0), 1).is_err());
        let full = DataProjection::new(&data, Some(2), 1).unwrap();
        let mut p = [0.3, 0.4];
        full.project(&mut p, None).unwrap();
        assert_eq!(p, [0.3, 0.4]);
    }
}
