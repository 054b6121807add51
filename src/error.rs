//! Error values of the library.
//!
//! Every variant names where the problem is (the file, and where known the line, element or face
//! index) so that the `remesh` binary can print it on one line. No function of the library panics
//! on anything a user's input can reach; it returns one of these instead.

use std::path::PathBuf;

/// The library's error type.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The operating system refused to read or write a file.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },

    /// A file's extension names no format we read or write.
    #[error("{}: unsupported format (expected .obj, .ply, .off, .stl, .gltf or .glb)", path.display())]
    UnsupportedFormat {
        /// The file concerned.
        path: PathBuf,
    },

    /// A file could not be parsed: its content does not match its format.
    #[error("{}{}: {message}", path.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Parse {
        /// The file concerned.
        path: PathBuf,
        /// The 1-based line, where the format is line-based and the line is known.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },

    /// The file parsed, but the mesh it holds cannot be used (no triangles, a non-finite
    /// coordinate, an index out of range, a zero-size bounding box, ...). Shown as
    /// `PATH: MESSAGE`, or the message alone for a mesh that did not come from a file.
    #[error("{}{message}", file_prefix(path))]
    InvalidMesh {
        /// The file concerned (empty when the mesh did not come from a file).
        path: PathBuf,
        /// What is wrong, naming the offending element where there is one.
        message: String,
    },

    /// An output file could not be written (missing directory, no permission, disk full, ...).
    /// Nothing is left at the target path when this is returned.
    #[error("{}: cannot write: {message}", path.display())]
    Write {
        /// The output file concerned.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },

    /// A parameter is out of its valid range.
    #[error("invalid parameter {name}: {message}")]
    InvalidParameter {
        /// The parameter's name as the library and the Python module spell it (`points`,
        /// `sigma_p`, ...; the field of `RemeshOptions`), which the command line shows as its
        /// flag (`--points`, `--sigma-p`). A message names other parameters in backticks.
        name: &'static str,
        /// What is wrong.
        message: String,
    },

    /// A stage of the pipeline failed on valid input: a bug or a limit of the method.
    #[error("{stage}: {message}")]
    Internal {
        /// The pipeline stage.
        stage: &'static str,
        /// What went wrong.
        message: String,
    },
}

impl Error {
    /// Convenience constructor for [`Error::InvalidMesh`].
    pub fn invalid_mesh(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Error::InvalidMesh {
            path: path.into(),
            message: message.into(),
        }
    }

    /// Convenience constructor for [`Error::Parse`].
    pub fn parse(
        path: impl Into<PathBuf>,
        line: Option<usize>,
        message: impl Into<String>,
    ) -> Self {
        Error::Parse {
            path: path.into(),
            line,
            message: message.into(),
        }
    }

    /// Convenience constructor for [`Error::Io`].
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }

    /// The process exit code the `remesh` binary uses for this error: 2 for a bad parameter
    /// (usage), 3 for an input that cannot be read or used, 4 for an output that cannot be
    /// written, 1 for an internal failure.
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::InvalidParameter { .. } => 2,
            Error::UnsupportedFormat { .. } | Error::Parse { .. } | Error::InvalidMesh { .. } => 3,
            Error::Io { .. } => 3,
            Error::Write { .. } => 4,
            Error::Internal { .. } => 1,
        }
    }
}

/// `PATH: ` for an error's message, or nothing for an empty path (a mesh given in memory, which
/// no file names: a message never starts with a bare `: `).
fn file_prefix(path: &std::path::Path) -> String {
    if path.as_os_str().is_empty() {
        String::new()
    } else {
        format!("{}: ", path.display())
    }
}

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// A number as a message shows it: plain in the usual range, in exponent form beyond it (a
/// given `1e-300` is not printed as 300 digits).
pub(crate) fn shown(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e9).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 56, R13 (a): a mesh given in memory (the Python module's arrays) has no file name,
    /// and its errors read `: no triangle of non-zero area`, an empty name before the colon.
    #[test]
    fn a_mesh_without_a_file_is_not_named_by_an_empty_string() {
        let e = Error::invalid_mesh("", "no triangle of non-zero area");
        assert_eq!(e.to_string(), "no triangle of non-zero area");
        let e = Error::invalid_mesh("a.obj", "no faces");
        assert_eq!(e.to_string(), "a.obj: no faces");
    }
}
