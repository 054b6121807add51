//! OFF (Object File Format, Geomview): the plain text format of CGAL and of much geometry
//! processing code. `OFF`, then the vertex, face and edge counts, the vertices (`x y z`, more
//! values such as colours ignored) and the faces (`k i1 … ik`, 0-based, colours after them
//! ignored). `#` starts a comment. Our own reader: no well-kept crate reads it, and the format
//! is a few lines of text.

use std::fmt::Write as _;
use std::path::Path;

use glam::DVec3;

use super::polygon::triangulate_polygon;
use super::{read_file, ReadStats};
use crate::error::{Error, Result};
use crate::mesh::TriMesh;

/// Parses the OFF file at `path`: its vertices in file order, its faces triangulated in file
/// order (polygons in their plane, [`triangulate_polygon`]). Accepts the `OFF` keyword with the
/// counts on the same line or the next, and the `COFF`, `NOFF`, `CNOFF` variants (the extra
/// per-vertex values ignored).
pub(super) fn read(path: &Path, stats: &mut ReadStats) -> Result<TriMesh> {
    let data = read_file(path)?;
    // A UTF-8 byte-order mark is not part of the keyword.
    let text = String::from_utf8_lossy(data.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&data));
    // Lines without comments, numbered from 1, blank ones skipped.
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.split('#').next().unwrap_or("").trim()))
        .filter(|(_, l)| !l.is_empty());
    let err = |line: usize, message: String| Error::parse(path, Some(line), message);
    let (first_no, first) = lines
        .next()
        .ok_or_else(|| Error::parse(path, None, "no OFF header (the file has no content)"))?;
    let mut head = first.split_whitespace();
    let word = head.next().unwrap_or("");
    // The keyword, and a count written against it (`OFF8 6 12`, which trimesh reads).
    let (keyword, glued) = ["CNOFF", "COFF", "NOFF", "OFF"]
        .iter()
        .find_map(|k| {
            let rest = word.strip_prefix(k)?;
            (rest.is_empty() || rest.bytes().all(|b| b.is_ascii_digit())).then_some((*k, rest))
        })
        .unwrap_or((word, ""));
    if !matches!(keyword, "OFF" | "COFF" | "NOFF" | "CNOFF") {
        return Err(err(
            first_no,
            format!(
                "not an OFF file: it starts with `{}`, not `OFF`",
                short(keyword)
            ),
        ));
    }
    let rest: Vec<&str> = (!glued.is_empty())
        .then_some(glued)
        .into_iter()
        .chain(head)
        .collect();
    let (counts_no, counts) = if rest.is_empty() {
        lines
            .next()
            .map(|(n, l)| (n, l.split_whitespace().collect::<Vec<_>>()))
            .ok_or_else(|| err(first_no, "the vertex and face counts are missing".into()))?
    } else {
        (first_no, rest)
    };
    let count = |k: usize, what: &str| -> Result<usize> {
        counts
            .get(k)
            .ok_or_else(|| err(counts_no, format!("the {what} count is missing")))?
            .parse::<usize>()
            .map_err(|_| {
                err(
                    counts_no,
                    format!(
                        "the {what} count `{}` is not a whole number",
                        short(counts[k])
                    ),
                )
            })
    };
    let (nv, nf) = (count(0, "vertex")?, count(1, "face")?);
    // Everything on the counts' line and nothing after it (`OFF 4 4 0 0 0 0 1 0 0 …`, which
    // common readers take as a stream of tokens): the records are read from that line's tokens.
    if counts.len() > 3 && lines.clone().next().is_none() {
        return read_one_line(path, counts_no, &counts[3..], nv, nf, stats);
    }
    // Record `k` of `n` (vertices or faces): the next line with content, with its number.
    let mut record = |k: usize, n: usize, what: &str| {
        lines.next().ok_or_else(|| {
            Error::parse(
                path,
                None,
                format!("the file ends after {k} of its {n} {what}"),
            )
        })
    };
    let mut positions = Vec::with_capacity(nv.min(1 << 24));
    // A record's tokens: its line's, and the next lines' while it needs more (OFF is
    // whitespace-separated; some writers wrap long records). Values past those it needs on its
    // last line (colours) are left out.
    let mut tokens_of = |k: usize, n: usize, what: &str, need: &dyn Fn(&[&str]) -> usize| {
        let (no, line) = record(k, n, what)?;
        let mut tokens: Vec<&str> = line.split_whitespace().collect();
        while tokens.len() < need(&tokens) {
            match record(k, n, what) {
                Ok((_, more)) => tokens.extend(more.split_whitespace()),
                Err(_) => break,
            }
        }
        Ok::<_, Error>((no, tokens))
    };
    for k in 0..nv {
        let (no, tokens) = tokens_of(k, nv, "vertices", &|_| 3)?;
        let missing = || err(no, "a vertex needs three coordinates".into());
        positions.push(vertex(&mut tokens.into_iter(), &missing, &|m| err(no, m))?);
    }
    let mut faces = Faces::new(nf);
    for k in 0..nf {
        let (no, tokens) = tokens_of(k, nf, "faces", &|t: &[&str]| {
            t.first()
                .and_then(|c| c.parse::<usize>().ok())
                .map_or(0, |size| size.saturating_add(1))
        })?;
        // A record's line has content: its first token, the corner count, is always there.
        let mut tokens = tokens.into_iter();
        let missing = || err(no, "the face has fewer corners than it says".into());
        faces.push(
            &mut tokens,
            &positions,
            stats,
            &missing,
            &|m| err(no, m),
            &|i| {
                Error::invalid_mesh(
                    path,
                    format!("face on line {no} names vertex {i}, but the file has {nv} vertices"),
                )
            },
        )?;
    }
    let triangles = faces.triangles;
    stats.vertices_read = positions.len();
    Ok(TriMesh::new(positions, triangles))
}

