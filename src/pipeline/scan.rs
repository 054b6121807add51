//! The linear scan stage: the fixed samples on the boundary and crease curves, then the
//! randomized linear scan of the candidates (Sec. 6.1), with the search for the sigma_p that
//! gives the asked count (Sec. 6.3).

use std::borrow::Cow;

use glam::DVec3;
use rayon::prelude::*;

use super::input::{Candidates, NormalizedInput};
use super::params::Target;
use super::sizing::{crease_terms, Sizing, Widths};
use super::{RemeshParams, MAX_POINTS};
use crate::error::{Error, Result};
use crate::kernel::Kernel;
use crate::sampling::crease_curvature::crease_curvature;
use crate::sampling::crease_separation::CreaseSeparation;
use crate::sampling::curves::{boundary_sample_count, sample_curves_and_features, FeaturePiece};
use crate::sampling::features::{feature_pieces, graded_corners, Corners, GradedCorner};
use crate::sampling::linear_scan::{linear_scan, LinearScanResult};
use crate::sampling::sizing::{GradedPoints, SizingField, Uniform};
use crate::sampling::spacing::{BOUNDARY_SPACING_PER_SIGMA, FEATURE_SPACING_PER_SIGMA};
use crate::sampling::target_count::{find_sigma_p, TargetCountParams};
use crate::surface::curvature::CurvatureWidths;
use crate::surface::features::{Features, LONG_CURVE_SPACINGS};

/// Rounds of the search at most when grading moves the widths with sigma_p (see [`scan`]).
const MAX_WIDTH_ROUNDS: usize = 3;

/// One linear scan with its fixed curve samples: the scan's result (the curve samples first),
/// the edges between consecutive curve samples (boundary, then creases), and the corners the
/// creases are graded towards.
pub(super) struct CurveScan {
    pub result: LinearScanResult,
    pub boundary_edges: Vec<[u32; 2]>,
    pub feature_edges: Vec<[u32; 2]>,
    pub corners: Vec<GradedCorner>,
    /// The grading beside creases closer than their samples' gap (at the creases' spacing).
    pub separation: CreaseSeparation,
    /// The grading along curved creases (at the creases' spacing).
    pub curvature: GradedPoints,
}

/// The state of the count search across the pipeline's attempts: the count aimed at, where the
/// search starts, the sigma_p the grading's widths are taken for, and every evaluation so far.
pub(super) struct Search {
    pub goal: usize,
    pub start: f64,
    pub sigma_ref: f64,
    /// The largest sigma_p the search tries (infinity without a sizing field; see
    /// `GradingParams::max_coarsening`).
    pub max_sigma: f64,
    pub history: Vec<(f64, usize)>,
}

/// The linear scan's answer: sigma_p, whether the count came within the tolerance, this
/// attempt's evaluations as (sigma_p, samples), the scan, and the widths of its last round
/// (those of `sigma_ref`, which the gradient ascent takes too).
pub(super) struct Scanned<'s> {
    pub sigma_p: f64,
    pub target_reached: bool,
    pub history: Vec<(f64, usize)>,
    pub scan: CurveScan,
    pub widths: Widths<'s>,
}

impl Scanned<'_> {
    /// The grading towards the corners the creases are graded towards, at the creases' spacing.
    pub(super) fn corner_term(&self) -> Corners<'_> {
        Corners::new(&self.scan.corners, FEATURE_SPACING_PER_SIGMA * self.sigma_p)
    }
}

/// What one evaluation of the scan reads.
struct ScanInputs<'a> {
    input: &'a NormalizedInput,
    features: &'a Features,
    pool: &'a [crate::surface::SurfaceSample],
    params: &'a RemeshParams,
    /// The creases' total length (the curves the scan samples besides the boundary).
    crease_length: f64,
    /// The most curve samples one evaluation places (see [`scan`]).
    boundary_limit: f64,
}

