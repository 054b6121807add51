//! Reading triangle meshes from PLY with `ply-rs-bw` (ascii and binary of either byte order).

use std::io::{BufReader, Cursor, Read};
use std::path::Path;

use glam::DVec3;
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{
    Encoding, Header, Property, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType,
};

use super::{read_header, strip_line_prefix};
use crate::error::{Error, Result};
use crate::io::polygon::triangulate_polygon;
use crate::io::{one_line, read_file, ReadStats};
use crate::mesh::TriMesh;

/// The names a face element's index list may have.
const INDEX_LISTS: [&str; 2] = ["vertex_indices", "vertex_index"];

/// One element of the payload, whatever its kind: the parser uses one type for all elements,
/// so this holds what a vertex (`x y z`) or a face (an index list) needs.
#[derive(Default)]
struct Element {
    xyz: [f64; 3],
    indices: Vec<i64>,
}

impl Element {
    fn coordinate(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        let k = match name {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return PropertyAccessResult::Ignored,
        };
        self.xyz[k] = value;
        PropertyAccessResult::Set
    }

    fn index_list<T: Into<i64>>(&mut self, name: &str, values: Vec<T>) -> PropertyAccessResult {
        if INDEX_LISTS.contains(&name) {
            self.indices = values.into_iter().map(Into::into).collect();
            PropertyAccessResult::Set
        } else {
            PropertyAccessResult::Ignored
        }
    }
}

impl PropertyAccess for Element {
    fn new() -> Self {
        Element::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        let value = match property {
            Property::Char(v) => f64::from(v),
            Property::UChar(v) => f64::from(v),
            Property::Short(v) => f64::from(v),
            Property::UShort(v) => f64::from(v),
            Property::Int(v) => f64::from(v),
            Property::UInt(v) => f64::from(v),
            Property::Float(v) => f64::from(v),
            Property::Double(v) => v,
            // Other lists (texture coordinates, ...) are not ours; float index lists are
            // refused by the header check before the payload is read.
            _ => return PropertyAccessResult::Ignored,
        };
        self.coordinate(name, value)
    }

    fn set_float(&mut self, name: &str, value: f32) -> PropertyAccessResult {
        self.coordinate(name, f64::from(value))
    }

    fn set_double(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        self.coordinate(name, value)
    }

    fn set_list_char(&mut self, name: &str, value: Vec<i8>) -> PropertyAccessResult {
        self.index_list(name, value)
    }

    fn set_list_uchar(&mut self, name: &str, value: Vec<u8>) -> PropertyAccessResult {
        self.index_list(name, value)
    }

    fn set_list_short(&mut self, name: &str, value: Vec<i16>) -> PropertyAccessResult {
        self.index_list(name, value)
    }

    fn set_list_ushort(&mut self, name: &str, value: Vec<u16>) -> PropertyAccessResult {
        self.index_list(name, value)
    }

    fn set_list_int(&mut self, name: &str, value: Vec<i32>) -> PropertyAccessResult {
        self.index_list(name, value)
    }

    fn set_list_uint(&mut self, name: &str, value: Vec<u32>) -> PropertyAccessResult {
        self.index_list(name, value)
    }
}

/// The element of triangle strips (the Georgia Tech archive's models): one or more records,
/// each an index list of strips separated by -1.
const STRIPS: &str = "tristrips";

/// Checks that the header has what we read, before reading the payload: `vertex` with scalar
/// `x y z`, and `face` and `tristrips` (where present) each with an integer index list. Returns
/// whether there is a face element and whether there is a strip element.
fn check_header(path: &Path, header: &Header) -> Result<(bool, bool)> {
    check_vertices(path, header)?;
    let faces = check_index_list(path, header, "face")?;
    let strips = check_index_list(path, header, STRIPS)?;
    Ok((faces, strips))
}

/// The `vertex` element has scalar `x y z`.
fn check_vertices(path: &Path, header: &Header) -> Result<()> {
    let parse_err = |message: String| Error::parse(path, None, message);
    let vertex = header
        .elements
        .get("vertex")
        .ok_or_else(|| parse_err("the header declares no 'vertex' element".to_string()))?;
    for axis in ["x", "y", "z"] {
        match vertex.properties.get(axis).map(|p| &p.data_type) {
            Some(PropertyType::Scalar(_)) => {}
            Some(PropertyType::List(..)) => {
                return Err(parse_err(format!(
                    "vertex property '{axis}' is a list, expected a number"
                )))
            }
            None => {
                return Err(parse_err(format!(
                    "the 'vertex' element has no '{axis}' property"
                )))
            }
        }
    }
    Ok(())
}

/// Whether the header has the element `element` (`face` or `tristrips`); when it has, that
/// the element has an integer index list `vertex_indices` (or `vertex_index`).
fn check_index_list(path: &Path, header: &Header, element: &str) -> Result<bool> {
    let parse_err = |message: String| Error::parse(path, None, message);
    let Some(face) = header.elements.get(element) else {
        return Ok(false);
    };
    for name in INDEX_LISTS {
        match face.properties.get(name).map(|p| &p.data_type) {
            Some(PropertyType::List(_, ScalarType::Float | ScalarType::Double)) => {
                return Err(parse_err(format!(
                    "{element} property '{name}' holds floating-point numbers, expected integers"
                )))
            }
            Some(PropertyType::List(..)) => return Ok(true),
            Some(PropertyType::Scalar(_)) => {
                return Err(parse_err(format!(
                    "{element} property '{name}' is a single number, expected a list"
                )))
            }
            None => {}
        }
    }
    Err(parse_err(format!(
        "the '{element}' element has no 'vertex_indices' (or 'vertex_index') list"
    )))
}

