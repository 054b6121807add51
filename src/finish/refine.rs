//! Refining the output where it is coarser than the input's sheets lie apart.
//!
//! Where two sheets of the input lie closer than the output's spacing (plates meeting at a
//! corner, a part's creases fanned out into long faces), the output's chords cut across the other
//! sheet, and untangle's presses cannot separate them: every vertex is already on its own sheet,
//! and the faces are too large to move apart without leaving it (or their corners are fixed
//! crease samples). This operator splits the edges of each such face at the surface, so that the
//! faces follow their sheet closer; untangle then separates what is left (`pipeline/finish.rs`
//! runs it in rounds). It is red-green refinement's first half: every edge of a marked face is
//! split, its neighbours across those edges with it (the edge split keeps the mesh conforming);
//! the last pass of the optimization then mends the angles.

#[cfg(test)]
use glam::DVec3;
use serde::Serialize;

use crate::mesh::edit::{EditMesh, SlotPolicy};
use crate::mesh::TriMesh;
use crate::surface::SurfaceQuery;

/// Parameters of [`refine_faces`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RefineCrossingsParams {
    /// Rounds of refinement and untangling at most (`pipeline/finish.rs`). Default 4: each
    /// round halves the edges where crossings are left, so four take them to a sixteenth.
    pub max_rounds: usize,
    /// Edges shorter than this are not split (σ_p units). Default 1/16.
    pub min_edge_sigma_p: f64,
    /// The splits of all rounds together at most this share of the mesh's vertices when the
    /// rounds begin (rounded up): a bound on the work where the rounds do not separate the
    /// sheets, since each round can double the faces that cross (a folded sliver box at 161
    /// points, `tests/fuzz/remesh-coincident-seam-curves.obj`: 7,844 splits in 8 rounds and
    /// 60 s, all taken back). Default 1/4; the corpus at 3000 needs at most 200 (cycloidal.ply,
    /// chair_model.obj 115, box.STL 21).
    pub max_splits_per_vertex: f64,
}

impl Default for RefineCrossingsParams {
    fn default() -> Self {
        RefineCrossingsParams {
            max_rounds: 8,
            min_edge_sigma_p: 1.0 / 16.0,
            max_splits_per_vertex: 0.25,
        }
    }
}

/// What the rounds of refinement did (summed over rounds).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct RefineCrossingsStats {
    /// Rounds run.
    pub rounds: usize,
    /// Edges split.
    pub splits: usize,
    /// Edges of marked faces not split: on the boundary, kept creases, shorter than
    /// `min_edge_sigma_p`, or whose surface point lies on a sheet facing away from the edge's faces.
    pub refused: usize,
    /// Pairs of faces that cross outside the input's own crossings before the first round.
    pub pairs_before: usize,
    /// The same after the last round.
    pub pairs_after: usize,
}

