//! The sheets of a mesh whose parts meet at non-manifold edges: the faces joined across edges of
//! exactly two faces. Two closed parts of a scene that share an edge or a corner (a cube and a
//! tetrahedron in its corner, two boxes of a building on one edge, STL solids welded where they
//! touch) are two sheets; a manifold mesh's sheets are its components. [`Sheets::split`] gives
//! each sheet its own copy of the vertices of the non-manifold edges it shares with another, so
//! that a walk over the mesh's vertices (the restricted Voronoi cells' growth) stays on one
//! sheet.

use super::TriMesh;

/// The sheets of a mesh and the vertices where they meet.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Sheets {
    /// `of_face[f]`: the sheet of face `f`, named by its first face. Faces joined across an
    /// edge of exactly two faces are on one sheet.
    pub of_face: Vec<u32>,
    /// The junction: vertices of an edge of more than two faces that faces of two or more
    /// sheets use, ascending.
    pub junction: Vec<u32>,
}

impl Sheets {
    /// The sheets of `mesh` (indices in range). O(faces · log faces).
    pub fn new(mesh: &TriMesh) -> Self {
        let n = mesh.triangles.len();
        // Face sides by edge: (lo, hi, face).
        let mut sides: Vec<(u32, u32, u32)> = Vec::with_capacity(3 * n);
        for (f, t) in mesh.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                sides.push((a.min(b), a.max(b), f as u32));
            }
        }
        sides.sort_unstable();
        let mut parent: Vec<u32> = (0..n as u32).collect();
        fn root(parent: &mut [u32], mut x: u32) -> u32 {
            while parent[x as usize] != x {
                parent[x as usize] = parent[parent[x as usize] as usize];
                x = parent[x as usize];
            }
            x
        }
        let mut on_non_manifold_edge = vec![false; mesh.positions.len()];
        for group in sides.chunk_by(|a, b| (a.0, a.1) == (b.0, b.1)) {
            match group {
                [a, b] => {
                    let (ra, rb) = (root(&mut parent, a.2), root(&mut parent, b.2));
                    // The smaller root wins, so a sheet is named by its first face.
                    parent[ra.max(rb) as usize] = ra.min(rb);
                }
                [e, _, _, ..] => {
                    on_non_manifold_edge[e.0 as usize] = true;
                    on_non_manifold_edge[e.1 as usize] = true;
                }
                _ => {}
            }
        }
        let of_face: Vec<u32> = (0..n as u32).map(|f| root(&mut parent, f)).collect();
        // A vertex of a non-manifold edge is on the junction when two sheets use it.
        let mut first = vec![u32::MAX; mesh.positions.len()];
        let mut junction = vec![false; mesh.positions.len()];
        for (t, &s) in mesh.triangles.iter().zip(&of_face) {
            for &v in t {
                let v = v as usize;
                if !on_non_manifold_edge[v] {
                    continue;
                }
                if first[v] == u32::MAX {
                    first[v] = s;
                } else if first[v] != s {
                    junction[v] = true;
                }
            }
        }
        Sheets {
            of_face,
            junction: (0..junction.len() as u32)
                .filter(|&v| junction[v as usize])
                .collect(),
        }
    }

    /// `mesh` (the mesh these sheets are of) with every junction vertex copied once per sheet
    /// that uses it, so that a walk over the vertices stays on one sheet (the faces keep their
    /// indices and order; a vertex's first sheet keeps its index, the copies come after the
    /// mesh's vertices), or `None` when there is no junction. Where sheets touch only at a
    /// corner, no edge joins them and they stay joined there. O(faces).
    pub fn split(&self, mesh: &TriMesh) -> Option<TriMesh> {
        if self.junction.is_empty() {
            return None;
        }
        let mut is_junction = vec![false; mesh.positions.len()];
        for &v in &self.junction {
            is_junction[v as usize] = true;
        }
        let mut first = vec![u32::MAX; mesh.positions.len()];
        let mut positions = mesh.positions.clone();
        let mut copies: rustc_hash::FxHashMap<(u32, u32), u32> = Default::default();
        let triangles = mesh
            .triangles
            .iter()
            .zip(&self.of_face)
            .map(|(t, &s)| {
                t.map(|v| {
                    let i = v as usize;
                    if !is_junction[i] {
                        return v;
                    }
                    if first[i] == u32::MAX {
                        first[i] = s;
                    }
                    if first[i] == s {
                        v
                    } else {
                        *copies.entry((v, s)).or_insert_with(|| {
                            positions.push(mesh.positions[i]);
                            (positions.len() - 1) as u32
                        })
                    }
                })
            })
            .collect();
        Some(TriMesh::new(positions, triangles))
    }

    /// The faces that have a corner on the junction, ascending.
    pub fn junction_faces(&self, mesh: &TriMesh) -> Vec<u32> {
        if self.junction.is_empty() {
            return Vec::new();
        }
        let mut is_junction = vec![false; mesh.positions.len()];
        for &v in &self.junction {
            is_junction[v as usize] = true;
        }
        (0..mesh.triangles.len() as u32)
            .filter(|&f| {
                mesh.triangles[f as usize]
                    .iter()
                    .any(|&v| is_junction[v as usize])
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// Two tetrahedra that share the edge 0-1 (and nothing else).
    fn two_tetrahedra_on_an_edge() -> TriMesh {
        let p = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(0.5, 1.0, 0.0),
            DVec3::new(0.5, 0.5, 1.0),
            DVec3::new(0.5, -1.0, 0.0),
            DVec3::new(0.5, -0.5, -1.0),
        ];
        TriMesh::new(
            p,
            vec![
                [0, 2, 1],
                [0, 1, 3],
                [1, 2, 3],
                [2, 0, 3],
                [0, 1, 4],
                [0, 5, 1],
                [1, 5, 4],
                [4, 5, 0],
            ],
        )
    }

    #[test]
    fn parts_meeting_at_an_edge_are_two_sheets_and_split_there() {
        let m = two_tetrahedra_on_an_edge();
        let s = Sheets::new(&m);
        assert_eq!(s.of_face, vec![0, 0, 0, 0, 4, 4, 4, 4]);
        assert_eq!(s.junction, vec![0, 1]);
        assert_eq!(s.junction_faces(&m), (0..8).collect::<Vec<u32>>());
        let split = s.split(&m).unwrap();
        // Vertices 0 and 1 get one copy each, for the second tetrahedron.
        assert_eq!(split.positions.len(), 8);
        assert_eq!(split.triangles[..4], m.triangles[..4]);
        let used: Vec<u32> = split.triangles[4..].iter().flatten().copied().collect();
        assert!(!used.contains(&0) && !used.contains(&1));
        assert!(used.contains(&6) && used.contains(&7));
        assert_eq!(split.positions[6], m.positions[0]);
        assert_eq!(split.positions[7], m.positions[1]);
    }

    #[test]
    fn a_manifold_mesh_is_not_split() {
        let m = two_tetrahedra_on_an_edge();
        let one = TriMesh::new(m.positions.clone(), m.triangles[..4].to_vec());
        let s = Sheets::new(&one);
        assert_eq!(s.of_face, vec![0; 4]);
        assert!(s.junction.is_empty());
        assert!(s.split(&one).is_none());
    }

    #[test]
    fn parts_touching_at_a_corner_only_are_not_split() {
        // The second tetrahedron moved to share only vertex 0 with the first.
        let mut m = two_tetrahedra_on_an_edge();
        m.positions.push(DVec3::new(-1.0, -0.2, 0.1));
        for t in &mut m.triangles[4..] {
            for v in t.iter_mut() {
                if *v == 1 {
                    *v = 6;
                }
            }
        }
        let s = Sheets::new(&m);
        assert_eq!(s.of_face, vec![0, 0, 0, 0, 4, 4, 4, 4]);
        assert!(s.junction.is_empty());
        assert!(s.split(&m).is_none());
    }
}
