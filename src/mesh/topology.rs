//! The combinatorial topology of a triangle mesh: counts, χ, genus, boundary loops,
//! manifoldness, orientation, and the hygiene counts the invariant check reads.
//!
//! Source: standard combinatorial topology of simplicial surfaces; see e.g. Botsch, Kobbelt,
//! Pauly, Alliez, Lévy, *Polygon Mesh Processing*, 2010, Ch. 1.

use crate::disjoint_sets::Dsu;
use serde::Serialize;

use crate::geometry::triangle::is_degenerate_face;
use crate::mesh::TriMesh;

/// Combinatorial topology and hygiene counts of a triangle mesh. All counts are of mesh elements;
/// nothing here depends on positions except `degenerate_faces`.
///
/// Definitions:
/// - `vertices` (V): distinct vertex indices used by at least one face (an out-of-range index
///   counts too; [`check_invariants`](crate::check::check_invariants) reports it). Vertices no face
///   uses are *not* counted here but in `unreferenced_vertices`.
/// - `faces` (F): all triangles, including degenerate and duplicate ones.
/// - `edges` (E): distinct undirected vertex pairs `{i, j}`, `i ≠ j`, that are a side of some face.
///   Each face side with two different indices is one *incidence* of its edge; a side `(i, i)` of a
///   face with a repeated index is not an edge (so `[a, a, b]` gives two incidences of `{a, b}`).
/// - `boundary_edges`: edges with exactly 1 incidence.
/// - `non_manifold_edges`: edges with 3 or more incidences.
/// - `non_manifold_vertices`: referenced vertices whose incident faces do not form a single fan.
///   Precisely: at vertex v, two faces containing v are *fan-adjacent* when they share an edge `{v,
///   w}` (whatever that edge's number of incidences); v is non-manifold when the graph of its
///   incident faces under fan-adjacency has 2 or more connected components. This flags the "bowtie"
///   (two cones touching at the tip); a vertex on a non-manifold edge is flagged only if its fans
///   are split in this sense (three triangles sharing an edge make one fan at each end).
/// - `components`: connected components of the faces, two faces being connected when they share a
///   *vertex* (not only an edge) — the topological components of the surface. Two tetrahedra
///   touching at one vertex are 1 component. Unreferenced vertices form no component.
/// - `euler_characteristic` χ = V − E + F with the V, E, F above (referenced vertices only).
/// - `boundary_loops`: connected components of the graph formed by the boundary edges and their
///   vertices. On a manifold mesh every boundary vertex has exactly two boundary edges, so this is
///   the number of boundary cycles; where boundary cycles touch at a (non-manifold) vertex they
///   count as one.
/// - `genus`: the total genus `g = (2·components − χ − boundary_loops) / 2` (summed over
///   components; for a single closed component `g = (2 − χ)/2`). It is `Some` only where the
///   formula holds: there is at least one face, every face has three distinct in-range indices,
///   there are no duplicate faces (so the faces form a simplicial complex), no non-manifold edge or
///   vertex, the surface is orientable (faces can be flipped so that every interior edge is
///   traversed in opposite directions — a mesh with a few flipped faces still has a genus), and the
///   numerator comes out even and non-negative. Otherwise `None`.
/// - `degenerate_faces`: faces that repeat a vertex index or have zero area
///   ([`is_degenerate_face`](crate::geometry::triangle::is_degenerate_face): `|(b-a)×(c-a)| <=
///   1e-12 · h²`).
/// - `duplicate_faces`: faces whose sorted index triple equals that of an earlier face (same
///   vertices in any order and either orientation); the first occurrence is not counted.
/// - `unreferenced_vertices`: entries of `positions` that no face uses.
/// - `inconsistent_orientation_edges`: edges with exactly 2 incidences whose two faces traverse
///   them in the same direction (a consistently oriented manifold traverses each interior edge once
///   each way). One flipped face in a closed mesh gives 3.
///
/// Source: standard combinatorial topology of simplicial surfaces (Euler–Poincaré formula χ = 2c −
/// 2g − b for orientable compact surfaces); see e.g. Botsch, Kobbelt, Pauly, Alliez, Lévy, *Polygon
/// Mesh Processing*, 2010, Ch. 1.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Topology {
    /// V: vertices referenced by at least one face.
    pub vertices: usize,
    /// F: all faces.
    pub faces: usize,
    /// E: distinct undirected edges.
    pub edges: usize,
    /// Edges in exactly one face.
    pub boundary_edges: usize,
    /// Connected components of the boundary-edge graph.
    pub boundary_loops: usize,
    /// Edges in three or more faces.
    pub non_manifold_edges: usize,
    /// Referenced vertices whose incident faces form two or more fans.
    pub non_manifold_vertices: usize,
    /// Connected components of faces joined through shared vertices.
    pub components: usize,
    /// χ = V − E + F.
    pub euler_characteristic: i64,
    /// Total genus, where the mesh is an orientable manifold simplicial complex (see above).
    pub genus: Option<i64>,
    /// Faces with a repeated index or zero area.
    pub degenerate_faces: usize,
    /// Faces repeating the vertex set of an earlier face.
    pub duplicate_faces: usize,
    /// Positions no face uses.
    pub unreferenced_vertices: usize,
    /// Two-face edges traversed in the same direction by both faces.
    pub inconsistent_orientation_edges: usize,
}

