//! The grading beside creases that run closer together than their samples may come (issue 59).
//! Two feature curves closer than [`CURVE_SAMPLE_GAP`] spacings would crowd each other's
//! samples, and [`feature_pieces`](crate::sampling::features::feature_pieces) leaves the
//! shorter out: a hex nut's chamfer arc where it dips towards the chamfer's circle, fandisk's
//! faceted fillet (three creases 0.7 gaps apart along their whole length). Here the spacing is
//! lowered where that happens, to the width at which the two curves' samples keep the gap (down
//! to [`SEPARATION_MIN_WIDTH`]), and graded back to the spacing around it (the spacing's
//! Lipschitz constant, [`GradedPoints`]), so both curves are sampled and the sheet between them
//! gets samples as close as theirs.
//!
//! Curves that share a corner are not each other's neighbours here: near the corner they come as
//! close as the angle between them makes them, which the corner grading
//! ([`Corners`](crate::sampling::features::Corners)) answers.

use glam::DVec3;

use crate::geometry::segment::points_along;
use crate::mesh::TriMesh;
use crate::sampling::features::CURVE_SAMPLE_GAP;
use crate::sampling::sizing::{GradedPoints, SizingField};
use crate::spatial::StaticTree;
use crate::surface::features::Features;

/// The smallest relative width the separation grading gives (as the corner grading's
/// `CORNER_MIN_WIDTH`): creases closer than half the gap stay crowded, and the shorter is
/// sampled as a ladder beside the other ([`crease_ladder`](crate::sampling::crease_ladder)).
pub const SEPARATION_MIN_WIDTH: f64 = 0.5;

/// Points along each curve per spacing, where the separation is measured.
const POINTS_PER_SPACING: f64 = 4.0;

/// The widths the creases' separation asks for, at points along the creases where it is below
/// 1 (bbox-100 units), graded around them ([`GradedPoints`]).
pub struct CreaseSeparation(GradedPoints);

impl CreaseSeparation {
    /// The grading for `features`' curves on `mesh` sampled at `spacing` (bbox-100 units), for
    /// the curves marked in `crowded` (those the even sampling left out for crowding): at a point
    /// of such a curve whose nearest point on another curve (one sharing no corner with it) is
    /// `d` away, and at that nearest point, the width `d / (CURVE_SAMPLE_GAP · spacing)`,
    /// slightly less (so samples of the two at that width keep the gap), at least
    /// [`SEPARATION_MIN_WIDTH`]. Curves that were kept are graded only beside a crowded one: a
    /// gear's tooth flanks, closer than the gap but sampled without crowding, keep the spacing.
    /// Uniform when nothing is crowded. Deterministic.
    pub fn new(mesh: &TriMesh, features: &Features, crowded: &[bool], spacing: f64) -> Self {
        if !crowded.contains(&true) {
            return CreaseSeparation(GradedPoints::new(&[], Vec::new(), spacing));
        }
        let step = spacing / POINTS_PER_SPACING;
        let mut points: Vec<DVec3> = Vec::new();
        let mut owner: Vec<u32> = Vec::new();
        for (i, c) in features.curves.iter().enumerate() {
            // Each edge's points after its first vertex (the one before it has that), and a
            // closed curve's without its last (its first).
            let nv = c.vertices.len();
            let pos = |k: usize| mesh.positions[c.vertices[k % nv] as usize];
            for k in 0..c.faces.len() {
                points.extend(points_along(pos(k), pos(k + 1), step).skip(usize::from(k > 0)));
            }
            if c.closed {
                points.pop();
            }
            owner.resize(points.len(), i as u32);
        }
        let ends = |i: u32| {
            let c = &features.curves[i as usize];
            (!c.closed).then(|| [c.vertices[0], c.vertices[c.vertices.len() - 1]])
        };
        let share_a_corner = |i: u32, j: u32| match (ends(i), ends(j)) {
            (Some(a), Some(b)) => a.iter().any(|v| b.contains(v)),
            _ => false,
        };
        let gap = CURVE_SAMPLE_GAP * spacing;
        let all = StaticTree::new(&points);
        let mut near = Vec::new();
        let mut kept_points = Vec::new();
        let mut widths = Vec::new();
        // Per point of a crowded curve, its nearest point on another curve within the gap.
        let nearest: Vec<Option<(u32, f64)>> = points
            .iter()
            .enumerate()
            .map(|(k, &p)| {
                if !crowded.get(owner[k] as usize).copied().unwrap_or(false) {
                    return None;
                }
                all.within(p, gap * gap, &mut near);
                near.iter()
                    .filter(|&&(j, _)| {
                        let (a, b) = (owner[k], owner[j as usize]);
                        a != b && !share_a_corner(a, b)
                    })
                    .map(|&(j, d2)| (j, d2.sqrt()))
                    .min_by(|x, y| x.1.total_cmp(&y.1))
            })
            .collect();
        for (k, n) in nearest.iter().enumerate() {
            let Some((j, d)) = *n else {
                continue;
            };
            // A step's worth less: the curves' samples fall anywhere along them.
            let w = ((d - step).max(0.0) / gap).max(SEPARATION_MIN_WIDTH);
            if w < 1.0 {
                kept_points.extend([points[k], points[j as usize]]);
                widths.extend([w, w]);
            }
        }
        CreaseSeparation(GradedPoints::new(&kept_points, widths, spacing))
    }
}

