//! The output of a job: the mesh checked as its file will store it, written with its report
//! (both from temporary files, renamed together once both are written), and refused under
//! `--strict` when it breaks an invariant or the topology.

use crate::timing::Clock;

use super::job::RemeshJob;
use crate::error::{Error, Result};
use crate::io::{encode_mesh, AtomicFile, MeshFormat};
use crate::mesh::TriMesh;
use crate::pipeline::RemeshParams;
use crate::report::QualityReport;

/// The files a [`RemeshJob`] writes, open as temporary files until [`Outputs::commit`]: the
/// mesh (`None` for standard output), whether its bytes went in, and the report.
pub(super) struct Outputs {
    pub(super) mesh: std::cell::RefCell<Option<AtomicFile>>,
    pub(super) written: std::cell::Cell<bool>,
    pub(super) report: Option<AtomicFile>,
}

impl Outputs {
    /// Writes `report` into its file, finishes both temporary files (every byte written and
    /// synced), and only then renames the mesh and the report into place: a disk that fills up
    /// (or any other failure) while either is written leaves both targets as they were.
    ///
    /// # Errors
    /// [`Error::Write`] naming the file that could not be written; the temporary files are
    /// removed and neither target is touched. (Only a rename can fail after the other file's
    /// rename; a rename within a directory takes no room on the disk.)
    pub(super) fn commit(self, report: &QualityReport) -> Result<()> {
        use std::io::Write;
        let mut report_file = self.report;
        if let Some(f) = &mut report_file {
            f.write_all(report.to_json().as_bytes())
                .map_err(|e| f.error(e.to_string()))?;
        }
        let mesh = match self.mesh.into_inner() {
            Some(mesh) if self.written.get() => Some(mesh.finish()?),
            _ => None,
        };
        let report_file = report_file.map(AtomicFile::finish).transpose()?;
        for finished in [mesh, report_file].into_iter().flatten() {
            finished.persist()?;
        }
        Ok(())
    }
}

/// The report's entry `key`: `value` as JSON (null if it does not serialize).
pub(super) fn insert_json(
    extra: &mut serde_json::Map<String, serde_json::Value>,
    key: &str,
    value: impl serde::Serialize,
) {
    extra.insert(key.into(), serde_json::to_value(value).unwrap_or_default());
}

/// The report's `sigma_p`, `sigma_n`, `target_points` and `seed` entries.
pub(super) fn insert_kernel_extras(
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
pub(super) fn check_and_write(
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
pub(super) fn refuse_if_strict(job: &RemeshJob, report: &mut QualityReport) -> Result<()> {
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
                "{}; {} was not written (`strict`)",
                refusals.join("; "),
                job.output.display()
            ),
        });
    }
    Ok(())
}

/// Writes `mesh` to `job.output` in `format`, atomically, or to standard output: the complete
/// bytes or nothing.
pub(super) fn write_output(
    job: &RemeshJob,
    format: MeshFormat,
    mesh: &TriMesh,
    outputs: &Outputs,
) -> Result<()> {
    use std::io::Write;
    let bytes = encode_mesh(&job.output, mesh, format)?;
    if let Some(file) = outputs.mesh.borrow_mut().as_mut() {
        file.write_all(&bytes)
            .map_err(|e| file.error(e.to_string()))?;
        outputs.written.set(true);
        Ok(())
    } else {
        let mut stdout = std::io::stdout().lock();
        stdout
            .write_all(&bytes)
            .and_then(|()| stdout.flush())
            .map_err(|e| Error::Write {
                // `-: cannot write: ...` would not say where.
                path: "- (standard output)".into(),
                message: e.to_string(),
            })
    }
}
