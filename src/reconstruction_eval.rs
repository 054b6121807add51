//! The reconstruction experiment of Sec. 7.2 (Table 2): how well a subsampled point set
//! reproduces the surface reconstructed from all points, with the same kernel.
//!
//! For a model (a mesh, normalized to the bbox-100 frame of Sec. 7 and oriented outward):
//! 1. the input point set: the mesh's vertices with its vertex normals, or a dense area-uniform
//!    random point set drawn from its surface with interpolated vertex normals
//!    ([`PointSource`]);
//! 2. per σ_p: the RIMLS surface (σ_p, σ_n) of all points, triangulated by marching cubes
//!    ([`reconstruct_rimls`], cell σ_p/2 by default);
//! 3. the subsamplers ([`Subsampler`]): the randomized linear scan with the same kernel (σ_p,
//!    σ_n) first, as the paper runs it ("we run only our simplification algorithm and not the
//!    resampling"); its count is the target of the others;
//! 4. each subset's RIMLS surface with the same σ_p, σ_n on the same grid, compared with the
//!    all-points surface by the Metro-style two-sided distance
//!    ([`crate::quality::surface_distance`]: RMS and Hausdorff, bbox-100 units).
//!
//! The same kernel (σ_p, σ_n) serves sampling and reconstruction (Sec. 3 and 5: "The same kernel
//! with the same parameters σ_p and σ_n is used for both sampling and reconstruction"); σ_p is in
//! bbox-100 units (Sec. 7: "models are scaled such that their bounding box has a maximum length
//! of 100"); σ_n = 0.75 (Sec. 7.2).
//!
//! The paper's comparison methods (AS, KS: iterative simplification) are not implemented; the
//! baselines are uniform random, voxel-grid clustering and Poisson-disk subsampling (see
//! [`crate::points::subsample`]).

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::DVec3;
use serde::Serialize;

use crate::error::{Error, Result};
use crate::io::{read_mesh, write_mesh};
use crate::kernel::Kernel;
use crate::mesh::{Normalization, TriMesh};
use crate::points::generate::surface_points;
use crate::points::reconstruct::{reconstruct_rimls, ReconstructParams, Reconstruction};
use crate::points::subsample::{
    linear_scan_subsample, poisson_disk_subsample_to_count, random_subsample,
    voxel_grid_subsample_to_count, Subsampler,
};
use crate::points::{PlyPointWriter, Point};
use crate::quality::{surface_distance_with, topology, SurfaceDistance};
use crate::sampling::linear_scan::LinearScanParams;
use crate::sampling::target_count::TargetCountParams;
use crate::surface::MeshSurface;

/// Where the input points come from.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum PointSource {
    /// The mesh's vertices with its (angle-weighted) vertex normals.
    Vertices,
    /// ⌈area / spacing²⌉ points drawn uniformly by area on the mesh (bbox-100 units), each with
    /// the vertex normals interpolated at it: a dense, scanner-like point set.
    Surface {
        /// Mean spacing (bbox-100 units, > 0).
        spacing: f64,
    },
}

/// Parameters of [`evaluate_model`].
#[derive(Debug, Clone, PartialEq)]
pub struct ReconstructionEvalParams {
    /// Kernel widths σ_p to test (bbox-100 units). Default the paper's 0.5, 0.75, 1.
    pub sigma_p: Vec<f64>,
    /// σ_n for sampling and reconstruction. Default 0.75 (Sec. 7.2).
    pub sigma_n: f64,
    /// The input points. Default [`PointSource::Vertices`].
    pub source: PointSource,
    /// Subsamplers; must include [`Subsampler::LinearScan`] (its count is the others' target).
    /// Default all four.
    pub methods: Vec<Subsampler>,
    /// Marching-cubes cell in units of σ_p (default 0.5).
    pub cell_per_sigma: f64,
    /// The reconstructions' restricted domain
    /// ([`crate::points::reconstruct::ReconstructParams::domain_neighbours`]; default 16, 0 for
    /// none).
    pub domain_neighbours: usize,
    /// Random samples per side of each distance, on top of the vertices (default 200,000).
    pub distance_samples: usize,
    /// Relative tolerance of the baselines' count searches (default 0.005).
    pub count_tolerance: f64,
    /// Seed of the point set, the visit orders and the distance sampling (default 1).
    pub seed: u64,
    /// When set, every reconstruction is written there as binary PLY (bbox-100 units):
    /// `MODEL-sS-METHOD.ply`, with METHOD `all` for the surface of all points, and every subset
    /// as a PLY point set with normals, `MODEL-sS-METHOD-points.ply`.
    pub mesh_dir: Option<PathBuf>,
}