/// The `nv` vertices (three coordinates each) and `nf` faces (a corner count, then the corners)
/// of an OFF file whose records are all on its line `no` as the `tokens` after its counts;
/// errors as [`read`]'s, naming that line.
fn read_one_line(
    path: &Path,
    no: usize,
    tokens: &[&str],
    nv: usize,
    nf: usize,
    stats: &mut ReadStats,
) -> Result<TriMesh> {
    let err = |message: String| Error::parse(path, Some(no), message);
    let mut tokens = tokens.iter().copied();
    let mut positions = Vec::with_capacity(nv.min(1 << 24));
    for k in 0..nv {
        let missing = || {
            err(format!(
                "the line ends before vertex {k} of {nv} is complete"
            ))
        };
        positions.push(vertex(&mut tokens, &missing, &err)?);
    }
    let mut faces = Faces::new(nf);
    for k in 0..nf {
        let missing = || err(format!("the line ends before face {k} of {nf} is complete"));
        faces.push(&mut tokens, &positions, stats, &missing, &err, &|i| {
            Error::invalid_mesh(
                path,
                format!("face {k} names vertex {i}, but the file has {nv} vertices"),
            )
        })?;
    }
    let triangles = faces.triangles;
    stats.vertices_read = positions.len();
    Ok(TriMesh::new(positions, triangles))
}

/// A vertex record's three coordinates, the first three of `tokens` (the rest of the record is
/// left unread: colours): `missing()` when there are fewer, `bad(message)` for a token that is
/// not a number.
fn vertex(
    tokens: &mut dyn Iterator<Item = &str>,
    missing: &dyn Fn() -> Error,
    bad: &dyn Fn(String) -> Error,
) -> Result<DVec3> {
    let mut p = [0.0f64; 3];
    for c in &mut p {
        let tok = tokens.next().ok_or_else(missing)?;
        *c = tok
            .parse::<f64>()
            .map_err(|_| bad(format!("`{}` is not a number", short(tok))))?;
    }
    Ok(DVec3::from_array(p))
}

/// The faces read so far, triangulated ([`triangulate_polygon`]).
struct Faces {
    triangles: Vec<[u32; 3]>,
    corners: Vec<u32>,
}

impl Faces {
    fn new(nf: usize) -> Self {
        Faces {
            triangles: Vec::with_capacity(nf.min(1 << 24)),
            corners: Vec::new(),
        }
    }

    /// Reads a face record from `tokens` (a corner count, then the corners; what follows is
    /// left unread: colours) over the vertices `positions` and adds its triangles:
    /// `missing()` when the tokens run out, `bad(message)` for a token that is not a count or
    /// an index, `out_of_range(i)` for a corner past the vertices.
    fn push(
        &mut self,
        tokens: &mut dyn Iterator<Item = &str>,
        positions: &[DVec3],
        stats: &mut ReadStats,
        missing: &dyn Fn() -> Error,
        bad: &dyn Fn(String) -> Error,
        out_of_range: &dyn Fn(u64) -> Error,
    ) -> Result<()> {
        let size_tok = tokens.next().ok_or_else(missing)?;
        let size: usize = size_tok
            .parse()
            .map_err(|_| bad(format!("`{}` is not a corner count", short(size_tok))))?;
        self.corners.clear();
        for _ in 0..size {
            let tok = tokens.next().ok_or_else(missing)?;
            let i = tok
                .parse::<u64>()
                .map_err(|_| bad(format!("`{}` is not a vertex index", short(tok))))?;
            if i >= positions.len() as u64 {
                return Err(out_of_range(i));
            }
            self.corners.push(i as u32);
        }
        stats.faces_read += usize::from(size >= 3);
        if size > 3 {
            stats.polygons_triangulated += 1;
        }
        self.triangles
            .extend(triangulate_polygon(positions, &self.corners));
        Ok(())
    }
}

