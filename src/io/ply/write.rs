//! The binary little-endian PLY writer behind every PLY file the crate writes: meshes
//! ([`encode_mesh`]) and streamed point sets (`points::PlyPointWriter`).

use std::io::{Error as IoError, ErrorKind, Write};

use glam::{DVec3, Vec3};
use ply_rs_bw::ply::{
    Addable, DefaultElement, ElementDef, Encoding, Header, PropertyDef, PropertyType, ScalarType,
};
use ply_rs_bw::writer::Writer;

use crate::mesh::TriMesh;

/// Writes binary little-endian PLY 1.0 to `W`: the header (by `ply-rs-bw`), then `vertices`
/// vertex records `x y z` (`double`) and `nx ny nz` (`float`), 36 bytes, with, when asked for,
/// a `uchar level` (37 bytes), then `faces` triangles as `list uchar int vertex_indices` (13 bytes each).
/// [`BinaryPlyWriter::finish`] checks that exactly the announced counts were written.
pub(crate) struct BinaryPlyWriter<W: Write> {
    out: W,
    vertices: u64,
    faces: u64,
    with_levels: bool,
    vertices_written: u64,
    faces_written: u64,
}

impl<W: Write> BinaryPlyWriter<W> {
    /// Writes the header to `out`: one `comment` line (no line breaks), element `vertex` with
    /// `vertices` records (and a `uchar level` property when `with_levels`), and element `face`
    /// with `faces` records when `faces` is `Some` (no face element when `None`).
    ///
    /// # Errors
    /// The errors of `out`.
    pub(crate) fn new(
        mut out: W,
        comment: &str,
        vertices: u64,
        with_levels: bool,
        faces: Option<u64>,
    ) -> std::io::Result<Self> {
        let count = |n: u64| {
            usize::try_from(n)
                .map_err(|_| IoError::new(ErrorKind::InvalidInput, format!("{n} is too many")))
        };
        let mut header = Header::new();
        header.encoding = Encoding::BinaryLittleEndian;
        header.comments.push(comment.to_string());
        let mut vertex = ElementDef::new("vertex".to_string());
        vertex.count = count(vertices)?;
        // Positions as `double`: scans and LiDAR live at coordinates (UTM: 5e5, 5e6) where
        // `float` keeps a few centimetres at best; unit normals lose nothing as `float`.
        for (name, ty) in [
            ("x", ScalarType::Double),
            ("y", ScalarType::Double),
            ("z", ScalarType::Double),
            ("nx", ScalarType::Float),
            ("ny", ScalarType::Float),
            ("nz", ScalarType::Float),
        ] {
            vertex
                .properties
                .add(PropertyDef::new(name.to_string(), PropertyType::Scalar(ty)));
        }
        if with_levels {
            let uchar = PropertyType::Scalar(ScalarType::UChar);
            vertex
                .properties
                .add(PropertyDef::new("level".to_string(), uchar));
        }
        header.elements.add(vertex);
        if let Some(faces) = faces {
            let mut face = ElementDef::new("face".to_string());
            face.count = count(faces)?;
            let list = PropertyType::List(ScalarType::UChar, ScalarType::Int);
            face.properties
                .add(PropertyDef::new("vertex_indices".to_string(), list));
            header.elements.add(face);
        }
        Writer::<DefaultElement>::new().write_header(&mut out, &header)?;
        Ok(BinaryPlyWriter {
            out,
            vertices,
            faces: faces.unwrap_or(0),
            with_levels,
            vertices_written: 0,
            faces_written: 0,
        })
    }

    /// Appends one vertex record; `level` must be given exactly when the file has levels.
    ///
    /// # Errors
    /// The errors of the output; [`ErrorKind::InvalidInput`] for a vertex past the announced
    /// count or a level where the file has none (or none where it has them).
    pub(crate) fn vertex(
        &mut self,
        position: [f64; 3],
        normal: [f32; 3],
        level: Option<u8>,
    ) -> std::io::Result<()> {
        if self.vertices_written == self.vertices {
            return Err(invalid(format!(
                "more than the {} vertices announced",
                self.vertices
            )));
        }
        if level.is_some() != self.with_levels {
            return Err(invalid(if self.with_levels {
                "the file has levels: each vertex needs one".to_string()
            } else {
                "the file has no levels".to_string()
            }));
        }
        let mut record = [0u8; 37];
        for (k, c) in position.into_iter().enumerate() {
            record[8 * k..8 * k + 8].copy_from_slice(&c.to_le_bytes());
        }
        for (k, c) in normal.into_iter().enumerate() {
            record[24 + 4 * k..28 + 4 * k].copy_from_slice(&c.to_le_bytes());
        }
        let len = match level {
            Some(l) => {
                record[36] = l;
                37
            }
            None => 36,
        };
        self.out.write_all(&record[..len])?;
        self.vertices_written += 1;
        Ok(())
    }

