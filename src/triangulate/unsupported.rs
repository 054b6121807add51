//! Faces with no data under them: on a point set with holes (an open scan), the umbrellas and
//! the hole filling of the assembly close every small loop, also across a hole in the data. A
//! face whose centroid or an edge midpoint lies farther than a distance from every input point
//! spans such a hole; it is removed with the whole patch of hole-filling faces it belongs to
//! (the assembly's fill of that loop), and the vertices the removal pinches (two fans meeting
//! at one vertex) keep their largest fan (the assembly's own repair), so the output stays
//! manifold.

use glam::DVec3;
use rustc_hash::FxHashMap;

use crate::mesh::edit::{EditMesh, SlotPolicy};
use crate::mesh::TriMesh;
use crate::triangulate::cleanup::repair_pinched_vertices;
use crate::triangulate::FaceSource;

/// What [`remove_unsupported_faces`] removed.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct UnsupportedFaces {
    /// Faces spanning a gap in the data.
    pub faces: usize,
    /// Faces of the smaller fans at vertices the removal pinched.
    pub pinched_faces: usize,
}

/// Removes the faces of `mesh` with a point (centroid or edge midpoint) that `supported` says
/// has no data near it, each with the hole-filling faces joined to it through edges of
/// hole-filling faces (`sources[f]` is `FaceSource::HoleFill`: the fill of one loop goes as a
/// whole), then the smaller fans at pinched vertices, until every vertex has one fan. Vertices
/// stay (unreferenced ones are left for the caller); `sources` (one per face, or empty) is
/// filtered along. Deterministic.
pub fn remove_unsupported_faces(
    mesh: &mut TriMesh,
    sources: &mut Vec<FaceSource>,
    supported: impl Fn(DVec3) -> bool + Sync,
) -> UnsupportedFaces {
    use rayon::prelude::*;
    let p = &mesh.positions;
    let mut drop: Vec<bool> = mesh
        .triangles
        .par_iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| p[i as usize]);
            ![
                (a + b + c) / 3.0,
                (a + b) / 2.0,
                (b + c) / 2.0,
                (c + a) / 2.0,
            ]
            .into_iter()
            .all(&supported)
        })
        .collect();
    // The hole fills reached from a dropped face go too.
    let fill = |f: usize| sources.get(f) == Some(&FaceSource::HoleFill);
    let mut by_edge: FxHashMap<(u32, u32), Vec<usize>> = FxHashMap::default();
    for (f, t) in mesh.triangles.iter().enumerate() {
        if fill(f) {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                by_edge.entry((a.min(b), a.max(b))).or_default().push(f);
            }
        }
    }
    let mut stack: Vec<usize> = (0..drop.len()).filter(|&f| drop[f] && fill(f)).collect();
    while let Some(f) = stack.pop() {
        let t = mesh.triangles[f];
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            for &g in by_edge.get(&(a.min(b), a.max(b))).into_iter().flatten() {
                if !drop[g] {
                    drop[g] = true;
                    stack.push(g);
                }
            }
        }
    }
    remove_marked(mesh, sources, &drop)
}

/// Removes the faces of `mesh` with a corner that `near` says has no data near it (a vertex the
/// finishing left off the data, at the data's edge, where the centroid and edge midpoints of its
/// faces still are near some), then the smaller fans at pinched vertices, as
/// [`remove_unsupported_faces`] does (hole fills are not followed: the faces themselves are
/// the fault). Vertices stay; `sources` (one per face, or empty) is filtered along.
/// Deterministic.
pub fn remove_faces_off_data(
    mesh: &mut TriMesh,
    sources: &mut Vec<FaceSource>,
    near: impl Fn(DVec3) -> bool + Sync,
) -> UnsupportedFaces {
    use rayon::prelude::*;
    let off: Vec<bool> = mesh.positions.par_iter().map(|&p| !near(p)).collect();
    let drop: Vec<bool> = mesh
        .triangles
        .iter()
        .map(|t| t.iter().any(|&v| off[v as usize]))
        .collect();
    remove_marked(mesh, sources, &drop)
}

/// [`remove_faces_keeping_manifold`] with what it removed counted.
fn remove_marked(
    mesh: &mut TriMesh,
    sources: &mut Vec<FaceSource>,
    drop: &[bool],
) -> UnsupportedFaces {
    let faces = drop.iter().filter(|&&d| d).count();
    if faces == 0 {
        return UnsupportedFaces::default();
    }
    let pinched_faces = remove_faces_keeping_manifold(mesh, sources, drop);
    UnsupportedFaces {
        faces,
        pinched_faces,
    }
}

