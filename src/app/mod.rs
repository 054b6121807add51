//! The jobs behind the `remesh` command line, as library functions: remesh a file and report on
//! it, report on any mesh against a reference, simplify a point set out of core, draw points
//! from a mesh; writing the JSON report, and turning a panic into an error.

mod memory;
mod options;
mod remesh_points;
pub use remesh_points::remesh_point_set;
mod simplify;

pub use memory::{
    effective_memory_limit, estimate_remesh_bytes, memory_limit, parse_bytes, physical_memory,
};
pub use options::RemeshOptions;
pub use simplify::{run_simplify, SimplifyDensity, SimplifyDetail, SimplifyJob, SimplifySummary};

mod files;
mod job;
mod notes;
mod output;
mod points;
mod quality;
mod remesh;

pub use files::{check_report_path, write_report, STDOUT};
pub use job::{RemeshJob, RemeshedMesh};
pub use points::{run_points, PointsJob, MAX_SURFACE_POINTS};
pub use quality::{quality_mesh, run_quality};
pub use remesh::{remesh_mesh, run_remesh};

use crate::error::{Error, Result};

/// Samples per side for the Hausdorff and RMS distances of the report (Metro-style, on top of
/// every vertex).
pub const DISTANCE_SAMPLES: usize = 200_000;

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
                name: "points",
                message: "x".into(),
            })
        })
        .unwrap_err();
        assert_eq!(e.exit_code(), 2);
    }
}