impl ScanInputs<'_> {
    /// The scan at `sigma_p` with the width field `widths` (`pool_widths`: its values at the
    /// candidates): the sample count, and the scan (`None` when the curves alone would take
    /// more than the limit: the count is then theirs, a lower bound of the scan's).
    fn at(
        &self,
        sigma_p: f64,
        widths: &Widths,
        pool_widths: Option<&[f64]>,
    ) -> Result<(usize, Option<CurveScan>)> {
        let (normalized, params) = (&self.input.mesh, self.params);
        let kernel = Kernel::new(sigma_p, params.sigma_n)?;
        let spacing = BOUNDARY_SPACING_PER_SIGMA * sigma_p;
        let feature_spacing = FEATURE_SPACING_PER_SIGMA * sigma_p;
        // The curves' samples from their lengths, before any is placed: a sigma_p whose curves
        // would take four times the limit is answered without placing them (a crease of 10^8
        // spacings, a sliver's edge at a tiny sigma_p, filled the memory before the count below
        // was reached). Four times: creases crowded out by others take no samples, so the count
        // below can be lower than this one, not that much lower.
        let least = self.input.boundary_length / spacing + self.crease_length / feature_spacing;
        if !(least <= 4.0 * self.boundary_limit) {
            return Ok((least.min(usize::MAX as f64) as usize, None));
        }
        // The boundary curves, cut where creases end on them, and the creases long enough to
        // take samples at their spacing; along a curved crease, at the spacing its chords' sag
        // asks for (crease_curvature).
        let curvature = crease_curvature(normalized, self.features, feature_spacing);
        let field = widths.field().with(&curvature);
        let (mut boundary_pieces, mut feature_curves) = feature_pieces(
            normalized,
            &self.input.curves,
            self.features,
            feature_spacing,
            &field,
            false,
        );
        // Where creases were left out for running closer to others than their samples' gap,
        // the spacing is lowered beside them (crease_separation) and the curves taken again;
        // those still crowded then are sampled as ladders beside the others (crease_ladder).
        let crowded = left_out(
            self.features,
            &feature_curves,
            &normalized.positions,
            feature_spacing,
        );
        let separation =
            CreaseSeparation::new(normalized, self.features, &crowded, feature_spacing);
        if crowded.contains(&true) {
            (boundary_pieces, feature_curves) = feature_pieces(
                normalized,
                &self.input.curves,
                self.features,
                feature_spacing,
                &widths.field().with(&curvature).with(&separation),
                true,
            );
        }
        let boundary_count = boundary_sample_count(normalized, &boundary_pieces, spacing)
            + boundary_sample_count(
                normalized,
                feature_curves.iter().map(|f| &f.curve),
                feature_spacing,
            );
        if !(boundary_count <= self.boundary_limit) {
            return Ok((boundary_count.min(usize::MAX as f64) as usize, None));
        }
        // Around a corner that creases are graded towards, the other curves and the surface
        // samples are graded too (corner_width).
        let corners = graded_corners(normalized, &feature_curves, feature_spacing);
        let corner_term = Corners::new(&corners, feature_spacing);
        let creases = crease_terms(&corner_term, &separation, &curvature);
        let field = widths.field().with(&creases);
        let b = sample_curves_and_features(
            normalized,
            &boundary_pieces,
            &feature_curves,
            spacing,
            feature_spacing,
            &field,
        );
        let r = if !field.is_uniform() {
            // The candidates' widths: the round's, lowered by the crease terms (around the graded
            // corners, beside crowded creases, along curved ones).
            let pool_w: Option<Cow<[f64]>> = if creases.is_uniform() {
                pool_widths.map(Cow::Borrowed)
            } else {
                Some(Cow::Owned(
                    self.pool
                        .par_iter()
                        .enumerate()
                        .map(|(i, c)| {
                            pool_widths
                                .map_or(1.0, |pw| pw[i])
                                .min(creases.width(c.position))
                        })
                        .collect(),
                ))
            };
            linear_scan(
                &kernel,
                self.pool,
                pool_w.as_deref(),
                &b.samples,
                &field,
                &params.linear_scan,
            )
        } else {
            linear_scan(
                &kernel,
                self.pool,
                None,
                &b.samples,
                &Uniform,
                &params.linear_scan,
            )
        };
        let count = r.samples.len();
        let scan = CurveScan {
            result: r,
            boundary_edges: b.edges,
            feature_edges: b.feature_edges,
            corners,
            separation,
            curvature,
        };
        Ok((count, Some(scan)))
    }
}

