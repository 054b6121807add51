//! The points job: area-uniform points with normals drawn from a mesh, streamed to PLY.

use std::path::{Path, PathBuf};

use super::files::{is_stdout, with_path};
use crate::error::{Error, Result};
use crate::io::{read_mesh, MeshFormat};

/// The most points a [`PointsJob`] draws: 10^9, about 24 GB of binary PLY (a bound on the disk
/// a careless `--count` can fill).
pub const MAX_SURFACE_POINTS: u64 = 1_000_000_000;

/// A `remesh points` job: `count` points drawn uniformly by area from the mesh in `mesh`, with
/// normals, written to `output` as binary PLY (streamed).
#[derive(Debug, Clone, PartialEq)]
pub struct PointsJob {
    /// The mesh to draw from (.obj, .ply, .gltf, .glb, .stl, .off).
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
/// [`Error::InvalidParameter`] for an output that is not a `.ply` file or is the input; reading
/// and writing errors naming the file.
pub fn run_points(job: &PointsJob) -> Result<()> {
    require_ply_output(&job.output)?;
    super::files::refuse_input_as_output(&job.mesh, &job.output)?;
    if job.count > MAX_SURFACE_POINTS {
        return Err(Error::InvalidParameter {
            name: "count",
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