impl Default for ReconstructionEvalParams {
    fn default() -> Self {
        ReconstructionEvalParams {
            sigma_p: vec![0.5, 0.75, 1.0],
            sigma_n: 0.75,
            source: PointSource::Vertices,
            methods: Subsampler::ALL.to_vec(),
            cell_per_sigma: crate::points::reconstruct::DEFAULT_CELL_PER_SIGMA,
            domain_neighbours: crate::points::reconstruct::DEFAULT_DOMAIN_NEIGHBOURS,
            distance_samples: 200_000,
            count_tolerance: 0.005,
            seed: 1,
            mesh_dir: None,
        }
    }
}

/// A reconstruction's mesh statistics.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeshStats {
    /// Vertices.
    pub vertices: usize,
    /// Triangles.
    pub faces: usize,
    /// Edges in one triangle only (holes where RIMLS is undefined).
    pub boundary_edges: usize,
    /// Connected components.
    pub components: usize,
    /// Grid cells the surface crosses that have an undefined corner.
    pub cells_skipped: usize,
    /// Triangles dropped outside the restricted domain.
    pub clipped_triangles: usize,
    /// Evaluations of the RIMLS function (grid corners).
    pub evaluations: usize,
    /// The file it was written to, if any.
    pub file: Option<PathBuf>,
}

/// One subsampler at one σ_p.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MethodResult {
    /// The subsampler's short name (`ours`, `random`, `voxel`, `poisson`).
    pub method: &'static str,
    /// Points kept.
    pub points: usize,
    /// The count the baselines aimed at (the linear scan's count; for the scan itself, its own).
    pub target: usize,
    /// Whether the count is within the tolerance of the target.
    pub reached: bool,
    /// The method's size parameter: σ_p for ours, the voxel side, the Poisson radius (bbox-100
    /// units); `None` for random.
    pub parameter: Option<f64>,
    /// Distance from this reconstruction (side A) to the all-points one (side B); `None` when
    /// the reconstruction is empty.
    pub distance: Option<SurfaceDistance>,
    /// The reconstruction.
    pub mesh: MeshStats,
    /// Seconds to subsample.
    pub subsample_seconds: f64,
    /// Seconds to reconstruct.
    pub reconstruct_seconds: f64,
}

/// Everything at one σ_p.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SigmaResult {
    /// σ_p, bbox-100 units.
    pub sigma_p: f64,
    /// Marching-cubes cell, bbox-100 units.
    pub cell: f64,
    /// The reconstruction from all points.
    pub all_points: MeshStats,
    /// Seconds to reconstruct from all points.
    pub all_points_seconds: f64,
    /// Distance from the all-points reconstruction (A) to the input mesh (B): how well RIMLS
    /// reproduces the model at this σ_p (not part of Table 2).
    pub all_points_to_input: Option<SurfaceDistance>,
    /// One entry per subsampler, the linear scan first.
    pub methods: Vec<MethodResult>,
}

/// The experiment on one model.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelResult {
    /// The model's file stem.
    pub model: String,
    /// The mesh file.
    pub path: PathBuf,
    /// The input points' source.
    pub source: PointSource,
    /// Input points.
    pub input_points: usize,
    /// Mesh vertices and faces.
    pub mesh_vertices: usize,
    /// Mesh faces.
    pub mesh_faces: usize,
    /// Surface area, bbox-100 units².
    pub area: f64,
    /// Whether the mesh was oriented inward (negative signed volume) and flipped.
    pub flipped: bool,
    /// σ_n.
    pub sigma_n: f64,
    /// Per σ_p.
    pub sigmas: Vec<SigmaResult>,
    /// Wall-clock seconds for the model.
    pub seconds: f64,
}

/// Reads `path`, normalizes it to bbox 100, orients it outward (flipping the faces when its
/// signed volume is negative) and returns it with whether it was flipped.
///
/// # Errors
/// Reading errors; [`Error::InvalidMesh`] for a mesh with a zero-size bounding box.
pub fn read_normalized_outward(path: &Path) -> Result<(TriMesh, bool)> {
    let (mesh, _) = read_mesh(path)?;
    let bbox = mesh
        .bbox()
        .ok_or_else(|| Error::invalid_mesh(path, "the mesh has no vertices"))?;
    let normalization = Normalization::for_bbox(&bbox)
        .ok_or_else(|| Error::invalid_mesh(path, "the bounding box has zero size"))?;
    let mut mesh = normalization.apply_mesh(&mesh);
    let flipped = mesh.signed_volume() < 0.0;
    if flipped {
        mesh.flip_orientation();
    }
    Ok((mesh, flipped))
}

