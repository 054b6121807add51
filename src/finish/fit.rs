//! Least-squares fit of the output's vertices to the input surface, along their normals.
//!
//! The samples lie on the input, so on a curved part every output face is a chord under the
//! surface: its distance to the input is zero at its corners and largest inside (a sag of
//! κ h² / 8), one-sided everywhere. Moving the vertices off the surface, along their normals, by
//! about the mean of that sag halves the largest distance and cuts the RMS distance by about 2.4
//! (a parabolic sag of height δ has RMS 0.73 δ about zero and 0.30 δ about its mean of 2/3 δ).
//! This is the vertex placement of least-squares approximation (as in quadric-error
//! simplification, Garland and Heckbert 1997), restricted to the normal direction so that the
//! triangles keep their shapes.
//!
//! Each iteration measures, at the six points of a degree-4 quadrature rule on every face, the
//! signed distance to the input along the face's normal, and moves each free vertex along its
//! normal by the mean of those residuals on its faces weighted by the vertex's barycentric
//! coordinate (∫ b r / ∫ b: a Jacobi step of the least-squares problem over the vertex offsets).
//! A vertex never moves more than [`FIT_MAX_SHIFT`] of its shortest edge in all; fixed vertices
//! (boundary and crease samples) do not move, and a flat part, where the residuals are zero,
//! does not either.

use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;

use crate::geometry::self_intersection::{crossing_faces, faces_of_pairs, undo_new_crossings};
use crate::geometry::triangle::AngleBounds;
use crate::mesh::TriMesh;
use crate::surface::{SurfacePoint, SurfaceQuery};

/// The largest total offset of a vertex, as a fraction of its shortest edge (a sag is κ h² / 8,
/// under a twentieth of h where κ h < 0.4; a larger residual is another sheet or a tip, not a
/// chord's sag).
pub const FIT_MAX_SHIFT: f64 = 0.1;

/// The least cosine between an output face's normal and the input's at a point it is measured
/// against (60°): a point on a sheet facing elsewhere (the other side of a thin part, the far
/// side of a crease) is left out.
pub const FIT_MIN_NORMAL_COS: f64 = 0.5;

/// The points measured on each face and their weights: the 6-point quadrature rule of degree 4
/// on a triangle (Dunavant, "High degree efficient symmetrical Gaussian quadrature rules for the
/// triangle", 1985), exact for the integral of a corner's weight times a residual that is a
/// quadratic over the face (a chord's sag).
const POINTS: [([f64; 3], f64); 6] = {
    const A: f64 = 0.445_948_490_915_965;
    const B: f64 = 0.108_103_018_168_070;
    const C: f64 = 0.091_576_213_509_771;
    const D: f64 = 0.816_847_572_980_459;
    const WA: f64 = 0.223_381_589_678_011;
    const WC: f64 = 0.109_951_743_655_322;
    [
        ([B, A, A], WA),
        ([A, B, A], WA),
        ([A, A, B], WA),
        ([D, C, C], WC),
        ([C, D, C], WC),
        ([C, C, D], WC),
    ]
};

/// A face's sums for its three corners: Σ b · residual and Σ b over its points.
type Contribution = [(f64, f64); 3];

/// A face's points' closest points on the surface (`None` where none was found).
type Closest = [Option<SurfacePoint>; 6];

/// What [`fit_to_surface`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct FitStats {
    /// Vertices moved.
    pub moved: usize,
    /// Their mean offset from where they started (units of the mesh: bbox-100 in the pipeline).
    pub mean_offset: f64,
    /// Their largest offset (same units).
    pub max_offset: f64,
}

