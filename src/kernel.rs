//! The sampling and reconstruction kernel of Sec. 3: a point with position p and unit normal n is
//! mapped to x = [p/sigma_p, n/sigma_n] in R^6 and k(x, y) = exp(-|x - y|^2).
//!
//! sigma_p and sigma_n are in bbox-100 units (Sec. 7: models are scaled so that the longest side
//! of their bounding box is 100). sigma_n = infinity gives the isotropic (positions-only) kernel.
//!
//! A graded kernel (issue 15: sample density following the local feature size) gives each point
//! its own spatial width sigma_p(x) = w(x) · sigma_p with w in (0, 1]. Two points then meet with
//! the Gibbs kernel (M. N. Gibbs, *Bayesian Gaussian processes for regression and
//! classification*, PhD thesis, Cambridge 1997, eq. 3.24; C. E. Rasmussen, C. K. I. Williams,
//! *Gaussian Processes for Machine Learning*, MIT Press 2006, eq. 4.32):
//!
//! k(x, y) = (w_x w_y / s²)^{3/2} exp(-|p_x - p_y|² / (s² sigma_p²) - |n_x - n_y|² / sigma_n²),
//! s² = (w_x² + w_y²) / 2,
//!
//! positive definite for any width field (so the measure stays in [0, 1]), k(x, x) = 1, and the
//! kernel above when w_x = w_y = 1.

use glam::DVec3;

use crate::error::{Error, Result};

/// A positive definite kernel with k(x, x) = 1 on points already mapped to kernel space: what
/// the spectral measure (eq. 9, [`spectral_measure`](crate::internal::spectral_measure)) and its
/// evaluation by eq. 10 need of a kernel. The measure's code is written once over this trait;
/// [`Kernel`] (surfaces in R^3, x = [p/sigma_p, n/sigma_n] in R^6) and [`GaussianKernel`]
/// (point sets in R^d, x in R^K) implement it.
pub trait UnitKernel {
    /// A point in kernel space.
    type Point: Copy;
    /// k(x, y), with k(x, x) = 1 and every kernel matrix positive (semi-)definite.
    fn eval(&self, x: &Self::Point, y: &Self::Point) -> f64;
}

/// The neighbourhood radius in kernel space (Sec. 6.3): k(x, y) = exp(-6.25) ≈ 0.0019 beyond it.
pub const SUPPORT_RADIUS: f64 = 2.5;

/// A point mapped to kernel space: `coords = [p/sigma_p, n/sigma_n]` (dimensionless) and its
/// relative spatial width `width` = sigma_p(x) / sigma_p in (0, 1] (1 for the global kernel).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KernelPoint {
    /// `[p/sigma_p, n/sigma_n]`; the normal part is zero for the isotropic kernel.
    pub coords: [f64; 6],
    /// sigma_p(x) / sigma_p, in (0, 1]: 1 everywhere gives the paper's kernel.
    pub width: f64,
}

impl KernelPoint {
    /// Squared Euclidean distance of the coordinates in kernel space (widths ignored).
    #[inline]
    pub fn dist2(&self, other: &KernelPoint) -> f64 {
        let mut d = 0.0;
        for k in 0..6 {
            let t = self.coords[k] - other.coords[k];
            d += t * t;
        }
        d
    }

    /// The exponent of the kernel between the two points: |Δp|² / s² + |Δn|² (see the module
    /// docs; [`KernelPoint::dist2`] when both widths are 1). Points beyond
    /// [`SUPPORT_RADIUS`]² of each other in this measure contribute less than exp(-6.25).
    #[inline]
    pub fn pair_dist2(&self, other: &KernelPoint) -> f64 {
        if self.width == 1.0 && other.width == 1.0 {
            return self.dist2(other);
        }
        self.graded_dist2(other, self.pair_s2(other))
    }

