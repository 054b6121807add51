//! # spectral-remesh
//!
//! Spectral sampling and remeshing of triangle meshes, after *Spectral Sampling of Manifolds*
//! (A. C. Öztireli, M. Alexa, M. Gross, ACM Trans. Graph. 29(6), SIGGRAPH Asia 2010,
//! doi:10.1145/1882261.1866190).
//!
//! The pipeline (see `ARCHITECTURE.md`): read → normalize (bbox 100) → candidates → linear scan →
//! gradient ascent + projection → triangulate → clean up → report → write.

#![warn(missing_docs)]
#![deny(rustdoc::broken_intra_doc_links)]

pub mod app;
pub mod check;
pub mod error;
pub mod geometry;
pub mod io;
pub mod kernel;
pub mod measure;
pub mod mesh;
pub mod pipeline;
pub mod points;
pub mod report;
pub mod sampling;
pub mod spatial;
pub mod surface;
pub mod timing;
pub mod triangulate;

pub use error::{Error, Result};
pub use mesh::{Aabb, Normalization, TriMesh};
pub use surface::{MeshSurface, SurfacePoint};
