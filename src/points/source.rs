//! Where a point set comes from: a point file read in chunks ([`PointReader`]), or points
//! already in memory, read the same way through [`ReadPoints`].

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::DVec3;

use super::normals::NormalOrientation;
use super::stream::{Point, PointReader};
use super::visibility::{hidden_fraction, MAX_HIDDEN_FRACTION};
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
    /// One of the parts far apart of another source (see `PointSource::parts`), read from it
    /// as it goes.
    Part(PointPart),
}

/// How many points, from the first, [`PointSource::orientation`] tests against a file's
/// viewpoint.
pub const CAMERA_TEST_POINTS: usize = 200_000;

/// A file's viewpoint and whether the points look seen from it ([`PointSource::orientation`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// The viewpoint, model units.
    pub position: DVec3,
    /// The fraction (0–1) of the points tested that others hide from it ([`hidden_fraction`]).
    pub hidden: f64,
    /// Whether it was taken as the scanner's position (the normals face it).
    pub used: bool,
}

/// One part of a point source whose points form parts far apart
/// ([`SeparateParts`](super::far_groups::SeparateParts)): its points are those of the whole
/// source in the part, read as the whole is.
#[derive(Debug, Clone)]
pub struct PointPart {
    /// The whole source's name with the part's: `in.xyz (part 2 of 3)`.
    name: PathBuf,
    whole: Box<PointSource>,
    parts: Arc<super::far_groups::SeparateParts>,
    index: usize,
    pub(crate) count: u64,
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
            PointSource::Part(part) => &part.name,
        }
    }

    /// The scanner's position the source gives: a PLY range map's `camera`
    /// ([`PointReader::viewpoint`]), a PCD file's `VIEWPOINT` or the sensor of an E57 file of
    /// one scan, the file's units; only the header (E57: its XML section) is read. `None` for
    /// text and LAS/LAZ files (which give none), E57 files of several scans (one sensor each,
    /// not one viewpoint: `points::e57::read_e57`) and points in memory.
    ///
    /// # Errors
    /// Those of [`PointReader::open`].
    pub fn viewpoint(&self) -> Result<Option<DVec3>> {
        match self {
            PointSource::File(path) if super::pcd::is_pcd_extension(path) => {
                super::pcd::read_pcd_viewpoint(path).map(Some)
            }
            PointSource::File(path) if super::e57::is_e57_extension(path) => {
                super::e57::read_e57_viewpoint(path)
            }
            PointSource::File(path) if !super::stream::is_text_extension(path) => {
                Ok(PointReader::open(path)?.viewpoint())
            }
            PointSource::Part(part) => part.whole.viewpoint(),
            _ => Ok(None),
        }
    }

    /// The points the source announces and the bytes its reader holds, from the header alone
    /// (nothing of the payload read): a PCD or E57 file is read whole
    /// (`points::pcd::pcd_payload`, `points::e57::e57_points`); the other files are read in
    /// chunks (their reader holds no points) and announce their count in the header, but for
    /// text files, whose count is not known before they are read (`None`). Points in memory
    /// count as read.
    ///
    /// # Errors
    /// Those of the header checks for a PCD or E57 file (a payload the file cannot hold) and of
    /// [`PointReader::open`] for the others.
    pub fn input_size(&self) -> Result<InputSize> {
        Ok(match self {
            PointSource::File(path) if super::pcd::is_pcd_extension(path) => {
                let payload = super::pcd::pcd_payload(path)?;
                InputSize {
                    points: Some(payload.points),
                    reader_bytes: payload.resident_bytes,
                }
            }
            PointSource::File(path) if super::e57::is_e57_extension(path) => {
                let points = super::e57::e57_points(path)?;
                InputSize {
                    points: Some(points),
                    reader_bytes: points.saturating_mul(super::e57::BYTES_PER_POINT_READ),
                }
            }
            PointSource::File(path) if !super::stream::is_text_extension(path) => InputSize {
                points: Some(PointReader::open(path)?.count()),
                reader_bytes: 0,
            },
            PointSource::Part(part) => part.whole.input_size()?,
            _ => InputSize {
                points: None,
                reader_bytes: 0,
            },
        })
    }

    /// How normals estimated for these points are oriented: towards `given` (model units) when
    /// there is one, else towards the file's viewpoint ([`PointSource::viewpoint`]) when there
    /// is one and it saw the points (at most `MAX_HIDDEN_FRACTION` (5%) of the first
    /// `CAMERA_TEST_POINTS` hidden from it, `points::visibility`), else by the spanning tree.
    /// Also returns the file's viewpoint and the test's verdict when there is one.
    ///
    /// # Errors
    /// Those of [`PointSource::viewpoint`] and of reading the points.
    pub fn orientation(&self, given: Option<DVec3>) -> Result<(NormalOrientation, Option<Camera>)> {
        if let Some(v) = given {
            return Ok((NormalOrientation::Viewpoint(v), None));
        }
        let Some(position) = self.viewpoint()? else {
            return Ok((NormalOrientation::SpanningTree, None));
        };
        let mut reader = self.open()?;
        let mut points = Vec::new();
        let mut positions = Vec::new();
        while positions.len() < CAMERA_TEST_POINTS {
            let n = reader.read_chunk(&mut points, CAMERA_TEST_POINTS - positions.len())?;
            if n == 0 {
                break;
            }
            positions.extend(points.iter().map(|p| p.position));
        }
        let hidden = hidden_fraction(&positions, position);
        let used = hidden <= MAX_HIDDEN_FRACTION;
        let orientation = if used {
            NormalOrientation::Viewpoint(position)
        } else {
            NormalOrientation::SpanningTree
        };
        Ok((
            orientation,
            Some(Camera {
                position,
                hidden,
                used,
            }),
        ))
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
            PointSource::Part(part) => Box::new(PartPoints {
                whole: part.whole.open()?,
                parts: Arc::clone(&part.parts),
                index: part.index,
                count: part.count,
                buffer: Vec::new(),
            }),
        })
    }

    /// Each part of `parts` (found on this source's points) as a source of its own, in the
    /// parts' order, after one pass over the points to count each part's; and the number of
    /// points in no part (far groups).
    ///
    /// # Errors
    /// Those of reading the points.
    pub(crate) fn parts(
        &self,
        parts: &Arc<super::far_groups::SeparateParts>,
    ) -> Result<(Vec<PointSource>, u64)> {
        let mut counts = vec![0u64; parts.len()];
        let mut outside = 0u64;
        let mut reader = self.open()?;
        let mut chunk = Vec::new();
        while reader.read_chunk(&mut chunk, 1 << 16)? > 0 {
            for p in &chunk {
                match parts.part_of(p.position) {
                    Some(k) => counts[k] += 1,
                    None => outside += 1,
                }
            }
        }
        let name = self.name().display().to_string();
        let sources = counts
            .into_iter()
            .enumerate()
            .map(|(index, count)| {
                PointSource::Part(PointPart {
                    name: PathBuf::from(format!("{name} (part {} of {})", index + 1, parts.len())),
                    whole: Box::new(self.clone()),
                    parts: Arc::clone(parts),
                    index,
                    count,
                })
            })
            .collect();
        Ok((sources, outside))
    }
}

/// What reading a source takes ([`PointSource::input_size`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InputSize {
    /// The points the header announces (`None` where the format has no header count).
    pub points: Option<u64>,
    /// Bytes the reader holds (a file read whole).
    pub reader_bytes: u64,
}

/// The reader of one part's points: the whole source's, those in the part.
struct PartPoints {
    whole: Box<dyn ReadPoints>,
    parts: Arc<super::far_groups::SeparateParts>,
    index: usize,
    count: u64,
    buffer: Vec<Point>,
}

impl ReadPoints for PartPoints {
    fn count(&self) -> u64 {
        self.count
    }
    fn has_normals(&self) -> bool {
        self.whole.has_normals()
    }
    fn viewpoint(&self) -> Option<DVec3> {
        self.whole.viewpoint()
    }
    fn read_chunk(&mut self, out: &mut Vec<Point>, max: usize) -> Result<usize> {
        out.clear();
        while out.is_empty() {
            if self.whole.read_chunk(&mut self.buffer, max)? == 0 {
                return Ok(0);
            }
            out.extend(
                self.buffer
                    .iter()
                    .filter(|p| self.parts.part_of(p.position) == Some(self.index)),
            );
        }
        Ok(out.len())
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
