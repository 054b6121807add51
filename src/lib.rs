//! # spectral-remesh
//!
//! Spectral sampling and remeshing of triangle meshes and point sets, after *Spectral Sampling
//! of Manifolds* (Öztireli, Alexa, Gross 2010): the samples are placed by the spectral measure
//! s(x) of a Gaussian kernel over positions and normals, then triangulated.
//!
//! # The pipeline
//!
//! [`remesh`] runs the whole of it on a mesh in memory; [`run_remesh`] adds reading, writing and
//! the report, as the `remesh` command line does. The stages, each a module of the crate
//! (ARCHITECTURE.md draws the map; they are reachable for the crate's own tools through the
//! hidden module `internal`, which may change without notice):
//!
//! ```text
//! read_mesh                      OBJ, PLY, glTF, STL, OFF → TriMesh (model units)
//!   │
//! validate_input, Normalization  → bbox 100 (every length below in bbox-100 units)
//!   │
//! orient_consistently            faces oriented consistently (and, on the output, closed
//!                                parts turned outward)
//!   │
//! surface_candidates             area-uniform random candidates on the input (MeshSurface)
//!   + sample_boundary            samples on the boundary curves, kept fixed
//!   │
//! linear_scan                    keep a candidate when s(x) > epsilon (Sec. 6.1, eq. 10);
//!   (find_sigma_p)               sigma_p searched for a target count (Sec. 6.3)
//!   │
//! gradient_ascent                move each sample up the gradient of s, projected back onto
//!   │                            the input (Sec. 6.2, eq. 11; Projection)
//!   │
//! triangulate                    the restricted Delaunay triangulation of the samples' cells
//!   (restricted_delaunay,        on the input, the topological ball property checked (or
//!    topological_ball)           tangent-plane umbrellas merged by votes, for point sets),
//!                                then cleaned up into a manifold mesh (holes filled, flips)
//!   │
//! optimize                       local operations against the input surface (cover, collapse,
//!   │                            flip, relax)
//! untangle                       move apart faces that still cross
//!   (refine)                     where the output's own crossings are left: their faces'
//!   │                            edges split at the surface, untangle again, in rounds
//! check_invariants, topology,    manifold, oriented, no degenerate or duplicate face; counts;
//!   self_intersections           crossing faces
//!   │
//! QualityReport                  Table 1's triangle measures (triangle_quality), Hausdorff and
//!   │                            RMS distance to the input (surface_distance), stage times
//! write_mesh, write_report       back to model units, written atomically
//! ```
//!
//! Point sets take a second path: [`remesh_points`] meshes a scan (out of core, on the RIMLS
//! surface of its points), [`simplify_out_of_core`] subsamples one with the randomized linear
//! scan in buckets (Sec. 6.4), and [`sample_manifold`] and [`resample_manifold`] sample point sets
//! near a manifold of any dimension in R^d.
//!
//! # Example
//!
//! Remesh a sphere to about 300 vertices and check the result:
//!
//! ```
//! use spectral_remesh::{check_invariants, remesh, topology, Density, RemeshParams, TriMesh};
//!
//! // An octahedron subdivided three times and pushed onto the unit sphere.
//! let mut mesh = TriMesh::new(
//!     vec![
//!         [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0],
//!         [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0],
//!     ]
//!     .into_iter()
//!     .map(glam::DVec3::from)
//!     .collect(),
//!     vec![
//!         [0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
//!         [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5],
//!     ],
//! );
//! for _ in 0..3 {
//!     let mut faces = Vec::new();
//!     for [a, b, c] in mesh.triangles.clone() {
//!         let mut mid = |u: u32, v: u32| {
//!             let p = (mesh.positions[u as usize] + mesh.positions[v as usize]).normalize();
//!             mesh.positions.push(p);
//!             (mesh.positions.len() - 1) as u32
//!         };
//!         let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
//!         faces.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
//!     }
//!     mesh.triangles = faces;
//! }
//! // Midpoints were added once per face: weld the copies.
//! mesh.weld_identical_positions();
//!
//! let params = RemeshParams {
//!     density: Density::Points(300),
//!     ..RemeshParams::default()
//! };
//! let output = remesh(&mesh, &params, &|_stage| {})?;
//! assert!(check_invariants(&output.mesh).is_empty());
//! let t = topology(&output.mesh);
//! assert!(t.is_closed_manifold());
//! assert_eq!(t.euler_characteristic, 2);
//! assert!((output.mesh.vertex_count() as f64 - 300.0).abs() <= 3.0);
//! # Ok::<(), spectral_remesh::Error>(())
//! ```
//!
//! # Units
//!
//! Meshes are read and written in their own (model) units; the pipeline works in bbox-100 units
//! (the input scaled so that its bounding box's longest side is 100, `Normalization`). Lengths
//! given relative to the kernel width sigma_p say so in their name (`*_sigma_p`); kernel-space
//! quantities (a support radius of 2.5, the ascent's step) are in kernel units, x =
//! [p/sigma_p, n/sigma_n] (the `Kernel`).
//!
//! # References
//!
//! A. C. Öztireli, M. Alexa, M. Gross. *Spectral Sampling of Manifolds*. ACM Trans. Graph. 29(6),
//! 2010 (SIGGRAPH Asia). doi:10.1145/1882261.1866190. Section and equation numbers in these docs
//! are the paper's.