    /// Appends one triangle (after every vertex).
    ///
    /// # Errors
    /// The errors of the output; [`ErrorKind::InvalidInput`] before the last vertex or past the
    /// announced count of faces.
    pub(crate) fn triangle(&mut self, corners: [i32; 3]) -> std::io::Result<()> {
        if self.vertices_written != self.vertices {
            return Err(invalid(format!(
                "a face after {} of the {} vertices",
                self.vertices_written, self.vertices
            )));
        }
        if self.faces_written == self.faces {
            return Err(invalid(format!(
                "more than the {} faces announced",
                self.faces
            )));
        }
        let mut record = [3u8; 13];
        for (k, i) in corners.into_iter().enumerate() {
            record[1 + 4 * k..5 + 4 * k].copy_from_slice(&i.to_le_bytes());
        }
        self.out.write_all(&record)?;
        self.faces_written += 1;
        Ok(())
    }

    /// The output, for its own errors and state.
    pub(crate) fn get_ref(&self) -> &W {
        &self.out
    }

    /// Checks the counts and hands back the output (not flushed: the caller completes it).
    ///
    /// # Errors
    /// [`ErrorKind::InvalidInput`] when fewer vertices or faces than announced were written.
    pub(crate) fn finish(self) -> std::io::Result<W> {
        if self.vertices_written != self.vertices || self.faces_written != self.faces {
            return Err(invalid(format!(
                "{} vertices and {} faces written of the {} and {} announced",
                self.vertices_written, self.faces_written, self.vertices, self.faces
            )));
        }
        Ok(self.out)
    }
}

fn invalid(message: String) -> IoError {
    IoError::new(ErrorKind::InvalidInput, message)
}

/// The binary little-endian PLY bytes of `mesh` with `normals`: vertex `x y z` as `double`
/// (exact), `nx ny nz` as `float` (normals renormalized in `f32`, +Z where that fails), face
/// `list uchar int vertex_indices`. The caller has checked that vertex indices fit in `i32`.
///
/// # Errors
/// Only when `normals` and the vertices differ in number.
pub(crate) fn encode_mesh(mesh: &TriMesh, normals: &[DVec3]) -> std::io::Result<Vec<u8>> {
    let (v, f) = (mesh.positions.len(), mesh.triangles.len());
    let mut out = BinaryPlyWriter::new(
        Vec::with_capacity(512 + v * 36 + f * 13),
        &format!("written by spectral-remesh {}", env!("CARGO_PKG_VERSION")),
        v as u64,
        false,
        Some(f as u64),
    )?;
    for (p, n) in mesh.positions.iter().zip(normals) {
        let n = n.as_vec3().normalize_or(Vec3::Z);
        out.vertex(p.to_array(), n.to_array(), None)?;
    }
    for t in &mesh.triangles {
        out.triangle(t.map(|i| i as i32))?;
    }
    out.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_and_records_have_the_announced_layout() {
        let mut w = BinaryPlyWriter::new(Vec::new(), "c", 2, true, Some(1)).unwrap();
        w.vertex([1.0, 2.0, 3.0], [0.0, 0.0, 1.0], Some(1)).unwrap();
        assert!(
            w.triangle([0, 1, 0]).is_err(),
            "a face before the last vertex"
        );
        assert!(
            w.vertex([0.0; 3], [0.0; 3], None).is_err(),
            "a vertex without level"
        );
        w.vertex([4.0, 5.0, 6.0], [1.0, 0.0, 0.0], Some(2)).unwrap();
        assert!(
            w.vertex([0.0; 3], [0.0; 3], Some(3)).is_err(),
            "one vertex too many"
        );
        w.triangle([0, 1, 1]).unwrap();
        let bytes = w.finish().unwrap();
        let header = "ply\nformat binary_little_endian 1.0\ncomment c\nelement vertex 2\n\
                      property double x\nproperty double y\nproperty double z\n\
                      property float nx\nproperty float ny\nproperty float nz\n\
                      property uchar level\nelement face 1\n\
                      property list uchar int vertex_indices\nend_header\n";
        assert_eq!(&bytes[..header.len()], header.as_bytes());
        let body = &bytes[header.len()..];
        assert_eq!(body.len(), 2 * 37 + 13);
        assert_eq!(body[8..16], 2.0f64.to_le_bytes());
        assert_eq!(body[32..36], 1.0f32.to_le_bytes());
        assert_eq!((body[36], body[73]), (1, 2));
        assert_eq!(body[74..79], [3, 0, 0, 0, 0]);
    }

    #[test]
    fn too_few_records_are_an_error() {
        let mut w = BinaryPlyWriter::new(Vec::new(), "c", 2, false, None).unwrap();
        w.vertex([0.0; 3], [0.0; 3], None).unwrap();
        assert!(w.finish().is_err());
    }
}
