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
//!    ([`spectral_remesh::internal::surface_distance`]: RMS and Hausdorff, bbox-100 units);
//! 5. unless [`ReconstructionEvalParams::weighted`] is off, each subset again with the weights of
//!    the points it dropped as RIMLS masses ([`representation_weights`], Sec. 5: a dropped
//!    point's weight moves to the kept points that span its φ), the same rule for every
//!    subsampler ([`MethodResult::weighted`]).
//!
//! Why the weights: the subset's RIMLS is a weighted average over its points, and with unit
//! masses every kept point counts as much as any other whatever it stands for. The linear scan
//! with a finite σ_n keeps more points where normals turn (adaptive sampling, Sec. 7.1), so with
//! unit masses those places weigh more in the subset's average than in the all-points one. On
//! horse at σ_p 0.5 (dense points, one run) a cluster the scan kept on a small fin of the
//! tail (a mesh artifact with wildly turning normals) made a blob 1 bbox-100 unit off the
//! all-points surface, 62% of that run's squared distances; with the weights the run's RMS went
//! from 0.0133 to 0.0048 and its Hausdorff from 1.05 to 0.31 (Poisson disk: 0.0097 and 0.99
//! unweighted, 0.0088 and 0.99 weighted).
//!
//! The same kernel (σ_p, σ_n) serves sampling and reconstruction (Sec. 3 and 5: "The same kernel
//! with the same parameters σ_p and σ_n is used for both sampling and reconstruction"); σ_p is in
//! bbox-100 units (Sec. 7: "models are scaled such that their bounding box has a maximum length
//! of 100"); σ_n = 0.75 (Sec. 7.2).
//!
//! The paper's comparison methods (AS, KS: iterative simplification) are not implemented; the
//! baselines are uniform random, voxel-grid clustering and Poisson-disk subsampling (see
//! [`crate::subsample`]).

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::DVec3;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use crate::reconstruct::{
    clip_to_domain, reconstruct_rimls, reconstruct_rimls_with_masses, ReconstructParams,
    Reconstruction,
};
use crate::subsample::{
    linear_scan_subsample, poisson_disk_subsample_to_count, random_subsample,
    representation_weights, voxel_grid_subsample_to_count, RepresentationParams, Subsampler,
};
use spectral_remesh::internal::{
    surface_distance_with, surface_points_with, Kernel, LinearScanParams, MeshSurface, NormalField,
    Normalization, PlyPointWriter, Point, TargetCountParams,
};
use spectral_remesh::{read_mesh, topology, write_mesh, Error, Result, SurfaceDistance, TriMesh};

/// Where the input points come from.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum PointSource {
    /// The mesh's vertices with its (angle-weighted) vertex normals.
    Vertices,
    /// ⌈area / spacing²⌉ points drawn uniformly by area on the mesh (bbox-100 units), each with
    /// the normals of `normals` interpolated at it: a dense, scanner-like point set.
    Surface {
        /// Mean spacing (bbox-100 units, > 0).
        spacing: f64,
        /// The normal field ([`NormalField`]: smooth vertex normals, or corner normals with a
        /// crease angle that keep sharp edges sharp).
        normals: NormalField,
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
    /// The restricted domain of the reconstructions in the table, in units of σ_p
    /// ([`crate::reconstruct::ReconstructParams::domain`]; default 1.5; 0 for none).
    /// The distances without it are reported too ([`MethodResult::distance_no_domain`]).
    pub domain: f64,
    /// Random samples per side of each distance, on top of the vertices (default 200,000).
    pub distance_samples: usize,
    /// Relative tolerance of the baselines' count searches (default 0.005).
    pub count_tolerance: f64,
    /// Whether every subset is also reconstructed with the weights of the points it dropped as
    /// masses ([`representation_weights`], Sec. 5; [`MethodResult::weighted`]), beside the
    /// plain reconstruction with unit masses. Default true.
    pub weighted: bool,
    /// Seed of the point set and the distance sampling; the subsamplers of repeat r use seeds
    /// derived from `seed + r` (default 1).
    pub seed: u64,
    /// Runs of every subsampler with different seeds (visit orders, random choices, voxel-grid
    /// shifts), all against the same all-points surface (default 5): one run's numbers can
    /// hinge on a single spurious sheet of RIMLS.
    pub repeats: usize,
    /// When set, every reconstruction of the first repeat is written there as binary PLY
    /// (bbox-100 units, restricted to the domain): `MODEL-sS-METHOD.ply`, with METHOD `all`
    /// for the surface of all points, and every subset as a PLY point set with normals,
    /// `MODEL-sS-METHOD-points.ply`.
    pub mesh_dir: Option<PathBuf>,
}