#![warn(missing_docs)]
#![deny(rustdoc::broken_intra_doc_links)]

mod app;
mod check;
mod disjoint_sets;
mod error;
mod finish;
#[doc(hidden)]
pub mod geometry;
mod io;
mod kernel;
#[doc(hidden)]
pub mod manifold;
mod measure;
mod mesh;
mod pipeline;
mod points;
mod report;
mod sampling;
mod spatial;
mod surface;
mod timing;
mod triangulate;

// The public API: the calls a user makes. Everything else (the stages one by one, their
// parameters and constants) is in the hidden module `internal`, for the binary, the Python
// module, the experiments crate, the tests and the benchmarks.

// Errors: one enum for the whole crate.
pub use error::{Error, Result};
// Meshes: reading and writing (OBJ, PLY, glTF, STL, OFF), atomically.
pub use io::{read_mesh, write_mesh, MeshFormat, ReadStats};
pub use mesh::TriMesh;
// The pipeline in one call, and the jobs of the command line (files in, files and report out).
pub use app::{remesh_mesh, run_remesh, RemeshJob, RemeshOptions, RemeshedMesh};
pub use pipeline::{remesh, Density, FeatureStats, RemeshOutput, RemeshParams};
pub use timing::Stage;
// The report on any mesh: Table 1's triangle measures, Metro-style distances, topology,
// invariants.
pub use app::{quality_mesh, run_quality};
pub use check::{check_invariants, topology, Topology, Violation};
pub use report::{QualityReport, SurfaceDistance, TriangleQuality};
// Point sets: a scan to a mesh, and the out-of-core linear scan.
pub use app::remesh_point_set;
pub use pipeline::points::{remesh_points, PointRemeshOutput, PointRemeshParams, OPEN_GAP_SIGMA_P};
pub use points::out_of_core::{simplify_out_of_core, OutOfCoreParams, OutOfCoreResult};
pub use points::source::PointSource;
// Point sets near a manifold of any dimension in R^d: the linear scan and the gradient ascent.
pub use manifold::{
    resample_manifold, sample_manifold, DataProjection, ManifoldProjection, ManifoldResampleParams,
    ManifoldSampleParams, ManifoldSampling, PointSet,
};

/// The crate's internals: every stage on its own, with its parameters and constants, for the
/// `remesh` binary, the Python module, the experiments crate, the tests and the benchmarks. Not
/// part of the public API: it may change without notice.
#[doc(hidden)]
pub mod internal {
    // Errors: one enum for the whole crate.
    pub use crate::error::{Error, Result};

