//! STL (stereolithography), binary and ascii, through the `stl_io` crate: the format CAD parts
//! are exported in. A triangle soup: every triangle stores its three corners, so shared corners
//! are welded by position, bit-identical or a rounding apart (the readers' common clean-up).

use std::io::Cursor;
use std::path::Path;

use glam::DVec3;

use super::{one_line, read_file, ReadStats};
use crate::error::{Error, Result};
use crate::mesh::TriMesh;

/// Bytes of the binary header before the triangle count.
const HEADER: usize = 80;
/// Bytes of one binary triangle record: normal, three corners (12 `f32`) and a `u16`.
const RECORD: usize = 50;

/// Whether `data` has the binary layout: an 80-byte header, a triangle count n and exactly n
/// records of 50 bytes. Many exporters begin the binary header with `solid` too, so the
/// length, not the first word, tells binary from ascii.
fn is_binary(data: &[u8]) -> bool {
    data.len() >= HEADER + 4 && {
        let n = u32::from_le_bytes([data[80], data[81], data[82], data[83]]) as u64;
        data.len() as u64 == (HEADER + 4) as u64 + n * RECORD as u64
    }
}

/// Parses the STL file at `path` into a mesh with three vertices per triangle in file order
/// (welded later by position); the stored facet normals are ignored (the corners' order gives
/// the orientation).
pub(super) fn read(path: &Path, stats: &mut ReadStats) -> Result<TriMesh> {
    let mut data = read_file(path)?;
    let parse_err = |message: String| Error::parse(path, None, message);
    let binary = is_binary(&data);
    if !binary {
        // Keywords in any case (`SOLID`, `FACET NORMAL`, as some exporters write them): the
        // text lowered (numbers read the same, `1E-5` as `1e-5`).
        data.make_ascii_lowercase();
    }
    if binary {
        // stl_io tells ascii by a leading `solid `: blank the header (it holds nothing we use)
        // so that a binary file whose header starts so is read as binary.
        data[..HEADER].fill(0);
    } else if !data.starts_with(b"solid") {
        return Err(parse_err(if data.len() >= HEADER + 4 {
            let n = u32::from_le_bytes([data[80], data[81], data[82], data[83]]);
            format!(
                "not an ascii STL (it does not start with `solid`), and as binary STL its \
                 header says {n} triangles, which take {} bytes, but the file has {}",
                (HEADER + 4) as u64 + u64::from(n) * RECORD as u64,
                data.len()
            )
        } else {
            format!(
                "not an STL file: {} bytes, too short for a binary STL and not starting with \
                 `solid`",
                data.len()
            )
        }));
    }
    // An ascii file may hold several solids (a multi-body CAD export): each is read.
    let blocks: Vec<Vec<u8>> = if binary {
        vec![data]
    } else {
        ascii_solids(&data)
    };
    let mut positions = Vec::new();
    let mut i = 0usize;
    for block in &blocks {
        let mut cursor = Cursor::new(&block[..]);
        let triangles = stl_io::create_stl_reader(&mut cursor)
            .map_err(|e| parse_err(format!("cannot read the STL: {}", one_line(&e.to_string()))))?;
        for t in triangles {
            let t = t.map_err(|e| {
                parse_err(format!(
                    "triangle {} (0-based): {}",
                    i,
                    one_line(&e.to_string())
                ))
            })?;
            for v in t.vertices {
                positions.push(DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64));
            }
            i += 1;
        }
    }
    stats.vertices_read = positions.len();
    stats.faces_read = positions.len() / 3;
    let triangles = (0..stats.faces_read as u32)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    Ok(TriMesh::new(positions, triangles))
}

/// The solids of an ascii STL (lower-cased `data` that starts with `solid`): from each line that
/// begins with `solid` to the next, each starting with `solid ` as stl_io wants it (a `solid`
/// without a name gets the space).
fn ascii_solids(data: &[u8]) -> Vec<Vec<u8>> {
    let mut starts = vec![0];
    for (k, &b) in data.iter().enumerate() {
        if b == b'\n' {
            let line_start = k + 1;
            let rest = &data[line_start..];
            let first = rest
                .iter()
                .position(|c| !c.is_ascii_whitespace() || *c == b'\n');
            if let Some(f) = first {
                if rest[f..].starts_with(b"solid") && line_start + f > 0 {
                    starts.push(line_start + f);
                }
            }
        }
    }
    starts.dedup();
    starts.push(data.len());
    starts
        .windows(2)
        .map(|w| {
            let mut block = data[w[0]..w[1]].to_vec();
            if !block.starts_with(b"solid ") {
                block.insert(5, b' ');
            }
            block
        })
        .collect()
}

/// Binary STL of `mesh`: a header naming the writer, one record per triangle with its unit
/// normal (zero for a degenerate one) and its corners as `f32`.
pub(super) fn encode(mesh: &TriMesh) -> std::io::Result<Vec<u8>> {
    let f32x3 = |p: DVec3| stl_io::Vector::new([p.x as f32, p.y as f32, p.z as f32]);
    let triangles: Vec<stl_io::Triangle> = (0..mesh.face_count())
        .map(|f| {
            let c = mesh.corners(f);
            stl_io::Triangle {
                normal: f32x3(mesh.face_normal(f)),
                vertices: c.map(f32x3),
            }
        })
        .collect();
    let mut out = Vec::with_capacity(HEADER + 4 + RECORD * triangles.len());
    stl_io::write_stl(&mut out, triangles.iter())?;
    Ok(out)
}