impl Default for ReconstructionEvalParams {
    fn default() -> Self {
        ReconstructionEvalParams {
            sigma_p: vec![0.5, 0.75, 1.0],
            sigma_n: 0.75,
            source: PointSource::Vertices,
            methods: Subsampler::ALL.to_vec(),
            cell_per_sigma: crate::reconstruct::DEFAULT_CELL_PER_SIGMA,
            domain: crate::reconstruct::DEFAULT_DOMAIN,
            distance_samples: 200_000,
            count_tolerance: 0.005,
            weighted: true,
            seed: 1,
            repeats: 5,
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
    /// Triangles dropped outside the restricted domain (of the marching cubes' output).
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
    /// The repeat (0-based).
    pub repeat: usize,
    /// Points kept.
    pub points: usize,
    /// The count the baselines aimed at (the linear scan's count; for the scan itself, its own).
    pub target: usize,
    /// Whether the count is within the tolerance of the target.
    pub reached: bool,
    /// The method's size parameter: σ_p for ours, the voxel side, the Poisson radius (bbox-100
    /// units); `None` for random.
    pub parameter: Option<f64>,
    /// Distance from this reconstruction (side A) to the all-points one (side B), both
    /// restricted to the domain; `None` when either is empty.
    pub distance: Option<SurfaceDistance>,
    /// The same without the restricted domain (every zero crossing where RIMLS is defined).
    pub distance_no_domain: Option<SurfaceDistance>,
    /// The reconstruction (restricted to the domain).
    pub mesh: MeshStats,
    /// Seconds to subsample.
    pub subsample_seconds: f64,
    /// Seconds to reconstruct.
    pub reconstruct_seconds: f64,
    /// Seconds for the two distances.
    pub distance_seconds: f64,
    /// The same subset reconstructed with its representation weights as masses (when
    /// [`ReconstructionEvalParams::weighted`]).
    pub weighted: Option<WeightedResult>,
}

/// A subset reconstructed with the weights of the points it dropped ([`representation_weights`]:
/// Sec. 5 of the paper) as RIMLS masses.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WeightedResult {
    /// Distance to the all-points reconstruction, both restricted to the domain.
    pub distance: Option<SurfaceDistance>,
    /// The same without the restricted domain.
    pub distance_no_domain: Option<SurfaceDistance>,
    /// The reconstruction (restricted to the domain).
    pub mesh: MeshStats,
    /// Kept points whose weight came out negative and was set to 0.
    pub weights_clamped: usize,
    /// Input points with no kept point within the kernel's support (their weight went to the
    /// nearest kept point).
    pub weights_unsupported: usize,
    /// The smallest and largest weight, in input points.
    pub weight_range: (f64, f64),
    /// Seconds to compute the weights.
    pub weights_seconds: f64,
    /// Seconds to reconstruct.
    pub reconstruct_seconds: f64,
    /// Seconds for the two distances.
    pub distance_seconds: f64,
}

/// Everything at one σ_p.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SigmaResult {
    /// σ_p, bbox-100 units.
    pub sigma_p: f64,
    /// Marching-cubes cell, bbox-100 units.
    pub cell: f64,
    /// The reconstruction from all points (restricted to the domain).
    pub all_points: MeshStats,
    /// Seconds to reconstruct from all points.
    pub all_points_seconds: f64,
    /// Distance from the all-points reconstruction (A) to the input mesh (B): how well RIMLS
    /// reproduces the model at this σ_p (not part of Table 2).
    pub all_points_to_input: Option<SurfaceDistance>,
    /// The same without the restricted domain.
    pub all_points_to_input_no_domain: Option<SurfaceDistance>,
    /// One entry per repeat and subsampler, by repeat, the linear scan first in each.
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
    /// The restricted domain, in units of σ_p (0: none).
    pub domain: f64,
    /// Per σ_p.
    pub sigmas: Vec<SigmaResult>,
    /// Wall-clock seconds for the model.
    pub seconds: f64,
}

/// The seeds of repeat `repeat`'s subsamplers: linear scan, random, Poisson disk, voxel-grid
/// shift.
fn repeat_seeds(seed: u64, repeat: usize) -> [u64; 4] {
    let base = seed.wrapping_add(1000 * repeat as u64);
    [base, base + 1, base + 2, base + 3]
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
        PointSource::Surface { spacing, normals } => {
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
            if let NormalField::Crease { angle_deg } = normals {
                if !(angle_deg.is_finite() && angle_deg >= 0.0) {
                    return Err(Error::InvalidParameter {
                        name: "--crease-angle",
                        message: format!("must be a number of degrees >= 0, got {angle_deg}"),
                    });
                }
            }
            let points = surface_points_with(mesh, count as usize, seed, normals)?;
            Ok(points.into_iter().map(|p| (p.position, p.normal)).unzip())
        }
    }
}

