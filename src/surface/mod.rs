//! The input surface the samples live on, and projection onto it.

pub mod area_sampler;
pub mod candidates;
pub mod curvature;
pub mod feature_lines;
pub mod features;
pub(crate) mod front_regions;
pub mod local_feature_size;
pub mod mesh_projection;
pub mod winding;
pub mod winding_number;

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
/// ([`Rimls`](crate::internal::Rimls), Newton projection).
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

    /// [`Projection::project`] for a point moved a little from `from` (a sample this surface
    /// gave): the same answer, found faster where the surface can start its search from
    /// `from` (on a mesh: from its triangle, [`MeshSurface::closest_point_from`]).
    fn project_from(&self, p: DVec3, from: &SurfaceSample) -> Option<SurfaceSample> {
        self.project_near(p, p.distance(from.position))
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

    fn project_from(&self, p: DVec3, from: &SurfaceSample) -> Option<SurfaceSample> {
        self.closest_point_from(p, from.face, f64::MAX)
            .map(|sp| self.sample_at(&sp))
    }
}

/// Closest-point queries on the surface a mesh is fitted to, as the stages after the
/// triangulation ask them (the last pass's moves, flips, collapses and splits, the fit): on the
/// input mesh ([`MeshSurface`], exact closest points through a BVH), or on another surface that
/// answers the same questions. Positions and distances in the units of the surface (bbox-100 in
/// the pipeline).
pub trait SurfaceQuery: Sync {
    /// The closest point of the surface to `p` if it is within `max_dist` of `p`; `None` also
    /// when `p` is not finite.
    fn closest_point_within(&self, p: DVec3, max_dist: f64) -> Option<SurfacePoint>;

    /// The unit normal of the surface at `sp` (a point this surface returned), smooth across
    /// the pieces of the surface.
    fn smooth_normal(&self, sp: &SurfacePoint) -> DVec3;

    /// The unit normal of the piece of the surface `sp` lies on (on a mesh, its triangle's);
    /// [`SurfaceQuery::smooth_normal`] on a smooth surface.
    fn piece_normal(&self, sp: &SurfacePoint) -> DVec3 {
        self.smooth_normal(sp)
    }

    /// The closest point to `p` within `max_dist` on a piece of the surface whose normal
    /// ([`SurfaceQuery::piece_normal`]) points the way of `facing` (a positive dot product):
    /// the sheet a mesh piece of that orientation follows, where a sheet facing away (another
    /// part's wall, the far side of a thin plate) lies nearer. On a surface of one smooth sheet,
    /// the closest point when it faces that way, else `None`.
    fn closest_point_facing(&self, p: DVec3, facing: DVec3, max_dist: f64) -> Option<SurfacePoint> {
        self.closest_point_within(p, max_dist)
            .filter(|sp| self.piece_normal(sp).dot(facing) > 0.0)
    }

    /// The closest point of the surface to `p`. `None` only when `p` is not finite.
    fn closest_point(&self, p: DVec3) -> Option<SurfacePoint> {
        self.closest_point_within(p, f64::MAX)
    }

    /// [`SurfaceQuery::closest_point_within`], where `hint` is the distance from `p` to a point
    /// known to lie on the surface: the same answer, possibly found faster.
    fn closest_point_hinted(&self, p: DVec3, hint: f64, max_dist: f64) -> Option<SurfacePoint> {
        let _ = hint;
        self.closest_point_within(p, max_dist)
    }

    /// The closest point to the midpoint of `a` and `b`, two points on the surface.
    fn closest_point_to_midpoint(&self, a: DVec3, b: DVec3) -> Option<SurfacePoint> {
        self.closest_point_hinted(0.5 * (a + b), 0.5 * a.distance(b), f64::MAX)
    }

    /// [`SurfaceQuery::closest_point_within`] for a point near `from` (a point this surface
    /// returned): the same answer, found faster where the search can start from `from` (on a
    /// mesh: from its triangle, [`MeshSurface::closest_point_from`]).
    fn closest_point_near(
        &self,
        p: DVec3,
        from: &SurfacePoint,
        max_dist: f64,
    ) -> Option<SurfacePoint> {
        self.closest_point_hinted(p, p.distance(from.position), max_dist)
    }

    /// The closest points to several points near each other (the quadrature points of one
    /// face): `out[k]` is [`SurfaceQuery::closest_point_near`] of `points[k]` from `from[k]`
    /// where that is given, and [`SurfaceQuery::closest_point_hinted`] with `hint[k]` where
    /// not, each within `max_dist`. The same answers as one query at a time (on a mesh one
    /// walk of its tree serves them all). The four slices have one length.
    fn closest_points_near(
        &self,
        points: &[DVec3],
        from: &[Option<SurfacePoint>],
        hint: &[f64],
        max_dist: f64,
        out: &mut [Option<SurfacePoint>],
    ) {
        for (k, &p) in points.iter().enumerate() {
            out[k] = match &from[k] {
                Some(f) => self.closest_point_near(p, f, max_dist),
                None => self.closest_point_hinted(p, hint[k], max_dist),
            };
        }
    }
}

impl SurfaceQuery for MeshSurface {
    fn closest_point_within(&self, p: DVec3, max_dist: f64) -> Option<SurfacePoint> {
        MeshSurface::closest_point_within(self, p, max_dist)
    }

    fn smooth_normal(&self, sp: &SurfacePoint) -> DVec3 {
        MeshSurface::smooth_normal(self, sp)
    }

    fn piece_normal(&self, sp: &SurfacePoint) -> DVec3 {
        self.face_normal(sp.face)
    }

    fn closest_point_facing(&self, p: DVec3, facing: DVec3, max_dist: f64) -> Option<SurfacePoint> {
        MeshSurface::closest_point_facing(self, p, facing, max_dist)
    }

    fn closest_point(&self, p: DVec3) -> Option<SurfacePoint> {
        MeshSurface::closest_point(self, p)
    }

    fn closest_point_hinted(&self, p: DVec3, hint: f64, max_dist: f64) -> Option<SurfacePoint> {
        MeshSurface::closest_point_hinted(self, p, hint, max_dist)
    }

    fn closest_point_to_midpoint(&self, a: DVec3, b: DVec3) -> Option<SurfacePoint> {
        MeshSurface::closest_point_to_midpoint(self, a, b)
    }

    fn closest_point_near(
        &self,
        p: DVec3,
        from: &SurfacePoint,
        max_dist: f64,
    ) -> Option<SurfacePoint> {
        MeshSurface::closest_point_from(self, p, from.face, max_dist)
    }

    fn closest_points_near(
        &self,
        points: &[DVec3],
        from: &[Option<SurfacePoint>],
        hint: &[f64],
        max_dist: f64,
        out: &mut [Option<SurfacePoint>],
    ) {
        MeshSurface::closest_points_near(self, points, from, hint, max_dist, out);
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
