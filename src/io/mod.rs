//! Reading and writing meshes: OBJ, PLY, glTF 2.0 (`.gltf`/`.glb`), chosen by extension.
//!
//! [`read_mesh`] parses a file into a [`TriMesh`] in the file's own units, then cleans it the same
//! way for every format: it checks the indices and the coordinates, welds vertices with identical
//! positions (glTF splits vertices at texture seams, OBJ files keep them shared, so welding makes
//! the OBJ and glTF versions of a model the same mesh) and drops vertices no triangle uses.
//!
//! [`write_mesh`] writes a mesh with angle-weighted vertex normals, atomically: the target is
//! either replaced by the complete new file or left as it was. [`write_atomically`] and
//! [`AtomicFile`] do that for every file the crate writes.
//!
//! No function here panics on a file's content; every failure is an [`Error`] naming the file.

mod atomic;
mod gltf;
mod obj;
mod off;
pub(crate) mod ply;
mod polygon;
mod stl;
pub(crate) mod temporaries;

use std::fs;
use std::path::Path;

use glam::DVec3;
use serde::Serialize;

use crate::error::{Error, Result};
use crate::geometry::tolerance::{WELD_EDGE_RELATIVE, WELD_RELATIVE};
use crate::mesh::TriMesh;

pub use atomic::{write_atomically, AtomicFile, FinishedFile};
pub use temporaries::remove_temporaries;

/// A mesh file format, chosen by the file's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum MeshFormat {
    /// Wavefront OBJ (`.obj`), text.
    Obj,
    /// Stanford PLY (`.ply`): ascii, binary little endian or binary big endian.
    Ply,
    /// glTF 2.0 as JSON (`.gltf`), with its buffers embedded as data URIs or in external files.
    Gltf,
    /// glTF 2.0 binary container (`.glb`).
    Glb,
    /// STL (`.stl`): binary or ascii; a triangle soup whose corners are welded by position.
    Stl,
    /// OFF (`.off`), text: CGAL's and geometry processing's plain format.
    Off,
}

impl MeshFormat {
    /// The format a file's extension names, compared case-insensitively (`.obj`, `.ply`,
    /// `.gltf`, `.glb`, `.stl`, `.off`).
    ///
    /// # Errors
    ///
    /// [`Error::UnsupportedFormat`] naming `path` when it has no extension or another one.
    pub fn from_path(path: &Path) -> Result<MeshFormat> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("obj") => Ok(MeshFormat::Obj),
            Some("ply") => Ok(MeshFormat::Ply),
            Some("gltf") => Ok(MeshFormat::Gltf),
            Some("glb") => Ok(MeshFormat::Glb),
            Some("stl") => Ok(MeshFormat::Stl),
            Some("off") => Ok(MeshFormat::Off),
            _ => Err(Error::UnsupportedFormat {
                path: path.to_path_buf(),
            }),
        }
    }

    /// The usual lower-case extension of the format, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            MeshFormat::Obj => "obj",
            MeshFormat::Ply => "ply",
            MeshFormat::Gltf => "gltf",
            MeshFormat::Glb => "glb",
            MeshFormat::Stl => "stl",
            MeshFormat::Off => "off",
        }
    }
}

/// What [`read_mesh`] found in a file and what its clean-up changed. All counts are plain
/// numbers of elements (no units).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct ReadStats {
    /// The format the file was read as.
    pub format: MeshFormat,
    /// Vertices in the file: OBJ `v` lines, the PLY `vertex` element count, or for glTF the sum
    /// of the POSITION accessor counts over every primitive instance placed in the scene.
    pub vertices_read: usize,
    /// Faces as the file stores them: OBJ `f` statements and PLY `face` elements with at least
    /// three corners (polygons count once each) plus the triangles of PLY `tristrips` (without
    /// the degenerate ones that stitch strips), or for glTF the triangles its triangle,
    /// strip and fan primitives describe.
    pub faces_read: usize,
    /// Faces with more than three corners, triangulated into `corners - 2` triangles each: by a
    /// constrained Delaunay triangulation in the polygon's best-fit plane, so that concave
    /// polygons are covered without overlap; a polygon that is not simple in that plane (a
    /// repeated corner, zero area, a boundary crossing itself) is fanned from its first corner
    /// (OBJ and PLY; always 0 for glTF).
    pub polygons_triangulated: usize,
    /// Vertices merged into another one at the same position: bit-identical, or within 1e-10 of
    /// the bounding box's diagonal and 1e-7 of the shortest edge at either
    /// ([`TriMesh::weld_close_positions`]).
    pub welded_vertices: usize,
    /// Vertices dropped because no triangle uses them
    /// ([`TriMesh::remove_unreferenced_vertices`]).
    pub unreferenced_vertices_removed: usize,
    /// glTF primitive instances skipped because they hold points or lines rather than
    /// triangles (always 0 for OBJ and PLY, whose point and line statements are ignored).
    pub skipped_primitives: usize,
}

