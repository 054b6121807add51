//! The sharp-feature stage: creases that stay sharp at the sample spacing, kept when they are a
//! part's (long curves) or when asked for.

use super::input::NormalizedInput;
use super::output::FeatureStats;
use crate::sampling::spacing::SAMPLES_PER_SIGMA2;
use crate::surface::features::{
    detect_features, long_curve_share, FeatureDetection, FeatureParams, Features,
    AUTO_FEATURE_MIN_SHARE,
};
use crate::surface::MeshSurface;

/// The creases of `input` at the sample spacing of `first_sigma_p` (bbox-100 units), by
/// `detection`: the features kept (none when automatic detection finds a scan's folds) and
/// what was found.
pub(super) fn sharp_features(
    input: &NormalizedInput,
    surface: &MeshSurface,
    first_sigma_p: f64,
    detection: FeatureDetection,
) -> (Features, FeatureStats) {
    let feature_scale = first_sigma_p / SAMPLES_PER_SIGMA2.sqrt();
    let mut features = detect_features(
        surface,
        &FeatureParams {
            angle_deg: detection.angle_deg(),
            scale: feature_scale,
        },
    );
    let positions = &input.mesh.positions;
    let long_share = long_curve_share(&features, positions, feature_scale);
    // Automatic detection keeps a part's creases and leaves a scan's folds out.
    let auto_kept =
        (detection == FeatureDetection::Auto).then_some(long_share >= AUTO_FEATURE_MIN_SHARE);
    let stats = FeatureStats {
        angle_deg: detection.angle_deg(),
        automatic_kept: auto_kept,
        long_curve_share: long_share,
        scale: feature_scale,
        edges: features.edges.len(),
        curves: features.curves.len(),
        closed_curves: features.curves.iter().filter(|c| c.closed).count(),
        corners: features.corners.len(),
        length: features.length(positions),
        sampled_edges: 0,
        triangulated_edges: 0,
        recovered_edges: 0,
        kept_edges: 0,
        crease_distance: None,
    };
    if auto_kept == Some(false) {
        features = Features::default();
    }
    (features, stats)
}
