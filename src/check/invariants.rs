//! The invariants every mesh the pipeline produces must keep, checked in one pass, each violated
//! kind reported as a typed [`Violation`] with its count and its first offender.
//!
//! Source: this project's invariant checker (STYLE.md, practice 7), in the spirit of spade's
//! `sanity_check`; the definitions are those of [`Topology`](super::Topology).

use std::fmt;

use serde::Serialize;

use super::self_intersection::{self_intersections, SelfIntersections};
use crate::mesh::topology::{analyze, Analysis, Topology};
use crate::mesh::TriMesh;

/// One violated invariant: how many elements break it (`count`) and the first of them (lowest
/// index). `Display` gives the one-line message the report prints.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(tag = "kind")]
pub enum Violation {
    /// Faces referring to a vertex index `>= vertex_count`; the first is `face`, using `vertex`.
    IndexOutOfRange {
        /// Faces with an out-of-range index.
        count: usize,
        /// The first such face.
        face: usize,
        /// The out-of-range index it uses.
        vertex: u32,
        /// The number of vertices of the mesh.
        vertex_count: usize,
    },
    /// Vertices with a NaN or infinite coordinate.
    NonFiniteVertex {
        /// Vertices with a non-finite coordinate.
        count: usize,
        /// The first such vertex.
        vertex: usize,
    },
    /// Faces with a repeated index or zero area
    /// ([`is_degenerate_face`](crate::geometry::triangle::is_degenerate_face)).
    DegenerateFace {
        /// Degenerate faces.
        count: usize,
        /// The first such face.
        face: usize,
        /// Its vertex indices.
        triangle: [u32; 3],
    },
    /// Faces repeating the vertex set of an earlier face (in either orientation).
    DuplicateFace {
        /// Faces repeating an earlier one.
        count: usize,
        /// The first such face.
        face: usize,
        /// The earlier face it repeats.
        earlier: usize,
        /// The vertex indices of `face`.
        triangle: [u32; 3],
        /// The vertex indices of `earlier`.
        earlier_triangle: [u32; 3],
    },
    /// Edges in three or more faces.
    NonManifoldEdge {
        /// Non-manifold edges.
        count: usize,
        /// The first such edge (its two vertex indices, smaller first).
        edge: [u32; 2],
        /// How many faces it is in.
        faces: usize,
    },
    /// Vertices whose faces form two or more fans.
    NonManifoldVertex {
        /// Non-manifold vertices.
        count: usize,
        /// The first such vertex.
        vertex: u32,
    },
    /// Interior edges traversed in the same direction by both their faces.
    InconsistentOrientation {
        /// Inconsistently oriented edges.
        count: usize,
        /// The first such edge (its two vertex indices, smaller first).
        edge: [u32; 2],
        /// Its two faces.
        faces: [u32; 2],
    },
    /// Vertices no face uses.
    UnreferencedVertex {
        /// Unreferenced vertices.
        count: usize,
        /// The first such vertex.
        vertex: usize,
    },
    /// Pairs of faces that intersect
    /// ([`self_intersections`](super::self_intersections): faces that share no vertex and
    /// meet, share one and meet elsewhere too, or share an edge and overlap); the first pair is
    /// `f`, `g`, f < g.
    Crossing {
        /// Intersecting pairs (all kinds).
        count: usize,
        /// Of them, pairs of faces with no vertex in common.
        apart: usize,
        /// Pairs of faces with one vertex in common that meet elsewhere too.
        at_vertex: usize,
        /// Pairs of faces with an edge in common that overlap.
        along_edge: usize,
        /// The first face of the first pair.
        f: u32,
        /// The second face of the first pair.
        g: u32,
    },
}

impl fmt::Display for Violation {
    fn fmt(&self, out: &mut fmt::Formatter<'_>) -> fmt::Result {
        let plural = |n: usize, one: &'static str, many: &'static str| {
            format!("{n} {}", if n == 1 { one } else { many })
        };
        match *self {
            Violation::IndexOutOfRange { count, face, vertex, vertex_count } => write!(
                out,
                "{} to a vertex index out of range (first: face {face} uses vertex {vertex}, but there are {vertex_count} vertices)",
                plural(count, "face refers", "faces refer"),
            ),
            Violation::NonFiniteVertex { count, vertex } => write!(
                out,
                "{} a non-finite coordinate (first: vertex {vertex})",
                plural(count, "vertex has", "vertices have")
            ),
            Violation::DegenerateFace { count, face, triangle } => write!(
                out,
                "{} degenerate (zero area or a repeated index) (first: face {face} {triangle:?})",
                plural(count, "face is", "faces are"),
            ),
            Violation::DuplicateFace { count, face, earlier, triangle, earlier_triangle } => write!(
                out,
                "{} the vertices of an earlier face (first: face {face} {triangle:?} repeats face {earlier} {earlier_triangle:?})",
                plural(count, "face repeats", "faces repeat"),
            ),
            Violation::NonManifoldEdge { count, edge: [u, v], faces } => write!(
                out,
                "{} in 3 or more faces (first: edge {u}-{v}, in {faces} faces)",
                plural(count, "non-manifold edge", "non-manifold edges")
            ),
            Violation::NonManifoldVertex { count, vertex } => write!(
                out,
                "{} whose faces form 2 or more fans (first: vertex {vertex})",
                plural(count, "non-manifold vertex", "non-manifold vertices")
            ),
            Violation::InconsistentOrientation { count, edge: [u, v], faces: [f, g] } => write!(
                out,
                "{} traversed in the same direction by both faces (first: edge {u}-{v}, faces {f} and {g})",
                plural(count, "inconsistently oriented edge", "inconsistently oriented edges")
            ),
            Violation::UnreferencedVertex { count, vertex } => write!(
                out,
                "{} used by no face (first: vertex {vertex})",
                plural(count, "vertex", "vertices")
            ),
            Violation::Crossing { count, apart, at_vertex, along_edge, f, g } => write!(
                out,
                "{} ({apart} apart, {at_vertex} at a shared vertex, {along_edge} along a shared edge) (first: faces {f} and {g})",
                plural(count, "pair of faces intersects", "pairs of faces intersect")
            ),
        }
    }
}

