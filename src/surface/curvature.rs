//! Sample density graded by curvature: the chord of a surface of normal curvature κ over a
//! spacing h lies κ h² / 8 from the surface, so a spacing h(x) = sqrt(8 e / κ(x)) keeps the chord
//! error at e everywhere, and flat parts (κ = 0) keep the global spacing. With a fixed sample
//! count this moves samples from flat parts to curved ones, which lowers the Hausdorff and RMS
//! distance to the input (the chord error is the distance on a curved part; a flat part has
//! none at any spacing).
//!
//! The curvature of an input face is the normal-cycle estimate of Cohen-Steiner and Morvan
//! ("Restricted Delaunay triangulations and normal cycle", SoCG 2003) over the face: the sum over
//! its edges of half the edge's dihedral angle θ times its length, over the face's area,
//! κ ≈ Σ θ_e |e| / (2 A). It is the trace κ1 + κ2 of their curvature tensor: 1 / R on a
//! cylinder of radius R, whatever the facets' shape (the largest curvature, which sets the chord
//! error), 2 / R on a sphere (the spacing there is finer by √2 than the chord error needs).
//! Edges bending by [`CURVATURE_MAX_BEND_DEG`] or more are shape edges, not curvature, and are
//! left out. The widths are taken at points on
//! the surface (the linear scan's candidates, each with the face it lies on) and made Lipschitz,
//! h(x) ≤ h(y) + L |x − y| ([`CURVATURE_GRADATION`]), so the spacing changes gradually from a
//! curved part to the flat parts around it; a position takes the width of its nearest point.

use glam::DVec3;
use rayon::prelude::*;
use rustc_hash::FxHashSet;

use crate::spatial::StaticTree;
use crate::surface::{MeshSurface, SurfaceSample};

/// The bend (degrees) from which an edge is not read as curvature: a fold that sharp (a box's
/// 90°, a hexagonal prism's 60°) is a shape's edge, kept as a crease or not at all, not a
/// curved surface that the sampling could follow more closely. Milder creases (a cylinder
/// tessellated in 22° facets, as on fandisk) are read as curvature: they are the facets of a
/// curved part, and a spacing finer than the facets keeps each one.
pub const CURVATURE_MAX_BEND_DEG: f64 = 60.0;

/// The Lipschitz constant L of the spacing h(x) = w(x) · sigma_p: h(x) ≤ h(y) + L |x − y| (the
/// spacing grows by at most half the distance, so neighbouring triangles differ in size by at most
/// about a half).
pub const CURVATURE_GRADATION: f64 = 0.3;

/// The curvature of every face of a mesh (1 / mesh units).
#[derive(Debug, Clone)]
pub struct Curvature {
    /// Per face: Σ θ_e |e| / (2 A) over its edges that are not shape edges (see the module).
    pub faces: Vec<f64>,
}

impl Curvature {
    /// The curvature of the faces of `surface`'s mesh (1 / mesh units), the edges in `creases`
    /// (`[a, b]` with `a < b`; the pipeline passes none, see [`CURVATURE_MAX_BEND_DEG`]) and the
    /// edges bending by [`CURVATURE_MAX_BEND_DEG`] or more left out. Edges with other than two
    /// faces, or a face of zero area, give no curvature.
    pub fn new(surface: &MeshSurface, creases: &[[u32; 2]]) -> Self {
        let mesh = surface.mesh();
        let creases: FxHashSet<[u32; 2]> = creases.iter().copied().collect();
        // A bend within a hair of the bound counts as reaching it (a regular hexagon's normals
        // are 60° apart up to rounding).
        let cos_max = (CURVATURE_MAX_BEND_DEG - 0.01).to_radians().cos();
        let uses = mesh.edge_uses();
        let faces = (0..mesh.triangles.len())
            .map(|f| {
                let t = mesh.triangles[f];
                let area = 0.5 * mesh.face_cross(f).length();
                if !(area > 0.0) {
                    return 0.0;
                }
                // Half of each smooth edge's bend times its length, over the face's area.
                let mut bend = 0.0;
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    let key = [a.min(b), a.max(b)];
                    if creases.contains(&key) {
                        continue;
                    }
                    let g = match uses.get(&(key[0], key[1])) {
                        Some(&([x, y], 2)) => {
                            if x as usize == f {
                                y
                            } else {
                                x
                            }
                        }
                        _ => continue,
                    };
                    let (n0, n1) = (surface.face_normal(f as u32), surface.face_normal(g));
                    if n0 == DVec3::ZERO || n1 == DVec3::ZERO {
                        continue;
                    }
                    let cos = n0.dot(n1).clamp(-1.0, 1.0);
                    if cos <= cos_max {
                        continue;
                    }
                    let length = mesh.positions[a as usize].distance(mesh.positions[b as usize]);
                    bend += 0.5 * cos.acos() * length;
                }
                bend / area
            })
            .collect();
        Curvature { faces }
    }
}