/// Moves the vertices of `mesh` not `fixed` along their normals so that the faces approximate
/// `surface` in the least-squares sense (see the module), in `iterations` Jacobi steps. With
/// `bounds`, a step's move is undone for the corners of every face it would take out of the
/// angle bounds (or further out). The fit makes no new crossing: the moves that would are undone.
/// `intersecting`: the pairs of faces (indices) that intersect before, when the caller knows
/// them (else they are searched for). Parallel and deterministic. `fixed` has one entry per
/// vertex.
pub fn fit_to_surface<S: SurfaceQuery + ?Sized>(
    mesh: &mut TriMesh,
    surface: &S,
    fixed: &[bool],
    iterations: usize,
    bounds: Option<AngleBounds>,
    intersecting: Option<&[[u32; 2]]>,
) -> FitStats {
    let n = mesh.positions.len();
    let start = mesh.positions.clone();
    // The faces that cross another before the fit: the fit makes no new crossing.
    let crossing_before = match intersecting {
        Some(pairs) => faces_of_pairs(&mesh.triangles, pairs),
        None => crossing_faces(&mesh.positions, &mesh.triangles),
    };
    // Each face's angle score before the fit: what the bounds keep.
    let score_before: Vec<f64> = match &bounds {
        Some(b) => (0..mesh.triangles.len())
            .map(|f| b.score(mesh.corners(f)))
            .collect(),
        None => Vec::new(),
    };
    let normals = mesh.vertex_normals();
    // Each vertex's shortest edge, for the bound on its offset.
    let shortest = mesh.shortest_edges();
    let mut offset = vec![0.0f64; n];
    // Each face's points' closest points of the last iteration: points of the surface, whose
    // distance to a point bounds its distance to the surface (the search prunes by it).
    let mut found: Vec<Closest> = vec![[None; 6]; mesh.triangles.len()];
    for _ in 0..iterations {
        // Per face: for each corner, Σ b · residual and Σ b over the face's points. Its points'
        // answers replace the last iteration's in place (one array of them alive, not two: at
        // 2M faces each is about 0.9 GB).
        let contributions: Vec<Contribution> = found
            .par_iter_mut()
            .enumerate()
            .map(|(f, last)| {
                let t = mesh.triangles[f];
                let p = mesh.corners(f);
                let normal = mesh.face_normal(f);
                let mut out = [(0.0, 0.0); 3];
                if normal == DVec3::ZERO {
                    *last = [None; 6];
                    return out;
                }
                let reach = p[0]
                    .distance(p[1])
                    .max(p[1].distance(p[2]))
                    .max(p[2].distance(p[0]));
                let points = POINTS.map(|(b, _)| b[0] * p[0] + b[1] * p[1] + b[2] * p[2]);
                // The points' closest points within half the face's longest edge; searched
                // from the last iteration's answers (on a mesh, starting at their triangles), or
                // first within the distance to the nearest corner where it started (a point of
                // the surface): the same answers, with most of the search pruned. One search
                // for the six (on a mesh, one walk of its tree).
                let mut hints = [0.0; 6];
                for k in (0..6).filter(|&k| last[k].is_none()) {
                    hints[k] = t
                        .iter()
                        .map(|&v| points[k].distance(start[v as usize]))
                        .fold(f64::INFINITY, f64::min);
                }
                let mut answers = [None; 6];
                surface.closest_points_near(&points, last, &hints, 0.5 * reach, &mut answers);
                *last = answers;
                for (k, (b, weight)) in POINTS.into_iter().enumerate() {
                    let x = points[k];
                    let Some(q) = answers[k] else {
                        continue;
                    };
                    // A point on another sheet (facing away: a thin part's other side) is not
                    // this face's sag.
                    if surface.piece_normal(&q).dot(normal) < FIT_MIN_NORMAL_COS {
                        continue;
                    }
                    let residual = (q.position - x).dot(normal);
                    for c in 0..3 {
                        if !fixed[t[c] as usize] {
                            out[c].0 += weight * b[c] * residual;
                            out[c].1 += weight * b[c];
                        }
                    }
                }
                out
            })
            .collect();
        let mut sum = vec![(0.0f64, 0.0f64); n];
        for (t, c) in mesh.triangles.iter().zip(&contributions) {
            for (&v, &(r, w)) in t.iter().zip(c) {
                sum[v as usize].0 += r;
                sum[v as usize].1 += w;
            }
        }
        let previous = offset.clone();
        for v in 0..n {
            let (r, w) = sum[v];
            if fixed[v] || !(w > 0.0) || normals[v] == DVec3::ZERO {
                continue;
            }
            // The residual is along the faces' normals; the move is along the vertex's. A
            // residual at rounding level (a flat part) moves nothing: the vertex stays exactly on
            // the input, where the later stages' exact tests see it as it was.
            let bound = FIT_MAX_SHIFT * shortest[v];
            if (r / w).abs() <= 1e-9 * shortest[v] {
                continue;
            }
            offset[v] = (offset[v] + r / w).clamp(-bound, bound);
            mesh.positions[v] = start[v] + offset[v] * normals[v];
        }
        if let Some(b) = &bounds {
            keep_angles(
                mesh,
                b,
                &score_before,
                &start,
                &normals,
                &previous,
                &mut offset,
            );
        }
    }
    undo_new_crossings(
        &mut mesh.positions,
        &mesh.triangles,
        &start,
        &crossing_before,
    );
    let moved: Vec<f64> = (0..n)
        .filter(|&v| mesh.positions[v] != start[v])
        .map(|v| mesh.positions[v].distance(start[v]))
        .collect();
    FitStats {
        moved: moved.len(),
        mean_offset: if moved.is_empty() {
            0.0
        } else {
            moved.iter().sum::<f64>() / moved.len() as f64
        },
        max_offset: moved.iter().copied().fold(0.0, f64::max),
    }
}

