//! Streaming point sets: a reader that hands out points in chunks (so a file of tens of millions
//! of points never has to be in memory at once) from PLY (the `vertex` element) or from XYZ/CSV
//! text, and a writer of binary little-endian PLY with normals. PLY headers are read by
//! `ply-rs-bw` (`io::ply`); the payload by the fixed-record decoder here, which reads
//! a binary vertex record in one pass without per-property dispatch through the parser.

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Seek};
use std::path::{Path, PathBuf};

use glam::DVec3;
use ply_rs_bw::ply::{PropertyType, ScalarType};

use crate::error::{Error, Result};
use crate::io::ply::{read_header, BinaryPlyWriter};
use crate::io::AtomicFile;

/// One point of a point set: position and unit normal (`DVec3::ZERO` when the file has none).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// Position (the file's units).
    pub position: DVec3,
    /// Unit normal, or zero.
    pub normal: DVec3,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    Ascii,
    BinaryLittle,
    BinaryBig,
    /// XYZ/CSV text: one point per line, values separated by commas, semicolons or blanks.
    Text,
    /// Read whole when opened (PCD, E57): the points are in `loaded`.
    Loaded,
    /// LAS or LAZ, read in chunks through `las`.
    Las,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl From<ScalarType> for Scalar {
    fn from(ty: ScalarType) -> Scalar {
        match ty {
            ScalarType::Char => Scalar::I8,
            ScalarType::UChar => Scalar::U8,
            ScalarType::Short => Scalar::I16,
            ScalarType::UShort => Scalar::U16,
            ScalarType::Int => Scalar::I32,
            ScalarType::UInt => Scalar::U32,
            ScalarType::Float => Scalar::F32,
            ScalarType::Double => Scalar::F64,
        }
    }
}

impl Scalar {
    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn decode(self, b: &[u8], little: bool) -> f64 {
        macro_rules! num {
            ($t:ty, $n:expr) => {{
                let a: [u8; $n] = b[..$n].try_into().unwrap_or([0; $n]);
                if little {
                    <$t>::from_le_bytes(a) as f64
                } else {
                    <$t>::from_be_bytes(a) as f64
                }
            }};
        }
        match self {
            Scalar::I8 => num!(i8, 1),
            Scalar::U8 => num!(u8, 1),
            Scalar::I16 => num!(i16, 2),
            Scalar::U16 => num!(u16, 2),
            Scalar::I32 => num!(i32, 4),
            Scalar::U32 => num!(u32, 4),
            Scalar::F32 => num!(f32, 4),
            Scalar::F64 => num!(f64, 8),
        }
    }
}

/// The viewpoint from a camera record's `values` at `slots` (those of `view_px view_py
/// view_pz`); `None` for a missing or non-finite one.
fn camera_viewpoint(slots: &[usize], values: &[f64]) -> Option<DVec3> {
    let v = DVec3::new(
        *values.get(slots[0])?,
        *values.get(slots[1])?,
        *values.get(slots[2])?,
    );
    v.is_finite().then_some(v)
}

