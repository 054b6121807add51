//! The parts of a triangle mesh: its faces grouped by shared vertices (the components the
//! report counts), each with its vertices and whether it is closed.

use crate::disjoint_sets::Dsu;
use rustc_hash::FxHashMap;

use super::TriMesh;

/// One part of a mesh: faces joined through shared vertices.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Part {
    /// Its faces (indices into `mesh.triangles`, increasing).
    pub faces: Vec<usize>,
    /// Its vertices, sorted, each once.
    pub vertices: Vec<u32>,
    /// Whether every edge of its faces is in exactly two of them (no boundary, no
    /// non-manifold edge).
    pub closed: bool,
}

/// The parts of `mesh`, in the order of their first face. Time O(F α(V)) plus a hash of the
/// edges ([`TriMesh::edge_uses`]). Indices must be in range.
pub(crate) fn parts(mesh: &TriMesh) -> Vec<Part> {
    let mut sets = Dsu::new(mesh.positions.len());
    for t in &mesh.triangles {
        for k in 1..3 {
            sets.union(t[0] as usize, t[k] as usize, false);
        }
    }
    let mut index_of: FxHashMap<usize, usize> = FxHashMap::default();
    let mut faces_of: Vec<Vec<usize>> = Vec::new();
    for (f, t) in mesh.triangles.iter().enumerate() {
        let root = sets.find(t[0] as usize).0;
        let k = *index_of.entry(root).or_insert_with(|| {
            faces_of.push(Vec::new());
            faces_of.len() - 1
        });
        faces_of[k].push(f);
    }
    // A part is closed when no edge of its faces is in other than two of them.
    let mut closed = vec![true; faces_of.len()];
    for (_, ([f, _], uses)) in mesh.edge_uses() {
        if uses != 2 {
            closed[index_of[&sets.find(mesh.triangles[f as usize][0] as usize).0]] = false;
        }
    }
    faces_of
        .into_iter()
        .zip(closed)
        .map(|(faces, closed)| {
            let mut vertices: Vec<u32> = faces.iter().flat_map(|&f| mesh.triangles[f]).collect();
            vertices.sort_unstable();
            vertices.dedup();
            Part {
                faces,
                vertices,
                closed,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes::cuboid;
    use glam::DVec3;

    #[test]
    fn a_box_and_an_open_triangle_are_two_parts_one_closed() {
        let mut m = cuboid(DVec3::ZERO, DVec3::ONE);
        let o = m.positions.len() as u32;
        m.positions.extend([
            DVec3::splat(2.0),
            DVec3::new(3.0, 2.0, 2.0),
            DVec3::new(2.0, 3.0, 2.0),
        ]);
        m.triangles.push([o, o + 1, o + 2]);
        let p = parts(&m);
        assert_eq!(p.len(), 2);
        assert!(p[0].closed && !p[1].closed);
        assert_eq!(p[0].faces.len(), 12);
        assert_eq!(p[0].vertices.len(), 8);
        assert_eq!(p[1].faces, vec![12]);
        assert_eq!(p[1].vertices, vec![o, o + 1, o + 2]);
    }
}
