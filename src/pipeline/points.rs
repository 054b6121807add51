//! The remeshing pipeline for a point set (a scan): out-of-core linear scan of the points → outlier
//! filter → RIMLS surface of the points → samples projected onto it → gradient ascent on it →
//! tangent-plane umbrellas → local optimization and fit against it → untangle → outward orientation
//! → model units. The paper's Figure 1 path (Sec. 6.1, 6.2 and 7).
//!
//! The mesh pipeline (the rest of [`crate::pipeline`]) has an input surface to project onto,
//! measure against and take boundaries, creases and local feature size from; here the surface is
//! the RIMLS surface ([`Rimls`](crate::internal::Rimls), Öztireli, Guennebaud, Gross 2009) of a
//! uniformly random subset of the points (the first bucket of the out-of-core scan) and the
//! samples, with the sampling's sigma_p and sigma_n, so memory stays bounded by the output and one
//! bucket, not by the input.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::DVec3;
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::finish::crossing_faces::{remove_crossing_faces, remove_faces_of_pairs, CrossingFaces};
use crate::finish::optimize::{mend_near, MendStats, OptimizeParams, OptimizeStats};
use crate::finish::refine::RefineCrossingsParams;
use crate::finish::stray_shells::{remove_tiny_pieces, StrayShells};
use crate::finish::untangle::{untangle, UntangleParams, UntangleStats};
use crate::kernel::Kernel;
use crate::mesh::{Normalization, OrientStats, TriMesh};
use crate::pipeline::finish::{finish, Finishing, StrayRule};
use crate::pipeline::{Density, RemeshParams};
use crate::points::boundary::{local_spacings, DataEdges};
use crate::points::far_groups::{KeptPoints, SeparateParts};
use crate::points::flatness::median_surface_variation;
use crate::points::normals::NormalOrientation;
use crate::points::out_of_core::{
    rimls_of, NormalRepairs, Opened, OutOfCoreParams, RimlsSupport, ScanOutput, ScannedInput,
};
use crate::points::rimls::Rimls;
use crate::points::rimls::RimlsParams;
use crate::points::source::PointSource;
use crate::points::Point;
use crate::sampling::curves::BoundarySamples;
use crate::sampling::gradient_ascent::{gradient_ascent, GradientAscentResult};
use crate::sampling::linear_scan::LinearScanner;
use crate::sampling::sizing::Uniform;
use crate::sampling::spacing::BOUNDARY_SPACING_PER_SIGMA;
use crate::spatial::StaticTree;
use crate::surface::feature_lines::FeatureLines;
use crate::surface::features::FeatureDetection;
use crate::surface::{Projection, SurfacePoint, SurfaceQuery, SurfaceSample};
pub use crate::timing::Stage;
use crate::timing::StageTimer;
use crate::triangulate::pillows::{open_pillows, FaceSide, Pillows};
use crate::triangulate::unsupported::{
    remove_faces_off_data, remove_unsupported_faces, UnsupportedFaces,
};
use crate::triangulate::{triangulate, AssemblyStats, SampleSet};

mod parts;

use parts::remesh_parts;
pub use parts::LeftOutPart;

/// Points of the RIMLS surface per output sample: random input points (the first bucket's), the
/// samples not among them (a sample is an input point: a near outlier taken as a sample would
/// hold a bubble of surface around itself). More average noise better at a proportional cost
/// per projection.
pub const RIMLS_POINTS_PER_SAMPLE: usize = 4;

/// The RIMLS surface's parameters for a sampling at `sigma_p` and `sigma_n`: the same widths,
/// but where the sampling is by position alone (sigma_n infinite) the surface keeps the normal
/// term at the RIMLS default (0.75): without it the two sides of a part thinner than the
/// support (3 sigma_p), whose normals point apart, average into one sheet between them.
pub fn rimls_params(sigma_p: f64, sigma_n: f64) -> RimlsParams {
    if sigma_n.is_finite() {
        RimlsParams::new(sigma_p, sigma_n)
    } else {
        RimlsParams {
            sigma_p,
            ..RimlsParams::default()
        }
    }
}

/// Gap in the data, in units of sigma_p, beyond which the surface is taken to be absent (an open
/// scan's boundary or hole): a face with its centroid or an edge midpoint farther than this
/// from every point of the RIMLS surface's support is removed (with the hole fill it is part
/// of). The support holds about `RIMLS_POINTS_PER_SAMPLE` points per sigma_p², uniformly
/// random: an empty disc of radius 1.5 sigma_p in it has probability exp(-4π 2.25) ≈ 5e-13
/// where the data goes on. Sparse data widens it: see `OPEN_GAP_SPACINGS`.
pub const OPEN_GAP_SIGMA_P: f64 = 1.5;

/// The open-scan gap in local spacings of the data (the distance from the nearest support point
/// to its 8th nearest, [`local_spacings`]), where that is wider than `OPEN_GAP_SIGMA_P` sigma_p:
/// data sparser than the samples (a scan of 5,000 points meshed at 4,000) has chance gaps wider
/// than 1.5 sigma_p. With ρ points per unit area the spacing s has ρ π s² ≈ 8, so an empty
/// disc of radius 1.25 s already has probability about exp(-8 · 1.25²) ≈ 4e-6; but the faces'
/// corners may lie `DOMAIN_GAP_SPACINGS` off the data and their centroids half an edge from
/// the corners. 5,000 points of spot -> 4,000, seeds 1-5: 3-5 boundary loops at 1.25 s (faces of
/// a closed surface removed), none at 2.0. Data sparse enough for this rule has its holes found
/// as boundaries ([`DataEdges`]).
pub const OPEN_GAP_SPACINGS: f64 = 2.0;

