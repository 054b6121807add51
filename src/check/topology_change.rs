//! How an output's topology differs from its input's: the components, the Euler characteristic
//! and the boundary loops, compared one by one.
//!
//! Source: the Euler–Poincaré formula χ = 2c − 2g − b for orientable compact surfaces (e.g.
//! Botsch, Kobbelt, Pauly, Alliez, Lévy, *Polygon Mesh Processing*, 2010, Ch. 1): with the
//! components c, χ and the boundary loops b equal, the genus is equal too, so these three
//! counts say whether a remesh kept the surface's topology.

use std::fmt;

use serde::Serialize;

use crate::geometry::triangle::is_degenerate_face;
use crate::mesh::topology::{topology, Topology};
use crate::mesh::TriMesh;

/// One count of [`Topology`] that differs between an input and its remesh. Serialized with a
/// `kind` tag (`Components`, `EulerCharacteristic`, `BoundaryLoops`) and the two values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(tag = "kind")]
pub enum TopologyChange {
    /// Connected components (faces joined through shared vertices): a part split off or two
    /// parts fused.
    Components {
        /// The input's count.
        input: usize,
        /// The output's count.
        output: usize,
    },
    /// χ = V − E + F: a handle or a tunnel made or closed, or a part split off or fused.
    EulerCharacteristic {
        /// The input's χ.
        input: i64,
        /// The output's χ.
        output: i64,
    },
    /// Boundary loops: holes opened, closed or merged.
    BoundaryLoops {
        /// The input's count.
        input: usize,
        /// The output's count.
        output: usize,
    },
}

impl fmt::Display for TopologyChange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TopologyChange::Components { input, output } => {
                write!(f, "{output} components where the input has {input}")
            }
            TopologyChange::EulerCharacteristic { input, output } => {
                write!(
                    f,
                    "Euler characteristic {output} where the input has {input}"
                )
            }
            TopologyChange::BoundaryLoops { input, output } => {
                write!(f, "{output} boundary loops where the input has {input}")
            }
        }
    }
}

/// Every difference between `input`'s and `output`'s components, Euler characteristic and
/// boundary loops (see [`Topology`] for the definitions), in that order; empty when the output
/// keeps the input's topology. Where the input is not a manifold (non-manifold edges or
/// vertices, which the output never has), these counts usually differ, and the differences are
/// listed all the same: the output is not the input's surface there.
pub fn topology_changes(input: &Topology, output: &Topology) -> Vec<TopologyChange> {
    let mut changes = Vec::new();
    if input.components != output.components {
        changes.push(TopologyChange::Components {
            input: input.components,
            output: output.components,
        });
    }
    if input.euler_characteristic != output.euler_characteristic {
        changes.push(TopologyChange::EulerCharacteristic {
            input: input.euler_characteristic,
            output: output.euler_characteristic,
        });
    }
    if input.boundary_loops != output.boundary_loops {
        changes.push(TopologyChange::BoundaryLoops {
            input: input.boundary_loops,
            output: output.boundary_loops,
        });
    }
    changes
}

/// The topology of `mesh`'s surface: [`topology`] of its faces without the ones that are not
/// surface: faces with a repeated index or zero area
/// ([`is_degenerate_face`]), and repeats of an earlier face's vertex set; and, where the faces
/// meet at non-manifold vertices but at no non-manifold edge, with each such vertex split into
/// one vertex per fan of faces around it (`split_pinched_vertices`). This is what a remesh
/// is compared with: it keeps no such face and no such vertex (its output is a manifold), so
/// they would otherwise show as differences (a lone zero-area face as a component of its own;
/// two parts that touch at a point as one component).
pub fn surface_topology(mesh: &TriMesh) -> Topology {
    let mut seen = std::collections::HashSet::new();
    let faces: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .copied()
        .filter(|&t| {
            let mut key = t;
            key.sort_unstable();
            !is_degenerate_face(&mesh.positions, t) && seen.insert(key)
        })
        .collect();
    let surface = if faces.len() == mesh.triangles.len() {
        topology(mesh)
    } else {
        topology(&TriMesh::new(mesh.positions.clone(), faces.clone()))
    };
    if surface.non_manifold_vertices == 0 || surface.non_manifold_edges > 0 {
        return surface;
    }
    topology(&split_pinched_vertices(&TriMesh::new(
        mesh.positions.clone(),
        faces,
    )))
}

