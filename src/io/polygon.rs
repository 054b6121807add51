//! Triangulation of the polygons (faces with more than three corners) that OBJ and PLY files
//! hold.
//!
//! A fan from the first corner is right only for convex polygons: a concave one (an L-shaped
//! cap, a comb) gives triangles that overlap each other and leave part of the polygon out. We
//! triangulate instead in the polygon's best-fit plane (Newell's normal) with a constrained
//! Delaunay triangulation (spade) whose constraints are the polygon's edges, and keep the
//! triangles inside the boundary. This is what other mesh tools do (e.g. Blender's polygon fill
//! and OpenMesh's triangulation of non-convex faces both triangulate in a projection plane).
//!
//! Source for Newell's normal: M. E. Newell, via Sutherland, Sproull and Schumacker, "A
//! characterization of ten hidden-surface algorithms", ACM Computing Surveys 6(1), 1974.

use glam::{DVec2, DVec3};
use spade::handles::FixedFaceHandle;
use spade::{ConstrainedDelaunayTriangulation, HasPosition, Point2, Triangulation};

use crate::geometry::tangent_basis;

/// The triangles of the polygon whose corners, in order, are `corners` (indices into
/// `positions`, every one in range), oriented like the polygon's corner order.
///
/// A polygon that projects to a simple polygon in its best-fit plane (the plane normal to its
/// Newell normal; corners distinct in index and in projected position, edges meeting only at
/// shared corners) gives `corners.len() - 2` triangles covering it exactly, without overlap.
/// Any other polygon (a repeated corner, zero area, a boundary that crosses or touches itself
/// in the projection) falls back to the fan from the first corner, as before this function
/// existed: the reader's clean-up then drops triangles that collapse. Three corners give the
/// triangle itself; fewer give nothing.
///
/// Cost: O(n log n) expected for n corners (spade's insertion and constraint walks).
///
/// # Panics
///
/// Panics if a corner index is out of range of `positions` (callers check indices first).
pub(super) fn triangulate_polygon(positions: &[DVec3], corners: &[u32]) -> Vec<[u32; 3]> {
    match corners.len() {
        0..=2 => Vec::new(),
        3 => vec![[corners[0], corners[1], corners[2]]],
        _ => constrained(positions, corners).unwrap_or_else(|| fan(corners)),
    }
}

/// The fan from the first corner: `corners.len() - 2` triangles.
fn fan(corners: &[u32]) -> Vec<[u32; 3]> {
    (1..corners.len().saturating_sub(1))
        .map(|k| [corners[0], corners[k], corners[k + 1]])
        .collect()
}

/// A polygon corner in the projection plane, with its index in the polygon.
#[derive(Clone, Copy)]
struct Corner {
    p: Point2<f64>,
    k: usize,
}

impl HasPosition for Corner {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.p
    }
}