/// Radius, in units of sigma_p, within which data on a face's side is looked for when the face
/// faces against the RIMLS gradient ([`open_pillows`]): a thin part's other sheet (two sheets
/// closer than the RIMLS support, where the gradient follows one of them) has its points within
/// a spacing of the face, about 4 support points per sigma_p²; a fold over one sheet has none.
/// Measured on the closed parts other than the largest (seeds 1-5): face000 -> 20k, pillows
/// 0.002-0.32 sigma_p thick, no face against the gradient with data on its side; the noisy cow
/// -> 10k, parts 0.17-0.8 sigma_p thick, 2-21 such faces in each part.
pub const FOLD_DATA_RADIUS_SIGMA_P: f64 = 1.0;

/// A data point is on a face's side when its normal is within 60° of the face's
/// ([`FOLD_DATA_RADIUS_SIGMA_P`]).
pub const FOLD_SIDE_COS: f64 = 0.5;

/// The projections' reach past the data in local spacings, where that is wider than
/// `DOMAIN_GAP_SIGMA_P` sigma_p: an empty disc of radius 0.6 s has probability
/// exp(-8 · 0.36) ≈ 0.06.
pub const DOMAIN_GAP_SPACINGS: f64 = 0.6;

/// Distance, in units of sigma_p, from the nearest support point beyond which a projection onto
/// the RIMLS surface is refused: the samples and the mesh stay on the data rather than on the
/// surface's extrapolation past an open scan's boundary. An empty disc of this radius among the
/// support points (about 4 per sigma_p²) has probability exp(-4π 0.5625) ≈ 1e-3 where the data
/// goes on: a move refused there is only a move not made.
pub const DOMAIN_GAP_SIGMA_P: f64 = 0.75;

/// The RIMLS surface restricted to where there is data: within a gap of a support point.
struct Domain<'a> {
    rimls: &'a Rimls,
    /// The support points' local spacings ([`local_spacings`]).
    spacings: &'a [f64],
    sigma_p: f64,
    /// Whether the data is sparser than the support asks for (the support is all of it): the
    /// gaps then widen with its local spacing. A random subset of dense data has the support's
    /// density, which the sigma_p rules assume.
    sparse: bool,
}

impl Domain<'_> {
    /// Whether the support point nearest `p` lies within `gap_sigma_p` sigma_p of it, or, for
    /// sparse data, within `gap_spacings` of its own local spacing.
    fn within(&self, p: DVec3, gap_sigma_p: f64, gap_spacings: f64) -> bool {
        self.rimls.nearest(p).is_some_and(|(i, d2)| {
            let mut r = gap_sigma_p * self.sigma_p;
            if self.sparse {
                r = r.max(gap_spacings * self.spacings[i as usize]);
            }
            d2 <= r * r
        })
    }

    /// Whether `p` is within the projections' reach of the data.
    fn covers_one(&self, p: DVec3) -> bool {
        self.within(p, DOMAIN_GAP_SIGMA_P, DOMAIN_GAP_SPACINGS)
    }
}

impl Projection for Domain<'_> {
    fn project(&self, p: DVec3) -> Option<SurfaceSample> {
        let s = Projection::project(self.rimls, p)?;
        self.covers_one(s.position).then_some(s)
    }
}

impl SurfaceQuery for Domain<'_> {
    fn closest_point_within(&self, p: DVec3, max_dist: f64) -> Option<SurfacePoint> {
        let sp = self.rimls.closest_point_within(p, max_dist)?;
        self.covers_one(sp.position).then_some(sp)
    }

    fn smooth_normal(&self, sp: &SurfacePoint) -> DVec3 {
        self.rimls.smooth_normal(sp)
    }
}

/// How near the boundary samples, in boundary spacings, a sample of the scan may stay: closer,
/// or nearer the data's edge than this, it goes (the gradient ascent spreads the others).
pub const BOUNDARY_CLEARANCE: f64 = 0.5;

/// The samples of `moving` clear of the data's boundary: farther than `BOUNDARY_CLEARANCE`
/// spacings from every boundary sample and, within 2.5 spacings of one, at least as far inside
/// the data's edge (`spacing`: the boundary spacing, bbox-100 units). In their order.
fn clear_of_boundary(
    moving: Vec<SurfaceSample>,
    boundary: &BoundarySamples,
    edges: &DataEdges,
    spacing: f64,
) -> Vec<SurfaceSample> {
    if boundary.samples.is_empty() {
        return moving;
    }
    let tree = StaticTree::new(
        &boundary
            .samples
            .iter()
            .map(|s| s.position)
            .collect::<Vec<_>>(),
    );
    let clear = BOUNDARY_CLEARANCE * spacing;
    let keep: Vec<bool> = moving
        .par_iter()
        .map(|s| match tree.nearest(s.position) {
            Some((_, d2)) if d2 <= clear * clear => false,
            Some((_, d2)) if d2 <= (2.5 * spacing).powi(2) => edges
                .edge_at(s.position, s.normal)
                .is_some_and(|v| v.distance >= clear),
            _ => true,
        })
        .collect();
    moving
        .into_iter()
        .zip(keep)
        .filter_map(|(s, k)| k.then_some(s))
        .collect()
}