impl Topology {
    /// Edge- and vertex-manifold: no non-manifold edge and no non-manifold vertex (boundaries
    /// allowed). Says nothing about orientation, degenerate or duplicate faces; see
    /// [`check_invariants`](crate::check::check_invariants) for the full list.
    pub fn is_manifold(&self) -> bool {
        self.non_manifold_edges == 0 && self.non_manifold_vertices == 0
    }

    /// [`Topology::is_manifold`], at least one face, and no boundary edge.
    pub fn is_closed_manifold(&self) -> bool {
        self.is_manifold() && self.faces > 0 && self.boundary_edges == 0
    }
}

/// The combinatorial topology of `mesh` (see [`Topology`] for every definition). Never panics:
/// out-of-range indices are treated as vertices of their own. O(F log F) (one sort of the 3F face
/// sides), sequential and deterministic.
pub fn topology(mesh: &TriMesh) -> Topology {
    analyze(mesh).topology
}

/// Everything [`topology`] and [`check_invariants`](crate::check::check_invariants) need, with the
/// first offender of each kind.
pub(crate) struct Analysis {
    pub(crate) topology: Topology,
    pub(crate) out_of_range_faces: usize,
    pub(crate) first_out_of_range: Option<(usize, u32)>,
    pub(crate) non_finite_vertices: usize,
    pub(crate) first_non_finite: Option<usize>,
    pub(crate) first_degenerate: Option<usize>,
    pub(crate) first_duplicate: Option<(usize, usize)>,
    pub(crate) first_non_manifold_edge: Option<([u32; 2], usize)>,
    pub(crate) first_non_manifold_vertex: Option<u32>,
    pub(crate) first_unreferenced: Option<usize>,
    pub(crate) first_inconsistent: Option<([u32; 2], [u32; 2])>,
}

