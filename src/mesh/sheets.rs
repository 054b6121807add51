//! The sheets of a mesh whose parts meet at non-manifold edges: the faces joined across edges of
//! exactly two faces. Two closed parts of a scene that share an edge (a cube and a tetrahedron
//! in its corner, two boxes of a building on one edge, STL solids welded where they touch) are
//! two closed sheets; a manifold mesh's sheets are its components. [`Sheets::split`] gives each
//! closed sheet its own copy of the vertices of the non-manifold edges it shares with another
//! part, so that a walk over the mesh's vertices (the restricted Voronoi cells' growth) stays
//! on one part. Open sheets that meet at an edge (a scan's fins on its body) are one surface
//! and stay joined: split apart, a sheet with a few samples came out in pieces (see
//! `docs/decisions/restricted-delaunay-default.md`).

use super::TriMesh;

/// The sheets of a mesh and the vertices where they meet.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Sheets {
    /// `of_face[f]`: the sheet of face `f`, named by its first face. Faces joined across an
    /// edge of exactly two faces are on one sheet.
    pub of_face: Vec<u32>,
    /// `part[f]`: the part of face `f` that the triangulation keeps apart from the others: its
    /// sheet when that sheet is closed (each of its edges has two of its own faces: the whole
    /// surface of a solid), or
    /// [`OPEN`] for every open sheet (pieces of one surface that meet at an edge, as a scan's
    /// fins, stay one surface).
    pub part: Vec<u32>,
    /// The junction: vertices of an edge of more than two faces that faces of two or more
    /// parts use, ascending.
    pub junction: Vec<u32>,
}

/// The part of every open sheet (see [`Sheets::part`]).
pub const OPEN: u32 = u32::MAX;

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
        // A sheet is closed when each of its edges has exactly two of its own faces (a cube
        // whose edge a tetrahedron also uses is closed; a fin of one face on a non-manifold
        // edge is not).
        let mut closed = vec![true; n];
        let mut on_edge: Vec<u32> = Vec::new();
        for group in sides.chunk_by(|a, b| (a.0, a.1) == (b.0, b.1)) {
            on_edge.clear();
            on_edge.extend(group.iter().map(|x| of_face[x.2 as usize]));
            on_edge.sort_unstable();
            for run in on_edge.chunk_by(|a, b| a == b) {
                if run.len() != 2 {
                    closed[run[0] as usize] = false;
                }
            }
        }
        let part: Vec<u32> = of_face
            .iter()
            .map(|&s| if closed[s as usize] { s } else { OPEN })
            .collect();
        // A vertex of a non-manifold edge is on the junction when two parts use it.
        let mut first = vec![u32::MAX; mesh.positions.len()];
        let mut junction = vec![false; mesh.positions.len()];
        for (t, &s) in mesh.triangles.iter().zip(&part) {
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
            part,
            junction: (0..junction.len() as u32)
                .filter(|&v| junction[v as usize])
                .collect(),
        }
    }

    /// `mesh` (the mesh these sheets are of) with every junction vertex copied once per part
    /// that uses it, so that a walk over the vertices stays on one part (the faces keep their
    /// indices and order; a vertex's first part keeps its index, the copies come after the
    /// mesh's vertices), or `None` when there is no junction. Where parts touch only at a
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
            .zip(&self.part)
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
        assert_eq!(s.part, s.of_face);
        assert_eq!(s.junction, vec![0, 1]);
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
    fn open_sheets_meeting_at_an_edge_stay_one_surface() {
        // Three fins on the edge 0-1 (a T-junction of open sheets), and a closed tetrahedron on
        // the same edge: only the tetrahedron is kept apart.
        let mut m = two_tetrahedra_on_an_edge();
        m.triangles.truncate(4);
        let fins = [
            DVec3::new(0.5, -1.0, 0.0),
            DVec3::new(0.5, 0.0, -1.0),
            DVec3::new(0.5, -1.0, -1.0),
        ];
        for (k, p) in fins.into_iter().enumerate() {
            m.positions.push(p);
            m.triangles.push([0, 1, 4 + k as u32]);
        }
        let s = Sheets::new(&m);
        assert_eq!(&s.part[4..], &[OPEN; 3]);
        assert_eq!(s.junction, vec![0, 1]);
        let split = s.split(&m).unwrap();
        // The fins keep 0 and 1 (the first part there is the tetrahedron's, so they get one
        // copy each, shared by all three fins).
        assert_eq!(split.positions.len(), m.positions.len() + 2);
        assert_eq!(split.triangles[4][..2], split.triangles[5][..2]);
        assert_eq!(split.triangles[4][..2], split.triangles[6][..2]);
        let only_fins = TriMesh::new(m.positions.clone(), m.triangles[4..].to_vec());
        assert!(Sheets::new(&only_fins).junction.is_empty());
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
