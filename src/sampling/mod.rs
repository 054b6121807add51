//! Sampling a surface with the spectral measure (Sec. 6): candidates on the input surface, the
//! randomized linear scan (Algorithm 1), gradient-ascent resampling (eq. 11), and the search for
//! the sigma_p that yields a target count.

pub mod boundary;
pub mod crease_band;
pub mod curves;
pub mod features;
pub mod gradient_ascent;
pub mod grading;
pub mod linear_scan;
pub mod spacing;
pub mod target_count;

/// A field of relative kernel widths w(p) in (0, 1] over positions (bbox-100 units): a graded
/// kernel's sigma_p(p) = w(p) · sigma_p (see [`Kernel`](crate::internal::Kernel)).
pub type WidthField<'a> = &'a (dyn Fn(glam::DVec3) -> f64 + Sync);