/// Reads a point set in chunks, from
/// - PLY (ascii or binary of either byte order): the `vertex` element (elements before it, such
///   as a range map's `camera`, are skipped; in binary they must hold scalars only); its
///   properties must be scalars; `x y z` are required, `nx ny nz` are
///   used when all three are present, everything else is skipped;
/// - PCD (`.pcd`; `points::pcd::read_pcd`: ascii, binary or binary_compressed, points
///   without depth left out, `VIEWPOINT` as the viewpoint), read whole when opened;
/// - LAS and LAZ (`.las .laz`; `points::las`: the points' `x y z`, scaled), in chunks;
/// - E57 (`.e57`; `points::e57::read_e57`: every scan posed into the file's frame, invalid
///   points left out, a single scan's sensor as the viewpoint), read whole when opened;
/// - XYZ/CSV text (`.xyz .csv .txt .pts .asc .xyzn`): one point per line, `x y z` or
///   `x y z nx ny nz` (further columns skipped), separated by commas, semicolons or blanks. A
///   first line of names (`x,y,z,nx,ny,nz` in any order, any case) picks the columns; blank lines
///   and lines starting with `#` or `//` are skipped; a leading line with a single number (the
///   point count of `.pts`) is skipped.
pub struct PointReader {
    path: PathBuf,
    input: BufReader<File>,
    encoding: Encoding,
    count: u64,
    read: u64,
    /// Per property: its type and where it goes (0-2 position, 3-5 normal, none).
    properties: Vec<(Scalar, Option<usize>)>,
    record_size: usize,
    has_normals: bool,
    /// The viewpoint of a range map's `camera` element, the file's units.
    viewpoint: Option<DVec3>,
    buffer: Vec<u8>,
    line: String,
    line_number: usize,
    /// The points of a file read whole (PCD), in order.
    loaded: Vec<Point>,
    /// A LAS file's reader.
    las: Option<super::las::LasPoints>,
}