/// Relative kernel widths graded by curvature for one global sigma_p, taken at points on the
/// surface and looked up by nearest point.
pub struct CurvatureWidths {
    tree: StaticTree,
    widths: Vec<f64>,
}

impl CurvatureWidths {
    /// The widths w = clamp(sqrt(8 e / κ) / sigma_p, `min_width`, 1) at `points` (each on the
    /// face whose curvature it takes), with e = `chord_error` · sigma_p (bbox-100 units), then
    /// the Lipschitz envelope w_i = min_j (w_j + L |p_i − p_j| / sigma_p), L =
    /// [`CURVATURE_GRADATION`]. Parallel and deterministic.
    pub fn new(
        curvature: &Curvature,
        points: &[SurfaceSample],
        sigma_p: f64,
        chord_error: f64,
        min_width: f64,
    ) -> Self {
        let positions: Vec<DVec3> = points.iter().map(|p| p.position).collect();
        let tree = StaticTree::new(&positions);
        let raw: Vec<f64> = points
            .par_iter()
            .map(|p| {
                let k = curvature.faces.get(p.face as usize).copied().unwrap_or(0.0);
                if !(k > 0.0) {
                    return 1.0;
                }
                ((8.0 * chord_error / (k * sigma_p)).sqrt()).clamp(min_width, 1.0)
            })
            .collect();
        // A point's width can only be lowered by a point within (1 − min_width) sigma_p / L.
        let reach = (1.0 - min_width) * sigma_p / CURVATURE_GRADATION;
        let slope = CURVATURE_GRADATION / sigma_p;
        let widths = (0..positions.len())
            .into_par_iter()
            .map_init(Vec::new, |near, i| {
                if raw[i] <= min_width {
                    return raw[i];
                }
                let r = (raw[i] - min_width) / slope;
                tree.within_unsorted(positions[i], (r.min(reach)).powi(2), near);
                near.iter()
                    .map(|&(j, d2)| raw[j as usize] + slope * d2.sqrt())
                    .fold(raw[i], f64::min)
            })
            .collect();
        CurvatureWidths { tree, widths }
    }

    /// The width at the point nearest `x` (1 with no points).
    pub fn width(&self, x: DVec3) -> f64 {
        let mut near = Vec::with_capacity(1);
        self.tree.nearest_n(x, 1, &mut near);
        near.first().map_or(1.0, |&(i, _)| self.widths[i as usize])
    }

    /// Whether some width is below 1.
    pub fn grades(&self) -> bool {
        self.widths.iter().any(|&w| w < 1.0)
    }
}

/// Parameters of the grading by curvature ([`CurvatureWidths`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvatureParams {
    /// The chord error asked for on curved parts, as a fraction of sigma_p (default
    /// [`CAD_CHORD_ERROR`]).
    pub chord_error: f64,
    /// The smallest width relative to sigma_p (default 0.5: at most 4 times the density).
    pub min_width: f64,
}

/// The chord error (fraction of sigma_p) measured for CAD parts: fandisk, bracket and flange at
/// their counts, with `--feature-angle 20` (see `docs/decisions/chord-error-cad.md`).
pub const CAD_CHORD_ERROR: f64 = 0.003;