impl SizingField for CreaseSeparation {
    fn width(&self, p: DVec3) -> f64 {
        self.0.width(p)
    }

    fn is_uniform(&self) -> bool {
        self.0.is_uniform()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::features::FeatureCurve;

    /// Two open curves from x = 0 to 10: a straight one on the x axis and one at y = 2 that dips
    /// to y = `d` at x = 5 (from x = 4 to 6) when `dip`, else runs at y = `d` all along.
    fn two_curves(d: f64, dip: bool) -> (TriMesh, Features) {
        let mut positions = vec![DVec3::new(0.0, 0.0, 0.0), DVec3::new(10.0, 0.0, 0.0)];
        let far = if dip { 2.0 } else { d };
        positions.extend([
            DVec3::new(0.0, far, 0.0),
            DVec3::new(4.0, far, 0.0),
            DVec3::new(5.0, d, 0.0),
            DVec3::new(6.0, far, 0.0),
            DVec3::new(10.0, far, 0.0),
        ]);
        let curve = FeatureCurve::open;
        let features = Features {
            edges: vec![[0, 1], [2, 3], [3, 4], [4, 5], [5, 6]],
            curves: vec![curve(vec![0, 1]), curve(vec![2, 3, 4, 5, 6])],
            corners: vec![0, 1, 2, 6],
        };
        (TriMesh::new(positions, vec![]), features)
    }

    #[test]
    fn a_crease_dipping_towards_another_gets_the_width_that_keeps_the_gap_there() {
        let spacing = 1.0;
        let gap = CURVE_SAMPLE_GAP * spacing;
        let (mesh, features) = two_curves(0.7 * gap, true);
        // Nothing crowded: no grading.
        assert!(CreaseSeparation::new(&mesh, &features, &[false, false], spacing).is_uniform());
        let s = CreaseSeparation::new(&mesh, &features, &[false, true], spacing);
        assert!(!s.is_uniform());
        let w = s.width(DVec3::new(5.0, 0.0, 0.0));
        // The two curves' samples at w · spacing keep w · gap between them.
        assert!(w * gap <= 0.7 * gap && w >= SEPARATION_MIN_WIDTH, "{w}");
        // Graded back to 1 a few spacings away, and between.
        assert_eq!(s.width(DVec3::new(5.0, 10.0, 0.0)), 1.0);
        assert_eq!(s.width(DVec3::new(0.0, -5.0, 0.0)), 1.0);
        let between = s.width(DVec3::new(5.0, 1.0, 0.0));
        assert!(between > w && between <= 1.0, "{between}");
        // Curves farther apart than the gap: none.
        let (mesh, features) = two_curves(1.2 * gap, true);
        assert!(CreaseSeparation::new(&mesh, &features, &[true, true], spacing).is_uniform());
    }

    #[test]
    fn a_strip_between_two_parallel_creases_is_graded_along_its_length() {
        // fandisk's faceted fillet: creases 0.7 gaps apart along their whole length.
        let spacing = 1.0;
        let gap = CURVE_SAMPLE_GAP * spacing;
        let (mesh, features) = two_curves(0.7 * gap, false);
        let s = CreaseSeparation::new(&mesh, &features, &[false, true], spacing);
        for x in [0.5, 3.0, 5.0, 7.0, 9.5] {
            let w = s.width(DVec3::new(x, 0.0, 0.0));
            assert!(
                w * gap <= 0.7 * gap && w >= SEPARATION_MIN_WIDTH,
                "{x}: {w}"
            );
        }
    }

    #[test]
    fn curves_sharing_a_corner_do_not_grade_each_other() {
        // Two curves leaving the corner 0 at 30°: close near it, but that is the corner's.
        let positions = vec![
            DVec3::ZERO,
            DVec3::new(10.0, 0.0, 0.0),
            DVec3::new(
                10.0 * 30f64.to_radians().cos(),
                10.0 * 30f64.to_radians().sin(),
                0.0,
            ),
        ];
        let line = |a: u32, b: u32| FeatureCurve::open(vec![a, b]);
        let features = Features {
            edges: vec![[0, 1], [0, 2]],
            curves: vec![line(0, 1), line(0, 2)],
            corners: vec![0, 1, 2],
        };
        let s = CreaseSeparation::new(
            &TriMesh::new(positions, vec![]),
            &features,
            &[true, true],
            1.0,
        );
        assert!(s.is_uniform());
    }
}