    // Reading and writing meshes (OBJ, PLY, glTF, STL, OFF), atomically.
    pub use crate::io::{
        read_mesh, remove_temporaries, write_atomically, write_mesh, AtomicFile, FinishedFile,
        MeshFormat, ReadStats,
    };

    // The meshes: the indexed triangle mesh, its normalization to bbox 100, its consistent
    // orientation, and the editable directed-edge mesh with its local operators.
    pub use crate::mesh::edit::{EditError, EditMesh, EditViolation, SlotPolicy};
    pub use crate::mesh::{
        orient_consistently, Aabb, FaceCleanup, Normalization, OrientStats, TriMesh,
    };

    // The pipeline in one call.
    pub use crate::pipeline::{
        remesh, validate_input, Density, FeatureStats, RemeshOutput, RemeshParams,
        BOUNDARY_SPACING_PER_SIGMA, FIT_ITERATIONS, MAX_POINTS, SAMPLES_PER_SIGMA2,
    };
    pub use crate::timing::Stage;

    // The input surface: closest points, projection, and the test for its self-buried parts.
    pub use crate::surface::winding::BuriedTest;

    // The local feature size of the input (shrinking medial balls), for a graded kernel width.
    pub use crate::surface::local_feature_size::{
        local_feature_size, LfsParams, LocalFeatureSize, MAX_LFS_SAMPLES,
    };
    // Sharp features of the input: crease edges, curves and corners.
    pub use crate::sampling::crease_band::{CreaseBand, CREASE_BAND_PER_SPACING};
    pub use crate::surface::curvature::{
        Curvature, CurvatureParams, CurvatureWidths, CAD_CHORD_ERROR, CURVATURE_GRADATION,
        CURVATURE_MAX_BEND_DEG,
    };
    pub use crate::surface::features::{
        detect_features, junction_curve_share, long_curve_share, FeatureCurve, FeatureDetection,
        FeatureParams, Features, AUTO_FEATURE_MIN_SHARE, CAD_FEATURE_ANGLE_DEG, GAP_ANGLE_DEG,
        LONG_CURVE_SPACINGS, MAX_CREASE_DENSITY, MAX_GAP_RATIO,
    };
    pub use crate::surface::{MeshSurface, Projection, SurfacePoint, SurfaceQuery, SurfaceSample};

    // Sampling stages: candidates and boundary samples, the linear scan (and the sigma_p search for
    // a count), the gradient ascent.
    pub use crate::sampling::boundary::{
        boundary_curves, sample_boundary, BoundaryCurve, BoundarySamples,
    };
    pub use crate::sampling::gradient_ascent::{
        gradient_ascent, GradientAscentParams, GradientAscentResult,
    };
    pub use crate::sampling::grading::{
        GradedRegion, Grading, GradingParams, GradingStats, MAX_GAP_LOOPS,
    };
    pub use crate::sampling::linear_scan::{
        linear_scan, LinearScanParams, LinearScanResult, LinearScanner,
    };
    pub use crate::sampling::sizing::{SizingField, Smallest, Uniform};
    pub use crate::sampling::target_count::{find_sigma_p, TargetCountParams, TargetCountResult};
    pub use crate::surface::candidates::surface_candidates;

    // Triangulation stages: local Delaunay umbrellas and votes, assembly and clean-up, the faces
    // without support removed.
    pub use crate::triangulate::unsupported::{remove_unsupported_faces, UnsupportedFaces};
    pub use crate::triangulate::{
        assemble, triangulate, triangulate_restricted, vote_triangles, AssemblyParams,
        AssemblyStats, FaceSource, RefineParams, RestrictedDelaunayParams, RestrictedDelaunayStats,
        SampleSet, TangentDelaunayParams, TriangulateParams, TriangulationMethod, VotedTriangle,
    };