impl PointReader {
    /// Opens `path` and reads its header. Text files (by extension) are read once here to count
    /// their points.
    ///
    /// # Errors
    /// [`Error::Io`] when the file cannot be opened; [`Error::Parse`] naming the file for a header
    /// that is not PLY, lacks `x y z`, or has no `vertex` element or one before it that cannot be
    /// skipped (a list property in binary), or for a text file whose first point has fewer than
    /// three numbers.
    pub fn open(path: &Path) -> Result<Self> {
        if is_text_extension(path) {
            return Self::open_text(path);
        }
        if super::pcd::is_pcd_extension(path) {
            return Self::open_pcd(path);
        }
        if super::las::is_las_extension(path) {
            return Self::open_las(path);
        }
        if super::e57::is_e57_extension(path) {
            return Self::open_e57(path);
        }
        let file = File::open(path).map_err(|e| Error::io(path, e))?;
        let mut input = BufReader::with_capacity(1 << 20, file);
        let parse = |message: String| Error::Parse {
            path: path.to_path_buf(),
            line: None,
            message,
        };
        let head = input.fill_buf().map_err(|e| Error::io(path, e))?;
        if !(head.starts_with(b"ply\n") || head.starts_with(b"ply\r\n")) {
            return Err(Error::Parse {
                path: path.to_path_buf(),
                line: Some(1),
                message: "not a PLY file (the first line is not `ply`)".into(),
            });
        }
        let mut reader = ply_rs_bw::parser::Reader::new(input);
        let header = read_header(path, &mut reader)?;
        // The line before the first payload line (ascii payloads count on from there).
        let line_number = reader.line().saturating_sub(1);
        let input = reader.into_inner();
        let encoding = match header.encoding {
            ply_rs_bw::ply::Encoding::Ascii => Encoding::Ascii,
            ply_rs_bw::ply::Encoding::BinaryLittleEndian => Encoding::BinaryLittle,
            ply_rs_bw::ply::Encoding::BinaryBigEndian => Encoding::BinaryBig,
        };
        // Elements before `vertex` (a range map's `camera`) are skipped: their records have a
        // fixed size (scalars only) or, in ascii, one line each.
        let Some(at) = header.elements.keys().position(|name| name == "vertex") else {
            return Err(parse("no `vertex` element".into()));
        };
        let mut input = input;
        let mut line_number = line_number;
        let mut viewpoint = None;
        for (name, element) in header.elements.iter().take(at) {
            // A range map's camera: its viewpoint, `view_px view_py view_pz` of the first
            // record (VCG's layout, as MeshLab writes range maps).
            let scalars = element
                .properties
                .values()
                .all(|p| matches!(p.data_type, PropertyType::Scalar(_)));
            let view_slots: Option<Vec<usize>> = (name == "camera" && element.count > 0 && scalars)
                .then(|| {
                    ["view_px", "view_py", "view_pz"]
                        .iter()
                        .map(|n| element.properties.keys().position(|k| k == n))
                        .collect()
                })
                .flatten();
            match encoding {
                Encoding::Ascii => {
                    let mut line = String::new();
                    for record in 0..element.count {
                        line.clear();
                        if input.read_line(&mut line).map_err(|e| Error::io(path, e))? == 0 {
                            return Err(parse(format!("the file ends inside `{name}`")));
                        }
                        line_number += 1;
                        if let (0, Some(slots)) = (record, &view_slots) {
                            let values: Vec<f64> = line
                                .split_whitespace()
                                .map(|v| v.parse().unwrap_or(f64::NAN))
                                .collect();
                            viewpoint = camera_viewpoint(slots, &values);
                        }
                    }
                }
                _ => {
                    let mut size = 0u64;
                    let mut fields = Vec::new();
                    for property in element.properties.values() {
                        match &property.data_type {
                            PropertyType::Scalar(ty) => {
                                let scalar = Scalar::from(ty.clone());
                                fields.push((size as usize, scalar));
                                size += scalar.size() as u64
                            }
                            PropertyType::List(..) => {
                                return Err(parse(format!(
                                    "`{name}` comes before `vertex` and has a list property; \
                                     it cannot be skipped"
                                )))
                            }
                        }
                    }
                    // Checked: a count near 2^64 must not wrap to a small length.
                    let mut skip = size.checked_mul(element.count as u64).ok_or_else(|| {
                        parse(format!(
                            "the header announces {} `{name}` records of {size} bytes, more \
                             than a file holds",
                            element.count
                        ))
                    })?;
                    if let Some(slots) = &view_slots {
                        let mut record = vec![0u8; size as usize];
                        input
                            .read_exact(&mut record)
                            .map_err(|_| parse(format!("the file ends inside `{name}`")))?;
                        skip -= size;
                        let little = encoding == Encoding::BinaryLittle;
                        let values: Vec<f64> = fields
                            .iter()
                            .map(|&(at, scalar)| scalar.decode(&record[at..], little))
                            .collect();
                        viewpoint = camera_viewpoint(slots, &values);
                    }
                    let copied = std::io::copy(&mut (&mut input).take(skip), &mut std::io::sink())
                        .map_err(|e| Error::io(path, e))?;
                    if copied < skip {
                        return Err(parse(format!("the file ends inside `{name}`")));
                    }
                }
            }
        }
        let vertex = &header.elements[at];
        let count = vertex.count as u64;
        let mut properties: Vec<(Scalar, Option<usize>)> = Vec::new();
        let mut names: Vec<&str> = Vec::new();
        for (name, property) in &vertex.properties {
            match &property.data_type {
                PropertyType::Scalar(ty) => properties.push((Scalar::from(ty.clone()), None)),
                PropertyType::List(..) => {
                    return Err(parse(
                        "list properties in `vertex` are not supported".into(),
                    ))
                }
            }
            names.push(name);
        }
        let slot = |n: &str| names.iter().position(|m| *m == n);
        for (k, name) in ["x", "y", "z"].iter().enumerate() {
            let i =
                slot(name).ok_or_else(|| parse(format!("the vertex element has no `{name}`")))?;
            properties[i].1 = Some(k);
        }
        let normal_slots: Vec<Option<usize>> = ["nx", "ny", "nz"].iter().map(|n| slot(n)).collect();
        let has_normals = normal_slots.iter().all(Option::is_some);
        if has_normals {
            for (k, i) in normal_slots.into_iter().flatten().enumerate() {
                properties[i].1 = Some(3 + k);
            }
        }
        let record_size: usize = properties.iter().map(|p| p.0.size()).sum();
        // The header's count against what the file can hold, before anything is sized by it:
        // a binary record takes `record_size` bytes, an ascii one at least a character and a
        // separator per property. Binary points that end the file fill it exactly.
        let position = input.stream_position().map_err(|e| Error::io(path, e))?;
        let length = input
            .get_ref()
            .metadata()
            .map_err(|e| Error::io(path, e))?
            .len();
        let body = length.saturating_sub(position);
        let least = match encoding {
            Encoding::Ascii => 2 * properties.len() as u64,
            _ => record_size as u64,
        };
        let last = at + 1 == header.elements.len();
        let fits = body / least.max(1);
        if fits < count {
            return Err(parse(format!(
                "truncated: the header announces {count} points, the file holds at most {fits}"
            )));
        }
        if last && encoding != Encoding::Ascii && body > count * least {
            return Err(parse(format!(
                "{} bytes after the last of the {count} points the header announces (a binary \
                 body must end with its last element)",
                body - count * least
            )));
        }
        Ok(PointReader {
            path: path.to_path_buf(),
            input,
            encoding,
            count,
            read: 0,
            properties,
            record_size,
            has_normals,
            viewpoint,
            buffer: Vec::new(),
            line: String::new(),
            line_number,
            loaded: Vec::new(),
            las: None,
        })
    }

