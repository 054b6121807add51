//! Triangle meshes: the indexed mesh the pipeline passes between its stages ([`TriMesh`], with
//! the bounding-box normalization of Sec. 7 of the paper), and the editable mesh with the local
//! operators that the triangulation stage works on ([`edit::EditMesh`]).

pub mod edit;
mod trimesh;

#[cfg(test)]
pub(crate) use trimesh::test_meshes;
pub use trimesh::{Aabb, Normalization, TriMesh};
