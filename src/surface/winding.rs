//! Which parts of a self-intersecting input lie inside the solid: the winding number of a
//! closed mesh by signed ray crossings, and the "buried" test of the sampler built on it.

use glam::DVec3;
use rayon::prelude::*;

use super::front_regions::FrontRegions;
use super::winding_number::{generalized_winding_number, RayWinding};
use crate::geometry::tolerance::BURIED_OFFSET;
use crate::mesh::topology::topology;
use crate::mesh::TriMesh;

/// The largest (faces × points to test) for which [`BuriedTest`] uses the generalized winding
/// number on an open mesh (O(F) per point): about a second on 2 cores.
pub const MAX_OPEN_WORK: f64 = 4e8;

/// How many points of a region [`BuriedTest::buried`] counts on their own before it takes the
/// region's winding number for the rest: the count must agree at all of them (the ray count can
/// be wrong at a point whose ray passes exactly through an edge; three such points in one region
/// would take three such coincidences).
pub const REGION_PROBES: u8 = 3;

/// The fewest points to test per face for which [`BuriedTest`] builds the regions in front of the
/// surface (`surface::front_regions`): building them costs about a quarter as much per face as
/// counting the winding number at one point costs per point (`docs/decisions/speed.md`), so
/// they pay off from about a quarter of a point per face; half a point leaves room.
pub const MIN_POINTS_PER_FACE_FOR_REGIONS: f64 = 0.5;

/// The parts of a self-intersecting closed input that lie inside its own solid: a surface point
/// p with outward normal n is *buried* when the winding number just in front of it,
/// at p + [`BURIED_OFFSET`] n, is not 0: there the point is inside another part of the model (a
/// cow's tail sunk into its rump), and a remesh through it would cross that part. Sampling only
/// the points that are not buried gives the outer surface of the model (the boundary of the
/// union of its parts). Closed meshes are tested by ray crossings, open ones (whose parts may
/// still cross, as the beetle's do) by the generalized winding number.
///
/// On a closed mesh whose faces form a 2-cycle, the test of many points at once
/// ([`BuriedTest::buried`]) counts the winding number once per region of the space in front of
/// the surface that no face passes through (`surface::front_regions`) instead of once per point:
/// the answer is the same, since the winding number is constant on each such region, and only the
/// points near where the surface crosses or nearly touches itself are counted on their own.
pub struct BuriedTest<'a> {
    /// Closed meshes: ray crossings; open ones: the generalized winding number.
    winding: Option<RayWinding<'a>>,
    /// The regions in front of a closed mesh's faces (when they form a 2-cycle and there are
    /// enough points to test for them to pay off).
    regions: Option<FrontRegions>,
    mesh: &'a TriMesh,
    /// +1 for an outward-oriented mesh, -1 for an inward one.
    orientation: i32,
}

/// What is known of one region's winding number while [`BuriedTest::buried`] probes it.
#[derive(Clone, Copy)]
enum Probed {
    /// No point of the region counted yet.
    Unseen,
    /// Every probe so far counted this.
    Agreed(i32),
    /// Two probes disagreed: every point of the region is counted on its own.
    Mixed,
}

impl<'a> BuriedTest<'a> {
    /// The test for `mesh` (bbox-100 units), or `None` when no point of it can be buried: it
    /// does not intersect itself ([`self_intersections`](crate::check::self_intersections)).
    /// `points` is how many points will be tested: an open mesh is tested with the generalized
    /// winding number, O(F) per point, and gets `None` when F · points exceeds `MAX_OPEN_WORK`
    /// (4e8); a closed one gets the regions in front of its surface when there are at least
    /// `MIN_POINTS_PER_FACE_FOR_REGIONS` (0.5) points per face.
    pub fn new(mesh: &'a TriMesh, points: usize) -> Option<Self> {
        // The BVH of the ray count serves the test for self-intersections too.
        let rays = RayWinding::new(mesh);
        if !rays.crosses_itself() {
            return None;
        }
        Self::of_crossing(mesh, points, rays)
    }

