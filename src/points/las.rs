//! LAS, the ASPRS LiDAR exchange format, and LAZ, its LASzip compression, read as a point set
//! through the `las` crate (versions 1.0–1.4, every point format; LAZ through its `laz`
//! feature): the points' `x y z` with the header's scale and offset applied (the file's units,
//! metres or feet as its coordinate reference system says), in chunks (a LiDAR survey may hold
//! more points than memory). LAS has no normals and no single sensor position (an airborne
//! scanner moves), so the normals are estimated and oriented without a viewpoint.
//!
//! LAZ is read in chunks too: LASzip compresses the points in chunks (50,000 points by default)
//! listed in a chunk table, so a seek decompresses from the start of the chunk holding the point,
//! at most one LASzip chunk more than the points asked for. A LAZ without a chunk table (a
//! writer that did not finish) cannot seek: it reads when its points fit in the first chunk asked
//! for, and a larger one is an error naming the file.
//!
//! Sources: ASPRS, "LAS Specification 1.4 – R15" (2019); M. Isenburg, "LASzip: lossless
//! compression of LiDAR data", Photogrammetric Engineering & Remote Sensing 79(2), 2013, and the
//! LASzip format as `laz` implements it.

use std::path::Path;

use glam::DVec3;

use crate::error::{Error, Result};

/// A LAS file to read in chunks. The crate's reader cannot move between threads (the point
/// readers can), so each chunk opens the file again and seeks to its first point: a header read
/// per chunk of tens of thousands of points.
#[derive(Debug, Clone)]
pub(crate) struct LasPoints {
    count: u64,
}

impl LasPoints {
    /// Opens the LAS file at `path` and reads its header.
    ///
    /// # Errors
    /// [`Error::Parse`] naming the file for a file the `las` crate cannot read (not LAS or LAZ,
    /// a damaged header, a LAZ without its LASzip record).
    pub(crate) fn open(path: &Path) -> Result<Self> {
        let count = reader(path)?.header().number_of_points();
        Ok(LasPoints { count })
    }

    /// The number of points the header announces.
    pub(crate) fn count(&self) -> u64 {
        self.count
    }

    /// Appends the positions (model units) of `n` points from point `from` on to `out`; how
    /// many there were (fewer at the end of the file).
    ///
    /// # Errors
    /// [`Error::Parse`] naming `path` for a file or point record the crate cannot read.
    pub(crate) fn read(
        &self,
        path: &Path,
        from: u64,
        n: usize,
        out: &mut Vec<DVec3>,
    ) -> Result<usize> {
        let bad = |e: las::Error| Error::Parse {
            path: path.to_path_buf(),
            line: None,
            message: format!("a point record the las crate cannot read: {e}"),
        };
        let mut reader = reader(path)?;
        // A fresh reader is at the first point; seeking there would fail for a LAZ without a
        // chunk table.
        if from > 0 {
            reader.seek(from).map_err(bad)?;
        }
        let data = reader.read_points(n as u64).map_err(bad)?;
        let before = out.len();
        out.extend(
            data.x()
                .zip(data.y())
                .zip(data.z())
                .map(|((x, y), z)| DVec3::new(x, y, z)),
        );
        Ok(out.len() - before)
    }
}

/// The crate's reader of `path`, its header read.
fn reader(path: &Path) -> Result<las::Reader> {
    las::Reader::from_path(path).map_err(|e| Error::Parse {
        path: path.to_path_buf(),
        line: None,
        message: format!("not a LAS or LAZ file the las crate can read: {e}"),
    })
}

/// Whether `path`'s extension is `.las` or `.laz` (any case): the `las` crate reads both, and
/// tells them apart by the header's point format, not by the name.
pub(crate) fn is_las_extension(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("las") || e.eq_ignore_ascii_case("laz"))
}

#[cfg(test)]
mod tests;
