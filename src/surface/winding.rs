//! Which parts of a self-intersecting input lie inside the solid: the winding number of a
//! closed mesh by signed ray crossings, and the "buried" test of the sampler built on it.

use glam::DVec3;
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};
use parry3d_f64::query::{Ray, RayCast};
use rayon::prelude::*;

use crate::check::{self_intersections, topology};
use crate::geometry::tolerance::BURIED_OFFSET;
use crate::geometry::triangle::is_degenerate_face;
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
}

impl<'a> RayWinding<'a> {
    /// The structure over `mesh`'s faces (degenerate faces and faces with an index out of range
    /// or a non-finite corner are left out).
    pub fn new(mesh: &'a TriMesh) -> Self {
        let n = mesh.positions.len();
        let boxes: Vec<(usize, Aabb)> = (0..mesh.triangles.len())
            .filter(|&f| {
                let t = mesh.triangles[f];
                t.iter()
                    .all(|&i| (i as usize) < n && mesh.positions[i as usize].is_finite())
                    && !is_degenerate_face(&mesh.positions, mesh.triangles[f])
            })
            .map(|f| {
                let [a, b, c] = mesh.corners(f);
                (f, Aabb::new(a.min(b).min(c), a.max(b).max(c)))
            })
            .collect();
        let bvh = Bvh::from_iter(BvhBuildStrategy::Binned, boxes.iter().copied());
        let normals = (0..mesh.triangles.len())
            .map(|f| mesh.face_normal(f))
            .collect();
        RayWinding { mesh, bvh, normals }
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

/// The largest (faces × points to test) for which [`BuriedTest`] uses the generalized winding
/// number on an open mesh (O(F) per point): about a second on 2 cores.
pub const MAX_OPEN_WORK: f64 = 4e8;

/// The parts of a self-intersecting closed input that lie inside its own solid: a surface point
/// p with outward normal n is *buried* when the winding number just in front of it,
/// at p + [`BURIED_OFFSET`] n, is not 0: there the point is inside another part of the model (a
/// cow's tail sunk into its rump), and a remesh through it would cross that part. Sampling only
/// the points that are not buried gives the outer surface of the model (the boundary of the
/// union of its parts). Closed meshes are tested by ray crossings, open ones (whose parts may
/// still cross, as the beetle's do) by the generalized winding number.
pub struct BuriedTest<'a> {
    /// Closed meshes: ray crossings; open ones: the generalized winding number.
    winding: Option<RayWinding<'a>>,
    mesh: &'a TriMesh,
    /// +1 for an outward-oriented mesh, -1 for an inward one.
    orientation: i32,
}

impl<'a> BuriedTest<'a> {
    /// The test for `mesh` (bbox-100 units), or `None` when no point of it can be buried: it
    /// does not intersect itself ([`self_intersections`]). `points` is how many points will be
    /// tested: an open mesh is tested with the generalized winding number, O(F) per point, and
    /// gets `None` when F · points exceeds `MAX_OPEN_WORK` (4e8).
    pub fn new(mesh: &'a TriMesh, points: usize) -> Option<Self> {
        if self_intersections(mesh).pairs == 0 {
            return None;
        }
        let orientation = if mesh.signed_volume() < 0.0 { -1 } else { 1 };
        let winding = if topology(mesh).boundary_edges == 0 {
            Some(RayWinding::new(mesh))
        } else if (mesh.triangles.len() as f64) * (points as f64) <= MAX_OPEN_WORK {
            None
        } else {
            return None;
        };
        Some(BuriedTest {
            winding,
            mesh,
            orientation,
        })
    }

    /// Whether the surface point `p` with unit normal `n` (the mesh's own orientation) is
    /// buried: the winding number at p + [`BURIED_OFFSET`] n is at least 1 (closed mesh) or
    /// above 1/2 (open mesh), counted along the mesh's orientation.
    pub fn is_buried(&self, p: DVec3, n: DVec3) -> bool {
        let front = p + BURIED_OFFSET * n * self.orientation as f64;
        match &self.winding {
            Some(w) => w.winding_number(front) * self.orientation > 0,
            None => generalized_winding_number(self.mesh, front) * self.orientation as f64 > 0.5,
        }
    }

