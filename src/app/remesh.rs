//! The remesh job: read the input, run the pipeline, check and write the output and its report
//! (atomically, together), and build the report with its notes.

use crate::timing::Clock;
use std::path::{Path, PathBuf};

use super::files::{is_stdout, output_format, refuse_input_as_output, report_clash, with_path};
use super::job::{RemeshJob, RemeshedMesh};
use super::memory;
use super::notes::{
    count_note, dropped_note, features_note, grading_notes, grew_the_count, holes_note,
    orientation_notes, topological_ball_notes,
};
use super::output::{check_and_write, insert_json, insert_kernel_extras, write_output, Outputs};
use super::quality::{
    as_quality_reads, crossings_of_the_input, into_normal_range, scale_by_power_of_two,
};
use super::remesh_points;
use super::DISTANCE_SAMPLES;
use crate::error::{Error, Result};
use crate::io::{as_written, check_and_clean, read_mesh, AtomicFile, MeshFormat};
use crate::mesh::TriMesh;
use crate::pipeline::{
    expected_samples, points_for_edge_length, remesh, validate_input, Density, RemeshParams,
    MAX_POINTS,
};
use crate::points::source::PointSource;
use crate::report::{surface_distance_with, QualityReport};
use crate::surface::MeshSurface;
use crate::triangulate::TriangulationMethod;

/// Reads, remeshes, writes, and reports. `on_stage` is called with each stage name as it starts.
///
/// The mesh goes to `job.output`, atomically, or with an output of `-`
/// ([`STDOUT`](crate::internal::STDOUT)) to standard output in `job.format` (OBJ by default);
/// either way its bytes are built in memory and written only once every check has passed, so an
/// error (or `--strict`) never leaves a part of a mesh behind. The report goes to `job.report` the
/// same way; both files are created (as temporary files beside their targets) before any work and
/// renamed into place only when both are written, so a run that fails leaves every file it would
/// write as it was.
///
/// The output's invariants ([`check_invariants`](crate::check_invariants)) are checked before it is
/// written, on the mesh as the output format stores it (glTF positions rounded to `f32` relative to
/// the node's translation; OBJ and PLY are exact); violations go into the report
/// ([`QualityReport::invariant_violations`] and a note). Its topology is compared with the input's;
/// every difference goes into the report ([`QualityReport::topology_changes`] and a note).
///
/// # Errors
/// Whatever reading, the pipeline or writing return, each naming the file concerned; an
/// [`Error::InvalidParameter`] when the output or the report path is the input's, or the report's
/// is the output's; [`Error::Write`] (before any work) for an output or report path that is a
/// directory or a special file or whose folder is missing; with `job.strict`, an
/// [`Error::Internal`] (stage `invariant check`) naming the violations when the output breaks an
/// invariant or its topology differs from the input's, and then nothing is written;
/// [`Error::InvalidParameter`] (usage errors, before any work) for an output extension no format
/// has, a `job.format` that contradicts it, a binary format for standard output when that is a
/// terminal, or (naming `--max-memory`) a job whose estimated peak memory is over `job.max_memory`.
pub fn run_remesh(job: &RemeshJob, on_stage: &(dyn Fn(&str) + Sync)) -> Result<QualityReport> {
    // The output's format is known before any work: an unknown extension is a usage error.
    let to_stdout = is_stdout(&job.output);
    let format = output_format(&job.output, job.format)?;
    if to_stdout && matches!(format, MeshFormat::Ply | MeshFormat::Glb | MeshFormat::Stl) {
        use std::io::IsTerminal;
        if std::io::stdout().is_terminal() {
            return Err(Error::InvalidParameter {
                name: "format",
                message: format!(
                    "standard output is a terminal, and {} is a binary format; redirect it to a \
                     file or a pipe",
                    format.extension().to_ascii_uppercase()
                ),
            });
        }
    }
    if !to_stdout {
        refuse_input_as_output(&job.input, &job.output)?;
    }
    if let Some(report) = &job.report {
        let mut others = vec![(job.input.as_path(), "the input file")];
        if !to_stdout {
            others.push((job.output.as_path(), "the output mesh"));
        }
        report_clash(report, &others)?;
    }
    // A mesh too large for the memory the job may take is refused before anything else is
    // allocated (the output buffers included: under a tight address-space limit they could not
    // be).
    let points = job.as_points || crate::pipeline::points::is_point_set(&job.input)?;
    if let (false, Some(limit)) = (points, job.max_memory) {
        memory::check_input_size(&job.input, limit)?;
    }
    // Every file the job writes is opened (as a temporary beside it) before the work: a path
    // that cannot be written is an error now, not after the run.
    let outputs = Outputs {
        mesh: std::cell::RefCell::new(if to_stdout {
            None
        } else {
            Some(AtomicFile::create(&job.output)?)
        }),
        written: std::cell::Cell::new(false),
        report: job.report.as_deref().map(AtomicFile::create).transpose()?,
    };
    let write = |mesh: &TriMesh| write_output(job, format, mesh, &outputs);
    let report = if points {
        remesh_points::run(
            job,
            &PointSource::File(job.input.clone()),
            format,
            &write,
            on_stage,
        )?
    } else {
        on_stage("read");
        let t = Clock::start();
        let (input, stats) = read_mesh(&job.input)?;
        let (_, report) = remesh_read(
            job,
            format,
            input,
            stats.welded_vertices,
            t,
            &write,
            on_stage,
        )?;
        report
    };
    outputs.commit(&report)?;
    Ok(report)
}