/// Undoes this step's move (back to the offsets `previous`) at the corners of every face whose
/// angle score fell below the bound and below `score_before`, until none is left (an undone
/// corner can take a neighbouring face out in turn; at most a few rounds, then every move of
/// the step is undone).
fn keep_angles(
    mesh: &mut TriMesh,
    bounds: &AngleBounds,
    score_before: &[f64],
    start: &[DVec3],
    normals: &[DVec3],
    previous: &[f64],
    offset: &mut [f64],
) {
    const ROUNDS: usize = 8;
    let broken = |mesh: &TriMesh| -> Vec<usize> {
        (0..mesh.triangles.len())
            .filter(|&f| {
                let s = bounds.score(mesh.corners(f));
                s < bounds.min_deg && s < score_before[f] - 1e-9
            })
            .collect()
    };
    for round in 0..=ROUNDS {
        let faces = broken(mesh);
        if faces.is_empty() {
            return;
        }
        let undo: Vec<usize> = if round < ROUNDS {
            let mut v: Vec<usize> = faces
                .iter()
                .flat_map(|&f| mesh.triangles[f].map(|u| u as usize))
                .collect();
            v.sort_unstable();
            v.dedup();
            v
        } else {
            (0..offset.len()).collect()
        };
        for v in undo {
            offset[v] = previous[v];
            mesh.positions[v] = start[v] + offset[v] * normals[v];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::MeshSurface;
    use std::f64::consts::PI;

    use crate::mesh::test_meshes::{grid, open_cylinder as cylinder};

    /// The largest and the RMS distance of points spread evenly over the faces of `mesh` that use
    /// no `fixed` vertex from the cylinder of radius `r`.
    fn distances(mesh: &TriMesh, fixed: &[bool], r: f64) -> (f64, f64) {
        let (mut worst, mut sum, mut count) = (0.0f64, 0.0, 0);
        for (f, t) in mesh.triangles.iter().enumerate() {
            if t.iter().any(|&v| fixed[v as usize]) {
                continue;
            }
            let p = mesh.corners(f);
            // The centroids of the face cut into 64 equal triangles (equal areas, so the mean of
            // their squared distances is the RMS over the face).
            let n = 8;
            let mut at = |u: f64, v: f64| {
                let x = p[0] + u * (p[1] - p[0]) + v * (p[2] - p[0]);
                let d = (x.truncate().length() - r).abs();
                worst = worst.max(d);
                sum += d * d;
                count += 1;
            };
            for i in 0..n {
                for j in 0..n - i {
                    let (i, j) = (i as f64, j as f64);
                    at((i + 1.0 / 3.0) / n as f64, (j + 1.0 / 3.0) / n as f64);
                    if i + j <= (n - 2) as f64 {
                        at((i + 2.0 / 3.0) / n as f64, (j + 2.0 / 3.0) / n as f64);
                    }
                }
            }
        }
        (worst, (sum / count as f64).sqrt())
    }

    #[test]
    fn a_coarse_cylinder_fitted_to_a_fine_one_straddles_it() {
        let r = 10.0;
        // The input: 360 facets (within 0.0008 of the true cylinder); the output: 24 of them,
        // its vertices on the input, its faces chords 0.085 under it at most.
        let fine = cylinder(r, 360, 8, 2.0);
        let surface = MeshSurface::new(&fine).unwrap();
        let mut coarse = cylinder(r, 24, 4, 4.0);
        let free = vec![false; coarse.positions.len()];
        let before = coarse.positions.clone();
        let (worst0, rms0) = distances(&coarse, &free, r);
        let stats = fit_to_surface(&mut coarse, &surface, &free, 3, None, None);
        let (worst1, rms1) = distances(&coarse, &free, r);
        // A parabolic sag of δ: largest distance δ → 2/3 δ, RMS 0.73 δ → 0.30 δ.
        assert!(worst1 < 0.75 * worst0, "largest {worst0} -> {worst1}");
        assert!(rms1 < 0.5 * rms0, "RMS {rms0} -> {rms1}");
        // Outward, within the bound.
        let facet = 2.0 * r * (PI / 24.0).sin();
        for (v, p) in coarse.positions.iter().enumerate() {
            let moved = *p - before[v];
            assert!(moved.dot(before[v].truncate().extend(0.0)) > 0.0);
            assert!(moved.length() <= FIT_MAX_SHIFT * facet + 1e-12);
        }
        assert_eq!(stats.moved, coarse.positions.len());
        // A fixed vertex (the bottom ring, a boundary) stays where it is.
        let mut coarse = cylinder(r, 24, 4, 4.0);
        let fixed: Vec<bool> = (0..coarse.positions.len()).map(|v| v < 24).collect();
        let stats = fit_to_surface(&mut coarse, &surface, &fixed, 3, None, None);
        assert_eq!(coarse.positions[..24], before[..24]);
        assert_eq!(stats.moved, coarse.positions.len() - 24);
    }

    #[test]
    fn a_coarse_cylinder_fitted_to_the_rimls_surface_of_points_straddles_it() {
        // The same fit with a point set's surface for the input: 40000 points on the cylinder
        // (beyond the mesh's ends, so its ends are not at the surface's), their normals radial.
        use rand::{RngExt, SeedableRng};
        let r = 10.0;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let (mut points, mut normals) = (Vec::new(), Vec::new());
        for _ in 0..40_000 {
            let a: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            let z: f64 = rng.random_range(-4.0..20.0);
            normals.push(DVec3::new(a.cos(), a.sin(), 0.0));
            points.push(DVec3::new(r * a.cos(), r * a.sin(), z));
        }
        let params = crate::points::rimls::RimlsParams::new(1.0, f64::INFINITY);
        let surface = crate::points::rimls::Rimls::new(points, normals, params).unwrap();
        let mut coarse = cylinder(r, 24, 4, 4.0);
        let free = vec![false; coarse.positions.len()];
        let (worst0, rms0) = distances(&coarse, &free, r);
        let stats = fit_to_surface(&mut coarse, &surface, &free, 3, None, None);
        let (worst1, rms1) = distances(&coarse, &free, r);
        // The chords' sag δ (0.085) against RIMLS's own offset from a cylinder (sigma_p^2 / 4r,
        // 0.025 outward): the fit to the true cylinder (largest 2/3 δ) moved out by that offset.
        let bias = 0.025;
        assert!(
            worst1 < 2.0 / 3.0 * worst0 + bias,
            "largest {worst0} -> {worst1}"
        );
        assert!(rms1 < 0.7 * rms0, "RMS {rms0} -> {rms1}");
        assert_eq!(stats.moved, coarse.positions.len());
    }

    #[test]
    fn a_flat_part_does_not_move() {
        // A plane as both input and output (the output coarser): every residual is zero.
        let plane = |n: usize| {
            grid(n, |i, j| {
                DVec3::new(i as f64 / n as f64, j as f64 / n as f64, 0.0) * 10.0
            })
        };
        let surface = MeshSurface::new(&plane(20)).unwrap();
        let mut out = plane(5);
        let before = out.positions.clone();
        let stats = fit_to_surface(
            &mut out,
            &surface,
            &vec![false; before.len()],
            3,
            None,
            None,
        );
        assert_eq!(out.positions, before);
        assert_eq!(stats.moved, 0);
    }
}
