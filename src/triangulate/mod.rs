//! Triangulating surface samples: local tangent-plane Delaunay umbrellas merged by votes, then a
//! manifold clean-up.

pub mod cleanup;
pub mod optimize;
pub mod refine;
pub mod tangent_delaunay;
pub mod untangle;

pub use cleanup::{assemble, AssemblyParams, AssemblyStats, FaceSource};
pub use refine::RefineParams;
pub use tangent_delaunay::{vote_triangles, SampleSet, TangentDelaunayParams, VotedTriangle};

/// Parameters of [`triangulate`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TriangulateParams {
    /// The local Delaunay step.
    pub local: TangentDelaunayParams,
    /// The assembly and clean-up step.
    pub assembly: AssemblyParams,
}

/// Triangulates samples on a surface: every sample's tangent-plane Delaunay umbrella, merged by
/// votes, then cleaned up into an edge- and vertex-manifold mesh oriented like `normals`.
/// Returns the faces (indices into `set.positions`), how each came in, and what the assembly did.
pub fn triangulate(
    set: &SampleSet,
    params: &TriangulateParams,
) -> (Vec<[u32; 3]>, Vec<FaceSource>, AssemblyStats) {
    let voted = vote_triangles(set, &params.local);
    assemble(
        set.positions,
        set.normals,
        &voted,
        set.boundary_edges,
        &params.assembly,
    )
}
