//! Geometry primitives: triangle measures, exact predicates, Morton codes, and the one module of
//! tolerances. Nothing here knows of meshes as structures or of the pipeline: functions take
//! points, triangles as corner arrays, or indexed triangles as slices.

pub mod morton;
pub mod self_intersection;
pub mod tolerance;
pub mod triangle;
pub mod triangle_intersection;
