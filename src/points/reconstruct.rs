//! Surface reconstruction from an oriented point set: the RIMLS surface of the points
//! ([`super::rimls`]) triangulated by marching cubes ([`crate::surface::marching_cubes`]) on a
//! grid much finer than the kernel, the "densely triangulated implicit function" the paper
//! measures reconstructions on (Sec. 7.2).

use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;

use super::rimls::{Rimls, RimlsParams};
use crate::error::{Error, Result};
use crate::mesh::TriMesh;
use crate::spatial::StaticTree;
use crate::surface::marching_cubes::{marching_cubes, MarchingCubesParams};

/// The grid cell of a reconstruction, in units of σ_p: 0.5 (cell = σ_p/2). The RIMLS surface
/// varies on the scale of σ_p, so cells of σ_p/2 resolve it; halving the cell (σ_p/4) changed
/// the distances between horse reconstructions by a few percent (see `ARCHITECTURE.md`).
pub const DEFAULT_CELL_PER_SIGMA: f64 = 0.5;

/// The restricted domain of reconstructions ([`ReconstructParams::domain_neighbours`]): 16, as
/// in MeshLab's MLS surfaces (each point's ball reaches its 16th nearest neighbour).
pub const DEFAULT_DOMAIN_NEIGHBOURS: usize = 16;

/// Parameters of [`reconstruct_rimls`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReconstructParams {
    /// The RIMLS surface (σ_p, σ_n and its fitting parameters; lengths in the points' units,
    /// bbox-100 units in this crate).
    pub rimls: RimlsParams,
    /// Grid cell in units of σ_p (> 0). Default [`DEFAULT_CELL_PER_SIGMA`].
    pub cell_per_sigma: f64,
    /// Restricted domain: with k > 0, the surface is kept only within `r_i` of some point i,
    /// where r_i is the distance from point i to its k-th nearest neighbour among the points (its
    /// local spacing: about 2.3 spacings for k = 16); 0 keeps everything the marching cubes
    /// find where RIMLS is defined (within the support of a point). Far from the points relative
    /// to their spacing, RIMLS extrapolates, and its zero set there can hold spurious sheets;
    /// the restriction cuts them off (triangles whose centroid lies outside are dropped). Default
    /// [`DEFAULT_DOMAIN_NEIGHBOURS`]. After the restricted domain of the MLS surfaces in MeshLab
    /// (G. Guennebaud's APSS and RIMLS), the union of balls of twice a point's radius, itself
    /// half the distance to its 16th nearest neighbour: the same balls as k = 16 here.
    pub domain_neighbours: usize,
    /// A lattice point of the grid (the points' units). Reconstructions compared with each other
    /// should share it (and the cell), so that their discretizations are the same. Default the
    /// origin.
    pub origin: DVec3,
}

impl ReconstructParams {
    /// The defaults with kernel widths `sigma_p` (the points' units) and `sigma_n`.
    pub fn new(sigma_p: f64, sigma_n: f64) -> Self {
        ReconstructParams {
            rimls: RimlsParams::new(sigma_p, sigma_n),
            domain_neighbours: DEFAULT_DOMAIN_NEIGHBOURS,
            cell_per_sigma: DEFAULT_CELL_PER_SIGMA,
            origin: DVec3::ZERO,
        }
    }

    /// The grid cell: `cell_per_sigma · σ_p`.
    pub fn cell(&self) -> f64 {
        self.cell_per_sigma * self.rimls.sigma_p
    }
}