/// Statistics of a reconstruction (its mesh restricted to the domain, `clipped` triangles
/// dropped), writing the mesh to `file` when given.
fn mesh_stats(
    rec: &Reconstruction,
    mesh: &TriMesh,
    clipped: usize,
    file: Option<PathBuf>,
) -> Result<MeshStats> {
    if let Some(f) = &file {
        write_mesh(f, mesh)?;
    }
    let t = topology(mesh);
    Ok(MeshStats {
        vertices: mesh.positions.len(),
        faces: mesh.triangles.len(),
        boundary_edges: t.boundary_edges,
        components: t.components,
        cells_skipped: rec.cells_skipped,
        clipped_triangles: clipped,
        evaluations: rec.evaluations,
        file,
    })
}

/// A reconstruction and its search structure (`None` for an empty mesh).
struct Surface {
    mesh: TriMesh,
    search: Option<MeshSurface>,
}

impl Surface {
    fn new(mesh: TriMesh) -> Self {
        let search = MeshSurface::new(&mesh).ok();
        Surface { mesh, search }
    }

    /// The Metro-style distance from `self` (A) to `other` (B); `None` when either is empty.
    fn distance(
        &self,
        other: &Surface,
        params: &ReconstructionEvalParams,
    ) -> Option<SurfaceDistance> {
        match (&self.search, &other.search) {
            (Some(a), Some(b)) => Some(surface_distance_with(
                &self.mesh,
                a,
                &other.mesh,
                b,
                params.distance_samples,
                params.seed,
            )),
            _ => None,
        }
    }
}

