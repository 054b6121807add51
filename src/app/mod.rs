//! The jobs behind the `remesh` command line, as library functions: remesh a file and report on
//! it, report on any mesh against a reference, simplify a point set out of core, draw points
//! from a mesh; writing the JSON report, and turning a panic into an error.

mod memory;
mod options;
mod remesh_points;
pub use remesh_points::remesh_point_set;
mod simplify;

pub use memory::{estimate_remesh_bytes, memory_limit, parse_bytes, physical_memory};
pub use options::RemeshOptions;
pub use simplify::{run_simplify, SimplifyDensity, SimplifyDetail, SimplifyJob, SimplifySummary};

use crate::geometry::self_intersection::{intersecting_pairs, CrossingRegions};
use crate::timing::Clock;
use crate::RemeshOutput;
use glam::DVec3;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::io::{
    as_written, check_and_clean, encode_mesh, read_mesh, write_atomically, AtomicFile, MeshFormat,
};
use crate::mesh::{Normalization, OrientStats, TriMesh};
use crate::pipeline::{
    expected_samples, remesh, validate_input, Density, RemeshParams, MAX_POINTS,
};
use crate::report::{surface_distance_with, QualityReport};
use crate::surface::MeshSurface;
use crate::triangulate::TriangulationMethod;

/// Samples per side for the Hausdorff and RMS distances of the report (Metro-style, on top of
/// every vertex).
pub const DISTANCE_SAMPLES: usize = 200_000;

/// A remeshing job: input and output files and the pipeline's parameters.
#[derive(Debug, Clone)]
pub struct RemeshJob {
    /// Input mesh (.obj, .ply, .gltf, .glb).
    pub input: PathBuf,
    /// Output mesh (.obj, .ply, .gltf, .glb), format by extension; `-` ([`STDOUT`]) writes it
    /// to standard output instead, in `format`.
    pub output: PathBuf,
    /// The output's format: `None` takes it from `output`'s extension, or OBJ for standard
    /// output. Given with a file, it must agree with the extension; the binary formats (PLY,
    /// GLB) go to standard output only when asked for here, and never to a terminal.
    pub format: Option<MeshFormat>,
    /// Pipeline parameters (`Density::InputVertices`: as many as the input has vertices).
    pub params: RemeshParams,
    /// Whether to measure the distance to the input (Hausdorff, RMS).
    pub measure_distance: bool,
    /// Whether a violated output invariant ([`check_invariants`](crate::check_invariants):
    /// manifold, oriented, no degenerate, duplicate or intersecting faces) or a topology that
    /// differs from the input's ([`topology_changes`](crate::topology_changes): components,
    /// Euler characteristic, boundary loops) is an error, with nothing written, rather than a
    /// note of the report.
    pub strict: bool,
    /// The most memory the job may take, in bytes: a job whose estimated peak
    /// ([`estimate_remesh_bytes`]) is larger is refused before it starts (and an input file too
    /// large to fit is refused before it is read). `None`: no limit.
    pub max_memory: Option<u64>,
    /// Whether the input is read as a point set (its faces ignored) even when it has faces:
    /// `--as-points` (a PLY file). A text point file or a PLY file without faces is read as a
    /// point set either way ([`is_point_set`](crate::is_point_set)).
    pub as_points: bool,
    /// For a point set without normals: the estimated normals face this point (model units; a
    /// single scan's sensor) instead of being oriented outward by a spanning tree. Not used for
    /// meshes.
    pub viewpoint: Option<glam::DVec3>,
    /// Where the JSON report goes as well (`--report`): written with the mesh, both only once
    /// everything has been written. `None`: nowhere.
    pub report: Option<PathBuf>,
}

