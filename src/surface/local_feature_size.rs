//! The local feature size of a triangle mesh, estimated with shrinking balls: for each surface
//! point, the largest balls tangent there on either side that hold no other part of the surface.
//! Their centres approximate the medial axis, their radii the distance to it.

use glam::DVec3;
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::mesh::TriMesh;
use crate::spatial::StaticTree;
use crate::surface::candidates::surface_candidates;
use crate::surface::MeshSurface;

/// Parameters of [`local_feature_size`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LfsParams {
    /// Spacing of the area-uniform points the estimate is made at besides the vertices
    /// (bbox-100 units): about area / spacing² points, so that long coarse triangles are covered.
    /// Default 1.0 (about 20 000 points on a 100 × 100 plate, 15 000 on the horse).
    pub spacing: f64,
    /// The largest radius a ball may have (bbox-100 units); 0 means the bounding box's diagonal.
    /// Where no surface limits a side (the outer side of a convex part, an open sheet), that
    /// side's radius is this cap. Default 0.
    pub max_radius: f64,
    /// The smallest angle, seen from the new ball's centre, between the point and the surface
    /// point that shrinks the ball (degrees). A closer point is the tessellation's own facets
    /// near the point rather than another part of the surface: the ball stops shrinking there
    /// and keeps its radius (Ma et al.'s denoising). Default 20.
    pub min_separation_deg: f64,
    /// Most shrinking steps per side; a side still shrinking after them counts as not
    /// converged (its last radius is kept). Default 64.
    pub max_iterations: usize,
    /// Seed of the area-uniform points. Default 1.
    pub seed: u64,
    /// Crease angle of the normals at the area-uniform points (degrees): each gets its face's
    /// corner normals ([`TriMesh::corner_normals`]) interpolated at its barycentric
    /// coordinates, so that on a tessellated curved part its normal is the surface's, not its
    /// facet's (a facet tilted by α lowers the estimate by about 2α / θ, θ the separation
    /// angle), while across an edge sharper than this the faces keep their own. Default 30.
    pub crease_angle_deg: f64,
    /// The separation angle (degrees, seen from a medial ball's centre, between the point and
    /// a contact on another sheet) from which the ball counts toward
    /// [`LocalFeatureSize::thickness`]. Default 120: a plate, a tube, two facing sheets and the
    /// tip of a wedge sharper than 60° give 120° to 180°; a concave crease of dihedral angle
    /// φ gives 180° − φ, a bump on one sheet less.
    pub thin_separation_deg: f64,
    /// Estimate at the mesh's vertices too (default true); when false, only at the
    /// area-uniform points (`vertex_count` is then 0): enough for a field on a dense mesh, at a
    /// cost set by the spacing rather than by the input.
    pub at_vertices: bool,
}

impl Default for LfsParams {
    fn default() -> Self {
        LfsParams {
            spacing: 1.0,
            max_radius: 0.0,
            min_separation_deg: 20.0,
            max_iterations: 64,
            seed: 1,
            crease_angle_deg: 30.0,
            thin_separation_deg: 150.0,
            at_vertices: true,
        }
    }
}

/// Most area-uniform points [`local_feature_size`] draws; a finer spacing is coarsened to it.
pub const MAX_LFS_SAMPLES: usize = 2_000_000;

/// The local feature size at the vertices of a mesh and at area-uniform points on it, and its
/// evaluation anywhere on the surface ([`LocalFeatureSize::at`]). All lengths bbox-100 units.
pub struct LocalFeatureSize {
    /// The points the estimate was made at: the mesh's vertices (same indices) first, then the
    /// area-uniform points.
    pub positions: Vec<DVec3>,
    /// The estimate at each of `positions`: the smaller radius of the two medial balls.
    pub lfs: Vec<f64>,
    /// The thickness at each of `positions`: the smaller radius of the medial balls that reach
    /// across to another sheet (see `Ball::shrink`: the solid's thickness or the gap to a
    /// nearby sheet, a tube's radius, a tip), the cap otherwise (a ball set by a concave crease,
    /// a bump, a polyhedron's corner or the curvature of one sheet). Bounds `lfs` from above.
    pub thickness: Vec<f64>,
    /// Number of mesh vertices (the first entries of `positions` and `lfs`; 0 without
    /// [`LfsParams::at_vertices`]).
    pub vertex_count: usize,
    /// The spacing of the area-uniform points actually used (larger than asked when
    /// [`MAX_LFS_SAMPLES`] capped the count).
    pub spacing: f64,
    /// The radius cap used.
    pub max_radius: f64,
    /// Points whose normal is zero (vertices in no or only degenerate faces): given the cap.
    pub without_normal: usize,
    /// Sides that still shrank after [`LfsParams::max_iterations`] steps.
    pub not_converged: usize,
    tree: StaticTree,
}