    /// [`BuriedTest::new`] and the pairs of `mesh`'s faces that cross
    /// ([`intersecting_pairs`](crate::geometry::self_intersection::intersecting_pairs), found
    /// on the test's own BVH), also when there is no test (an open input too large for it): the
    /// output's faces where the input's cross are the input's crossings either way.
    pub fn with_crossings(mesh: &'a TriMesh, points: usize) -> (Option<Self>, Vec<[u32; 2]>) {
        let rays = RayWinding::new(mesh);
        let pairs = rays.crossing_pairs();
        if pairs.is_empty() {
            return (None, pairs);
        }
        (Self::of_crossing(mesh, points, rays), pairs)
    }

    /// The test of a `mesh` that crosses itself, on its ray count `rays`.
    fn of_crossing(mesh: &'a TriMesh, points: usize, rays: RayWinding<'a>) -> Option<Self> {
        let orientation = if mesh.signed_volume() < 0.0 { -1 } else { 1 };
        let winding = if topology(mesh).boundary_edges == 0 {
            Some(rays)
        } else if (mesh.triangles.len() as f64) * (points as f64) <= MAX_OPEN_WORK {
            None
        } else {
            return None;
        };
        let regions = winding.as_ref().and_then(|w| {
            (points as f64 >= MIN_POINTS_PER_FACE_FOR_REGIONS * w.face_count() as f64)
                .then(|| FrontRegions::new(w, orientation as f64))
                .flatten()
        });
        Some(BuriedTest {
            winding,
            regions,
            mesh,
            orientation,
        })
    }

    /// The point the test counts the winding number at for the surface point `p` with unit
    /// normal `n`: p + [`BURIED_OFFSET`] n, n turned outward.
    fn front(&self, p: DVec3, n: DVec3) -> DVec3 {
        p + BURIED_OFFSET * n * self.orientation as f64
    }

    /// Whether the winding number `w` (closed mesh) means buried.
    fn buried_at(&self, w: i32) -> bool {
        w * self.orientation > 0
    }

    /// Whether the surface point `p` with unit normal `n` (the mesh's own orientation) is
    /// buried: the winding number at p + [`BURIED_OFFSET`] n is at least 1 (closed mesh) or
    /// above 1/2 (open mesh), counted along the mesh's orientation.
    pub fn is_buried(&self, p: DVec3, n: DVec3) -> bool {
        let front = self.front(p, n);
        match &self.winding {
            Some(w) => self.buried_at(w.winding_number(front)),
            None => generalized_winding_number(self.mesh, front) * self.orientation as f64 > 0.5,
        }
    }

    /// The vertices of `mesh` as points for [`BuriedTest::buried`]: each with its normal
    /// ([`TriMesh::vertex_normals`]) and the first face it is a corner of (`None` for an
    /// unreferenced vertex).
    pub(crate) fn vertex_points(mesh: &TriMesh) -> Vec<(DVec3, DVec3, Option<u32>)> {
        let mut vertex_face = vec![None; mesh.positions.len()];
        for (f, t) in mesh.triangles.iter().enumerate().rev() {
            for &v in t {
                if let Some(slot) = vertex_face.get_mut(v as usize) {
                    *slot = Some(f as u32);
                }
            }
        }
        mesh.positions
            .iter()
            .zip(mesh.vertex_normals())
            .zip(vertex_face)
            .map(|((&p, n), f)| (p, n, f))
            .collect()
    }

    /// Removes the buried items of `items` (keeping the order of the others), each seen as the
    /// surface point, normal and face `point` gives (see [`BuriedTest::buried`]); returns how
    /// many were removed. In parallel.
    pub fn remove_buried<T>(
        &self,
        items: &mut Vec<T>,
        point: impl Fn(&T) -> (DVec3, DVec3, Option<u32>),
    ) -> usize {
        let buried = self.buried(&items.iter().map(point).collect::<Vec<_>>());
        let mut keep = buried.iter().map(|b| !b);
        items.retain(|_| keep.next().unwrap_or(true));
        buried.iter().filter(|&&b| b).count()
    }

