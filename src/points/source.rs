//! Where a point set comes from: a point file read in chunks ([`PointReader`]), or points
//! already in memory, read the same way through [`ReadPoints`].

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::DVec3;

use super::normals::NormalOrientation;
use super::stream::{Point, PointReader};
use crate::error::Result;

/// Where a point set comes from: a point file, read in chunks (out of core), or points already in
/// memory (the Python module's arrays), read the same way without a file.
#[derive(Debug, Clone)]
pub enum PointSource {
    /// A PLY file without faces, or a text point file ([`PointReader`]).
    File(PathBuf),
    /// Points in memory (model units); `name` names them in messages (`input points`).
    Memory {
        /// What messages call them.
        name: PathBuf,
        /// The points (model units; unit normals, or zero without normals).
        points: Arc<[Point]>,
        /// Whether the normals are given.
        has_normals: bool,
    },
}

impl PointSource {
    /// Points in memory: `positions` and, when given, their normals (made unit length, as a
    /// file's are), named `name` in messages.
    pub fn memory(name: &str, positions: &[DVec3], normals: Option<&[DVec3]>) -> PointSource {
        let points: Arc<[Point]> = positions
            .iter()
            .enumerate()
            .map(|(i, &position)| Point {
                position,
                normal: normals.map_or(DVec3::ZERO, |n| n[i].normalize_or_zero()),
            })
            .collect();
        PointSource::Memory {
            name: PathBuf::from(name),
            points,
            has_normals: normals.is_some(),
        }
    }

    /// The file, or the name of the points in memory.
    pub fn name(&self) -> &Path {
        match self {
            PointSource::File(path) => path,
            PointSource::Memory { name, .. } => name,
        }
    }

    /// The scanner's position the source gives: a PLY range map's `camera`
    /// ([`PointReader::viewpoint`], the file's units; only the header is read). `None` for text
    /// files (not read) and points in memory.
    ///
    /// # Errors
    /// Those of [`PointReader::open`].
    pub fn viewpoint(&self) -> Result<Option<DVec3>> {
        match self {
            PointSource::File(path) if !super::stream::is_text_extension(path) => {
                Ok(PointReader::open(path)?.viewpoint())
            }
            _ => Ok(None),
        }
    }

    /// How normals estimated for these points are oriented: towards `given` (model units) when
    /// there is one, else towards the range map's camera ([`PointSource::viewpoint`]) when
    /// there is one, else by the spanning tree. Also returns the camera when it is the one used.
    ///
    /// # Errors
    /// Those of [`PointSource::viewpoint`].
    pub fn orientation(&self, given: Option<DVec3>) -> Result<(NormalOrientation, Option<DVec3>)> {
        let camera = match given {
            Some(_) => None,
            None => self.viewpoint()?,
        };
        let orientation = match given.or(camera) {
            Some(v) => NormalOrientation::Viewpoint(v),
            None => NormalOrientation::SpanningTree,
        };
        Ok((orientation, camera))
    }

    /// A reader from the first point.
    ///
    /// # Errors
    /// Those of [`PointReader::open`] for a file.
    pub fn open(&self) -> Result<Box<dyn ReadPoints>> {
        Ok(match self {
            PointSource::File(path) => Box::new(PointReader::open(path)?),
            PointSource::Memory {
                points,
                has_normals,
                ..
            } => Box::new(MemoryPoints {
                points: Arc::clone(points),
                has_normals: *has_normals,
                read: 0,
            }),
        })
    }
}

/// Points read in chunks, from a file or from memory.
pub trait ReadPoints: Send {
    /// The number of points.
    fn count(&self) -> u64;
    /// Whether the points have normals.
    fn has_normals(&self) -> bool;
    /// The scanner's position, when the source says it ([`PointReader::viewpoint`]).
    fn viewpoint(&self) -> Option<DVec3> {
        None
    }
    /// Replaces `out` with up to `max` next points; returns how many (0 at the end).
    ///
    /// # Errors
    /// Those of [`PointReader::read_chunk`] for a file.
    fn read_chunk(&mut self, out: &mut Vec<Point>, max: usize) -> Result<usize>;
}

impl ReadPoints for PointReader {
    fn count(&self) -> u64 {
        PointReader::count(self)
    }
    fn has_normals(&self) -> bool {
        PointReader::has_normals(self)
    }
    fn viewpoint(&self) -> Option<DVec3> {
        PointReader::viewpoint(self)
    }
    fn read_chunk(&mut self, out: &mut Vec<Point>, max: usize) -> Result<usize> {
        PointReader::read_chunk(self, out, max)
    }
}

/// The reader of points in memory.
struct MemoryPoints {
    points: Arc<[Point]>,
    has_normals: bool,
    read: usize,
}

impl ReadPoints for MemoryPoints {
    fn count(&self) -> u64 {
        self.points.len() as u64
    }
    fn has_normals(&self) -> bool {
        self.has_normals
    }
    fn read_chunk(&mut self, out: &mut Vec<Point>, max: usize) -> Result<usize> {
        out.clear();
        let n = (self.points.len() - self.read).min(max);
        out.extend_from_slice(&self.points[self.read..self.read + n]);
        self.read += n;
        Ok(n)
    }
}
