//! The input surface the samples live on, and projection onto it.

pub mod mesh_projection;
pub mod winding;

pub use mesh_projection::{MeshSurface, SurfacePoint};

use glam::DVec3;

use crate::sampling::SurfaceSample;

/// A surface samples are projected onto after each gradient-ascent move (Sec. 6.2): the input
/// mesh ([`MeshSurface`], closest point) or the RIMLS surface of a point set
/// ([`crate::points::rimls::Rimls`], Newton projection).
pub trait Projection: Sync {
    /// The projection of `p` (bbox-100 units) with the surface's unit normal there and, on a
    /// mesh, the triangle it lies on (0 elsewhere); `None` when `p` cannot be projected.
    fn project(&self, p: DVec3) -> Option<SurfaceSample>;
}

impl Projection for MeshSurface {
    fn project(&self, p: DVec3) -> Option<SurfaceSample> {
        self.closest_point(p).map(|sp| SurfaceSample {
            position: sp.position,
            normal: self.face_normal(sp.face),
            face: sp.face,
        })
    }
}