    /// Opens a LAS file (`points::las`), read in chunks.
    fn open_las(path: &Path) -> Result<Self> {
        let las = super::las::LasPoints::open(path)?;
        let mut reader = Self::decoded_elsewhere(path, Encoding::Las, las.count())?;
        reader.las = Some(las);
        Ok(reader)
    }

    /// Opens a PCD file and reads it whole (`points::pcd::read_pcd`).
    fn open_pcd(path: &Path) -> Result<Self> {
        let pcd = super::pcd::read_pcd(path)?;
        Self::loaded(
            path,
            &pcd.positions,
            pcd.has_normals.then_some(&pcd.normals[..]),
            Some(pcd.viewpoint),
        )
    }

    /// Opens an E57 file and reads it whole (`points::e57::read_e57`).
    fn open_e57(path: &Path) -> Result<Self> {
        let e57 = super::e57::read_e57(path)?;
        Self::loaded(
            path,
            &e57.positions,
            e57.has_normals.then_some(&e57.normals[..]),
            e57.viewpoint(),
        )
    }

    /// A reader of points a crate has read whole: `positions`, with their unit `normals` (one
    /// per position) when the file has normals, and the sensor's position when it says one.
    fn loaded(
        path: &Path,
        positions: &[DVec3],
        normals: Option<&[DVec3]>,
        viewpoint: Option<DVec3>,
    ) -> Result<Self> {
        let count = positions.len() as u64;
        let mut reader = Self::decoded_elsewhere(path, Encoding::Loaded, count)?;
        reader.has_normals = normals.is_some();
        reader.viewpoint = viewpoint;
        let normals = normals.unwrap_or_default();
        reader.loaded = positions
            .iter()
            .enumerate()
            .map(|(i, &position)| Point {
                position,
                normal: normals.get(i).copied().unwrap_or(DVec3::ZERO),
            })
            .collect();
        Ok(reader)
    }

    /// A reader of `count` points of a format a crate decodes (PCD, LAS, E57): no properties,
    /// records or lines of its own, no normals or viewpoint until the caller sets them.
    fn decoded_elsewhere(path: &Path, encoding: Encoding, count: u64) -> Result<Self> {
        let file = File::open(path).map_err(|e| Error::io(path, e))?;
        Ok(PointReader {
            path: path.to_path_buf(),
            input: BufReader::new(file),
            encoding,
            count,
            read: 0,
            properties: Vec::new(),
            record_size: 0,
            has_normals: false,
            viewpoint: None,
            buffer: Vec::new(),
            line: String::new(),
            line_number: 0,
            loaded: Vec::new(),
            las: None,
        })
    }