/// Removes the faces `drop` marks (one flag per face), then the smaller fans at the vertices
/// the removal pinched (two fans meeting at one vertex: the assembly's own repair), until every
/// vertex has one fan. Returns how many faces that repair removed. Vertices stay; `sources`
/// (one per face, or empty) is filtered along. Deterministic.
pub(crate) fn remove_faces_keeping_manifold(
    mesh: &mut TriMesh,
    sources: &mut Vec<FaceSource>,
    drop: &[bool],
) -> usize {
    let mut m: EditMesh<FaceSource> = EditMesh::from_trimesh(
        mesh,
        |f| {
            sources
                .get(f as usize)
                .copied()
                .unwrap_or(FaceSource::Refined)
        },
        SlotPolicy::Reuse,
    );
    for (f, _) in drop.iter().enumerate().filter(|(_, &d)| d) {
        // Every face of the mesh is live in `m`.
        let _ = m.remove_face(f as u32);
    }
    let mut pinched_faces = 0;
    // Removing a fan can pinch another vertex of it: repeat until none is left.
    loop {
        let n = repair_pinched_vertices(&mut m);
        if n == 0 {
            break;
        }
        pinched_faces += n;
    }
    let (_, triangles, labels) = m.into_parts();
    mesh.triangles = triangles;
    if !sources.is_empty() {
        *sources = labels;
    }
    pinched_faces
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::topology;

    /// An n × n grid of unit squares in the plane z = 0, two triangles each.
    fn grid(n: usize) -> TriMesh {
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                positions.push(DVec3::new(i as f64, j as f64, 0.0));
            }
        }
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mut triangles = Vec::new();
        for j in 0..n {
            for i in 0..n {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        TriMesh::new(positions, triangles)
    }

    #[test]
    fn faces_over_a_gap_go_and_the_rest_stays_manifold() {
        let mut mesh = grid(20);
        let faces = mesh.triangles.len();
        // No data within 2.5 of (10, 10): a hole about 5 wide.
        let stats = remove_unsupported_faces(&mut mesh, &mut Vec::new(), |p| {
            p.distance(DVec3::new(10.0, 10.0, 0.0)) > 2.5
        });
        assert!(stats.faces > 0);
        let t = topology(&mesh);
        assert!(t.is_manifold(), "{t:?}");
        assert_eq!(t.boundary_loops, 2, "{t:?}");
        assert_eq!(
            mesh.triangles.len() + stats.faces + stats.pinched_faces,
            faces
        );
        // Every face left has its points on the data.
        for tri in &mesh.triangles {
            let c = tri
                .iter()
                .map(|&i| mesh.positions[i as usize])
                .sum::<DVec3>()
                / 3.0;
            assert!(c.distance(DVec3::new(10.0, 10.0, 0.0)) > 2.5);
        }
    }

    #[test]
    fn faces_with_a_corner_off_the_data_go() {
        let mut mesh = grid(10);
        // The data covers x <= 6.5: the faces with a corner at x >= 7 go, the rest stay.
        let stats = remove_faces_off_data(&mut mesh, &mut Vec::new(), |p| p.x <= 6.5);
        assert_eq!(stats.faces, 2 * 10 * 4);
        assert_eq!(mesh.triangles.len(), 2 * 10 * 6);
        for t in &mesh.triangles {
            assert!(t.iter().all(|&v| mesh.positions[v as usize].x <= 6.0));
        }
        assert!(topology(&mesh).is_manifold());
    }

    #[test]
    fn a_pinch_keeps_the_larger_fan() {
        // Two holes touching at the vertex (10, 10) along the diagonal leave it pinched.
        let mut mesh = grid(20);
        let gap = |p: DVec3| {
            let d = p - DVec3::new(10.0, 10.0, 0.0);
            // Unsupported: two quadrants' corner regions near the vertex.
            !(d.x.abs() < 1.0 && d.y.abs() < 1.0 && d.x * d.y > 0.0)
        };
        let stats = remove_unsupported_faces(&mut mesh, &mut Vec::new(), gap);
        assert!(stats.faces > 0);
        let t = topology(&mesh);
        assert!(t.is_manifold(), "{t:?}");
        assert!(stats.pinched_faces > 0, "{stats:?}");
    }

    #[test]
    fn a_hole_fill_goes_as_a_whole() {
        // The grid's middle 4 × 4 squares marked as one hole fill; only one of its faces is
        // unsupported, yet all 32 go, and nothing else.
        let mut mesh = grid(10);
        let mut sources: Vec<FaceSource> = mesh
            .triangles
            .iter()
            .map(|t| {
                let c = t.iter().map(|&i| mesh.positions[i as usize]).sum::<DVec3>() / 3.0;
                if (3.0..7.0).contains(&c.x) && (3.0..7.0).contains(&c.y) {
                    FaceSource::HoleFill
                } else {
                    FaceSource::Refined
                }
            })
            .collect();
        let faces = mesh.triangles.len();
        let stats = remove_unsupported_faces(&mut mesh, &mut sources, |p| {
            p.distance(DVec3::new(5.3, 5.6, 0.0)) > 0.3
        });
        assert_eq!(stats.faces, 32, "{stats:?}");
        assert_eq!(mesh.triangles.len(), faces - 32);
        assert_eq!(sources.len(), mesh.triangles.len());
        assert!(!sources.contains(&FaceSource::HoleFill));
        assert_eq!(topology(&mesh).boundary_loops, 2);
    }

    #[test]
    fn fully_supported_meshes_are_untouched() {
        let mut mesh = grid(5);
        let before = mesh.clone();
        let stats = remove_unsupported_faces(&mut mesh, &mut Vec::new(), |_| true);
        assert_eq!(stats, UnsupportedFaces::default());
        assert_eq!(mesh.triangles, before.triangles);
    }
}