    /// s² = (w_x² + w_y²) / 2 of the pair (see the module docs).
    #[inline]
    fn pair_s2(&self, other: &KernelPoint) -> f64 {
        0.5 * (self.width * self.width + other.width * other.width)
    }

    /// |Δp|² / s2 + |Δn|².
    #[inline]
    fn graded_dist2(&self, other: &KernelPoint, s2: f64) -> f64 {
        let (mut dp, mut dn) = (0.0, 0.0);
        for k in 0..3 {
            let t = self.coords[k] - other.coords[k];
            dp += t * t;
            let t = self.coords[k + 3] - other.coords[k + 3];
            dn += t * t;
        }
        dp / s2 + dn
    }

    /// The position part, `p / sigma_p`.
    #[inline]
    pub fn position(&self) -> DVec3 {
        DVec3::new(self.coords[0], self.coords[1], self.coords[2])
    }
}

/// The Gaussian kernel k(x, y) = exp(-|x - y|^2) on x = [p/sigma_p, n/sigma_n] (Sec. 3, after
/// Öztireli, Guennebaud, Gross 2009, "Feature preserving point set surfaces based on non-linear
/// kernel regression").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kernel {
    sigma_p: f64,
    sigma_n: f64,
}

impl Kernel {
    /// A kernel with spatial width `sigma_p` (> 0, bbox-100 units) and normal width `sigma_n`
    /// (> 0; `f64::INFINITY` for positions only).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when a width is not positive, or sigma_p is not finite.
    pub fn new(sigma_p: f64, sigma_n: f64) -> Result<Self> {
        if !(sigma_p.is_finite() && sigma_p > 0.0) {
            return Err(Error::InvalidParameter {
                name: "sigma_p",
                message: format!(
                    "must be a positive number, got {}",
                    crate::error::shown(sigma_p)
                ),
            });
        }
        if sigma_n.is_nan() || sigma_n <= 0.0 {
            return Err(Error::InvalidParameter {
                name: "sigma_n",
                message: format!(
                    "must be positive (or infinite), got {}",
                    crate::error::shown(sigma_n)
                ),
            });
        }
        Ok(Kernel { sigma_p, sigma_n })
    }

    /// Spatial width sigma_p (bbox-100 units).
    pub fn sigma_p(&self) -> f64 {
        self.sigma_p
    }

    /// Normal width sigma_n (infinite for the isotropic kernel).
    pub fn sigma_n(&self) -> f64 {
        self.sigma_n
    }

    /// Whether the kernel ignores normals (sigma_n = infinity).
    pub fn is_isotropic(&self) -> bool {
        self.sigma_n.is_infinite()
    }

    /// Maps a surface point (position in bbox-100 units, unit normal) to kernel space, with the
    /// global width (`width` 1).
    #[inline]
    pub fn embed(&self, p: DVec3, n: DVec3) -> KernelPoint {
        self.embed_graded(p, n, 1.0)
    }

    /// Maps a surface point to kernel space with its own spatial width `width` · sigma_p
    /// (`width` in (0, 1]; see the module docs).
    #[inline]
    pub fn embed_graded(&self, p: DVec3, n: DVec3, width: f64) -> KernelPoint {
        let q = p / self.sigma_p;
        let m = if self.is_isotropic() {
            DVec3::ZERO
        } else {
            n / self.sigma_n
        };
        KernelPoint {
            coords: [q.x, q.y, q.z, m.x, m.y, m.z],
            width,
        }
    }

    /// k(x, y): exp(-|x - y|^2) for two points of width 1, the Gibbs kernel of the module docs
    /// otherwise.
    #[inline]
    pub fn eval(&self, x: &KernelPoint, y: &KernelPoint) -> f64 {
        if x.width == 1.0 && y.width == 1.0 {
            return (-x.dist2(y)).exp();
        }
        let s2 = x.pair_s2(y);
        let r = x.width * y.width / s2;
        r * r.sqrt() * (-x.graded_dist2(y, s2)).exp()
    }

