//! Closest-point projection onto a triangle mesh, through a bounding-volume hierarchy built for
//! that query ([`ClosestPointTree`]), warm-started from the face of a previous answer where the
//! caller has one. Used to project gradient-ascent moves back onto the input surface (Sec. 6.2) and
//! to measure the distance between two surfaces (Hausdorff, RMS).

use crate::error::{Error, Result};
use crate::geometry::closest_point_tree::{Closest, ClosestPointTree, GROUP};
use crate::geometry::closest_point_walk::{FaceRings, Walked};
use crate::geometry::tolerance::SEARCH_BOUND_SLACK;
use crate::mesh::TriMesh;
use glam::DVec3;

/// A point on the surface: where it is, on which triangle, with which barycentric coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// Position on the surface (units of the mesh).
    pub position: DVec3,
    /// Index of the triangle of the source mesh it lies on.
    pub face: u32,
    /// Barycentric coordinates in that triangle (sum 1).
    pub barycentric: [f64; 3],
    /// Distance from the query point to `position`.
    pub distance: f64,
}

/// A triangle mesh prepared for closest-point queries and normal look-ups.
///
/// Degenerate triangles (zero area) are left out of the search structure; every other triangle
/// keeps its index in the source mesh.
pub struct MeshSurface {
    mesh: TriMesh,
    tree: ClosestPointTree,
    /// The faces' rings for warm-started queries ([`MeshSurface::with_face_rings`]; empty:
    /// every query asks the tree).
    rings: FaceRings,
    face_normals: Vec<DVec3>,
    vertex_normals: Vec<DVec3>,
}

impl MeshSurface {
    /// Builds the search structure over `mesh` (copied).
    ///
    /// # Errors
    /// [`Error::InvalidMesh`] when the mesh has no triangle of non-zero area, an index out of
    /// range, or a non-finite coordinate.
    pub fn new(mesh: &TriMesh) -> Result<Self> {
        mesh.check_geometry()?;
        let face_normals: Vec<DVec3> = (0..mesh.face_count())
            .map(|f| mesh.face_normal(f))
            .collect();
        let tree = ClosestPointTree::new(
            (0..mesh.face_count() as u32)
                .filter(|&f| face_normals[f as usize] != DVec3::ZERO)
                .map(|f| (f, mesh.corners(f as usize))),
        );
        if tree.is_empty() {
            return Err(Error::invalid_mesh("", "no triangle of non-zero area"));
        }
        Ok(MeshSurface {
            vertex_normals: mesh.vertex_normals(),
            mesh: mesh.clone(),
            tree,
            rings: FaceRings::default(),
            face_normals,
        })
    }

    /// The surface with each face's ring and clearance built (one tree query per face, in
    /// parallel), so that a query started from a face ([`MeshSurface::closest_point_from`],
    /// [`MeshSurface::closest_points_near`]) walks from it and asks the tree only where the
    /// walk cannot certify its answer (`geometry::closest_point_walk`). For a surface queried
    /// many times from previous answers (the input, through sampling and finishing).
    pub fn with_face_rings(mut self) -> Self {
        self.rings = FaceRings::new(&self.tree, &self.mesh.triangles);
        self
    }

    /// The source mesh.
    pub fn mesh(&self) -> &TriMesh {
        &self.mesh
    }

    /// The closest point of the surface to `p`. `None` only when `p` is not finite.
    pub fn closest_point(&self, p: DVec3) -> Option<SurfacePoint> {
        self.closest_point_within(p, f64::MAX)
    }

    /// The closest point of the surface to `p` if it is within `max_dist` of `p`.
    pub fn closest_point_within(&self, p: DVec3, max_dist: f64) -> Option<SurfacePoint> {
        self.search(p, max_dist, None)
    }

    /// Whether the surface comes within `max_dist` of `p` (strictly closer, up to the search
    /// slack): [`MeshSurface::closest_point_within`]`.is_some()`, ended at the first face close
    /// enough instead of searching for the closest.
    pub fn is_within(&self, p: DVec3, max_dist: f64) -> bool {
        let bound = max_dist * max_dist * (1.0 + SEARCH_BOUND_SLACK);
        self.tree.any_within(p, bound)
    }

