//! The finishing stage: the local operators that take the triangulated samples (from
//! [`crate::triangulate`]) to the mesh that is written, each editing one mesh against the surface
//! the samples came from. One file (or directory) per operator:
//!
//! - [`optimize`]: the local optimization against that surface: cover (`cover.rs`), collapse
//!   (`collapse.rs`), max-min flips and relaxation (`relax.rs`), tangential relaxation with
//!   valence flips (`smooth.rs`), and the last pass on the faces still below the angle bound or
//!   crossing another (`angles.rs`; `mend_near` runs it again after the untangling);
//! - [`fit`]: the least-squares fit of the vertices to the surface, along their normals;
//! - [`untangle`]: faces that cross each other moved apart;
//! - [`refine`]: where faces still cross, their edges split at the surface (then untangle again);
//! - [`degenerate`]: faces of no area mended;
//! - [`stray_shells`]: the tiny closed shells left at unresolved tips removed;
//! - [`crossing_faces`]: on an open output (a point set's), the faces that still cross removed.
//!
//! `pipeline/finish.rs` runs them in that order, for meshes and point sets alike. The flips they
//! share with the triangulation's clean-up are `triangulate/flip.rs`.

pub mod crossing_faces;
pub mod degenerate;
pub mod fit;
pub mod optimize;
pub mod refine;
pub mod stray_shells;
pub mod untangle;
