//! Triangle meshes: the indexed mesh the pipeline passes between its stages ([`TriMesh`], with
//! the bounding-box normalization of Sec. 7 of the paper), and the editable mesh with the local
//! operators that the triangulation stage works on ([`edit::EditMesh`]); the consistent
//! orientation of an input ([`orient_consistently`]).

pub mod bisect;
pub(crate) mod crossing_guard;
pub mod edit;
mod orient;
pub(crate) mod parts;
pub mod sheets;
pub mod topology;
mod trimesh;

pub use orient::{orient_consistently, OrientStats};
#[cfg(test)]
pub(crate) use trimesh::test_meshes;
pub use trimesh::{Aabb, FaceCleanup, Normalization, TriMesh};