impl ReadStats {
    fn new(format: MeshFormat) -> Self {
        ReadStats {
            format,
            vertices_read: 0,
            faces_read: 0,
            polygons_triangulated: 0,
            welded_vertices: 0,
            unreferenced_vertices_removed: 0,
            skipped_primitives: 0,
        }
    }
}

/// Reads a triangle mesh from an OBJ, PLY, glTF, GLB, STL or OFF file (format by extension), in
/// the file's units (glTF positions are placed by the scene's node transforms).
///
/// Polygons are triangulated in their best-fit plane (concave ones included, see
/// [`ReadStats::polygons_triangulated`]); points and lines are ignored. After parsing, the mesh is
/// checked (every index in range, every coordinate finite), vertices at the same position
/// (bit-identical, or within 1e-10 of the bounding box's diagonal and 1e-7 of the shortest edge at either,
/// as CAD exports repeat a seam's corners a rounding apart) are welded (triangles that collapse
/// are dropped) and vertices no triangle uses are removed; [`ReadStats`] reports what was found
/// and changed.
///
/// - OBJ: `v` and `f` statements (`f` corners as `v`, `v/vt`, `v//vn`, `v/vt/vn`, negative
///   indices relative to the vertices read so far). Vertices are shared by position index even
///   where texture or normal indices differ; all objects and groups are merged; materials are
///   not read, so a missing `.mtl` file does not matter. Coordinates are parsed as `f64`.
/// - PLY: ascii or binary of either byte order; element `vertex` with scalar properties `x`,
///   `y`, `z` of any type, element `face` with an integer list property `vertex_indices` (or
///   `vertex_index`), and/or element `tristrips` with such a list holding triangle strips
///   separated by -1 (alternating winding; degenerate stitching triangles left out). Other
///   elements and properties are ignored.
/// - glTF 2.0: the default scene (else the first scene; with no scene, every mesh
///   untransformed), nodes walked recursively with their world transforms applied (winding
///   reversed under a negative determinant), meshes instanced once per node using them.
///   Triangle, strip and fan primitives are read; point and line primitives are counted in
///   [`ReadStats::skipped_primitives`]. Buffers may be the GLB binary chunk, data URIs or
///   external files beside the `.gltf`. Images are not loaded.
/// - STL: binary (told by its length: 84 bytes and 50 per triangle, whatever the header says)
///   or ascii (`solid`); three vertices per triangle, welded by position as below; the stored
///   facet normals are ignored. Read with the `stl_io` crate.
/// - OFF: `OFF` (or `COFF`, `NOFF`, `CNOFF`), the counts, `x y z` per vertex and `k i1 … ik`
///   per face (0-based; extra values such as colours ignored); `#` comments.
///
/// # Errors
///
/// Every error names `path`:
/// - [`Error::UnsupportedFormat`] for an extension other than the six above;
/// - [`Error::Io`] when the file (or an external glTF buffer) cannot be read;
/// - [`Error::Parse`] when the content does not match the format (with the line, for OBJ and
///   ascii PLY header problems where known);
/// - [`Error::InvalidMesh`] for an index out of range (naming the face and the index), a
///   non-finite coordinate (naming the vertex), or a file with no triangles ("no faces").
pub fn read_mesh(path: &Path) -> Result<(TriMesh, ReadStats)> {
    let format = MeshFormat::from_path(path)?;
    check_content(path, format)?;
    let mut stats = ReadStats::new(format);
    let raw = match format {
        MeshFormat::Obj => obj::read(path, &mut stats)?,
        MeshFormat::Ply => ply::read(path, &mut stats)?,
        MeshFormat::Gltf | MeshFormat::Glb => gltf::read(path, &mut stats)?,
        MeshFormat::Stl => stl::read(path, &mut stats)?,
        MeshFormat::Off => off::read(path, &mut stats)?,
    };
    let mesh = finish(path, raw, &mut stats)?;
    Ok((mesh, stats))
}

