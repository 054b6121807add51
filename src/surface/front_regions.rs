//! The space just in front of a closed surface, cut into regions that no face of the surface
//! passes through, so that the buried test counts a winding number once per region instead of
//! once per point.
//!
//! The winding number of a closed surface (a 2-cycle: every edge used as often in one direction
//! as in the other) is constant on each connected part of the space off the surface. The buried
//! test ([`BuriedTest`](super::winding::BuriedTest)) counts it at p + d N, d =
//! [`BURIED_OFFSET`], for a point p of a face with front normal N. Here every face gets a thin
//! prism over it, between the heights d/2 and 3d/2 along its front normal (its corners moved
//! towards the centroid by a millionth of their distance, so that the faces next to it are apart
//! from it by more than rounding), kept only when no face of the surface meets it. Two faces
//! across a manifold edge are in one region when the two segments from their prisms' anchors
//! (the centroids lifted by d) to the junction over the edge (its midpoint lifted by d along the
//! mean of the two front normals) meet no face either. A region is then a connected set off the
//! surface: every point inside one of its prisms, or joined to one by a segment that meets no
//! face, has the region's winding number.
//!
//! Every "meets no face" is decided exactly for the floating-point coordinates, with no
//! tolerance. A separating axis settles most pairs first: the spans of the two point sets along
//! it, computed in floating point and widened by a bound on the rounding error, are apart (the
//! prism's height and sides, the face's normal, the cross products of their edges). The rest are
//! decided by Shewchuk's orientation predicates: a prism is the union of three tetrahedra, each
//! convex, and a face meets a tetrahedron exactly when a corner of the face is inside it or the
//! face meets one of the tetrahedron's faces. Where a test cannot be settled, the answer is the
//! safe one (the face gets no region, the faces are not linked, the point is counted on its own).
//!
//! Sources: the winding number as an invariant of the complement of a closed surface
//! (A. Jacobson, L. Kavan, O. Sorkine-Hornung, *Robust Inside-Outside Segmentation using
//! Generalized Winding Numbers*, ACM TOG 32(4), 2013, Sec. 2); separating planes of convex sets
//! (C. Ericson, *Real-Time Collision Detection*, Morgan Kaufmann, 2005, Sec. 5.2.1); the
//! predicates: J. R. Shewchuk, *Adaptive Precision Floating-Point Arithmetic and Fast Robust
//! Geometric Predicates*, Discrete Comput. Geom. 18, 1997.

use glam::DVec3;
use parry3d_f64::bounding_volume::Aabb;
use rayon::prelude::*;

use super::winding_number::RayWinding;
use crate::disjoint_sets::Dsu;
use crate::geometry::tolerance::BURIED_OFFSET;
use crate::geometry::triangle_intersection::{orient, segment_meets_triangle, triangles_intersect};

/// The height of a prism's bottom above its face, in units of [`BURIED_OFFSET`].
const PRISM_BOTTOM: f64 = 0.5;
/// The height of a prism's top above its face, in units of [`BURIED_OFFSET`].
const PRISM_TOP: f64 = 1.5;
/// How far a prism's corners are moved towards the face's centroid, relative to their distance
/// from it (dimensionless): far above rounding, so that a face that only touches this one at an
/// edge or a corner is apart from the prism by a margin the separating planes can certify, and
/// far below any size that matters (a point drawn closer than this to an edge is tested on its
/// own, or through a segment).
const PRISM_SHRINK: f64 = 1e-6;
/// The relative error bound of a dot product `n · (x - o)` of `f64` vectors, with room to spare:
/// the rounding error is at most about 4 · 2^-53 ≈ 4.4e-16 times `|n| · |x - o|` (componentwise
/// absolute values; N. J. Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed.,
/// SIAM 2002, Sec. 3.1). Dimensionless.
const DOT_ERROR: f64 = 1e-14;