/// Reads, remeshes, writes, and reports. `on_stage` is called with each stage name as it starts.
///
/// The mesh goes to `job.output`, atomically, or with an output of `-` ([`STDOUT`]) to standard
/// output in `job.format` (OBJ by default); either way its bytes are built in memory and written
/// only once every check has passed, so an error (or `--strict`) never leaves a part of a mesh
/// behind. The report goes to `job.report` the same way; both files are created (as temporary
/// files beside their targets) before any work and renamed into place only when both are
/// written, so a run that fails leaves every file it would write as it was.
///
/// The output's invariants ([`check_invariants`](crate::check_invariants)) are checked before it
/// is written, on the mesh as the output format stores it (glTF positions rounded to `f32`
/// relative to the node's translation; OBJ and PLY are exact); violations go into the report ([`QualityReport::invariant_violations`] and a note).
/// Its topology is compared with the input's; every difference goes into the report
/// ([`QualityReport::topology_changes`] and a note).
///
/// # Errors
/// Whatever reading, the pipeline or writing return, each naming the file concerned; an
/// [`Error::InvalidParameter`] when the output or the report path is the input's, or the
/// report's is the output's; [`Error::Write`] (before any work) for an output or report path
/// that is a directory or a special file or whose folder is missing; with `job.strict`, an
/// [`Error::Internal`] (stage `invariant check`) naming the violations when the output breaks
/// an invariant or its topology differs from the input's, and then nothing is written;
/// [`Error::InvalidParameter`] (usage errors, before any work) for an output extension no
/// format has, a `job.format` that contradicts it, a binary format for standard output when
/// that is a terminal, or (naming `--max-memory`) a job whose estimated peak memory is over
/// `job.max_memory`.
pub fn run_remesh(job: &RemeshJob, on_stage: &(dyn Fn(&str) + Sync)) -> Result<QualityReport> {
    // The output's format is known before any work: an unknown extension is a usage error.
    let to_stdout = is_stdout(&job.output);
    let format = output_format(&job.output, job.format)?;
    if to_stdout && matches!(format, MeshFormat::Ply | MeshFormat::Glb | MeshFormat::Stl) {
        use std::io::IsTerminal;
        if std::io::stdout().is_terminal() {
            return Err(Error::InvalidParameter {
                name: "--format",
                message: format!(
                    "standard output is a terminal, and {} is a binary format; redirect it to a \
                     file or a pipe",
                    format.extension().to_ascii_uppercase()
                ),
            });
        }
    }
    if !to_stdout && same_target(&job.input, &job.output) {
        return Err(Error::InvalidParameter {
            name: "OUTPUT",
            message: format!(
                "{} is the input file; choose another output path",
                job.output.display()
            ),
        });
    }
    if let Some(report) = &job.report {
        let mut others = vec![(job.input.as_path(), "the input file")];
        if !to_stdout {
            others.push((job.output.as_path(), "the output mesh"));
        }
        report_clash(report, &others)?;
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
    let report = if job.as_points || crate::is_point_set(&job.input)? {
        remesh_points::run(job, format, &write, on_stage)?
    } else {
        if let Some(limit) = job.max_memory {
            memory::check_input_size(&job.input, limit)?;
        }
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

/// The files a [`RemeshJob`] writes, open as temporary files until [`Outputs::commit`]: the
/// mesh (`None` for standard output), whether its bytes went in, and the report.
struct Outputs {
    mesh: std::cell::RefCell<Option<AtomicFile>>,
    written: std::cell::Cell<bool>,
    report: Option<AtomicFile>,
}

impl Outputs {
    /// Writes `report` into its file, then renames the mesh and the report into place.
    ///
    /// # Errors
    /// [`Error::Write`] naming the file that could not be written; the temporary files are
    /// removed (a mesh renamed before the report's rename failed stays).
    fn commit(self, report: &QualityReport) -> Result<()> {
        use std::io::Write;
        let mut report_file = self.report;
        if let Some(f) = &mut report_file {
            f.write_all(report.to_json().as_bytes())
                .map_err(|e| f.error(format!("cannot write: {e}")))?;
        }
        if let Some(mesh) = self.mesh.into_inner() {
            if self.written.get() {
                mesh.commit()?;
            }
        }
        report_file.map_or(Ok(()), AtomicFile::commit)
    }
}

/// [`run_remesh`] from the mesh read on (shared with [`remesh_mesh`]): the pipeline, the check,
/// `write` (called with the output mesh in model units once `--strict` has passed), the report.
/// `input` is the mesh as read, `welded_vertices` what reading welded, `t` the clock started
/// before reading (the report's `read` stage). Returns the output mesh as written and the report.
fn remesh_read(
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
    // mesh as stored, welded as a reader welds it, in its own bbox-100 frame (crossings are
    // decided exactly, so a face pair that rounding makes touch is seen here as in the file).
    let file = as_quality_reads(as_written(mesh_out, format), &job.output);
    let mut report = QualityReport::new(file.as_ref().map_or(checked, |(m, _)| m));
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
                    ""
                }
            ));
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
        let a = MeshSurface::new(checked)?;
        let b = MeshSurface::new(&out.input_normalized)?;
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
    extra.insert(
        "sigma_p_search".into(),
        serde_json::to_value(&out.search_history).unwrap_or_default(),
    );
    extra.insert(
        "assembly".into(),
        serde_json::to_value(&out.assembly).unwrap_or_default(),
    );
    extra.insert(
        "restricted_delaunay".into(),
        serde_json::to_value(&out.restricted_delaunay).unwrap_or_default(),
    );
    if out.restricted_delaunay.is_none() && params.triangulation != TriangulationMethod::Umbrellas {
        report.notes.push(
            "the samples were connected by tangent-plane umbrellas: the restricted Delaunay \
             triangulation would have refined this input too far (slivers) or gave no triangle"
                .into(),
        );
    }
    extra.insert(
        "optimize".into(),
        serde_json::to_value(out.optimize).unwrap_or_default(),
    );
    extra.insert(
        "untangle".into(),
        serde_json::to_value(out.untangle).unwrap_or_default(),
    );
    if out.degenerate.found > 0 {
        extra.insert(
            "degenerate".into(),
            serde_json::to_value(out.degenerate).unwrap_or_default(),
        );
    }
    let crossing = report.self_intersections.pairs;
    // The file's crossing pairs, and of them those where the input's own faces cross or its
    // closed parts meet.
    let theirs = match (&file, crossing) {
        (Some((m, frame)), 1..) => crossings_of_the_input(&out, m, frame, up),
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
    extra.insert(
        "features".into(),
        serde_json::to_value(&out.features).unwrap_or_default(),
    );
    if let Some(fit) = out.fit {
        extra.insert("fit".into(), serde_json::to_value(fit).unwrap_or_default());
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
    extra.insert(
        "input_cleanup".into(),
        serde_json::to_value(cleanup).unwrap_or_default(),
    );
    if welded_vertices > 0 {
        report.notes.push(format!(
            "{welded_vertices} input vertices at identical positions were merged"
        ));
    }
    count_note(&mut report.notes, out.target, out.mesh.vertex_count());
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
            .extend(grading_notes(g, out.mesh.vertex_count()));
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
    extra.insert(
        "orientation".into(),
        serde_json::to_value(out.orientation).unwrap_or_default(),
    );
    extra.insert(
        "output_orientation".into(),
        serde_json::to_value(out.output_orientation).unwrap_or_default(),
    );
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

/// The report's note when the output's vertex count is more than 1% off the target.
fn count_note(notes: &mut Vec<String>, target: Option<usize>, vertices: usize) {
    if let Some(n) = target {
        if (vertices as f64 - n as f64).abs() > 0.01 * n as f64 {
            notes.push(format!(
                "target not reached: {vertices} vertices for --points {n} (more than 1% off)"
            ));
        }
    }
}

/// The report's note on samples that ended in no triangle.
fn dropped_note(dropped: usize) -> String {
    format!("{dropped} samples ended in no triangle and were left out")
}

/// The report's note on holes of the triangulation left open.
fn holes_note(holes: usize) -> String {
    format!("{holes} holes of the triangulation could not be closed")
}

/// The report's `sigma_p`, `sigma_n`, `target_points` and `seed` entries.
fn insert_kernel_extras(
    extra: &mut serde_json::Map<String, serde_json::Value>,
    sigma_p: f64,
    params: &RemeshParams,
    target: Option<usize>,
) {
    extra.insert("sigma_p".into(), sigma_p.into());
    extra.insert(
        "sigma_n".into(),
        if params.sigma_n.is_finite() {
            params.sigma_n.into()
        } else {
            "infinity".into()
        },
    );
    if let Some(n) = target {
        extra.insert("target_points".into(), n.into());
    }
    extra.insert("seed".into(), params.seed.into());
}

/// The end of a remeshing job: `--strict` ([`refuse_if_strict`]), then `mesh` written by
/// `write`, and the report's stages: the pipeline's `stages`, the check (`check_seconds`, wall
/// and processor) and the write.
fn check_and_write(
    job: &RemeshJob,
    write: &dyn Fn(&TriMesh) -> Result<()>,
    mesh: &TriMesh,
    report: &mut QualityReport,
    stages: &[crate::timing::Stage],
    check_seconds: (f64, f64),
    on_stage: &(dyn Fn(&str) + Sync),
) -> Result<()> {
    refuse_if_strict(job, report)?;
    on_stage("write");
    let t = Clock::start();
    write(mesh)?;
    let write_seconds = t.elapsed();
    for s in stages {
        report.push_stage(s.name, s.seconds, s.cpu_seconds);
    }
    report.push_stage("check (report)", check_seconds.0, check_seconds.1);
    report.push_stage("write", write_seconds.0, write_seconds.1);
    Ok(())
}

/// Notes the output's invariant violations in `report`; with `job.strict`, an error when it
/// breaks an invariant or its topology differs from the input's.
fn refuse_if_strict(job: &RemeshJob, report: &mut QualityReport) -> Result<()> {
    let mut refusals = Vec::new();
    if !report.invariant_violations.is_empty() {
        let list = report
            .invariant_violations
            .iter()
            .map(|v| v.to_string())
            .collect::<Vec<_>>()
            .join("; ");
        refusals.push(format!("the output mesh breaks its invariants ({list})"));
        report
            .notes
            .push(format!("the output mesh breaks its invariants: {list}"));
    }
    if !report.topology_changes.is_empty() {
        refusals.push(format!(
            "the output's topology differs from the input's ({})",
            report.topology_changes_text()
        ));
    }
    if job.strict && !refusals.is_empty() {
        return Err(Error::Internal {
            stage: "invariant check",
            message: format!(
                "{}; {} was not written (--strict)",
                refusals.join("; "),
                job.output.display()
            ),
        });
    }
    Ok(())
}

/// Writes `mesh` to `job.output` in `format`, atomically, or to standard output: the complete
/// bytes or nothing.
fn write_output(
    job: &RemeshJob,
    format: MeshFormat,
    mesh: &TriMesh,
    outputs: &Outputs,
) -> Result<()> {
    use std::io::Write;
    let bytes = encode_mesh(&job.output, mesh, format)?;
    if let Some(file) = outputs.mesh.borrow_mut().as_mut() {
        file.write_all(&bytes)
            .map_err(|e| file.error(format!("cannot write: {e}")))?;
        outputs.written.set(true);
        Ok(())
    } else {
        let mut stdout = std::io::stdout().lock();
        stdout
            .write_all(&bytes)
            .and_then(|()| stdout.flush())
            .map_err(|e| Error::Write {
                path: job.output.clone(),
                message: format!("cannot write to standard output: {e}"),
            })
    }
}

/// The report's notes on orienting the input and the output ([`OrientStats`]): how many input
/// faces were reversed and why, a non-orientable input said plainly, and an inward-facing
/// closed input whose output was turned outward.
fn orientation_notes(input: &OrientStats, output: &OrientStats, input_faces: usize) -> Vec<String> {
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

/// Reports on the mesh in `path`; with `reference`, also the distance to it. Both are scaled by
/// the reference's bbox-100 normalization (or the mesh's own without a reference).
///
/// # Errors
/// Reading errors naming the file; [`Error::InvalidMesh`] for a mesh without area.
pub fn run_quality(path: &Path, reference: Option<&Path>, seed: u64) -> Result<QualityReport> {
    let t = Clock::start();
    let (mesh, _) = read_mesh(path)?;
    let reference = reference
        .map(|r| read_mesh(r).map(|(m, _)| (m, r)))
        .transpose()?;
    quality_read(mesh, path, reference, seed, t)
}

/// Reports on a mesh held in memory as [`run_quality`] reports on a file holding it: `mesh`
/// and `reference` get the checks and clean-up reading gives a file's mesh (faces present,
/// indices in range, finite coordinates; identical positions welded, unreferenced vertices
/// removed), then the same measures; with `reference`, the distance to it too (both in the
/// reference's bbox-100 frame, or the mesh's own without one; the distance's random points
/// from `seed`). The report equals `run_quality`'s for files holding the same meshes, but for
/// its stage times.
///
/// # Errors
/// [`Error::InvalidMesh`] naming `mesh` or `reference` for a mesh that fails those checks or
/// has no area.
pub fn quality_mesh(mesh: TriMesh, reference: Option<TriMesh>, seed: u64) -> Result<QualityReport> {
    let t = Clock::start();
    let (mesh, _) = check_and_clean(Path::new("mesh"), mesh)?;
    let reference = reference
        .map(|r| {
            check_and_clean(Path::new("reference"), r).map(|(m, _)| (m, Path::new("reference")))
        })
        .transpose()?;
    quality_read(mesh, Path::new("mesh"), reference, seed, t)
}

/// [`run_quality`] from the meshes read on (shared with [`quality_mesh`]): `path` and the
/// reference's path name them in errors; `t` is the clock started before reading.
fn quality_read(
    mesh: TriMesh,
    path: &Path,
    reference: Option<(TriMesh, &Path)>,
    seed: u64,
    t: Clock,
) -> Result<QualityReport> {
    // Subnormal coordinates: both meshes scaled up alike (the report is in bbox-100 units).
    let (mesh, reference) = match &reference {
        Some((r, p)) => {
            let (r, up) = into_normal_range(r.clone());
            (scale_by_power_of_two(&mesh, up), Some((r, *p)))
        }
        None => (into_normal_range(mesh).0, None),
    };
    let frame = reference.as_ref().map_or(&mesh, |(r, _)| r);
    let normalization = own_frame(frame, path)?;
    let m = normalization.apply_mesh(&mesh);
    let mut report = QualityReport::new(&m);
    let (wall, cpu) = t.elapsed();
    report.push_stage("read and measure", wall, cpu);
    if let Some((r, reference_path)) = &reference {
        let t = Clock::start();
        let rn = normalization.apply_mesh(r);
        report.set_input(&rn);
        // Each side's error names its own file.
        let sm = MeshSurface::new(&m).map_err(|e| with_path(e, path))?;
        let sr = MeshSurface::new(&rn).map_err(|e| with_path(e, reference_path))?;
        report.distance = Some(surface_distance_with(
            &m,
            &sm,
            &rn,
            &sr,
            DISTANCE_SAMPLES,
            seed,
        ));
        let (wall, cpu) = t.elapsed();
        report.push_stage("distance", wall, cpu);
    }
    Ok(report)
}

impl RemeshJob {
    /// The job of an input held in memory ([`remesh_mesh`], [`remesh_point_set`]): `input`
    /// names it (or is the temporary file holding it); the output is handed back, not written.
    fn in_memory(
        input: PathBuf,
        params: &RemeshParams,
        measure_distance: bool,
        strict: bool,
        max_memory: Option<u64>,
        viewpoint: Option<glam::DVec3>,
    ) -> Self {
        RemeshJob {
            input,
            output: PathBuf::from("the output mesh"),
            format: None,
            params: *params,
            measure_distance,
            strict,
            max_memory,
            as_points: false,
            viewpoint,
            report: None,
        }
    }
}

/// The output of [`remesh_mesh`]: the remeshed mesh and its report.
#[derive(Debug, Clone)]
pub struct RemeshedMesh {
    /// The output mesh in the input's (model) units: what [`run_remesh`] writes to a file (as
    /// PLY, OBJ or OFF, which store it exactly).
    pub mesh: TriMesh,
    /// The report, as [`run_remesh`] gives it (its `write` stage is the hand-over of the mesh).
    pub report: QualityReport,
}

/// Remeshes a mesh held in memory exactly as [`run_remesh`] remeshes a file holding it (written
/// as PLY, OBJ or OFF): the checks and clean-up reading gives a file's mesh (faces present,
/// indices in range, finite coordinates; identical positions welded, unreferenced vertices
/// removed), the same pipeline, check and report. The same `params` give the same output mesh,
/// bit for bit, as `remesh` on a file holding `mesh`.
///
/// `measure_distance`, `strict` and `max_memory` are [`RemeshJob`]'s fields of those names;
/// `on_stage` is called with each stage's name as it starts. Errors name the mesh as `input
/// mesh`.
///
/// # Errors
/// [`Error::InvalidMesh`] for a mesh that fails the reader's checks; whatever the pipeline
/// returns ([`Error::InvalidParameter`] for parameters out of range); with `strict`, an
/// [`Error::Internal`] (stage `invariant check`) when the output breaks an invariant or its
/// topology differs from the input's; [`Error::InvalidParameter`] naming `--max-memory` for a
/// job whose estimated peak memory is over `max_memory`.
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

/// The output path that means standard output: `-`.
pub const STDOUT: &str = "-";

/// Whether `output` is [`STDOUT`].
fn is_stdout(output: &Path) -> bool {
    output.as_os_str() == STDOUT
}

/// The format a [`RemeshJob`] writes: `format` where given (agreeing with a file's extension),
/// else by the extension, or OBJ for standard output.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `OUTPUT` for an extension no mesh format has, or
/// `--format` when it contradicts the extension.
fn output_format(output: &Path, format: Option<MeshFormat>) -> Result<MeshFormat> {
    if is_stdout(output) {
        return Ok(format.unwrap_or(MeshFormat::Obj));
    }
    let by_extension = MeshFormat::from_path(output).map_err(|_| Error::InvalidParameter {
        name: "OUTPUT",
        message: format!(
            "{}: unsupported output format (expected .obj, .ply, .off, .stl, .gltf or .glb, or - \
             for standard output)",
            output.display()
        ),
    })?;
    match format {
        Some(f) if f != by_extension => Err(Error::InvalidParameter {
            name: "--format",
            message: format!(
                "--format {} contradicts the extension of {}; the format of a file is its \
                 extension's (--format chooses the format of standard output, -)",
                f.extension(),
                output.display()
            ),
        }),
        _ => Ok(by_extension),
    }
}

/// `mesh` (model units, as a file stores it) as [`run_quality`] sees the file: cleaned as a
/// reader cleans it ([`check_and_clean`]: identical positions welded, unreferenced vertices
/// dropped), subnormal coordinates scaled up, in its own bbox-100 frame ([`own_frame`]).
/// `None` when the file would be refused.
/// With it, the map from model units (before the subnormal scaling) into that frame.
fn as_quality_reads(mesh: TriMesh, path: &Path) -> Option<(TriMesh, FileFrame)> {
    let (mesh, _) = check_and_clean(path, mesh).ok()?;
    let (mesh, up) = into_normal_range(mesh);
    let frame = own_frame(&mesh, path).ok()?;
    Some((frame.apply_mesh(&mesh), FileFrame { frame, up }))
}

/// The frame [`as_quality_reads`] puts a file's mesh in: scaled by `2^up`, then `frame`.
#[derive(Debug, Clone, Copy)]
struct FileFrame {
    frame: Normalization,
    up: i32,
}

impl FileFrame {
    /// A point in model units (before the run's own subnormal scaling by `2^run_up`) in this
    /// frame; `None` when the two scalings differ by more than `f64` holds exactly here.
    fn map(&self, run_up: i32) -> Option<impl Fn(DVec3) -> DVec3 + '_> {
        let k = self.up - run_up;
        (k.abs() < 1000).then_some(move |p: DVec3| self.frame.apply(p * 2f64.powi(k)))
    }
}

/// How many of the crossing pairs of `checked` (the written mesh as [`as_quality_reads`] sees
/// it, in `file`'s frame) lie where the input's own faces cross or its closed parts meet (both
/// faces reach into the input's [`CrossingRegions`], loosened by sigma_p, mapped into that
/// frame).
fn crossings_of_the_input(
    out: &RemeshOutput,
    checked: &TriMesh,
    file: &FileFrame,
    run_up: i32,
) -> usize {
    if out.input_crossing_pairs.is_empty() && out.junction_faces.is_empty() {
        return 0;
    }
    let Some(to_file) = file.map(run_up) else {
        return 0;
    };
    let input = &out.input_normalized;
    let positions: Vec<DVec3> = input
        .positions
        .iter()
        .map(|&p| to_file(out.normalization.invert(p)))
        .collect();
    // sigma_p in the file's frame: the two frames differ by a scale.
    let unit = to_file(out.normalization.invert(DVec3::X))
        - to_file(out.normalization.invert(DVec3::ZERO));
    let regions = CrossingRegions::new(
        &positions,
        &input.triangles,
        &out.input_crossing_pairs,
        &out.junction_faces,
        out.sigma_p * unit.length(),
    );
    let pairs = intersecting_pairs(&checked.positions, &checked.triangles);
    regions.count_inside(&checked.positions, &checked.triangles, &pairs)
}

/// The bbox-100 frame of `mesh`'s own bounding box, the frame [`run_quality`] measures a mesh
/// in when there is no reference; errors name `path`.
fn own_frame(mesh: &TriMesh, path: &Path) -> Result<Normalization> {
    let bbox = mesh
        .bbox()
        .ok_or_else(|| Error::invalid_mesh(path, "the mesh has no vertices"))?;
    Normalization::for_bbox(&bbox)
        .ok_or_else(|| Error::invalid_mesh(path, Normalization::refusal(&bbox)))
}

/// A model too small for the bbox-100 frame's `f64` scale (a longest side below about
/// 5.6e-307 model units: subnormal coordinates) scaled up by `2^k` so its longest side is
/// between 1 and 2, and `k`; every other model as it is, and 0. Scaling by a power of two
/// changes no digit, so the model is the same one in other units.
fn into_normal_range(mesh: TriMesh) -> (TriMesh, i32) {
    let Some(bbox) = mesh.bbox() else {
        return (mesh, 0);
    };
    let side = bbox.longest_side();
    if !(side.is_finite() && side > 0.0) || Normalization::for_bbox(&bbox).is_some() {
        return (mesh, 0);
    }
    let k = -(side.log2().floor() as i32);
    (scale_by_power_of_two(&mesh, k), k)
}

/// `mesh` with every coordinate multiplied by `2^k`, in steps that stay in `f64`'s range (so
/// each step is exact, and the result is rounded once at most, where it is subnormal).
fn scale_by_power_of_two(mesh: &TriMesh, k: i32) -> TriMesh {
    let mut positions = mesh.positions.clone();
    let mut left = k;
    while left != 0 {
        let step = left.clamp(-1000, 1000);
        let f = 2f64.powi(step);
        for p in &mut positions {
            *p *= f;
        }
        left -= step;
    }
    TriMesh {
        positions,
        triangles: mesh.triangles.clone(),
    }
}

/// Fills in the file of an [`Error::InvalidMesh`] that was raised without one.
fn with_path(e: Error, path: &Path) -> Error {
    match e {
        Error::InvalidMesh { path: p, message } if p.as_os_str().is_empty() => Error::InvalidMesh {
            path: path.to_path_buf(),
            message,
        },
        other => other,
    }
}

/// Whether two paths name the same existing file.
fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(x), Ok(y)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            // Hard links too: one file, two names.
            return (x.dev(), x.ino()) == (y.dev(), y.ino());
        }
    }
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

/// Whether writing to `a` and to `b` would write one file: [`same_file`] for files that exist,
/// and for one that does not yet, the same name in the same (canonical) folder.
fn same_target(a: &Path, b: &Path) -> bool {
    if same_file(a, b) {
        return true;
    }
    let place = |p: &Path| -> Option<PathBuf> {
        let name = p.file_name()?;
        let dir = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        Some(dir.canonicalize().ok()?.join(name))
    };
    matches!((place(a), place(b)), (Some(x), Some(y)) if x == y)
}

/// The most points a [`PointsJob`] draws: 10^9, about 24 GB of binary PLY (a bound on the disk
/// a careless `--count` can fill).
pub const MAX_SURFACE_POINTS: u64 = 1_000_000_000;

/// A `remesh points` job: `count` points drawn uniformly by area from the mesh in `mesh`, with
/// normals, written to `output` as binary PLY (streamed).
#[derive(Debug, Clone, PartialEq)]
pub struct PointsJob {
    /// The mesh to draw from (.obj, .ply, .gltf, .glb).
    pub mesh: PathBuf,
    /// The output point set (.ply).
    pub output: PathBuf,
    /// How many points.
    pub count: u64,
    /// Seed of the draw.
    pub seed: u64,
}

/// Runs a [`PointsJob`].
///
/// # Errors
/// Reading and writing errors naming the file.
pub fn run_points(job: &PointsJob) -> Result<()> {
    require_ply_output(&job.output)?;
    if job.count > MAX_SURFACE_POINTS {
        return Err(Error::InvalidParameter {
            name: "--count",
            message: format!(
                "{} points is more than the {MAX_SURFACE_POINTS} `remesh points` writes (about \
                 24 bytes each on disk)",
                job.count
            ),
        });
    }
    let (mesh, _) = read_mesh(&job.mesh)?;
    crate::points::generate::write_surface_points(&mesh, job.count, job.seed, &job.output)
        .map_err(|e| with_path(e, &job.mesh))
}

/// Point sets are written as binary PLY only: any other extension of `output` is a usage error
/// (rather than PLY bytes under another format's name), and so is `-` (standard output): point
/// sets are streamed to a temporary file and renamed into place, so they need a file.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `OUTPUT`.
pub(crate) fn require_ply_output(output: &Path) -> Result<()> {
    if is_stdout(output) {
        return Err(Error::InvalidParameter {
            name: "OUTPUT",
            message: "point sets are not written to standard output (-): they are streamed to a \
                      .ply file through a temporary file beside it; give a .ply path"
                .to_string(),
        });
    }
    match MeshFormat::from_path(output) {
        Ok(MeshFormat::Ply) => Ok(()),
        _ => Err(Error::InvalidParameter {
            name: "OUTPUT",
            message: format!(
                "{}: point sets are written as binary PLY; give the output a .ply extension",
                output.display()
            ),
        }),
    }
}

/// Writes `report` as pretty JSON to `path`, atomically (a temporary file beside it, renamed
/// over the target only when complete).
///
/// # Errors
/// [`Error::Write`] naming `path`.
pub fn write_report(path: &Path, report: &QualityReport) -> Result<()> {
    let json = report.to_json();
    write_atomically(path, |w| w.write_all(json.as_bytes()))
}

/// Checks, before any work, that a JSON report can go to `report` without replacing a file the
/// job reads or writes: `others` are those paths, each with what it is ("the input file").
///
/// # Errors
/// [`Error::InvalidParameter`] naming `--report` when `report` is one of `others` (the same
/// file under any name, or the same name in the same folder); [`Error::Write`] naming `report`
/// when it is a directory or a special file, or its folder is missing or not writable.
pub fn check_report_path(report: &Path, others: &[(&Path, &str)]) -> Result<()> {
    report_clash(report, others)?;
    // Creating the temporary file (removed when dropped) is the test of the folder.
    AtomicFile::create(report).map(drop)
}

/// [`check_report_path`] without the test of the folder ([`run_remesh`] creates the report's
/// temporary file itself).
fn report_clash(report: &Path, others: &[(&Path, &str)]) -> Result<()> {
    match others.iter().find(|(p, _)| same_target(report, p)) {
        Some((_, what)) => Err(Error::InvalidParameter {
            name: "--report",
            message: format!("{} is {what}; choose another report path", report.display()),
        }),
        None => Ok(()),
    }
}

/// Runs `job`, turning a panic (a bug) into an [`Error::Internal`] with stage `panic`, the
/// panic's message and where it happened, on one line. The process's panic hook is replaced for
/// the call (the default hook would print several lines) and restored after it.
///
/// # Errors
/// Whatever `job` returns, or the panic as above.
pub fn catch_panics<T>(job: impl FnOnce() -> Result<T>) -> Result<T> {
    use std::sync::{Arc, Mutex};
    let last: Arc<Mutex<Option<String>>> = Arc::default();
    let seen = Arc::clone(&last);
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let message = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown cause".into());
        let place = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        if let Ok(mut p) = seen.lock() {
            *p = Some(format!("{message}{place}"));
        }
    }));
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(job));
    std::panic::set_hook(previous);
    result.unwrap_or_else(|_| {
        let what = last
            .lock()
            .ok()
            .and_then(|p| p.clone())
            .unwrap_or_else(|| "unknown cause".into());
        Err(Error::Internal {
            stage: "panic",
            message: format!("{} (a bug: please report it)", what.replace('\n', " ")),
        })
    })
}