/// The linear scan for `target`: at the given sigma_p, or at the sigma_p the search finds for
/// `search.goal` samples. The widths depend on sigma_p; a search over sigma_p with them moving
/// could find the count flat (a part graded at every sigma_p tried). So each search holds the
/// widths of `search.sigma_ref`, and when it ends far from there, the widths are taken again at
/// its answer and the search repeats from there (at most [`MAX_WIDTH_ROUNDS`] rounds; only when
/// the grading changes some width).
///
/// # Errors
/// [`Error::InvalidParameter`] when even the best sigma_p tried puts more samples on the
/// boundary curves than the bound (4 times the goal; loops need 3 samples each, however short).
pub(super) fn scan<'s>(
    target: Target,
    search: &mut Search,
    input: &NormalizedInput,
    features: &Features,
    candidates: &Candidates,
    sizing: &'s Sizing,
    params: &RemeshParams,
) -> Result<Scanned<'s>> {
    let pool = &candidates.pool;
    // The boundary samples of one evaluation are bounded: a sigma_p whose boundary curves alone
    // take more than four times the target (or more than the memory bound) is far from the
    // answer, and its count is reported without sampling (None: skipped). The count is a lower
    // bound of the scan's, so the search still moves the right way.
    let boundary_limit = match target {
        Target::Points(_) => (4.0 * search.goal as f64).clamp(64.0, MAX_POINTS as f64),
        Target::SigmaP(_) => MAX_POINTS as f64,
    };
    let inputs = ScanInputs {
        input,
        features,
        pool,
        params,
        crease_length: features
            .curves
            .iter()
            .map(|c| c.length(&input.mesh.positions))
            .sum(),
        boundary_limit,
    };
    // The candidates' widths for one sigma_ref, taken once for a round's evaluations.
    // (None for a uniform field, which the scan takes as 1 everywhere.)
    let pool_widths = |w: &Widths| -> Option<Vec<f64>> {
        let field = w.field();
        (!field.is_uniform()).then(|| pool.par_iter().map(|c| field.width(c.position)).collect())
    };
    let (sigma_p, target_reached, history, value, widths) = match target {
        Target::SigmaP(s) => {
            let w = sizing.widths_at(pool, s);
            let pool_w = pool_widths(&w);
            let (count, value) = inputs.at(s, &w, pool_w.as_deref())?;
            (s, true, vec![(s, count)], value, w)
        }
        Target::Points(_) => {
            let count_search = TargetCountParams {
                tolerance: params.count_tolerance,
                max_sigma: search.max_sigma,
                ..TargetCountParams::new(search.goal)
            };
            let mut history = Vec::new();
            let mut round_start = search.start;
            let mut round = 0;
            loop {
                let w = sizing.widths_at(pool, search.sigma_ref);
                let pool_w = pool_widths(&w);
                let mut failure = None;
                let r = find_sigma_p(&count_search, round_start, |s| {
                    match inputs.at(s, &w, pool_w.as_deref()) {
                        Ok(v) => v,
                        Err(e) => {
                            failure = Some(e);
                            (0, None)
                        }
                    }
                });
                if let Some(e) = failure {
                    return Err(e);
                }
                history.extend(r.history.iter().copied());
                round += 1;
                let moved = (r.sigma_p / search.sigma_ref).ln().abs() > 0.1;
                let widths_change = sizing
                    .grading
                    .as_ref()
                    .is_some_and(|g| g.grades_below(search.sigma_ref.max(r.sigma_p)))
                    || w.curvature.as_ref().is_some_and(CurvatureWidths::grades);
                if round >= MAX_WIDTH_ROUNDS || !moved || !widths_change {
                    break (r.sigma_p, r.reached, history, r.value, w);
                }
                search.sigma_ref = r.sigma_p;
                round_start = r.sigma_p;
            }
        }
    };
    let Some(scan) = value else {
        let (name, what) = target.named(search.goal);
        return Err(Error::InvalidParameter {
            name,
            message: format!(
                "{what} cannot be reached on this surface: its {} boundary curves \
                 ({:.3} long, bbox-100 units) alone take more than {boundary_limit} samples at \
                 every sigma_p tried",
                input.curves.len(),
                input.boundary_length,
            ),
        });
    };
    Ok(Scanned {
        sigma_p,
        target_reached,
        history,
        scan,
        widths,
    })
}

/// Per curve of `features`: whether it is long ([`LONG_CURVE_SPACINGS`] `spacing`s or more,
/// bbox-100 units) and not among the `kept` pieces, so left out for crowding, not for its
/// length. Only those are worth the finer spacing beside them: a long crease lost costs its
/// whole length; a short one (a gear's tooth land beside its flanks at a coarse spacing) costs
/// a spacing, and grading its crowded neighbourhood costs more triangles of worse shape.
fn left_out(
    features: &Features,
    kept: &[FeaturePiece],
    positions: &[DVec3],
    spacing: f64,
) -> Vec<bool> {
    let kept: rustc_hash::FxHashSet<&[u32]> =
        kept.iter().map(|p| p.curve.vertices.as_slice()).collect();
    features
        .curves
        .iter()
        .map(|c| {
            c.length(positions) >= LONG_CURVE_SPACINGS * spacing
                && !kept.contains(c.vertices.as_slice())
        })
        .collect()
}