/// A prism's corners: 0, 1, 2 the bottom (over the face's corners in order), 3, 4, 5 the top.
/// The three tetrahedra that make it up (each pair sharing a face).
const TETS: [[usize; 4]; 3] = [[0, 1, 2, 3], [1, 2, 3, 4], [2, 3, 4, 5]];
/// The faces of a tetrahedron, as indices of its corners.
const TET_FACES: [[usize; 3]; 4] = [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]];

/// How far around a face's bounding box the faces near it are listed, bbox-100 units: twice
/// [`BURIED_OFFSET`], room for the prism (up to 1.5 d above the face), the junctions (up to d)
/// and a vertex's test point (d from the vertex).
const NEAR_MARGIN: f64 = 2.0 * BURIED_OFFSET;

/// No face (an edge without a manifold neighbour).
const NO_FACE: u32 = u32::MAX;
/// The region of no face (its prism meets the surface, or it has none).
const NO_REGION: u32 = u32::MAX;

/// Bounds on `n · (x - o)` over the points `xs` that hold for the exact value: the computed
/// least and largest, widened by the rounding error bound ([`DOT_ERROR`]).
fn span(o: DVec3, n: DVec3, xs: &[DVec3]) -> (f64, f64) {
    let na = n.abs();
    xs.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            let d = x - o;
            let v = n.dot(d);
            let e = DOT_ERROR * na.dot(d.abs()) + f64::MIN_POSITIVE;
            (lo.min(v - e), hi.max(v + e))
        })
}

/// Whether two spans (see [`span`]) are certainly apart: then the plane `n · (x - o) = t`, for a
/// t between them, separates the two point sets, and so their convex hulls.
fn apart(a: (f64, f64), b: (f64, f64)) -> bool {
    a.1 < b.0 || b.1 < a.0
}

/// The thin prism in front of one face (bbox-100 units).
struct Prism {
    corners: [DVec3; 6],
    /// orient3d of each of [`TETS`] (nonzero: none is flat).
    tet_sides: [i8; 3],
    /// A point inside the prism: the face's centroid lifted by [`BURIED_OFFSET`].
    anchor: DVec3,
}

/// The directions a prism is first tested along for being apart from a triangle: its height and
/// the normals of its three sides, each with the prism's span along it (from its centroid).
struct PrismAxes {
    centroid: DVec3,
    /// The prism's bounding box.
    bounds: Aabb,
    /// The prism's height direction (the face's front normal), then the three sides' normals.
    axes: [DVec3; 4],
    /// The prism's span along each axis.
    spans: [(f64, f64); 4],
    /// The face's edge directions (the directions of the prism's top and bottom edges).
    edges: [DVec3; 3],
}

impl Prism {
    /// The prism over the triangle `face` along the unit `front` normal, and its axes; `None`
    /// when one of its tetrahedra is flat (a face too small for its coordinates to show the
    /// shrinking) or the anchor is not inside it.
    fn new(face: [DVec3; 3], front: DVec3) -> Option<(Prism, PrismAxes)> {
        let centroid = (face[0] + face[1] + face[2]) / 3.0;
        let shrunk = face.map(|x| x - PRISM_SHRINK * (x - centroid));
        let lift = |h: f64| shrunk.map(|x| x + h * BURIED_OFFSET * front);
        let (bottom, top) = (lift(PRISM_BOTTOM), lift(PRISM_TOP));
        let corners = [bottom[0], bottom[1], bottom[2], top[0], top[1], top[2]];
        if !corners.iter().all(|c| c.is_finite()) {
            return None;
        }
        let tet_sides =
            TETS.map(|t| orient(corners[t[0]], corners[t[1]], corners[t[2]], corners[t[3]]));
        if tet_sides.contains(&0) {
            return None;
        }
        let anchor = centroid + BURIED_OFFSET * front;
        let prism = Prism {
            corners,
            tet_sides,
            anchor,
        };
        if !prism.contains(anchor) {
            return None;
        }
        let edges = [0, 1, 2].map(|k| face[(k + 1) % 3] - face[k]);
        let axes = [
            front,
            front.cross(edges[0]),
            front.cross(edges[1]),
            front.cross(edges[2]),
        ];
        let spans = axes.map(|n| span(centroid, n, &corners));
        let bounds = prism.aabb();
        Some((
            prism,
            PrismAxes {
                centroid,
                bounds,
                axes,
                spans,
                edges,
            },
        ))
    }