/// The report's notes on the grading by the local feature size: how many samples it moved to a
/// finer spacing and where, and the parts too thin for the count.
fn grading_notes(g: &crate::sampling::grading::GradingStats, vertices: usize) -> Vec<String> {
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
        notes.push(format!(
            "local feature size: {} of {vertices} samples are spaced finer than sigma_p (down to \
             {:.2} sigma_p) at thin parts, in {} regions (largest: {})",
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
            format!("; about --points {} would resolve them", round_up_2(n))
        });
        notes.push(format!(
            "{} samples lie on parts thinner than this count can resolve (held at the finest \
             spacing the grading allows, so the output there may split, fuse or lose a tip): \
             {}{resolve}",
            g.unresolved_samples,
            shown.join("; ")
        ));
    }
    notes
}

/// `n` rounded up to two significant digits (a count for a note).
fn round_up_2(n: f64) -> u64 {
    if !(n.is_finite() && n > 0.0) {
        return 0;
    }
    let scale = 10f64.powi((n.log10().floor() as i32 - 1).max(0));
    ((n / scale).ceil() * scale) as u64
}

/// The report's line on the sharp features of a remesh: what was found, what the output keeps
/// and how far the creases are from its edges, or why automatic detection left them out. None
/// when detection was off or found nothing to leave out.
fn features_note(f: &crate::pipeline::FeatureStats) -> Option<String> {
    if !(f.angle_deg < 180.0) {
        return None;
    }
    if f.automatic == Some(false) {
        if f.edges == 0 {
            return None;
        }
        return Some(format!(
            "sharp features (automatic, at {}°): {} crease edges in {} curves, {:.0}% of their \
             length in curves of {} spacings or more: a scan's folds, not a part's creases, so \
             they are sampled like the rest (--feature-angle {} keeps them)",
            f.angle_deg,
            f.edges,
            f.curves,
            100.0 * f.long_curve_share,
            crate::LONG_CURVE_SPACINGS,
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
    Some(format!(
        "sharp features at {}°: {} crease edges in {} curves ({} closed), {} corners; {kept}{distance}",
        f.angle_deg, f.edges, f.curves, f.closed_curves, f.corners
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The panic path, injected: one line with the message and the place, the internal exit code.
    #[test]
    fn a_panic_becomes_one_internal_error_line() {
        let e = catch_panics::<()>(|| panic!("injected\nover two lines")).unwrap_err();
        let line = e.to_string();
        assert!(matches!(e, Error::Internal { stage: "panic", .. }), "{e:?}");
        assert_eq!(e.exit_code(), 1);
        assert_eq!(line.lines().count(), 1, "{line}");
        assert!(line.contains("injected over two lines"), "{line}");
        assert!(line.contains("src/app/mod.rs:"), "{line}");
        assert!(line.contains("a bug: please report it"), "{line}");
        // Errors and results pass through.
        assert_eq!(catch_panics(|| Ok(3)).unwrap(), 3);
        let e = catch_panics::<()>(|| {
            Err(Error::InvalidParameter {
                name: "--points",
                message: "x".into(),
            })
        })
        .unwrap_err();
        assert_eq!(e.exit_code(), 2);
    }
}