/// The format a file's first bytes show, when they show one: `ply` for PLY, `glTF` for binary
/// glTF; `None` when the bytes are not conclusive (OBJ and glTF JSON have no magic).
fn sniff(head: &[u8]) -> Option<MeshFormat> {
    if head.starts_with(b"ply\n") || head.starts_with(b"ply\r\n") {
        Some(MeshFormat::Ply)
    } else if head.starts_with(b"glTF") {
        Some(MeshFormat::Glb)
    } else {
        None
    }
}

/// A file whose content is plainly another format than its extension names is an input error
/// naming both, instead of the parse error of the wrong reader.
fn check_content(path: &Path, format: MeshFormat) -> Result<()> {
    use std::io::Read;
    let mut head = [0u8; 8];
    let n = std::fs::File::open(path)
        .and_then(|mut f| f.read(&mut head))
        .map_err(|e| Error::io(path, e))?;
    let shown = sniff(&head[..n]);
    let name = |f: MeshFormat| match f {
        MeshFormat::Obj => "OBJ",
        MeshFormat::Ply => "PLY",
        MeshFormat::Gltf => "glTF (JSON)",
        MeshFormat::Glb => "binary glTF (.glb)",
        MeshFormat::Stl => "STL",
        MeshFormat::Off => "OFF",
    };
    let error = |message: String| {
        Err(Error::Parse {
            path: path.to_path_buf(),
            line: None,
            message,
        })
    };
    if n == 0 {
        return error("the file is empty".into());
    }
    match shown {
        Some(f) if f != format && !(f == MeshFormat::Glb && format == MeshFormat::Gltf) => {
            error(format!(
                "the content is {} (by its first bytes), not {} as the extension says",
                name(f),
                name(format)
            ))
        }
        None if format == MeshFormat::Ply => {
            error("not a PLY file (it does not start with the line `ply`)".into())
        }
        None if format == MeshFormat::Glb => {
            error("not a binary glTF file (it does not start with `glTF`)".into())
        }
        _ => Ok(()),
    }
}

/// Writes `mesh` to `path` in the format its extension names, in the mesh's own units, with
/// unit vertex normals from [`TriMesh::vertex_normals`] (a vertex whose normal is undefined, such
/// as an isolated vertex, gets +Z).
///
/// - `.obj`: a comment header, `v x y z` and `vn nx ny nz` lines with Rust's shortest
///   round-trip formatting of `f64` (reading the file back gives the same coordinates), and
///   `f a//a b//b c//c` faces (1-based).
/// - `.ply`: `binary_little_endian 1.0`, vertex `x y z` as `double` (exact) and `nx ny nz` as
///   `float`, face `list uchar int vertex_indices`.
/// - `.glb`: binary glTF 2.0 with one scene, one node, one mesh of one triangle primitive:
///   POSITION and NORMAL (`f32` VEC3) and `u32` indices. The node's `translation` is the
///   bounding box's centre (rounded to `f32`) and positions are stored relative to it, so large
///   coordinates (UTM, 5e6) keep the precision of the mesh's size.
/// - `.gltf`: the same glTF 2.0 asset as JSON, its buffer embedded as a base64 data URI.
/// - `.stl`: binary STL, corners as `f32`, each triangle with its unit normal.
/// - `.off`: OFF text with the shortest round-trip `f64` coordinates, `3 a b c` faces.
///
/// The file is written atomically ([`write_atomically`]): to a temporary file in the target's
/// directory, synced, then renamed onto the target, which an existing file is replaced by.
///
/// # Errors
///
/// - [`Error::UnsupportedFormat`] for another extension;
/// - [`Error::Write`] naming `path` when the mesh cannot be written as it is (an index out of
///   range, a non-finite coordinate, more than `u32::MAX` elements; for glTF, no triangles) or
///   the file cannot be written (missing directory, no permission, disk full, ...). Nothing is
///   left behind at the target or the temporary path when an error is returned.
pub fn write_mesh(path: &Path, mesh: &TriMesh) -> Result<()> {
    let format = MeshFormat::from_path(path)?;
    let bytes = encode_mesh(path, mesh, format)?;
    write_atomically(path, |w| w.write_all(&bytes))
}