    /// Whether `q` is in the closed prism (in one of its tetrahedra), exactly. The middle
    /// tetrahedron is tried first: it holds the prism's middle height over the face's middle
    /// (half of the points at mid-height, drawn uniformly over the face).
    fn contains(&self, q: DVec3) -> bool {
        self.contains_from(q, 1)
    }

    /// [`Prism::contains`], trying tetrahedron `first` first (the one q is expected in).
    fn contains_from(&self, q: DVec3, first: usize) -> bool {
        [first, (first + 1) % 3, (first + 2) % 3]
            .into_iter()
            .any(|k| in_tetrahedron(TETS[k].map(|i| self.corners[i]), self.tet_sides[k], q))
    }

    /// The bounding box of the corners (and so of the prism).
    fn aabb(&self) -> Aabb {
        let (lo, hi) = self.corners[1..]
            .iter()
            .fold((self.corners[0], self.corners[0]), |(lo, hi), &c| {
                (lo.min(c), hi.max(c))
            });
        Aabb::new(lo, hi)
    }

    /// Whether the closed triangle `g` (not flat) meets the closed prism, exactly; `axes` are
    /// the prism's ([`Prism::new`]), `height` g's span along the first (the prism's height). A
    /// separating axis settles most pairs (the coordinate axes, the prism's height and sides,
    /// g's normal, then the cross products of their edges: the candidates of the separating axis
    /// theorem); the rest are decided by exact predicates.
    fn meets(&self, axes: &PrismAxes, g: [DVec3; 3], height: (f64, f64)) -> bool {
        let o = axes.centroid;
        if apart(axes.spans[0], height) {
            return false;
        }
        if !boxes_meet(&axes.bounds, g) {
            return false;
        }
        if (1..4).any(|k| apart(axes.spans[k], span(o, axes.axes[k], &g))) {
            return false;
        }
        let g_edges = [g[1] - g[0], g[2] - g[1], g[0] - g[2]];
        let g_normal = g_edges[0].cross(g_edges[1]);
        if apart(span(o, g_normal, &self.corners), span(o, g_normal, &g)) {
            return false;
        }
        for d in g_edges {
            for e in [axes.axes[0]].iter().chain(&axes.edges) {
                let n = e.cross(d);
                if apart(span(o, n, &self.corners), span(o, n, &g)) {
                    return false;
                }
            }
        }
        let c = &self.corners;
        TETS.iter().zip(self.tet_sides).any(|(t, side)| {
            let tet = t.map(|i| c[i]);
            g.iter().any(|&x| in_tetrahedron(tet, side, x))
                || TET_FACES
                    .iter()
                    .any(|f| triangles_intersect(f.map(|i| tet[i]), g))
        })
    }
}

/// Whether `q` is in the closed tetrahedron `t` whose orient3d is `side` (nonzero), exactly:
/// each barycentric coordinate of q, as the orient3d with q in place of that corner, is not of
/// the other sign.
fn in_tetrahedron(t: [DVec3; 4], side: i8, q: DVec3) -> bool {
    (0..4).all(|k| {
        let mut s = t;
        s[k] = q;
        orient(s[0], s[1], s[2], s[3]) != -side
    })
}

/// Whether the box `inner` is inside the box `outer` (exact comparisons).
fn box_inside(inner: &Aabb, outer: &Aabb) -> bool {
    inner.mins.cmpge(outer.mins).all() && inner.maxs.cmple(outer.maxs).all()
}

/// Whether the closed box `b` meets the bounding box of the triangle `t` (exact comparisons).
fn boxes_meet(b: &Aabb, t: [DVec3; 3]) -> bool {
    let (lo, hi) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
    lo.cmple(b.maxs).all() && hi.cmpge(b.mins).all()
}