/// Splits each edge of the faces `faces` (indices into `mesh.triangles`) at the point nearest
/// its middle of the sheet the edge follows: the surface's pieces facing the way of the mean
/// normal of the edge's two faces ([`SurfaceQuery::closest_point_facing`]), within half the
/// edge's length (its ends lie on the surface), so that a nearer sheet facing away (another
/// part's wall, the far side of a thin plate) is passed over. Not split: boundary edges, edges
/// in `protected` (kept creases, either direction), edges shorter than `min_edge`, and edges
/// with no such sheet that close. Longest edges first, ties by vertex index: deterministic.
/// Positions in bbox-100 units.
///
/// At most `max_splits` splits: the longest edges past them are left (not counted as refused).
///
/// Returns the edges split and refused, and each face's index before (`None` for a face a split
/// made). The new vertices are appended to `mesh.positions`.
pub fn refine_faces<S: SurfaceQuery + ?Sized>(
    mesh: &mut TriMesh,
    surface: &S,
    faces: &[u32],
    protected: &[[u32; 2]],
    min_edge: f64,
    max_splits: usize,
) -> (usize, usize, Vec<Option<u32>>) {
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let protected: rustc_hash::FxHashSet<(u32, u32)> =
        protected.iter().map(|e| key(e[0], e[1])).collect();
    let mut edges: Vec<(u32, u32)> = faces
        .iter()
        .flat_map(|&f| {
            let t = mesh.triangles[f as usize];
            (0..3).map(move |k| key(t[k], t[(k + 1) % 3]))
        })
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let length =
        |&(a, b): &(u32, u32)| mesh.positions[a as usize].distance(mesh.positions[b as usize]);
    edges.sort_by(|x, y| length(y).total_cmp(&length(x)).then(x.cmp(y)));
    let mut m: EditMesh<Option<u32>> = EditMesh::from_trimesh(mesh, Some, SlotPolicy::Reuse);
    let (mut splits, mut refused) = (0, 0);
    for (a, b) in edges {
        if splits >= max_splits {
            break;
        }
        let (pa, pb) = (m.position(a), m.position(b));
        if protected.contains(&(a, b)) || pa.distance(pb) < min_edge {
            refused += 1;
            continue;
        }
        let Ok((f1, f2, _, _)) = m.edge_faces(a, b) else {
            refused += 1;
            continue;
        };
        let normal = |f: u32| {
            let [p, q, r] = m.corners(m.face(f).expect("a live face"));
            (q - p).cross(r - p).normalize_or_zero()
        };
        // The edge's ends lie on the surface, half its length from its middle: the sheet the
        // edge follows is within that, facing its faces' way.
        let facing = normal(f1) + normal(f2);
        let Some(sp) = surface.closest_point_facing(0.5 * (pa + pb), facing, 0.5 * pa.distance(pb))
        else {
            refused += 1;
            continue;
        };
        let v = m.add_vertex(sp.position);
        if m.split_edge(a, b, v, None).is_ok() {
            splits += 1;
        } else {
            m.pop_vertex();
            refused += 1;
        }
    }
    let (positions, triangles, origin) = m.into_parts();
    mesh.positions = positions;
    mesh.triangles = triangles;
    (splits, refused, origin)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::MeshSurface;

    /// A bent strip: two squares meeting at a crease along x = 1 (the second tilted up), each as
    /// two triangles. Its coarse version spans the crease with a single chord plane.
    fn bent() -> TriMesh {
        let p = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 1.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(2.0, 1.0, 1.0),
        ];
        TriMesh::new(p, vec![[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]])
    }

    #[test]
    fn the_edges_of_a_marked_face_are_split_at_the_surface() {
        let surface_mesh = bent();
        let surface = MeshSurface::new(&surface_mesh).unwrap();
        // The coarse mesh: one chord from x = 0 to x = 2 (it cuts under the crease).
        let mut coarse = TriMesh::new(
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(2.0, 0.0, 1.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(2.0, 1.0, 1.0),
            ],
            vec![[0, 1, 3], [0, 3, 2]],
        );
        let (splits, refused, origin) =
            refine_faces(&mut coarse, &surface, &[0], &[], 0.01, usize::MAX);
        // Of face 0's edges only the diagonal 0-3 is interior.
        assert_eq!((splits, refused), (1, 2));
        assert_eq!(coarse.positions.len(), 5);
        assert_eq!(coarse.triangles.len(), 4);
        assert!(origin.iter().all(Option::is_none));
        // The new vertex is on the surface, the point nearest the diagonal's middle (1, 0.5,
        // 0.5): on the tilted square, 1/(2√2) away, not the chord's middle.
        let q = coarse.positions[4];
        assert!(surface.closest_point(q).unwrap().distance < 1e-12);
        assert!((q - DVec3::new(1.25, 0.5, 0.25)).length() < 1e-12, "{q}");
        // No split past the bound on splits.
        let mut bounded = coarse.clone();
        let mut unbounded = coarse.clone();
        let (all, _, _) = refine_faces(
            &mut unbounded,
            &surface,
            &[0, 1, 2, 3],
            &[],
            0.01,
            usize::MAX,
        );
        assert!(all > 2, "{all}");
        let (s, _, _) = refine_faces(&mut bounded, &surface, &[0, 1, 2, 3], &[], 0.01, 2);
        assert_eq!(s, 2);
        assert_eq!(bounded.positions.len(), coarse.positions.len() + 2);
        // A protected edge, or one shorter than the bound, is left.
        let mut again = coarse.clone();
        let (s, _, _) = refine_faces(
            &mut again,
            &surface,
            &[0, 1, 2, 3],
            &[[0, 4], [4, 3]],
            10.0,
            usize::MAX,
        );
        assert_eq!(s, 0);
        assert_eq!(again.triangles, coarse.triangles);
    }

    /// Two parts' walls a hair apart (box.STL's parts lie 0.001 to 0.005 apart where the
    /// spacing is 0.32): the edge follows the upper wall, a low ridge facing up, and its chord
    /// passes under the ridge, nearer the lower wall, which faces down. The split point is on
    /// the ridge, not on the nearer wall.
    #[test]
    fn the_split_point_is_on_the_sheet_the_edge_follows_past_a_nearer_one_facing_away() {
        let p = vec![
            // The ridge: z = 0 at x = 0 and 2, 0.05 along x = 1; faces up.
            DVec3::new(0.0, -1.0, 0.0),
            DVec3::new(1.0, -1.0, 0.05),
            DVec3::new(2.0, -1.0, 0.0),
            DVec3::new(0.0, 3.0, 0.0),
            DVec3::new(1.0, 3.0, 0.05),
            DVec3::new(2.0, 3.0, 0.0),
            // The lower wall at z = -0.01; faces down.
            DVec3::new(-1.0, -1.0, -0.01),
            DVec3::new(3.0, -1.0, -0.01),
            DVec3::new(3.0, 3.0, -0.01),
            DVec3::new(-1.0, 3.0, -0.01),
        ];
        let walls = TriMesh::new(
            p,
            vec![
                [0, 1, 4],
                [0, 4, 3],
                [1, 2, 5],
                [1, 5, 4],
                [6, 8, 7],
                [6, 9, 8],
            ],
        );
        let surface = MeshSurface::new(&walls).unwrap();
        // A coarse square over the ridge, its corners on the ridge's feet, facing up.
        let mut coarse = TriMesh::new(
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(2.0, 0.0, 0.0),
                DVec3::new(2.0, 2.0, 0.0),
                DVec3::new(0.0, 2.0, 0.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        let mid = 0.5 * (coarse.positions[0] + coarse.positions[2]);
        let near = surface.closest_point(mid).unwrap();
        assert!(near.face >= 4, "the lower wall is nearer: {near:?}");
        let (splits, _, _) = refine_faces(&mut coarse, &surface, &[0], &[], 0.01, usize::MAX);
        assert_eq!(splits, 1);
        // The foot of (1, 1, 0) on the ridge's plane z = 0.05 x.
        let q = coarse.positions[4];
        let foot = DVec3::new(1.0 - 0.0025 / 1.0025, 1.0, 0.05 / 1.0025);
        assert!((q - foot).length() < 1e-12, "{q}");
    }

    #[test]
    fn a_surface_point_on_a_sheet_facing_away_is_refused() {
        // The surface: a square facing down, under the mesh's square facing up.
        let below = TriMesh::new(
            vec![
                DVec3::new(0.0, 0.0, -0.1),
                DVec3::new(1.0, 0.0, -0.1),
                DVec3::new(0.0, 1.0, -0.1),
                DVec3::new(1.0, 1.0, -0.1),
            ],
            vec![[0, 2, 3], [0, 3, 1]],
        );
        let surface = MeshSurface::new(&below).unwrap();
        let mut up = TriMesh::new(
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
            ],
            vec![[0, 1, 3], [0, 3, 2]],
        );
        let (splits, refused, _) = refine_faces(&mut up, &surface, &[0, 1], &[], 0.01, usize::MAX);
        assert_eq!((splits, refused), (0, 5));
        // Facing up, the same sheet is taken.
        let above = TriMesh::new(below.positions.clone(), vec![[0, 3, 2], [0, 1, 3]]);
        let surface = MeshSurface::new(&above).unwrap();
        let (splits, _, _) = refine_faces(&mut up, &surface, &[0, 1], &[], 0.01, usize::MAX);
        assert_eq!(splits, 1);
    }
}
