//! The sizing field from the local feature size (issue 75): the spacing
//! h(x) = clamp(ε · lfs(x), h_floor, sigma_p) in absolute units (bbox-100), so that a part
//! thinner than the sampling (a tube, a plate, two sheets close together, a hole or a gap
//! between two boundary loops) gets the samples its own size needs, whatever the count asked;
//! sigma_p, searched for the count, sets the spacing only where the field does not bound it.
//!
//! The local feature size comes from [`crate::surface::local_feature_size`] (shrinking balls:
//! the balls that reach across to another sheet, Amenta & Bern 1999's distance to the medial
//! axis where it is a thickness, a gap or a hole's radius; the curvature radius of one sheet and
//! the creases are the crease and curvature terms' to follow), median-filtered and smoothed to
//! its Lipschitz envelope, so the spacing changes gradually. The floor h_floor is
//! [`GradingParams::h_min`], raised when the count the field asks for would pass
//! [`GradingParams::max_growth`] times the one asked ([`Grading::bound_growth`]): the parts
//! below the floor are unresolved, and [`Grading::resolving_count`] says how many samples would
//! resolve them.

use glam::DVec3;

use crate::disjoint_sets::Dsu;
use crate::error::Result;
use crate::mesh::{Normalization, TriMesh};
use crate::sampling::boundary::BoundaryCurve;
use crate::sampling::sizing::SizingField;
use crate::sampling::spacing::SAMPLES_PER_SIGMA2;
use crate::spatial::StaticTree;
use crate::surface::local_feature_size::{local_feature_size, LfsParams, LocalFeatureSize};

/// Parameters of the sizing field from the local feature size: the spacing
/// h(x) = clamp(ε · lfs(x), h_floor, sigma_p), h_floor the larger of `h_min` and the spacing the
/// growth bound allows, with neighbouring spacings within the Lipschitz factor `gradation`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GradingParams {
    /// ε in h(x) = ε · lfs(x) (default 2.5: two sides of a wall of thickness 2 lfs meet in one
    /// restricted Voronoi cell when the samples' covering radius on a side, about mean edge /
    /// √3 with the mean edge about 1.2 h, exceeds it, so the topological ball property needs
    /// h ≲ 2.8 lfs; `docs/decisions/sizing-field.md`).
    pub lfs_factor: f64,
    /// The smallest spacing, absolute (bbox-100 units; default 0.05, a 2000th of the bounding
    /// box): a part thinner than h_min / ε is held at it and reported unresolved.
    pub h_min: f64,
    /// The Lipschitz constant L of the spacing: h(x) ≤ h(y) + L |x − y| (default 0.75; gentler
    /// gradations, 0.4 and 0.25, measured no better Qave on horse, bunny and spot).
    pub gradation: f64,
    /// The most the field may raise the count above the one asked (default 4: at most 4 N
    /// samples for `--points N`); where the field asks for more, its floor is raised until the
    /// expected count fits, and the parts below it are reported unresolved.
    pub max_growth: f64,
    /// The most sigma_p may grow over the paper's sigma_p for the count (the one of a uniform
    /// sampling) while the search holds `--points N` with the field's samples in it (default
    /// √2: the surface the field does not bound keeps at least half the paper's density; past
    /// it, the count grows instead).
    pub max_coarsening: f64,
}

impl Default for GradingParams {
    fn default() -> Self {
        GradingParams {
            lfs_factor: 2.5,
            h_min: 0.05,
            gradation: 0.75,
            max_growth: 4.0,
            max_coarsening: std::f64::consts::SQRT_2,
        }
    }
}

/// What the grading of the kernel width by the local feature size did ([`GradingParams`]).
#[derive(Debug, Clone, PartialEq)]
pub struct GradingStats {
    /// Output samples whose width is below 1 (a finer spacing than sigma_p).
    pub graded_samples: usize,
    /// The smallest width of an output sample (relative to sigma_p).
    pub min_width: f64,
    /// The field's smallest spacing (model units; [`Grading::floor`]).
    pub floor: f64,
    /// Output samples held at the smallest width although the local feature size asks for a
    /// finer one: parts too thin for the asked count.
    pub unresolved_samples: usize,
    /// When some samples are unresolved: about how many samples would resolve every thin part
    /// ([`Grading::resolving_count`]).
    pub resolving_count: Option<f64>,
    /// Where the graded samples are: the bounding boxes (model units) of the groups of graded
    /// samples within 2 sigma_p of each other, largest first, with their sample counts and
    /// whether they hold unresolved samples.
    pub regions: Vec<GradedRegion>,
}