    /// Opens an XYZ/CSV text file: a first pass counts the points and finds the columns.
    fn open_text(path: &Path) -> Result<Self> {
        let open = || -> Result<BufReader<File>> {
            let file = File::open(path).map_err(|e| Error::io(path, e))?;
            Ok(BufReader::with_capacity(1 << 20, file))
        };
        let parse = |line: usize, message: String| Error::Parse {
            path: path.to_path_buf(),
            line: Some(line),
            message,
        };
        let mut input = open()?;
        let mut line = String::new();
        let (mut line_number, mut count) = (0usize, 0u64);
        let mut columns: Option<Vec<Option<usize>>> = None;
        let mut names: Option<Vec<String>> = None;
        let mut skipped_head = 0usize;
        loop {
            line.clear();
            if input.read_line(&mut line).map_err(|e| Error::io(path, e))? == 0 {
                break;
            }
            line_number += 1;
            if is_comment(&line) {
                continue;
            }
            if columns.is_some() {
                count += 1;
                continue;
            }
            let fields: Vec<&str> = split_fields(&line, true).collect();
            let numeric = fields.iter().all(|f| f.parse::<f64>().is_ok());
            if !numeric && names.is_none() && count == 0 {
                names = Some(fields.iter().map(|f| f.to_ascii_lowercase()).collect());
                skipped_head = line_number;
                continue;
            }
            if numeric && fields.len() == 1 && names.is_none() && count == 0 {
                skipped_head = line_number; // the point count of a .pts file
                continue;
            }
            let slots: Vec<Option<usize>> = match &names {
                Some(names) => {
                    let slot = |n: &str| names.iter().position(|m| m == n);
                    let mut slots = vec![None; names.len().max(fields.len())];
                    for (k, name) in ["x", "y", "z"].iter().enumerate() {
                        let i = slot(name).ok_or_else(|| {
                            parse(skipped_head, format!("the column names have no `{name}`"))
                        })?;
                        slots[i] = Some(k);
                    }
                    let normal: Vec<Option<usize>> =
                        ["nx", "ny", "nz"].iter().map(|n| slot(n)).collect();
                    if normal.iter().all(Option::is_some) {
                        for (k, i) in normal.into_iter().flatten().enumerate() {
                            slots[i] = Some(3 + k);
                        }
                    }
                    slots
                }
                None if fields.len() >= 3 => (0..fields.len())
                    .map(|i| (i < 3 || fields.len() >= 6 && i < 6).then_some(i))
                    .collect(),
                None => {
                    return Err(parse(
                        line_number,
                        format!(
                            "a point needs three numbers x y z, the line has {}",
                            fields.len()
                        ),
                    ))
                }
            };
            columns = Some(slots);
            count = 1;
        }
        let columns = columns.unwrap_or_default();
        let has_normals = columns.iter().filter(|c| c.is_some_and(|k| k >= 3)).count() == 3;
        // Second pass from the start, past the lines of names or count.
        let mut input = open()?;
        for _ in 0..skipped_head {
            line.clear();
            input.read_line(&mut line).map_err(|e| Error::io(path, e))?;
        }
        Ok(PointReader {
            path: path.to_path_buf(),
            input,
            encoding: Encoding::Text,
            count,
            read: 0,
            properties: columns.into_iter().map(|c| (Scalar::F64, c)).collect(),
            record_size: 0,
            has_normals,
            viewpoint: None,
            buffer: Vec::new(),
            line,
            line_number: skipped_head,
            loaded: Vec::new(),
            las: None,
        })
    }

    /// The number of points the header announces.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Whether the points have normals (`nx ny nz`).
    pub fn has_normals(&self) -> bool {
        self.has_normals
    }

    /// The scanner's position when the file says it, in the points' units: a PLY `camera`
    /// element of scalars before `vertex` with `view_px view_py view_pz` (VCG's layout, as
    /// MeshLab writes range maps; the first camera when there are several), a PCD's `VIEWPOINT`,
    /// or the sensor of an E57 file of one scan (its pose's translation). `None` otherwise (E57
    /// files of several scans among them), or when a PLY camera's values are not finite.
    pub fn viewpoint(&self) -> Option<DVec3> {
        self.viewpoint
    }