    /// The radius in position space (bbox-100 units) that holds every point within
    /// [`SUPPORT_RADIUS`] in kernel space: `2.5 sigma_p`.
    pub fn position_support_radius(&self) -> f64 {
        SUPPORT_RADIUS * self.sigma_p
    }
}

impl UnitKernel for Kernel {
    type Point = KernelPoint;

    #[inline]
    fn eval(&self, x: &KernelPoint, y: &KernelPoint) -> f64 {
        Kernel::eval(self, x, y)
    }
}

/// The paper's Gaussian k(x, y) = exp(-|x - y|²) (Sec. 3) on points of R^K already scaled to
/// kernel space: x = [p/sigma_p, n/sigma_n] for a point p of R^d with a normal n (K = 2d), or
/// x = p/sigma_p with positions only (K = d). The kernel of point sets near a manifold of any
/// dimension (the paper's abstract and Sec. 3; [`crate::manifold`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct GaussianKernel<const K: usize>;

impl<const K: usize> GaussianKernel<K> {
    /// Squared Euclidean distance in kernel space, |x - y|².
    #[inline]
    pub fn dist2(x: &[f64; K], y: &[f64; K]) -> f64 {
        let mut d = 0.0;
        for k in 0..K {
            let t = x[k] - y[k];
            d += t * t;
        }
        d
    }
}

impl<const K: usize> UnitKernel for GaussianKernel<K> {
    type Point = [f64; K];

    #[inline]
    fn eval(&self, x: &[f64; K], y: &[f64; K]) -> f64 {
        (-Self::dist2(x, y)).exp()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernel_is_one_on_the_diagonal_and_decays() {
        let k = Kernel::new(2.0, f64::INFINITY).unwrap();
        let x = k.embed(DVec3::ZERO, DVec3::Z);
        let y = k.embed(DVec3::new(2.0, 0.0, 0.0), -DVec3::Z);
        assert_eq!(k.eval(&x, &x), 1.0);
        // |p|/sigma_p = 1; normals ignored.
        assert!((k.eval(&x, &y) - (-1.0f64).exp()).abs() < 1e-15);
        let kn = Kernel::new(2.0, 1.0).unwrap();
        let xn = kn.embed(DVec3::ZERO, DVec3::Z);
        let yn = kn.embed(DVec3::new(2.0, 0.0, 0.0), -DVec3::Z);
        // 1 + |2 z|^2 = 5.
        assert!((kn.eval(&xn, &yn) - (-5.0f64).exp()).abs() < 1e-15);
    }

    #[test]
    fn the_gaussian_in_r_k_is_the_surface_kernel_on_the_same_coordinates() {
        let k = Kernel::new(1.7, 0.6).unwrap();
        let x = k.embed(DVec3::new(0.3, -1.2, 2.0), DVec3::new(0.6, 0.0, 0.8));
        let y = k.embed(DVec3::new(1.1, -0.4, 2.5), DVec3::Z);
        assert_eq!(
            GaussianKernel::<6>.eval(&x.coords, &y.coords),
            k.eval(&x, &y)
        );
        assert_eq!(GaussianKernel::<2>.eval(&[0.5, 1.0], &[0.5, 1.0]), 1.0);
        assert!(
            (GaussianKernel::<2>.eval(&[0.0, 0.0], &[1.0, 1.0]) - (-2.0f64).exp()).abs() < 1e-16
        );
    }

    #[test]
    fn bad_widths_are_errors() {
        assert!(Kernel::new(0.0, 1.0).is_err());
        assert!(Kernel::new(f64::NAN, 1.0).is_err());
        assert!(Kernel::new(1.0, -1.0).is_err());
        assert!(Kernel::new(f64::INFINITY, 1.0).is_err());
        assert!(Kernel::new(1.0, f64::INFINITY).is_ok());
    }
}