/// Whether the closed segment `a b` meets the closed triangle `t` (not flat), exactly: first
/// along t's normal (both ends certainly on one side), then by exact predicates.
fn segment_meets(a: DVec3, b: DVec3, t: [DVec3; 3]) -> bool {
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    if apart(span(t[0], n, &[a, b]), span(t[0], n, &t)) {
        return false;
    }
    segment_meets_triangle(a, b, t)
}

/// What the construction of [`FrontRegions`] finds for one face whose prism no face meets.
struct FaceFront {
    prism: Prism,
    /// For each edge (k: corners k, k + 1), whether the segment from the prism's anchor to the
    /// junction over the edge meets no face (false where the edge has no manifold neighbour).
    halves: [bool; 3],
    /// The counted faces whose bounding boxes meet the face's [`near_box`].
    near: Vec<u32>,
}

/// The regions in front of a closed surface that the surface does not pass through (see the
/// module doc), for the faces [`RayWinding`] counts.
pub(crate) struct FrontRegions {
    /// Each face's prism, when no face meets it.
    prisms: Vec<Option<Prism>>,
    /// Each face's region (dense, numbered in the order of their first face), or [`NO_REGION`].
    region: Vec<u32>,
    /// How many regions there are.
    count: usize,
    /// The side the prisms are on: +1 along the face normals, -1 against them.
    front: f64,
    /// Where each face's list in `near` starts (one more entry than faces).
    near_start: Vec<usize>,
    /// For each face with a prism, the counted faces whose bounding boxes meet its
    /// [`near_box`]: every face that meets that box is among them.
    near: Vec<u32>,
}

