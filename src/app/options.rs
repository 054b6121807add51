//! The `remesh` command line's pipeline options as plain values, and the one translation of them
//! into [`RemeshParams`]: the binary and the Python bindings both go through
//! [`RemeshOptions::params`], so the same options give the same pipeline, byte for byte.

use crate::error::{Error, Result};
use crate::finish::optimize::SMOOTH_ITERATIONS;
use crate::pipeline::{Density, RemeshParams, FIT_ITERATIONS};
use crate::sampling::grading::GradingParams;
use crate::surface::curvature::CurvatureParams;
use crate::surface::features::FeatureDetection;
use crate::triangulate::{RestrictedDelaunayParams, TriangulationMethod};

/// The most sweeps `--iterations` (gradient ascent), `--smooth` (finishing relaxation) and
/// `simplify --resample` take: 1000, a hundred times the defaults (the ascent has converged
/// after a few tens, Sec. 5.2); more only runs longer.
pub const MAX_SWEEPS: usize = 1000;

/// The pipeline options of `remesh INPUT OUTPUT`, one field per flag, as given (unchecked);
/// [`RemeshOptions::default`] holds the command line's defaults. Lengths are in bbox-100 units
/// (the input scaled so its bounding box's longest side is 100), angles in degrees.
#[derive(Debug, Clone, PartialEq)]
pub struct RemeshOptions {
    /// `--points N`: about N output vertices (sigma_p searched for). `None` with `sigma_p`
    /// `None` too: as many as the input has vertices.
    pub points: Option<usize>,
    /// `--sigma-p S`: the kernel width, instead of `points` (giving both is an error).
    pub sigma_p: Option<f64>,
    /// `--edge-length L`: output edges about L long (model units, the input's own), instead of
    /// `points` or `sigma_p`: for a mesh the count of equilateral triangles of that edge on the
    /// input's area, for a point set sigma_p = L / 1.2 in bbox-100 units (its sampling's mean
    /// edge is 1.2 sigma_p).
    pub edge_length: Option<f64>,
    /// `--sigma-n S`: the normal width; `None` is infinity (isotropic sampling).
    pub sigma_n: Option<f64>,
    /// `--lfs-factor C`: the sizing field from the local feature size with ε = C, the spacing
    /// h(x) = ε · lfs(x) where that is below sigma_p; 0 turns it off (one sigma_p everywhere,
    /// the paper's sampling).
    pub lfs_factor: f64,
    /// `--chord-error E`: the spacing follows the curvature; 0 turns it off.
    pub chord_error: f64,
    /// `--no-fit`: no least-squares vertex placement (the vertices stay on the input).
    pub no_fit: bool,
    /// `--smooth N`: iterations of the finishing relaxation.
    pub smooth: usize,
    /// `--min-angle DEG`: the smallest angle the last optimization pass works towards, in
    /// [0, 60).
    pub min_angle: f64,
    /// `--max-angle DEG`: the largest angle it works towards, in (60, 180].
    pub max_angle: f64,
    /// `--feature-angle DEG`: keep every crease found at DEG (0 to 180); `None`: automatic at
    /// 20°.
    pub feature_angle: Option<f64>,
    /// `--no-features`: no crease detection (giving `feature_angle` too is an error).
    pub no_features: bool,
    /// `--triangulation METHOD`: `restricted` (restricted Delaunay) or `umbrellas`.
    pub triangulation: String,
    /// `--iterations K`: gradient-ascent sweeps.
    pub iterations: usize,
    /// `--seed S`: the seed of every random choice.
    pub seed: u64,
}

impl Default for RemeshOptions {
    /// The command line's defaults (a test of the binary checks that they agree).
    fn default() -> Self {
        RemeshOptions {
            points: None,
            sigma_p: None,
            edge_length: None,
            sigma_n: None,
            lfs_factor: 0.0,
            chord_error: 0.0,
            no_fit: false,
            smooth: SMOOTH_ITERATIONS,
            min_angle: 35.0,
            max_angle: 100.0,
            feature_angle: None,
            no_features: false,
            triangulation: "restricted".to_string(),
            iterations: 10,
            seed: 1,
        }
    }
}