/// The invariants every mesh the pipeline produces must keep, checked in one pass: one
/// [`Violation`] per violated kind, in the order of the variants, with its count and the first
/// offending element (lowest index); an empty vector when all hold.
///
/// The invariants: every index in range; every coordinate finite; no degenerate face
/// ([`is_degenerate_face`](crate::geometry::triangle::is_degenerate_face)); no duplicate face;
/// every edge in at most 2 faces; every vertex a single fan (see
/// [`Topology::non_manifold_vertices`](super::Topology)); every interior edge traversed once
/// each way (consistent orientation); no unreferenced vertex; no two faces that intersect
/// ([`self_intersections`](super::self_intersections): the standard definition, exact, through
/// a BVH).
/// Boundaries are allowed (an open mesh passes), and so is an empty mesh.
pub fn check_invariants(mesh: &TriMesh) -> Vec<Violation> {
    violations(mesh, &analyze(mesh), &self_intersections(mesh))
}

/// The topology, the self-intersections and the violations of `mesh` in one pass (what the
/// report needs; [`check_invariants`] alone computes the same violations), the
/// self-intersections decided on `stored`: the same faces at the coordinates a file stores
/// (`mesh` itself, or `mesh` before it was mapped into a bbox-100 frame, whose rounding can make
/// two faces that touch apart or the reverse; the exact test is only as exact as the coordinates
/// it is given).
pub(crate) fn check_all(
    mesh: &TriMesh,
    stored: &TriMesh,
) -> (Topology, SelfIntersections, Vec<Violation>) {
    let analysis = analyze(mesh);
    let crossings = self_intersections(stored);
    let found = violations(mesh, &analysis, &crossings);
    (analysis.topology, crossings, found)
}

/// The violations of [`check_invariants`] from the analysis and the self-intersections of
/// `mesh`.
fn violations(mesh: &TriMesh, a: &Analysis, crossings: &SelfIntersections) -> Vec<Violation> {
    let t = &a.topology;
    let mut out = Vec::new();
    if let Some((face, vertex)) = a.first_out_of_range {
        out.push(Violation::IndexOutOfRange {
            count: a.out_of_range_faces,
            face,
            vertex,
            vertex_count: mesh.positions.len(),
        });
    }
    if let Some(vertex) = a.first_non_finite {
        out.push(Violation::NonFiniteVertex {
            count: a.non_finite_vertices,
            vertex,
        });
    }
    if let Some(face) = a.first_degenerate {
        out.push(Violation::DegenerateFace {
            count: t.degenerate_faces,
            face,
            triangle: mesh.triangles[face],
        });
    }
    if let Some((face, earlier)) = a.first_duplicate {
        out.push(Violation::DuplicateFace {
            count: t.duplicate_faces,
            face,
            earlier,
            triangle: mesh.triangles[face],
            earlier_triangle: mesh.triangles[earlier],
        });
    }
    if let Some((edge, faces)) = a.first_non_manifold_edge {
        out.push(Violation::NonManifoldEdge {
            count: t.non_manifold_edges,
            edge,
            faces,
        });
    }
    if let Some(vertex) = a.first_non_manifold_vertex {
        out.push(Violation::NonManifoldVertex {
            count: t.non_manifold_vertices,
            vertex,
        });
    }
    if let Some((edge, faces)) = a.first_inconsistent {
        out.push(Violation::InconsistentOrientation {
            count: t.inconsistent_orientation_edges,
            edge,
            faces,
        });
    }
    if let Some(vertex) = a.first_unreferenced {
        out.push(Violation::UnreferencedVertex {
            count: t.unreferenced_vertices,
            vertex,
        });
    }
    if let Some([f, g]) = crossings.first {
        out.push(Violation::Crossing {
            count: crossings.pairs,
            apart: crossings.apart,
            at_vertex: crossings.at_vertex,
            along_edge: crossings.along_edge,
            f,
            g,
        });
    }
    out
}