/// The input points of `mesh` (bbox-100 units) as positions and unit normals.
///
/// # Errors
/// [`Error::InvalidParameter`] for a spacing that is not positive and finite or that asks for
/// more than 100 million points; [`Error::InvalidMesh`] when the mesh has no area.
pub fn input_points(
    mesh: &TriMesh,
    source: PointSource,
    seed: u64,
) -> Result<(Vec<DVec3>, Vec<DVec3>)> {
    match source {
        PointSource::Vertices => {
            let normals = mesh.vertex_normals();
            Ok(mesh
                .positions
                .iter()
                .zip(normals)
                .filter(|(_, n)| *n != DVec3::ZERO)
                .map(|(p, n)| (*p, n))
                .unzip())
        }
        PointSource::Surface { spacing } => {
            if !(spacing.is_finite() && spacing > 0.0) {
                return Err(Error::InvalidParameter {
                    name: "--spacing",
                    message: format!("must be a positive number, got {spacing}"),
                });
            }
            let count = (mesh.area() / (spacing * spacing)).ceil();
            if !(count <= 1e8) {
                return Err(Error::InvalidParameter {
                    name: "--spacing",
                    message: format!("{spacing} asks for {count} points, more than 100 million"),
                });
            }
            let points = surface_points(mesh, count as usize, seed)?;
            Ok(points.into_iter().map(|p| (p.position, p.normal)).unzip())
        }
    }
}

/// Statistics of a reconstruction, writing it to `file` when given.
fn mesh_stats(rec: &Reconstruction, file: Option<PathBuf>) -> Result<MeshStats> {
    if let Some(f) = &file {
        write_mesh(f, &rec.mesh)?;
    }
    let t = topology(&rec.mesh);
    Ok(MeshStats {
        vertices: rec.mesh.positions.len(),
        faces: rec.mesh.triangles.len(),
        boundary_edges: t.boundary_edges,
        components: t.components,
        cells_skipped: rec.cells_skipped,
        clipped_triangles: rec.clipped_triangles,
        evaluations: rec.evaluations,
        file,
    })
}