impl FrontRegions {
    /// The regions in front of the faces `winding` counts, on the side `front` gives (+1: along
    /// the face normals, -1: against them); `None` when those faces are not a 2-cycle (an edge
    /// used more often in one direction than in the other: a boundary, an inconsistent
    /// orientation, or a face left out as degenerate), where the ray count is no winding number
    /// and need not be constant off the surface. O(F log F), in parallel and deterministic.
    pub(crate) fn new(winding: &RayWinding, front: f64) -> Option<FrontRegions> {
        let faces = winding.face_count();
        // Every directed edge of a counted face, as (low, high, face, +1 when low -> high).
        let mut edges: Vec<(u32, u32, u32, i8)> = (0..faces)
            .filter(|&f| winding.counts(f))
            .flat_map(|f| {
                let t = winding.triangle(f);
                (0..3).map(move |k| {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    (a.min(b), a.max(b), f as u32, if a < b { 1 } else { -1 })
                })
            })
            .collect();
        edges.par_sort_unstable();
        let groups: Vec<&[(u32, u32, u32, i8)]> =
            edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)).collect();
        if groups
            .iter()
            .any(|g| g.iter().map(|e| i32::from(e.3)).sum::<i32>() != 0)
        {
            return None;
        }
        // The manifold edges (used by two counted faces), and each face's neighbour across each
        // of its edges (edge k: corners k, k + 1) where it has one.
        let edge_index = |f: u32, a: u32, b: u32| {
            let t = winding.triangle(f as usize);
            (0..3).find(|&k| {
                let (u, v) = (t[k], t[(k + 1) % 3]);
                (u.min(v), u.max(v)) == (a, b)
            })
        };
        let manifold: Vec<(u32, u32, u32, u32)> = groups
            .iter()
            .filter_map(|g| match **g {
                [(a, b, f, _), (_, _, h, _)] => Some((a, b, f, h)),
                _ => None,
            })
            .collect();
        let mut across = vec![[NO_FACE; 3]; faces];
        for &(a, b, f, h) in &manifold {
            if let (Some(kf), Some(kh)) = (edge_index(f, a, b), edge_index(h, a, b)) {
                across[f as usize][kf] = h;
                across[h as usize][kh] = f;
            }
        }
        // The segment between two faces' prisms across their common edge goes through the
        // junction: the edge's midpoint lifted by d along the mean of the two front normals
        // (computed alike from either face).
        let junction = |f: usize, k: usize| {
            let t = winding.triangle(f);
            let (u, v) = (t[k], t[(k + 1) % 3]);
            let h = across[f][k] as usize;
            let mid = 0.5 * (winding.position(u.min(v)) + winding.position(u.max(v)));
            let n = winding.normal(f.min(h)) + winding.normal(f.max(h));
            mid + 0.5 * BURIED_OFFSET * front * n
        };
        // Each face's prism when no face meets it, for each edge whether the segment from the
        // prism's anchor to the junction meets no face, and the faces near it.
        let fronts: Vec<Option<FaceFront>> = (0..faces)
            .into_par_iter()
            .map(|f| {
                if !winding.counts(f) {
                    return None;
                }
                let normal = front * winding.normal(f);
                let (prism, axes) = Prism::new(winding.corners(f), normal)?;
                let mut halves: [Option<(DVec3, DVec3)>; 3] = [None; 3];
                for (k, half) in halves.iter_mut().enumerate() {
                    if across[f][k] != NO_FACE {
                        *half = Some((prism.anchor, junction(f, k)));
                    }
                }
                let near: Vec<u32> = winding
                    .faces_meeting(near_box(winding, f))
                    .map(|g| g as u32)
                    .collect();
                // The box of the prism and the segments, inside the box the list covers.
                let mut reach = axes.bounds;
                for &(_, junction) in halves.iter().flatten() {
                    reach.take_point(junction);
                }
                if !box_inside(&reach, &near_box(winding, f)) {
                    return None;
                }
                for &g in &near {
                    let t = winding.corners(g as usize);
                    if !boxes_meet(&reach, t) {
                        continue;
                    }
                    let height = span(axes.centroid, axes.axes[0], &t);
                    if prism.meets(&axes, t, height) {
                        return None;
                    }
                    for half in &mut halves {
                        if let Some((a, b)) = *half {
                            // Apart along the prism's height, or else tested in full.
                            if !apart(span(axes.centroid, axes.axes[0], &[a, b]), height)
                                && segment_meets(a, b, t)
                            {
                                *half = None;
                            }
                        }
                    }
                }
                Some(FaceFront {
                    prism,
                    halves: halves.map(|h| h.is_some()),
                    near,
                })
            })
            .collect();
        // Two faces are linked across a manifold edge when both halves of the segment are clear.
        let half_clear = |f: u32, k: Option<usize>| {
            k.and_then(|k| fronts[f as usize].as_ref().map(|front| front.halves[k]))
                .unwrap_or(false)
        };
        let mut sets = Dsu::new(faces);
        for &(a, b, f, h) in &manifold {
            if half_clear(f, edge_index(f, a, b)) && half_clear(h, edge_index(h, a, b)) {
                sets.union(f as usize, h as usize, false);
            }
        }
        let mut id_of_root = vec![NO_REGION; faces];
        let mut region = vec![NO_REGION; faces];
        let mut count = 0;
        for (f, r) in region.iter_mut().enumerate() {
            if fronts[f].is_some() {
                let root = sets.find(f).0;
                if id_of_root[root] == NO_REGION {
                    id_of_root[root] = count as u32;
                    count += 1;
                }
                *r = id_of_root[root];
            }
        }
        let mut near_start = Vec::with_capacity(faces + 1);
        let mut near = Vec::new();
        let mut prisms = Vec::with_capacity(faces);
        for front in fronts {
            near_start.push(near.len());
            prisms.push(front.map(|front| {
                near.extend(front.near);
                front.prism
            }));
        }
        near_start.push(near.len());
        Some(FrontRegions {
            prisms,
            region,
            count,
            front,
            near_start,
            near,
        })
    }

    /// How many regions there are (they are numbered `0..count()`).
    pub(crate) fn count(&self) -> usize {
        self.count
    }

    /// The region of the point `q` (bbox-100 units) given `face`, a face it is near (in front of
    /// it, or of a corner of it): the face's region when q is inside the face's prism, or when
    /// q is within [`NEAR_MARGIN`] of the face's bounding box and the segment from q to a point
    /// inside the prism (its anchor, or the point over the corner nearest q) meets no face of
    /// `winding` (the structure this was built from); `None` otherwise (or when the face has no
    /// region), where q's winding number must be counted on its own.
    pub(crate) fn region_of(&self, winding: &RayWinding, q: DVec3, face: u32) -> Option<u32> {
        let f = face as usize;
        let prism = self.prisms.get(f)?.as_ref()?;
        let region = *self.region.get(f)?;
        if prism.contains(q) {
            return Some(region);
        }
        // The end inside the prism: the anchor, or the point over the face's corner nearest to
        // q (moved towards the centroid by twice the prism's shrinking, lifted by d: inside the
        // tetrahedron of the prism that holds that corner's middle height), whichever is nearer.
        let face_corners = winding.corners(f);
        let centroid = (face_corners[0] + face_corners[1] + face_corners[2]) / 3.0;
        let lift = BURIED_OFFSET * self.front * winding.normal(f);
        let (end, tet) = face_corners
            .iter()
            .enumerate()
            .map(|(k, &x)| (x + 2.0 * PRISM_SHRINK * (centroid - x) + lift, k))
            .chain([(prism.anchor, 1)])
            .min_by(|a, b| q.distance_squared(a.0).total_cmp(&q.distance_squared(b.0)))?;
        let reach = Aabb::new(q.min(end), q.max(end));
        if !box_inside(&reach, &near_box(winding, f))
            || (end != prism.anchor && !prism.contains_from(end, tet))
        {
            return None;
        }
        let near = self
            .near
            .get(*self.near_start.get(f)?..*self.near_start.get(f + 1)?)?;
        near.iter()
            .all(|&g| {
                let t = winding.corners(g as usize);
                !boxes_meet(&reach, t) || !segment_meets(q, end, t)
            })
            .then_some(region)
    }
}

