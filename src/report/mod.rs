//! The quality report: the triangle measures of the paper's Table 1, topology, invariants, and
//! distance to the input surface.
//!
//! This module is the project's one ruler: the `remesh` binary prints its [`QualityReport`], and
//! the evaluation harness measures every remesher (ours and the ones we compare with) with the
//! same functions. Every measure is defined in the docs of the item that computes it, with its
//! units and its source.
//!
//! | measure | function | source |
//! |---|---|---|
//! | θmin, θmin,ave, Qmin, Qave, %θ<30 | [`triangle_quality`] | Öztireli et al. 2010, Sec. 7.1 and Table 1, after Yan et al. 2009 and Valette et al. 2008 |
//! | P30 (share of angles below 30°) | [`triangle_quality`] | the tables of Yan et al. 2009 and ACVD (Valette et al. 2008) |
//! | counts, χ, genus, boundary loops, manifoldness, orientation | [`topology`](crate::check::topology) | standard combinatorial topology (e.g. Botsch et al. 2010, *Polygon Mesh Processing*, Ch. 1) |
//! | Hausdorff, RMS and mean distance | [`surface_distance`] | Metro (Cignoni, Rocchini, Scopigno 1998), as used for Table 2 of the paper |
//! | invariants every triangulation must keep | [`check_invariants`](crate::check::check_invariants) | this project (STYLE.md, practice 7) |
//!
//! # Determinism
//! Every function here returns the same numbers for the same input on every run and every thread
//! count: reductions run sequentially in index order, random samples come from a seeded ChaCha8
//! stream, and no output depends on hash-map iteration order.
//!
//! # References
//! - A. C. Öztireli, M. Alexa, M. Gross. *Spectral Sampling of Manifolds*. ACM Trans. Graph.
//!   29(6), 2010 (SIGGRAPH Asia). doi:10.1145/1882261.1866190. Sec. 7.1, Tables 1 and 2.
//! - D.-M. Yan, B. Lévy, Y. Liu, F. Sun, W. Wang. *Isotropic Remeshing with Fast and Exact
//!   Computation of Restricted Voronoi Diagram*. Computer Graphics Forum 28(5), 2009 (SGP).
//!   The paper's "YR".
//! - S. Valette, J.-M. Chassery, R. Prost. *Generic Remeshing of 3D Triangular Meshes with
//!   Metric-Dependent Discrete Voronoi Diagrams*. IEEE TVCG 14(2), 2008. The paper's "VR"
//!   (ACVD).
//! - P. J. Frey, H. Borouchaki. *Surface mesh quality evaluation*. Int. J. Numer. Meth. Engng
//!   45, 1999 (shape measures of the kind `S / (p h)`).
//! - P. Cignoni, C. Rocchini, R. Scopigno. *Metro: Measuring Error on Simplified Surfaces*.
//!   Computer Graphics Forum 17(2), 1998 (the paper cites the Metro tool as
//!   \[Cignoni et al. 2001\]).
//!
//! The paper's text of Sec. 7.1 for Table 1: "θmin is the smallest angle in the mesh, θmin,ave
//! is the average of minimum angles of all triangles, and θ < 30° is the percentage of triangles
//! with minimum angle below 30°. Q denotes quality of a triangle and measured as
//! 6 S_t / (√3 p_t h_t), where S_t is the area of the triangle t, p_t is its half-perimeter, and
//! h_t is the length of the longest edge. Qmin and Qave are the minimum and average of Q's of
//! all triangles in the mesh."

mod distance;
mod quality_report;
mod triangle_quality;

pub use distance::{surface_distance, surface_distance_with, surface_samples, SurfaceDistance};
pub use quality_report::{QualityReport, StageTime};
pub use triangle_quality::{triangle_quality, TriangleQuality};