/// The bytes [`write_mesh`] writes for `mesh` in `format`; `path` is only named in errors.
///
/// # Errors
/// [`Error::Write`] naming `path` when the mesh cannot be written as it is (see
/// [`write_mesh`]).
pub(crate) fn encode_mesh(path: &Path, mesh: &TriMesh, format: MeshFormat) -> Result<Vec<u8>> {
    let write_err = |message: String| Error::Write {
        path: path.to_path_buf(),
        message,
    };
    if let Some((f, i)) = mesh.check_indices() {
        return Err(write_err(format!(
            "triangle {f} names vertex {i}, but the mesh has {} vertices",
            mesh.positions.len()
        )));
    }
    if let Some(v) = mesh.first_non_finite_vertex() {
        return Err(write_err(format!(
            "vertex {v} has a non-finite coordinate {:?}",
            mesh.positions[v].to_array()
        )));
    }
    if u32::try_from(mesh.positions.len()).is_err() || i32::try_from(mesh.positions.len()).is_err()
    {
        return Err(write_err(format!(
            "too many vertices ({}) for a 32-bit index",
            mesh.positions.len()
        )));
    }
    let normals = output_normals(mesh);
    let bytes = match format {
        MeshFormat::Obj => obj::encode(mesh, &normals),
        MeshFormat::Ply => {
            ply::encode_mesh(mesh, &normals).map_err(|e| write_err(e.to_string()))?
        }
        MeshFormat::Glb => gltf::encode_glb(mesh, &normals).map_err(write_err)?,
        MeshFormat::Gltf => gltf::encode_gltf(mesh, &normals).map_err(write_err)?,
        MeshFormat::Stl => stl::encode(mesh).map_err(|e| write_err(e.to_string()))?,
        MeshFormat::Off => off::encode(mesh),
    };
    Ok(bytes)
}

/// `mesh` as [`write_mesh`] stores it in `format` and [`read_mesh`] reads it back (vertex and
/// triangle order kept, before welding): positions exactly as they are for OBJ (shortest
/// round-trip `f64` text) and PLY (`double`); for glTF (`f32` by the specification), each
/// position rounded to `f32` relative to the node translation the writer puts at the bounding
/// box's centre. Checking this mesh, rather than the one in memory, checks the file.
pub(crate) fn as_written(mesh: &TriMesh, format: MeshFormat) -> TriMesh {
    match format {
        MeshFormat::Obj | MeshFormat::Ply | MeshFormat::Off => mesh.clone(),
        MeshFormat::Gltf | MeshFormat::Glb => gltf::as_written(mesh),
        MeshFormat::Stl => stl::as_written(mesh),
    }
}

/// Unit vertex normals for output: [`TriMesh::vertex_normals`], with +Z where that is zero.
fn output_normals(mesh: &TriMesh) -> Vec<DVec3> {
    mesh.vertex_normals()
        .into_iter()
        .map(|n| {
            if n.is_finite() && n.length_squared() > 0.5 {
                n
            } else {
                DVec3::Z
            }
        })
        .collect()
}

