//! The last resort of an open output (a point set's mesh): faces that still intersect once the
//! finishing stage is done (where the data holds sheets closer than the output's spacing, such
//! as a scanner's view through glass, and untangle's moves and collapses ran out) are removed.
//! A hole in an open mesh is a smaller fault than a crossing: the output's own check and CGAL's
//! `does_self_intersect` then find none.
//!
//! Which faces go: a greedy cover of the intersecting pairs (the standard definition of
//! [`intersecting_pairs`]: apart and meeting, sharing a vertex and meeting elsewhere too, sharing
//! an edge and overlapping), the face in most pairs first, so a face that crosses many loses
//! itself rather than each of them. The removal keeps the mesh manifold (the smaller fans at
//! the vertices it pinches go too, [`remove_faces_keeping_manifold`]). Removing faces makes no
//! face cross and no angle smaller.

use rustc_hash::FxHashMap;

use crate::geometry::self_intersection::intersecting_pairs;
use crate::mesh::TriMesh;
use crate::triangulate::unsupported::remove_faces_keeping_manifold;
use crate::triangulate::FaceSource;

/// What [`remove_crossing_faces`] removed.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct CrossingFaces {
    /// Intersecting pairs found.
    pub pairs: usize,
    /// Faces removed to leave none.
    pub faces: usize,
    /// Faces of the smaller fans at the vertices the removal pinched.
    pub pinched_faces: usize,
}

/// Removes faces of `mesh` until no two intersect (see the module's text); `sources` (one per
/// face, or empty) is filtered along. Vertices stay (unreferenced ones are left for the caller).
/// Deterministic: the same mesh gives the same faces removed.
pub fn remove_crossing_faces(mesh: &mut TriMesh, sources: &mut Vec<FaceSource>) -> CrossingFaces {
    let pairs = intersecting_pairs(&mesh.positions, &mesh.triangles);
    remove_faces_of_pairs(mesh, sources, &pairs)
}

/// [`remove_crossing_faces`] with the intersecting pairs of `mesh` known (face indices, as
/// [`intersecting_pairs`] gives them). Removing faces makes no new pair: the faces left cross
/// none.
pub fn remove_faces_of_pairs(
    mesh: &mut TriMesh,
    sources: &mut Vec<FaceSource>,
    pairs: &[[u32; 2]],
) -> CrossingFaces {
    if pairs.is_empty() {
        return CrossingFaces::default();
    }
    let drop = cover(pairs, mesh.triangles.len());
    CrossingFaces {
        pairs: pairs.len(),
        faces: drop.iter().filter(|&&d| d).count(),
        pinched_faces: remove_faces_keeping_manifold(mesh, sources, &drop),
    }
}

/// A greedy cover of `pairs` (face indices below `faces`): one flag per face, set for the faces
/// removed. The faces in most pairs are taken first (ties: the lower index), each only while one
/// of its pairs is not yet covered.
fn cover(pairs: &[[u32; 2]], faces: usize) -> Vec<bool> {
    let mut pairs_of: FxHashMap<u32, Vec<usize>> = FxHashMap::default();
    for (k, pair) in pairs.iter().enumerate() {
        for &f in pair {
            pairs_of.entry(f).or_default().push(k);
        }
    }
    let mut order: Vec<(u32, usize)> = pairs_of.iter().map(|(&f, ks)| (f, ks.len())).collect();
    order.sort_unstable_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    let mut covered = vec![false; pairs.len()];
    let mut drop = vec![false; faces];
    for (f, _) in order {
        let ks = &pairs_of[&f];
        if ks.iter().any(|&k| !covered[k]) {
            drop[f as usize] = true;
            for &k in ks {
                covered[k] = true;
            }
        }
    }
    drop
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::check::topology;

    /// An n × n grid of unit squares in the plane z = `z`, two triangles each, its vertices
    /// numbered from `first`.
    fn grid(n: usize, z: f64, first: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                positions.push(DVec3::new(i as f64, j as f64, z));
            }
        }
        let id = |i: usize, j: usize| first + (j * (n + 1) + i) as u32;
        let mut triangles = Vec::new();
        for j in 0..n {
            for i in 0..n {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        (positions, triangles)
    }

    #[test]
    fn a_sheet_through_another_loses_the_faces_that_cross_and_nothing_else() {
        // A 10 × 10 sheet at z = 0 and a 2 × 2 sheet standing upright through its middle.
        let (mut positions, mut triangles) = grid(10, 0.0, 0);
        let first = positions.len() as u32;
        for j in 0..3 {
            for i in 0..3 {
                positions.push(DVec3::new(4.3 + i as f64, 5.5, -1.0 + j as f64));
            }
        }
        let id = |i: u32, j: u32| first + j * 3 + i;
        for j in 0..2 {
            for i in 0..2 {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let mut mesh = TriMesh::new(positions, triangles);
        let before = mesh.triangles.len();
        let pairs_before = intersecting_pairs(&mesh.positions, &mesh.triangles).len();
        assert!(pairs_before > 0);
        let stats = remove_crossing_faces(&mut mesh, &mut Vec::new());
        assert!(intersecting_pairs(&mesh.positions, &mesh.triangles).is_empty());
        assert_eq!(stats.pairs, pairs_before);
        assert_eq!(
            mesh.triangles.len() + stats.faces + stats.pinched_faces,
            before
        );
        // A cover, not every face of every pair: fewer faces than the pairs' faces.
        assert!(stats.faces < 2 * pairs_before, "{stats:?}");
        assert!(topology(&mesh).is_manifold());
    }

    #[test]
    fn a_fold_at_a_shared_vertex_is_found_and_removed() {
        // A fan of four faces around the origin with one face folded back over its neighbour:
        // the two share a vertex (the hub) and overlap elsewhere.
        let positions = vec![
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(-1.0, 0.0, 0.0),
            DVec3::new(0.0, -1.0, 0.0),
            DVec3::new(0.6, 0.3, 0.0),
        ];
        // [0, 4, 5] lies over [0, 1, 2]'s interior at z = 0 and shares vertex 0 with it.
        let triangles = vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]];
        let mut mesh = TriMesh::new(positions, triangles);
        assert!(!intersecting_pairs(&mesh.positions, &mesh.triangles).is_empty());
        let stats = remove_crossing_faces(&mut mesh, &mut Vec::new());
        assert!(stats.faces >= 1);
        assert!(intersecting_pairs(&mesh.positions, &mesh.triangles).is_empty());
    }

    #[test]
    fn a_mesh_without_crossings_is_left_as_it_is() {
        let (positions, triangles) = grid(6, 0.0, 0);
        let mut mesh = TriMesh::new(positions, triangles.clone());
        let stats = remove_crossing_faces(&mut mesh, &mut Vec::new());
        assert_eq!(stats, CrossingFaces::default());
        assert_eq!(mesh.triangles, triangles);
    }

    #[test]
    fn the_face_in_most_pairs_goes_first() {
        // Three disjoint pairs all sharing face 0: the cover takes face 0 alone.
        let pairs = [[0, 1], [0, 2], [0, 3]];
        let drop = cover(&pairs, 4);
        assert_eq!(drop, vec![true, false, false, false]);
    }
}
