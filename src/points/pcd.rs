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
//! memory grows with the file, as for the scanner frames PCD holds. Before anything is
//! allocated, what the header promises is checked against the file ([`pcd_payload`]): a
//! payload larger than the bytes after the header, a compressed block that decompresses to
//! another size than its points need or by more than LZF can expand ([`LZF_MAX_RATIO`]), or a
//! field count whose record size overflows is an error naming the file, not an allocation the
//! header's numbers size.
//!
//! Source: the Point Cloud Library's documentation, "The PCD (Point Cloud Data) file format".

use std::io::{Read, Seek};
use std::path::Path;

use glam::DVec3;
use pcd_rs::{DataKind, DynReader, Field, PcdMeta};

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

/// The most an LZF block can expand: a back reference of at most 264 bytes takes 3 bytes of
/// input (LZF's format, as `pcd-rs` decodes it), so no valid block decompresses to more than
/// 88 times its size (plus a few bytes of a last literal run).
pub const LZF_MAX_RATIO: u64 = 88;

/// Bytes a point read from a PCD file holds in memory: its position and its normal (f64 each),
/// and the point the stream makes of them (the same again).
const BYTES_PER_POINT_READ: u64 = 96;

/// What a PCD file's header promises of its payload, checked against the file
/// ([`pcd_payload`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PcdPayload {
    /// The points the header announces (`POINTS`), which the file's bytes can hold.
    pub points: u64,
    /// Bytes of one point's record in the binary encodings (the sum of `SIZE` × `COUNT`).
    pub record_bytes: u64,
    /// Bytes the reading holds at its peak: a `binary_compressed` block, its decompressed
    /// payload and that payload reordered by point, and the points read (96 bytes each).
    pub resident_bytes: u64,
}

/// Reads the header of the PCD file at `path` and checks what it promises against the file,
/// reading nothing of the payload but a `binary_compressed` block's two sizes (see the
/// module).
///
/// # Errors
/// [`Error::Io`] when the file cannot be opened or read; [`Error::Parse`] naming the file for a
/// header `pcd-rs` cannot read, `x y z` fields of other than one value, a record size that
/// overflows, or a payload the file cannot hold: a `binary` payload past the end of the file,
/// a `binary_compressed` block past it, or one that decompresses to another size than its
/// points need or by more than [`LZF_MAX_RATIO`], or more `ascii` points than its bytes can
/// hold (two bytes a value at least).
pub fn pcd_payload(path: &Path) -> Result<PcdPayload> {
    let parse = |message: String| parse_error(path, message);
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let length = file.metadata().map_err(|e| Error::io(path, e))?.len();
    let mut reader = std::io::BufReader::new(file);
    let meta = PcdMeta::from_reader(&mut reader)
        .map_err(|e| parse(format!("not a PCD file pcd-rs can read: {e}")))?;
    let after_header = reader.stream_position().map_err(|e| Error::io(path, e))?;
    let remaining = length.saturating_sub(after_header);
    for field in meta.field_defs.iter() {
        if ["x", "y", "z"].contains(&field.name.as_str()) && field.count != 1 {
            return Err(parse(format!(
                "field `{}` has COUNT {} (a coordinate is one value)",
                field.name, field.count
            )));
        }
    }
    let (record_bytes, values) = meta
        .field_defs
        .iter()
        .try_fold((0u64, 0u64), |(b, v), f| {
            let bytes = (f.kind.byte_size() as u64).checked_mul(f.count)?;
            Some((b.checked_add(bytes)?, v.checked_add(f.count)?))
        })
        .ok_or_else(|| parse("fields whose COUNT overflows the size of a point".into()))?;
    let points = meta.num_points;
    let payload = points.checked_mul(record_bytes).ok_or_else(|| {
        parse(format!(
            "POINTS {points} of {record_bytes} bytes each overflows"
        ))
    })?;
    let held = |block: u64| {
        points
            .saturating_mul(BYTES_PER_POINT_READ)
            .saturating_add(block)
    };
    let resident_bytes = match meta.data {
        DataKind::Ascii => {
            // A value is a character at least, and a separator or the line's end follows it.
            let most = (remaining + 1) / values.max(1).saturating_mul(2);
            if points > most {
                return Err(parse(format!(
                    "the header promises {points} ascii points and the {remaining} bytes after \
                     it hold at most {most}"
                )));
            }
            held(0)
        }
        DataKind::Binary => {
            if payload > remaining {
                return Err(parse(format!(
                    "the header promises {points} points of {record_bytes} bytes ({payload} \
                     bytes) and the file holds {remaining} after it"
                )));
            }
            held(0)
        }
        DataKind::BinaryCompressed => {
            let mut sizes = [0u8; 8];
            reader
                .read_exact(&mut sizes)
                .map_err(|_| parse("no sizes of the compressed block after the header".into()))?;
            let compressed = u32::from_le_bytes(sizes[..4].try_into().unwrap()) as u64;
            let decompressed = u32::from_le_bytes(sizes[4..].try_into().unwrap()) as u64;
            if compressed > remaining - 8 {
                return Err(parse(format!(
                    "a compressed block of {compressed} bytes and the file holds {} after \
                     its header",
                    remaining - 8
                )));
            }
            if decompressed != payload {
                return Err(parse(format!(
                    "the compressed block decompresses to {decompressed} bytes and the header's \
                     {points} points of {record_bytes} bytes need {payload}"
                )));
            }
            if decompressed > compressed.saturating_mul(LZF_MAX_RATIO) + 64 {
                return Err(parse(format!(
                    "a compressed block of {compressed} bytes that claims to decompress to \
                     {decompressed} (more than LZF can expand it)"
                )));
            }
            held(compressed + 2 * decompressed)
        }
    };
    Ok(PcdPayload {
        points,
        record_bytes,
        resident_bytes,
    })
}

/// A parse error naming `path`.
fn parse_error(path: &Path, message: String) -> Error {
    Error::Parse {
        path: path.to_path_buf(),
        line: None,
        message,
    }
}

/// Reads the PCD file at `path` (see the module).
///
/// # Errors
/// [`Error::Io`] when the file cannot be opened; [`Error::Parse`] naming the file for a header
/// or payload `pcd-rs` cannot read (a truncated file, a bad `DATA` line), for fields without
/// `x y z`, or for what [`pcd_payload`] refuses.
pub fn read_pcd(path: &Path) -> Result<PcdPoints> {
    let parse = |message: String| parse_error(path, message);
    let payload = pcd_payload(path)?;
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
    // As many as the file can hold (checked by `pcd_payload`).
    let mut positions = Vec::with_capacity(payload.points as usize);
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
    let meta = PcdMeta::from_reader(std::io::BufReader::new(file))
        .map_err(|e| parse_error(path, format!("not a PCD file pcd-rs can read: {e}")))?;
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
