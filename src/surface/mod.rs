//! The input surface the samples live on, and projection onto it.

pub mod mesh_projection;

pub use mesh_projection::{MeshSurface, SurfacePoint};
