//! E57, the ASTM 3D imaging data exchange format, read as a point set through the `e57` crate.
//!
//! An E57 file holds one or more scans (`data3D`), each a point cloud in its own frame with a
//! pose (a unit quaternion and a translation, metres) that maps it into the file's frame:
//!
//! - every scan is read and its pose applied, so the positions are in the file's frame
//!   (metres, as the standard says; the pipeline takes them as they are);
//! - a point's cartesian `x y z` is used when its `cartesianInvalidState` is 0 (or absent);
//!   otherwise its spherical `range azimuth elevation` (radians) when `sphericalInvalidState`
//!   is 0 (or absent); a point with neither (state 1, a direction without range; 2, no
//!   return), or with a coordinate that is not finite, is left out;
//! - normals come from libE57's surface normals extension (`nor:normalX nor:normalY
//!   nor:normalZ`, in the scan's frame, turned by its pose) when every scan has them; other
//!   fields (colour, intensity, row and column, time) are skipped;
//! - a scan's sensor is at the origin of its frame, so its position in the file's frame is its
//!   pose's translation ([`E57Scan::sensor`]). A file of one scan has that position as its
//!   viewpoint, which estimated normals are oriented towards (as PCD's `VIEWPOINT`). A file of
//!   several scans has none ([`E57Points::viewpoint`]): the pipeline orients normals towards one
//!   point per source, and each point facing its own scan's sensor would need the scan carried
//!   with every point through the out-of-core scan; such files are oriented by the spanning
//!   tree, and the sensors are kept per scan here for when that is done.
//!
//! The whole file is read when opened (48 bytes a point kept in memory, about 72 while it is
//! read; some 1 million points a second): the crate's point readers borrow the file's reader and
//! cannot seek, so reading in chunks would decode each scan again from its start for every
//! chunk.
//!
//! Source: ASTM E2807-11 (2019), "Standard Specification for 3D Imaging Data Exchange, Version
//! 1.0"; libE57's extension "E57_NOR_surface_normals" for the normals.

use std::fs::File;
use std::io::BufReader;
use std::ops::Range;
use std::path::Path;

use e57::{E57Reader, PointCloud, Record, RecordDataType, RecordName};
use glam::{DQuat, DVec3};

use crate::error::{Error, Result};

/// The URI of libE57's surface normals extension.
const NORMALS_EXTENSION: &str = "http://www.libe57.org/E57_NOR_surface_normals.txt";

/// One scan of an E57 file.
#[derive(Debug, Clone, PartialEq)]
pub struct E57Scan {
    /// Where its sensor was: its pose's translation, in the file's frame (metres).
    pub sensor: DVec3,
    /// Its points' indices in [`E57Points::positions`] (the scans follow one another in file
    /// order).
    pub points: Range<usize>,
}

/// The points of an E57 file (see the module).
#[derive(Debug, Clone, PartialEq)]
pub struct E57Points {
    /// The points of every scan with a valid position, posed into the file's frame (metres),
    /// scan after scan in file order.
    pub positions: Vec<DVec3>,
    /// Their unit normals in the file's frame (zero where not finite), or none without normals.
    pub normals: Vec<DVec3>,
    /// Whether the file has normals: every scan has `nor:normalX nor:normalY nor:normalZ`.
    pub has_normals: bool,
    /// The scans, in file order.
    pub scans: Vec<E57Scan>,
    /// Points left out: no valid cartesian or spherical position, or one that is not finite.
    pub left_out: u64,
}

impl E57Points {
    /// The sensor's position when the file holds a single scan ([`E57Scan::sensor`]), the file's
    /// frame; `None` for several scans (or none), which have no one viewpoint.
    pub fn viewpoint(&self) -> Option<DVec3> {
        match self.scans.as_slice() {
            [scan] => Some(scan.sensor),
            _ => None,
        }
    }
}