/// Edge collapses at most where untangling by moves leaves crossing faces
/// ([`UntangleParams::max_collapses`]): each removes one crossing pair or more.
pub const POINT_UNTANGLE_COLLAPSES: usize = 100;

/// Scans of the input at most: the first at the searched sigma_p, then corrections of sigma_p
/// for the count on the surface.
pub const MAX_SCANS: usize = 3;

/// Data whose median surface variation around the samples, over the support within two
/// sigma_p, exceeds this is not near a surface and is refused (`points::flatness::median_surface_variation`).
/// Measured (release build, seed 1): points filling a cube, a ball, a Gaussian blob or a slab a
/// fifth as thick as wide 0.17-0.24 (the support's outlier rules thin a volume towards sheets,
/// below a volume's 1/3); scans and meshes' points 0.001-0.005; the horse's points with
/// Gaussian noise of 0.3% and 1% of the diagonal 0.04 and 0.095 (at 3,000 and 500 vertices),
/// without noise at 150 vertices (legs thinner than the scale) 0.073.
pub const MAX_SURFACE_VARIATION: f64 = 0.15;

/// Parameters of [`remesh_points`].
#[derive(Debug, Clone)]
pub struct PointRemeshParams {
    /// The pipeline's parameters as for a mesh. `density` must be `Points` or `SigmaP`; a point
    /// set has no local feature size or curvature estimate yet (`grading` and `curvature` must
    /// be `None`) and no detected creases (`features` `Angle` is refused); `triangulation` is
    /// always the umbrellas (the restricted Delaunay triangulation needs an input mesh), and
    /// `fit_iterations` is not used (see [`remesh_points`]).
    pub remesh: RemeshParams,
    /// Points per bucket of the out-of-core scan (the fixed buffer; default 2^20).
    pub bucket_points: usize,
    /// Where the bucket files go (default: the system's temporary folder).
    pub temp_dir: Option<PathBuf>,
    /// How normals are oriented for a point set without them (a viewpoint in model units).
    pub orientation: NormalOrientation,
    /// Whether isolated points are dropped
    /// ([`OutlierFilter`](crate::points::outliers::OutlierFilter); default true).
    pub drop_outliers: bool,
}

impl Default for PointRemeshParams {
    fn default() -> Self {
        PointRemeshParams {
            remesh: RemeshParams::default(),
            bucket_points: 1 << 20,
            temp_dir: None,
            orientation: NormalOrientation::SpanningTree,
            drop_outliers: true,
        }
    }
}

/// The result of [`remesh_points`].
#[derive(Debug, Clone)]
pub struct PointRemeshOutput {
    /// The output mesh, model units (the input points' units).
    pub mesh: TriMesh,
    /// The same mesh in bbox-100 units.
    pub mesh_normalized: TriMesh,
    /// Model units ↔ bbox-100 units (the points' bounding box).
    pub normalization: Normalization,
    /// The sigma_p used, bbox-100 units.
    pub sigma_p: f64,
    /// The target count, if one was given.
    pub target: Option<usize>,
    /// Points read, less the coincident and the far ones.
    pub input_points: u64,
    /// Points merged into another at the same position.
    pub duplicate_points: u64,
    /// Points of far groups left out (counted in `outliers_removed` too).
    pub far_points: u64,
    /// The points kept (far groups left out; in a part when there are parts far apart): the
    /// input the output is measured against.
    pub kept: KeptPoints,
    /// When the points form parts far apart, meshed each on its own: each part's output
    /// vertices, the largest part (most points) first; empty otherwise. The stage statistics
    /// (`gradient_ascent` to `output_orientation`) are then the first part's; the counts and
    /// times are summed over the parts.
    pub separate_parts: Vec<usize>,
    /// Of those parts, the ones left out: no surface at their share of the count (a part other
    /// than the largest; the largest's errors are the run's).
    pub left_out_parts: Vec<LeftOutPart>,
    /// Whether the input had normals (else they were estimated).
    pub had_normals: bool,
    /// What was mended of the input's normals among the RIMLS surface's points: missing ones
    /// fitted, random signs oriented again (`points::out_of_core::rimls_of`).
    pub normal_repairs: NormalRepairs,
    /// Isolated points dropped from the samples and the RIMLS support.
    pub outliers_removed: usize,
    /// Samples after the scan and the outlier filter.
    pub samples: usize,
    /// Samples the RIMLS projection did not reach (left out).
    pub unprojected_samples: usize,
    /// Projected samples the second linear scan rejected (they were accepted off the surface).
    pub rescan_rejected: usize,
    /// The median surface variation of the data around the samples at the output's scale
    /// (`points::flatness::median_surface_variation`); `None` when too sparse to tell.
    pub surface_variation: Option<f64>,
    /// Samples placed on the data's boundary curves (fixed; see
    /// `DataEdges`, src/points/boundary.rs).
    pub boundary_samples: usize,
    /// The data's boundary curves (closed loops and open chains).
    pub boundary_curves: usize,
    /// Points of the RIMLS surface.
    pub rimls_points: usize,
    /// The gradient ascent on the RIMLS surface.
    pub gradient_ascent: GradientAscentResult,
    /// The umbrellas' assembly.
    pub assembly: AssemblyStats,
    /// Faces removed for spanning a gap in the data (open scans).
    pub unsupported: UnsupportedFaces,
    /// Faces the finishing made across a gap in the data (its collapses can close a hole the
    /// removal opened), removed again after it.
    pub unsupported_after_finishing: UnsupportedFaces,
    /// Faces folded over the data removed (facing against it with no data on their side: both
    /// sides of a strip of one-sided data, a flap at the data's edge), after the finishing and
    /// the gap rule.
    pub pillows: Pillows,
    /// Faces with a corner farther from every data point than the output's mean edge length
    /// (a vertex the finishing left off the data's edge; on data sparser than the samples, than
    /// `OPEN_GAP_SPACINGS` local spacings where that is wider) removed, after the folds.
    pub off_data: UnsupportedFaces,
    /// Faces that still crossed removed, last (`finish::crossing_faces`).
    pub crossing_faces: CrossingFaces,
    /// The optimization's last pass again around the boundary the removals after the
    /// finishing opened.
    pub mend_after_removals: MendStats,
    /// Pieces no larger than 4 sigma_p across removed, last (all but the largest piece).
    pub tiny_pieces: StrayShells,
    /// The local optimization against the RIMLS surface.
    pub optimize: OptimizeStats,
    /// The separation of crossing faces of the umbrellas (before the optimization).
    pub untangle_umbrellas: UntangleStats,
    /// The separation of crossing faces after the optimization.
    pub untangle: UntangleStats,
    /// The optimization's last pass again around the faces untangle's collapses changed.
    pub mend_after_untangle: MendStats,
    /// The refinement where the output's own crossings were left after untangle.
    pub refine: crate::finish::refine::RefineCrossingsStats,
    /// Samples that ended in no triangle (the optimization's and the untangling's collapses
    /// included).
    pub dropped_samples: usize,
    /// Tiny closed shells left out (see [`remesh_points`]).
    pub stray_shells: StrayShells,
    /// The output's orientation (closed parts turned outward).
    pub output_orientation: OrientStats,
    /// Seconds of the scan: reading and bucketing, the sigma_p search and outlier filter, the
    /// linear scan.
    pub scan_seconds: [f64; 3],
    /// Wall-clock and processor seconds per stage.
    pub stages: Vec<Stage>,
}

