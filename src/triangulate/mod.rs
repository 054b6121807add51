//! Triangulating surface samples: the restricted Delaunay triangulation of the samples' Voronoi
//! cells on the input (the default: cells grown over the input refined,
//! [`restricted_delaunay`], or clipped exactly from its facets, [`restricted_voronoi`]; the
//! topological ball property checked and samples inserted where it fails,
//! [`topological_ball`]), or the local tangent-plane Delaunay umbrellas merged by votes
//! ([`tangent_delaunay`]: point sets, and `--triangulation umbrellas`); then a manifold
//! clean-up. The finishing stage's operators on the triangulated samples are in
//! [`crate::finish`].

pub mod cleanup;
pub(crate) mod flip;
pub mod pillows;
pub mod recover;
pub mod refine;
pub mod restricted_delaunay;
pub mod restricted_voronoi;
mod rows;
pub mod tangent_delaunay;
pub mod topological_ball;
pub mod unsupported;

pub use cleanup::{assemble, AssemblyParams, AssemblyStats, FaceSource};
pub use refine::RefineParams;
pub use restricted_delaunay::{RestrictedDelaunayParams, RestrictedDelaunayStats};
pub use tangent_delaunay::{vote_triangles, SampleSet, TangentDelaunayParams, VotedTriangle};

use crate::mesh::sheets::Sheets;
use crate::sampling::sizing::SizingField;
use glam::DVec3;
use rustc_hash::FxHashMap;

use crate::geometry::triangle::is_degenerate_triangle;
use crate::surface::MeshSurface;

/// Parameters of [`triangulate`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TriangulateParams {
    /// The local Delaunay step.
    pub local: TangentDelaunayParams,
    /// The assembly and clean-up step.
    pub assembly: AssemblyParams,
}

/// Where the candidate triangles of the remesh's triangulation come from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TriangulationMethod {
    /// Tangent-plane Delaunay umbrellas of the samples ([`triangulate`]).
    Umbrellas,
    /// The restricted Delaunay triangulation on the input mesh ([`triangulate_restricted`]; the
    /// default: it keeps thin parts whole where the umbrellas of their two sides see each other).
    RestrictedDelaunay(RestrictedDelaunayParams),
}

impl Default for TriangulationMethod {
    fn default() -> Self {
        TriangulationMethod::RestrictedDelaunay(RestrictedDelaunayParams::default())
    }
}

/// Triangulates samples on a surface: every sample's tangent-plane Delaunay umbrella, merged by
/// votes, then cleaned up into an edge- and vertex-manifold mesh oriented like `normals`.
/// Returns the faces (indices into `set.positions`), how each came in, and what the assembly did.
///
/// Samples at exactly the same position count as one (the first of them); the others are in no
/// face. Candidate triangles of zero area (three samples on a line) are never used.
pub fn triangulate(
    set: &SampleSet,
    params: &TriangulateParams,
) -> (Vec<[u32; 3]>, Vec<FaceSource>, AssemblyStats) {
    on_distinct(set, |s| triangulate_distinct(s, params))
}

/// Triangulates samples on `surface` (their restricted Delaunay triangulation: the dual of
/// their Voronoi cells grown over the input mesh, see `restricted_delaunay`), then assembles
/// and cleans it up as [`triangulate`] does. `spacing`: the sample spacing (units of the
/// positions). Returns also what the restricted Delaunay step did; `None` when its refinement of
/// the input would be too large (see [`RestrictedDelaunayParams::max_added_per_sample`]) or it
/// gives no triangle. `sheets`: those of `surface`'s mesh (`Sheets::new`, made once per input).
pub fn triangulate_restricted(
    set: &SampleSet,
    surface: &MeshSurface,
    sheets: &Sheets,
    spacing: f64,
    field: &dyn SizingField,
    params: &TriangulateParams,
    rd: &RestrictedDelaunayParams,
) -> Option<Restricted> {
    let mut rd_stats = None;
    let mut added: Vec<DVec3> = Vec::new();
    let (faces, sources, stats) = on_distinct(set, |s| {
        let found = if rd.clipped {
            let tolerance = crate::geometry::tolerance::ON_SURFACE_RELATIVE * spacing;
            restricted_voronoi::restricted_voronoi(
                surface,
                sheets,
                s.positions,
                s.normals,
                tolerance,
            )
            .map(|(v, st)| (v, st, Vec::new()))
        } else {
            restricted_delaunay::restricted_delaunay(
                surface,
                sheets,
                s.positions,
                spacing,
                field,
                rd,
            )
        };
        let Some((voted, st, inserted)) = found else {
            return (Vec::new(), Vec::new(), AssemblyStats::default());
        };
        rd_stats = Some(st);
        if inserted.is_empty() {
            return assemble_candidates(s, voted, params);
        }
        // The samples inserted for the topological ball property, after the others, with the
        // input's normals.
        let mut positions = s.positions.to_vec();
        let mut normals = s.normals.to_vec();
        for &p in &inserted {
            positions.push(p);
            normals.push(
                surface
                    .closest_point(p)
                    .map_or(DVec3::ZERO, |sp| surface.smooth_normal(&sp)),
            );
        }
        added = inserted;
        let extended = SampleSet {
            positions: &positions,
            normals: &normals,
            boundary_edges: s.boundary_edges,
        };
        assemble_candidates(&extended, voted, params)
    });
    // No triangle at all (samples scattered over parts far below the refinement's resolution,
    // such as a small sphere beside a far triangle) is no triangulation either.
    rd_stats
        .filter(|_| !faces.is_empty())
        .map(|st| (faces, sources, stats, st, added))
}