/// The marching cubes' surface of `positions` and that surface restricted to the domain, with
/// the statistics of the restricted one.
fn reconstruct_both(
    positions: &[DVec3],
    normals: &[DVec3],
    masses: Option<&[f64]>,
    rec_params: &ReconstructParams,
    domain_radius: f64,
    file: Option<PathBuf>,
) -> Result<(Surface, Surface, MeshStats, f64)> {
    let rec = match masses {
        Some(m) => reconstruct_rimls_with_masses(positions, normals, m, rec_params)?,
        None => reconstruct_rimls(positions, normals, rec_params)?,
    };
    let mut clipped = rec.mesh.clone();
    let dropped = if domain_radius > 0.0 {
        clip_to_domain(&mut clipped, positions, domain_radius)
    } else {
        0
    };
    let stats = mesh_stats(&rec, &clipped, dropped, file)?;
    let seconds = rec.seconds;
    let (unclipped, clipped) = rayon::join(|| Surface::new(rec.mesh), || Surface::new(clipped));
    Ok((clipped, unclipped, stats, seconds))
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
    if !(params.domain.is_finite() && params.domain >= 0.0) {
        return Err(Error::InvalidParameter {
            name: "--domain",
            message: format!("must be a finite number >= 0, got {}", params.domain),
        });
    }
    let input_surface = Surface::new(mesh.clone());
    if input_surface.search.is_none() {
        return Err(Error::invalid_mesh(
            path,
            "the mesh has no triangle of non-zero area",
        ));
    }
    let mut sigmas = Vec::new();
    for &sigma_p in &params.sigma_p {
        // Reconstructed without the domain, then restricted to it (both are measured).
        let rec_params = ReconstructParams {
            cell_per_sigma: params.cell_per_sigma,
            domain: 0.0,
            ..ReconstructParams::new(sigma_p, params.sigma_n)
        };
        let domain_radius = params.domain * sigma_p;
        let file = |method: &str| {
            params
                .mesh_dir
                .as_ref()
                .map(|d| d.join(format!("{model}-s{sigma_p}-{method}.ply")))
        };
        let (all, all_no_domain, all_stats, all_seconds) = reconstruct_both(
            &positions,
            &normals,
            None,
            &rec_params,
            domain_radius,
            file("all"),
        )?;
        let all_points_to_input = all.distance(&input_surface, params);
        let all_points_to_input_no_domain = all_no_domain.distance(&input_surface, params);
        progress(&format!(
            "{model} sigma_p {sigma_p}: all {} points -> {} faces in {all_seconds:.1} s; to the input: {}",
            positions.len(),
            all_stats.faces,
            all_points_to_input
                .as_ref()
                .map(|d| format!("RMS {:.4} Hausdorff {:.4}", d.rms, d.hausdorff))
                .unwrap_or_else(|| "empty".into())
        ));
        let kernel = Kernel::new(sigma_p, params.sigma_n)?;
        let mut methods = Vec::new();
        // The linear scan first: it sets the count.
        let mut order = vec![Subsampler::LinearScan];
        order.extend(
            params
                .methods
                .iter()
                .filter(|&&m| m != Subsampler::LinearScan),
        );
        for repeat in 0..params.repeats.max(1) {
            let seeds = repeat_seeds(params.seed, repeat);
            let mut target = 0;
            for &method in &order {
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
                            seeds[0],
                        );
                        target = kept.len();
                        (kept, Some(sigma_p), true)
                    }
                    Subsampler::UniformRandom => (
                        random_subsample(positions.len(), target, seeds[1]),
                        None,
                        true,
                    ),
                    Subsampler::VoxelGrid => {
                        let mut rng = ChaCha8Rng::seed_from_u64(seeds[3]);
                        let offset = DVec3::new(rng.random(), rng.random(), rng.random());
                        let r =
                            voxel_grid_subsample_to_count(&positions, &tolerance, sigma_p, offset);
                        (r.value, Some(r.sigma_p), r.reached)
                    }
                    Subsampler::PoissonDisk => {
                        let r = poisson_disk_subsample_to_count(
                            &positions, &tolerance, sigma_p, seeds[2],
                        );
                        (r.value, Some(r.sigma_p), r.reached)
                    }
                };
                let subsample_seconds = t.elapsed().as_secs_f64();
                let (p, n): (Vec<DVec3>, Vec<DVec3>) =
                    indices.iter().map(|&i| (positions[i], normals[i])).unzip();
                if let (Some(dir), 0) = (&params.mesh_dir, repeat) {
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
                let mesh_file = if repeat == 0 {
                    file(method.name())
                } else {
                    None
                };
                let (rec, rec_no_domain, stats, reconstruct_seconds) =
                    reconstruct_both(&p, &n, None, &rec_params, domain_radius, mesh_file)?;
                let t = Instant::now();
                let distance = rec.distance(&all, params);
                let distance_no_domain = rec_no_domain.distance(&all_no_domain, params);
                let distance_seconds = t.elapsed().as_secs_f64();
                drop((rec, rec_no_domain));
                let show = |d: &Option<SurfaceDistance>| {
                    d.as_ref()
                        .map(|d| format!("RMS {:.4} Hausdorff {:.4}", d.rms, d.hausdorff))
                        .unwrap_or_else(|| "no surface".into())
                };
                progress(&format!(
                "{model} sigma_p {sigma_p} run {repeat} {:>7}: {:>7} points, {} (no domain: {})",
                method.name(),
                indices.len(),
                show(&distance),
                show(&distance_no_domain),
            ));
                let weighted = if params.weighted {
                    let t = Instant::now();
                    let w = representation_weights(
                        &positions,
                        &normals,
                        &indices,
                        &kernel,
                        &RepresentationParams::default(),
                    )?;
                    let weights_seconds = t.elapsed().as_secs_f64();
                    let mesh_file = if repeat == 0 {
                        file(&format!("{}-weighted", method.name()))
                    } else {
                        None
                    };
                    let (rec, rec_no_domain, mesh, reconstruct_seconds) = reconstruct_both(
                        &p,
                        &n,
                        Some(&w.weights),
                        &rec_params,
                        domain_radius,
                        mesh_file,
                    )?;
                    let t = Instant::now();
                    let distance = rec.distance(&all, params);
                    let distance_no_domain = rec_no_domain.distance(&all_no_domain, params);
                    let distance_seconds = t.elapsed().as_secs_f64();
                    progress(&format!(
                        "{model} sigma_p {sigma_p} run {repeat} {:>7}: weighted, {} (no domain: {})",
                        method.name(),
                        show(&distance),
                        show(&distance_no_domain),
                    ));
                    let range = w
                        .weights
                        .iter()
                        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
                            (lo.min(x), hi.max(x))
                        });
                    Some(WeightedResult {
                        distance,
                        distance_no_domain,
                        mesh,
                        weights_clamped: w.clamped,
                        weights_unsupported: w.unsupported,
                        weight_range: range,
                        weights_seconds,
                        reconstruct_seconds,
                        distance_seconds,
                    })
                } else {
                    None
                };
                methods.push(MethodResult {
                    method: method.name(),
                    repeat,
                    points: indices.len(),
                    target,
                    reached,
                    parameter,
                    distance,
                    distance_no_domain,
                    mesh: stats,
                    subsample_seconds,
                    reconstruct_seconds,
                    distance_seconds,
                    weighted,
                });
            }
        }
        sigmas.push(SigmaResult {
            sigma_p,
            cell: rec_params.cell(),
            all_points: all_stats,
            all_points_seconds: all_seconds,
            all_points_to_input,
            all_points_to_input_no_domain,
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
        domain: params.domain,
        sigmas,
        seconds: t0.elapsed().as_secs_f64(),
    })
}