/// `mesh` with every vertex split into one vertex per fan of its faces (faces around it joined
/// through the edges at it that have exactly two faces): a vertex where parts or sheets touch
/// at a point (a pinched vertex) becomes one per part; every other vertex stays one (at the
/// end of the positions, in order of first use). The manifold surface a pinched mesh stands
/// for, as CGAL's `duplicate_non_manifold_vertices` makes it. Faces keep their order.
pub fn split_pinched_vertices(mesh: &TriMesh) -> TriMesh {
    use crate::disjoint_sets::Dsu;
    let t = &mesh.triangles;
    let corner = |f: usize, v: u32| 3 * f + t[f].iter().position(|&w| w == v).unwrap_or(0);
    // Edges with their faces: (low, high, face).
    let mut sides: Vec<(u32, u32, usize)> = Vec::with_capacity(3 * t.len());
    for (f, tri) in t.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            if a != b {
                sides.push((a.min(b), a.max(b), f));
            }
        }
    }
    sides.sort_unstable();
    let mut corners = Dsu::new(3 * t.len());
    for run in sides.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        if let [(lo, hi, f), (_, _, g)] = *run {
            corners.union(corner(f, lo), corner(g, lo), false);
            corners.union(corner(f, hi), corner(g, hi), false);
        }
    }
    let mut index: std::collections::HashMap<usize, u32> = std::collections::HashMap::new();
    let mut positions = Vec::new();
    let triangles = t
        .iter()
        .enumerate()
        .map(|(f, tri)| {
            tri.map(|v| {
                let root = corners.find(corner(f, v)).0;
                *index.entry(root).or_insert_with(|| {
                    positions.push(mesh.positions[v as usize]);
                    (positions.len() - 1) as u32
                })
            })
        })
        .collect();
    TriMesh::new(positions, triangles)
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;

    /// A closed octahedron, shifted by `offset`.
    fn octahedron(offset: DVec3) -> TriMesh {
        let p = [
            DVec3::X,
            DVec3::NEG_X,
            DVec3::Y,
            DVec3::NEG_Y,
            DVec3::Z,
            DVec3::NEG_Z,
        ]
        .map(|v| v + offset)
        .to_vec();
        let t = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        TriMesh::new(p, t)
    }

    fn two_octahedra() -> TriMesh {
        let a = octahedron(DVec3::ZERO);
        let b = octahedron(DVec3::new(5.0, 0.0, 0.0));
        let mut t = a.triangles.clone();
        t.extend(b.triangles.iter().map(|f| f.map(|i| i + 6)));
        TriMesh::new([a.positions, b.positions].concat(), t)
    }

    #[test]
    fn the_same_surface_has_no_changes() {
        let t = topology(&octahedron(DVec3::ZERO));
        assert!(topology_changes(&t, &t).is_empty());
    }

    #[test]
    fn a_split_off_part_is_listed_with_its_counts() {
        let input = topology(&octahedron(DVec3::ZERO));
        let output = topology(&two_octahedra());
        let changes = topology_changes(&input, &output);
        assert_eq!(
            changes,
            vec![
                TopologyChange::Components {
                    input: 1,
                    output: 2
                },
                TopologyChange::EulerCharacteristic {
                    input: 2,
                    output: 4
                },
            ]
        );
        assert_eq!(changes[0].to_string(), "2 components where the input has 1");
    }

    #[test]
    fn an_opened_hole_changes_the_boundary_loops_and_chi() {
        let input = topology(&octahedron(DVec3::ZERO));
        let mut open = octahedron(DVec3::ZERO);
        open.triangles.pop();
        let changes = topology_changes(&input, &topology(&open));
        assert_eq!(
            changes,
            vec![
                TopologyChange::EulerCharacteristic {
                    input: 2,
                    output: 1
                },
                TopologyChange::BoundaryLoops {
                    input: 0,
                    output: 1
                },
            ]
        );
        let json = serde_json::to_value(changes[1]).unwrap();
        assert_eq!(json["kind"], "BoundaryLoops");
        assert_eq!(json["output"], 1);
    }

    #[test]
    fn faces_that_are_not_surface_are_left_out_of_the_surface_topology() {
        let clean = octahedron(DVec3::ZERO);
        let mut messy = clean.clone();
        // A lone zero-area face (its own component with a boundary loop), a face repeating an
        // index, and a repeat of a face in the other orientation.
        let n = messy.positions.len() as u32;
        messy.positions.extend([
            DVec3::new(3.0, 0.0, 0.0),
            DVec3::new(4.0, 0.0, 0.0),
            DVec3::new(5.0, 0.0, 0.0),
        ]);
        messy.triangles.push([n, n + 1, n + 2]);
        messy.triangles.push([0, 0, 2]);
        messy.triangles.push([0, 4, 2]);
        assert!(!topology_changes(&topology(&messy), &topology(&clean)).is_empty());
        let surface = surface_topology(&messy);
        assert!(topology_changes(&surface, &topology(&clean)).is_empty());
        assert_eq!(surface.faces, clean.triangles.len());
    }
    /// Two octahedra touching at a vertex: one component with a pinched vertex as faces go,
    /// two closed surfaces as a manifold remesh can keep them, and so the surface compared.
    #[test]
    fn parts_that_touch_at_a_point_are_compared_apart() {
        let a = octahedron(DVec3::ZERO);
        // The second octahedron's vertex -X (index 1) at the first's +X (index 0).
        let b = octahedron(DVec3::new(2.0, 0.0, 0.0));
        let mut t = a.triangles.clone();
        t.extend(
            b.triangles
                .iter()
                .map(|f| f.map(|i| if i == 1 { 0 } else { i + 6 })),
        );
        let pinched = TriMesh::new([a.positions, b.positions].concat(), t);
        let raw = topology(&pinched);
        assert_eq!(
            (
                raw.components,
                raw.non_manifold_vertices,
                raw.euler_characteristic
            ),
            (1, 1, 3)
        );
        let surface = surface_topology(&pinched);
        assert_eq!(
            (
                surface.components,
                surface.non_manifold_vertices,
                surface.euler_characteristic
            ),
            (2, 0, 4)
        );
        assert!(topology_changes(&surface, &topology(&two_octahedra())).is_empty());
        // A vertex where faces fan once stays one vertex.
        let one = split_pinched_vertices(&octahedron(DVec3::ZERO));
        assert_eq!(one.positions.len(), 6);
    }
}