/// The constrained triangulation of a polygon of at least four corners, or `None` when the
/// polygon is not simple in its best-fit plane (see [`triangulate_polygon`]).
fn constrained(positions: &[DVec3], corners: &[u32]) -> Option<Vec<[u32; 3]>> {
    let n = corners.len();
    let mut sorted = corners.to_vec();
    sorted.sort_unstable();
    if sorted.windows(2).any(|w| w[0] == w[1]) {
        return None;
    }
    let pts: Vec<DVec3> = corners.iter().map(|&c| positions[c as usize]).collect();
    // Centred first: Newell's sum and the projection then lose less to rounding.
    let center = pts.iter().sum::<DVec3>() / n as f64;
    let newell: DVec3 = (0..n)
        .map(|i| (pts[i] - center).cross(pts[(i + 1) % n] - center))
        .sum();
    let normal = newell.try_normalize()?;
    // u × w = normal, so the corner order is counter-clockwise in (u, w) coordinates (its
    // projected signed area is |newell| / 2 > 0), and so are spade's faces.
    let (u, w) = tangent_basis(normal);
    let flat: Vec<DVec2> = pts
        .iter()
        .map(|&p| DVec2::new((p - center).dot(u), (p - center).dot(w)))
        .collect();

    let mut cdt: ConstrainedDelaunayTriangulation<Corner> = ConstrainedDelaunayTriangulation::new();
    let mut handles = Vec::with_capacity(n);
    for (k, q) in flat.iter().enumerate() {
        let h = cdt
            .insert(Corner {
                p: Point2::new(q.x, q.y),
                k,
            })
            .ok()?;
        // Two corners at one projected position: spade keeps one vertex for both.
        if cdt.vertex(h).data().k != k {
            return None;
        }
        handles.push(h);
    }
    for k in 0..n {
        let (a, b) = (handles[k], handles[(k + 1) % n]);
        // Empty when the edge crosses an earlier one; several edges when a corner lies on it.
        if cdt.try_add_constraint(a, b).len() != 1 {
            return None;
        }
    }
    if cdt.num_constraints() != n {
        return None;
    }

    // Inside or outside for every inner face: faces beside the convex hull are inside exactly
    // when the hull edge is a polygon edge; crossing a polygon edge flips the side, crossing
    // any other edge keeps it.
    let mut inside: Vec<Option<bool>> = vec![None; cdt.num_all_faces()];
    let mut stack: Vec<(FixedFaceHandle<spade::handles::InnerTag>, bool)> = Vec::new();
    for face in cdt.inner_faces() {
        for e in face.adjacent_edges() {
            if e.rev().face().is_outer() {
                stack.push((face.fix(), cdt.is_constraint_edge(e.as_undirected().fix())));
            }
        }
    }
    while let Some((f, side)) = stack.pop() {
        match inside[f.index()] {
            Some(s) if s == side => continue,
            // A face reached as both inside and outside: the boundary is not a simple loop.
            Some(_) => return None,
            None => inside[f.index()] = Some(side),
        }
        for e in cdt.face(f).adjacent_edges() {
            if let Some(g) = e.rev().face().as_inner() {
                let crossed = cdt.is_constraint_edge(e.as_undirected().fix());
                stack.push((g.fix(), side != crossed));
            }
        }
    }

    // As corner positions, each triangle starting at its first corner in the polygon's order,
    // the triangles sorted: a convex quad split like the fan comes out as the fan.
    let mut out: Vec<[usize; 3]> = Vec::with_capacity(n - 2);
    for face in cdt.inner_faces() {
        match inside[face.fix().index()] {
            Some(true) => {
                let mut t = face.vertices().map(|v| v.data().k);
                let first = (0..3).min_by_key(|&i| t[i]).unwrap_or(0);
                t.rotate_left(first);
                out.push(t);
            }
            Some(false) => {}
            None => return None,
        }
    }
    out.sort_unstable();
    (out.len() == n - 2).then(|| out.iter().map(|t| t.map(|k| corners[k])).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The area vector (half the sum of cross products) of triangles.
    fn area_vector(p: &[DVec3], tris: &[[u32; 3]]) -> DVec3 {
        tris.iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| p[i as usize]);
                (b - a).cross(c - a) * 0.5
            })
            .sum()
    }

    /// The area vector of a polygon (Newell).
    fn polygon_area_vector(p: &[DVec3], corners: &[u32]) -> DVec3 {
        let n = corners.len();
        (0..n)
            .map(|i| p[corners[i] as usize].cross(p[corners[(i + 1) % n] as usize]) * 0.5)
            .sum()
    }

    /// Even-odd point-in-polygon test in the xy plane.
    fn inside_xy(q: DVec3, poly: &[DVec3]) -> bool {
        let mut inside = false;
        let m = poly.len();
        for i in 0..m {
            let (a, c) = (poly[i], poly[(i + 1) % m]);
            if (a.y > q.y) != (c.y > q.y) && q.x < a.x + (q.y - a.y) * (c.x - a.x) / (c.y - a.y) {
                inside = !inside;
            }
        }
        inside
    }

    /// Checks a triangulation of a planar polygon in z = const: n - 2 triangles, each with
    /// positive area about +z (the polygon being counter-clockwise), centroid inside, areas
    /// summing to the polygon's, every triangle made of the polygon's corners.
    fn check_planar_ccw(p: &[DVec3], corners: &[u32]) {
        let tris = triangulate_polygon(p, corners);
        assert_eq!(tris.len(), corners.len() - 2, "{tris:?}");
        let poly: Vec<DVec3> = corners.iter().map(|&c| p[c as usize]).collect();
        let mut total = 0.0;
        for t in &tris {
            assert!(t.iter().all(|v| corners.contains(v)), "{t:?}");
            let [a, b, c] = t.map(|i| p[i as usize]);
            let area = (b - a).cross(c - a).z * 0.5;
            assert!(area > 0.0, "{t:?} is reversed or flat: {area}");
            assert!(inside_xy((a + b + c) / 3.0, &poly), "{t:?} lies outside");
            total += area;
        }
        let expected = polygon_area_vector(p, corners).z;
        assert!(
            (total - expected).abs() < 1e-12 * expected,
            "{total} vs {expected}"
        );
    }

    fn xy(points: &[[f64; 2]]) -> Vec<DVec3> {
        points.iter().map(|&[x, y]| DVec3::new(x, y, 0.0)).collect()
    }

    #[test]
    fn concave_polygons_are_covered_exactly_without_overlap() {
        // An L (its reflex corner at index 3, so the fan from 0 would overlap).
        let l = xy(&[[0., 0.], [2., 0.], [2., 1.], [1., 1.], [1., 2.], [0., 2.]]);
        // Start at every corner: some starts make the fan wrong, none may make this wrong.
        for s in 0..6u32 {
            let corners: Vec<u32> = (0..6).map(|k| (k + s) % 6).collect();
            check_planar_ccw(&l, &corners);
        }
        // A five-pointed star (10 corners, 5 reflex).
        let star: Vec<DVec3> = (0..10)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 10.0;
                let r = if k % 2 == 0 { 1.0 } else { 0.4 };
                DVec3::new(r * a.cos(), r * a.sin(), 3.0)
            })
            .collect();
        check_planar_ccw(&star, &(0..10).collect::<Vec<_>>());
        // A comb: five teeth of width 1 and height 2 on a base of height 1.
        let mut comb = vec![[0., 0.], [9., 0.]];
        for t in (0..5).rev() {
            let x = 2.0 * t as f64;
            comb.extend([[x + 1.0, 3.0], [x, 3.0]]);
            if t > 0 {
                comb.extend([[x, 1.0], [x - 1.0, 1.0]]);
            }
        }
        let comb = xy(&comb);
        check_planar_ccw(&comb, &(0..comb.len() as u32).collect::<Vec<_>>());
    }

    #[test]
    fn orientation_follows_the_corner_order() {
        // The L in clockwise order: every triangle must be clockwise about +z.
        let l = xy(&[[0., 0.], [0., 2.], [1., 2.], [1., 1.], [2., 1.], [2., 0.]]);
        let corners: Vec<u32> = (0..6).collect();
        let tris = triangulate_polygon(&l, &corners);
        assert_eq!(tris.len(), 4);
        for t in &tris {
            let [a, b, c] = t.map(|i| l[i as usize]);
            assert!((b - a).cross(c - a).z < 0.0, "{t:?}");
        }
        let (got, want) = (area_vector(&l, &tris), polygon_area_vector(&l, &corners));
        assert!((got - want).length() < 1e-12, "{got} vs {want}");
    }

    #[test]
    fn a_warped_polygon_in_a_tilted_plane_is_triangulated() {
        // The L, tilted out of every coordinate plane, with corners moved off the plane by up
        // to 1% of its size.
        let l = [[0., 0.], [2., 0.], [2., 1.], [1., 1.], [1., 2.], [0., 2.]];
        let (e1, e2) = (
            DVec3::new(1.0, 0.3, -0.2).normalize(),
            DVec3::new(-0.2, 0.5, 1.0).normalize(),
        );
        let normal = e1.cross(e2).normalize();
        let offset = DVec3::new(10.0, -4.0, 7.0);
        let p: Vec<DVec3> = l
            .iter()
            .enumerate()
            .map(|(k, &[x, y])| {
                offset + e1 * x + e2 * y + normal * 0.02 * if k % 2 == 0 { 1.0 } else { -1.0 }
            })
            .collect();
        let corners: Vec<u32> = (0..6).collect();
        let tris = triangulate_polygon(&p, &corners);
        assert_eq!(tris.len(), 4);
        let want = polygon_area_vector(&p, &corners);
        for t in &tris {
            let [a, b, c] = t.map(|i| p[i as usize]);
            assert!((b - a).cross(c - a).dot(want) > 0.0, "{t:?} is reversed");
        }
        // The projected areas add up (triangles do not overlap in the plane).
        let got = area_vector(&p, &tris).dot(want.normalize());
        assert!(
            (got - want.length()).abs() < 1e-9,
            "{got} vs {}",
            want.length()
        );
        // Not the fan, which would cover the reflex corner twice.
        assert_ne!(tris, fan(&corners));
    }

    #[test]
    fn degenerate_polygons_fall_back_to_the_fan_without_panicking() {
        let sq = xy(&[[0., 0.], [1., 0.], [1., 1.], [0., 1.], [2., 2.]]);
        let cases: Vec<(Vec<DVec3>, Vec<u32>)> = vec![
            // A repeated corner.
            (sq.clone(), vec![0, 1, 1, 2, 3]),
            (sq.clone(), vec![0, 1, 2, 0, 3]),
            // Collinear corners: zero area.
            (
                xy(&[[0., 0.], [1., 0.], [2., 0.], [3., 0.]]),
                vec![0, 1, 2, 3],
            ),
            // All at one point.
            (vec![DVec3::ONE; 4], vec![0, 1, 2, 3]),
            // A bow tie (the boundary crosses itself) and a figure with a touching corner.
            (sq.clone(), vec![0, 1, 3, 2]),
            (
                xy(&[[0., 0.], [2., 0.], [2., 2.], [1., 0.], [0., 2.]]),
                vec![0, 1, 2, 3, 4],
            ),
            // Two distinct corners at one position.
            (
                xy(&[[0., 0.], [1., 0.], [1., 1.], [1., 0.], [0., 1.]]),
                vec![0, 1, 2, 3, 4],
            ),
            // Tiny and huge coordinates.
            (sq.iter().map(|&q| q * 1e-300).collect(), vec![0, 1, 4, 3]),
            (sq.iter().map(|&q| q * 1e300).collect(), vec![0, 1, 4, 3]),
        ];
        for (p, corners) in &cases {
            let tris = triangulate_polygon(p, corners);
            assert_eq!(tris.len(), corners.len() - 2, "{corners:?}");
            assert!(tris.iter().flatten().all(|v| corners.contains(v)));
        }
        assert!(triangulate_polygon(&sq, &[0, 1]).is_empty());
        assert_eq!(triangulate_polygon(&sq, &[2, 0, 1]), vec![[2, 0, 1]]);
    }
}