/// A group of graded samples ([`GradingStats::regions`]).
#[derive(Debug, Clone, PartialEq)]
pub struct GradedRegion {
    /// Bounding box corners, model units.
    pub min: DVec3,
    /// Bounding box corners, model units.
    pub max: DVec3,
    /// Samples in the group.
    pub samples: usize,
    /// Of those, samples held at the smallest width (unresolved).
    pub unresolved: usize,
}

/// A local feature size field ready to grade the kernel width.
pub struct Grading {
    lfs: LocalFeatureSize,
    /// The smoothed thickness at the estimate points (the field the width follows).
    thickness: Vec<f64>,
    params: GradingParams,
    /// Estimates at or above this radius (bbox-100 units) mean "no feature nearer": width 1.
    cap: f64,
    /// The smallest of `thickness` and of the boundary gaps.
    min_thickness: f64,
    /// The smallest spacing (bbox-100 units): [`GradingParams::h_min`], or the larger floor
    /// [`Grading::bound_growth`] set.
    floor: f64,
    /// One kd-tree per boundary loop over its vertices (at most [`MAX_GAP_LOOPS`] loops), for
    /// the gap between loops ([`Grading::boundary_gap`]).
    loops: Vec<StaticTree>,
    /// The vertices of all of `loops` in one kd-tree (`None` without `loops`): a point farther
    /// than d from all of them has a gap of at least d.
    loop_vertices: Option<StaticTree>,
}

/// How far (in estimate spacings, [`LocalFeatureSize::spacing`]) the thickness of an estimate
/// point reaches: a point with no estimate point within this distance has no thickness (the
/// area-uniform estimate points leave a hole that wide with probability about e^(−π · 64)).
/// The bound lets [`Thickness`] find the ungraded points by a search among the graded
/// estimate points alone.
pub const ESTIMATE_REACH: f64 = 8.0;

/// The most boundary loops whose gaps the grading follows (each point queries every loop).
pub const MAX_GAP_LOOPS: usize = 64;

impl Grading {
    /// Estimates the local feature size of `mesh` (bbox-100 units) up to `cap` (a part thicker
    /// than `cap` is not graded: pass a few times the largest sigma_p / c the sampling may use),
    /// with estimate points every `spacing`.
    ///
    /// # Errors
    /// Those of [`local_feature_size`] (an unusable mesh, a bad spacing).
    ///
    /// With `curves` (the input's boundary curves), the thickness also follows the gap between
    /// two boundary loops (a strip of surface between two holes is thin too; see
    /// [`Grading::boundary_gap`]), for inputs with at most [`MAX_GAP_LOOPS`] loops.
    pub fn new(
        mesh: &TriMesh,
        curves: &[BoundaryCurve],
        params: GradingParams,
        cap: f64,
        spacing: f64,
    ) -> Result<Self> {
        let lfs = local_feature_size(
            mesh,
            &LfsParams {
                spacing,
                max_radius: cap,
                at_vertices: false,
                ..LfsParams::default()
            },
        )?;
        let values = lfs.thickness.clone();
        // The spacing c · lfs grows by at most `gradation` per unit of distance.
        let slope = (params.gradation / params.lfs_factor).min(1.0);
        let filtered = median_filtered(&lfs, &values, MEDIAN_NEIGHBORS);
        let thickness = lfs.envelope_with_slope(&filtered, cap, slope);
        let loop_points: Vec<Vec<DVec3>> = if curves.len() >= 2 && curves.len() <= MAX_GAP_LOOPS {
            curves
                .iter()
                .map(|c| {
                    c.vertices
                        .iter()
                        .map(|&v| mesh.positions[v as usize])
                        .collect()
                })
                .collect()
        } else {
            Vec::new()
        };
        let loops: Vec<StaticTree> = loop_points.iter().map(|p| StaticTree::new(p)).collect();
        let loop_vertices = (!loops.is_empty()).then(|| StaticTree::new(&loop_points.concat()));
        let mut grading = Grading {
            lfs,
            min_thickness: f64::INFINITY,
            floor: params.h_min,
            thickness,
            params,
            cap,
            loops,
            loop_vertices,
        };
        let boundary_min = curves
            .iter()
            .flat_map(|c| c.vertices.iter())
            .map(|&v| grading.boundary_gap(mesh.positions[v as usize]))
            .fold(f64::INFINITY, f64::min);
        grading.min_thickness = grading
            .thickness
            .iter()
            .copied()
            .fold(boundary_min, f64::min);
        Ok(grading)
    }

