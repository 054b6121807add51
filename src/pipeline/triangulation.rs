//! The triangulation stage: the samples connected (the restricted Delaunay triangulation on the
//! input, or tangent-plane umbrellas merged by votes), then the crease edges it left out put in.

use glam::DVec3;
use rayon::prelude::*;

use super::finish::{carried_sources, edges_present};
use super::input::InputIndex;
use super::RemeshParams;
use crate::geometry::tolerance::ON_SURFACE_RELATIVE;
use crate::mesh::edit::{EditMesh, SlotPolicy};
use crate::mesh::TriMesh;
use crate::sampling::sizing::SizingField;
use crate::sampling::spacing::SAMPLES_PER_SIGMA2;
use crate::surface::SurfaceSample;
use crate::triangulate::recover::{close_slits, flip_crease_slivers, recover_edges, RecoverStats};
use crate::triangulate::{
    triangulate, triangulate_restricted, AssemblyStats, FaceSource, RestrictedDelaunayStats,
    SampleSet, TriangulationMethod,
};

/// The triangulated samples.
pub(super) struct Triangulated {
    /// The mesh (bbox-100 units), its vertices the samples in order.
    pub mesh: TriMesh,
    /// How each face came in.
    pub face_sources: Vec<FaceSource>,
    pub assembly: AssemblyStats,
    /// `None` when the umbrellas made the triangles.
    pub restricted_delaunay: Option<RestrictedDelaunayStats>,
    /// Of the sampled crease edges, those the triangulation made.
    pub feature_edges_triangulated: usize,
    /// What putting in the others did.
    pub recovery: RecoverStats,
    /// The samples the restricted Delaunay triangulation inserted where the samples' cells
    /// failed the topological ball property (after the given samples among the vertices).
    pub inserted: Vec<DVec3>,
}

/// Triangulates `samples` (on the input, spaced about `sigma_p` times the sizing `field`) with
/// their curve edges (`boundary_edges`, `feature_edges`: vertex pairs).
pub(super) fn triangulate_samples(
    samples: &[SurfaceSample],
    sigma_p: f64,
    field: &dyn SizingField,
    (boundary_edges, feature_edges): (&[[u32; 2]], &[[u32; 2]]),
    index: &InputIndex,
    params: &RemeshParams,
) -> Triangulated {
    let surface = &index.surface;
    let mut positions: Vec<DVec3> = samples.iter().map(|s| s.position).collect();
    let normals: Vec<DVec3> = samples
        .par_iter()
        .map(
            // A sample lies on the surface (up to rounding).
            |s: &SurfaceSample| match surface.closest_point_hinted(
                s.position,
                ON_SURFACE_RELATIVE * sigma_p,
                f64::MAX,
            ) {
                Some(sp) => surface.smooth_normal(&sp),
                None => s.normal,
            },
        )
        .collect();
    let set = SampleSet {
        positions: &positions,
        normals: &normals,
        boundary_edges,
    };
    // The restricted Delaunay triangulation, or the umbrellas where it is not asked for or its
    // refinement of the input would be too large.
    let restricted = match params.triangulation {
        TriangulationMethod::Umbrellas => None,
        TriangulationMethod::RestrictedDelaunay(mut rd) => {
            // An input with non-manifold edges has no topology a manifold output can keep: no
            // sample is inserted for it (chair_model.obj, 9518 such edges: 884 samples inserted
            // in 24 rounds, and the property still failed; beetle.obj, 47: 498 inserted, 116
            // crossing pairs where there were none).
            // Where its faces cross, samples are inserted: the cow (its tail through its rump)
            // comes out in one part, as its input is (2000 and 3000 points, seeds 1-5).
            rd.topological_ball.enabled &= index.manifold_edges;
            // The sample spacing is about sigma_p (SAMPLES_PER_SIGMA2 samples per sigma_p^2 of
            // area; on boundary curves one per sigma_p or closer).
            let spacing = sigma_p / SAMPLES_PER_SIGMA2.sqrt();
            let sheets = &index.sheets;
            triangulate_restricted(
                &set,
                surface,
                sheets,
                spacing,
                field,
                &params.triangulate,
                &rd,
            )
        }
    };
    let mut inserted = Vec::new();
    let (faces, mut face_sources, mut assembly, restricted_delaunay) = match restricted {
        Some((f, s, a, rd, added)) => {
            positions.extend_from_slice(&added);
            inserted = added;
            (f, s, a, Some(rd))
        }
        None => {
            let (f, s, a) = triangulate(&set, &params.triangulate);
            (f, s, a, None)
        }
    };
    let mut mesh = TriMesh::new(positions, faces);
    let feature_edges_triangulated = edges_present(&mesh, feature_edges);
    // Crease edges the triangulation left out (where a crease leaves a corner at a small angle
    // to another) are put in, and slits along graded creases (one sheet's faces skipping a
    // sample) closed.
    let recovery = if !feature_edges.is_empty() {
        let mut m: EditMesh<Option<u32>> = EditMesh::from_trimesh(&mesh, Some, SlotPolicy::Reuse);
        let slits = close_slits(&mut m, None);
        assembly.holes_left = assembly.holes_left.saturating_sub(slits);
        let stats = recover_edges(&mut m, feature_edges, None);
        flip_crease_slivers(&mut m, None);
        let (positions, faces, origin) = m.into_parts();
        mesh = TriMesh::new(positions, faces);
        face_sources = carried_sources(&origin, &face_sources);
        stats
    } else {
        RecoverStats::default()
    };
    Triangulated {
        mesh,
        face_sources,
        assembly,
        restricted_delaunay,
        feature_edges_triangulated,
        recovery,
        inserted,
    }
}