/// Remeshes the point set `input`: a file (PLY without faces, or XYZ/CSV text; see
/// [`PointReader`](crate::internal::PointReader)) or points in memory
/// ([`PointSource::memory`]), with or without normals, out of core. `on_stage` is called with each
/// stage name as it starts.
///
/// With a target count, the count of the samples once projected onto the surface decides: when it
/// is off by more than `count_tolerance`, sigma_p is corrected and the buckets scanned again (up to
/// [`MAX_SCANS`] scans); when the output's count is still off by more than 1% (samples lost to the
/// triangulation and its finishing, as on data hardly denser than the output), the whole job runs
/// once more for a goal moved by the miss, and of the two the one with fewer faces still
/// crossing where untangle stopped is kept, of equals the nearer (its stage times include both
/// runs). There is no least-squares fit of the output to the surface (no closer, at
/// twice the run time: `docs/decisions/point-set-no-fit.md`). Closed shells of at most 8 vertices
/// and 4 sigma_p across are left out, the largest part always kept.
///
/// Memory: the output, the first bucket of the input (`params.bucket_points` points), and the RIMLS
/// surface of `RIMLS_POINTS_PER_SAMPLE` points per sample; not the input.
///
/// # Errors
/// [`Error::InvalidParameter`] naming the parameter for a density other than a count or sigma_p
/// or a count outside 4 to [`MAX_POINTS`](crate::pipeline::MAX_POINTS) (`points`), the sizing field (`lfs_factor`), curvature (`chord_error`), a crease angle
/// (`feature_angle`) or a finite sigma_n (`sigma_n`) on points without normals; the errors of
/// reading the points ([`PointReader`](crate::internal::PointReader)), naming the file;
/// [`Error::InvalidMesh`] for an empty set, one with no extent, or one of which nothing could be
/// triangulated.
pub fn remesh_points(
    source: &PointSource,
    params: &PointRemeshParams,
    on_stage: &(dyn Fn(&str) + Sync),
) -> Result<PointRemeshOutput> {
    if let Density::Points(n) = params.remesh.density {
        super::params::check_count(n)?;
    }
    match remesh_points_whole(source, params, on_stage)? {
        Run::Meshed(out) => Ok(*out),
        Run::Parts(parts) => remesh_parts(source, params, parts, on_stage),
    }
}

/// What a run over a point source gave: the output, or the parts far apart the points form
/// (nothing meshed).
enum Run {
    Meshed(Box<PointRemeshOutput>),
    Parts(Arc<SeparateParts>),
}

/// [`remesh_points`] of points that are one scene (parts near enough to share one scale).
fn remesh_points_whole(
    source: &PointSource,
    params: &PointRemeshParams,
    on_stage: &(dyn Fn(&str) + Sync),
) -> Result<Run> {
    let first = match remesh_points_once(source, params, on_stage)? {
        Run::Meshed(out) => *out,
        parts => return Ok(parts),
    };
    let Density::Points(n) = params.remesh.density else {
        return Ok(Run::Meshed(Box::new(first)));
    };
    let miss = |o: &PointRemeshOutput| n as f64 - o.mesh.vertex_count() as f64;
    if miss(&first).abs() <= 0.01 * n as f64 {
        return Ok(Run::Meshed(Box::new(first)));
    }
    let mut again = params.clone();
    again.remesh.density = Density::Points(((n as f64 + miss(&first)).round() as usize).max(4));
    on_stage("scan");
    // (The same points and seed: the same buckets, so one scene again.)
    let Run::Meshed(second) = remesh_points_once(source, &again, on_stage)? else {
        return Err(Error::Internal {
            stage: "remesh_points",
            message: "a second run found parts the first did not".into(),
        });
    };
    let second = *second;
    // A run whose faces still cross where untangle stopped is a worse output than one off
    // the count.
    let worse = |o: &PointRemeshOutput| (o.untangle.pairs_after, miss(o).abs());
    let (mut kept, other) = if worse(&second) < worse(&first) {
        (second, first)
    } else {
        (first, second)
    };
    kept.target = Some(n);
    for stage in other.stages {
        crate::timing::add_stage(&mut kept.stages, stage);
    }
    Ok(Run::Meshed(Box::new(kept)))
}

