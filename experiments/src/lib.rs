//! # spectral-experiments
//!
//! The experiments of *Spectral Sampling of Manifolds* (A. C. Öztireli, M. Alexa, M. Gross,
//! SIGGRAPH Asia 2010, doi:10.1145/1882261.1866190), apart from the product: they run on the
//! `spectral-remesh` library (its kernel, measure, linear scan, RIMLS surface and quality
//! ruler) but nothing in the product uses them.
//!
//! - [`plane`]: blue noise on the periodic unit square (Sec. 7.1, Fig. 11), the paper's samplers
//!   and the baselines, with the measures of Lagae and Dutré 2008 and Ulichney 1987.
//! - [`reconstruction_eval`]: reconstruction accuracy (Sec. 7.2, Table 2): the RIMLS surface of
//!   all points against that of subsets chosen by the linear scan and by [`subsample`]'s
//!   baselines, each triangulated by [`marching_cubes`] ([`reconstruct`]).
//!
//! The binary `spectral-experiments` runs both (`blue-noise`, `reconstruct-eval`); the scripts in
//! `eval/` (`eval/blue_noise`, `eval/reconstruction`) draw the figures and tables.

pub mod marching_cubes;
pub mod plane;
pub mod reconstruct;
pub mod reconstruction_eval;
pub mod subsample;
#[cfg(test)]
pub(crate) mod test_points;