    /// Replaces `out` with up to `max` next points; returns how many (0 at the end).
    ///
    /// # Errors
    /// [`Error::Parse`] naming the file for a truncated payload, a malformed ascii line or a
    /// non-finite coordinate; [`Error::Io`] for a read failure.
    pub fn read_chunk(&mut self, out: &mut Vec<Point>, max: usize) -> Result<usize> {
        out.clear();
        let n = (self.count - self.read).min(max as u64) as usize;
        if n == 0 {
            return Ok(0);
        }
        let mut values = [0.0f64; 6];
        match self.encoding {
            Encoding::Las => {
                let mut positions = Vec::with_capacity(n);
                if let Some(las) = &self.las {
                    las.read(&self.path, self.read, n, &mut positions)?;
                }
                if positions.len() < n {
                    self.read += positions.len() as u64;
                    return Err(self.truncated());
                }
                for p in positions {
                    self.push(out, &[p.x, p.y, p.z, 0.0, 0.0, 0.0])?;
                }
            }
            Encoding::Loaded => {
                let from = self.read as usize;
                out.extend_from_slice(&self.loaded[from..from + n]);
                self.read += n as u64;
            }
            Encoding::Ascii | Encoding::Text => {
                let text = self.encoding == Encoding::Text;
                let mut got = 0;
                while got < n {
                    self.line.clear();
                    self.line_number += 1;
                    if self
                        .input
                        .read_line(&mut self.line)
                        .map_err(|e| Error::io(&self.path, e))?
                        == 0
                    {
                        return Err(self.truncated());
                    }
                    if text && is_comment(&self.line) {
                        continue;
                    }
                    self.parse_line(text, &mut values)?;
                    self.push(out, &values)?;
                    got += 1;
                }
            }
            Encoding::BinaryLittle | Encoding::BinaryBig => {
                let little = self.encoding == Encoding::BinaryLittle;
                self.buffer.resize(n * self.record_size, 0);
                let filled = fill(&mut self.input, &mut self.buffer)
                    .map_err(|e| Error::io(&self.path, e))?;
                if filled < self.buffer.len() {
                    // The complete records before the end count as read, for the message.
                    self.read += (filled / self.record_size) as u64;
                    return Err(self.truncated());
                }
                let buffer = std::mem::take(&mut self.buffer);
                for record in buffer.chunks_exact(self.record_size) {
                    let mut offset = 0;
                    for &(ty, slot) in &self.properties {
                        if let Some(k) = slot {
                            values[k] = ty.decode(&record[offset..], little);
                        }
                        offset += ty.size();
                    }
                    self.push(out, &values)?;
                }
                self.buffer = buffer;
            }
        }
        Ok(n)
    }

    /// The values of the line just read into their slots of `values`. Ascii PLY: blank-separated,
    /// every property present. Text: also comma- or semicolon-separated, and columns past the
    /// last one used may be missing.
    fn parse_line(&self, text: bool, values: &mut [f64; 6]) -> Result<()> {
        let error = |message: String| Error::Parse {
            path: self.path.clone(),
            line: Some(self.line_number),
            message,
        };
        let mut fields = split_fields(&self.line, text);
        for &(_, slot) in &self.properties {
            let field = fields.next();
            let Some(k) = slot else {
                if field.is_none() && !text {
                    return Err(error("too few values for the vertex properties".into()));
                }
                continue;
            };
            let w = field.ok_or_else(|| {
                error(if text {
                    "too few values on the line".into()
                } else {
                    "too few values for the vertex properties".into()
                })
            })?;
            values[k] = w
                .parse()
                .map_err(|_| error(format!("`{w}` is not a number")))?;
        }
        Ok(())
    }

    fn push(&mut self, out: &mut Vec<Point>, v: &[f64; 6]) -> Result<()> {
        let position = DVec3::new(v[0], v[1], v[2]);
        if !position.is_finite() {
            return Err(Error::Parse {
                path: self.path.clone(),
                line: None,
                message: format!("point {} has a non-finite coordinate", self.read),
            });
        }
        let normal = if self.has_normals {
            let n = DVec3::new(v[3], v[4], v[5]);
            if !n.is_finite() {
                return Err(Error::Parse {
                    path: self.path.clone(),
                    line: None,
                    message: format!(
                        "point {} has a non-finite normal ({} {} {})",
                        self.read, n.x, n.y, n.z
                    ),
                });
            }
            n.normalize_or_zero()
        } else {
            DVec3::ZERO
        };
        out.push(Point { position, normal });
        self.read += 1;
        Ok(())
    }