    /// [`MeshSurface::is_within`], trying face `start` first (the face the last point near `p`
    /// found within the distance): the face found, `None` when the surface does not come that
    /// close. The same decision as `is_within`.
    pub fn within_from(&self, p: DVec3, max_dist: f64, start: Option<u32>) -> Option<u32> {
        let bound = max_dist * max_dist * (1.0 + SEARCH_BOUND_SLACK);
        self.tree.any_within_from(p, bound, start)
    }

    /// [`MeshSurface::closest_point_within`] warm-started from face `start` (the face of a
    /// previous answer near `p`): the search begins with that face's distance as its bound.
    /// The same answer (among faces at exactly equal distances, the smallest index); where the
    /// surface has its faces' rings ([`MeshSurface::with_face_rings`]), found by a walk from
    /// `start` when the walk can certify it.
    pub fn closest_point_from(&self, p: DVec3, start: u32, max_dist: f64) -> Option<SurfacePoint> {
        self.search(p, max_dist, Some(start))
    }

    /// [`SurfaceQuery::closest_points_near`](super::SurfaceQuery::closest_points_near): one walk
    /// of the tree for all the points ([`ClosestPointTree::closest_each`]), then, for a hinted
    /// point with no surface within its hint, a search within `max_dist` of its own.
    pub fn closest_points_near(
        &self,
        points: &[DVec3],
        from: &[Option<SurfacePoint>],
        hint: &[f64],
        max_dist: f64,
        out: &mut [Option<SurfacePoint>],
    ) {
        let n = points.len();
        assert!(from.len() == n && hint.len() == n && out.len() == n);
        if n > GROUP {
            for k in (0..n).step_by(GROUP) {
                let e = (k + GROUP).min(n);
                self.closest_points_near(
                    &points[k..e],
                    &from[k..e],
                    &hint[k..e],
                    max_dist,
                    &mut out[k..e],
                );
            }
            return;
        }
        // Each point's first bound: max_dist from a start, its hint (a hair more) without one.
        let mut within = [0.0; GROUP];
        let mut bounds = [0.0; GROUP];
        let mut starts = [None; GROUP];
        for k in 0..n {
            within[k] = match from[k] {
                Some(_) => max_dist,
                None => (hint[k] * (1.0 + SEARCH_BOUND_SLACK) + f64::MIN_POSITIVE).min(max_dist),
            };
            bounds[k] = within[k] * within[k] * (1.0 + SEARCH_BOUND_SLACK);
            starts[k] = from[k].map(|f| f.face);
        }
        // The points a walk from their start answers; the others asked of the tree together.
        let mut found = [None; GROUP];
        let mut ask = [0usize; GROUP];
        let mut asked = 0;
        for k in 0..n {
            match starts[k].map(|s| self.walk(points[k], bounds[k], s)) {
                Some(Walked::Certified(c)) => found[k] = c,
                unsure => {
                    if let Some(Walked::Unsure(s)) = unsure {
                        starts[k] = Some(s);
                    }
                    ask[asked] = k;
                    asked += 1;
                }
            }
        }
        if asked > 0 {
            let mut ps = [DVec3::ZERO; GROUP];
            let mut bs = [0.0; GROUP];
            let mut ss = [None; GROUP];
            for (j, &k) in ask[..asked].iter().enumerate() {
                (ps[j], bs[j], ss[j]) = (points[k], bounds[k], starts[k]);
            }
            let mut got = [None; GROUP];
            self.tree
                .closest_each(&ps[..asked], &bs[..asked], &ss[..asked], &mut got[..asked]);
            for (j, &k) in ask[..asked].iter().enumerate() {
                found[k] = got[j];
            }
        }
        for k in 0..n {
            out[k] = match found[k] {
                Some(c) => Some(surface_point(c)),
                None if within[k] < max_dist => self.search(points[k], max_dist, None),
                None => None,
            };
        }
    }

