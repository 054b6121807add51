//! Sampling a surface with the spectral measure (Sec. 6): candidates on the input surface, the
//! randomized linear scan (Algorithm 1), gradient-ascent resampling (eq. 11), and the search for
//! the sigma_p that yields a target count.

pub mod boundary;
pub mod candidates;
pub mod gradient_ascent;
pub mod linear_scan;
pub mod surface_sampler;
pub mod target_count;

use glam::DVec3;

/// A point on the input surface: position (bbox-100 units), the unit normal of the input
/// triangle it lies on (the n of the kernel's x = [p/sigma_p, n/sigma_n]), and that triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceSample {
    /// Position, bbox-100 units.
    pub position: DVec3,
    /// Unit normal of the input surface at `position`.
    pub normal: DVec3,
    /// Index of the input triangle `position` lies on.
    pub face: u32,
}