impl Default for CurvatureParams {
    fn default() -> Self {
        CurvatureParams {
            chord_error: CAD_CHORD_ERROR,
            min_width: 0.5,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes::{grid, open_cylinder};
    use crate::mesh::TriMesh;

    /// A cylinder of radius `r` round the z axis, open, `sides` facets round and `rings` bands
    /// of height `band`, each quad split along a diagonal; then a flat square of side `2 r`
    /// beside it (x from `3 r` to `5 r`, z = 0), as a separate sheet.
    fn cylinder_and_plane(r: f64, sides: usize, rings: usize, band: f64) -> TriMesh {
        let cylinder = open_cylinder(r, sides, rings, band);
        let (mut positions, mut triangles) = (cylinder.positions, cylinder.triangles);
        let plane = grid(8, |i, j| {
            let (u, v) = (i as f64 / 8.0, j as f64 / 8.0);
            DVec3::new(3.0 * r + 2.0 * r * u, 2.0 * r * v, 0.0)
        });
        let base = positions.len() as u32;
        positions.extend(plane.positions);
        triangles.extend(plane.triangles.iter().map(|t| t.map(|v| v + base)));
        TriMesh::new(positions, triangles)
    }

    #[test]
    fn a_cylinder_has_curvature_one_over_its_radius_and_a_plane_none() {
        let (r, sides) = (5.0, 48);
        // Bands as tall as a facet is wide, and four times as tall: the estimate does not
        // depend on the facets' shape.
        let facet = 2.0 * r * (std::f64::consts::PI / sides as f64).sin();
        for band in [facet, 4.0 * facet] {
            let mesh = cylinder_and_plane(r, sides, 6, band);
            let c = Curvature::new(&MeshSurface::new(&mesh).unwrap(), &[]);
            let on_cylinder = 2 * sides * 6;
            // The rows at the open rims lack a neighbour across the rim, which is no bend.
            for f in 0..on_cylinder {
                let k = c.faces[f] * r;
                assert!((k - 1.0).abs() < 0.02, "face {f}: κR = {k} at band {band}");
            }
            assert!(c.faces[on_cylinder..].iter().all(|&k| k == 0.0));
        }
        // A crease listed is not curvature: a cylinder whose every facet edge is listed is flat.
        let mesh = cylinder_and_plane(r, sides, 2, facet);
        let creases: Vec<[u32; 2]> = (0..3 * sides)
            .map(|i| {
                let (a, b) = (i as u32, (i + sides) as u32);
                [a.min(b), a.max(b)]
            })
            .collect();
        let c = Curvature::new(&MeshSurface::new(&mesh).unwrap(), &creases);
        assert!(c.faces.iter().all(|&k| k < 1e-9 || k * r < 0.6));
    }

    #[test]
    fn a_bend_of_a_shape_edge_is_not_curvature() {
        // A hexagonal prism's sides: 60° apart, a shape's edges, not facets of a curved part.
        let mesh = cylinder_and_plane(5.0, 6, 2, 3.0);
        let c = Curvature::new(&MeshSurface::new(&mesh).unwrap(), &[]);
        // (Two triangles of one flat facet bend by rounding only.)
        assert!(c.faces.iter().all(|&k| k < 1e-6), "{:?}", c.faces);
        // A 12-sided one (30°) is a curved part.
        let mesh = cylinder_and_plane(5.0, 12, 2, 3.0);
        let c = Curvature::new(&MeshSurface::new(&mesh).unwrap(), &[]);
        assert!(c.faces[..48].iter().all(|&k| k > 0.01));
    }

    #[test]
    fn widths_follow_the_chord_error_and_change_gradually() {
        let (r, sides) = (5.0, 96);
        let facet = 2.0 * r * (std::f64::consts::PI / sides as f64).sin();
        let mesh = cylinder_and_plane(r, sides, 12, facet);
        let c = Curvature::new(&MeshSurface::new(&mesh).unwrap(), &[]);
        // A point at every face's centroid.
        let points: Vec<SurfaceSample> = (0..mesh.triangles.len())
            .map(|f| {
                let p = mesh.corners(f);
                SurfaceSample {
                    position: (p[0] + p[1] + p[2]) / 3.0,
                    normal: mesh.face_cross(f).normalize(),
                    face: f as u32,
                }
            })
            .collect();
        let (sigma_p, e) = (1.0, 0.01);
        let w = CurvatureWidths::new(&c, &points, sigma_p, e, 0.3);
        // On the cylinder: h = sqrt(8 e sigma_p R) = 0.632 sigma_p, its chord error e sigma_p.
        let expected = (8.0 * e * r / sigma_p).sqrt();
        let on_cylinder = 2 * sides * 12;
        for s in &points[..on_cylinder] {
            assert!((w.width(s.position) - expected).abs() < 0.01);
        }
        // On the plane, far from the cylinder: 1; near it: graded, at most L per sigma_p.
        let far = DVec3::new(5.0 * r, 2.0 * r, 0.0);
        assert_eq!(w.width(far), 1.0);
        for a in &points {
            for b in &points {
                let (wa, wb) = (w.width(a.position), w.width(b.position));
                let d = a.position.distance(b.position) / sigma_p;
                assert!((wa - wb).abs() <= CURVATURE_GRADATION * d + 1e-9);
            }
        }
        // The smallest width holds where the chord error asks for less.
        let tight = CurvatureWidths::new(&c, &points, sigma_p, 0.001, 0.3);
        assert_eq!(tight.width(points[0].position), 0.3);
        assert!(tight.grades() && w.grades());
    }
}