pub(crate) fn analyze(mesh: &TriMesh) -> Analysis {
    let npos = mesh.positions.len();
    let faces = mesh.triangles.len();

    // Out-of-range indices become extra vertices npos, npos + 1, ... (in increasing order of the
    // index), so that arrays stay sized by the vertices actually used, whatever the indices.
    let mut out_of_range_faces = 0;
    let mut first_out_of_range = None;
    let mut extra: Vec<u32> = Vec::new();
    for (f, t) in mesh.triangles.iter().enumerate() {
        if let Some(&bad) = t.iter().find(|&&i| i as usize >= npos) {
            out_of_range_faces += 1;
            first_out_of_range.get_or_insert((f, bad));
            extra.extend(t.iter().filter(|&&i| i as usize >= npos));
        }
    }
    extra.sort_unstable();
    extra.dedup();
    let nv = npos + extra.len();
    let tris: Vec<[u32; 3]> = if extra.is_empty() {
        mesh.triangles.clone()
    } else {
        let local = |i: u32| {
            if (i as usize) < npos {
                i
            } else {
                (npos + extra.partition_point(|&x| x < i)) as u32
            }
        };
        mesh.triangles.iter().map(|t| t.map(local)).collect()
    };
    // Back from these local indices to the mesh's, for messages.
    let original = |v: u32| -> u32 {
        if (v as usize) < npos {
            v
        } else {
            extra[v as usize - npos]
        }
    };

    // Referenced and unreferenced vertices.
    let mut referenced = vec![false; nv];
    for t in &tris {
        for &i in t {
            referenced[i as usize] = true;
        }
    }
    let vertices = referenced.iter().filter(|&&r| r).count();
    let unreferenced_vertices = referenced[..npos].iter().filter(|&&r| !r).count();
    let first_unreferenced = referenced[..npos].iter().position(|&r| !r);
    let non_finite_vertices = mesh.positions.iter().filter(|p| !p.is_finite()).count();
    let first_non_finite = mesh.first_non_finite_vertex();

    // Degenerate, collapsed (repeated index) and duplicate faces.
    let mut degenerate_faces = 0;
    let mut first_degenerate = None;
    let mut collapsed_faces = 0;
    let mut duplicate_faces = 0;
    let mut first_duplicate = None;
    let mut seen: rustc_hash::FxHashMap<[u32; 3], usize> = Default::default();
    seen.reserve(faces);
    for (f, t) in mesh.triangles.iter().enumerate() {
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            collapsed_faces += 1;
        }
        if is_degenerate_face(&mesh.positions, *t) {
            degenerate_faces += 1;
            first_degenerate.get_or_insert(f);
        }
        let mut key = *t;
        key.sort_unstable();
        match seen.entry(key) {
            std::collections::hash_map::Entry::Occupied(e) => {
                duplicate_faces += 1;
                first_duplicate.get_or_insert((f, *e.get()));
            }
            std::collections::hash_map::Entry::Vacant(e) => {
                e.insert(f);
            }
        }
    }

    // Face sides as (lo, hi, face, forward), sorted so that the incidences of each edge are
    // adjacent (full-key sort: deterministic).
    let mut sides: Vec<(u32, u32, u32, bool)> = Vec::with_capacity(3 * faces);
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a != b {
                sides.push((a.min(b), a.max(b), f as u32, a < b));
            }
        }
    }
    sides.sort_unstable();

    // The corner of vertex v in face f: f*3 + the first k with t[k] == v (a face with a repeated
    // index has one corner per distinct vertex).
    let corner = |f: u32, v: u32| -> usize {
        let t = tris[f as usize];
        let k = if t[0] == v {
            0
        } else if t[1] == v {
            1
        } else {
            2
        };
        3 * f as usize + k
    };

    let mut corners = Dsu::new(3 * faces);
    let mut orientation = Dsu::new(faces);
    let mut boundary = Dsu::new(nv);
    let mut on_boundary = vec![false; nv];
    let mut orientable = true;
    let mut edges = 0;
    let mut boundary_edges = 0;
    let mut non_manifold_edges = 0;
    let mut first_non_manifold_edge = None;
    let mut inconsistent_orientation_edges = 0;
    let mut first_inconsistent = None;
    for run in sides.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        edges += 1;
        let (lo, hi) = (run[0].0, run[0].1);
        match run.len() {
            1 => {
                boundary_edges += 1;
                boundary.union(lo as usize, hi as usize, false);
                on_boundary[lo as usize] = true;
                on_boundary[hi as usize] = true;
            }
            2 => {
                let (f, g) = (run[0].2, run[1].2);
                let same_direction = run[0].3 == run[1].3;
                if same_direction {
                    inconsistent_orientation_edges += 1;
                    first_inconsistent.get_or_insert(([original(lo), original(hi)], [f, g]));
                }
                if f != g && !orientation.union(f as usize, g as usize, same_direction) {
                    orientable = false;
                }
            }
            n => {
                non_manifold_edges += 1;
                first_non_manifold_edge.get_or_insert(([original(lo), original(hi)], n));
            }
        }
        let f0 = run[0].2;
        for s in &run[1..] {
            corners.union(corner(f0, lo), corner(s.2, lo), false);
            corners.union(corner(f0, hi), corner(s.2, hi), false);
        }
    }

    // Fans: the distinct corner roots at each vertex.
    let mut fan_root = vec![u32::MAX; nv];
    let mut split = vec![false; nv];
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let v = t[k];
            if (0..k).any(|j| t[j] == v) {
                continue;
            }
            let (root, _) = corners.find(3 * f + k);
            let slot = &mut fan_root[v as usize];
            if *slot == u32::MAX {
                *slot = root as u32;
            } else if *slot != root as u32 {
                split[v as usize] = true;
            }
        }
    }
    let non_manifold_vertices = split.iter().filter(|&&s| s).count();
    let first_non_manifold_vertex = split.iter().position(|&s| s).map(|v| original(v as u32));

    // Components: vertices joined through faces.
    let mut vertex_sets = Dsu::new(nv);
    for t in &tris {
        vertex_sets.union(t[0] as usize, t[1] as usize, false);
        vertex_sets.union(t[0] as usize, t[2] as usize, false);
    }
    let components = (0..nv)
        .filter(|&v| referenced[v] && vertex_sets.find(v).0 == v)
        .count();
    let boundary_loops = (0..nv)
        .filter(|&v| on_boundary[v] && boundary.find(v).0 == v)
        .count();

    let euler_characteristic = vertices as i64 - edges as i64 + faces as i64;
    let genus = if faces > 0
        && collapsed_faces == 0
        && out_of_range_faces == 0
        && duplicate_faces == 0
        && non_manifold_edges == 0
        && non_manifold_vertices == 0
        && orientable
    {
        let twice = 2 * components as i64 - euler_characteristic - boundary_loops as i64;
        (twice >= 0 && twice % 2 == 0).then_some(twice / 2)
    } else {
        None
    };

    Analysis {
        topology: Topology {
            vertices,
            faces,
            edges,
            boundary_edges,
            boundary_loops,
            non_manifold_edges,
            non_manifold_vertices,
            components,
            euler_characteristic,
            genus,
            degenerate_faces,
            duplicate_faces,
            unreferenced_vertices,
            inconsistent_orientation_edges,
        },
        out_of_range_faces,
        first_out_of_range,
        non_finite_vertices,
        first_non_finite,
        first_degenerate,
        first_duplicate,
        first_non_manifold_edge,
        first_non_manifold_vertex,
        first_unreferenced,
        first_inconsistent,
    }
}
