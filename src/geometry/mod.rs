//! Geometry primitives: triangle measures, exact predicates, Morton codes, and the one module of
//! tolerances. Nothing here knows of meshes as structures or of the pipeline: functions take
//! points, triangles as corner arrays, or indexed triangles as slices.
//!
//! A public namespace of its own (`spectral_remesh::geometry::triangle_q`, ...): these are small
//! building blocks under the pipeline's stages, not stages, and read best with the prefix.

pub(crate) mod bvh;
pub(crate) mod closest_point_tree;
pub(crate) mod closest_point_walk;
pub(crate) mod crossing_curve;
pub(crate) mod face_intersection;
pub(crate) mod morton;
pub(crate) mod plane;
pub(crate) mod polygon_triangulation;
pub(crate) mod segment;
pub(crate) mod self_intersection;
pub(crate) mod tolerance;
pub(crate) mod triangle;
pub(crate) mod triangle_intersection;

pub use face_intersection::{faces_intersect, PairKind};
pub use plane::tangent_basis;
pub use self_intersection::{
    classified_pairs, intersecting_pairs, intersecting_pairs_counted, PairSearch,
};
pub use tolerance::{
    BURIED_OFFSET, DEGENERATE_AREA_TOLERANCE, SEARCH_BOUND_SLACK, SINGULAR_TOLERANCE,
};
pub use triangle::{
    face_key, is_degenerate_face, is_degenerate_triangle, triangle_angles_deg, triangle_q,
};
pub use triangle_intersection::{segment_meets_triangle, triangles_intersect};