/// The output of [`reconstruct_rimls`].
#[derive(Debug, Clone)]
pub struct Reconstruction {
    /// The triangulated RIMLS surface, in the points' units, oriented outward (along the
    /// normals).
    pub mesh: TriMesh,
    /// Evaluations of the RIMLS function.
    pub evaluations: usize,
    /// Grid cells the surface crosses but that could not be triangulated because RIMLS is
    /// undefined at a corner (no point within its support): where the reconstruction has holes.
    pub cells_skipped: usize,
    /// Triangles dropped outside the restricted domain.
    pub clipped_triangles: usize,
    /// Whether the marching cubes' cell limit was not hit.
    pub complete: bool,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// Reconstructs the RIMLS surface of `positions` with unit outward `normals` (the same length)
/// and triangulates it by marching cubes on the grid `params.origin + cell · (i, j, k)`, with
/// cell = `params.cell_per_sigma` · σ_p, visiting the cells around the points and following the
/// surface from there; then drops the triangles outside the restricted domain
/// (`params.domain_neighbours`) and the vertices no triangle uses.
///
/// # Errors
/// [`Error::InvalidParameter`] from [`Rimls::new`] (bad parameters, empty or mismatched
/// inputs, non-finite points or normals) or from [`marching_cubes`] (a point too far from the
/// origin for the grid), or when `cell_per_sigma` is not positive and finite.
pub fn reconstruct_rimls(
    positions: &[DVec3],
    normals: &[DVec3],
    params: &ReconstructParams,
) -> Result<Reconstruction> {
    let t = Instant::now();
    if !(params.cell_per_sigma.is_finite() && params.cell_per_sigma > 0.0) {
        return Err(Error::InvalidParameter {
            name: "cell_per_sigma",
            message: format!(
                "must be a positive finite number, got {}",
                params.cell_per_sigma
            ),
        });
    }
    let rimls = Rimls::new(positions.to_vec(), normals.to_vec(), params.rimls)?;
    let grid = MarchingCubesParams {
        cell: params.cell(),
        origin: params.origin,
        ..MarchingCubesParams::default()
    };
    let out = marching_cubes(&rimls, positions, &grid)?;
    let mut mesh = out.mesh;
    let clipped_triangles = if params.domain_neighbours > 0 {
        clip_to_domain(&mut mesh, positions, params.domain_neighbours)
    } else {
        0
    };
    Ok(Reconstruction {
        mesh,
        clipped_triangles,
        evaluations: out.evaluations,
        cells_skipped: out.cells_skipped,
        complete: out.complete,
        seconds: t.elapsed().as_secs_f64(),
    })
}

/// Drops the triangles of `mesh` whose centroid lies outside every ball about a point of
/// `positions` reaching its `k`-th nearest neighbour, and the vertices left unused; returns how
/// many triangles were dropped.
fn clip_to_domain(mesh: &mut TriMesh, positions: &[DVec3], k: usize) -> usize {
    let tree = StaticTree::new(positions);
    // A point is its own nearest neighbour: ask for k + 1.
    let radius_2: Vec<f64> = positions
        .par_iter()
        .map_init(Vec::new, |found, &p| {
            tree.nearest_n(p, k + 1, found);
            found.last().map_or(0.0, |&(_, d2)| d2)
        })
        .collect();
    let reach_2 = radius_2.iter().copied().fold(0.0, f64::max);
    let keep: Vec<bool> = (0..mesh.triangles.len())
        .into_par_iter()
        .map_init(Vec::new, |found, f| {
            let [a, b, c] = mesh.corners(f);
            tree.within_unsorted((a + b + c) / 3.0, reach_2, found);
            found.iter().any(|&(i, d2)| d2 <= radius_2[i as usize])
        })
        .collect();
    let before = mesh.triangles.len();
    let mut k = keep.iter();
    mesh.triangles
        .retain(|_| k.next().copied().unwrap_or(false));
    mesh.remove_unreferenced_vertices();
    before - mesh.triangles.len()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quality::topology;

    #[test]
    fn a_sampled_sphere_comes_back_closed_and_near_its_radius() {
        // 20,000 points on a sphere of radius 20 (a Fibonacci spiral), exact normals.
        let (r, n) = (20.0, 20_000);
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        let normals: Vec<DVec3> = (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let s = (1.0 - z * z).sqrt();
                let a = golden * i as f64;
                DVec3::new(s * a.cos(), s * a.sin(), z)
            })
            .collect();
        let positions: Vec<DVec3> = normals.iter().map(|n| *n * r).collect();
        // Spacing about 0.5; sigma_p 1.
        let params = ReconstructParams::new(1.0, 0.75);
        let rec = reconstruct_rimls(&positions, &normals, &params).unwrap();
        let t = topology(&rec.mesh);
        assert!(t.is_closed_manifold(), "{t:?}");
        assert_eq!((t.components, t.genus), (1, Some(0)));
        assert_eq!(rec.cells_skipped, 0);
        // The planar fit's bias is sigma_p^2 / (2 r) = 0.025 outward; the grid's error is about
        // cell^2 / (8 r) = 0.0016.
        for p in &rec.mesh.positions {
            let d = p.length() - r;
            assert!((-0.01..0.06).contains(&d), "{p}: {d}");
        }
        assert!(reconstruct_rimls(&positions, &normals[1..], &params).is_err());
        let bad = ReconstructParams {
            cell_per_sigma: 0.0,
            ..params
        };
        assert!(reconstruct_rimls(&positions, &normals, &bad).is_err());
    }
}
