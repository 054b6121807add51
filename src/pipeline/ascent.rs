//! The gradient ascent stage (Sec. 6.2): the surface samples move up the gradient of the
//! spectral measure, projected back onto the input; the curve samples stay.

use glam::DVec3;

use crate::geometry::morton::morton_order;

use super::input::InputIndex;
use super::scan::Scanned;
use super::sizing::crease_terms;
use super::RemeshParams;
use crate::error::Result;
use crate::kernel::Kernel;
use crate::sampling::crease_band::CreaseBand;
use crate::sampling::gradient_ascent::{gradient_ascent, GradientAscentResult};
use crate::sampling::spacing::FEATURE_SPACING_PER_SIGMA;
use crate::surface::SurfaceSample;

/// The samples after the gradient ascent.
pub(super) struct Ascended {
    /// The samples, the fixed curve samples first (bbox-100 units).
    pub samples: Vec<SurfaceSample>,
    /// How many of them are fixed curve samples.
    pub boundary_count: usize,
    /// The final linear scan's statistics: candidates rejected by their nearest sample, and
    /// candidates whose measure was evaluated.
    pub rejected_by_nearest: usize,
    pub measured: usize,
    /// The ascent's convergence record.
    pub record: GradientAscentResult,
    /// Samples the ascent moved onto the buried part of a face, put back where the scan put
    /// them.
    pub buried_samples: usize,
}

/// The gradient ascent of `scanned`'s samples on the input (`index`), in its width field; the
/// surface samples keep out of a band along the sampled creases.
///
/// # Errors
/// Those of [`Kernel::new`] (sigma_n was checked before).
pub(super) fn ascend(
    scanned: &mut Scanned,
    index: &InputIndex,
    params: &RemeshParams,
) -> Result<Ascended> {
    let sigma_p = scanned.sigma_p;
    let kernel = Kernel::new(sigma_p, params.sigma_n)?;
    let mut samples = std::mem::take(&mut scanned.scan.result.samples);
    let (scanned, feature_spacing) = (&*scanned, FEATURE_SPACING_PER_SIGMA * sigma_p);
    let scan = &scanned.scan;
    let boundary_count = scan.result.initial;
    let before_ascent = index.buried_test.as_ref().map(|_| samples.clone());
    let corner_term = scanned.corner_term();
    let creases = crease_terms(
        &corner_term,
        &scanned.scan.separation,
        &scanned.scan.curvature,
    );
    let field = scanned.widths.field().with(&creases);
    // Surface samples keep out of a band along the sampled creases.
    let band = {
        let positions: Vec<DVec3> = samples[..boundary_count]
            .iter()
            .map(|s| s.position)
            .collect();
        CreaseBand::new(
            &positions,
            &scan.feature_edges,
            feature_spacing,
            0.05 * feature_spacing,
        )
    };
    let record = gradient_ascent(
        &kernel,
        &index.surface,
        &mut samples,
        boundary_count,
        &field,
        band.as_ref(),
        &params.gradient_ascent,
        params.seed,
    );
    // A face buried only in part can still take a sample onto its buried part (the closest point
    // of the input can lie there): such a sample goes back to where the scan put it.
    let mut buried_samples = 0;
    if let (Some(test), Some(before)) = (&index.buried_test, &before_ascent) {
        let buried = test.buried(
            &samples
                .iter()
                .map(|s| (s.position, s.normal, Some(s.face)))
                .collect::<Vec<_>>(),
        );
        for (i, b) in buried.iter().enumerate() {
            if *b && i >= boundary_count {
                samples[i] = before[i];
                buried_samples += 1;
            }
        }
    }
    // The surface samples in Morton order from here on: the triangulation's and the finishing
    // stage's loops over vertices then walk the surface, which keeps the input's and the
    // output's search structures in cache (they came in the scan's random order).
    let order = morton_order(
        &samples[boundary_count..]
            .iter()
            .map(|s| s.position)
            .collect::<Vec<_>>(),
    );
    let surface: Vec<SurfaceSample> = order
        .iter()
        .map(|&i| samples[boundary_count + i as usize])
        .collect();
    samples.truncate(boundary_count);
    samples.extend(surface);
    Ok(Ascended {
        samples,
        boundary_count,
        rejected_by_nearest: scan.result.rejected_by_nearest,
        measured: scan.result.measured,
        record,
        buried_samples,
    })
}