impl LocalFeatureSize {
    /// The estimate at the mesh's vertices, `V` entries in vertex order.
    pub fn vertex_lfs(&self) -> &[f64] {
        &self.lfs[..self.vertex_count]
    }

    /// The local feature size at `x` (a point on or near the surface, bbox-100 units): the
    /// estimate at the nearest estimate point q. The local feature size is 1-Lipschitz, so
    /// this is off by at most |x − q| (about [`LocalFeatureSize::spacing`] / 2 on the surface)
    /// beyond the estimate's own error. `f64::INFINITY` when there are no points.
    pub fn at(&self, x: DVec3) -> f64 {
        self.nearest(x).map_or(f64::INFINITY, |j| self.lfs[j])
    }

    /// The kd-tree over `positions`.
    pub fn tree(&self) -> &StaticTree {
        &self.tree
    }

    /// The index (into `positions`) of the estimate point nearest `x`; `None` when there are
    /// none.
    pub fn nearest(&self, x: DVec3) -> Option<usize> {
        let mut near = Vec::with_capacity(1);
        self.tree.nearest_n(x, 1, &mut near);
        near.first().map(|&(j, _)| j as usize)
    }

    /// The 1-Lipschitz lower envelope of the estimate, clamped at `max_radius` (bbox-100 units):
    /// at each point, `min(max_radius, min_q lfs(q) + |p − q|)` over all estimate points `q`.
    /// Exact: a `q` that lowers the value below `max_radius` lies within `min(lfs(p),
    /// max_radius)` of `p`, so only that neighbourhood is searched. The grading of a kernel
    /// width by the local feature size needs this (Lipschitz) form. Same order as `lfs`.
    pub fn smoothed(&self, max_radius: f64) -> Vec<f64> {
        self.lipschitz_envelope(&self.lfs, max_radius)
    }

    /// [`LocalFeatureSize::smoothed`] of any values at the estimate points (`values[i]` at
    /// `positions[i]`, for example [`LocalFeatureSize::thickness`]).
    pub fn lipschitz_envelope(&self, values: &[f64], max_radius: f64) -> Vec<f64> {
        self.envelope_with_slope(values, max_radius, 1.0)
    }

    /// [`LocalFeatureSize::lipschitz_envelope`] with slope `slope` in (0, 1]:
    /// `min(max_radius, min_q values(q) + slope · |p − q|)`.
    pub fn envelope_with_slope(&self, values: &[f64], max_radius: f64, slope: f64) -> Vec<f64> {
        (0..self.positions.len())
            .into_par_iter()
            .map_init(Vec::new, |near, i| {
                let m = values[i].min(max_radius);
                if !(m > 0.0) {
                    return m.max(0.0);
                }
                let reach = m / slope;
                self.tree
                    .within_unsorted(self.positions[i], reach * reach, near);
                near.iter()
                    .map(|&(j, d2)| values[j as usize] + slope * d2.sqrt())
                    .fold(m, f64::min)
            })
            .collect()
    }
}