    fn search(&self, p: DVec3, max_dist: f64, start: Option<u32>) -> Option<SurfacePoint> {
        // Squared bound a hair above max_dist², so that a point exactly at max_dist is kept.
        let bound = max_dist * max_dist * (1.0 + SEARCH_BOUND_SLACK);
        let start = match start.map(|s| self.walk(p, bound, s)) {
            Some(Walked::Certified(c)) => return c.map(surface_point),
            Some(Walked::Unsure(s)) => Some(s),
            None => None,
        };
        self.tree.closest(p, bound, start).map(surface_point)
    }

    /// The walk from face `start` where the rings are built, else `Unsure(start)`.
    fn walk(&self, p: DVec3, bound: f64, start: u32) -> Walked {
        if self.rings.fits(self.tree.len()) {
            self.rings.closest_from(&self.tree, p, bound, start)
        } else {
            Walked::Unsure(start)
        }
    }

    /// [`MeshSurface::closest_point_within`] with a hint: `hint` is the distance from `p` to a
    /// point known to lie on the surface, so the closest point is no farther. The search is made
    /// within the hint first (a hair more, for rounding), which prunes most of the hierarchy,
    /// and within `max_dist` only when that finds nothing (a hint that was not a surface point's
    /// distance): the same answer as without the hint.
    pub fn closest_point_hinted(&self, p: DVec3, hint: f64, max_dist: f64) -> Option<SurfacePoint> {
        let near = hint * (1.0 + SEARCH_BOUND_SLACK) + f64::MIN_POSITIVE;
        if near < max_dist {
            if let Some(sp) = self.closest_point_within(p, near) {
                return Some(sp);
            }
        }
        self.closest_point_within(p, max_dist)
    }

    /// The closest point to the midpoint of `a` and `b`, hinted by the distance to `a` (a mesh
    /// edge whose ends lie on the surface: the usual case, and the search is then short).
    pub fn closest_point_to_midpoint(&self, a: DVec3, b: DVec3) -> Option<SurfacePoint> {
        self.closest_point_hinted(0.5 * (a + b), 0.5 * a.distance(b), f64::MAX)
    }

    /// The closest point to `p` within `max_dist` among the faces whose normal points the way
    /// of `facing` (a positive dot product): the point on the sheet a mesh piece with that
    /// normal follows, passing over a sheet of another part, or the far side of a thin wall,
    /// that lies nearer but faces away. `None` when no such face is that close.
    pub fn closest_point_facing(
        &self,
        p: DVec3,
        facing: DVec3,
        max_dist: f64,
    ) -> Option<SurfacePoint> {
        let bound = max_dist * max_dist * (1.0 + SEARCH_BOUND_SLACK);
        let away = |slot: usize| self.face_normals[self.tree.id(slot) as usize].dot(facing) <= 0.0;
        self.tree
            .closest_skipping(p, bound, away)
            .map(surface_point)
    }

    /// Unit normal of face `f` of the source mesh.
    #[inline]
    pub fn face_normal(&self, f: u32) -> DVec3 {
        self.face_normals[f as usize]
    }

    /// The smooth normal at a surface point: the angle-weighted vertex normals interpolated with
    /// its barycentric coordinates (falls back to the face normal where they cancel).
    pub fn smooth_normal(&self, sp: &SurfacePoint) -> DVec3 {
        let t = self.mesh.triangles[sp.face as usize];
        let n = (0..3)
            .map(|k| sp.barycentric[k] * self.vertex_normals[t[k] as usize])
            .fold(DVec3::ZERO, |a, b| a + b);
        let n = n.normalize_or_zero();
        if n == DVec3::ZERO {
            self.face_normal(sp.face)
        } else {
            n
        }
    }
}

