//! The quality job: the report on any mesh, against a reference in the reference's bbox-100
//! frame.

use crate::geometry::crossing_curve::{output_spacing, CrossingCurve};
use crate::geometry::self_intersection::intersecting_pairs;
use crate::timing::Clock;
use crate::RemeshOutput;
use glam::DVec3;
use std::path::Path;

use super::files::with_path;
use super::DISTANCE_SAMPLES;
use crate::error::{Error, Result};
use crate::io::{check_and_clean, read_mesh};
use crate::mesh::{Normalization, TriMesh};
use crate::report::{surface_distance_with, QualityReport};
use crate::surface::MeshSurface;

/// Reports on the mesh in `path`; with `reference`, also the distance to it. Both are scaled by
/// the reference's bbox-100 normalization (or the mesh's own without a reference).
///
/// # Errors
/// Reading errors naming the file; [`Error::InvalidMesh`] for a mesh without area.
pub fn run_quality(path: &Path, reference: Option<&Path>, seed: u64) -> Result<QualityReport> {
    let t = Clock::start();
    let (mesh, _) = read_mesh(path)?;
    let reference = reference
        .map(|r| read_mesh(r).map(|(m, _)| (m, r)))
        .transpose()?;
    quality_read(mesh, path, reference, seed, t)
}

/// Reports on a mesh held in memory as [`run_quality`] reports on a file holding it: `mesh`
/// and `reference` get the checks and clean-up reading gives a file's mesh (faces present,
/// indices in range, finite coordinates; positions within a rounding welded, unreferenced vertices
/// removed), then the same measures; with `reference`, the distance to it too (both in the
/// reference's bbox-100 frame, or the mesh's own without one; the distance's random points
/// from `seed`). The report equals `run_quality`'s for files holding the same meshes, but for
/// its stage times.
///
/// # Errors
/// [`Error::InvalidMesh`] naming `mesh` or `reference` for a mesh that fails those checks or
/// has no area.
pub fn quality_mesh(mesh: TriMesh, reference: Option<TriMesh>, seed: u64) -> Result<QualityReport> {
    let t = Clock::start();
    let (mesh, _) = check_and_clean(Path::new("mesh"), mesh)?;
    let reference = reference
        .map(|r| {
            check_and_clean(Path::new("reference"), r).map(|(m, _)| (m, Path::new("reference")))
        })
        .transpose()?;
    quality_read(mesh, Path::new("mesh"), reference, seed, t)
}

/// [`run_quality`] from the meshes read on (shared with [`quality_mesh`]): `path` and the
/// reference's path name them in errors; `t` is the clock started before reading.
pub(super) fn quality_read(
    mesh: TriMesh,
    path: &Path,
    reference: Option<(TriMesh, &Path)>,
    seed: u64,
    t: Clock,
) -> Result<QualityReport> {
    // Subnormal coordinates: both meshes scaled up alike (the report is in bbox-100 units).
    let (mesh, reference) = match &reference {
        Some((r, p)) => {
            let (r, up) = into_normal_range(r.clone());
            (scale_by_power_of_two(&mesh, up), Some((r, *p)))
        }
        None => (into_normal_range(mesh).0, None),
    };
    let frame = reference.as_ref().map_or(&mesh, |(r, _)| r);
    let normalization = own_frame(frame, path)?;
    let m = normalization.apply_mesh(&mesh);
    // Crossings at the file's own coordinates, not the frame's rounded ones.
    let mut report = QualityReport::with_crossings_on(&m, &mesh);
    let duplicates = report.topology.duplicate_faces;
    if duplicates > 0 {
        report.notes.push(format!(
            "{duplicates} faces repeat an earlier face's three vertices (duplicate faces); each \
             is counted once in the search for crossing faces (faces searched: {}){}",
            report.self_intersections.faces,
            if reference.is_some() {
                " and in the distance"
            } else {
                ""
            }
        ));
    }
    let (wall, cpu) = t.elapsed();
    report.push_stage("read and measure", wall, cpu);
    if let Some((r, reference_path)) = &reference {
        let t = Clock::start();
        let rn = normalization.apply_mesh(r);
        report.set_input(&rn);
        // The surfaces without their duplicate faces: the same surfaces, each face once (a
        // face repeated 20,000 times is not 20,000 candidates of every closest-point query).
        let (m, _) = m.without_duplicate_faces();
        let (rn, _) = rn.without_duplicate_faces();
        // Each side's error names its own file.
        let sm = MeshSurface::new(&m).map_err(|e| with_path(e, path))?;
        let sr = MeshSurface::new(&rn).map_err(|e| with_path(e, reference_path))?;
        report.distance = Some(surface_distance_with(
            &m,
            &sm,
            &rn,
            &sr,
            DISTANCE_SAMPLES,
            seed,
        ));
        let (wall, cpu) = t.elapsed();
        report.push_stage("distance", wall, cpu);
    }
    Ok(report)
}