/// `mesh` as [`encode`] stores it: every position rounded to `f32`.
pub(super) fn as_written(mesh: &TriMesh) -> TriMesh {
    TriMesh::new(
        mesh.positions
            .iter()
            .map(|p| p.as_vec3().as_dvec3())
            .collect(),
        mesh.triangles.clone(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetrahedron() -> TriMesh {
        TriMesh::new(
            vec![
                DVec3::ZERO,
                DVec3::new(1.5, 0.0, 0.0),
                DVec3::new(0.0, 2.25, 0.0),
                DVec3::new(0.0, 0.0, 0.125),
            ],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        )
    }

    fn read_bytes(bytes: &[u8]) -> Result<(TriMesh, ReadStats)> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.stl");
        std::fs::write(&path, bytes).unwrap();
        super::super::read_mesh(&path)
    }

    #[test]
    fn binary_round_trip_welds_the_corners_back() {
        let m = tetrahedron();
        let bytes = encode(&m).unwrap();
        assert_eq!(bytes.len(), 84 + 50 * 4);
        let (back, stats) = read_bytes(&bytes).unwrap();
        assert_eq!(stats.vertices_read, 12);
        assert_eq!(stats.faces_read, 4);
        assert_eq!(stats.welded_vertices, 8);
        // The same triangles, corner for corner (vertices renumbered in order of first use).
        let corners = |m: &TriMesh| -> Vec<[DVec3; 3]> {
            (0..m.face_count()).map(|f| m.corners(f)).collect()
        };
        assert_eq!(corners(&back), corners(&m));
    }

    #[test]
    fn a_binary_header_starting_with_solid_is_still_binary() {
        let mut bytes = encode(&tetrahedron()).unwrap();
        bytes[..12].copy_from_slice(b"solid binary");
        let (back, _) = read_bytes(&bytes).unwrap();
        assert_eq!(back.triangles.len(), 4);
    }

    #[test]
    fn ascii_is_read() {
        let text = "solid t\n\
            facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\nendfacet\n\
            facet normal 0 0 1\n outer loop\n  vertex 1 0 0\n  vertex 1 1 0\n  vertex 0 1 0\n endloop\nendfacet\n\
            endsolid t\n";
        let (m, stats) = read_bytes(text.as_bytes()).unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles, vec![[0, 1, 2], [1, 3, 2]]);
        assert_eq!(stats.welded_vertices, 2);
    }

    /// The corners of each face of `m`, as arrays.
    fn corner_arrays(m: &TriMesh) -> Vec<[[f64; 3]; 3]> {
        (0..m.face_count())
            .map(|f| m.corners(f).map(|p| p.to_array()))
            .collect()
    }

    /// An ascii STL of `solids`, each a name and its triangles.
    fn ascii(solids: &[(&str, &[[[f64; 3]; 3]])]) -> String {
        let mut text = String::new();
        for (name, triangles) in solids {
            text += &format!("solid {name}\n");
            for t in *triangles {
                text += "  facet normal 0 0 0\n    outer loop\n";
                for p in t {
                    text += &format!("      vertex {} {} {}\n", p[0], p[1], p[2]);
                }
                text += "    endloop\n  endfacet\n";
            }
            text += &format!("endsolid {name}\n");
        }
        text
    }

    /// Issue 56, R6: an ascii STL of two `solid … endsolid` blocks (a multi-body CAD export)
    /// was read up to the first `endsolid`, silently. Every solid is read, in order.
    #[test]
    fn every_solid_of_an_ascii_stl_is_read() {
        let m = tetrahedron();
        let corners = corner_arrays(&m);
        let text = ascii(&[
            ("first", &corners[..2]),
            ("", &corners[2..3]),
            ("third", &corners[3..]),
        ]);
        let (back, stats) = read_bytes(text.as_bytes()).unwrap();
        assert_eq!(stats.faces_read, 4);
        let read: Vec<[DVec3; 3]> = (0..back.face_count()).map(|f| back.corners(f)).collect();
        let made: Vec<[DVec3; 3]> = (0..m.face_count()).map(|f| m.corners(f)).collect();
        assert_eq!(read, made);
        assert_eq!(back.positions.len(), 4, "welded across the solids");
    }

    /// Issue 56, R11: an ascii STL in upper case (`SOLID`, `FACET NORMAL`, `1E-1`) was taken for
    /// binary. It reads as the same file in lower case.
    #[test]
    fn an_ascii_stl_in_upper_case_is_read() {
        let m = tetrahedron();
        let corners = corner_arrays(&m);
        let lower = ascii(&[("part", &corners)]).replace("0.125", "1.25e-1");
        let upper = lower.to_ascii_uppercase();
        assert!(upper.contains("SOLID PART") && upper.contains("1.25E-1"));
        let (a, _) = read_bytes(lower.as_bytes()).unwrap();
        let (b, _) = read_bytes(upper.as_bytes()).unwrap();
        assert_eq!(a, b);
        assert_eq!(a.triangles.len(), 4);
    }

    #[test]
    fn truncated_and_foreign_files_are_one_line_errors_naming_the_file() {
        let bytes = encode(&tetrahedron()).unwrap();
        for bad in [
            &bytes[..bytes.len() - 7],
            &b"hello"[..],
            &b"solid x\nfacet nonsense\n"[..],
        ] {
            let e = read_bytes(bad).unwrap_err().to_string();
            assert!(e.contains("m.stl") && !e.contains('\n'), "{e}");
        }
    }
}