    /// The thickness at `x` (bbox-100 units; [`LocalFeatureSize::thickness`], smoothed to its
    /// 1-Lipschitz envelope) at the nearest estimate point within [`ESTIMATE_REACH`]
    /// spacings: the local feature size where a medial ball reaches across to another sheet;
    /// `f64::INFINITY` at or beyond the cap.
    ///
    /// The smaller of that and [`Grading::boundary_gap`].
    pub fn lfs(&self, x: DVec3) -> f64 {
        let l = self.thickness_at(x).min(self.boundary_gap(x));
        if l >= self.cap {
            f64::INFINITY
        } else {
            l
        }
    }

    /// The thickness of the nearest estimate point within [`ESTIMATE_REACH`] spacings of `x`
    /// (`f64::INFINITY` with none).
    fn thickness_at(&self, x: DVec3) -> f64 {
        let reach = ESTIMATE_REACH * self.lfs.spacing;
        self.lfs
            .tree()
            .nearest(x)
            .filter(|&(_, d2)| d2 <= reach * reach)
            .map_or(f64::INFINITY, |(j, _)| self.thickness[j as usize])
    }

    /// Half the width of the strip of surface between two boundary loops at `x` (bbox-100
    /// units): (d1 + d2) / 2, d1 and d2 the distances from `x` to its nearest and second-nearest
    /// boundary loops (1-Lipschitz; half the gap between the loops on a boundary point);
    /// `f64::INFINITY` with fewer than two loops followed.
    pub fn boundary_gap(&self, x: DVec3) -> f64 {
        if self.loops.len() < 2 {
            return f64::INFINITY;
        }
        let mut near = Vec::with_capacity(1);
        let (mut d1, mut d2) = (f64::INFINITY, f64::INFINITY);
        for tree in &self.loops {
            tree.nearest_n(x, 1, &mut near);
            if let Some(&(_, d)) = near.first() {
                let d = d.sqrt();
                if d < d1 {
                    d2 = d1;
                    d1 = d;
                } else if d < d2 {
                    d2 = d;
                }
            }
        }
        0.5 * (d1 + d2)
    }

    /// The spacing at `x` (bbox-100 units): ε · lfs(x), at least the floor;
    /// `f64::INFINITY` where no feature bounds it.
    pub fn spacing(&self, x: DVec3) -> f64 {
        let l = self.lfs(x);
        if !l.is_finite() {
            return f64::INFINITY;
        }
        (self.params.lfs_factor * l).max(self.floor)
    }

    /// The relative kernel width at `x` for the global `sigma_p`: `min(1, h(x) / sigma_p)`,
    /// h the absolute spacing ([`Grading::spacing`]).
    pub fn width(&self, x: DVec3, sigma_p: f64) -> f64 {
        (self.spacing(x) / sigma_p).min(1.0)
    }

    /// Whether some width is below 1 at a global `sigma_p` of `sigma_p` or less (some
    /// thickness t has max(ε · t, floor) < sigma_p).
    pub fn grades_below(&self, sigma_p: f64) -> bool {
        (self.params.lfs_factor * self.min_thickness).max(self.floor) < sigma_p
    }

    /// Whether the spacing at `x` is held at the floor although ε · lfs(x) asks for less: a
    /// part thinner than the field resolves ([`Grading::bound_growth`]), when the floor is
    /// below `sigma_p` (above it, the part is not graded at all).
    pub fn is_unresolved(&self, x: DVec3, sigma_p: f64) -> bool {
        let l = self.lfs(x);
        l.is_finite() && self.params.lfs_factor * l < self.floor && self.floor < sigma_p
    }