/// [`run_remesh`](crate::run_remesh) from the mesh read on (shared with
/// [`remesh_mesh`](crate::remesh_mesh)): the pipeline, the check, `write` (called with the output
/// mesh in model units once `--strict` has passed), the report. `input` is the mesh as read,
/// `welded_vertices` what reading welded, `t` the clock started before reading (the report's `read`
/// stage). Returns the output mesh as written and the report.
pub(super) fn remesh_read(
    job: &RemeshJob,
    format: MeshFormat,
    input: TriMesh,
    welded_vertices: usize,
    t: Clock,
    write: &dyn Fn(&TriMesh) -> Result<()>,
    on_stage: &(dyn Fn(&str) + Sync),
) -> Result<(TriMesh, QualityReport)> {
    let input_side = input.bbox().map_or(0.0, |b| b.longest_side());
    let (input, up) = into_normal_range(input);
    // Faces without area and repeated faces (double-sided exports, duplicated faces) carry no
    // surface of their own and only make crossings and non-manifold edges downstream (tested
    // after subnormal coordinates are scaled up, where the exact area test does not underflow).
    let mut input = input;
    let cleanup = input.remove_duplicate_and_zero_area_faces();
    if cleanup.any() {
        input.remove_unreferenced_vertices();
        if input.triangles.is_empty() {
            return Err(Error::invalid_mesh(
                &job.input,
                "no faces with area (every face is collinear or repeats another)",
            ));
        }
    }
    if up != 0 && matches!(format, MeshFormat::Gltf | MeshFormat::Glb | MeshFormat::Stl) {
        return Err(Error::InvalidParameter {
            name: "OUTPUT",
            message: format!(
                "{}: {} stores positions as 32-bit floats, which cannot hold the coordinates \
                 of {} (subnormal numbers); write .obj, .ply or .off",
                job.output.display(),
                if format == MeshFormat::Stl {
                    "STL"
                } else {
                    "glTF"
                },
                job.input.display()
            ),
        });
    }
    let read_seconds = t.elapsed();
    let params = job.params;
    if let Some(limit) = job.max_memory {
        let points = match params.density {
            Density::Points(n) => n as f64,
            Density::InputVertices => input.vertex_count() as f64,
            Density::EdgeLength(l) => points_for_edge_length(input.area(), l) as f64,
            Density::SigmaP(s) => {
                // The count sigma_p gives on the area, in bbox-100 units (the interior term of
                // the pipeline's expected count; the boundary samples are not counted here).
                let scale = validate_input(&input)
                    .map_err(|e| with_path(e, &job.input))?
                    .scale;
                expected_samples(input.area() * scale * scale, 0.0, s)
            }
        };
        // Beyond MAX_POINTS the pipeline refuses the density itself, naming the option.
        if points <= MAX_POINTS as f64 {
            memory::check_remesh_budget(
                input.face_count() as u64,
                points,
                job.measure_distance,
                limit,
            )?;
        }
    }
    let input_area = input.area();
    let out = remesh(&input, &params, on_stage).map_err(|e| with_path(e, &job.input))?;
    on_stage("check");
    let t = Clock::start();
    // The report and `--strict` describe the file: the mesh as the format stores it (OBJ and
    // PLY exactly; glTF in f32 relative to the node's translation), normalized like the input.
    // A model scaled up by 2^up is written scaled back (rounded to its subnormal numbers), and
    // checked as written.
    let scaled_back = (up != 0).then(|| scale_by_power_of_two(&out.mesh, -up));
    let mesh_out = scaled_back.as_ref().unwrap_or(&out.mesh);
    let written;
    let checked = match format {
        MeshFormat::Obj | MeshFormat::Ply | MeshFormat::Off if up == 0 => &out.mesh_normalized,
        MeshFormat::Obj | MeshFormat::Ply | MeshFormat::Off => {
            written = out
                .normalization
                .apply_mesh(&scale_by_power_of_two(mesh_out, up));
            &written
        }
        MeshFormat::Gltf | MeshFormat::Glb | MeshFormat::Stl => {
            written = out.normalization.apply_mesh(&as_written(&out.mesh, format));
            &written
        }
    };
    // The invariants, crossings and topology are those `remesh quality` finds in the file: the
    // mesh as stored, welded as a reader welds it, in its own bbox-100 frame; crossings are
    // decided exactly at the file's own coordinates, so a face pair that rounding makes touch is
    // seen here as in the file.
    let file = as_quality_reads(as_written(mesh_out, format), &job.output);
    let mut report = match &file {
        Some((m, _, stored)) => QualityReport::with_crossings_on(m, stored),
        None => QualityReport::new(checked),
    };
    // The input column describes the input as read: its faces before they were oriented
    // (orientation changes none of the counts the topology is compared by).
    report.set_input(&TriMesh::new(
        out.input_normalized.positions.clone(),
        input.triangles.clone(),
    ));
    if let Some(t) = report.input_topology.clone() {
        if t.non_manifold_vertices > 0 || t.non_manifold_edges > 0 {
            report.notes.push(format!(
                "the input has {} non-manifold vertices and {} non-manifold edges; the sampler \
                 works on the surface as a point set and the output is rebuilt manifold{}",
                t.non_manifold_vertices,
                t.non_manifold_edges,
                if t.non_manifold_edges > 0 {
                    " (parts that meet at a non-manifold edge are triangulated apart)"
                } else {
                    " (parts or sheets that touch at a vertex come out apart, and the topology \
                     is compared with the input's split there)"
                }
            ));
        }
    }
    // With `strict`, a count too small to keep the topology is refused: the samples inserted
    // for it took the count more than 1% past the target.
    if let (true, Some(rd), Some(n)) = (job.strict, &out.restricted_delaunay, out.target) {
        let (inserted, written) = (rd.topological_ball.inserted, mesh_out.vertex_count());
        if inserted > 0 && written as f64 > 1.01 * n as f64 {
            return Err(Error::Internal {
                stage: "invariant check",
                message: format!(
                    "{n} points are too few to keep the input's topology ({written} written, \
                     {inserted} of them inserted for it); {} was not written (`strict`)",
                    job.output.display()
                ),
            });
        }
    }
    // With `strict`, a count the sizing field had to grow is refused too.
    if let (true, Some(g), Some(n)) = (job.strict, &out.grading, out.target) {
        let written = mesh_out.vertex_count();
        if grew_the_count(g, written, out.target) {
            return Err(Error::Internal {
                stage: "invariant check",
                message: format!(
                    "{n} points are too few for the input's local feature size ({written} \
                     written, {} of them spaced by it); {} was not written (`strict`; \
                     without `lfs_factor` the count is kept with one sigma_p)",
                    g.graded_samples,
                    job.output.display()
                ),
            });
        }
    }
    let check_seconds = t.elapsed();
    report.push_stage("read", read_seconds.0, read_seconds.1);
    check_and_write(
        job,
        write,
        mesh_out,
        &mut report,
        &out.stages,
        check_seconds,
        on_stage,
    )?;
    if job.measure_distance {
        on_stage("distance");
        let t = Clock::start();
        // Each side's error names its mesh (a surface of no area has no closest points).
        let a = MeshSurface::new(checked).map_err(|e| with_path(e, &job.output))?;
        let b = MeshSurface::new(&out.input_normalized).map_err(|e| with_path(e, &job.input))?;
        report.distance = Some(surface_distance_with(
            checked,
            &a,
            &out.input_normalized,
            &b,
            DISTANCE_SAMPLES,
            params.seed,
        ));
        let (wall, cpu) = t.elapsed();
        report.push_stage("distance (report)", wall, cpu);
    }
    let extra = &mut report.extra;
    insert_kernel_extras(extra, out.sigma_p, &params, out.target);
    extra.insert("samples".into(), out.samples.into());
    extra.insert("boundary_samples".into(), out.boundary_samples.into());
    extra.insert("candidates".into(), out.candidates.into());
    insert_json(extra, "sigma_p_search", &out.search_history);
    insert_json(extra, "assembly", &out.assembly);
    insert_json(extra, "restricted_delaunay", &out.restricted_delaunay);
    if out.restricted_delaunay.is_none() && params.triangulation != TriangulationMethod::Umbrellas {
        report.notes.push(
            "the samples were connected by tangent-plane umbrellas: the restricted Delaunay \
             triangulation would have refined this input too far (slivers) or gave no triangle"
                .into(),
        );
    }
    insert_json(extra, "optimize", out.optimize);
    insert_json(extra, "untangle", out.untangle);
    if out.mend_after_untangle.attempts > 0 {
        insert_json(extra, "mend_after_untangle", out.mend_after_untangle);
    }
    if out.refine.rounds > 0 {
        insert_json(extra, "refine", out.refine);
    }
    if out.degenerate.found > 0 {
        insert_json(extra, "degenerate", out.degenerate);
    }
    let crossing = report.self_intersections.pairs;
    // The file's crossing pairs, and of them those where the input's own faces cross or its
    // closed parts meet.
    let theirs = match (&file, crossing) {
        (Some((m, frame, stored)), 1..) => crossings_of_the_input(&out, m, stored, frame, up),
        _ => 0,
    };
    extra.insert(
        "output_crossings".into(),
        serde_json::json!({"pairs": crossing, "where_input_crosses": theirs}),
    );
    if crossing > 0 {
        report.notes.push(if theirs == crossing {
            format!(
                "all {crossing} crossing pairs of the output lie where the input's own faces \
                 cross or its parts meet at non-manifold edges"
            )
        } else {
            format!(
                "{} of the output's {crossing} crossing pairs lie where the input's faces \
                 neither cross nor meet ({theirs} where they do)",
                crossing - theirs
            )
        });
    }
    insert_json(extra, "features", &out.features);
    if let Some(fit) = out.fit {
        insert_json(extra, "fit", fit);
    }
    extra.insert("input_vertices".into(), input.vertex_count().into());
    extra.insert("input_faces".into(), input.face_count().into());
    if up != 0 {
        report.notes.push(format!(
            "the input's coordinates are subnormal numbers (bounding box {:e} across): the model \
             was scaled by 2^{up} for the work (exactly) and the output scaled back",
            input_side
        ));
    }
    if cleanup.any() {
        let mut parts = Vec::new();
        if cleanup.duplicates > 0 {
            let copies = cleanup.duplicates - cleanup.opposite_duplicates;
            parts.push(match (cleanup.opposite_duplicates, copies) {
                (0, n) => format!("{n} duplicate faces"),
                (m, 0) => format!("{m} faces that are the back of a double-sided face"),
                (m, n) => format!(
                    "{} duplicate faces ({m} of them the back of a double-sided face)",
                    m + n
                ),
            });
        }
        if cleanup.internal_walls > 0 {
            parts.push(format!(
                "{} faces between two closed parts (walls inside the solid they make, given in \
                 both windings)",
                cleanup.internal_walls
            ));
        }
        if cleanup.zero_area > 0 {
            parts.push(format!("{} faces of zero area", cleanup.zero_area));
        }
        report
            .notes
            .push(format!("the input's {} were left out", parts.join(" and ")));
    }
    let left = out.optimize.mend.left;
    if let (true, Some(op)) = (left.total > 0, params.optimize.as_ref()) {
        let elsewhere = left.total - left.at_creases - left.on_boundary - left.at_input_crossings;
        let parts: Vec<String> = [
            (left.at_creases, "at a kept crease"),
            (left.on_boundary, "on the boundary"),
            (left.at_input_crossings, "where the input's own faces cross"),
            (elsewhere, "elsewhere"),
        ]
        .into_iter()
        .filter(|&(n, _)| n > 0)
        .map(|(n, where_)| format!("{n} {where_}"))
        .collect();
        report.notes.push(format!(
            "{} faces are outside the angle bounds [{}°, {}°] after the last pass ({}): no flip, \
             collapse, move or split within the guards mends them{}",
            left.total,
            op.final_theta_deg,
            op.final_theta_max_deg,
            parts.join(", "),
            if out.optimize.mend.exhausted {
                ", and the pass's budget ran out"
            } else {
                ""
            }
        ));
    }
    insert_json(extra, "input_cleanup", cleanup);
    if welded_vertices > 0 {
        report.notes.push(format!(
            "{welded_vertices} input vertices at the position of another (identical, or a rounding apart) were merged"
        ));
    }
    if let (Density::EdgeLength(l), Some(n)) = (job.params.density, out.target) {
        report.notes.push(format!(
            "--edge-length {l}: about {n} points (equilateral triangles of that edge on the \
             input's area, {input_area:.6e} square units)"
        ));
    }
    // A count the sizing field grew is the field's note, not a miss.
    let grown = out
        .grading
        .as_ref()
        .is_some_and(|g| grew_the_count(g, out.mesh.vertex_count(), out.target));
    if !grown {
        count_note(&mut report.notes, out.target, out.mesh.vertex_count());
    }
    if let Some(rd) = &out.restricted_delaunay {
        let (target, vertices) = (out.target, out.mesh.vertex_count());
        topological_ball_notes(&mut report.notes, &rd.topological_ball, target, vertices);
    }
    if out.buried_candidates + out.buried_samples > 0 {
        report.notes.push(format!(
            "the input passes through itself: {} candidate points inside its own solid were left \
             out and {} samples moved there were put back, so the output follows its outer \
             surface there",
            out.buried_candidates, out.buried_samples
        ));
    }
    extra.insert("buried_candidates".into(), out.buried_candidates.into());
    if let Some(g) = &out.grading {
        extra.insert(
            "grading".into(),
            serde_json::json!({
                "graded_samples": g.graded_samples,
                "unresolved_samples": g.unresolved_samples,
                "min_width": g.min_width,
                "regions": g.regions.iter().map(|r| serde_json::json!({
                    "min": [r.min.x, r.min.y, r.min.z],
                    "max": [r.max.x, r.max.y, r.max.z],
                    "samples": r.samples,
                    "unresolved": r.unresolved,
                })).collect::<Vec<_>>(),
            }),
        );
        report
            .notes
            .extend(grading_notes(g, out.mesh.vertex_count(), out.target));
        let st = &out.stray_shells;
        if st.shells > 0 {
            let (lo, hi) = (
                out.normalization.invert(st.min),
                out.normalization.invert(st.max),
            );
            report.notes.push(format!(
                "{} tiny closed pieces ({} vertices) that split off where the surface is too \
                 thin for this count were left out (a tip comes out blunted, a part thinner \
                 still may come out broken): [{:.4}, {:.4}, {:.4}]-[{:.4}, {:.4}, {:.4}]",
                st.shells, st.vertices, lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
            ));
        }
        extra.insert(
            "stray_shells".into(),
            serde_json::json!({"shells": st.shells, "vertices": st.vertices}),
        );
    }
    insert_json(extra, "orientation", out.orientation);
    insert_json(extra, "output_orientation", out.output_orientation);
    report.notes.extend(orientation_notes(
        &out.orientation,
        &out.output_orientation,
        input.face_count(),
    ));
    if out.dropped_samples > 0 {
        report.notes.push(dropped_note(out.dropped_samples));
    }
    if let Some(note) = features_note(&out.features) {
        report.notes.push(note);
    }
    if out.assembly.holes_left > 0 {
        report.notes.push(holes_note(out.assembly.holes_left));
    }
    Ok((scaled_back.unwrap_or(out.mesh), report))
}

