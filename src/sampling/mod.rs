//! Sampling a surface with the spectral measure (Sec. 6): candidates on the input surface, the
//! randomized linear scan (Algorithm 1), gradient-ascent resampling (eq. 11), and the search for
//! the sigma_p that yields a target count.

pub mod boundary;
pub mod crease_band;
pub mod crease_curvature;
pub mod crease_ladder;
pub mod crease_separation;
pub mod curves;
pub mod features;
pub mod gradient_ascent;
pub mod grading;
pub mod linear_scan;
pub mod sizing;
pub mod spacing;
pub(crate) mod sweep;
pub mod target_count;