    /// [`BuriedTest::is_buried`] for every point `(p, n, face)`, where `face` is a face of the
    /// mesh that p lies on or at a corner of, when known: the same answers, in parallel and
    /// deterministic. With the regions in front of the surface (closed meshes whose faces form a
    /// 2-cycle, tested at enough points), a point in front of a face with a region is given the
    /// region's winding number, counted at the region's first `REGION_PROBES` (3) such points
    /// (in the order given) and taken only when they all agree; every other point is counted on
    /// its own.
    pub fn buried(&self, points: &[(DVec3, DVec3, Option<u32>)]) -> Vec<bool> {
        let (Some(winding), Some(regions)) = (&self.winding, &self.regions) else {
            return points
                .par_iter()
                .map(|&(p, n, _)| self.is_buried(p, n))
                .collect();
        };
        let fronts: Vec<DVec3> = points.iter().map(|&(p, n, _)| self.front(p, n)).collect();
        let region: Vec<Option<u32>> = points
            .par_iter()
            .zip(&fronts)
            .map(|(&(_, _, face), &q)| face.and_then(|f| regions.region_of(winding, q, f)))
            .collect();
        // The first REGION_PROBES points of each region are probes, counted on their own like
        // the points without a region.
        let mut probes = vec![0u8; regions.count()];
        let probe: Vec<bool> = region
            .iter()
            .map(|r| match r.and_then(|k| probes.get_mut(k as usize)) {
                Some(c) if *c < REGION_PROBES => {
                    *c += 1;
                    true
                }
                Some(_) => false,
                None => true,
            })
            .collect();
        let counted: Vec<Option<i32>> = fronts
            .par_iter()
            .zip(&probe)
            .map(|(&q, &p)| p.then(|| winding.winding_number(q)))
            .collect();
        let mut probed = vec![Probed::Unseen; regions.count()];
        for (r, w) in region.iter().zip(&counted) {
            if let (Some(k), Some(w)) = (r, w) {
                if let Some(state) = probed.get_mut(*k as usize) {
                    *state = match *state {
                        Probed::Unseen => Probed::Agreed(*w),
                        Probed::Agreed(v) if v == *w => Probed::Agreed(v),
                        _ => Probed::Mixed,
                    };
                }
            }
        }
        region
            .par_iter()
            .zip(&counted)
            .zip(&fronts)
            .map(|((r, w), &q)| {
                let w = match (w, r.and_then(|k| probed.get(k as usize))) {
                    (Some(w), _) => *w,
                    (None, Some(Probed::Agreed(v))) => *v,
                    (None, _) => winding.winding_number(q),
                };
                self.buried_at(w)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes::{cuboid, union_of, uv_sphere};
    use crate::surface::candidates::surface_candidates;

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

    /// The candidates on `m` (area-uniform, with their faces and face normals) and its vertices
    /// (with their normals and a face they are a corner of).
    fn test_points(m: &TriMesh, count: usize, seed: u64) -> Vec<(DVec3, DVec3, Option<u32>)> {
        surface_candidates(m, count, seed)
            .iter()
            .map(|c| (c.position, c.normal, Some(c.face)))
            .chain(BuriedTest::vertex_points(m))
            .collect()
    }

    /// Two spheres of radius 10 whose centres are 12 apart along z, each with a cap inside the
    /// other (crossing on the circle at z = 6), as one mesh, oriented outward.
    fn two_crossing_spheres() -> TriMesh {
        let a = uv_sphere(10.0, 24, 48);
        let b = TriMesh::new(
            a.positions.iter().map(|&p| p + DVec3::Z * 12.0).collect(),
            a.triangles.clone(),
        );
        union_of(&a, &b)
    }

    /// The crossing pairs found on the test's BVH are the whole search's, and there are none
    /// (and no test) for spheres apart.
    #[test]
    fn the_crossings_found_with_the_test_are_those_of_the_whole_search() {
        use crate::geometry::self_intersection::intersecting_pairs;
        let m = two_crossing_spheres();
        let (test, pairs) = BuriedTest::with_crossings(&m, 1000);
        assert!(test.is_some());
        assert!(!pairs.is_empty());
        assert_eq!(pairs, intersecting_pairs(&m.positions, &m.triangles));
        let a = uv_sphere(10.0, 24, 48);
        let apart = union_of(
            &a,
            &TriMesh::new(
                a.positions.iter().map(|&p| p + DVec3::Z * 30.0).collect(),
                a.triangles.clone(),
            ),
        );
        let (test, pairs) = BuriedTest::with_crossings(&apart, 1000);
        assert!(test.is_none() && pairs.is_empty());
    }

    #[test]
    fn the_regions_give_every_point_the_per_point_answer() {
        // As given (outward) and turned inside out (the test follows the orientation).
        let mut inward = two_crossing_spheres();
        inward.flip_orientation();
        for m in [two_crossing_spheres(), inward] {
            let points = test_points(&m, 20_000, 3);
            let test = BuriedTest::new(&m, points.len()).expect("the spheres cross");
            let (Some(winding), Some(regions)) = (&test.winding, &test.regions) else {
                panic!("a closed 2-cycle with enough points gets its regions");
            };
            let fast = test.buried(&points);
            // The same answer as the point-by-point test for every point ...
            for (k, (&(p, n, _), &got)) in points.iter().zip(&fast).enumerate() {
                assert_eq!(got, test.is_buried(p, n), "point {k} at {p}");
            }
            // ... which is the true one away from the circle where the spheres cross (z = 6):
            // buried where inside the other sphere.
            let mut in_regions = 0;
            for (&(p, n, f), &got) in points.iter().zip(&fast) {
                if (p.z - 6.0).abs() > 1.0 {
                    // On a (centred at 0) the other is b (at 12 z), and the reverse.
                    let on_a = (p.length() - 10.0).abs() < 0.5;
                    let other = if on_a { DVec3::Z * 12.0 } else { DVec3::ZERO };
                    assert_eq!(got, p.distance(other) < 10.0, "{p}");
                }
                let q = test.front(p, n);
                in_regions +=
                    usize::from(f.and_then(|f| regions.region_of(winding, q, f)).is_some());
            }
            // Nearly every point took its region's answer: the regions were tested.
            assert!(regions.count() >= 4, "{}", regions.count());
            assert!(
                in_regions as f64 > 0.9 * points.len() as f64,
                "{in_regions}"
            );
            assert!(fast.iter().filter(|&&b| b).count() > points.len() / 20);
        }
    }

    #[test]
    fn points_without_a_face_or_off_their_face_are_tested_on_their_own() {
        let m = two_crossing_spheres();
        let mut points = test_points(&m, 5_000, 1);
        // No face, a face far away, a face index out of range.
        let n = points.len();
        for k in (0..n).step_by(3) {
            points[k].2 = match k % 9 {
                0 => None,
                3 => Some(((k * 7919) % m.face_count()) as u32),
                _ => Some(u32::MAX),
            };
        }
        let test = BuriedTest::new(&m, 4 * points.len()).expect("the spheres cross");
        assert!(test.regions.is_some());
        let fast = test.buried(&points);
        for (&(p, n, _), &got) in points.iter().zip(&fast) {
            assert_eq!(got, test.is_buried(p, n), "{p}");
        }
        // Too few points for the regions to pay off: point by point.
        assert!(BuriedTest::new(&m, 10).unwrap().regions.is_none());
    }

    #[test]
    fn a_face_with_an_index_out_of_range_is_left_out() {
        let a = cuboid(DVec3::ZERO, DVec3::splat(2.0));
        let b = cuboid(DVec3::splat(1.0), DVec3::splat(3.0));
        let mut m = union_of(&a, &b);
        m.triangles.push([0, 1, 999]);
        let w = RayWinding::new(&m);
        assert!(w.crosses_itself() && !w.counts(24));
        assert_eq!(w.winding_number(DVec3::splat(1.5)), 2);
        // Apart: no test, without reading the bad face's corners.
        let mut apart = a.clone();
        apart.triangles.push([0, 1, 999]);
        assert!(BuriedTest::new(&apart, 1000).is_none());
    }
}
