//! The sizing field: the kernel width at a point relative to sigma_p, w(p) in (0, 1], so that a
//! graded kernel's width is w(p) · sigma_p (see `Kernel`). One field is read by every stage that
//! places samples: the curve samples (`sampling::curves`, `sampling::features`), the linear scan
//! and the gradient ascent. Its terms are the paper's single sigma_p ([`Uniform`]), the grading
//! by thickness (`grading::Thickness`, the local feature size), the grading by curvature
//! (`CurvatureWidths`), the grading towards crease corners (`features::Corners`), beside
//! crowded creases (`crease_separation`) and along curved ones (`crease_curvature`); a run's
//! field is the smallest of the terms it asks for ([`Smallest`]).

use glam::DVec3;

use crate::spatial::StaticTree;
use crate::surface::curvature::{CurvatureWidths, CURVATURE_GRADATION};

/// A field of relative kernel widths over positions (bbox-100 units).
pub trait SizingField: Sync {
    /// The relative width at `p`, in (0, 1].
    fn width(&self, p: DVec3) -> f64;

    /// Whether the field is 1 everywhere by construction: the stages then take the paper's
    /// single sigma_p (the same samples as a graded field of 1 everywhere, at less cost).
    fn is_uniform(&self) -> bool {
        false
    }
}

/// One sigma_p everywhere, as in the paper.
#[derive(Debug, Clone, Copy, Default)]
pub struct Uniform;

impl SizingField for Uniform {
    fn width(&self, _: DVec3) -> f64 {
        1.0
    }

    fn is_uniform(&self) -> bool {
        true
    }
}

/// The grading by curvature (the widths taken at points, the nearest one's at p).
impl SizingField for CurvatureWidths {
    fn width(&self, p: DVec3) -> f64 {
        CurvatureWidths::width(self, p)
    }
}

/// Relative widths given at points, graded around them: at `x`, the smallest over the points q
/// of w(q) + [`CURVATURE_GRADATION`] · |x − q| / `spacing` (the spacing's Lipschitz bound), at
/// most 1. The terms that lower the spacing along creases build one
/// (`sampling::crease_separation`, `sampling::crease_curvature`).
pub struct GradedPoints {
    tree: StaticTree,
    widths: Vec<f64>,
    /// The spacing where the width is 1 (bbox-100 units).
    spacing: f64,
    /// The farthest a point's width reaches before the grading brings it to 1, squared.
    reach_2: f64,
    /// The smallest of `widths` (1 with none).
    least: f64,
}

impl GradedPoints {
    /// The field of `widths` at `points` (each in (0, 1)), for the spacing `spacing`.
    pub fn new(points: &[DVec3], widths: Vec<f64>, spacing: f64) -> Self {
        let least = widths.iter().copied().fold(1.0f64, f64::min);
        let reach = (1.0 - least) / CURVATURE_GRADATION * spacing;
        GradedPoints {
            tree: StaticTree::new(points),
            widths,
            spacing,
            reach_2: (reach * (1.0 + 1e-9)).powi(2),
            least,
        }
    }
}

impl SizingField for GradedPoints {
    /// The nearest point's value first: a point q lowers it only within (value − least) ·
    /// spacing / gradation of p (its w(q) is at least `least`), so only that ball is searched,
    /// not the whole reach. The same smallest value either way.
    fn width(&self, p: DVec3) -> f64 {
        let value = |i: u32, d2: f64| {
            self.widths[i as usize] + CURVATURE_GRADATION * d2.sqrt() / self.spacing
        };
        let Some((i, d2)) = self.tree.nearest(p) else {
            return 1.0;
        };
        if d2 > self.reach_2 {
            return 1.0;
        }
        let mut w = value(i, d2).min(1.0);
        let r = (w - self.least) * self.spacing / CURVATURE_GRADATION * (1.0 + 1e-9);
        if r > 0.0 {
            self.tree
                .visit_within(p, (r * r).min(self.reach_2), |i, d2| {
                    w = w.min(value(i, d2))
                });
        }
        w
    }

    fn is_uniform(&self) -> bool {
        self.widths.is_empty()
    }
}

/// The smallest of its terms (1 where none is smaller): uniform when every term is. The terms
/// that are uniform by construction are left out when it is made, not asked at every point.
pub struct Smallest<'a>(Vec<&'a dyn SizingField>);

impl<'a> Smallest<'a> {
    /// The smallest of `terms`.
    pub fn new(terms: impl IntoIterator<Item = &'a dyn SizingField>) -> Self {
        Smallest(terms.into_iter().filter(|t| !t.is_uniform()).collect())
    }

    /// This field and `term`, the smaller.
    pub fn with(mut self, term: &'a dyn SizingField) -> Self {
        if !term.is_uniform() {
            self.0.push(term);
        }
        self
    }
}

impl SizingField for Smallest<'_> {
    fn width(&self, p: DVec3) -> f64 {
        self.0.iter().fold(1.0, |w, t| w.min(t.width(p)))
    }

    fn is_uniform(&self) -> bool {
        self.0.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Half;
    impl SizingField for Half {
        fn width(&self, p: DVec3) -> f64 {
            if p.x > 0.0 {
                0.5
            } else {
                1.0
            }
        }
    }

    #[test]
    fn the_smallest_term_sets_the_width() {
        let corners = crate::sampling::features::Corners::new(&[], 1.0);
        assert!(Smallest::new([]).is_uniform());
        assert!(Smallest::new([&Uniform as &dyn SizingField, &corners]).is_uniform());
        let field = Smallest::new([&Uniform as &dyn SizingField, &Half, &corners]);
        assert!(!field.is_uniform());
        assert_eq!(field.width(DVec3::X), 0.5);
        assert_eq!(field.width(-DVec3::X), 1.0);
    }

    /// A field of 1 everywhere that does not say so takes the graded path of the scan and the
    /// ascent; [`Uniform`] takes the paper's: the same samples, bit for bit (the uniform path is
    /// only faster). And a field below 1 somewhere changes them.
    #[test]
    fn the_uniform_path_is_the_graded_path_at_width_1() {
        use crate::kernel::Kernel;
        use crate::mesh::test_meshes;
        use crate::sampling::gradient_ascent::{gradient_ascent, GradientAscentParams};
        use crate::sampling::linear_scan::{linear_scan, LinearScanParams};
        use crate::surface::candidates::surface_candidates;
        use crate::surface::MeshSurface;

        struct One;
        impl SizingField for One {
            fn width(&self, _: DVec3) -> f64 {
                1.0
            }
        }
        let mesh = test_meshes::uv_sphere(10.0, 24, 48);
        let surface = MeshSurface::new(&mesh).unwrap();
        let kernel = Kernel::new(2.0, 0.9).unwrap();
        let pool = surface_candidates(&mesh, 3000, 4);
        let (initial, pool) = pool.split_at(20);
        let params = LinearScanParams::default();
        let scan =
            |field: &dyn SizingField| linear_scan(&kernel, pool, None, initial, field, &params);
        let (uniform, one, half) = (scan(&Uniform), scan(&One), scan(&Half));
        assert_eq!(uniform.samples, one.samples);
        assert_ne!(uniform.samples.len(), half.samples.len());
        let ascend = |field: &dyn SizingField| {
            let mut samples = uniform.samples.clone();
            let p = GradientAscentParams::default();
            gradient_ascent(&kernel, &surface, &mut samples, 20, field, None, &p, 7);
            samples
        };
        let moved = ascend(&Uniform);
        assert_ne!(moved, uniform.samples);
        assert_eq!(moved, ascend(&One));
        assert_ne!(moved, ascend(&Half));
    }
}