/// Estimates the local feature size of `mesh` (bbox-100 units): at each vertex (with its
/// angle-weighted normal, [`TriMesh::vertex_normals`]) and at about area / spacing²
/// area-uniform points (with their face's normal), the radii of the largest balls tangent to
/// the surface there on the inner and the outer side that contain no surface point; the
/// estimate is the smaller radius, the distance from the point to its nearest medial-axis
/// point found.
///
/// Each ball starts at the cap (`max_radius`) and shrinks: the closest point q of the mesh to
/// its centre (the BVH of [`MeshSurface`], so the opposite side of a plate 0.1 thick is found
/// exactly however coarse its triangles) gives the ball through p and q tangent at p,
/// r = |p − q|² / (2 |(p − q)·n|), until no surface point is strictly inside, or until q is
/// within [`LfsParams::min_separation_deg`] of p seen from the centre (the facets of p's own
/// neighbourhood; the ball keeps its radius). On a curved part tessellated at edge length h,
/// the facets' chords make the estimate low by about (h / lfs)² / (3 θ²) (θ the separation
/// angle in radians): under 1% at h = lfs / 20. At a sharp edge or corner the true local
/// feature size is 0; the estimate there is a positive value set by the denoising angle.
///
/// Deterministic (the area-uniform points are seeded); parallel over the points.
///
/// # Errors
/// [`Error::InvalidMesh`] when the mesh has no triangle of non-zero area, an index out of
/// range or a non-finite coordinate; [`Error::InvalidParameter`] for a spacing, cap or angle
/// that is not finite and positive (the cap may be 0, the angle below 180).
///
/// # References
/// - J. Ma, S. W. Bae, S. Choi. *3D medial axis point approximation using nearest neighbors
///   and the normal field*. The Visual Computer 28(1), 2012, 7–19. doi:10.1007/s00371-011-0594-7
///   (the shrinking ball, its radius formula and the denoising by the separation angle).
/// - N. Amenta, M. Bern. *Surface Reconstruction by Voronoi Filtering*. Discrete Comput. Geom.
///   22, 1999, 481–504. doi:10.1007/PL00009475 (the local feature size: the distance from a
///   surface point to the medial axis; it is 1-Lipschitz).
pub fn local_feature_size(mesh: &TriMesh, params: &LfsParams) -> Result<LocalFeatureSize> {
    let bad = |name: &'static str, message: String| Error::InvalidParameter { name, message };
    if !(params.spacing.is_finite() && params.spacing > 0.0) {
        return Err(bad(
            "spacing",
            format!("must be finite and > 0, got {}", params.spacing),
        ));
    }
    if !(params.max_radius.is_finite() && params.max_radius >= 0.0) {
        return Err(bad(
            "max_radius",
            format!("must be finite and >= 0, got {}", params.max_radius),
        ));
    }
    if !(params.min_separation_deg >= 0.0 && params.min_separation_deg < 180.0) {
        return Err(bad(
            "min_separation_deg",
            format!("must be in [0, 180), got {}", params.min_separation_deg),
        ));
    }
    let surface = MeshSurface::new(mesh)?;
    let max_radius = if params.max_radius > 0.0 {
        params.max_radius
    } else {
        mesh.bbox().map_or(0.0, |b| b.diagonal())
    };
    let area = mesh.area();
    let mut spacing = params.spacing;
    let mut count = (area / (spacing * spacing)).ceil();
    if count > MAX_LFS_SAMPLES as f64 {
        spacing = (area / MAX_LFS_SAMPLES as f64).sqrt();
        count = MAX_LFS_SAMPLES as f64;
    }
    let samples = surface_candidates(mesh, count as usize, params.seed);
    let (mut positions, mut normals) = if params.at_vertices {
        (mesh.positions.clone(), mesh.vertex_normals())
    } else {
        (Vec::new(), Vec::new())
    };
    let vertex_count = positions.len();
    positions.extend(samples.iter().map(|s| s.position));
    let corner_normals = mesh.corner_normals(params.crease_angle_deg);
    normals.extend(samples.iter().map(|s| {
        let w = barycentric(mesh.corners(s.face as usize), s.position);
        let c = corner_normals[s.face as usize];
        let n = (w[0] * c[0] + w[1] * c[1] + w[2] * c[2]).normalize_or_zero();
        if n == DVec3::ZERO {
            s.normal
        } else {
            n
        }
    }));

    let tree = StaticTree::new(&positions);
    let ball = Ball {
        surface: &surface,
        positions: &positions,
        max_radius,
        chord_per_radius: 2.0 * (0.5 * params.min_separation_deg.to_radians()).sin(),
        max_iterations: params.max_iterations,
        cos_thin: params.thin_separation_deg.to_radians().cos(),
    };
    let per_point: Vec<(f64, usize, f64)> = positions
        .par_iter()
        .zip(normals.par_iter())
        .map(|(&p, &n)| {
            if !(n.length_squared() > 0.5) || !p.is_finite() {
                return (max_radius, 0, max_radius);
            }
            let (inner, a, inner_thin) = ball.shrink(p, n, -1.0, &tree);
            let (outer, b, outer_thin) = ball.shrink(p, n, 1.0, &tree);
            let thin = |r: f64, thin: bool| if thin { r } else { max_radius };
            (
                inner.min(outer),
                usize::from(!a) + usize::from(!b),
                thin(inner, inner_thin).min(thin(outer, outer_thin)),
            )
        })
        .collect();
    let without_normal = normals
        .iter()
        .zip(&positions)
        .filter(|(n, p)| !(n.length_squared() > 0.5) || !p.is_finite())
        .count();
    let not_converged = per_point.iter().map(|x| x.1).sum();
    let thickness = per_point.iter().map(|x| x.2).collect();
    let lfs = per_point.into_iter().map(|x| x.0).collect();
    Ok(LocalFeatureSize {
        tree,
        positions,
        lfs,
        thickness,
        vertex_count,
        spacing,
        max_radius,
        without_normal,
        not_converged,
    })
}