/// What the scans leave on the RIMLS surface: the last scan, its kernel and surface, and the
/// samples on it.
struct OnSurface {
    scan: ScanOutput,
    kernel: Kernel,
    rimls: Rimls,
    /// The support points' local spacings ([`local_spacings`]).
    spacings: Vec<f64>,
    /// Whether the data is sparser than the support asks for (see [`Domain`]).
    sparse: bool,
    /// The scan's samples as read.
    samples: Vec<Point>,
    /// The samples projected onto the surface, clear of the boundary.
    moving: Vec<SurfaceSample>,
    /// The data's boundary, sampled, and how many curves it has.
    boundary: BoundarySamples,
    boundary_curves: usize,
    /// Samples the projection did not reach.
    unprojected: usize,
    /// Projected samples the second linear scan rejected.
    rescan_rejected: usize,
    /// See [`PointRemeshOutput::surface_variation`].
    surface_variation: Option<f64>,
    /// See [`PointRemeshOutput::normal_repairs`].
    repairs: NormalRepairs,
}

/// One run of [`remesh_points`] for the count (or sigma_p) `params` asks.
fn remesh_points_once(
    source: &PointSource,
    params: &PointRemeshParams,
    on_stage: &(dyn Fn(&str) + Sync),
) -> Result<Run> {
    let input = source.name();
    let rp = &params.remesh;
    let refuse = |name: &'static str, what: &str| Error::InvalidParameter {
        name,
        message: format!(
            "{what} is not available for a point set ({})",
            input.display()
        ),
    };
    let mut edge_length = None;
    let (target, sigma_p) = match rp.density {
        Density::EdgeLength(l) if !(l.is_finite() && l > 0.0) => {
            return Err(Error::InvalidParameter {
                name: "edge_length",
                message: format!("must be a positive number, got {}", crate::error::shown(l)),
            })
        }
        // sigma_p is the length in bbox-100 units, once the points' bounding box is known.
        Density::EdgeLength(l) => {
            edge_length = Some(l);
            (None, 1.0)
        }
        Density::Points(n) => (Some(n), 1.0),
        Density::SigmaP(s) => (None, s),
        Density::InputVertices => {
            return Err(Error::InvalidParameter {
                name: "points",
                message: format!(
                    "{} is a point set: give the output's vertex count with `points` (or \
                     its sigma_p with `sigma_p`)",
                    input.display()
                ),
            })
        }
    };
    if rp.grading.is_some() {
        return Err(refuse("lfs_factor", "grading by local feature size"));
    }
    if rp.curvature.is_some() {
        return Err(refuse("chord_error", "grading by curvature"));
    }
    if matches!(rp.features, FeatureDetection::Angle(_)) {
        return Err(refuse("feature_angle", "sharp-feature detection"));
    }
    // (Opening a text file counts its points: only when sigma_n needs the answer.)
    if rp.sigma_n.is_finite() && !source.open()?.has_normals() {
        return Err(Error::InvalidParameter {
            name: "sigma_n",
            message: format!("{} has no normals; sigma_n needs them", input.display()),
        });
    }
    let mut timer = StageTimer::new();

    on_stage("scan");
    let scan_params = OutOfCoreParams {
        target,
        sigma_p,
        edge_length,
        sigma_n: rp.sigma_n,
        scan: rp.linear_scan,
        bucket_points: params.bucket_points,
        seed: rp.seed,
        temp_dir: params.temp_dir.clone(),
        resample: 0,
        orientation: params.orientation,
    };
    let mut source = match ScannedInput::open(source, &scan_params, params.drop_outliers)? {
        Opened::Input(s) => *s,
        Opened::Parts(parts) => return Ok(Run::Parts(parts)),
    };
    let mut sigma_p = source.sigma_p;
    let mut scans = 0;
    let OnSurface {
        scan,
        kernel,
        rimls,
        spacings,
        sparse,
        samples,
        moving,
        boundary,
        boundary_curves,
        unprojected,
        rescan_rejected,
        surface_variation,
        repairs,
    } = loop {
        scans += 1;
        let mut scan = source.scan(sigma_p, RIMLS_POINTS_PER_SAMPLE)?;
        let kernel = Kernel::new(sigma_p, rp.sigma_n)?;
        let mut samples = std::mem::take(&mut scan.samples);
        timer.lap("scan");

        on_stage("RIMLS surface");
        // Data sparser than the surface's support asks for: the support is all of it, and its
        // gaps are the data's own, not a random subset's.
        let sparse = scan.support.len() < RIMLS_POINTS_PER_SAMPLE * samples.len();
        let (rimls, repairs) = rimls_of(
            rimls_params(sigma_p, rp.sigma_n),
            &mut samples,
            std::mem::take(&mut scan.support),
            RimlsSupport {
                points_per_sample: RIMLS_POINTS_PER_SAMPLE,
                samples_in_support: false,
                // Points on no sheet of the density the open-gap rule bridges carry no
                // surface.
                sheet_radius: Some(2.0 * OPEN_GAP_SIGMA_P * sigma_p),
            },
            scan.had_normals,
            // The points are in the bbox-100 frame, a viewpoint in model units.
            params.orientation.in_frame(&scan.normalization),
        )?;
        let spacings = local_spacings(&rimls);
        // Data that is not near a surface (noise filling a volume) is refused here, before
        // the optimization spends its time on a surface that is not there.
        let positions: Vec<DVec3> = samples.iter().map(|p| p.position).collect();
        let surface_variation = median_surface_variation(&rimls, &positions, 2.0 * sigma_p);
        if let Some(v) = surface_variation.filter(|&v| v > MAX_SURFACE_VARIATION) {
            return Err(Error::invalid_mesh(
                input,
                format!(
                    "the points are not near a surface: around the samples they spread in \
                     every direction at the output's spacing (median surface variation {v:.3}; \
                     a surface's is near 0, a volume's 1/3); noisy data may hold one at a \
                     coarser spacing (a smaller count)"
                ),
            ));
        }
        let domain = Domain {
            rimls: &rimls,
            spacings: &spacings,
            sigma_p,
            sparse,
        };
        // The samples are input points, noisy: they start on the surface.
        let projected = rimls.project_all(&positions);
        drop(positions);
        let mut moving: Vec<SurfaceSample> = projected
            .into_iter()
            .flatten()
            .filter(|&(position, _)| domain.covers_one(position))
            .map(|(position, normal)| SurfaceSample {
                position,
                normal,
                face: 0,
            })
            .collect();
        let unprojected = samples.len() - moving.len();
        // The scan saw the points where they were read: a sample accepted only because noise
        // or a near outlier put it off the surface crowds its neighbours once projected. The
        // projected samples are scanned again, in the order the scan took them.
        let rejected = {
            let batch: Vec<(DVec3, DVec3)> =
                moving.iter().map(|s| (s.position, s.normal)).collect();
            let mut scanner = LinearScanner::new(&kernel, &rp.linear_scan);
            let mut accepted = Vec::new();
            scanner.offer_batch(&batch, &mut accepted);
            let before = moving.len();
            moving = accepted.iter().map(|&i| moving[i]).collect();
            before - moving.len()
        };
        timer.lap("RIMLS surface");
        // Where the data ends: its boundary curves, sampled at the boundary spacing, and the
        // samples clear of them.
        on_stage("boundary");
        let edges = DataEdges::new(&rimls, &spacings, sigma_p);
        let spacing = BOUNDARY_SPACING_PER_SIGMA * sigma_p;
        let (boundary, boundary_curves) = edges.boundary_samples(spacing);
        let moving = clear_of_boundary(moving, &boundary, &edges, spacing);
        timer.lap("boundary");
        // The count the search aimed at was for the points as read; on the surface (noise and
        // outliers gone) it can be lower: sigma_p is corrected (the count goes as
        // sigma_p^-2) and the input scanned again.
        let v = (moving.len() + boundary.samples.len()) as f64;
        match target {
            Some(n)
                if scans < MAX_SCANS
                    && v > 0.0
                    && (v - n as f64).abs() > rp.count_tolerance.max(0.0) * n as f64 =>
            {
                sigma_p *= (v / n as f64).sqrt();
                on_stage("scan");
            }
            _ => {
                break OnSurface {
                    scan,
                    kernel,
                    rimls,
                    spacings,
                    sparse,
                    samples,
                    moving,
                    boundary,
                    boundary_curves,
                    unprojected,
                    rescan_rejected: rejected,
                    surface_variation,
                    repairs,
                }
            }
        }
    };
    let normalization = scan.normalization;
    let domain = Domain {
        rimls: &rimls,
        spacings: &spacings,
        sigma_p,
        sparse,
    };
    // The RIMLS points on their own surface: the points the optimization keeps covered.
    let cover_points: Vec<DVec3> = rimls
        .project_all(rimls.positions())
        .into_iter()
        .flatten()
        .map(|(p, _)| p)
        .collect();
    timer.lap("RIMLS surface");

    on_stage("gradient ascent");
    // The samples in Morton order (they come in the scan's order): a move reads its
    // neighbours' and the RIMLS points near it, and the later loops over vertices walk the
    // surface instead of jumping across it.
    let order = crate::geometry::morton::morton_order(
        &moving.iter().map(|s| s.position).collect::<Vec<_>>(),
    );
    // The boundary samples first: they stay where they are.
    let fixed = boundary.samples.len();
    let mut moving: Vec<SurfaceSample> = boundary
        .samples
        .iter()
        .copied()
        .chain(order.iter().map(|&i| moving[i as usize]))
        .collect();
    let ga = gradient_ascent(
        &kernel,
        &domain,
        &mut moving,
        fixed,
        &Uniform,
        None,
        &rp.gradient_ascent,
        rp.seed,
    );
    timer.lap("gradient ascent");

    on_stage("triangulate");
    let positions: Vec<DVec3> = moving.iter().map(|s| s.position).collect();
    let normals: Vec<DVec3> = moving
        .par_iter()
        .map(|s| {
            rimls
                .value_and_gradient(s.position)
                .and_then(|(_, g)| g.try_normalize())
                .unwrap_or(s.normal)
        })
        .collect();
    let set = SampleSet {
        positions: &positions,
        normals: &normals,
        boundary_edges: &boundary.edges,
    };
    // Where the data has edges, a loop that closes only from behind is a sheet's outline.
    let mut triangulate_params = rp.triangulate;
    triangulate_params.assembly.fill_outlines = boundary_curves == 0;
    let (faces, mut sources, assembly) = triangulate(&set, &triangulate_params);
    if faces.is_empty() {
        return Err(Error::invalid_mesh(
            input,
            "the points gave no triangle (too few, or not on a surface)",
        ));
    }
    let mut mesh = TriMesh::new(positions, faces);
    // Faces the assembly closed across a gap in the data (an open scan's holes) go.
    let supported = |p| domain.within(p, OPEN_GAP_SIGMA_P, OPEN_GAP_SPACINGS);
    let unsupported = remove_unsupported_faces(&mut mesh, &mut sources, supported);

    // The RIMLS surface is a level set: it never passes through itself, so a crossing of the
    // umbrellas is a fold of the triangulation (a tip thinner than sigma_p, where the samples
    // of its two sides see each other), which collapsing its edges removes when moving its
    // vertices does not. Untangled before the optimization (which then shapes the triangles the
    // collapses left) and after it.
    // Faces that would touch once written in model units are separated too.
    let untangle_params = UntangleParams {
        max_collapses: POINT_UNTANGLE_COLLAPSES,
        near: rp.untangle.near.max(normalization.written_rounding()),
        ..rp.untangle
    };
    // The optimization's guards keep faces that far apart too.
    let optimize = rp.optimize.map(|op| OptimizeParams {
        near: op.near.max(untangle_params.near),
        ..op
    });
    let no_fixed = vec![false; mesh.positions.len()];
    let (untangle_umbrellas, _) = untangle(&mut mesh, &no_fixed, sigma_p, &untangle_params, None);
    timer.lap("triangulate");

    // No least-squares fit to the RIMLS surface (`fit_iterations` is not used: see
    // docs/decisions/point-set-no-fit.md). A tiny closed shell (a few samples closing into a
    // tetrahedron where a tip is thinner than the spacing) is no part of the surface: a real
    // part 4 sigma_p across would have tens of samples. The largest part always stays.
    let stray = |shell: &[DVec3]| {
        let (lo, hi) = shell.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        lo.distance(hi) <= 4.0 * sigma_p
    };
    let boundary_lines = FeatureLines::new(
        &boundary
            .samples
            .iter()
            .map(|s| s.position)
            .collect::<Vec<_>>(),
        boundary.edges.iter().copied(),
    );
    let finishing = Finishing {
        surface: &domain,
        cover_points: &cover_points,
        fixed,
        protected: &[],
        untangle_moves_fixed: true,
        boundary: boundary_lines.as_ref(),
        input_crossings: None,
        sigma_p,
        optimize: optimize.as_ref(),
        fit_iterations: 0,
        untangle: untangle_params,
        // Not on a point set's surface: each round's mend projects onto the RIMLS surface (car6.pcd
        // at 3000: 66 s, over 18 minutes with the rounds); the faces that still cross on an open
        // output are removed instead (`finish/crossing_faces.rs`).
        refine: RefineCrossingsParams {
            max_rounds: 0,
            ..rp.refine
        },
        crossing_rule: None,
        stray: Some(StrayRule {
            keep: 1,
            stray: &stray,
        }),
    };
    // The points' normals point outward (given, or oriented so): so does the output.
    let finished = finish(&mut mesh, &mut sources, &finishing, on_stage, &mut timer);
    // The same rule once more: no output face spans a gap in the data. (Removing faces makes no
    // angle smaller and no faces cross.)
    let unsupported_after_finishing = remove_unsupported_faces(&mut mesh, &mut sources, supported);
    // Then the folds (after the gap rule, whose removal of a hole's fill starts from its faces
    // over the gap): faces facing against the data with no data on their side (both sides of a
    // strip of one-sided data closed into a flat part, a part or a flap folded over one sheet).
    let fold_radius_2 = (FOLD_DATA_RADIUS_SIGMA_P * sigma_p).powi(2);
    let pillows = open_pillows(
        &mut mesh,
        &mut sources,
        boundary_curves > 0,
        |centroid, normal| {
            if rimls
                .value_and_gradient(centroid)
                .is_none_or(|(_, g)| g.dot(normal) > 0.0)
            {
                return FaceSide::Front;
            }
            let mut backed = false;
            rimls.visit_within(centroid, fold_radius_2, |i, _| {
                backed |= rimls.normals()[i as usize].dot(normal) > FOLD_SIDE_COS;
            });
            if backed {
                FaceSide::Backed
            } else {
                FaceSide::Fold
            }
        },
    );
    // Every output vertex within one output spacing (the mean edge length) of the data: a face
    // with a corner farther off spans empty space at the data's edge. Where the data is sparser
    // than the samples, its own chance gaps are wider: the gap rule's local spacings widen the
    // reach as they do for the faces (5,000 points of spot meshed at 4,000: a vertex a mean edge
    // from every point is no edge of the data there).
    let (spacing, boundary_before) = edge_figures(&mesh);
    let off_data = remove_faces_off_data(&mut mesh, &mut sources, |p| {
        domain.within(p, spacing / sigma_p, OPEN_GAP_SPACINGS)
    });
    // Last, no two faces cross: those untangle could not separate (sheets of the data closer
    // than the spacing) go, leaving holes.
    let mut crossing_faces = remove_crossing_faces(&mut mesh, &mut sources);
    // The faces beside the boundary those removals opened were shaped with neighbours now gone:
    // the optimization's last pass mends those of small angle again (the vertices of the new
    // boundary and their neighbours), under its guards (no new crossing, on the surface).
    let mut mend_after_removals = MendStats::default();
    if let Some(op) = optimize.as_ref() {
        let near = around_new_boundary(&mesh, &boundary_before);
        if near.iter().any(|&n| n) {
            let fixed_now: Vec<bool> = (0..mesh.positions.len()).map(|i| i < fixed).collect();
            let (stats, mended) = mend_near(
                &mut mesh,
                &domain,
                &fixed_now,
                &[],
                boundary_lines.as_ref(),
                None,
                sigma_p,
                op,
                &near,
                None,
            );
            sources = crate::pipeline::finish::carried_sources(&mended.origin, &sources);
            mend_after_removals = stats;
            let again = remove_faces_of_pairs(&mut mesh, &mut sources, &mended.intersecting);
            crossing_faces.faces += again.faces;
            crossing_faces.pinched_faces += again.pinched_faces;
        }
    }
    // Pieces no larger than a stray shell (4 sigma_p across, a dozen samples at most), open or
    // closed, are stray points meshed on their own (flying pixels at a depth jump, stray
    // returns), or what the removals above left of a fold: no surface the output resolves.
    let tiny_pieces = remove_tiny_pieces(&mut mesh, &mut sources, stray);
    let dropped_after_finishing = mesh.remove_unreferenced_vertices();
    timer.lap("untangle");
    // An empty mesh is never a result.
    if mesh.triangles.is_empty() {
        return Err(Error::invalid_mesh(
            input,
            "no triangle is left once the faces the data does not support are removed (the \
             points are too sparse, or not on a surface)",
        ));
    }
    Ok(Run::Meshed(Box::new(PointRemeshOutput {
        mesh: normalization.invert_mesh(&mesh),
        mesh_normalized: mesh,
        normalization,
        sigma_p,
        target,
        input_points: scan.input_points,
        duplicate_points: scan.duplicate_points,
        far_points: scan.far_points,
        kept: KeptPoints::whole(scan.far_groups.clone()),
        separate_parts: Vec::new(),
        left_out_parts: Vec::new(),
        had_normals: scan.had_normals,
        normal_repairs: repairs,
        outliers_removed: scan.outliers_removed,
        samples: samples.len(),
        unprojected_samples: unprojected,
        rescan_rejected,
        surface_variation,
        boundary_samples: fixed,
        boundary_curves,
        rimls_points: rimls.len(),
        gradient_ascent: ga,
        assembly,
        unsupported,
        unsupported_after_finishing,
        pillows,
        off_data,
        crossing_faces,
        tiny_pieces,
        mend_after_removals,
        optimize: finished.optimize,
        untangle_umbrellas,
        untangle: finished.untangle,
        mend_after_untangle: finished.mend_after_untangle,
        refine: finished.refine,
        dropped_samples: finished.dropped_samples
            + finished.later_dropped
            + dropped_after_finishing,
        stray_shells: finished.stray_shells,
        output_orientation: finished.orientation,
        scan_seconds: scan.seconds,
        stages: timer.take_stages(),
    })))
}

