//! The sampling and reconstruction kernel of Sec. 3: a point with position p and unit normal n is
//! mapped to x = [p/sigma_p, n/sigma_n] in R^6 and k(x, y) = exp(-|x - y|^2).
//!
//! sigma_p and sigma_n are in bbox-100 units (Sec. 7: models are scaled so that the longest side
//! of their bounding box is 100). sigma_n = infinity gives the isotropic (positions-only) kernel.

use glam::DVec3;

use crate::error::{Error, Result};

/// The neighbourhood radius in kernel space (Sec. 6.3): k(x, y) = exp(-6.25) ≈ 0.0019 beyond it.
pub const SUPPORT_RADIUS: f64 = 2.5;

/// A point mapped to kernel space: `[p/sigma_p, n/sigma_n]` (dimensionless).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KernelPoint(pub [f64; 6]);

impl KernelPoint {
    /// Squared Euclidean distance in kernel space.
    #[inline]
    pub fn dist2(&self, other: &KernelPoint) -> f64 {
        let mut d = 0.0;
        for k in 0..6 {
            let t = self.0[k] - other.0[k];
            d += t * t;
        }
        d
    }

    /// The position part, `p / sigma_p`.
    #[inline]
    pub fn position(&self) -> DVec3 {
        DVec3::new(self.0[0], self.0[1], self.0[2])
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
                name: "--sigma-p",
                message: format!("must be a positive number, got {sigma_p}"),
            });
        }
        if sigma_n.is_nan() || sigma_n <= 0.0 {
            return Err(Error::InvalidParameter {
                name: "--sigma-n",
                message: format!("must be positive (or infinite), got {sigma_n}"),
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

    /// Maps a surface point (position in bbox-100 units, unit normal) to kernel space.
    #[inline]
    pub fn embed(&self, p: DVec3, n: DVec3) -> KernelPoint {
        let q = p / self.sigma_p;
        let m = if self.is_isotropic() {
            DVec3::ZERO
        } else {
            n / self.sigma_n
        };
        KernelPoint([q.x, q.y, q.z, m.x, m.y, m.z])
    }

    /// k(x, y) = exp(-|x - y|^2).
    #[inline]
    pub fn eval(&self, x: &KernelPoint, y: &KernelPoint) -> f64 {
        (-x.dist2(y)).exp()
    }

    /// The radius in position space (bbox-100 units) that holds every point within
    /// [`SUPPORT_RADIUS`] in kernel space: `2.5 sigma_p`.
    pub fn position_support_radius(&self) -> f64 {
        SUPPORT_RADIUS * self.sigma_p
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
    fn bad_widths_are_errors() {
        assert!(Kernel::new(0.0, 1.0).is_err());
        assert!(Kernel::new(f64::NAN, 1.0).is_err());
        assert!(Kernel::new(1.0, -1.0).is_err());
        assert!(Kernel::new(f64::INFINITY, 1.0).is_err());
        assert!(Kernel::new(1.0, f64::INFINITY).is_ok());
    }
}
