//! The notes of the report: what the pipeline did that a user should know, one line each.

use crate::mesh::OrientStats;

/// The report's note when the output's vertex count is more than 1% off the target.
pub(super) fn count_note(notes: &mut Vec<String>, target: Option<usize>, vertices: usize) {
    if let Some(n) = target {
        if (vertices as f64 - n as f64).abs() > 0.01 * n as f64 {
            notes.push(format!(
                "target not reached: {vertices} vertices for --points {n} (more than 1% off)"
            ));
        }
    }
}

/// The report's notes on the samples the triangulation inserted for the topological ball
/// property ([`TopologicalBallStats`]): how many, with the count asked and written, and where
/// the property still failed after the last insertion.
pub(super) fn topological_ball_notes(
    notes: &mut Vec<String>,
    stats: &crate::triangulate::topological_ball::TopologicalBallStats,
    target: Option<usize>,
    vertices: usize,
) {
    if stats.inserted > 0 {
        let asked = target.map_or(String::new(), |n| {
            format!("{n} asked, {vertices} written: ")
        });
        notes.push(format!(
            "{asked}{} samples were inserted where the sampling was too coarse for the surface \
             (a sample's restricted Voronoi cell not a disc, or two cells meeting twice: a hole, \
             a gap, a wall or a tube narrower than the spacing), so that the output keeps the \
             input's topology",
            stats.inserted
        ));
    }
    let left = stats.bad_cells_left + stats.bad_pairs_left;
    if left > 0 {
        notes.push(format!(
            "after {} inserted samples the topological ball property still fails at {} cells and \
             {} pairs of cells: the output's topology may differ from the input's there",
            stats.inserted, stats.bad_cells_left, stats.bad_pairs_left
        ));
    }
}

/// The report's note on samples that ended in no triangle.
pub(super) fn dropped_note(dropped: usize) -> String {
    format!("{dropped} samples ended in no triangle and were left out")
}

/// The report's note on holes of the triangulation left open.
pub(super) fn holes_note(holes: usize) -> String {
    format!("{holes} holes of the triangulation could not be closed")
}

/// The report's notes on orienting the input and the output ([`OrientStats`]): how many input
/// faces were reversed and why, a non-orientable input said plainly, and an inward-facing
/// closed input whose output was turned outward.
pub(super) fn orientation_notes(
    input: &OrientStats,
    output: &OrientStats,
    input_faces: usize,
) -> Vec<String> {
    let mut notes = Vec::new();
    if input.non_orientable_components > 0 {
        notes.push(format!(
            "the input is non-orientable ({} part(s), {} faces, like a Möbius strip): the \
             output is an oriented surface, so it cannot have the input's topology there; {} \
             faces were reversed so that the input is consistently oriented everywhere but \
             across a seam of {} edges; the output is cut open there (a Möbius strip comes \
             out as a twisted disc, χ 1 instead of 0, whose two sides of the cut can touch or \
             cross)",
            input.non_orientable_components,
            input.non_orientable_faces,
            input.faces_flipped,
            input.seam_edges
        ));
    } else if input.inconsistent_edges > 0 {
        notes.push(format!(
            "the input was not consistently oriented ({} edges ran the same way in both their \
             faces): {} of its {input_faces} faces were reversed so that every edge between two \
             faces runs once each way (each part keeps the orientation of its larger area)",
            input.inconsistent_edges, input.faces_flipped,
        ));
    }
    match output.components_turned_outward {
        0 => {}
        1 => notes.push(
            "the input faced inward (negative signed volume): the output, closed, was turned \
             outward"
                .to_string(),
        ),
        k => notes.push(format!(
            "the input faced inward (negative signed volume): {k} closed parts of the output \
             were turned outward"
        )),
    }
    notes
}

/// The report's notes on the sizing field from the local feature size: where it spaced samples
/// finer than sigma_p, with the count asked and written when it grew the count past
/// `target` (1%), and the parts it could not resolve within its growth bound.
pub(super) fn grading_notes(
    g: &crate::sampling::grading::GradingStats,
    vertices: usize,
    target: Option<usize>,
) -> Vec<String> {
    let bbox = |r: &crate::sampling::grading::GradedRegion| {
        format!(
            "[{:.4}, {:.4}, {:.4}]-[{:.4}, {:.4}, {:.4}]",
            r.min.x, r.min.y, r.min.z, r.max.x, r.max.y, r.max.z
        )
    };
    let mut notes = Vec::new();
    if g.graded_samples > 0 {
        let shown: Vec<String> = g
            .regions
            .iter()
            .take(3)
            .map(|r| format!("{} in {}", r.samples, bbox(r)))
            .collect();
        let asked = match target {
            Some(n) if grew_the_count(g, vertices, target) => format!(
                "{n} asked, {vertices} written: the input is narrower than the spacing for {n} \
                 (without --lfs-factor the count is kept with one sigma_p; --strict refuses); "
            ),
            _ => String::new(),
        };
        notes.push(format!(
            "{asked}sizing field: {} of {vertices} samples are spaced by the local feature size, \
             finer than sigma_p (down to {:.2} sigma_p), where walls, tubes, holes or gaps are \
             narrower than the spacing, in {} regions (largest: {})",
            g.graded_samples,
            g.min_width,
            g.regions.len(),
            shown.join("; ")
        ));
    }
    if g.unresolved_samples > 0 {
        let shown: Vec<String> = g
            .regions
            .iter()
            .filter(|r| r.unresolved > 0)
            .take(3)
            .map(|r| format!("{} in {}", r.unresolved, bbox(r)))
            .collect();
        let resolve = g.resolving_count.map_or(String::new(), |n| {
            format!("; about {} samples would resolve them", round_up_2(n))
        });
        notes.push(format!(
            "{} samples lie on parts thinner than the sizing field resolves within its bound \
             (held at its smallest spacing, {:.4} model units, so the output there may split, \
             fuse or lose a tip): {}{resolve}",
            g.unresolved_samples,
            g.floor,
            shown.join("; ")
        ));
    }
    notes
}

