//! Checks of a mesh: its combinatorial topology, the invariants every output must keep (typed
//! [`Violation`]s), and its self-intersections. These read meshes and never feed the
//! triangulation.

mod crease_distance;
mod invariants;
mod self_intersection;
mod topology_change;

pub use crate::mesh::topology::{topology, Topology};
pub use crease_distance::{crease_distance, CreaseDistance};
pub(crate) use invariants::check_all;
pub use invariants::{check_invariants, Violation};
pub use self_intersection::{self_intersections, SelfIntersections};
pub use topology_change::{surface_topology, topology_changes, TopologyChange};