/// The triangles of triangle strips: `indices` holds strips separated by -1; in each strip,
/// triangle `k` is `(s[k], s[k+1], s[k+2])` for even `k` and `(s[k+1], s[k], s[k+2])` for odd
/// `k` (the alternating winding that keeps every triangle's orientation). Triangles with a
/// repeated corner (the degenerate ones that stitch strips together) are left out; they still
/// count for the alternation. Appends to `triangles`; returns how many were appended.
///
/// # Errors
/// The first index that is neither -1 nor a vertex (`0 <= i < n`), for the caller's message.
fn strip_triangles(indices: &[i64], n: i64, triangles: &mut Vec<[u32; 3]>) -> Result<usize, i64> {
    let before = triangles.len();
    if let Some(&bad) = indices
        .iter()
        .find(|&&i| i != -1 && (i < 0 || i >= n || i > i64::from(u32::MAX)))
    {
        return Err(bad);
    }
    for strip in indices.split(|&i| i == -1) {
        for (k, w) in strip.windows(3).enumerate() {
            // Checked above: 0 <= index <= u32::MAX.
            let [a, b, c] = [w[0] as u32, w[1] as u32, w[2] as u32];
            if a == b || b == c || a == c {
                continue;
            }
            triangles.push(if k % 2 == 0 { [a, b, c] } else { [b, a, c] });
        }
    }
    Ok(triangles.len() - before)
}

/// Parses the PLY file at `path`; polygons are triangulated in their plane
/// ([`triangulate_polygon`]), indices checked (naming the face element).
pub(crate) fn read(path: &Path, stats: &mut ReadStats) -> Result<TriMesh> {
    let data = read_file(path)?;
    let parser = Parser::<Element>::new();
    let mut reader = Reader::new(BufReader::new(Cursor::new(&data[..])));
    let header = read_header(path, &mut reader)?;
    let (has_faces, has_strips) = check_header(path, &header)?;
    let payload = parser.read_payload(&mut reader, &header).map_err(|e| {
        // Line numbers mean something only in ascii files.
        let line = match header.encoding {
            Encoding::Ascii => e.line(),
            _ => None,
        };
        Error::parse(path, line, one_line(&strip_line_prefix(&e.to_string())))
    })?;
    // Nothing may follow a binary body's last element: bytes there are a body that does not
    // match its header (an ascii body under a binary header, a count too small) or garbage. An
    // ascii body may run on (MeshLab writes files with a line more than their header counts,
    // and reads them).
    let mut rest = Vec::new();
    reader
        .into_inner()
        .read_to_end(&mut rest)
        .map_err(|e| Error::io(path, e))?;
    if header.encoding != Encoding::Ascii && !rest.is_empty() {
        return Err(Error::parse(
            path,
            None,
            format!(
                "{} bytes after the last element the header announces (the body does not \
                 match the header)",
                rest.len()
            ),
        ));
    }

    let vertices = payload.get("vertex").map_or(&[][..], |v| &v[..]);
    let faces = payload.get("face").map_or(&[][..], |f| &f[..]);
    stats.vertices_read = vertices.len();
    let positions: Vec<DVec3> = vertices.iter().map(|v| DVec3::from_array(v.xyz)).collect();
    let n = positions.len() as i64;

    let mut triangles = Vec::with_capacity(faces.len());
    let mut corners: Vec<u32> = Vec::new();
    if has_faces {
        for (f, face) in faces.iter().enumerate() {
            let idx = &face.indices;
            if let Some(&bad) = idx
                .iter()
                .find(|&&i| i < 0 || i >= n || i > i64::from(u32::MAX))
            {
                return Err(Error::invalid_mesh(
                    path,
                    format!("face {f} (0-based) names vertex {bad}, but the file has {n} vertices"),
                ));
            }
            if idx.len() < 3 {
                continue;
            }
            stats.faces_read += 1;
            if idx.len() > 3 {
                stats.polygons_triangulated += 1;
            }
            // Checked above: 0 <= index <= u32::MAX.
            if let [a, b, c] = idx[..] {
                triangles.push([a as u32, b as u32, c as u32]);
            } else {
                corners.clear();
                corners.extend(idx.iter().map(|&i| i as u32));
                triangles.extend(triangulate_polygon(&positions, &corners));
            }
        }
    }
    if has_strips {
        for (e, record) in payload.get(STRIPS).into_iter().flatten().enumerate() {
            let made = strip_triangles(&record.indices, n, &mut triangles).map_err(|bad| {
                Error::invalid_mesh(
                    path,
                    format!(
                        "tristrips record {e} (0-based) names vertex {bad}, but the file has {n} \
                         vertices (strips are separated by -1)"
                    ),
                )
            })?;
            stats.faces_read += made;
        }
    }
    Ok(TriMesh::new(positions, triangles))
}