    /// Removes the buried items of `items` (keeping the order of the others), each seen as the
    /// surface point and normal `point` gives; returns how many were removed. In parallel.
    pub fn remove_buried<T>(
        &self,
        items: &mut Vec<T>,
        point: impl Fn(&T) -> (DVec3, DVec3),
    ) -> usize {
        let buried = self.buried(&items.iter().map(point).collect::<Vec<_>>());
        let mut keep = buried.iter().map(|b| !b);
        items.retain(|_| keep.next().unwrap_or(true));
        buried.iter().filter(|&&b| b).count()
    }

    /// [`BuriedTest::is_buried`] for every point, in parallel.
    pub fn buried(&self, points: &[(DVec3, DVec3)]) -> Vec<bool> {
        points
            .par_iter()
            .map(|&(p, n)| self.is_buried(p, n))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes::cuboid;

    fn union_of(a: &TriMesh, b: &TriMesh) -> TriMesh {
        let mut m = a.clone();
        let off = m.positions.len() as u32;
        m.positions.extend(b.positions.iter().copied());
        m.triangles
            .extend(b.triangles.iter().map(|t| t.map(|v| v + off)));
        m
    }

    #[test]
    fn winding_numbers_count_the_layers_of_solid() {
        let a = cuboid(DVec3::ZERO, DVec3::splat(2.0));
        let b = cuboid(DVec3::splat(1.0), DVec3::splat(3.0));
        let m = union_of(&a, &b);
        let w = RayWinding::new(&m);
        assert_eq!(w.winding_number(DVec3::splat(0.5)), 1);
        assert_eq!(w.winding_number(DVec3::splat(1.5)), 2);
        assert_eq!(w.winding_number(DVec3::splat(2.5)), 1);
        assert_eq!(w.winding_number(DVec3::splat(3.5)), 0);
        assert_eq!(w.winding_number(DVec3::new(0.5, 2.5, 0.5)), 0);
        // Inward orientation negates it.
        let mut flipped = m.clone();
        flipped.flip_orientation();
        assert_eq!(
            RayWinding::new(&flipped).winding_number(DVec3::splat(1.5)),
            -2
        );
    }

    #[test]
    fn the_generalized_winding_number_agrees_with_the_ray_count_on_a_closed_mesh() {
        let a = cuboid(DVec3::ZERO, DVec3::splat(2.0));
        let b = cuboid(DVec3::splat(1.0), DVec3::splat(3.0));
        let m = union_of(&a, &b);
        let w = RayWinding::new(&m);
        for p in [0.5, 1.5, 2.5, 3.5, -1.0] {
            let q = DVec3::new(p, p + 0.013, p - 0.011);
            let g = generalized_winding_number(&m, q);
            assert!((g - w.winding_number(q) as f64).abs() < 1e-9, "{q}: {g}");
        }
    }

    #[test]
    fn the_parts_of_each_box_inside_the_other_are_buried() {
        let a = cuboid(DVec3::ZERO, DVec3::splat(2.0));
        let b = cuboid(DVec3::splat(1.0), DVec3::splat(3.0));
        let m = union_of(&a, &b);
        let t = BuriedTest::new(&m, 100).expect("the boxes cross");
        // a's top face at z = 2: buried where it is inside b (x, y > 1).
        assert!(t.is_buried(DVec3::new(1.5, 1.5, 2.0), DVec3::Z));
        assert!(!t.is_buried(DVec3::new(0.5, 0.5, 2.0), DVec3::Z));
        // b's bottom face at z = 1, normal down: buried inside a.
        assert!(t.is_buried(DVec3::new(1.5, 1.5, 1.0), -DVec3::Z));
        assert!(!t.is_buried(DVec3::new(2.5, 2.5, 1.0), -DVec3::Z));
        // Apart, or a box alone: nothing to test.
        assert!(BuriedTest::new(&a, 100).is_none());
        let far = union_of(&a, &cuboid(DVec3::splat(5.0), DVec3::splat(6.0)));
        assert!(BuriedTest::new(&far, 100).is_none());
        // Open: b without its top face (z = 3) still buries a's top face inside it.
        let mut open = m.clone();
        open.triangles
            .retain(|t| !t.iter().all(|&v| open.positions[v as usize].z == 3.0));
        let t = BuriedTest::new(&open, 100).expect("still crossing");
        assert!(t.is_buried(DVec3::new(1.5, 1.5, 2.0), DVec3::Z));
        assert!(!t.is_buried(DVec3::new(0.5, 0.5, 2.0), DVec3::Z));
        // Too much work for the O(F) test: none.
        assert!(BuriedTest::new(&open, 1 << 40).is_none());
    }
}