    fn truncated(&self) -> Error {
        Error::Parse {
            path: self.path.clone(),
            line: None,
            message: format!(
                "truncated: the header announces {} points, the file ends after {}",
                self.count, self.read
            ),
        }
    }
}

/// Reads into `buf` until it is full or the input ends; returns how many bytes were read.
fn fill(input: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut filled = 0;
    while filled < buf.len() {
        match input.read(&mut buf[filled..]) {
            Ok(0) => break,
            Ok(k) => filled += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(filled)
}

/// Whether `path`'s extension names an XYZ/CSV text point set.
/// Whether `path` holds a point set rather than a mesh: a text point format by its extension,
/// or a PLY file whose header declares no faces (no `face` or `tristrips` element with entries).
/// A file that cannot be read or is not PLY is not a point set (reading it as a mesh then says
/// what is wrong); this never fails.
pub(crate) fn is_point_set(path: &Path) -> Result<bool> {
    if is_text_extension(path)
        || super::pcd::is_pcd_extension(path)
        || super::las::is_las_extension(path)
        || super::e57::is_e57_extension(path)
    {
        return Ok(true);
    }
    let is_ply = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("ply"));
    if !is_ply {
        return Ok(false);
    }
    let Ok(file) = File::open(path) else {
        return Ok(false);
    };
    let mut input = BufReader::new(file);
    match input.fill_buf() {
        Ok(head) if head.starts_with(b"ply\n") || head.starts_with(b"ply\r\n") => {}
        _ => return Ok(false),
    }
    let mut reader = ply_rs_bw::parser::Reader::new(input);
    let Ok(header) = read_header(path, &mut reader) else {
        return Ok(false);
    };
    let has_vertices = header
        .elements
        .iter()
        .any(|(name, e)| name == "vertex" && e.count > 0);
    let has_faces = header
        .elements
        .iter()
        .any(|(name, e)| (name == "face" || name == "tristrips") && e.count > 0);
    Ok(has_vertices && !has_faces)
}

pub(crate) fn is_text_extension(path: &Path) -> bool {
    path.extension().and_then(|e| e.to_str()).is_some_and(|e| {
        ["xyz", "csv", "txt", "pts", "asc", "xyzn"]
            .iter()
            .any(|t| e.eq_ignore_ascii_case(t))
    })
}

/// Blank lines and `#` or `//` comments of a text point set.
fn is_comment(line: &str) -> bool {
    let t = line.trim_start();
    t.is_empty() || t.starts_with('#') || t.starts_with("//")
}

/// The values of a line: separated by blanks, and for text point sets (`text`) also by commas
/// or semicolons.
fn split_fields(line: &str, text: bool) -> impl Iterator<Item = &str> {
    line.split(move |c: char| c.is_whitespace() || (text && (c == ',' || c == ';')))
        .filter(|f| !f.is_empty())
}

/// Bytes of one point in the binary record layout of `remesh simplify`'s bucket files:
/// `x y z` as float64 LE (so coordinates far from the origin, such as UTM, keep their precision)
/// and `nx ny nz` as float32 LE.
pub(crate) const RECORD_BYTES: usize = 36;

/// The point of one record in that layout (`b` holds at least [`RECORD_BYTES`] bytes).
pub(crate) fn decode_record(b: &[u8]) -> Point {
    let d = |k: usize| f64::from_le_bytes(b[8 * k..8 * k + 8].try_into().unwrap_or([0; 8]));
    let f = |k: usize| {
        f64::from(f32::from_le_bytes(
            b[24 + 4 * k..28 + 4 * k].try_into().unwrap_or([0; 4]),
        ))
    };
    Point {
        position: DVec3::new(d(0), d(1), d(2)),
        normal: DVec3::new(f(0), f(1), f(2)),
    }
}

/// Appends `p` in that layout.
pub(crate) fn encode_record(p: &Point, out: &mut Vec<u8>) {
    for v in [p.position.x, p.position.y, p.position.z] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for v in [p.normal.x, p.normal.y, p.normal.z] {
        out.extend_from_slice(&(v as f32).to_le_bytes());
    }
}

/// Writes points with normals as binary little-endian PLY (`x y z` as float64, `nx ny nz` as
/// float32, and with
/// [`PlyPointWriter::create_with_levels`] a `uchar level`) through the crate's one binary PLY
/// writer, atomically ([`AtomicFile`]): a temporary file beside the target that
/// [`PlyPointWriter::finish`] renames into place, so a failure never leaves a partial file at
/// the target. The count must be known when the file is created.
pub struct PlyPointWriter {
    ply: BinaryPlyWriter<AtomicFile>,
}

impl PlyPointWriter {
    /// Starts a file of exactly `count` points at `path`.
    ///
    /// # Errors
    /// [`Error::Write`] naming `path` when the temporary file cannot be created.
    pub fn create(path: &Path, count: u64) -> Result<Self> {
        Self::start(path, count, false)
    }

    /// Starts a file of exactly `count` points with a per-point `uchar level` property (the
    /// level of a progressive sampling, Sec. 6.4), written by [`PlyPointWriter::write_levels`].
    ///
    /// # Errors
    /// [`Error::Write`] naming `path` when the temporary file cannot be created.
    pub fn create_with_levels(path: &Path, count: u64) -> Result<Self> {
        Self::start(path, count, true)
    }

    fn start(path: &Path, count: u64, with_levels: bool) -> Result<Self> {
        let file = AtomicFile::create(path)?;
        let write_error = |e: std::io::Error| Error::Write {
            path: path.to_path_buf(),
            message: e.to_string(),
        };
        let ply = BinaryPlyWriter::new(file, "spectral-remesh point set", count, with_levels, None)
            .map_err(write_error)?;
        Ok(PlyPointWriter { ply })
    }

    /// Appends points (to a file made by [`PlyPointWriter::create`]).
    ///
    /// # Errors
    /// [`Error::Write`] on a write failure, when more points than announced are written, or when
    /// the file has levels.
    pub fn write(&mut self, points: &[Point]) -> Result<()> {
        self.append(points, None)
    }

    /// Appends points with their levels (to a file made by
    /// [`PlyPointWriter::create_with_levels`]).
    ///
    /// # Errors
    /// [`Error::Write`] on a write failure, when more points than announced are written, when
    /// the file has no levels, or when `levels` and `points` differ in length.
    pub fn write_levels(&mut self, points: &[Point], levels: &[u8]) -> Result<()> {
        if levels.len() != points.len() {
            return Err(self.error("levels must come one per point".into()));
        }
        self.append(points, Some(levels))
    }

    fn append(&mut self, points: &[Point], levels: Option<&[u8]>) -> Result<()> {
        let f32s = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32];
        for (k, p) in points.iter().enumerate() {
            let level = levels.map(|l| l[k]);
            self.ply
                .vertex(p.position.to_array(), f32s(p.normal), level)
                .map_err(|e| self.ply.get_ref().error(e.to_string()))?;
        }
        Ok(())
    }

    /// Completes the file and moves it to its path.
    ///
    /// # Errors
    /// [`Error::Write`] when fewer points than announced were written or the file cannot be
    /// completed; the temporary file is removed.
    pub fn finish(self) -> Result<()> {
        let path = self.ply.get_ref().path().to_path_buf();
        let file = self.ply.finish().map_err(|e| Error::Write {
            path,
            message: e.to_string(),
        })?;
        file.commit()
    }

    fn error(&self, message: String) -> Error {
        self.ply.get_ref().error(message)
    }
}

#[cfg(test)]
mod tests;