/// Reads the E57 file at `path` (see the module).
///
/// # Errors
/// [`Error::Io`] when the file cannot be opened; [`Error::Parse`] naming the file for a file
/// the `e57` crate cannot read (not E57, a damaged page or XML section, truncated point data),
/// a pose that is not finite or whose quaternion is zero, or a scan without coordinates.
pub fn read_e57(path: &Path) -> Result<E57Points> {
    let parse = |message: String| parse_error(path, message);
    let mut reader = open(path)?;
    let clouds = reader.pointclouds();
    let extensions = reader.extensions();
    let namespace = extensions
        .iter()
        .find(|e| e.url == NORMALS_EXTENSION)
        .map_or("nor", |e| e.namespace.as_str());
    let layouts = clouds
        .iter()
        .enumerate()
        .map(|(k, pc)| Layout::of(&pc.prototype, namespace).ok_or_else(|| parse(no_coordinates(k))))
        .collect::<Result<Vec<_>>>()?;
    let has_normals = !layouts.is_empty() && layouts.iter().all(|l| l.normal.is_some());
    // Sized by the XML's counts, which `held_points` checked against the file's size.
    let capacity = held_points(path, &clouds)? as usize;
    let mut positions = Vec::with_capacity(capacity);
    let mut normals = Vec::with_capacity(if has_normals { capacity } else { 0 });
    let mut scans = Vec::with_capacity(clouds.len());
    let mut left_out = 0;
    for (k, (pc, layout)) in clouds.iter().zip(&layouts).enumerate() {
        let (rotation, sensor) = pose(path, k, pc)?;
        let start = positions.len();
        let points = reader
            .pointcloud_raw(pc)
            .map_err(|e| parse(format!("scan {}: {}", k + 1, one_line(&e))))?;
        for (i, values) in points.enumerate() {
            let at = || format!("scan {}, point {}", k + 1, i + 1);
            let values = values.map_err(|e| parse(format!("{}: {}", at(), one_line(&e))))?;
            let value = |slot: usize| {
                match (values.get(slot), pc.prototype.get(slot)) {
                    (Some(v), Some(r)) => v.to_f64(&r.data_type).ok(),
                    _ => None,
                }
                .ok_or_else(|| parse(format!("{}: a value its prototype does not describe", at())))
            };
            let Some(local) = layout.position(value)?.filter(|p| p.is_finite()) else {
                left_out += 1;
                continue;
            };
            positions.push(rotation * local + sensor);
            if let (true, Some([a, b, c])) = (has_normals, layout.normal) {
                let n = DVec3::new(value(a)?, value(b)?, value(c)?);
                normals.push(if n.is_finite() {
                    (rotation * n).normalize_or_zero()
                } else {
                    DVec3::ZERO
                });
            }
        }
        scans.push(E57Scan {
            sensor,
            points: start..positions.len(),
        });
    }
    Ok(E57Points {
        positions,
        normals,
        has_normals,
        scans,
        left_out,
    })
}

/// The viewpoint an E57 file gives ([`E57Points::viewpoint`]), from its XML section alone (the
/// points are not read).
///
/// # Errors
/// As [`read_e57`] for the file's header, XML and poses.
pub fn read_e57_viewpoint(path: &Path) -> Result<Option<DVec3>> {
    let reader = open(path)?;
    match reader.pointclouds().as_slice() {
        [pc] => Ok(Some(pose(path, 0, pc)?.1)),
        _ => Ok(None),
    }
}

/// Bytes a point takes while an E57 file is read (its raw values, position and normal).
pub const BYTES_PER_POINT_READ: u64 = 72;

/// The points an E57 file's XML section announces, checked against the file's size: what
/// [`read_e57`] will allocate ([`BYTES_PER_POINT_READ`] each), known before it reads a point.
///
/// # Errors
/// As [`read_e57`] for the file's header and XML; [`Error::Parse`] naming the file for a scan
/// whose points the file cannot hold (see `held_points`).
pub fn e57_points(path: &Path) -> Result<u64> {
    let reader = open(path)?;
    held_points(path, &reader.pointclouds())
}

/// Bits one value of a record takes in the file: 0 for an integer whose minimum is its maximum
/// (every value is that one), as the standard packs it.
fn value_bits(data_type: &RecordDataType) -> u64 {
    match *data_type {
        RecordDataType::Single { .. } => 32,
        RecordDataType::Double { .. } => 64,
        RecordDataType::Integer { min, max } | RecordDataType::ScaledInteger { min, max, .. } => {
            let range = (max as i128 - min as i128).max(0) as u128;
            (128 - range.leading_zeros()) as u64
        }
    }
}

/// The points of `clouds` (the XML's record counts), each scan's checked against the file:
/// its records' bits times its count fit in the file's bytes, and a scan of points has a
/// record of at least one bit (every record an integer whose minimum is its maximum leaves the
/// e57 crate no data to count the points by: it would generate them without end).
fn held_points(path: &Path, clouds: &[PointCloud]) -> Result<u64> {
    let length = std::fs::metadata(path)
        .map_err(|e| Error::io(path, e))?
        .len();
    let mut total = 0u64;
    for (k, pc) in clouds.iter().enumerate() {
        let bits: u64 = pc.prototype.iter().map(|r| value_bits(&r.data_type)).sum();
        if pc.records > 0 && bits == 0 {
            return Err(parse_error(
                path,
                format!(
                    "scan {} stores its {} points in no bits (every field an integer whose \
                     minimum is its maximum): one position, no surface",
                    k + 1,
                    pc.records
                ),
            ));
        }
        let bytes = (pc.records as u128 * bits as u128).div_ceil(8);
        if bytes > length as u128 {
            return Err(parse_error(
                path,
                format!(
                    "scan {} announces {} points of {bits} bits and the file holds {length} \
                     bytes",
                    k + 1,
                    pc.records
                ),
            ));
        }
        total += pc.records;
    }
    Ok(total)
}