/// At most 40 characters of a token, for messages.
fn short(token: &str) -> String {
    token.chars().take(40).collect()
}

/// OFF text of `mesh`: the header, the vertices with Rust's shortest round-trip `f64`
/// formatting (reading the file back gives the same coordinates), the triangles.
pub(super) fn encode(mesh: &TriMesh) -> Vec<u8> {
    let mut s = String::with_capacity(32 * (mesh.positions.len() + mesh.triangles.len()) + 64);
    let _ = writeln!(s, "OFF");
    let _ = writeln!(s, "# written by spectral-remesh");
    let _ = writeln!(s, "{} {} 0", mesh.positions.len(), mesh.triangles.len());
    for p in &mesh.positions {
        let _ = writeln!(s, "{:?} {:?} {:?}", p.x, p.y, p.z);
    }
    for t in &mesh.triangles {
        let _ = writeln!(s, "3 {} {} {}", t[0], t[1], t[2]);
    }
    s.into_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_text(text: &str) -> Result<(TriMesh, ReadStats)> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.off");
        std::fs::write(&path, text).unwrap();
        super::super::read_mesh(&path)
    }

    #[test]
    fn round_trip_is_exact() {
        let m = TriMesh::new(
            vec![
                DVec3::new(0.1, 0.2, 0.3),
                DVec3::new(1.0 / 3.0, 0.0, 1e-300),
                DVec3::new(0.0, 2.5e10, 0.0),
                DVec3::new(0.0, 0.0, -7.0),
            ],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        );
        let (back, stats) = read_text(std::str::from_utf8(&encode(&m)).unwrap()).unwrap();
        assert_eq!(back.positions, m.positions);
        assert_eq!(back.triangles, m.triangles);
        assert_eq!((stats.vertices_read, stats.faces_read), (4, 4));
    }

    #[test]
    fn quads_comments_colours_and_counts_on_the_keyword_line() {
        let text = "# a unit square as one quad\nOFF 4 1 0\n0 0 0 255 0 0\n1 0 0\n\n1 1 0\n0 1 0 # last\n4 0 1 2 3 0.5 0.5 0.5\n";
        let (m, stats) = read_text(text).unwrap();
        assert_eq!(m.triangles.len(), 2);
        assert_eq!(stats.polygons_triangulated, 1);
        assert!((m.area() - 1.0).abs() < 1e-12);
    }

    /// Issue 56, R11: an OFF with all its tokens on one line was refused ("the file ends after 0
    /// of its 4 vertices"). It reads as the same file with a record per line.
    #[test]
    fn an_off_file_on_one_line_is_read() {
        let lines = "OFF\n4 4 0\n0 0 0\n1.5 0 0\n0 2.25 0\n0 0 0.125\n\
                     3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n";
        let one = lines.replace('\n', " ");
        let (a, _) = read_text(lines).unwrap();
        let (b, stats) = read_text(&one).unwrap();
        assert_eq!(a, b);
        assert_eq!((stats.vertices_read, stats.faces_read), (4, 4));
        // Cut short, it is an error naming the line.
        let short = one.trim_end().rsplit_once(' ').unwrap().0.to_string();
        let e = read_text(&short).unwrap_err().to_string();
        assert!(e.contains("m.off:1:") && !e.contains('\n'), "{e}");
    }

    #[test]
    fn bad_files_are_one_line_errors_naming_the_file_and_line() {
        for (text, needle) in [
            ("PLY\n", "m.off:1:"),
            ("OFF\n3 x 0\n", "m.off:2:"),
            ("OFF\n3 1 0\n0 0 0\n1 0 0\n", "ends after 2"),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
                "names vertex 7",
            ),
            ("OFF\n3 1 0\n0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n", "m.off:4:"),
        ] {
            let e = read_text(text).unwrap_err().to_string();
            assert!(
                e.contains("m.off") && e.contains(needle) && !e.contains('\n'),
                "{e}"
            );
        }
    }
}