/// Barycentric coordinates of `p` (in the triangle's plane) in triangle `[a, b, c]`; the
/// centroid's for a degenerate triangle.
fn barycentric([a, b, c]: [DVec3; 3], p: DVec3) -> [f64; 3] {
    let (e1, e2, d) = (b - a, c - a, p - a);
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (d1, d2) = (d.dot(e1), d.dot(e2));
    let det = d11 * d22 - d12 * d12;
    if !(det > 0.0) {
        return [1.0 / 3.0; 3];
    }
    let v = (d22 * d1 - d12 * d2) / det;
    let w = (d11 * d2 - d12 * d1) / det;
    [1.0 - v - w, v, w]
}

/// How far from a medial ball's centre, in ball radii, the other sheet may be for the ball to
/// count toward the thickness (see `Ball::shrink`): a faceted tube stops the ball short of its
/// inscribed radius (the adjacent facet of a 16-gon, seen along an interpolated normal, stops
/// it at 0.57 of the radius on the generated 2.9° cone), and its far side is then up to about
/// 2.5 ball radii from the centre.
const ACROSS_REACH: f64 = 3.0;

/// The shrinking ball's fixed inputs.
struct Ball<'a> {
    surface: &'a MeshSurface,
    positions: &'a [DVec3],
    max_radius: f64,
    /// Chord |p − q| per radius below which q is too close to p (2 sin(θ/2)).
    chord_per_radius: f64,
    max_iterations: usize,
    /// cos of [`LfsParams::thin_separation_deg`]: see [`Ball::shrink`].
    cos_thin: f64,
}