    // The finishing stage: the local optimization against the input, the fit, the separation of
    // crossing faces, the stray shells.
    pub use crate::finish::fit::{fit_to_surface, FitStats, FIT_MAX_SHIFT};
    pub use crate::finish::optimize::{
        optimize, FacesLeft, MendStats, OptimizeParams, OptimizeStats, SmoothStats,
        SMOOTH_ITERATIONS,
    };
    pub use crate::finish::refine::{refine_faces, RefineCrossingsParams, RefineCrossingsStats};
    pub use crate::finish::stray_shells::StrayShells;
    pub use crate::finish::untangle::{untangle, UntangleParams, UntangleStats};
    pub use crate::geometry::crossing_curve::CrossingCurve;
    pub use crate::geometry::triangle::AngleBounds;

    // The kernel and the spectral measure (Sec. 3, 4.3, 6.1, 6.2).
    pub use crate::kernel::{GaussianKernel, Kernel, KernelPoint, UnitKernel, SUPPORT_RADIUS};
    pub use crate::measure::{
        measure_and_gradient, projection_coefficients, spectral_measure, IncrementalInverse,
        Measure, MeasureWorkspace, Push, DEFAULT_EPSILON,
    };

    // kd-trees: over fixed 3D points (neighbourhoods of the measure), and over points of R^K.
    pub use crate::spatial::{DynamicKdTree, StaticKdTree, StaticTree};

    // Point sets near a manifold of any dimension in R^d: the linear scan and the gradient ascent.
    pub use crate::manifold::{
        estimate_dimension, resample_manifold, sample_manifold, DataProjection, ManifoldProjection,
        ManifoldResampleParams, ManifoldSampleParams, ManifoldSampling, PointSet,
        MANIFOLD_ASCENT_STEP,
    };

    // Checks of a mesh: invariants (typed violations), topology, self-intersections, the distance
    // from creases to the output's edges.
    pub use crate::check::{
        check_invariants, crease_distance, self_intersections, surface_topology, topology,
        topology_changes, CreaseDistance, SelfIntersections, Topology, TopologyChange, Violation,
    };

    // The quality report: Table 1's triangle measures, Metro-style distances, stage times.
    pub use crate::report::{
        surface_distance, surface_distance_with, surface_samples, triangle_quality,
        PointSetDistance, QualityReport, StageTime, SurfaceDistance, TriangleQuality,
    };

    // Point sets: streaming reading and writing, points drawn from a mesh, normal estimation, the
    // out-of-core linear scan, the RIMLS surface.
    pub use crate::points::generate::{
        surface_points, surface_points_with, write_surface_points, NormalField,
    };
    pub use crate::points::normals::{estimate_normals, NormalOrientation};
    pub use crate::points::out_of_core::{
        simplify_out_of_core, simplify_progressive, OutOfCoreParams, OutOfCoreResult,
        ProgressiveResult,
    };
    pub use crate::points::outliers::OutlierFilter;
    pub use crate::points::rimls::{Rimls, RimlsParams, RimlsProjection};

    // Point sets in, meshes out (issue 19).
    pub use crate::pipeline::points::{
        is_point_set, remesh_points, rimls_params, PointRemeshOutput, PointRemeshParams,
        DOMAIN_GAP_SIGMA_P, MAX_SCANS, MAX_SURFACE_VARIATION, OPEN_GAP_SIGMA_P,
        RIMLS_POINTS_PER_SAMPLE,
    };
    pub use crate::points::source::{InputSize, ReadPoints};
    pub use crate::points::{PlyPointWriter, Point, PointReader};

    // The jobs of the `remesh` command line: files in, files and report out.
    pub use crate::app::{
        catch_panics, check_report_path, effective_memory_limit, estimate_remesh_bytes,
        memory_limit, parse_bytes, physical_memory, quality_mesh, remesh_mesh, remesh_point_set,
        run_points, run_quality, run_remesh, run_simplify, write_report, PointsJob, RemeshJob,
        RemeshOptions, RemeshedMesh, SimplifyDensity, SimplifyDetail, SimplifyJob, SimplifySummary,
        DISTANCE_SAMPLES, MAX_SURFACE_POINTS, STDOUT,
    };
    pub use crate::geometry::{intersecting_pairs, triangle_angles_deg};
    pub use crate::manifold::MAX_KERNEL_DIMENSION;
}
