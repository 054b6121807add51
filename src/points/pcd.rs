//! PCD, the Point Cloud Library's point cloud format, read as a point set (through the
//! `pcd-rs` crate): `DATA ascii`, `binary` and `binary_compressed` (LZF), any field types.
//!
//! - `x y z` are required (any numeric type, one value each); `normal_x normal_y normal_z`
//!   (PCL's names) are used when all three are present; other fields (`rgb`, `intensity`,
//!   `curvature`, padding) are skipped.
//! - Points with a coordinate that is not finite are left out: an organized cloud (`HEIGHT` > 1,
//!   a depth or stereo camera's grid) marks pixels without depth by NaN.
//! - `VIEWPOINT tx ty tz qw qx qy qz` is where the sensor was, in the points' frame (PCL's
//!   convention, the origin when the line is absent): its translation is the point set's
//!   viewpoint, which the normals are oriented towards, as a PLY range map's camera is, when
//!   the points look seen from it (PCL writes the origin by default, also for clouds in a world
//!   frame: [`super::visibility`]).
//!
//! The whole payload is read at once (a `binary_compressed` payload is one compressed block):
//! memory grows with the file, as for the scanner frames PCD holds.
//!
//! Source: the Point Cloud Library's documentation, "The PCD (Point Cloud Data) file format".

use std::path::Path;

use glam::DVec3;
use pcd_rs::{DynReader, Field};

use crate::error::{Error, Result};

/// The points of a PCD file (see the module).
#[derive(Debug, Clone, PartialEq)]
pub struct PcdPoints {
    /// The points with finite coordinates, in file order (the file's units).
    pub positions: Vec<DVec3>,
    /// Their unit normals (zero where not finite), or none without normals.
    pub normals: Vec<DVec3>,
    /// Whether the file has normals (`normal_x normal_y normal_z`).
    pub has_normals: bool,
    /// The sensor's position (`VIEWPOINT`'s translation; the origin by default), the file's
    /// units.
    pub viewpoint: DVec3,
    /// Points left out for a coordinate that is not finite (an organized cloud's pixels
    /// without depth).
    pub left_out: u64,
}

/// Reads the PCD file at `path` (see the module).
///
/// # Errors
/// [`Error::Io`] when the file cannot be opened; [`Error::Parse`] naming the file for a header
/// or payload `pcd-rs` cannot read (a truncated file, a bad `DATA` line), or for fields without
/// `x y z`.
pub fn read_pcd(path: &Path) -> Result<PcdPoints> {
    let parse = |message: String| Error::Parse {
        path: path.to_path_buf(),
        line: None,
        message,
    };
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let reader = DynReader::from_reader(std::io::BufReader::with_capacity(1 << 20, file))
        .map_err(|e| parse(format!("not a PCD file pcd-rs can read: {e}")))?;
    let meta = reader.meta().clone();
    let slot = |name: &str| meta.field_defs.iter().position(|f| f.name == name);
    let [Some(x), Some(y), Some(z)] = ["x", "y", "z"].map(slot) else {
        let names: Vec<&str> = meta.field_defs.iter().map(|f| f.name.as_str()).collect();
        return Err(parse(format!(
            "no `x y z` fields (the fields are {})",
            names.join(" ")
        )));
    };
    let normal = match ["normal_x", "normal_y", "normal_z"].map(slot) {
        [Some(a), Some(b), Some(c)] => Some([a, b, c]),
        _ => None,
    };
    let v = &meta.viewpoint;
    let viewpoint = DVec3::new(v.tx, v.ty, v.tz);
    if !viewpoint.is_finite() {
        return Err(parse("a VIEWPOINT that is not finite".into()));
    }
    let capacity = meta.num_points.min(1 << 26) as usize;
    let mut positions = Vec::with_capacity(capacity);
    let mut normals = Vec::new();
    let mut left_out = 0;
    for (i, record) in reader.enumerate() {
        let record = record.map_err(|e| parse(format!("point {}: {e}", i + 1)))?;
        let value = |k: usize| record.0.get(k).and_then(first_value);
        let position = match (value(x), value(y), value(z)) {
            (Some(a), Some(b), Some(c)) => DVec3::new(a, b, c),
            _ => return Err(parse(format!("point {}: `x y z` are not numbers", i + 1))),
        };
        if !position.is_finite() {
            left_out += 1;
            continue;
        }
        positions.push(position);
        if let Some([a, b, c]) = normal {
            let n = match (value(a), value(b), value(c)) {
                (Some(x), Some(y), Some(z)) => DVec3::new(x, y, z),
                _ => DVec3::ZERO,
            };
            normals.push(if n.is_finite() {
                n.normalize_or_zero()
            } else {
                DVec3::ZERO
            });
        }
    }
    Ok(PcdPoints {
        positions,
        normals,
        has_normals: normal.is_some(),
        viewpoint,
        left_out,
    })
}

/// The sensor's position a PCD file's header gives ([`PcdPoints::viewpoint`]), the payload not
/// read.
///
/// # Errors
/// As [`read_pcd`] for the header.
pub fn read_pcd_viewpoint(path: &Path) -> Result<DVec3> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let meta =
        pcd_rs::PcdMeta::from_reader(std::io::BufReader::new(file)).map_err(|e| Error::Parse {
            path: path.to_path_buf(),
            line: None,
            message: format!("not a PCD file pcd-rs can read: {e}"),
        })?;
    let v = &meta.viewpoint;
    Ok(DVec3::new(v.tx, v.ty, v.tz))
}

/// The first value of a field, as f64 (`None` for a field of no values).
fn first_value(field: &Field) -> Option<f64> {
    Some(match field {
        Field::I8(v) => *v.first()? as f64,
        Field::I16(v) => *v.first()? as f64,
        Field::I32(v) => *v.first()? as f64,
        Field::I64(v) => *v.first()? as f64,
        Field::U8(v) => *v.first()? as f64,
        Field::U16(v) => *v.first()? as f64,
        Field::U32(v) => *v.first()? as f64,
        Field::U64(v) => *v.first()? as f64,
        Field::F32(v) => *v.first()? as f64,
        Field::F64(v) => *v.first()?,
    })
}

/// Whether `path`'s extension is `.pcd` (any case).
pub(crate) fn is_pcd_extension(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("pcd"))
}

#[cfg(test)]
mod tests;
