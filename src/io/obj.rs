//! Wavefront OBJ: a small reader for the geometry (`v`, `f`) and the writer.
//!
//! The reader is our own rather than `tobj`'s: `tobj` (without its `use_f64` feature) parses
//! coordinates as `f32`, which would make reading back our own `f64` output inexact; it renumbers
//! vertices in order of first use and drops unreferenced ones before we can count them; it
//! reports no line numbers; and some malformed inputs make it panic.

use std::fmt::Write as _;
use std::path::Path;

use glam::DVec3;

use super::polygon::triangulate_polygon;
use super::{read_file, ReadStats};
use crate::error::{Error, Result};
use crate::mesh::TriMesh;

/// Parses the OBJ file at `path` into a mesh with the file's vertices in file order and its
/// faces triangulated in file order, polygons in their plane ([`triangulate_polygon`]; indices
/// checked against the vertex count, 1-based in messages).
pub(super) fn read(path: &Path, stats: &mut ReadStats) -> Result<TriMesh> {
    let file = read_file(path)?;
    // A UTF-8 byte-order mark (some Windows editors write one) is not part of the first line.
    let data = file.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&file);
    let mut positions: Vec<DVec3> = Vec::new();
    // Every face's corners, one after another, and where each face ends in `face_corners`:
    // polygons are triangulated once every vertex is read (a face may name a later vertex).
    let mut face_corners: Vec<u32> = Vec::new();
    let mut face_ends: Vec<usize> = Vec::new();
    // The line of each face, for error messages.
    let mut face_lines: Vec<usize> = Vec::new();
    let mut corners: Vec<u32> = Vec::new();
    // A logical line continued with a trailing backslash, and the line it started on.
    let mut continued: Vec<u8> = Vec::new();
    let mut continued_from = 0;

    // Lines end with "\n" or "\r\n"; a file with only "\r" (classic Mac OS) splits on that.
    let eol = if !data.contains(&b'\n') && data.contains(&b'\r') {
        b'\r'
    } else {
        b'\n'
    };
    for (i, physical) in data.split(|&b| b == eol).enumerate() {
        let line_no = i + 1;
        let trimmed = trim_end(physical);
        if let Some(head) = trimmed.strip_suffix(b"\\") {
            if continued.is_empty() {
                continued_from = line_no;
            }
            continued.extend_from_slice(head);
            continued.push(b' ');
            continue;
        }
        let (line, line_no) = if continued.is_empty() {
            (trimmed, line_no)
        } else {
            continued.extend_from_slice(trimmed);
            (&continued[..], continued_from)
        };
        parse_line(
            path,
            line,
            line_no,
            &mut positions,
            &mut face_corners,
            &mut face_ends,
            &mut face_lines,
            &mut corners,
            stats,
        )?;
        continued.clear();
    }
    if !continued.is_empty() {
        let line = std::mem::take(&mut continued);
        parse_line(
            path,
            &line,
            continued_from,
            &mut positions,
            &mut face_corners,
            &mut face_ends,
            &mut face_lines,
            &mut corners,
            stats,
        )?;
    }

    stats.vertices_read = positions.len();
    let n = positions.len() as u64;
    let mut triangles: Vec<[u32; 3]> = Vec::with_capacity(face_ends.len());
    let mut start = 0;
    for (f, &end) in face_ends.iter().enumerate() {
        let face = &face_corners[start..end];
        start = end;
        if let Some(&bad) = face.iter().find(|&&v| u64::from(v) >= n) {
            return Err(Error::invalid_mesh(
                path,
                format!(
                    "face on line {} names vertex {}, but the file has {} vertices",
                    face_lines[f],
                    u64::from(bad) + 1,
                    n
                ),
            ));
        }
        if let [a, b, c] = face[..] {
            triangles.push([a, b, c]);
        } else {
            triangles.extend(triangulate_polygon(&positions, face));
        }
    }
    Ok(TriMesh::new(positions, triangles))
}

