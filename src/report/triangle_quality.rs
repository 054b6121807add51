//! The triangle measures of the paper's Table 1 over a whole mesh: θmin, θmin,ave, Qmin, Qave,
//! %θ<30, and P30.

use serde::Serialize;

use crate::geometry::triangle::{is_degenerate_triangle, triangle_angles_deg, triangle_q};
use crate::mesh::TriMesh;

/// The triangle measures of Table 1 of the paper (Öztireli et al. 2010, Sec. 7.1), plus P30.
/// Angles in degrees, Q dimensionless, percentages in percent (0–100).
///
/// Definitions (over the measured faces, see `faces_measured`):
/// - `theta_min` (θmin): the smallest angle of the mesh, min over triangles of the triangle's
///   smallest angle.
/// - `theta_min_ave` (θmin,ave): the mean over triangles of each triangle's smallest angle.
/// - `theta_max` (θmax): the largest angle of the mesh (180° for a degenerate triangle).
/// - `q_min`, `q_ave` (Qmin, Qave): min and mean over triangles of [`triangle_q`].
/// - `pct_theta_below_30` (%θ<30): percent of *triangles* whose smallest angle is below 30°
///   (strictly, no tolerance) — the Table 1 column "θ < 30°".
/// - `p30` (P30): percent of all *angles* (three per triangle) below 30° (strictly) — the
///   convention of the tables of Yan et al. 2009 and ACVD (Valette et al. 2008).
///
/// Angles come from [`triangle_angles_deg`]. A degenerate triangle ([`is_degenerate_triangle`],
/// including a repeated vertex index) is measured, not skipped: its smallest angle is 0° and its
/// Q is 0, so it sets θmin = 0 and Qmin = 0; its three angles enter P30 as computed (0° at a
/// corner with a zero-length edge, so it contributes 2 or 3 angles below 30°).
///
/// An empty mesh gives all zeros (no NaN) and `faces_measured = 0`: the `Default`.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct TriangleQuality {
    /// θmin: the smallest angle of the mesh, in degrees.
    pub theta_min: f64,
    /// θmin,ave: the mean over triangles of the smallest angle of each triangle, in degrees.
    pub theta_min_ave: f64,
    /// θmax: the largest angle of the mesh, in degrees.
    pub theta_max: f64,
    /// Qmin: the smallest triangle quality `6S/(√3 p h)`.
    pub q_min: f64,
    /// Qave: the mean triangle quality.
    pub q_ave: f64,
    /// %θ<30: percent of triangles whose smallest angle is below 30°.
    pub pct_theta_below_30: f64,
    /// P30: percent of all angles (3 per triangle) below 30°.
    pub p30: f64,
    /// The number of triangles measured: all faces except those with a vertex index out of range
    /// or a corner with a non-finite coordinate (those have no geometry to measure;
    /// [`check_invariants`](crate::check_invariants) reports them).
    pub faces_measured: usize,
}

/// The Table 1 measures of `mesh` (see [`TriangleQuality`] for the definitions). Units are the
/// mesh's own; the measures are scale-free. Runs in O(F), sequentially (deterministic sums).
///
/// Source: Öztireli et al. 2010, Sec. 7.1 and Table 1; P30 after Yan et al. 2009.
pub fn triangle_quality(mesh: &TriMesh) -> TriangleQuality {
    let n = mesh.positions.len();
    let mut measured = 0usize;
    let mut theta_min = f64::INFINITY;
    let mut theta_sum = 0.0;
    let mut theta_max = 0.0f64;
    let mut q_min = f64::INFINITY;
    let mut q_sum = 0.0;
    let mut triangles_below = 0usize;
    let mut angles_below = 0usize;
    for t in &mesh.triangles {
        if t.iter().any(|&i| i as usize >= n) {
            continue;
        }
        let p = t.map(|i| mesh.positions[i as usize]);
        if !p.iter().all(|c| c.is_finite()) {
            continue;
        }
        measured += 1;
        let angles = triangle_angles_deg(p);
        angles_below += angles.iter().filter(|&&a| a < 30.0).count();
        let repeated = t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
        let (tmin, tmax, q) = if repeated || is_degenerate_triangle(p) {
            (0.0, 180.0, 0.0)
        } else {
            (
                angles[0].min(angles[1]).min(angles[2]),
                angles[0].max(angles[1]).max(angles[2]),
                triangle_q(p),
            )
        };
        theta_max = theta_max.max(tmax);
        theta_min = theta_min.min(tmin);
        theta_sum += tmin;
        q_min = q_min.min(q);
        q_sum += q;
        if tmin < 30.0 {
            triangles_below += 1;
        }
    }
    if measured == 0 {
        return TriangleQuality::default();
    }
    let m = measured as f64;
    TriangleQuality {
        theta_min,
        theta_min_ave: theta_sum / m,
        theta_max,
        q_min,
        q_ave: q_sum / m,
        pct_theta_below_30: 100.0 * triangles_below as f64 / m,
        p30: 100.0 * angles_below as f64 / (3.0 * m),
        faces_measured: measured,
    }
}
