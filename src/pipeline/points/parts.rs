//! Points that form parts far apart compared with their sizes (two objects 10^6 apart, each 10
//! across: [`SeparateParts`]): one scale cannot hold them, so each part is meshed on its own at
//! its share of the count, and the outputs are put together.

use std::sync::Arc;

use super::{remesh_points_whole, PointRemeshOutput, PointRemeshParams, Run};
use crate::error::{Error, Result};
use crate::mesh::{Normalization, TriMesh};
use crate::pipeline::Density;
use crate::points::far_groups::{KeptPoints, SeparateParts};
use crate::points::source::PointSource;

/// The fewest points asked of a part: a sphere's 2000 points were "not near a surface" (their
/// spread at that spacing) at 8 and 12 samples at seed 1 and at 20 at seed 2 of 1–5, and met at
/// 30 and 40 at seeds 1–5. The largest part gives them up, so the count stays the one asked.
const MIN_PART_POINTS: usize = 40;

/// [`remesh_points`](super::remesh_points) of `source`, whose points form `parts`: each part
/// meshed on its own (as [`PointSource::Part`], read from `source` as it goes), the count
/// shared out by the parts' surface areas as guessed on the grouped subset
/// ([`PartEstimate::area`](crate::points::far_groups::PartEstimate)) so that the spacing is
/// about the same on every part; a sigma_p (bbox-100 units of the whole) is taken to each part's
/// frame by the part's box as the subset saw it. The same seed for every part.
///
/// # Errors
/// Those of reading `source`; a part's errors, naming it (`in.xyz (part 2 of 3): ...`);
/// [`Error::InvalidMesh`] for a part whose points are parts far apart again.
pub(super) fn remesh_parts(
    source: &PointSource,
    params: &PointRemeshParams,
    parts: Arc<SeparateParts>,
    on_stage: &(dyn Fn(&str) + Sync),
) -> Result<PointRemeshOutput> {
    let (sources, outside) = source.parts(&parts)?;
    let estimates = &parts.parts;
    let total_area: f64 = estimates.iter().map(|p| p.area).sum();
    let total_points: usize = estimates.iter().map(|p| p.subset_points).sum();
    let share = |k: usize| {
        if total_area > 0.0 && total_area.is_finite() {
            estimates[k].area / total_area
        } else {
            estimates[k].subset_points as f64 / total_points.max(1) as f64
        }
    };
    // Each part's count: its share, at least MIN_PART_POINTS, the largest part (the first)
    // giving up what the others took over their share.
    let counts: Option<Vec<usize>> = match params.remesh.density {
        Density::Points(n) => {
            let mut c: Vec<usize> = (0..sources.len())
                .map(|k| ((n as f64 * share(k)).round() as usize).max(MIN_PART_POINTS))
                .collect();
            let others: usize = c[1..].iter().sum();
            c[0] = n.saturating_sub(others).max(MIN_PART_POINTS);
            Some(c)
        }
        _ => None,
    };
    let whole_side = parts.whole.longest_side();
    let mut outs = Vec::with_capacity(sources.len());
    let mut left_out = Vec::new();
    for (k, part) in sources.iter().enumerate() {
        let mut p = params.clone();
        p.remesh.density = match params.remesh.density {
            Density::Points(_) => {
                Density::Points(counts.as_ref().map_or(MIN_PART_POINTS, |c| c[k]))
            }
            Density::SigmaP(s) => {
                Density::SigmaP(s * whole_side / estimates[k].bbox.longest_side())
            }
            other => other,
        };
        match remesh_points_whole(part, &p, on_stage) {
            Ok(Run::Meshed(out)) => outs.push(Some(*out)),
            Ok(Run::Parts(inner)) => {
                return Err(Error::invalid_mesh(part.name(), inner.refusal()));
            }
            // A part other than the largest that holds no surface at its share of the count is
            // left out, said in a note, rather than the whole run refused.
            Err(Error::InvalidMesh { message, .. }) if k > 0 => {
                let PointSource::Part(pp) = part else {
                    unreachable!("PointSource::parts gives parts")
                };
                left_out.push(LeftOutPart {
                    points: pp.count,
                    min: estimates[k].bbox.min,
                    max: estimates[k].bbox.max,
                    reason: message,
                });
                outs.push(None);
            }
            Err(e) => return Err(e),
        }
    }
    let mut out = merge(outs, parts, outside, params.remesh.density)?;
    out.left_out_parts = left_out;
    Ok(out)
}