/// The box around face `f` whose faces are listed in [`FrontRegions`]'s `near`: the face's
/// bounding box grown by [`NEAR_MARGIN`]. It holds the face's prism, the junctions over its
/// edges and the segments to them (all within 1.5 d of the face; checked where used).
fn near_box(winding: &RayWinding, f: usize) -> Aabb {
    let [a, b, c] = winding.corners(f);
    let margin = DVec3::splat(NEAR_MARGIN);
    Aabb::new(a.min(b).min(c) - margin, a.max(b).max(c) + margin)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes::{cuboid, union_of, uv_sphere};
    use crate::mesh::TriMesh;

    fn shifted(m: &TriMesh, by: DVec3) -> TriMesh {
        TriMesh::new(
            m.positions.iter().map(|&p| p + by).collect(),
            m.triangles.clone(),
        )
    }

    /// The point d in front of the middle of face `f`.
    fn in_front(m: &TriMesh, f: usize, front: f64) -> DVec3 {
        let [a, b, c] = m.corners(f);
        (a + b + c) / 3.0 + BURIED_OFFSET * front * m.face_normal(f)
    }

    #[test]
    fn a_closed_surface_that_does_not_cross_itself_is_one_region_on_either_side() {
        let m = uv_sphere(10.0, 12, 24);
        let w = RayWinding::new(&m);
        for front in [1.0, -1.0] {
            let r = FrontRegions::new(&w, front).expect("a closed sphere is a 2-cycle");
            assert_eq!(r.count(), 1);
            for f in 0..m.face_count() {
                assert_eq!(r.region_of(&w, in_front(&m, f, front), f as u32), Some(0));
                // Behind the face, or far off it: not in its region.
                assert_eq!(r.region_of(&w, in_front(&m, f, -front), f as u32), None);
                assert_eq!(r.region_of(&w, DVec3::splat(50.0), f as u32), None);
            }
            // A vertex's point in front of it, given one of its faces: joined by a segment.
            let normals = m.vertex_normals();
            for (f, t) in m.triangles.iter().enumerate() {
                for &v in t {
                    let q = m.positions[v as usize] + BURIED_OFFSET * front * normals[v as usize];
                    assert_eq!(r.region_of(&w, q, f as u32), Some(0), "face {f} vertex {v}");
                }
            }
        }
    }

    #[test]
    fn a_surface_that_is_not_a_two_cycle_has_no_regions() {
        // Open: a face missing.
        let mut open = uv_sphere(10.0, 12, 24);
        open.triangles.pop();
        assert!(FrontRegions::new(&RayWinding::new(&open), 1.0).is_none());
        // Closed but one face turned the wrong way.
        let mut turned = uv_sphere(10.0, 12, 24);
        turned.triangles[5].swap(1, 2);
        assert!(FrontRegions::new(&RayWinding::new(&turned), 1.0).is_none());
    }

    #[test]
    fn crossing_spheres_split_into_the_parts_inside_and_outside_the_other() {
        // Two spheres of radius 10 whose centres are 12 apart: each has a cap inside the other.
        let a = uv_sphere(10.0, 24, 48);
        let m = union_of(&a, &shifted(&a, DVec3::new(0.0, 0.0, 12.0)));
        let w = RayWinding::new(&m);
        let r = FrontRegions::new(&w, 1.0).expect("still a 2-cycle");
        let n = a.face_count();
        let region = |f: usize| r.region_of(&w, in_front(&m, f, 1.0), f as u32);
        // a's faces: the north cap (z > 6) is inside the other sphere, the rest outside; b's
        // mirror it. Faces near the circle where they cross (z = 6; a band of faces, 1.3 wide)
        // may have no region.
        let centre_z = |f: usize| {
            let [p, q, s] = m.corners(f);
            (p.z + q.z + s.z) / 3.0 - if f < n { 0.0 } else { 12.0 }
        };
        let (inside_a, outside_a) = (region(0), region(n - 1));
        assert!(centre_z(0) > 9.0 && centre_z(n - 1) < -9.0);
        assert!(inside_a.is_some() && outside_a.is_some() && inside_a != outside_a);
        let mut regions = std::collections::BTreeSet::new();
        for f in 0..m.face_count() {
            let z = centre_z(f);
            // b is a turned upside down: its cap inside a is its south one.
            let z = if f < n { z } else { -z };
            let got = region(f);
            if !(4.5..=7.5).contains(&z) {
                assert!(got.is_some(), "face {f} at {z}");
            }
            regions.insert(got);
            if f < n && z > 7.5 {
                assert_eq!(got, inside_a, "face {f}");
            }
            if f < n && z < 4.5 {
                assert_eq!(got, outside_a, "face {f}");
            }
        }
        // a inside and outside, b inside and outside, and faces at the crossing without one.
        assert_eq!(regions.len(), 5, "{regions:?}");
        assert!(regions.contains(&None));
    }

    #[test]
    fn a_face_met_by_another_or_nearly_touched_has_no_prism() {
        // Two boxes, the second's bottom face 0.3 d above the first's top face: the first's top
        // faces have no prism (the other face passes through it), the rest do.
        let a = cuboid(DVec3::ZERO, DVec3::splat(10.0));
        let lift = 10.0 + 0.3 * BURIED_OFFSET;
        let b = cuboid(DVec3::new(2.0, 2.0, lift), DVec3::new(8.0, 8.0, lift + 5.0));
        let m = union_of(&a, &b);
        let w = RayWinding::new(&m);
        let r = FrontRegions::new(&w, 1.0).expect("two closed boxes");
        for f in 0..m.face_count() {
            let top_of_a = f < 12 && m.corners(f).iter().all(|p| p.z == 10.0);
            let bottom_of_b = f >= 12 && m.corners(f).iter().all(|p| p.z == lift);
            let got = r.region_of(&w, in_front(&m, f, 1.0), f as u32);
            assert_eq!(got.is_none(), top_of_a, "face {f}");
            if bottom_of_b {
                assert!(got.is_some());
            }
        }
    }
}
