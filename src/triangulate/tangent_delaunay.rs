//! Local tangent-plane Delaunay triangulation of surface samples.
//!
//! For each sample its nearest samples are projected onto its tangent plane and triangulated
//! (2D Delaunay with spade, constrained by the boundary edges that fall among them); the
//! triangles incident to the sample form its umbrella. A triangle that is Delaunay in the tangent
//! planes of all three of its corners gets three votes; these form an edge-manifold, consistently
//! oriented mesh by themselves (each umbrella is a planar star). Triangles with two votes fill in
//! where the local views disagree (near-cocircular quads), when they fit; `cleanup` closes what
//! is left. (The approach of Gopi, Krishnan, Silva 2000, "Surface reconstruction based on lower
//! dimensional localized Delaunay triangulation", and of Boissonnat's tangent-plane methods.)

use crate::geometry::tangent_basis;
use crate::geometry::tolerance::ANGLE_SLACK;
use glam::{DVec2, DVec3};
use rayon::prelude::*;
use rustc_hash::FxHashMap;
use spade::handles::FixedVertexHandle;
use spade::{ConstrainedDelaunayTriangulation, HasPosition, Point2, Triangulation};

use crate::spatial::StaticTree;

/// Parameters of the local triangulation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TangentDelaunayParams {
    /// Neighbours projected into each tangent plane (default 14).
    pub neighbors: usize,
    /// Neighbours whose normal differs from the centre's by more than this are left out (they
    /// are on another sheet of the surface), degrees (default 90).
    pub max_normal_angle_deg: f64,
}

impl Default for TangentDelaunayParams {
    fn default() -> Self {
        TangentDelaunayParams {
            neighbors: 14,
            max_normal_angle_deg: 90.0,
        }
    }
}

/// Samples to triangulate.
#[derive(Debug, Clone, Copy)]
pub struct SampleSet<'a> {
    /// Positions (bbox-100 units).
    pub positions: &'a [DVec3],
    /// Unit normals of the surface at the samples (smooth normals: they define tangent planes).
    pub normals: &'a [DVec3],
    /// Boundary edges `[from, to]`, directed with the surface on the left; they become boundary
    /// edges of the output.
    pub boundary_edges: &'a [[u32; 2]],
}

/// A candidate triangle with its votes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VotedTriangle {
    /// Corners, counter-clockwise about the normals (the orientation of the first umbrella that
    /// produced it).
    pub corners: [u32; 3],
    /// How many of its corners' umbrellas contain it (1 to 3).
    pub votes: u8,
    /// Whether two umbrellas gave it opposite orientations.
    pub orientation_conflict: bool,
}

#[derive(Clone, Copy)]
struct LocalVertex {
    p: Point2<f64>,
    index: u32,
}

impl HasPosition for LocalVertex {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.p
    }
}

