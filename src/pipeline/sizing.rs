//! The sizing field of one run: the kernel width relative to sigma_p at each point, the
//! smallest of the grading by thickness (local feature size), the grading by curvature and the
//! grading towards crease corners; 1 everywhere when none is on.

use super::input::NormalizedInput;
use super::RemeshParams;
use crate::error::Result;
use crate::sampling::crease_separation::CreaseSeparation;
use crate::sampling::features::Corners;
use crate::sampling::grading::{Grading, Thickness};
use crate::sampling::sizing::{GradedPoints, SizingField, Smallest};
use crate::sampling::spacing::SAMPLES_PER_SIGMA2;
use crate::surface::curvature::{Curvature, CurvatureParams, CurvatureWidths};
use crate::surface::{MeshSurface, SurfaceSample};
use crate::timing::StageTimer;

/// The smallest width the refinement for the topological ball property asks for (relative to
/// sigma_p).
pub(super) const MIN_REFINED_WIDTH: f64 = 1.0 / 16.0;

/// The most points the local feature size is estimated at for the grading (their spacing is
/// about the expected samples' otherwise).
const MAX_GRADING_POINTS: f64 = 200_000.0;

/// The gradings a run asks for, estimated once on the input.
pub(super) struct Sizing {
    /// By thickness (`None` when off).
    pub grading: Option<Grading>,
    /// By curvature (`None` when off).
    pub curvature: Option<(Curvature, CurvatureParams)>,
    /// The input's component count, which the stray-shell pass (grading only) brings the output
    /// back to (0 without grading).
    pub input_components: usize,
    /// Where an earlier attempt's triangulation failed the topological ball property: the
    /// width lowered around the samples it inserted (`None` before any did).
    pub refinement: Option<GradedPoints>,
    /// The points and widths of `refinement`.
    refined_at: (Vec<glam::DVec3>, Vec<f64>),
}

impl Sizing {
    /// The gradings `params` ask for on `input`, for a search that starts at `first_sigma_p`.
    ///
    /// # Errors
    /// Those of [`Grading::new`].
    pub(super) fn new(
        input: &NormalizedInput,
        surface: &MeshSurface,
        first_sigma_p: f64,
        params: &RemeshParams,
        on_stage: &(dyn Fn(&str) + Sync),
        timer: &mut StageTimer,
    ) -> Result<Self> {
        let curvature = params.curvature.map(|p| (Curvature::new(surface, &[]), p));
        // The local feature size, for the grading of the kernel width: estimated up to a few
        // times the largest width the search is expected to try (a part thicker than that is not
        // graded).
        let grading = match params.grading {
            Some(g) => {
                on_stage("local feature size");
                let cap = 1.5 * g.max_coarsening * first_sigma_p / g.lfs_factor;
                // Estimate points every first_sigma_p (about one per expected sample), at most
                // MAX_GRADING_POINTS of them.
                let spacing = first_sigma_p.max((input.area / MAX_GRADING_POINTS).sqrt());
                let mut grading = Grading::new(&input.mesh, &input.curves, g, cap, spacing)?;
                // The count the field may grow to is bounded against the paper's count at
                // the first sigma_p.
                let uniform = SAMPLES_PER_SIGMA2 * input.area / (first_sigma_p * first_sigma_p);
                grading.bound_growth(input.area, first_sigma_p, uniform);
                timer.lap("local feature size");
                Some(grading)
            }
            None => None,
        };
        let input_components = grading.as_ref().map_or(0, |_| {
            crate::mesh::topology::topology(&input.mesh).components
        });
        Ok(Sizing {
            grading,
            curvature,
            input_components,
            refinement: None,
            refined_at: (Vec::new(), Vec::new()),
        })
    }

    /// Lowers the width to `factor` times `width_at` at `points` (where the
    /// triangulation inserted samples for the topological ball property), at least
    /// [`MIN_REFINED_WIDTH`], graded around them, for the global `sigma_ref`: the next attempt
    /// samples finely enough there by itself. Points already refined at are refined again.
    pub(super) fn refine_at(
        &mut self,
        points: &[glam::DVec3],
        width_at: &[f64],
        factor: f64,
        sigma_ref: f64,
    ) {
        let (at, widths) = &mut self.refined_at;
        for (&p, &w) in points.iter().zip(width_at) {
            at.push(p);
            widths.push((factor * w).max(MIN_REFINED_WIDTH));
        }
        self.refinement = Some(GradedPoints::new(at, widths.clone(), sigma_ref));
    }

    /// The width field for the global `sigma_ref`, the curvature's taken at the candidates
    /// `pool`.
    pub(super) fn widths_at(&self, pool: &[SurfaceSample], sigma_ref: f64) -> Widths<'_> {
        Widths {
            thickness: self
                .grading
                .as_ref()
                .map(|grading| Thickness::new(grading, sigma_ref)),
            curvature: self
                .curvature
                .as_ref()
                .map(|(c, p)| CurvatureWidths::new(c, pool, sigma_ref, p.chord_error, p.min_width)),
            refinement: self.refinement.as_ref(),
            sigma_ref,
        }
    }
}

/// The sizing terms of one remesh round: the grading by thickness and the grading by curvature,
/// for the global `sigma_ref`.
pub(super) struct Widths<'a> {
    pub thickness: Option<Thickness<'a>>,
    pub curvature: Option<CurvatureWidths>,
    /// Where an earlier attempt failed the topological ball property.
    pub refinement: Option<&'a GradedPoints>,
    pub sigma_ref: f64,
}

impl Widths<'_> {
    /// The sizing field: the smallest of the terms on (uniform with none).
    pub(super) fn field(&self) -> Smallest<'_> {
        let thickness = self.thickness.as_ref().map(|t| t as &dyn SizingField);
        let curvature = self.curvature.as_ref().map(|c| c as &dyn SizingField);
        let refinement = self.refinement.map(|r| r as &dyn SizingField);
        Smallest::new(thickness.into_iter().chain(curvature).chain(refinement))
    }
}

/// The crease terms of the sizing field: the grading around the corners creases are graded
/// towards, beside creases closer than their samples' gap and along creases curved tighter than
/// their chords allow. The field is [`Widths::field`] with these.
pub(super) fn crease_terms<'b>(
    corners: &'b Corners<'b>,
    separation: &'b CreaseSeparation,
    curvature: &'b GradedPoints,
) -> Smallest<'b> {
    Smallest::new([corners as &dyn SizingField, separation, curvature])
}