/// [`Triangulated`], what the restricted Delaunay step did, and the samples it inserted (the
/// faces number them after the given samples, in order).
pub type Restricted = (
    Vec<[u32; 3]>,
    Vec<FaceSource>,
    AssemblyStats,
    RestrictedDelaunayStats,
    Vec<DVec3>,
);

/// Faces, how each came in, and what the assembly did.
type Triangulated = (Vec<[u32; 3]>, Vec<FaceSource>, AssemblyStats);

/// Runs `run` on the samples at distinct positions and maps its faces back: coincident samples
/// would give faces of zero area (found by the triangulate fuzz target), so they count as one
/// (the first of them); the others are in no face.
fn on_distinct(set: &SampleSet, mut run: impl FnMut(&SampleSet) -> Triangulated) -> Triangulated {
    let mut first_at: FxHashMap<[u64; 3], u32> = FxHashMap::default();
    let mut distinct: Vec<u32> = Vec::new();
    let mut to_distinct: Vec<u32> = Vec::with_capacity(set.positions.len());
    for (i, p) in set.positions.iter().enumerate() {
        let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
        let k = *first_at.entry(key).or_insert_with(|| {
            distinct.push(i as u32);
            (distinct.len() - 1) as u32
        });
        to_distinct.push(k);
    }
    if distinct.len() == set.positions.len() {
        return run(set);
    }
    let positions: Vec<DVec3> = distinct
        .iter()
        .map(|&i| set.positions[i as usize])
        .collect();
    let normals: Vec<DVec3> = distinct.iter().map(|&i| set.normals[i as usize]).collect();
    let boundary_edges: Vec<[u32; 2]> = set
        .boundary_edges
        .iter()
        .map(|e| e.map(|v| to_distinct[v as usize]))
        .filter(|e| e[0] != e[1])
        .collect();
    let reduced = SampleSet {
        positions: &positions,
        normals: &normals,
        boundary_edges: &boundary_edges,
    };
    let (faces, sources, stats) = run(&reduced);
    // Samples the run inserted are numbered after the distinct ones, and after all of them in
    // the answer.
    let (given, kept) = (set.positions.len() as u32, distinct.len() as u32);
    let faces = faces
        .into_iter()
        .map(|f| {
            f.map(|v| {
                distinct
                    .get(v as usize)
                    .copied()
                    .unwrap_or(given + v - kept)
            })
        })
        .collect();
    (faces, sources, stats)
}

/// [`triangulate`] of samples at distinct positions.
fn triangulate_distinct(
    set: &SampleSet,
    params: &TriangulateParams,
) -> (Vec<[u32; 3]>, Vec<FaceSource>, AssemblyStats) {
    assemble_candidates(set, vote_triangles(set, &params.local), params)
}

/// Assembles candidate triangles of samples at distinct positions, those of zero area (three
/// samples on a line) left out.
fn assemble_candidates(
    set: &SampleSet,
    mut candidates: Vec<VotedTriangle>,
    params: &TriangulateParams,
) -> Triangulated {
    candidates.retain(|t| !is_degenerate_triangle(t.corners.map(|v| set.positions[v as usize])));
    assemble(
        set.positions,
        set.normals,
        &candidates,
        set.boundary_edges,
        &params.assembly,
    )
}