/// The umbrella of sample `i`: the triangles incident to it in the Delaunay triangulation of its
/// neighbours projected on its tangent plane, as `[i, a, b]` counter-clockwise about n_i.
fn umbrella(
    i: usize,
    set: &SampleSet,
    neighbors: &[(u32, f64)],
    params: &TangentDelaunayParams,
    chain: &FxHashMap<u32, (Option<u32>, Option<u32>)>,
    chain_rank: &FxHashMap<u32, usize>,
    out: &mut Vec<[u32; 3]>,
) {
    out.clear();
    let pi = set.positions[i];
    let ni = set.normals[i];
    let (u, v) = tangent_basis(ni);
    let cos_max = params.max_normal_angle_deg.to_radians().cos();
    let mut cdt: ConstrainedDelaunayTriangulation<LocalVertex> =
        ConstrainedDelaunayTriangulation::new();
    let Ok(center) = cdt.insert(LocalVertex {
        p: Point2::new(0.0, 0.0),
        index: i as u32,
    }) else {
        return;
    };
    let mut handles: Vec<(u32, FixedVertexHandle)> = Vec::with_capacity(neighbors.len());
    for &(j, _) in neighbors {
        if j as usize == i || set.normals[j as usize].dot(ni) < cos_max {
            continue;
        }
        // Projection onto the tangent plane, rescaled to keep the 3D distance (a first-order
        // log map): neighbours far out on a curved surface keep their spacing.
        let d = set.positions[j as usize] - pi;
        let mut q = DVec2::new(d.dot(u), d.dot(v));
        let l = q.length();
        if l > 0.0 {
            q *= d.length() / l;
        }
        if let Ok(h) = cdt.insert(LocalVertex {
            p: Point2::new(q.x, q.y),
            index: j,
        }) {
            if h != center && cdt.vertex(h).data().index == j {
                handles.push((j, h));
            }
        }
    }
    // Boundary edges among the local points are constraints.
    if !chain.is_empty() {
        let local: FxHashMap<u32, FixedVertexHandle> = handles
            .iter()
            .copied()
            .chain(std::iter::once((i as u32, center)))
            .collect();
        // The local boundary edges, in the chain's own order (the order decides which of two
        // crossing constraints is kept): found from the local points, not by a walk over the
        // whole chain, which made the triangulation quadratic in the boundary samples.
        let mut edges: Vec<(usize, FixedVertexHandle, FixedVertexHandle)> = local
            .iter()
            .filter_map(|(a, &ha)| {
                let next = chain.get(a)?.1?;
                let &hb = local.get(&next)?;
                Some((chain_rank[a], ha, hb))
            })
            .collect();
        edges.sort_unstable_by_key(|e| e.0);
        for (_, ha, hb) in edges {
            if cdt.can_add_constraint(ha, hb) {
                cdt.add_constraint(ha, hb);
            }
        }
    }
    // The wedge of a boundary sample: from the direction of its next boundary neighbour
    // counter-clockwise to the previous one (the surface is on the left of prev → i → next).
    let wedge = chain.get(&(i as u32)).and_then(|&(prev, next)| {
        let dir = |j: u32| {
            let d = set.positions[j as usize] - pi;
            d.dot(v).atan2(d.dot(u))
        };
        Some((dir(next?), dir(prev?)))
    });
    let c = cdt.vertex(center);
    for e in c.out_edges() {
        let Some(face) = e.face().as_inner() else {
            continue;
        };
        let [a, b, cc] = face.vertices().map(|h| h.data().index);
        let tri = if a == i as u32 {
            [a, b, cc]
        } else if b == i as u32 {
            [b, cc, a]
        } else {
            [cc, a, b]
        };
        if let Some((start, end)) = wedge {
            let span = |j: u32| {
                let d = set.positions[j as usize] - pi;
                (d.dot(v).atan2(d.dot(u)) - start).rem_euclid(std::f64::consts::TAU)
            };
            let limit = (end - start).rem_euclid(std::f64::consts::TAU) + ANGLE_SLACK;
            let (s1, s2) = (span(tri[1]), span(tri[2]));
            // Both edges within the wedge, and the triangle turning counter-clockwise in it.
            let s1 = if s1 > std::f64::consts::TAU - ANGLE_SLACK {
                0.0
            } else {
                s1
            };
            if !(s1 <= limit && s2 <= limit && s2 > s1) {
                continue;
            }
        }
        out.push(tri);
    }
}

