//! Blue noise in the plane (Sec. 7.1, Fig. 11): the paper's samplers on the periodic unit square,
//! the baselines it is compared with, and the measures of Lagae and Dutré 2008 and Ulichney 1987.
//!
//! - `torus.rs`: wrapping, toroidal distances, a uniform grid on the torus.
//! - `spectral.rs`: gradient ascent (eq. 11) and the linear scan (Algorithm 1) on the torus;
//!   path A (random start) and path B (dense set, scan, then ascent).
//! - `lloyd.rs`: Lloyd's method with exact periodic Voronoi cells.
//! - `dart_throwing.rs`: dart throwing to n points at a fixed radius.
//! - `analysis.rs`: normalized Poisson-disk radius, periodogram, radial power and anisotropy.
//! - `experiment.rs`: several sets by one method and their analysis, as a JSON report.
//!
//! Units: positions in [0, 1)², lengths in units of the square's side, frequencies as integer
//! vectors (reported in units of sqrt(n)).

pub mod analysis;
pub mod dart_throwing;
pub mod experiment;
pub mod lloyd;
pub mod spectral;
pub mod torus;

pub use experiment::{run_blue_noise, BlueNoiseParams, BlueNoiseReport, Method};
