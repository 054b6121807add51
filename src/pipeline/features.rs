//! The sharp-feature stage: creases that stay sharp at the sample spacing, kept when they are a
//! part's (long curves) or when asked for.

use super::input::NormalizedInput;
use super::output::FeatureStats;
use crate::sampling::spacing::SAMPLES_PER_SIGMA2;
use crate::surface::features::{
    detect_features, junction_curve_share, long_curve_share, FeatureDetection, FeatureParams,
    Features, AUTO_FEATURE_MIN_SHARE, GAP_ANGLE_DEG, MAX_CREASE_DENSITY, MAX_GAP_RATIO,
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
    let length = features.length(positions);
    let long_share = long_curve_share(&features, positions, feature_scale);
    // Automatic detection keeps a part's creases and leaves a scan's folds out: creases in long
    // curves are a part's; short ones between junctions are when they lie more than a spacing
    // apart and the surface shows no gentler bends beside them (the second detection runs only
    // then).
    let mut junction_share = None;
    let mut crease_density = None;
    let mut gap_ratio = None;
    let auto_kept = (detection == FeatureDetection::Auto).then(|| {
        if long_share >= AUTO_FEATURE_MIN_SHARE {
            return true;
        }
        let share = junction_curve_share(&features, positions, feature_scale);
        junction_share = Some(share);
        if share < AUTO_FEATURE_MIN_SHARE {
            return false;
        }
        let density = length * feature_scale / input.area;
        crease_density = Some(density);
        if density > MAX_CREASE_DENSITY {
            return false;
        }
        let gentle = detect_features(
            surface,
            &FeatureParams {
                angle_deg: GAP_ANGLE_DEG,
                scale: feature_scale,
            },
        );
        let ratio = gentle.length(positions) / length;
        gap_ratio = Some(ratio);
        ratio <= MAX_GAP_RATIO
    });
    let stats = FeatureStats {
        angle_deg: detection.angle_deg(),
        automatic_kept: auto_kept,
        long_curve_share: long_share,
        junction_curve_share: junction_share,
        crease_density,
        gap_ratio,
        scale: feature_scale,
        edges: features.edges.len(),
        curves: features.curves.len(),
        closed_curves: features.curves.iter().filter(|c| c.closed).count(),
        corners: features.corners.len(),
        length,
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
