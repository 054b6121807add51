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
/// ([`is_degenerate_face`]), and repeats of an earlier face's vertex set. This is what a remesh
/// is compared with: it keeps no such face, so they would otherwise show as differences (a lone
/// zero-area face as a component of its own).
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
    if faces.len() == mesh.triangles.len() {
        return topology(mesh);
    }
    topology(&TriMesh::new(mesh.positions.clone(), faces))
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
}