impl RemeshOptions {
    /// The pipeline parameters these options give.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`], naming the flag as the command line spells it, for a
    /// negative or non-finite `lfs_factor` or `chord_error`, a `feature_angle` outside 0–180,
    /// an unknown `triangulation`, angle bounds outside their ranges, or options that exclude
    /// each other (two of `points`, `sigma_p` and `edge_length`, `feature_angle` with
    /// `no_features`). The other
    /// ranges (`points`, `sigma_p`, `sigma_n`) are checked by the pipeline itself.
    pub fn params(&self) -> Result<RemeshParams> {
        let density = match (self.points, self.sigma_p, self.edge_length) {
            (Some(n), None, None) => Density::Points(n),
            (None, Some(s), None) => Density::SigmaP(s),
            (None, None, Some(l)) => Density::EdgeLength(l),
            (None, None, None) => Density::InputVertices,
            _ => {
                return Err(Error::InvalidParameter {
                    name: "points",
                    message: "give one of `points`, `sigma_p` and `edge_length`".into(),
                })
            }
        };
        let mut params = RemeshParams {
            density,
            seed: self.seed,
            ..Default::default()
        };
        for (name, value) in [("iterations", self.iterations), ("smooth", self.smooth)] {
            if value > MAX_SWEEPS {
                return Err(Error::InvalidParameter {
                    name,
                    message: format!("must be at most {MAX_SWEEPS}, got {value}"),
                });
            }
        }
        params.gradient_ascent.iterations = self.iterations;
        if !(self.lfs_factor.is_finite() && self.lfs_factor >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "lfs_factor",
                message: format!(
                    "must be a number >= 0, got {}",
                    crate::error::shown(self.lfs_factor)
                ),
            });
        }
        params.features = match self.feature_angle {
            Some(_) if self.no_features => {
                return Err(Error::InvalidParameter {
                    name: "feature_angle",
                    message: "give `feature_angle` or `no_features`, not both".into(),
                })
            }
            _ if self.no_features => FeatureDetection::Off,
            None => FeatureDetection::Auto,
            Some(a) if (0.0..=180.0).contains(&a) => FeatureDetection::Angle(a),
            Some(a) => {
                return Err(Error::InvalidParameter {
                    name: "feature_angle",
                    message: format!("must be an angle from 0 to 180 degrees, got {a}"),
                })
            }
        };
        params.triangulation = match self.triangulation.as_str() {
            "umbrellas" => TriangulationMethod::Umbrellas,
            "restricted" => TriangulationMethod::RestrictedDelaunay(Default::default()),
            "restricted-clipped" | "restricted-refined" => {
                TriangulationMethod::RestrictedDelaunay(RestrictedDelaunayParams {
                    clipped: self.triangulation == "restricted-clipped",
                    ..Default::default()
                })
            }
            other => {
                return Err(Error::InvalidParameter {
                    name: "triangulation",
                    message: format!(
                        "must be umbrellas, restricted, restricted-clipped or \
                         restricted-refined, got {other}"
                    ),
                })
            }
        };
        params.grading = (self.lfs_factor > 0.0).then(|| GradingParams {
            lfs_factor: self.lfs_factor,
            ..GradingParams::default()
        });
        if !(self.chord_error.is_finite() && self.chord_error >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "chord_error",
                message: format!(
                    "must be a number >= 0, got {}",
                    crate::error::shown(self.chord_error)
                ),
            });
        }
        params.fit_iterations = if self.no_fit { 0 } else { FIT_ITERATIONS };
        if !(self.min_angle >= 0.0 && self.min_angle < 60.0) {
            return Err(Error::InvalidParameter {
                name: "min_angle",
                message: format!(
                    "must be an angle from 0 to 60 degrees, got {}",
                    self.min_angle
                ),
            });
        }
        if !(self.max_angle > 60.0 && self.max_angle <= 180.0) {
            return Err(Error::InvalidParameter {
                name: "max_angle",
                message: format!(
                    "must be an angle above 60 and up to 180 degrees, got {}",
                    self.max_angle
                ),
            });
        }
        if let Some(op) = params.optimize.as_mut() {
            op.smooth_iterations = self.smooth;
            op.final_theta_deg = self.min_angle;
            op.final_theta_max_deg = self.max_angle;
        }
        params.curvature = (self.chord_error > 0.0).then(|| CurvatureParams {
            chord_error: self.chord_error,
            ..CurvatureParams::default()
        });
        if let Some(s) = self.sigma_n {
            params.sigma_n = s;
        }
        Ok(params)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Options that exclude each other are refused here (clap refuses them earlier for the
    /// binary); the defaults give the pipeline's defaults but for the density.
    #[test]
    fn exclusive_options_are_refused_and_defaults_pass() {
        let both = RemeshOptions {
            points: Some(100),
            sigma_p: Some(2.0),
            ..Default::default()
        };
        assert!(matches!(
            both.params(),
            Err(Error::InvalidParameter { name: "points", .. })
        ));
        let features = RemeshOptions {
            feature_angle: Some(30.0),
            no_features: true,
            ..Default::default()
        };
        assert!(matches!(
            features.params(),
            Err(Error::InvalidParameter {
                name: "feature_angle",
                ..
            })
        ));
        let p = RemeshOptions::default().params().unwrap();
        assert_eq!(p.density, Density::InputVertices);
        assert_eq!(p.seed, 1);
        assert_eq!(p.fit_iterations, FIT_ITERATIONS);
        assert_eq!(p.features, FeatureDetection::Auto);
    }
}