/// The crate's reader of `path`, its header and XML section read.
fn open(path: &Path) -> Result<E57Reader<BufReader<File>>> {
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    E57Reader::new(BufReader::with_capacity(1 << 20, file)).map_err(|e| {
        parse_error(
            path,
            format!("not an E57 file the e57 crate can read: {}", one_line(&e)),
        )
    })
}

/// Scan `k`'s pose: its rotation (the quaternion made unit) and translation, the identity
/// without one.
fn pose(path: &Path, k: usize, pc: &PointCloud) -> Result<(DQuat, DVec3)> {
    let Some(t) = &pc.transform else {
        return Ok((DQuat::IDENTITY, DVec3::ZERO));
    };
    let q = &t.rotation;
    let rotation = DQuat::from_xyzw(q.x, q.y, q.z, q.w);
    let translation = DVec3::new(t.translation.x, t.translation.y, t.translation.z);
    let length = rotation.length();
    if !(length > 0.0) || !length.is_finite() || !translation.is_finite() {
        return Err(parse_error(
            path,
            format!(
                "scan {}'s pose is not a rotation and translation (quaternion w {} x {} y {} z \
                 {}, translation {} {} {})",
                k + 1,
                q.w,
                q.x,
                q.y,
                q.z,
                translation.x,
                translation.y,
                translation.z
            ),
        ));
    }
    Ok((rotation / length, translation))
}

/// Where a scan's records are in its prototype.
struct Layout {
    cartesian: Option<[usize; 3]>,
    cartesian_state: Option<usize>,
    /// Range, azimuth, elevation.
    spherical: Option<[usize; 3]>,
    spherical_state: Option<usize>,
    normal: Option<[usize; 3]>,
}

impl Layout {
    /// The layout of `prototype`, the normals' records in `namespace`; `None` without cartesian
    /// or spherical coordinates.
    fn of(prototype: &[Record], namespace: &str) -> Option<Layout> {
        let slot = |name: &RecordName| prototype.iter().position(|r| &r.name == name);
        let three = |names: [RecordName; 3]| match names.each_ref().map(slot) {
            [Some(a), Some(b), Some(c)] => Some([a, b, c]),
            _ => None,
        };
        let normal = |axis: &str| RecordName::Unknown {
            namespace: namespace.to_string(),
            name: format!("normal{axis}"),
        };
        let layout = Layout {
            cartesian: three([
                RecordName::CartesianX,
                RecordName::CartesianY,
                RecordName::CartesianZ,
            ]),
            cartesian_state: slot(&RecordName::CartesianInvalidState),
            spherical: three([
                RecordName::SphericalRange,
                RecordName::SphericalAzimuth,
                RecordName::SphericalElevation,
            ]),
            spherical_state: slot(&RecordName::SphericalInvalidState),
            normal: three([normal("X"), normal("Y"), normal("Z")]),
        };
        (layout.cartesian.is_some() || layout.spherical.is_some()).then_some(layout)
    }

    /// A point's position in its scan's frame from its values (`value` of a prototype slot):
    /// cartesian when valid, else spherical when valid, else `None`.
    fn position(&self, value: impl Fn(usize) -> Result<f64>) -> Result<Option<DVec3>> {
        // Without a state record every point's coordinates are valid.
        let valid = |state: Option<usize>| state.map_or(Ok(true), |s| Ok(value(s)? == 0.0));
        if let Some([x, y, z]) = self.cartesian {
            if valid(self.cartesian_state)? {
                return Ok(Some(DVec3::new(value(x)?, value(y)?, value(z)?)));
            }
        }
        if let Some([r, a, e]) = self.spherical {
            if valid(self.spherical_state)? {
                let (range, azimuth, elevation) = (value(r)?, value(a)?, value(e)?);
                return Ok(Some(
                    range
                        * DVec3::new(
                            elevation.cos() * azimuth.cos(),
                            elevation.cos() * azimuth.sin(),
                            elevation.sin(),
                        ),
                ));
            }
        }
        Ok(None)
    }
}

fn no_coordinates(k: usize) -> String {
    format!(
        "scan {} has neither cartesianX/Y/Z nor sphericalRange/Azimuth/Elevation",
        k + 1
    )
}

fn parse_error(path: &Path, message: String) -> Error {
    Error::Parse {
        path: path.to_path_buf(),
        line: None,
        message,
    }
}

/// The crate's error on one line (an XML parser's message may hold line breaks).
fn one_line(e: &e57::Error) -> String {
    e.to_string()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

/// Whether `path`'s extension is `.e57` (any case).
pub(crate) fn is_e57_extension(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("e57"))
}

#[cfg(test)]
mod tests;