/// Runs the experiment (see the module documentation) on the mesh at `path`. `progress` is
/// called with a line of text as each step finishes.
///
/// # Errors
/// Reading errors; [`Error::InvalidParameter`] for a σ_p or σ_n out of range, an empty method
/// list or one without the linear scan, or a bad point source; [`Error::Write`] when a mesh
/// cannot be written.
pub fn evaluate_model(
    path: &Path,
    params: &ReconstructionEvalParams,
    progress: &dyn Fn(&str),
) -> Result<ModelResult> {
    let t0 = Instant::now();
    if !params.methods.contains(&Subsampler::LinearScan) {
        return Err(Error::InvalidParameter {
            name: "--methods",
            message: "must include ours (the linear scan sets the count)".into(),
        });
    }
    for &s in &params.sigma_p {
        Kernel::new(s, params.sigma_n)?;
    }
    let model = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "model".into());
    let (mesh, flipped) = read_normalized_outward(path)?;
    let (positions, normals) = input_points(&mesh, params.source, params.seed)?;
    progress(&format!(
        "{model}: {} input points ({:?}){}",
        positions.len(),
        params.source,
        if flipped {
            ", faces flipped outward"
        } else {
            ""
        }
    ));
    let input_surface = MeshSurface::new(&mesh).map_err(|e| with_path(e, path))?;
    let mut sigmas = Vec::new();
    for &sigma_p in &params.sigma_p {
        let mut rec_params = ReconstructParams {
            cell_per_sigma: params.cell_per_sigma,
            ..ReconstructParams::new(sigma_p, params.sigma_n)
        };
        rec_params.domain_neighbours = params.domain_neighbours;
        let file = |method: &str| {
            params
                .mesh_dir
                .as_ref()
                .map(|d| d.join(format!("{model}-s{sigma_p}-{method}.ply")))
        };
        let all = reconstruct_rimls(&positions, &normals, &rec_params)?;
        let all_stats = mesh_stats(&all, file("all"))?;
        let all_surface = MeshSurface::new(&all.mesh).ok();
        let all_points_to_input = all_surface.as_ref().map(|s| {
            surface_distance_with(
                &all.mesh,
                s,
                &mesh,
                &input_surface,
                params.distance_samples,
                params.seed,
            )
        });
        progress(&format!(
            "{model} sigma_p {sigma_p}: all {} points -> {} faces in {:.1} s; to the input: {}",
            positions.len(),
            all_stats.faces,
            all.seconds,
            all_points_to_input
                .as_ref()
                .map(|d| format!("RMS {:.4} Hausdorff {:.4}", d.rms, d.hausdorff))
                .unwrap_or_else(|| "empty".into())
        ));
        let kernel = Kernel::new(sigma_p, params.sigma_n)?;
        let mut target = 0;
        let mut methods = Vec::new();
        // The linear scan first: it sets the count.
        let mut order = vec![Subsampler::LinearScan];
        order.extend(
            params
                .methods
                .iter()
                .filter(|&&m| m != Subsampler::LinearScan),
        );
        for method in order {
            let t = Instant::now();
            let tolerance = TargetCountParams {
                tolerance: params.count_tolerance,
                ..TargetCountParams::new(target)
            };
            let (indices, parameter, reached) = match method {
                Subsampler::LinearScan => {
                    let kept = linear_scan_subsample(
                        &positions,
                        &normals,
                        &kernel,
                        &LinearScanParams::default(),
                        params.seed,
                    );
                    target = kept.len();
                    (kept, Some(sigma_p), true)
                }
                Subsampler::UniformRandom => (
                    random_subsample(positions.len(), target, params.seed + 1),
                    None,
                    true,
                ),
                Subsampler::VoxelGrid => {
                    let r = voxel_grid_subsample_to_count(&positions, &tolerance, sigma_p);
                    (r.value, Some(r.sigma_p), r.reached)
                }
                Subsampler::PoissonDisk => {
                    let r = poisson_disk_subsample_to_count(
                        &positions,
                        &tolerance,
                        sigma_p,
                        params.seed + 2,
                    );
                    (r.value, Some(r.sigma_p), r.reached)
                }
            };
            let subsample_seconds = t.elapsed().as_secs_f64();
            let (p, n): (Vec<DVec3>, Vec<DVec3>) =
                indices.iter().map(|&i| (positions[i], normals[i])).unzip();
            if let Some(dir) = &params.mesh_dir {
                let file = dir.join(format!("{model}-s{sigma_p}-{}-points.ply", method.name()));
                let mut w = PlyPointWriter::create(&file, p.len() as u64)?;
                let pts: Vec<Point> = p
                    .iter()
                    .zip(&n)
                    .map(|(&position, &normal)| Point { position, normal })
                    .collect();
                w.write(&pts)?;
                w.finish()?;
            }
            let rec = reconstruct_rimls(&p, &n, &rec_params)?;
            let stats = mesh_stats(&rec, file(method.name()))?;
            let distance = match (&all_surface, MeshSurface::new(&rec.mesh).ok()) {
                (Some(a), Some(r)) => Some(surface_distance_with(
                    &rec.mesh,
                    &r,
                    &all.mesh,
                    a,
                    params.distance_samples,
                    params.seed,
                )),
                _ => None,
            };
            progress(&format!(
                "{model} sigma_p {sigma_p} {:>7}: {:>7} points, {}",
                method.name(),
                indices.len(),
                distance
                    .as_ref()
                    .map(|d| format!("RMS {:.4} Hausdorff {:.4}", d.rms, d.hausdorff))
                    .unwrap_or_else(|| "no surface".into())
            ));
            methods.push(MethodResult {
                method: method.name(),
                points: indices.len(),
                target,
                reached,
                parameter,
                distance,
                mesh: stats,
                subsample_seconds,
                reconstruct_seconds: rec.seconds,
            });
        }
        sigmas.push(SigmaResult {
            sigma_p,
            cell: rec_params.cell(),
            all_points: all_stats,
            all_points_seconds: all.seconds,
            all_points_to_input,
            methods,
        });
    }
    Ok(ModelResult {
        model,
        path: path.to_path_buf(),
        source: params.source,
        input_points: positions.len(),
        mesh_vertices: mesh.positions.len(),
        mesh_faces: mesh.triangles.len(),
        area: mesh.area(),
        flipped,
        sigma_n: params.sigma_n,
        sigmas,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// Fills in the file of an [`Error::InvalidMesh`] raised without one.
fn with_path(e: Error, path: &Path) -> Error {
    match e {
        Error::InvalidMesh { path: p, message } if p.as_os_str().is_empty() => Error::InvalidMesh {
            path: path.to_path_buf(),
            message,
        },
        e => e,
    }
}