/// `mesh` (model units, as a file stores it) as [`run_quality`] sees the file: cleaned as a
/// reader cleans it ([`check_and_clean`]: positions within a rounding welded, unreferenced vertices
/// dropped), subnormal coordinates scaled up, in its own bbox-100 frame ([`own_frame`]).
/// `None` when the file would be refused.
/// With it, the map from model units (before the subnormal scaling) into that frame.
/// Also the same mesh before the frame: the file's coordinates (scaled by `2^up`, which is
/// exact), where crossings are decided ([`QualityReport::with_crossings_on`]).
pub(super) fn as_quality_reads(
    mesh: TriMesh,
    path: &Path,
) -> Option<(TriMesh, FileFrame, TriMesh)> {
    let (mesh, _) = check_and_clean(path, mesh).ok()?;
    let (mesh, up) = into_normal_range(mesh);
    let frame = own_frame(&mesh, path).ok()?;
    Some((frame.apply_mesh(&mesh), FileFrame { frame, up }, mesh))
}

/// The frame [`as_quality_reads`] puts a file's mesh in: scaled by `2^up`, then `frame`.
#[derive(Debug, Clone, Copy)]
pub(super) struct FileFrame {
    frame: Normalization,
    up: i32,
}

impl FileFrame {
    /// A point in model units (before the run's own subnormal scaling by `2^run_up`) in this
    /// frame; `None` when the two scalings differ by more than `f64` holds exactly here.
    fn map(&self, run_up: i32) -> Option<impl Fn(DVec3) -> DVec3 + '_> {
        let k = self.up - run_up;
        (k.abs() < 1000).then_some(move |p: DVec3| self.frame.apply(p * 2f64.powi(k)))
    }
}

/// How many of the crossing pairs of `stored` (the written mesh as [`as_quality_reads`] gives
/// it, at the file's coordinates; `checked` is the same in `file`'s frame) are the input's:
/// both faces lie within one output spacing (the mean edge of `checked`) of the curve where
/// the input's own faces cross or its closed parts meet ([`CrossingCurve`]), whatever vertex
/// they share.
pub(super) fn crossings_of_the_input(
    out: &RemeshOutput,
    checked: &TriMesh,
    stored: &TriMesh,
    file: &FileFrame,
    run_up: i32,
) -> usize {
    if out.input_crossing_pairs.is_empty() && out.junction.is_empty() {
        return 0;
    }
    let Some(to_file) = file.map(run_up) else {
        return 0;
    };
    let input = &out.input_normalized;
    let positions: Vec<DVec3> = input
        .positions
        .iter()
        .map(|&p| to_file(out.normalization.invert(p)))
        .collect();
    let regions = CrossingCurve::new(
        &positions,
        &input.triangles,
        &out.input_crossing_pairs,
        &out.junction,
        output_spacing(&checked.positions, &checked.triangles),
    );
    let pairs = intersecting_pairs(&stored.positions, &stored.triangles);
    regions.count_inside(&checked.positions, &checked.triangles, &pairs)
}

/// The bbox-100 frame of `mesh`'s own bounding box, the frame [`run_quality`] measures a mesh
/// in when there is no reference; errors name `path`.
pub(super) fn own_frame(mesh: &TriMesh, path: &Path) -> Result<Normalization> {
    let bbox = mesh
        .bbox()
        .ok_or_else(|| Error::invalid_mesh(path, "the mesh has no vertices"))?;
    Normalization::for_bbox(&bbox)
        .ok_or_else(|| Error::invalid_mesh(path, Normalization::refusal(&bbox)))
}

/// A model too small for the bbox-100 frame's `f64` scale (a longest side below about
/// 5.6e-307 model units: subnormal coordinates), or one whose squared lengths leave `f64`'s
/// range (a longest side below 2^-256 or above 2^256: the zero-area test's cross products
/// underflowed at 1e-300), scaled by `2^k` so its longest side is between 1 and 2, and `k`;
/// every other model as it is, and 0. Scaling by a power of two
/// changes no digit, so the model is the same one in other units.
pub(super) fn into_normal_range(mesh: TriMesh) -> (TriMesh, i32) {
    let Some(bbox) = mesh.bbox() else {
        return (mesh, 0);
    };
    let side = bbox.longest_side();
    // Also where squared lengths (the zero-area test's) leave f64's normal range.
    let squares_in_range = (2f64.powi(-256)..=2f64.powi(256)).contains(&side);
    if !(side.is_finite() && side > 0.0)
        || (Normalization::for_bbox(&bbox).is_some() && squares_in_range)
    {
        return (mesh, 0);
    }
    let k = -(side.log2().floor() as i32);
    (scale_by_power_of_two(&mesh, k), k)
}

/// `mesh` with every coordinate multiplied by `2^k`, in steps that stay in `f64`'s range (so
/// each step is exact, and the result is rounded once at most, where it is subnormal).
pub(super) fn scale_by_power_of_two(mesh: &TriMesh, k: i32) -> TriMesh {
    let mut positions = mesh.positions.clone();
    let mut left = k;
    while left != 0 {
        let step = left.clamp(-1000, 1000);
        let f = 2f64.powi(step);
        for p in &mut positions {
            *p *= f;
        }
        left -= step;
    }
    TriMesh {
        positions,
        triangles: mesh.triangles.clone(),
    }
}