/// A part far apart that was left out: no surface at its share of the count.
#[derive(Debug, Clone, PartialEq)]
pub struct LeftOutPart {
    /// Its points.
    pub points: u64,
    /// Its box as the grouped subset saw it (model units).
    pub min: glam::DVec3,
    /// Its box as the grouped subset saw it (model units).
    pub max: glam::DVec3,
    /// Why (the part's own error message).
    pub reason: String,
}

/// The parts' outputs as one (`None` for a part left out): the meshes side by side (model
/// units), in the frame of their common box; counts and times summed; the first part's stage
/// statistics. The points of a part left out are not among the kept ones.
fn merge(
    outs: Vec<Option<PointRemeshOutput>>,
    parts: Arc<SeparateParts>,
    outside: u64,
    density: Density,
) -> Result<PointRemeshOutput> {
    let mut mesh = TriMesh::new(Vec::new(), Vec::new());
    let left_out: Vec<bool> = outs.iter().map(Option::is_none).collect();
    for o in outs.iter().flatten() {
        let offset = mesh.positions.len() as u32;
        mesh.positions.extend_from_slice(&o.mesh.positions);
        mesh.triangles
            .extend(o.mesh.triangles.iter().map(|t| t.map(|i| i + offset)));
    }
    // (A mesh with no extent keeps the first part's frame.)
    let first_frame = outs.iter().flatten().next().map(|o| o.normalization);
    let normalization = mesh
        .bbox()
        .as_ref()
        .and_then(Normalization::for_bbox)
        .or(first_frame)
        .ok_or_else(|| Error::Internal {
            stage: "remesh_points",
            message: "the parts gave no output".into(),
        })?;
    let mut iter = outs.into_iter();
    // (The largest part is never left out: its errors are the run's.)
    let first = iter.next().flatten().ok_or_else(|| Error::Internal {
        stage: "remesh_points",
        message: "no part".into(),
    })?;
    // The first part's sigma_p in the whole's bbox-100 units.
    let sigma_p = first.sigma_p / first.normalization.scale * normalization.scale;
    let mut separate_parts = vec![first.mesh.vertex_count()];
    let mut far = vec![first.kept.far_of_whole()];
    let mut out = PointRemeshOutput {
        mesh_normalized: normalization.apply_mesh(&mesh),
        mesh,
        normalization,
        sigma_p,
        target: match density {
            Density::Points(n) => Some(n),
            _ => None,
        },
        far_points: first.far_points + outside,
        outliers_removed: first.outliers_removed + outside as usize,
        ..first
    };
    for o in iter {
        let Some(o) = o else {
            separate_parts.push(0);
            far.push(None);
            continue;
        };
        separate_parts.push(o.mesh.vertex_count());
        far.push(o.kept.far_of_whole());
        out.input_points += o.input_points;
        out.duplicate_points += o.duplicate_points;
        out.far_points += o.far_points;
        out.had_normals &= o.had_normals;
        out.outliers_removed += o.outliers_removed;
        out.samples += o.samples;
        out.unprojected_samples += o.unprojected_samples;
        out.rescan_rejected += o.rescan_rejected;
        out.surface_variation = match (out.surface_variation, o.surface_variation) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        };
        out.boundary_samples += o.boundary_samples;
        out.boundary_curves += o.boundary_curves;
        out.rimls_points += o.rimls_points;
        out.dropped_samples += o.dropped_samples;
        for (a, b) in out.scan_seconds.iter_mut().zip(o.scan_seconds) {
            *a += b;
        }
        for stage in o.stages {
            crate::timing::add_stage(&mut out.stages, stage);
        }
    }
    out.kept = KeptPoints::in_parts(parts, far, left_out);
    out.separate_parts = separate_parts;
    Ok(out)
}
