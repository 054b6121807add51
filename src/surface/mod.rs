//! The input surface the samples live on, and projection onto it.

pub mod curvature;
pub mod feature_lines;
pub mod features;
pub(crate) mod front_regions;
pub mod local_feature_size;
pub mod mesh_projection;
pub mod winding;

pub use mesh_projection::{MeshSurface, SurfacePoint};

use glam::DVec3;

/// A point on the input surface: position (bbox-100 units), the unit normal of the input
/// triangle it lies on (the n of the kernel's x = [p/sigma_p, n/sigma_n]), and that triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceSample {
    /// Position, bbox-100 units.
    pub position: DVec3,
    /// Unit normal of the input surface at `position`.
    pub normal: DVec3,
    /// Index of the input triangle `position` lies on.
    pub face: u32,
}

/// A surface samples are projected onto after each gradient-ascent move (Sec. 6.2): the input
/// mesh ([`MeshSurface`], closest point) or the RIMLS surface of a point set
/// ([`Rimls`](crate::Rimls), Newton projection).
pub trait Projection: Sync {
    /// The projection of `p` (bbox-100 units) with the surface's unit normal there and, on a
    /// mesh, the triangle it lies on (0 elsewhere); `None` when `p` cannot be projected.
    fn project(&self, p: DVec3) -> Option<SurfaceSample>;

    /// [`Projection::project`] for a point known to be within `bound` of the surface (bbox-100
    /// units; a point moved by `bound` from a point of the surface): the same answer, found
    /// faster where the surface can prune its search with the bound. `None` as for `project`.
    fn project_near(&self, p: DVec3, bound: f64) -> Option<SurfaceSample> {
        let _ = bound;
        self.project(p)
    }
}

impl Projection for MeshSurface {
    fn project(&self, p: DVec3) -> Option<SurfaceSample> {
        self.closest_point(p).map(|sp| self.sample_at(&sp))
    }

    fn project_near(&self, p: DVec3, bound: f64) -> Option<SurfaceSample> {
        self.closest_point_hinted(p, bound, f64::MAX)
            .map(|sp| self.sample_at(&sp))
    }
}

impl MeshSurface {
    /// The sample at a surface point: its position, face and the face's normal.
    fn sample_at(&self, sp: &SurfacePoint) -> SurfaceSample {
        SurfaceSample {
            position: sp.position,
            normal: self.face_normal(sp.face),
            face: sp.face,
        }
    }
}