/// A closest point of the tree as a point of the surface.
fn surface_point(c: Closest) -> SurfacePoint {
    SurfacePoint {
        position: c.point,
        face: c.id,
        barycentric: c.barycentric,
        distance: c.distance_squared.sqrt(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_square() -> TriMesh {
        TriMesh::new(
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
    }

    /// Two parallel squares a hair apart, facing away from each other (the walls of two parts
    /// that touch): the plain query takes the nearer, the facing one the sheet facing `facing`.
    #[test]
    fn the_facing_query_passes_over_a_nearer_sheet_facing_away() {
        let mut p = unit_square().positions;
        p.extend(p.clone().iter().map(|q| *q + DVec3::new(0.0, 0.0, -0.01)));
        // The upper square faces up (+z), the lower one down (-z).
        let two = TriMesh::new(p, vec![[0, 1, 2], [0, 2, 3], [4, 6, 5], [4, 7, 6]]);
        let s = MeshSurface::new(&two).unwrap();
        let q = DVec3::new(0.3, 0.6, -0.02);
        let near = s.closest_point(q).unwrap();
        assert!(near.face >= 2 && (near.distance - 0.01).abs() < 1e-12);
        let up = s.closest_point_facing(q, DVec3::Z, 1.0).unwrap();
        assert!(up.face < 2, "{up:?}");
        assert!((up.position - DVec3::new(0.3, 0.6, 0.0)).length() < 1e-12);
        assert!((up.distance - 0.02).abs() < 1e-12);
        // Nothing facing up within the bound, and nothing facing sideways at all.
        assert!(s.closest_point_facing(q, DVec3::Z, 0.015).is_none());
        assert!(s.closest_point_facing(q, DVec3::X, 10.0).is_none());
        let down = s.closest_point_facing(q, -DVec3::Z, 1.0).unwrap();
        assert_eq!(down.face, near.face);
    }

    #[test]
    fn projects_onto_the_plane_and_reports_the_face() {
        let s = MeshSurface::new(&unit_square()).unwrap();
        let sp = s.closest_point(DVec3::new(0.8, 0.2, 0.5)).unwrap();
        assert!((sp.position - DVec3::new(0.8, 0.2, 0.0)).length() < 1e-12);
        assert_eq!(sp.face, 0);
        assert!((sp.distance - 0.5).abs() < 1e-12);
        let b = sp.barycentric;
        let rebuilt = b[0] * s.mesh().positions[0]
            + b[1] * s.mesh().positions[1]
            + b[2] * s.mesh().positions[2];
        assert!((rebuilt - sp.position).length() < 1e-12);
        assert!((s.smooth_normal(&sp) - DVec3::Z).length() < 1e-12);
        // Outside the square: the closest point is on its border.
        let sp = s.closest_point(DVec3::new(2.0, 0.5, 0.0)).unwrap();
        assert!((sp.position - DVec3::new(1.0, 0.5, 0.0)).length() < 1e-12);
    }

    #[test]
    fn the_points_of_a_face_searched_together_get_their_own_answers() {
        use crate::surface::SurfaceQuery;
        use rand::{RngExt, SeedableRng};
        let mesh = crate::mesh::test_meshes::uv_sphere(1.0, 16, 32);
        let s = MeshSurface::new(&mesh).unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let mut fell_back = 0;
        for _ in 0..300 {
            let c = DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
            .normalize_or_zero();
            let points: Vec<DVec3> = (0..6)
                .map(|_| c + 0.05 * DVec3::new(rng.random_range(-1.0..1.0), 0.3, -0.2))
                .collect();
            // Half the points start from an earlier answer; the others have a hint, some too
            // short to hold the answer (the search then goes on to max_dist).
            let from: Vec<Option<SurfacePoint>> = (0..6)
                .map(|k| (k % 2 == 0).then(|| s.closest_point(points[(k + 1) % 6]).unwrap()))
                .collect();
            let hint: Vec<f64> = (0..6)
                .map(|k| if k % 3 == 1 { 1e-4 } else { 0.3 })
                .collect();
            let mut together = vec![None; 6];
            s.closest_points_near(&points, &from, &hint, 0.5, &mut together);
            for k in 0..6 {
                let alone = match &from[k] {
                    Some(f) => SurfaceQuery::closest_point_near(&s, points[k], f, 0.5),
                    None => SurfaceQuery::closest_point_hinted(&s, points[k], hint[k], 0.5),
                };
                let (a, b) = (together[k].unwrap(), alone.unwrap());
                assert_eq!(a.distance, b.distance, "point {k}");
                assert!(a.position.distance(b.position) < 1e-12);
                fell_back += usize::from(from[k].is_none() && hint[k] < a.distance);
            }
        }
        assert!(
            fell_back > 0,
            "no hint was too short: the fallback went untested"
        );
    }

    #[test]
    fn closest_point_agrees_with_brute_force() {
        use rand::{RngExt, SeedableRng};
        // A bumpy grid surface.
        let n = 12;
        let mesh = crate::mesh::test_meshes::grid(n, |i, j| {
            let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
            DVec3::new(x, y, 0.1 * (7.0 * x).sin() * (5.0 * y).cos())
        });
        let s = MeshSurface::new(&mesh).unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for _ in 0..200 {
            let p = DVec3::new(
                rng.random_range(-0.2..1.2),
                rng.random_range(-0.2..1.2),
                rng.random_range(-0.3..0.3),
            );
            let sp = s.closest_point(p).unwrap();
            let brute = (0..mesh.face_count())
                .map(|f| {
                    let [a, b, c] = mesh.corners(f);
                    let t = parry3d_f64::shape::Triangle::new(a, b, c);
                    use parry3d_f64::query::PointQuery;
                    (t.project_local_point(p, false).point - p).length()
                })
                .fold(f64::INFINITY, f64::min);
            assert!(
                (sp.distance - brute).abs() < 1e-12,
                "{} vs {}",
                sp.distance,
                brute
            );
        }
    }

    #[test]
    fn a_warm_start_gives_the_closest_point_also_across_a_thin_part() {
        use rand::{RngExt, SeedableRng};
        // Two bumpy sheets 0.02 apart (far below their edge length 1/12): a point near one is
        // often closer to the other, which a search started on the first must still find.
        let n = 12;
        let sheet = |z: f64| {
            crate::mesh::test_meshes::grid(n, move |i, j| {
                let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
                DVec3::new(x, y, z + 0.05 * (7.0 * x).sin() * (5.0 * y).cos())
            })
        };
        let (a, b) = (sheet(0.0), sheet(0.02));
        let offset = a.positions.len() as u32;
        let mut positions = a.positions.clone();
        positions.extend(&b.positions);
        let mut triangles = a.triangles.clone();
        triangles.extend(b.triangles.iter().map(|t| t.map(|v| v + offset)));
        let mesh = TriMesh::new(positions, triangles);
        let s = MeshSurface::new(&mesh).unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for i in 0..2000 {
            let mut r = |a: f64| rng.random_range(-a..a);
            let anywhere = DVec3::new(0.5 + r(0.6), 0.5 + r(0.6), r(0.1));
            // Every other point near the surface (as the pipeline's moves are), the others
            // anywhere around it.
            let p = match i % 2 {
                0 => {
                    let q = s.closest_point(anywhere).unwrap().position;
                    q + 0.01 * DVec3::new(r(1.0), r(1.0), r(1.0))
                }
                _ => anywhere,
            };
            let want = s.closest_point(p).unwrap();
            let near = s
                .closest_point(p + DVec3::new(0.01, -0.01, 0.0))
                .unwrap()
                .face;
            let arbitrary = (i * 7 % mesh.face_count()) as u32;
            for start in [near, arbitrary] {
                let got = s.closest_point_from(p, start, f64::MAX).unwrap();
                assert!(
                    (got.distance - want.distance).abs() < 1e-12,
                    "{p:?} from {start}"
                );
                let [x, y, z] = mesh.corners(got.face as usize);
                let b = got.barycentric;
                assert!((b[0] * x + b[1] * y + b[2] * z).distance(got.position) < 1e-12);
            }
            // A bound below the distance finds nothing, warm or not.
            assert!(s.closest_point_from(p, near, 0.5 * want.distance).is_none());
        }
    }

    #[test]
    fn rejects_a_mesh_without_area() {
        let m = TriMesh::new(vec![DVec3::ZERO, DVec3::X, 2.0 * DVec3::X], vec![[0, 1, 2]]);
        assert!(MeshSurface::new(&m).is_err());
    }
}
