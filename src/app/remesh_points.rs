//! `remesh IN OUT --points N` where IN is a point set: [`remesh_points`], the checks and the
//! report as for a mesh, and the distances measured against the input points themselves; and
//! [`remesh_point_set`], the same job on points held in memory.

use std::path::PathBuf;
use std::sync::Mutex;

use glam::DVec3;

use super::files::with_path;
use super::job::{RemeshJob, RemeshedMesh};
use super::memory;
use super::notes::{count_note, dropped_note, holes_note};
use super::output::{check_and_write, insert_json, insert_kernel_extras};
use super::DISTANCE_SAMPLES;
use crate::error::{Error, Result};
use crate::io::{as_written, MeshFormat};
use crate::mesh::TriMesh;
use crate::pipeline::points::{remesh_points, PointRemeshParams};
use crate::pipeline::RemeshParams;
use crate::pipeline::{Density, MAX_POINTS};
use crate::points::source::PointSource;
use crate::report::{PointSetDistance, QualityReport};
use crate::surface::MeshSurface;
use crate::timing::Clock;

/// Points per chunk of the distance measurement's pass over the input.
const DISTANCE_CHUNK: usize = 1 << 20;

/// The point-set branch of [`run_remesh`](super::run_remesh), after its usage checks.
/// `write` takes the output mesh (model units).
pub(super) fn run(
    job: &RemeshJob,
    source: &PointSource,
    format: MeshFormat,
    write: &dyn Fn(&TriMesh) -> Result<()>,
    on_stage: &(dyn Fn(&str) + Sync),
) -> Result<QualityReport> {
    if let Some(limit) = job.max_memory {
        // What the reader holds is known from the header (a PCD's decompressed payload, an
        // E57's points), before anything is allocated.
        let size = source.input_size().map_err(|e| with_path(e, &job.input))?;
        let points = match job.params.density {
            Density::Points(n) if n <= MAX_POINTS => n as f64,
            _ => 0.0,
        };
        let input_points = size.points.unwrap_or(0);
        let (distance, held) = (job.measure_distance, size.reader_bytes);
        memory::check_point_set_budget(input_points, held, points, distance, limit)?;
    }
    let (orientation, camera) = source
        .orientation(job.viewpoint)
        .map_err(|e| with_path(e, &job.input))?;
    let params = PointRemeshParams {
        remesh: job.params,
        orientation,
        ..PointRemeshParams::default()
    };
    let out = remesh_points(source, &params, on_stage).map_err(|e| with_path(e, &job.input))?;

    on_stage("check");
    let t = Clock::start();
    let written;
    let checked = match format {
        MeshFormat::Obj | MeshFormat::Ply | MeshFormat::Off => &out.mesh_normalized,
        MeshFormat::Gltf | MeshFormat::Glb | MeshFormat::Stl => {
            written = out.normalization.apply_mesh(&as_written(&out.mesh, format));
            &written
        }
    };
    // Crossings at the coordinates the file stores (exact there), not the frame's rounded ones.
    let mut report = QualityReport::with_crossings_on(checked, &as_written(&out.mesh, format));
    let check_seconds = t.elapsed();
    check_and_write(
        job,
        write,
        &out.mesh,
        &mut report,
        &out.stages,
        check_seconds,
        on_stage,
    )?;

    if job.measure_distance {
        on_stage("distance");
        let t = Clock::start();
        let surface = MeshSurface::new(checked)?;
        let mut distance =
            PointSetDistance::new(checked, &surface, DISTANCE_SAMPLES, job.params.seed);
        let mut reader = source.open()?;
        let mut chunk = Vec::new();
        let mut positions: Vec<DVec3> = Vec::new();
        while reader.read_chunk(&mut chunk, DISTANCE_CHUNK)? > 0 {
            positions.clear();
            positions.extend(
                chunk
                    .iter()
                    .filter(|p| out.kept.contains(p.position))
                    .map(|p| out.normalization.apply(p.position)),
            );
            distance.add_points(&positions);
        }
        report.distance = Some(distance.finish());
        let (wall, cpu) = t.elapsed();
        report.push_stage("distance (report)", wall, cpu);
        report.notes.push(format!(
            "Hausdorff and RMS are to the input points (output to its nearest point, each \
             point to the output), outliers included{}",
            if out.far_points > 0 {
                ", the far groups left out excluded"
            } else {
                ""
            }
        ));
    }

    if let Density::EdgeLength(l) = job.params.density {
        report.notes.push(format!(
            "--edge-length {l}: sigma_p {:.6} (bbox-100; a point set's mean edge is 1.2 \
             sigma_p), {} vertices written",
            out.sigma_p,
            out.mesh.vertex_count()
        ));
    }
    let extra = &mut report.extra;
    insert_kernel_extras(extra, out.sigma_p, &job.params, out.target);
    extra.insert("input_points".into(), out.input_points.into());
    extra.insert("had_normals".into(), out.had_normals.into());
    extra.insert("normals_filled".into(), out.normal_repairs.filled.into());
    extra.insert("normals_turned".into(), out.normal_repairs.turned.into());
    if let Some(c) = camera.filter(|_| !out.had_normals) {
        insert_json(extra, "camera_viewpoint", c.position.to_array());
        insert_json(extra, "camera_hidden_fraction", c.hidden);
        extra.insert("camera_used".into(), c.used.into());
    }
    extra.insert("outliers_removed".into(), out.outliers_removed.into());
    extra.insert("far_points".into(), out.far_points.into());
    extra.insert("duplicate_points".into(), out.duplicate_points.into());
    extra.insert("samples".into(), out.samples.into());
    extra.insert("unprojected_samples".into(), out.unprojected_samples.into());
    extra.insert("rescan_rejected".into(), out.rescan_rejected.into());
    insert_json(extra, "surface_variation", out.surface_variation);
    extra.insert("boundary_samples".into(), out.boundary_samples.into());
    extra.insert("boundary_curves".into(), out.boundary_curves.into());
    extra.insert("rimls_points".into(), out.rimls_points.into());
    insert_json(extra, "scan_seconds", out.scan_seconds);
    insert_json(extra, "assembly", &out.assembly);
    insert_json(extra, "unsupported_faces", out.unsupported);
    insert_json(
        extra,
        "unsupported_after_finishing",
        out.unsupported_after_finishing,
    );
    insert_json(extra, "pillows", out.pillows);
    insert_json(extra, "off_data", out.off_data);
    insert_json(extra, "crossing_faces", out.crossing_faces);
    insert_json(
        extra,
        "tiny_pieces",
        serde_json::json!({"pieces": out.tiny_pieces.shells, "vertices": out.tiny_pieces.vertices}),
    );
    insert_json(extra, "optimize", out.optimize);
    insert_json(extra, "untangle", out.untangle);
    if out.mend_after_removals.attempts > 0 {
        insert_json(extra, "mend_after_removals", out.mend_after_removals);
    }
    if out.mend_after_untangle.attempts > 0 {
        insert_json(extra, "mend_after_untangle", out.mend_after_untangle);
    }
    if out.refine.rounds > 0 {
        insert_json(extra, "refine", out.refine);
    }
    insert_json(extra, "untangle_umbrellas", out.untangle_umbrellas);
    insert_json(extra, "output_orientation", out.output_orientation);
    report.notes.push(format!(
        "the input is a point set ({} points, {}): the samples lie on the RIMLS surface of the \
         points and were connected by tangent-plane umbrellas",
        out.input_points,
        match (out.had_normals, camera) {
            (true, _) => {
                let r = out.normal_repairs;
                let mut said = "with normals".to_string();
                if r.filled > 0 {
                    said += &format!(
                        "; {} of the surface's points had none (NaN or zero) and got one fitted \
                         from the points near them",
                        r.filled
                    );
                }
                if r.turned > 0 {
                    said += &format!(
                        "; the file's normals were not consistently oriented (neighbours \
                         pointing to opposite sides): oriented again, {} of the surface's \
                         points turned",
                        r.turned
                    );
                }
                said
            }
            (false, None) => "normals estimated".to_string(),
            (false, Some(c)) => {
                let v = c.position;
                // (as the file's single precision, and no negative zero)
                let at = format!(
                    "({}, {}, {})",
                    v.x as f32 + 0.0,
                    v.y as f32 + 0.0,
                    v.z as f32 + 0.0
                );
                if c.used {
                    format!("normals estimated, oriented towards the file's viewpoint at {at}")
                } else {
                    format!(
                        "normals estimated; the file's viewpoint {at} was not used: from there \
                         {:.1}% of the points lie behind others, where a single view hides \
                         almost none, so the scanner did not stand there",
                        100.0 * c.hidden
                    )
                }
            }
        }
    ));
    if out.duplicate_points > 0 {
        report.notes.push(format!(
            "{} merged into another at the same position (the input lists a position more than \
             once)",
            super::notes::plural(
                out.duplicate_points,
                "coincident point was",
                "coincident points were"
            )
        ));
    }
    if !out.separate_parts.is_empty() {
        insert_json(extra, "separate_parts", &out.separate_parts);
        report.notes.push(format!(
            "the points form {} parts far apart compared with their sizes, which one scale cannot \
             hold: each was meshed on its own at its share of the count by surface area ({} \
             vertices); the figures in Extra other than counts are the first part's, and \
             distances are in bbox-100 units of the whole",
            out.separate_parts.len(),
            out.separate_parts
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    for part in &out.left_out_parts {
        let (lo, hi) = (part.min, part.max);
        report.notes.push(format!(
            "a part far from the rest ({} points in [{:.4}, {:.4}, {:.4}]-[{:.4}, {:.4}, {:.4}]) \
             was left out: at its share of the count it holds no surface ({}); a larger count \
             meshes it",
            part.points, lo.x, lo.y, lo.z, hi.x, hi.y, hi.z, part.reason
        ));
    }
    if !out.left_out_parts.is_empty() {
        insert_json(
            extra,
            "left_out_part_points",
            out.left_out_parts
                .iter()
                .map(|p| p.points)
                .collect::<Vec<_>>(),
        );
    }
    if out.far_points > 0 {
        report.notes.push(format!(
            "{} left out, in groups far from the rest and much smaller: they would have set the \
             scale",
            super::notes::plural(out.far_points, "point was", "points were")
        ));
    }
    let isolated = out.outliers_removed as u64 - out.far_points.min(out.outliers_removed as u64);
    if isolated > 0 {
        report.notes.push(format!(
            "{isolated} isolated points (outliers) were left out of the samples and the surface"
        ));
    }
    count_note(&mut report.notes, out.target, out.mesh.vertex_count());
    if let Some(n) = out.target {
        let v = out.mesh.vertex_count() as f64;
        let per_vertex = out.input_points as f64 / n as f64;
        let sparse = per_vertex < crate::pipeline::points::RIMLS_POINTS_PER_SAMPLE as f64;
        if (v - n as f64).abs() > 0.01 * n as f64 && sparse {
            report.notes.push(format!(
                "the input has {per_vertex:.2} points per vertex asked: samples are lost where \
                 the data is no denser than the output (projections refused across its gaps, \
                 samples in no triangle or collapsed), and a second run for a raised count did no \
                 better (no nearer, or with faces left crossing)"
            ));
        }
    }
    if out.dropped_samples > 0 {
        report.notes.push(dropped_note(out.dropped_samples));
    }
    if report.topology.boundary_loops > 0 {
        report.notes.push(format!(
            "the points leave {} boundary loops open (gaps in the data wider than {} sigma_p: \
             {} faces across them were removed)",
            report.topology.boundary_loops,
            crate::pipeline::points::OPEN_GAP_SIGMA_P,
            out.unsupported.faces
                + out.unsupported.pinched_faces
                + out.unsupported_after_finishing.faces
                + out.unsupported_after_finishing.pinched_faces
        ));
    }
    let st = &out.stray_shells;
    if st.shells > 0 {
        report.notes.push(format!(
            "{} tiny closed pieces ({} vertices) that split off where the surface is too thin \
             for this count were left out",
            st.shells, st.vertices
        ));
    }
    if out.pillows.opened > 0 {
        report.notes.push(format!(
            "{} pieces lost {} faces folded over the data (facing against it, no data on their \
             side: both sides of a strip of data a sample or two wide, a flap at the data's edge)",
            out.pillows.opened,
            out.pillows.faces + out.pillows.pinched_faces
        ));
    }
    let off = &out.off_data;
    if off.faces > 0 {
        report.notes.push(format!(
            "{} faces with a corner farther than the mean edge length from every point (two of \
             the data's own spacings where it is sparser) were removed (the data's edge)",
            off.faces + off.pinched_faces
        ));
    }
    let crossing = &out.crossing_faces;
    if crossing.pairs > 0 {
        report.notes.push(format!(
            "{} faces that still crossed another ({} pairs, where the data holds sheets closer \
             than the spacing) were removed, leaving holes",
            crossing.faces + crossing.pinched_faces,
            crossing.pairs
        ));
    }
    let tiny = &out.tiny_pieces;
    if tiny.shells > 0 {
        report.notes.push(format!(
            "{} pieces no larger than 4 sigma_p across ({} vertices: stray points meshed on \
             their own) were left out",
            tiny.shells, tiny.vertices
        ));
    }
    if out.assembly.holes_left > 0 {
        report.notes.push(holes_note(out.assembly.holes_left));
    }
    Ok(report)
}

/// The name errors and the report give points held in memory.
const INPUT_POINTS: &str = "input points";

/// Remeshes a point set held in memory exactly as [`run_remesh`](super::run_remesh) remeshes a
/// text point file holding it (`x y z` per line, or `x y z nx ny nz` with normals: `.xyz`,
/// `.xyzn`): the points are written to such a file in a temporary folder, each value in the
/// shortest form that reads back to the same `f64`, and the file goes through the same reading,
/// pipeline ([`remesh_points`]), check and report. The same arguments give the same output mesh,
/// bit for bit, as `remesh` on that file.
///
/// `points` in model units; `normals` one per point (any length but zero: the reader normalizes
/// them), or `None` (estimated, oriented outward by a spanning tree, or towards `viewpoint`, in
/// model units, as `--viewpoint` does). `params` need a density of [`Density::Points`] or
/// [`Density::SigmaP`]; `measure_distance`, `strict` and `max_memory` are [`RemeshJob`]'s fields
/// of those names; `on_stage` is called with each stage's name as it starts. Errors name the
/// points as `input points`.
///
/// # Errors
/// [`Error::InvalidMesh`] for no points, a coordinate or normal that is not finite, a normal of
/// length zero or a normal count that differs from the point count (naming the point);
/// [`Error::Io`] when the temporary file cannot be written; whatever
/// [`run_remesh`](super::run_remesh) returns for a point-set file.
#[allow(clippy::too_many_arguments)] // RemeshJob's fields, less the files
pub fn remesh_point_set(
    points: &[DVec3],
    normals: Option<&[DVec3]>,
    params: &RemeshParams,
    viewpoint: Option<DVec3>,
    measure_distance: bool,
    strict: bool,
    max_memory: Option<u64>,
    on_stage: &(dyn Fn(&str) + Sync),
) -> Result<RemeshedMesh> {
    let invalid = |message: String| Error::InvalidMesh {
        path: PathBuf::from(INPUT_POINTS),
        message,
    };
    if points.is_empty() {
        return Err(invalid("no points".into()));
    }
    if let Some(i) = points.iter().position(|p| !p.is_finite()) {
        return Err(invalid(format!(
            "point {i} has a coordinate that is not finite"
        )));
    }
    if let Some(n) = normals {
        if n.len() != points.len() {
            return Err(invalid(format!(
                "{} normals for {} points",
                n.len(),
                points.len()
            )));
        }
        if let Some(i) = n.iter().position(|v| !(v.is_finite() && v.length() > 0.0)) {
            return Err(invalid(format!(
                "normal {i} has no direction (zero, or not finite)"
            )));
        }
    }
    on_stage("read");
    let source = PointSource::memory(INPUT_POINTS, points, normals);
    let job = RemeshJob::in_memory(
        PathBuf::from(INPUT_POINTS),
        params,
        measure_distance,
        strict,
        max_memory,
        viewpoint,
    );
    let handed = Mutex::new(None);
    let report = run(
        &job,
        &source,
        MeshFormat::Ply,
        &|mesh| {
            *handed.lock().unwrap_or_else(|e| e.into_inner()) = Some(mesh.clone());
            Ok(())
        },
        on_stage,
    )?;
    let mesh = handed
        .into_inner()
        .unwrap_or_else(|e| e.into_inner())
        .ok_or_else(|| Error::Internal {
            stage: "write",
            message: "the point-set pipeline handed over no mesh".into(),
        })?;
    Ok(RemeshedMesh { mesh, report })
}