/// Whether the sizing field took the count `vertices` more than 1% past `target`: some
/// samples graded, and the count over.
pub(super) fn grew_the_count(
    g: &crate::sampling::grading::GradingStats,
    vertices: usize,
    target: Option<usize>,
) -> bool {
    g.graded_samples > 0 && target.is_some_and(|n| vertices as f64 > 1.01 * n as f64)
}

/// "1 `one`" or "n `many`" (a count in a note).
pub(super) fn plural(n: u64, one: &str, many: &str) -> String {
    if n == 1 {
        format!("1 {one}")
    } else {
        format!("{n} {many}")
    }
}

/// `n` rounded up to two significant digits (a count for a note).
pub(super) fn round_up_2(n: f64) -> u64 {
    if !(n.is_finite() && n > 0.0) {
        return 0;
    }
    let scale = 10f64.powi((n.log10().floor() as i32 - 1).max(0));
    ((n / scale).ceil() * scale) as u64
}

/// The report's line on the sharp features of a remesh: what was found, what the output keeps
/// and how far the creases are from its edges, or why automatic detection left them out. None
/// when detection was off or found nothing to leave out.
pub(super) fn features_note(f: &crate::pipeline::FeatureStats) -> Option<String> {
    if !(f.angle_deg < 180.0) {
        return None;
    }
    if f.automatic_kept == Some(false) {
        if f.edges == 0 {
            return None;
        }
        return Some(format!(
            "sharp features (automatic, at {}°): {} crease edges in {} curves, {}: a scan's \
             folds, not a part's creases, so they are sampled like the rest (--feature-angle {} \
             keeps them)",
            f.angle_deg,
            f.edges,
            f.curves,
            auto_reason(f),
            f.angle_deg
        ));
    }
    if f.edges == 0 {
        return Some(format!(
            "sharp features at {}°: no crease found",
            f.angle_deg
        ));
    }
    let kept = if f.kept_edges == f.sampled_edges {
        format!(
            "all {} crease edges of the samples are output edges",
            f.sampled_edges
        )
    } else {
        format!(
            "{} of the samples' {} crease edges are output edges",
            f.kept_edges, f.sampled_edges
        )
    };
    let distance = f.crease_distance.as_ref().map_or(String::new(), |d| {
        format!(
            "; the creases are within {:.3} of the output's edges (bbox-100)",
            d.max
        )
    });
    let why = match f.automatic_kept {
        Some(true) => format!(" (automatic: {}: a part's creases)", auto_reason(f)),
        _ => String::new(),
    };
    Some(format!(
        "sharp features at {}°{why}: {} crease edges in {} curves ({} closed), {} corners; \
         {kept}{distance}",
        f.angle_deg, f.edges, f.curves, f.closed_curves, f.corners
    ))
}

/// What the automatic decision on the creases went by
/// ([`FeatureDetection::Auto`](crate::internal::FeatureDetection::Auto)): the share in long
/// curves, and where that fell short, the share in curves from junction to junction, their
/// density and the gentler bends beside them.
fn auto_reason(f: &crate::pipeline::FeatureStats) -> String {
    use crate::surface::features::{
        GAP_ANGLE_DEG, LONG_CURVE_SPACINGS, MAX_CREASE_DENSITY, MAX_GAP_RATIO,
    };
    let long = format!(
        "{:.0}% of their length in curves of {} spacings or more",
        100.0 * f.long_curve_share,
        LONG_CURVE_SPACINGS
    );
    let Some(junction) = f.junction_curve_share else {
        return long;
    };
    let junction = format!(
        "{long}, {:.0}% in those or from junction to junction",
        100.0 * junction
    );
    let Some(density) = f.crease_density else {
        return junction;
    };
    // A measure against the bound that keeps the creases.
    let against = |v: f64, bound: f64| {
        if v <= bound {
            format!("at most {bound}")
        } else {
            format!("more than {bound}")
        }
    };
    let junction = format!(
        "{junction}, their length times the spacing over the area {density:.2} ({})",
        against(density, MAX_CREASE_DENSITY)
    );
    match f.gap_ratio {
        None => junction,
        Some(r) => format!(
            "{junction}, and detection at {GAP_ANGLE_DEG}° finds {r:.2} times their length ({})",
            against(r, MAX_GAP_RATIO)
        ),
    }
}