impl Ball<'_> {
    /// The radius of the medial ball tangent at `p` (unit normal `n`) on side `side` (−1: the
    /// centre at p − r n, +1: at p + r n), and whether it converged. A first pass shrinks the
    /// ball against the estimate points only (`points`, a kd-tree): they are part of the
    /// surface, so a ball empty of the surface is empty of them, and that pass never stops
    /// below the largest surface-empty ball (nested tangent balls); the second pass, against the
    /// mesh itself, starts from its radius instead of the cap, which spares the BVH most far
    /// queries.
    ///
    /// Also returns whether the ball reaches across to another sheet: whether the surface point
    /// q nearest to the point of the ball diametrically opposite p lies within
    /// [`ACROSS_REACH`] · r of the centre c and at a separation angle of at least θ (the
    /// angle p c q; θ = [`LfsParams::thin_separation_deg`]) from p. A plate, a tube or two
    /// facing sheets give about 180° (whichever of a tube's ring of contacts set the radius,
    /// and although a faceted tube stops the ball short of its inscribed radius); a concave
    /// crease of dihedral angle φ gives 180° − φ / 2 or less (135° at a right angle); a bump
    /// on one sheet, whose ball is small, finds the other sheet far beyond the reach. The
    /// other sheet must also face nearly opposite to p (normals at least θ apart): a plate, a
    /// tube, a sharp cone or two facing sheets are nearly parallel across, while near the
    /// corner of a polyhedron (a tetrahedron's faces are 109.5° apart) the ball's antipode can
    /// land on a third face at a wide angle: a corner is a feature, not a thin part.
    fn shrink(&self, p: DVec3, n: DVec3, side: f64, points: &StaticTree) -> (f64, bool, bool) {
        let mut near = Vec::with_capacity(2);
        let (upper, _, q1) = self.shrink_with(p, n, side, self.max_radius, |c, r| {
            points.nearest_n(c, 1, &mut near);
            let &(j, d2) = near.first()?;
            (d2 < r * r * (1.0 - 1e-9) * (1.0 - 1e-9)).then(|| self.positions[j as usize])
        });
        let (r, converged, q2) = self.shrink_with(p, n, side, upper, |c, r| {
            self.surface
                .closest_point_within(c, r * (1.0 - 1e-9))
                .map(|q| q.position)
        });
        let c = p + side * r * n;
        let thin = (q1.is_some() || q2.is_some())
            && self
                .surface
                .closest_point_within(c + side * r * n, (ACROSS_REACH + 1.0) * r)
                .is_some_and(|q| {
                    let (u, v) = (p - c, q.position - c);
                    v.length() <= ACROSS_REACH * r
                        && u.dot(v) <= self.cos_thin * u.length() * v.length()
                        && self.surface.face_normal(q.face).dot(n) <= self.cos_thin
                });
        (r, converged, thin)
    }

    /// The shrinking loop from radius `start`; `inside(c, r)` gives a point of the surface
    /// strictly inside the ball of centre `c` and radius `r` (the closest), if any.
    fn shrink_with(
        &self,
        p: DVec3,
        n: DVec3,
        side: f64,
        start: f64,
        mut inside: impl FnMut(DVec3, f64) -> Option<DVec3>,
    ) -> (f64, bool, Option<DVec3>) {
        let mut r = start;
        let mut last = None;
        for _ in 0..self.max_iterations {
            let c = p + side * r * n;
            let Some(q) = inside(c, r) else {
                return (r, true, last);
            };
            let d = q - p;
            let denominator = 2.0 * side * d.dot(n);
            if !(denominator > 0.0) {
                return (r, true, last);
            }
            let r_new = d.length_squared() / denominator;
            if !(r_new < r * (1.0 - 1e-9)) {
                return (r, true, last);
            }
            if d.length() < self.chord_per_radius * r_new {
                return (r, true, last);
            }
            r = r_new;
            last = Some(q);
        }
        (r, false, last)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes::{cuboid, grid, uv_sphere};
    use std::f64::consts::TAU;

    /// A closed surface of revolution-like grid: `nu × nv` quads of `position(u, v)` with
    /// u, v in [0, 1), wrapping in both directions (a torus).
    fn torus(big: f64, small: f64, nu: usize, nv: usize) -> TriMesh {
        let mut positions = Vec::new();
        for j in 0..nv {
            for i in 0..nu {
                let (u, v) = (TAU * i as f64 / nu as f64, TAU * j as f64 / nv as f64);
                let rho = big + small * v.cos();
                positions.push(DVec3::new(rho * u.cos(), rho * u.sin(), small * v.sin()));
            }
        }
        let id = |i: usize, j: usize| ((j % nv) * nu + (i % nu)) as u32;
        let mut triangles = Vec::new();
        for j in 0..nv {
            for i in 0..nu {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        TriMesh::new(positions, triangles)
    }

    /// A closed cylinder of radius `r` along z from −len/2 to len/2: `bands` along, `segments`
    /// around, the caps fans around their centres.
    fn cylinder(r: f64, len: f64, bands: usize, segments: usize) -> TriMesh {
        let mut positions = vec![
            DVec3::new(0.0, 0.0, -0.5 * len),
            DVec3::new(0.0, 0.0, 0.5 * len),
        ];
        for k in 0..=bands {
            let z = len * (k as f64 / bands as f64 - 0.5);
            for i in 0..segments {
                let a = TAU * i as f64 / segments as f64;
                positions.push(DVec3::new(r * a.cos(), r * a.sin(), z));
            }
        }
        let id = |k: usize, i: usize| (2 + k * segments + i % segments) as u32;
        let mut triangles = Vec::new();
        for i in 0..segments {
            triangles.push([0, id(0, i + 1), id(0, i)]);
            triangles.push([1, id(bands, i), id(bands, i + 1)]);
        }
        for k in 0..bands {
            for i in 0..segments {
                triangles.push([id(k, i), id(k, i + 1), id(k + 1, i + 1)]);
                triangles.push([id(k, i), id(k + 1, i + 1), id(k + 1, i)]);
            }
        }
        TriMesh::new(positions, triangles)
    }

    /// The estimates at the points `keep` selects: (smallest, largest).
    fn range(l: &LocalFeatureSize, keep: impl Fn(DVec3) -> bool) -> (f64, f64) {
        let v: Vec<f64> = l
            .positions
            .iter()
            .zip(&l.lfs)
            .filter(|(p, _)| keep(**p))
            .map(|(_, &x)| x)
            .collect();
        assert!(v.len() > 10, "too few points selected: {}", v.len());
        v.iter()
            .fold((f64::INFINITY, 0.0), |(lo, hi), &x| (lo.min(x), hi.max(x)))
    }

    fn assert_close(name: &str, (lo, hi): (f64, f64), truth: f64, rel: f64) {
        println!("{name}: lfs in [{lo:.5}, {hi:.5}], true {truth}");
        assert!(
            lo >= truth * (1.0 - rel) && hi <= truth * (1.0 + rel),
            "{name}: [{lo}, {hi}] vs {truth}"
        );
    }

    #[test]
    fn sphere_lfs_is_its_radius() {
        let l = local_feature_size(&uv_sphere(50.0, 64, 128), &LfsParams::default()).unwrap();
        assert_close("sphere r 50", range(&l, |_| true), 50.0, 0.03);
        assert_eq!(l.not_converged, 0);
        assert!((l.at(DVec3::new(0.0, 50.0, 0.0)) - 50.0).abs() < 1.5);
    }

    #[test]
    fn plates_lfs_is_half_the_thickness() {
        for t in [1.0, 0.1] {
            let mesh = cuboid(DVec3::new(-50.0, -50.0, 0.0), DVec3::new(50.0, 50.0, t));
            let l = local_feature_size(&mesh, &LfsParams::default()).unwrap();
            let middle = |p: DVec3| p.x.abs() < 40.0 && p.y.abs() < 40.0;
            assert_close(&format!("plate t {t}"), range(&l, middle), 0.5 * t, 0.02);
            assert!((l.at(DVec3::new(3.0, 4.0, t)) - 0.5 * t).abs() < 0.02 * t);
        }
    }

    #[test]
    fn parallel_sheets_lfs_is_half_the_gap() {
        for g in [2.5, 0.05] {
            let mut mesh = grid(4, |i, j| {
                DVec3::new(25.0 * i as f64 - 50.0, 25.0 * j as f64 - 50.0, 0.0)
            });
            let top = grid(4, |i, j| {
                DVec3::new(25.0 * i as f64 - 50.0, 25.0 * j as f64 - 50.0, g)
            });
            let offset = mesh.vertex_count() as u32;
            mesh.positions.extend(top.positions);
            mesh.triangles
                .extend(top.triangles.iter().map(|t| t.map(|v| v + offset)));
            let l = local_feature_size(&mesh, &LfsParams::default()).unwrap();
            let middle = |p: DVec3| p.x.abs() < 40.0 && p.y.abs() < 40.0;
            assert_close(&format!("sheets gap {g}"), range(&l, middle), 0.5 * g, 0.02);
            let smooth = l.smoothed(10.0);
            assert!(smooth.iter().zip(&l.lfs).all(|(s, r)| *s <= *r + 1e-12));
        }
    }

    #[test]
    fn cylinder_lfs_is_its_radius() {
        let mesh = cylinder(2.0, 100.0, 100, 96);
        let l = local_feature_size(&mesh, &LfsParams::default()).unwrap();
        assert_close("cylinder r 2", range(&l, |p| p.z.abs() < 40.0), 2.0, 0.03);
    }

    #[test]
    fn torus_lfs_is_its_tube_radius() {
        let mesh = torus(30.0, 5.0, 256, 96);
        let l = local_feature_size(&mesh, &LfsParams::default()).unwrap();
        assert_close("torus tube 5", range(&l, |_| true), 5.0, 0.03);
    }

    #[test]
    fn smoothed_is_lipschitz_and_below_the_estimate() {
        // A plate 1 thick beside a sphere: the grading falls by at most the distance.
        let l = local_feature_size(
            &cuboid(DVec3::new(-50.0, -50.0, 0.0), DVec3::new(50.0, 50.0, 1.0)),
            &LfsParams::default(),
        )
        .unwrap();
        let s = l.smoothed(20.0);
        for i in (0..s.len()).step_by(97) {
            assert!(s[i] <= l.lfs[i].min(20.0) + 1e-12);
            for j in (0..s.len()).step_by(89) {
                let d = l.positions[i].distance(l.positions[j]);
                assert!((s[i] - s[j]).abs() <= d + 1e-9);
            }
        }
    }

    #[test]
    fn degenerate_input_does_not_panic() {
        // An unreferenced vertex, a duplicate vertex, a zero-area face.
        let mut mesh = cuboid(DVec3::ZERO, DVec3::splat(10.0));
        mesh.positions.push(DVec3::splat(3.0));
        mesh.positions.push(DVec3::ZERO);
        mesh.triangles.push([0, 0, 1]);
        let l = local_feature_size(&mesh, &LfsParams::default()).unwrap();
        assert_eq!(l.without_normal, 2);
        assert!(l.lfs.iter().all(|x| x.is_finite() && *x >= 0.0));
        assert!(local_feature_size(
            &mesh,
            &LfsParams {
                spacing: 0.0,
                ..LfsParams::default()
            }
        )
        .is_err());
        let params = LfsParams::default();
        let again = local_feature_size(&mesh, &params).unwrap();
        assert_eq!(again.lfs, l.lfs);
    }

    #[test]
    #[ignore = "timing on the shared horse; run with --ignored --nocapture"]
    fn horse_timing() {
        let path = std::path::Path::new("../shared/data/horse.obj");
        if !path.exists() {
            return;
        }
        let (mesh, _) = crate::io::read_mesh(path).unwrap();
        let norm = crate::pipeline::validate_input(&mesh).unwrap();
        let mesh = norm.apply_mesh(&mesh);
        let t = std::time::Instant::now();
        let l = local_feature_size(&mesh, &LfsParams::default()).unwrap();
        let dt = t.elapsed();
        let v = l.vertex_lfs();
        let mut sorted = v.to_vec();
        sorted.sort_by(f64::total_cmp);
        println!(
            "horse: {} vertices + {} points, {:.3} s; vertex lfs min {:.3} median {:.3} max {:.3}; not converged {}",
            l.vertex_count,
            l.positions.len() - l.vertex_count,
            dt.as_secs_f64(),
            sorted[0],
            sorted[sorted.len() / 2],
            sorted[sorted.len() - 1],
            l.not_converged
        );
        for cap in [20.0, 5.0] {
            let t = std::time::Instant::now();
            let _ = local_feature_size(
                &mesh,
                &LfsParams {
                    max_radius: cap,
                    ..LfsParams::default()
                },
            )
            .unwrap();
            println!("horse, cap {cap}: {:.3} s", t.elapsed().as_secs_f64());
        }
    }
}