/// Computes every sample's umbrella and counts the votes of each triangle. The result is sorted
/// by corner indices (deterministic).
pub fn vote_triangles(set: &SampleSet, params: &TangentDelaunayParams) -> Vec<VotedTriangle> {
    let n = set.positions.len();
    let tree = StaticTree::new(set.positions);
    let mut chain: FxHashMap<u32, (Option<u32>, Option<u32>)> = FxHashMap::default();
    for &[a, b] in set.boundary_edges {
        chain.entry(a).or_insert((None, None)).1 = Some(b);
        chain.entry(b).or_insert((None, None)).0 = Some(a);
    }
    let chain_rank: FxHashMap<u32, usize> =
        chain.keys().enumerate().map(|(r, &a)| (a, r)).collect();
    let umbrellas: Vec<Vec<[u32; 3]>> = (0..n)
        .into_par_iter()
        .map_init(
            || (Vec::new(), Vec::new()),
            |(found, tris), i| {
                tree.nearest_n(set.positions[i], params.neighbors + 1, found);
                umbrella(i, set, found, params, &chain, &chain_rank, tris);
                tris.clone()
            },
        )
        .collect();
    let mut votes: FxHashMap<[u32; 3], VotedTriangle> = FxHashMap::default();
    for tris in &umbrellas {
        for &t in tris {
            let mut key = t;
            key.sort_unstable();
            let e = votes.entry(key).or_insert(VotedTriangle {
                corners: t,
                votes: 0,
                orientation_conflict: false,
            });
            e.votes = e.votes.saturating_add(1);
            if !same_orientation(e.corners, t) {
                e.orientation_conflict = true;
            }
        }
    }
    let mut all: Vec<([u32; 3], VotedTriangle)> = votes.into_iter().collect();
    all.sort_unstable_by_key(|x| x.0);
    all.into_iter().map(|x| x.1).collect()
}

/// Whether two triangles on the same three vertices have the same cyclic order.
pub fn same_orientation(a: [u32; 3], b: [u32; 3]) -> bool {
    let k = b.iter().position(|&x| x == a[0]);
    match k {
        Some(k) => b[(k + 1) % 3] == a[1],
        None => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use spade::DelaunayTriangulation;

    /// A jittered `n × n` grid of unit spacing in the plane z = 0 (fixed seed).
    fn jittered_grid(n: usize) -> Vec<DVec3> {
        let mut state = 7u64;
        let mut jitter = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.5
        };
        let mut out = Vec::new();
        for j in 0..n {
            for i in 0..n {
                out.push(DVec3::new(i as f64 + jitter(), j as f64 + jitter(), 0.0));
            }
        }
        out
    }

    /// Oracle: on a flat jittered grid, the triangles with three votes away from the border are
    /// exactly the triangles of the global 2D Delaunay triangulation there, oriented like the
    /// normals (counter-clockwise seen from +z).
    #[test]
    fn votes_on_a_flat_grid_give_the_delaunay_triangles() {
        let n = 14;
        let positions = jittered_grid(n);
        let normals = vec![DVec3::Z; positions.len()];
        let set = SampleSet {
            positions: &positions,
            normals: &normals,
            boundary_edges: &[],
        };
        let voted = vote_triangles(&set, &TangentDelaunayParams::default());
        let deep = |t: [u32; 3]| {
            t.iter().all(|&v| {
                let p = positions[v as usize];
                p.x > 3.0 && p.x < n as f64 - 4.0 && p.y > 3.0 && p.y < n as f64 - 4.0
            })
        };
        let mut dt: DelaunayTriangulation<Point2<f64>> = DelaunayTriangulation::new();
        for p in &positions {
            dt.insert(Point2::new(p.x, p.y)).expect("finite points");
        }
        let mut global: Vec<[u32; 3]> = dt
            .inner_faces()
            .map(|f| f.vertices().map(|v| v.fix().index() as u32))
            .filter(|&t| deep(t))
            .collect();
        let mut local: Vec<[u32; 3]> = voted
            .iter()
            .filter(|t| t.votes == 3 && deep(t.corners))
            .map(|t| {
                assert!(!t.orientation_conflict);
                t.corners
            })
            .collect();
        assert!(global.len() > 50, "{}", global.len());
        // Same triangles, same orientation: compare rotated to start at the smallest corner.
        let canonical = |t: [u32; 3]| {
            let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
            [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
        };
        global = global.into_iter().map(canonical).collect();
        local = local.into_iter().map(canonical).collect();
        global.sort_unstable();
        local.sort_unstable();
        assert_eq!(local, global);
    }

    #[test]
    fn orientation_is_the_cyclic_order() {
        assert!(same_orientation([1, 2, 3], [2, 3, 1]));
        assert!(same_orientation([1, 2, 3], [3, 1, 2]));
        assert!(!same_orientation([1, 2, 3], [1, 3, 2]));
        assert!(!same_orientation([1, 2, 3], [4, 5, 6]));
    }
}