    /// The smallest spacing (bbox-100 units).
    pub fn floor(&self) -> f64 {
        self.floor
    }

    /// The expected sample count on a surface of area `area` (bbox-100 units) with the spacing
    /// min(sigma_p, max(ε · t, floor)): `SAMPLES_PER_SIGMA2` per sigma², summed over the
    /// estimate points (area-uniform, each standing for `area / points`; the boundary gaps are
    /// left out).
    pub fn expected_count(&self, area: f64, sigma_p: f64, floor: f64) -> f64 {
        let c = self.params.lfs_factor;
        let points = self.thickness.len().max(1) as f64;
        let per_point = area / points;
        self.thickness
            .iter()
            .map(|&t| {
                let h = if t < self.cap {
                    (c * t).max(floor).min(sigma_p)
                } else {
                    sigma_p
                };
                SAMPLES_PER_SIGMA2 * per_point / (h * h)
            })
            .sum()
    }

    /// Raises the floor so that the field asks for at most [`GradingParams::max_growth`] times
    /// `count` samples on a surface of area `area` at the global `sigma_p` (bbox-100 units):
    /// the smallest floor from [`GradingParams::h_min`] up that does (bisection in log space).
    pub fn bound_growth(&mut self, area: f64, sigma_p: f64, count: f64) {
        let most = self.params.max_growth.max(1.0) * count;
        let (mut lo, mut hi) = (self.params.h_min, sigma_p.max(self.params.h_min));
        if self.expected_count(area, sigma_p, lo) <= most {
            self.floor = lo;
            return;
        }
        for _ in 0..40 {
            let mid = (lo * hi).sqrt();
            if self.expected_count(area, sigma_p, mid) <= most {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        self.floor = hi;
    }

    /// The count at which every part of a surface of area `area` (bbox-100 units) is resolved
    /// at the global `sigma_p`: the expected count with the floor at the thinnest part's
    /// spacing ε · t_min (at least [`GradingParams::h_min`]). `None` without a graded part.
    pub fn resolving_count(&self, area: f64, sigma_p: f64) -> Option<f64> {
        if !(self.min_thickness.is_finite() && self.min_thickness > 0.0) {
            return None;
        }
        let floor = (self.params.lfs_factor * self.min_thickness).max(self.params.h_min);
        Some(self.expected_count(area, sigma_p, floor))
    }

    /// The grading's record over the output's vertices `positions` (bbox-100 units in, model
    /// units out) for the widths of `sigma_p`, on a surface of area `area`.
    pub fn stats(
        &self,
        positions: &[DVec3],
        sigma_p: f64,
        normalization: &Normalization,
        area: f64,
    ) -> GradingStats {
        let grading = self;
        let graded: Vec<(DVec3, bool)> = positions
            .iter()
            .filter(|&&p| grading.width(p, sigma_p) < 1.0)
            .map(|&p| (p, grading.is_unresolved(p, sigma_p)))
            .collect();
        let min_width = positions
            .iter()
            .map(|&p| grading.width(p, sigma_p))
            .fold(1.0, f64::min);
        // Groups: connected components of the graph "within 2 sigma_p" (union-find over a kd-tree).
        let points: Vec<DVec3> = graded.iter().map(|g| g.0).collect();
        let tree = StaticTree::new(&points);
        let mut sets = Dsu::new(points.len());
        let r = 2.0 * sigma_p;
        let mut found = Vec::new();
        for (i, &p) in points.iter().enumerate() {
            tree.within(p, r * r, &mut found);
            for &(j, _) in &found {
                sets.union(i, j as usize, false);
            }
        }
        let mut regions: Vec<GradedRegion> = Vec::new();
        let mut index = std::collections::HashMap::new();
        for (i, &(p, unresolved)) in graded.iter().enumerate() {
            let root = sets.find(i).0;
            let k = *index.entry(root).or_insert_with(|| {
                regions.push(GradedRegion {
                    min: DVec3::splat(f64::INFINITY),
                    max: DVec3::splat(f64::NEG_INFINITY),
                    samples: 0,
                    unresolved: 0,
                });
                regions.len() - 1
            });
            let q = normalization.invert(p);
            let g = &mut regions[k];
            g.min = g.min.min(q);
            g.max = g.max.max(q);
            g.samples += 1;
            g.unresolved += usize::from(unresolved);
        }
        regions.sort_by_key(|r| std::cmp::Reverse(r.samples));
        let unresolved_samples = graded.iter().filter(|g| g.1).count();
        GradingStats {
            graded_samples: graded.len(),
            min_width,
            floor: self.floor / normalization.scale,
            unresolved_samples,
            resolving_count: if unresolved_samples > 0 {
                grading.resolving_count(area, sigma_p)
            } else {
                None
            },
            regions,
        }
    }
}

/// Estimate points whose median thickness [`median_filtered`] takes (the point and its nearest
/// 15).
const MEDIAN_NEIGHBORS: usize = 16;

/// The thickness at each estimate point replaced by the median over it and its nearest
/// `k - 1`: a thin part is thin at all of its points and keeps its value, while the isolated
/// near-zero values where an input passes through itself (two sheets crossing: a medial ball
/// of radius 0) or folds in a scanning artifact are dropped; their Lipschitz envelope would
/// otherwise grade everything around them.
fn median_filtered(lfs: &LocalFeatureSize, of: &[f64], k: usize) -> Vec<f64> {
    use rayon::prelude::*;
    let tree = crate::spatial::StaticTree::new(&lfs.positions);
    lfs.positions
        .par_iter()
        .map_init(
            || (Vec::new(), Vec::new()),
            |(near, values): &mut (Vec<(u32, f64)>, Vec<f64>), &p| {
                tree.nearest_n(p, k, near);
                values.clear();
                values.extend(near.iter().map(|&(j, _)| of[j as usize]));
                values.sort_by(f64::total_cmp);
                values
                    .get(values.len() / 2)
                    .copied()
                    .unwrap_or(f64::INFINITY)
            },
        )
        .collect()
}

/// The sizing field's relative widths: `min(1, h(p) / sigma_ref)` ([`Grading::width`]) for the
/// global `sigma_ref` (bbox-100 units).
///
/// Its cost is where it grades: a point with no graded estimate point (c · thickness <
/// sigma_ref) within [`ESTIMATE_REACH`] spacings and no boundary vertex within sigma_ref / c is
/// found to be at width 1 by a search among the graded estimate points alone (few: the thin
/// parts), not among all of them.
pub struct Thickness<'a> {
    grading: &'a Grading,
    sigma_ref: f64,
    /// The estimate points graded at `sigma_ref`.
    graded: StaticTree,
    /// [`ESTIMATE_REACH`] spacings, squared.
    reach_2: f64,
}

impl<'a> Thickness<'a> {
    /// The field of `grading` for the global `sigma_ref` (bbox-100 units).
    pub fn new(grading: &'a Grading, sigma_ref: f64) -> Self {
        let c = grading.params.lfs_factor;
        let graded: Vec<DVec3> = grading
            .thickness
            .iter()
            .zip(&grading.lfs.positions)
            .filter(|&(&t, _)| (c * t).max(grading.floor) < sigma_ref && t < grading.cap)
            .map(|(_, &p)| p)
            .collect();
        let reach = ESTIMATE_REACH * grading.lfs.spacing;
        Thickness {
            grading,
            sigma_ref,
            graded: StaticTree::new(&graded),
            reach_2: reach * reach,
        }
    }

    /// Whether `p` is certainly at width 1 (see [`Thickness`]).
    fn surely_ungraded(&self, p: DVec3) -> bool {
        if self
            .graded
            .nearest(p)
            .is_some_and(|(_, d2)| d2 <= self.reach_2)
        {
            return false;
        }
        let Some(loops) = &self.grading.loop_vertices else {
            return true;
        };
        let d = self.sigma_ref / self.grading.params.lfs_factor;
        loops.nearest(p).is_none_or(|(_, d2)| d2 >= d * d)
    }
}

impl SizingField for Thickness<'_> {
    fn width(&self, p: DVec3) -> f64 {
        if self.surely_ungraded(p) {
            return 1.0;
        }
        self.grading.width(p, self.sigma_ref)
    }

    /// No part is thin enough to be graded at `sigma_ref`: the field is left out.
    fn is_uniform(&self) -> bool {
        !self.grading.grades_below(self.sigma_ref)
    }
}
