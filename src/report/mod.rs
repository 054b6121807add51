//! The quality report: the triangle measures of the paper's Table 1, topology, invariants, and
//! distance to the input surface.
//!
//! The project's one ruler. The table of measures, their determinism and their sources are in the
//! docs of [`QualityReport`] (the module is private; those are the rendered docs).

mod distance;
mod quality_report;
mod triangle_quality;

pub use distance::{
    surface_distance, surface_distance_with, surface_samples, PointSetDistance, SurfaceDistance,
};
pub use quality_report::{QualityReport, StageTime};
pub use triangle_quality::{triangle_quality, TriangleQuality};