/// Remeshes a mesh held in memory exactly as [`run_remesh`](crate::run_remesh) remeshes a file
/// holding it (written as PLY, OBJ or OFF): the checks and clean-up reading gives a file's mesh
/// (faces present, indices in range, finite coordinates; positions within a rounding welded, unreferenced
/// vertices removed), the same pipeline, check and report. The same `params` give the same output
/// mesh, bit for bit, as `remesh` on a file holding `mesh`.
///
/// `measure_distance`, `strict` and `max_memory` are [`RemeshJob`]'s fields of those names;
/// `on_stage` is called with each stage's name as it starts. Errors name the mesh as `input mesh`.
///
/// # Errors
/// [`Error::InvalidMesh`] for a mesh that fails the reader's checks; whatever the pipeline returns
/// ([`Error::InvalidParameter`] for parameters out of range); with `strict`, an [`Error::Internal`]
/// (stage `invariant check`) when the output breaks an invariant or its topology differs from the
/// input's; [`Error::InvalidParameter`] naming `--max-memory` for a job whose estimated peak memory
/// is over `max_memory`.
pub fn remesh_mesh(
    mesh: TriMesh,
    params: &RemeshParams,
    measure_distance: bool,
    strict: bool,
    max_memory: Option<u64>,
    on_stage: &(dyn Fn(&str) + Sync),
) -> Result<RemeshedMesh> {
    const INPUT: &str = "input mesh";
    on_stage("read");
    let t = Clock::start();
    let (input, welded_vertices) = check_and_clean(Path::new(INPUT), mesh)?;
    let job = RemeshJob::in_memory(
        PathBuf::from(INPUT),
        params,
        measure_distance,
        strict,
        max_memory,
        None,
    );
    // PLY: the output is handed over in f64, exactly as PLY, OBJ and OFF store it.
    let (mesh, report) = remesh_read(
        &job,
        MeshFormat::Ply,
        input,
        welded_vertices,
        t,
        &|_| Ok(()),
        on_stage,
    )?;
    Ok(RemeshedMesh { mesh, report })
}
