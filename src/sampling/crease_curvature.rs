//! The grading along curved creases (issue 59): the creases' samples are joined by chords, and a
//! chord of length s on a crease of radius R stands s² / (8 R) off it. At the creases' spacing a
//! hole's rim or a chamfer's arc is cut by more than a tenth of a spacing; here the spacing is
//! lowered where a crease's own curvature asks, so the chord's sag stays within [`CREASE_SAG`]
//! of the spacing (down to [`CURVATURE_MIN_WIDTH`]), graded back around it ([`GradedPoints`]).

use crate::mesh::TriMesh;
use crate::sampling::sizing::GradedPoints;
use crate::surface::features::Features;

/// The most a chord between two crease samples may stand off a curved crease, in units of the
/// creases' spacing (1.15 sigma_p): 0.06, about 0.07 output edges, so that a chord up to a fifth
/// longer than the width asks (the steps along a crease are whole numbers) stays within issue
/// 59's tenth of an output edge. At 0.04 the rims took so many samples from the curved sheets
/// at a given count that the flange's Hausdorff went from 0.28 to 0.5 at 3000; at 0.075 the
/// chamfered block's worst seed went to 0.46 (0.35 at 0.06). `eval/features`.
pub const CREASE_SAG: f64 = 0.06;

/// The smallest relative width the grading gives (as the corner and separation gradings'): a
/// crease tighter than that (a hole of radius under 0.8 spacings) keeps chords of half the
/// spacing.
pub const CURVATURE_MIN_WIDTH: f64 = 0.5;

/// The grading for the curvature of `features`' curves on `mesh` sampled at `spacing` (bbox-100
/// units): at each vertex inside a curve, where the curve turns by θ over half its two edges'
/// length a (curvature κ = θ / a), the width sqrt(8 · [`CREASE_SAG`] / (κ · spacing)) when below
/// 1, at least [`CURVATURE_MIN_WIDTH`]. Uniform on straight creases. Deterministic.
pub fn crease_curvature(mesh: &TriMesh, features: &Features, spacing: f64) -> GradedPoints {
    let mut points = Vec::new();
    let mut widths = Vec::new();
    for c in &features.curves {
        let nv = c.vertices.len();
        let pos = |k: usize| mesh.positions[c.vertices[k % nv] as usize];
        // Every vertex of a closed curve; an open one's between its ends.
        let inner = if c.closed {
            0..nv
        } else {
            1..nv.saturating_sub(1)
        };
        for k in inner {
            let (a, b, d) = (pos(k + nv - 1), pos(k), pos(k + 1));
            let (u, v) = (b - a, d - b);
            let arc = 0.5 * (u.length() + v.length());
            if !(arc > 0.0) {
                continue;
            }
            let kappa = u.angle_between(v) / arc;
            if !(kappa > 0.0) {
                continue;
            }
            let w = (8.0 * CREASE_SAG / (kappa * spacing)).sqrt();
            if w < 1.0 {
                points.push(b);
                widths.push(w.max(CURVATURE_MIN_WIDTH));
            }
        }
    }
    GradedPoints::new(&points, widths, spacing)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::sizing::SizingField;
    use crate::surface::features::FeatureCurve;
    use glam::DVec3;

    /// A closed crease: a circle of radius `r` in the plane z = 0 with `n` vertices.
    fn circle(r: f64, n: usize) -> (TriMesh, Features) {
        let positions: Vec<DVec3> = (0..n)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / n as f64;
                DVec3::new(r * t.cos(), r * t.sin(), 0.0)
            })
            .collect();
        let curve = FeatureCurve {
            vertices: (0..n as u32).collect(),
            faces: vec![0; n],
            closed: true,
        };
        let edges = (0..n as u32)
            .map(|k| {
                let j = (k + 1) % n as u32;
                [k.min(j), k.max(j)]
            })
            .collect();
        let features = Features {
            edges,
            curves: vec![curve],
            corners: vec![],
        };
        (TriMesh::new(positions, vec![]), features)
    }

    #[test]
    fn a_tight_circle_gets_chords_within_the_sag_and_a_wide_one_none() {
        let spacing = 1.0;
        // Radius 4: chords of a whole spacing would stand 1/32 = 0.031 off: no grading.
        let (mesh, features) = circle(4.0, 96);
        assert!(crease_curvature(&mesh, &features, spacing).is_uniform());
        // Radius 1.5: 1/12 = 0.083 > 0.06: chords of w spacing with w² / 12 <= 0.06.
        let (mesh, features) = circle(1.5, 96);
        let g = crease_curvature(&mesh, &features, spacing);
        let w = g.width(DVec3::new(1.5, 0.0, 0.0));
        let sag = (w * spacing).powi(2) / (8.0 * 1.5);
        assert!(
            sag <= CREASE_SAG * spacing * 1.01 && w > 0.8 && w < 0.9,
            "w {w}, sag {sag}"
        );
        // Far from the rim, graded back to 1.
        assert_eq!(g.width(DVec3::new(20.0, 0.0, 0.0)), 1.0);
    }
}
