//! `remesh IN OUT --points N` where IN is a point set: [`remesh_points`], the checks and the
//! report as for a mesh, and the distances measured against the input points themselves.

use glam::DVec3;

use super::{
    check_and_write, count_note, dropped_note, holes_note, insert_kernel_extras, memory,
    write_output, RemeshJob, DISTANCE_SAMPLES,
};
use crate::error::Result;
use crate::io::{as_written, MeshFormat};
use crate::pipeline::{Density, MAX_POINTS};
use crate::point_pipeline::{remesh_points, PointRemeshParams};
use crate::points::normals::NormalOrientation;
use crate::points::PointReader;
use crate::report::{PointSetDistance, QualityReport};
use crate::surface::MeshSurface;
use crate::timing::Clock;

/// Points per chunk of the distance measurement's pass over the input.
const DISTANCE_CHUNK: usize = 1 << 20;

/// The point-set branch of [`run_remesh`](super::run_remesh), after its usage checks.
pub(super) fn run(
    job: &RemeshJob,
    format: MeshFormat,
    on_stage: &(dyn Fn(&str) + Sync),
) -> Result<QualityReport> {
    let params = PointRemeshParams {
        remesh: job.params,
        orientation: match job.viewpoint {
            Some(v) => NormalOrientation::Viewpoint(v),
            None => NormalOrientation::SpanningTree,
        },
        ..PointRemeshParams::default()
    };
    if let (Some(limit), Density::Points(n)) = (job.max_memory, job.params.density) {
        if n <= MAX_POINTS {
            memory::check_remesh_budget(0, n as f64, job.measure_distance, limit)?;
        }
    }
    let out = remesh_points(&job.input, &params, on_stage)?;

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
    let mut report = QualityReport::new(checked);
    let check_seconds = t.elapsed();
    check_and_write(
        job,
        &|mesh| write_output(job, format, mesh),
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
        let mut reader = PointReader::open(&job.input)?;
        let mut chunk = Vec::new();
        let mut positions: Vec<DVec3> = Vec::new();
        while reader.read_chunk(&mut chunk, DISTANCE_CHUNK)? > 0 {
            positions.clear();
            positions.extend(chunk.iter().map(|p| out.normalization.apply(p.position)));
            distance.add_points(&positions);
        }
        report.distance = Some(distance.finish());
        let (wall, cpu) = t.elapsed();
        report.push_stage("distance (report)", wall, cpu);
        report.notes.push(
            "Hausdorff and RMS are to the input points (output to its nearest point, each \
             point to the output), outliers included"
                .into(),
        );
    }

    let extra = &mut report.extra;
    insert_kernel_extras(extra, out.sigma_p, &job.params, out.target);
    extra.insert("input_points".into(), out.input_points.into());
    extra.insert("had_normals".into(), out.had_normals.into());
    extra.insert("outliers_removed".into(), out.outliers_removed.into());
    extra.insert("samples".into(), out.samples.into());
    extra.insert("unprojected_samples".into(), out.unprojected_samples.into());
    extra.insert("rescan_rejected".into(), out.rescan_rejected.into());
    extra.insert("rimls_points".into(), out.rimls_points.into());
    extra.insert(
        "scan_seconds".into(),
        serde_json::to_value(out.scan_seconds).unwrap_or_default(),
    );
    extra.insert(
        "assembly".into(),
        serde_json::to_value(&out.assembly).unwrap_or_default(),
    );
    extra.insert(
        "unsupported_faces".into(),
        serde_json::to_value(out.unsupported).unwrap_or_default(),
    );
    extra.insert(
        "optimize".into(),
        serde_json::to_value(out.optimize).unwrap_or_default(),
    );
    extra.insert(
        "untangle".into(),
        serde_json::to_value(out.untangle).unwrap_or_default(),
    );
    extra.insert(
        "untangle_umbrellas".into(),
        serde_json::to_value(out.untangle_umbrellas).unwrap_or_default(),
    );
    extra.insert(
        "output_orientation".into(),
        serde_json::to_value(out.output_orientation).unwrap_or_default(),
    );
    report.notes.push(format!(
        "the input is a point set ({} points, {}): the samples lie on the RIMLS surface of the \
         points and were connected by tangent-plane umbrellas",
        out.input_points,
        if out.had_normals {
            "with normals"
        } else {
            "normals estimated"
        }
    ));
    if out.outliers_removed > 0 {
        report.notes.push(format!(
            "{} isolated points (outliers) were left out of the samples and the surface",
            out.outliers_removed
        ));
    }
    count_note(&mut report.notes, out.target, out.mesh.vertex_count());
    if out.dropped_samples > 0 {
        report.notes.push(dropped_note(out.dropped_samples));
    }
    if report.topology.boundary_loops > 0 {
        report.notes.push(format!(
            "the points leave {} boundary loops open (gaps in the data wider than {} sigma_p: \
             {} faces across them were removed)",
            report.topology.boundary_loops,
            crate::point_pipeline::OPEN_GAP_SIGMA_P,
            out.unsupported.faces + out.unsupported.pinched_faces
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
    if out.assembly.holes_left > 0 {
        report.notes.push(holes_note(out.assembly.holes_left));
    }
    Ok(report)
}
