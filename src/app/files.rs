//! The job's files: standard output, the format of an output, one file under two names, the
//! JSON report and its clashes with the other files.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::io::{write_atomically, AtomicFile, MeshFormat};
use crate::report::QualityReport;

/// The output path that means standard output: `-`.
pub const STDOUT: &str = "-";

/// Whether `output` is [`STDOUT`].
pub(super) fn is_stdout(output: &Path) -> bool {
    output.as_os_str() == STDOUT
}

/// The format a [`RemeshJob`] writes: `format` where given (agreeing with a file's extension),
/// else by the extension, or OBJ for standard output.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `OUTPUT` for an extension no mesh format has, or
/// `--format` when it contradicts the extension.
pub(super) fn output_format(output: &Path, format: Option<MeshFormat>) -> Result<MeshFormat> {
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
            name: "format",
            message: format!(
                "`format` {} contradicts the extension of {}; the format of a file is its \
                 extension's (`format` chooses the format of standard output, -)",
                f.extension(),
                output.display()
            ),
        }),
        _ => Ok(by_extension),
    }
}

/// Fills in the file of an [`Error::InvalidMesh`] that was raised without one.
pub(super) fn with_path(e: Error, path: &Path) -> Error {
    match e {
        Error::InvalidMesh { path: p, message } if p.as_os_str().is_empty() => Error::InvalidMesh {
            path: path.to_path_buf(),
            message,
        },
        other => other,
    }
}

/// Whether two paths name the same existing file.
pub(super) fn same_file(a: &Path, b: &Path) -> bool {
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
pub(super) fn same_target(a: &Path, b: &Path) -> bool {
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

/// Refuses, before any work, an `output` that would replace the `input` it is made from
/// ([`same_target`]: the same file under any name, a hard link, or the same name in the same
/// folder): every subcommand that reads one file and writes another.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `OUTPUT`.
pub(super) fn refuse_input_as_output(input: &Path, output: &Path) -> Result<()> {
    if same_target(input, output) {
        return Err(Error::InvalidParameter {
            name: "OUTPUT",
            message: format!(
                "{} is the input file; choose another output path",
                output.display()
            ),
        });
    }
    Ok(())
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
pub(super) fn report_clash(report: &Path, others: &[(&Path, &str)]) -> Result<()> {
    match others.iter().find(|(p, _)| same_target(report, p)) {
        Some((_, what)) => Err(Error::InvalidParameter {
            name: "report",
            message: format!("{} is {what}; choose another report path", report.display()),
        }),
        None => Ok(()),
    }
}