/// The mean length of `mesh`'s edges (each once, summed in the order of their vertex pairs; 0
/// for a mesh without faces), position units, and `V` flags of the vertices on a boundary edge
/// (an edge of one face), from [`TriMesh::edge_uses`].
fn edge_figures(mesh: &TriMesh) -> (f64, Vec<bool>) {
    let uses = mesh.edge_uses();
    let mut boundary = vec![false; mesh.positions.len()];
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(uses.len());
    for (&(a, b), &(_, n)) in &uses {
        if n == 1 {
            boundary[a as usize] = true;
            boundary[b as usize] = true;
        }
        edges.push((a, b));
    }
    if edges.is_empty() {
        return (0.0, boundary);
    }
    edges.sort_unstable();
    let p = &mesh.positions;
    let total: f64 = edges
        .iter()
        .map(|&(a, b)| p[a as usize].distance(p[b as usize]))
        .sum();
    (total / edges.len() as f64, boundary)
}

/// `V` flags: the vertices of `mesh` on its boundary that `before` (flags of the same
/// vertices) did not have there, and the vertices of the faces around them.
fn around_new_boundary(mesh: &TriMesh, before: &[bool]) -> Vec<bool> {
    let (_, now) = edge_figures(mesh);
    let new: Vec<bool> = now
        .iter()
        .enumerate()
        .map(|(v, &b)| b && !before.get(v).copied().unwrap_or(false))
        .collect();
    crate::pipeline::finish::with_their_faces(mesh, new)
}

/// Whether the file `path` is a point set for [`remesh_points`] rather than a mesh: a text
/// point format by its extension (`.xyz .xyzn .csv .txt .pts .asc`), or a PLY file without
/// faces (no `face` element, or one with no entries).
///
/// # Errors
/// Reading a PLY header, naming the file.
pub fn is_point_set(path: &Path) -> Result<bool> {
    crate::points::stream::is_point_set(path)
}
