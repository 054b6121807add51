//! The winding number of a closed triangle mesh by signed ray crossings ([`RayWinding`]), and
//! the generalized winding number of any mesh ([`generalized_winding_number`]).

use glam::DVec3;
use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::partitioning::Bvh;
use parry3d_f64::query::{Ray, RayCast};

use crate::geometry::self_intersection::{
    face_boxes, has_intersecting_pair, intersecting_pairs_in,
};
use crate::mesh::TriMesh;

/// The directions of the crossing-count rays: fixed, unit length, far from every axis and
/// diagonal and from each other. A ray that passes exactly through an edge or a vertex can
/// miscount; three directions and the majority make a wrong answer need two such coincidences.
const RAY_DIRECTIONS: [DVec3; 3] = [
    DVec3::new(
        0.267_261_241_912_424_4,
        0.534_522_483_824_848_8,
        0.801_783_725_737_273_2,
    ),
    DVec3::new(
        -0.704_664_263_417_644_1,
        0.293_610_109_757_351_74,
        0.645_942_241_466_173_7,
    ),
    DVec3::new(0.384_615_384_615_384_6, -0.923_076_923_076_923_1, 0.0),
];

/// The winding number of a closed triangle mesh at points, by signed ray crossings: the ray from
/// p along a fixed direction leaves the solid once more than it enters it for every layer of
/// solid around p, so Σ sign(n_f · d) over the faces it crosses is the winding number (1 inside
/// an outward-oriented closed mesh, 0 outside, 2 where two parts of it overlap; negated for an
/// inward-oriented one). A BVH over the faces keeps each query O(log F + crossings).
///
/// Exact for a closed, consistently oriented mesh up to rays that pass exactly through an edge
/// or a vertex (counted once or twice; the fixed generic direction makes this rare), and
/// meaningless for an open one.
///
/// Source: the crossing-number form of the winding number (e.g. A. Jacobson, L. Kavan,
/// O. Sorkine-Hornung, *Robust Inside-Outside Segmentation using Generalized Winding Numbers*,
/// ACM TOG 32(4), 2013, Sec. 2).
pub struct RayWinding<'a> {
    mesh: &'a TriMesh,
    bvh: Bvh,
    normals: Vec<DVec3>,
    /// Whether each face is in the BVH (counted by the rays).
    counted: Vec<bool>,
    /// The counted faces with their bounding boxes (the BVH's leaves).
    boxes: Vec<(usize, Aabb)>,
}

impl<'a> RayWinding<'a> {
    /// The structure over `mesh`'s faces (degenerate faces and faces with an index out of range
    /// or a non-finite corner are left out: [`face_boxes`]).
    pub fn new(mesh: &'a TriMesh) -> Self {
        let boxes = face_boxes(&mesh.positions, &mesh.triangles);
        let bvh = crate::geometry::bvh::bvh_of(boxes.iter().copied());
        // Only the counted faces' corners are read: the others may have an index out of range.
        let mut counted = vec![false; mesh.triangles.len()];
        let mut normals = vec![DVec3::ZERO; mesh.triangles.len()];
        for &(f, _) in &boxes {
            counted[f] = true;
            normals[f] = mesh.face_normal(f);
        }
        RayWinding {
            mesh,
            bvh,
            normals,
            counted,
            boxes,
        }
    }

    /// Whether two of the counted faces that share no vertex meet: the test of
    /// [`self_intersections`](crate::check::self_intersections) (`pairs > 0`), on this
    /// structure's BVH (the same one), stopping at the first pair.
    pub(crate) fn crosses_itself(&self) -> bool {
        has_intersecting_pair(
            &self.bvh,
            &self.boxes,
            &self.mesh.positions,
            &self.mesh.triangles,
        )
    }

    /// The pairs of counted faces that share no vertex and meet, as
    /// [`intersecting_pairs`](crate::geometry::self_intersection::intersecting_pairs) gives
    /// them, found on this structure's BVH.
    pub(crate) fn crossing_pairs(&self) -> Vec<[u32; 2]> {
        intersecting_pairs_in(
            &self.bvh,
            &self.boxes,
            &self.mesh.positions,
            &self.mesh.triangles,
        )
    }

    /// How many faces the mesh has (counted or not).
    pub(crate) fn face_count(&self) -> usize {
        self.counted.len()
    }