/// Parses one logical line (comments and `\r` included; unknown statements ignored).
#[allow(clippy::too_many_arguments)]
fn parse_line(
    path: &Path,
    line: &[u8],
    line_no: usize,
    positions: &mut Vec<DVec3>,
    face_corners: &mut Vec<u32>,
    face_ends: &mut Vec<usize>,
    face_lines: &mut Vec<usize>,
    corners: &mut Vec<u32>,
    stats: &mut ReadStats,
) -> Result<()> {
    // Cut a comment (numbers never contain '#').
    let line = match line.iter().position(|&b| b == b'#') {
        Some(k) => &line[..k],
        None => line,
    };
    let mut tokens = line
        .split(|b| b.is_ascii_whitespace())
        .filter(|t| !t.is_empty());
    let parse_err = |message: String| Error::parse(path, Some(line_no), message);
    match tokens.next() {
        Some(b"v") => {
            let mut p = [0.0f64; 3];
            for (k, c) in p.iter_mut().enumerate() {
                let tok = tokens
                    .next()
                    .ok_or_else(|| parse_err(format!("vertex has {k} coordinates, expected 3")))?;
                *c = std::str::from_utf8(tok)
                    .ok()
                    .and_then(|s| s.parse::<f64>().ok())
                    .ok_or_else(|| {
                        parse_err(format!(
                            "cannot read vertex coordinate '{}'",
                            super::one_line(&String::from_utf8_lossy(tok))
                        ))
                    })?;
            }
            let p = DVec3::from_array(p);
            if !p.is_finite() {
                return Err(Error::invalid_mesh(
                    path,
                    format!(
                        "vertex {} (line {line_no}) has a non-finite coordinate {:?}",
                        positions.len() + 1,
                        p.to_array()
                    ),
                ));
            }
            positions.push(p);
        }
        Some(b"f") => {
            corners.clear();
            for tok in tokens {
                corners.push(parse_index(tok, positions.len()).map_err(parse_err)?);
            }
            if corners.len() < 3 {
                // A point or a line written as a face: ignored like `p` and `l`.
                return Ok(());
            }
            stats.faces_read += 1;
            if corners.len() > 3 {
                stats.polygons_triangulated += 1;
            }
            face_corners.extend_from_slice(corners);
            face_ends.push(face_corners.len());
            face_lines.push(line_no);
        }
        _ => {}
    }
    Ok(())
}

/// The 0-based vertex index of a face corner (`v`, `v/vt`, `v//vn` or `v/vt/vn`; negative `v`
/// counts back from the last vertex read so far, `-1` being the last).
fn parse_index(token: &[u8], vertices_so_far: usize) -> std::result::Result<u32, String> {
    let v = token.split(|&b| b == b'/').next().unwrap_or(token);
    let shown = || super::one_line(&String::from_utf8_lossy(token));
    let value: i64 = std::str::from_utf8(v)
        .ok()
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| format!("cannot read face corner '{}'", shown()))?;
    let index = if value > 0 {
        value - 1
    } else if value < 0 {
        let resolved = vertices_so_far as i64 + value;
        if resolved < 0 {
            return Err(format!(
                "face corner '{}' counts back past the first vertex ({} vertices so far)",
                shown(),
                vertices_so_far
            ));
        }
        resolved
    } else {
        return Err(format!(
            "face corner '{}' names vertex 0 (OBJ indices start at 1)",
            shown()
        ));
    };
    u32::try_from(index).map_err(|_| format!("face corner '{}' is out of range", shown()))
}

fn trim_end(mut s: &[u8]) -> &[u8] {
    while let [rest @ .., last] = s {
        if last.is_ascii_whitespace() {
            s = rest;
        } else {
            break;
        }
    }
    s
}

/// The OBJ text of `mesh` with `normals` (one per vertex): positions and normals with the
/// shortest `f64` formatting that reads back exactly, faces `f a//a b//b c//c`.
pub(super) fn encode(mesh: &TriMesh, normals: &[DVec3]) -> Vec<u8> {
    let mut s = String::with_capacity(mesh.positions.len() * 90 + mesh.triangles.len() * 40);
    let _ = writeln!(
        s,
        "# written by spectral-remesh {}",
        env!("CARGO_PKG_VERSION")
    );
    let _ = writeln!(
        s,
        "# {} vertices, {} triangles",
        mesh.positions.len(),
        mesh.triangles.len()
    );
    for p in &mesh.positions {
        let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
    }
    for n in normals {
        let _ = writeln!(s, "vn {} {} {}", n.x, n.y, n.z);
    }
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| u64::from(i) + 1);
        let _ = writeln!(s, "f {a}//{a} {b}//{b} {c}//{c}");
    }
    s.into_bytes()
}