/// The checks and clean-up every reader shares, on the mesh as parsed (indices as in the file,
/// before any welding). The readers check their indices themselves first where they can name
/// the face better (OBJ line, PLY face element, glTF primitive); this is the catch-all.
fn finish(path: &Path, mut mesh: TriMesh, stats: &mut ReadStats) -> Result<TriMesh> {
    if mesh.triangles.is_empty() {
        // A file of nothing at all (a PLY of `element vertex 0`) is not a mesh that lacks faces.
        let what = if mesh.positions.is_empty() {
            "no vertices: the file holds no points and no faces"
        } else {
            "no faces"
        };
        return Err(Error::invalid_mesh(path, what));
    }
    if u32::try_from(mesh.positions.len()).is_err() {
        return Err(Error::invalid_mesh(
            path,
            format!(
                "too many vertices ({}) for 32-bit indices",
                mesh.positions.len()
            ),
        ));
    }
    if let Some((f, i)) = mesh.check_indices() {
        return Err(Error::invalid_mesh(
            path,
            format!(
                "triangle {f} names vertex index {i} (0-based), but there are only {} vertices",
                mesh.positions.len()
            ),
        ));
    }
    if let Some(v) = mesh.first_non_finite_vertex() {
        return Err(Error::invalid_mesh(
            path,
            format!(
                "vertex {v} (0-based) has a non-finite coordinate {:?}",
                mesh.positions[v].to_array()
            ),
        ));
    }
    stats.welded_vertices = mesh.weld_close_positions(weld_tolerance(&mesh), WELD_EDGE_RELATIVE);
    stats.unreferenced_vertices_removed = mesh.remove_unreferenced_vertices();
    if mesh.triangles.is_empty() {
        return Err(Error::invalid_mesh(
            path,
            "no faces (every triangle is degenerate: it repeats a vertex)",
        ));
    }
    Ok(mesh)
}

/// The checks and clean-up [`read_mesh`] gives a file's mesh after parsing it (faces present,
/// indices in range, finite coordinates; positions within a rounding welded, unreferenced vertices
/// removed), for a mesh made in memory; `label` names it in errors where a file's path would.
/// Returns the mesh and how many vertices were welded.
pub(crate) fn check_and_clean(label: &Path, mesh: TriMesh) -> Result<(TriMesh, usize)> {
    let mut stats = ReadStats::new(MeshFormat::Ply);
    let mesh = finish(label, mesh, &mut stats)?;
    Ok((mesh, stats.welded_vertices))
}

/// The distance within which [`read_mesh`] welds two vertices (model units): [`WELD_RELATIVE`]
/// of the diagonal of the bounding box of the vertices the triangles use; zero for a mesh
/// without triangles. The weld also keeps within [`WELD_EDGE_RELATIVE`] of the edges at them.
fn weld_tolerance(mesh: &TriMesh) -> f64 {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for &i in mesh.triangles.iter().flatten() {
        let p = mesh.positions[i as usize];
        (lo, hi) = (lo.min(p), hi.max(p));
    }
    if lo.x > hi.x {
        return 0.0;
    }
    // The diagonal without squaring the sides (at 1e-200 their squares underflow to 0).
    let d = hi - lo;
    let m = d.abs().max_element();
    if !(m > 0.0 && m.is_finite()) {
        return 0.0;
    }
    WELD_RELATIVE * m * (d / m).length()
}

/// Reads a whole file, mapping failure to [`Error::Io`] naming `path`.
fn read_file(path: &Path) -> Result<Vec<u8>> {
    fs::read(path).map_err(|e| Error::io(path, e))
}

/// Collapses a third-party error message onto one line and bounds its length (some parsers
/// quote whole input lines, which may be arbitrary bytes).
fn one_line(message: &str) -> String {
    const MAX: usize = 300;
    let mut out = String::with_capacity(message.len().min(MAX + 3));
    let mut last_space = false;
    for c in message.chars() {
        let c = if c.is_whitespace() || c.is_control() {
            ' '
        } else {
            c
        };
        if c == ' ' && (last_space || out.is_empty()) {
            continue;
        }
        last_space = c == ' ';
        if out.len() + c.len_utf8() > MAX {
            out.push_str("...");
            return out;
        }
        out.push(c);
    }
    out.trim_end().to_string()
}