    /// Whether face `f` is counted (not left out as degenerate or broken).
    pub(crate) fn counts(&self, f: usize) -> bool {
        self.counted.get(f).copied().unwrap_or(false)
    }

    /// Face `f`'s vertex indices (`f` below [`RayWinding::face_count`]).
    pub(crate) fn triangle(&self, f: usize) -> [u32; 3] {
        self.mesh.triangles[f]
    }

    /// Face `f`'s corners (`f` a counted face).
    pub(crate) fn corners(&self, f: usize) -> [DVec3; 3] {
        self.mesh.corners(f)
    }

    /// Face `f`'s unit normal (`f` a counted face).
    pub(crate) fn normal(&self, f: usize) -> DVec3 {
        self.normals[f]
    }

    /// Vertex `v`'s position (`v` a vertex of a counted face).
    pub(crate) fn position(&self, v: u32) -> DVec3 {
        self.mesh.positions[v as usize]
    }

    /// The counted faces whose bounding boxes meet the closed box `aabb`: every counted face
    /// that meets it is among them.
    pub(crate) fn faces_meeting(&self, aabb: Aabb) -> impl Iterator<Item = usize> + '_ {
        self.bvh
            .leaves(move |node| node.aabb().intersects(&aabb))
            .map(|f| f as usize)
    }

    /// The winding number at `p` (see [`RayWinding`]): the count along three fixed rays, the
    /// value two of them agree on (the first ray's when all three differ).
    pub fn winding_number(&self, p: DVec3) -> i32 {
        let w = RAY_DIRECTIONS.map(|d| self.count_along(p, d));
        if w[1] == w[2] {
            w[1]
        } else {
            w[0]
        }
    }

    /// Σ sign(n_f · d) over the faces the ray p + t d (t > 0) crosses.
    fn count_along(&self, p: DVec3, d: DVec3) -> i32 {
        let ray = Ray::new(p, d);
        self.bvh
            .leaves(|node| node.aabb().cast_local_ray(&ray, f64::MAX, true).is_some())
            .filter(|&f| ray_crosses(p, d, self.mesh.corners(f as usize)))
            .map(|f| {
                let s = self.normals[f as usize].dot(d);
                if s > 0.0 {
                    1
                } else if s < 0.0 {
                    -1
                } else {
                    0
                }
            })
            .sum()
    }
}

/// Whether the ray p + t d, t > 0, passes through the triangle (Möller–Trumbore).
fn ray_crosses(p: DVec3, d: DVec3, [a, b, c]: [DVec3; 3]) -> bool {
    let e1 = b - a;
    let e2 = c - a;
    let h = d.cross(e2);
    let det = e1.dot(h);
    if det == 0.0 {
        return false;
    }
    let inv = 1.0 / det;
    let s = p - a;
    let u = inv * s.dot(h);
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let q = s.cross(e1);
    let v = inv * d.dot(q);
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    inv * e2.dot(q) > 0.0
}

/// The generalized winding number of `mesh` at `p`: the sum of the signed solid angles of its
/// faces seen from p, over 4π (Van Oosterom and Strackee's formula per triangle). For a closed
/// mesh it is the integer winding number; for an open one it is still 1 well inside and 0 well
/// outside, blending near the holes. O(F) per point.
///
/// Source: A. Jacobson, L. Kavan, O. Sorkine-Hornung, *Robust Inside-Outside Segmentation using
/// Generalized Winding Numbers*, ACM TOG 32(4), 2013; A. Van Oosterom, J. Strackee, *The Solid
/// Angle of a Plane Triangle*, IEEE Trans. Biomed. Eng. 30(2), 1983.
pub fn generalized_winding_number(mesh: &TriMesh, p: DVec3) -> f64 {
    let n = mesh.positions.len();
    let mut total = 0.0;
    for t in &mesh.triangles {
        if t.iter().any(|&i| i as usize >= n) {
            continue;
        }
        let [a, b, c] = t.map(|i| mesh.positions[i as usize] - p);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let num = a.dot(b.cross(c));
        let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
        let omega = 2.0 * num.atan2(den);
        if omega.is_finite() {
            total += omega;
        }
    }
    total / (4.0 * std::f64::consts::PI)
}
