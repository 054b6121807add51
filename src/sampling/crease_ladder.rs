//! Creases sampled as the rungs of a ladder beside a crease they run too close to (issue 59): a
//! thin fin's two rims meeting at its 1° tip, the two rims of a slot thinner than the spacing.
//!
//! Two creases closer than [`CURVE_SAMPLE_GAP`](crate::sampling::features::CURVE_SAMPLE_GAP)
//! spacings crowd each other's samples. Where the spacing can be lowered until they do not (the
//! separation grading, [`crease_separation`](crate::sampling::crease_separation), down to half
//! the spacing) both keep even samples; closer than that, or where they leave a corner at an angle
//! too small to grade towards, [`feature_pieces`](crate::sampling::features::feature_pieces)
//! left the shorter out, and the output's edges ran along the other one, up to their distance
//! away from it (the fin's rims: a third of an edge). Here the shorter one is kept, with its
//! samples where the samples of the creases beside it project onto it: each sample there has its
//! partner across the narrow face (or the thin solid) between them, so the triangles across a
//! narrow face are the quads between two rungs cut in two (their angles as small as the face's
//! own), and a surface point beside one crease is nearest that crease's own sample, not the
//! other's.

use glam::DVec3;

use crate::mesh::TriMesh;
use crate::sampling::curves::{edge_lengths, points_along, BoundaryCurve};

/// The least step between two of a ladder's samples, in units of the local spacing: stations
/// closer than this (two creases beside it sampled at steps that do not match) are merged into
/// the first.
pub const MIN_LADDER_STEP: f64 = 0.5;

/// The least distance between a sample beside the curve and the curve, in units of the local
/// spacing, for the sample to take a partner on the curve: closer, the partner would be the
/// sample's twin (a fuzzed input's sliver faces, whose long edges are far closer, gave two
/// faces on the same corners); the edges along the crease beside it follow the curve within
/// that anyway. A 1° fin's samples a step from its tip are 0.012 spacings from their partners.
pub const MIN_LADDER_WIDTH: f64 = 0.005;

/// The arc lengths (from the curve's start, units of the mesh) of the samples of `curve` as a
/// ladder: its ends; the nearest point on it of each point of `beside` (the samples of the kept
/// creases near it) within `reach(q)` of it and at least [`MIN_LADDER_WIDTH`] local steps
/// away; and of its own even samples `own` (arc lengths, each
/// with whether it is clear of those creases' samples) the clear ones farther than half the local
/// step `step(x)` (at the point x of the arc) from every station. Sorted, then thinned so that
/// consecutive arcs are at least [`MIN_LADDER_STEP`] local steps apart (the ends kept). A closed
/// curve's arcs start at 0 (its first vertex) and stop short of its length (that vertex again),
/// thinned across that point too. `None` when no point of `beside` is within reach (nothing to
/// pair with). Deterministic.
pub fn ladder_arcs(
    mesh: &TriMesh,
    curve: &BoundaryCurve,
    beside: &[DVec3],
    reach: impl Fn(DVec3) -> f64,
    own: &[(f64, bool)],
    step: impl Fn(DVec3) -> f64,
) -> Option<Vec<f64>> {
    let lengths = edge_lengths(mesh, curve);
    let total: f64 = lengths.iter().sum();
    if !(total > 0.0) {
        return None;
    }
    let nv = curve.vertices.len();
    let pos = |k: usize| mesh.positions[curve.vertices[k % nv] as usize];
    // Each point's nearest point on the curve, as (distance, arc).
    let nearest = |q: DVec3| -> (f64, f64) {
        let mut best = (f64::INFINITY, 0.0);
        let mut start = 0.0;
        for (k, &l) in lengths.iter().enumerate() {
            let (a, b) = (pos(k), pos(k + 1));
            let t = if l > 0.0 {
                ((q - a).dot(b - a) / (l * l)).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let d = q.distance(a.lerp(b, t));
            if d < best.0 {
                best = (d, start + t * l);
            }
            start += l;
        }
        best
    };
    let stations: Vec<f64> = beside
        .iter()
        .filter_map(|&q| {
            let (d, arc) = nearest(q);
            (d < reach(q) && d >= MIN_LADDER_WIDTH * step(q)).then_some(arc)
        })
        .collect();
    if stations.is_empty() {
        return None;
    }
    // The local step at an arc (at the curve's point there).
    let step = |arc: f64| step(points_along(mesh, curve, &lengths, [arc])[0].0);
    let mut arcs = vec![0.0, total];
    arcs.extend(stations.iter().copied().filter(|&a| a > 0.0 && a < total));
    arcs.extend(own.iter().filter_map(|&(a, clear)| {
        let free = clear && stations.iter().all(|&s| (s - a).abs() > 0.5 * step(a));
        (free && a > 0.0 && a < total).then_some(a)
    }));
    arcs.sort_by(f64::total_cmp);
    let mut out = vec![0.0];
    for &a in &arcs[1..arcs.len() - 1] {
        let prev = *out.last().unwrap_or(&0.0);
        let next = if curve.closed {
            f64::INFINITY
        } else {
            total - a
        };
        if a - prev >= MIN_LADDER_STEP * step(a) && next >= MIN_LADDER_STEP * step(a) {
            out.push(a);
        }
    }
    if curve.closed {
        // The first sample is the last one's next: the step across it is kept too.
        while out.len() > 1 && total - out[out.len() - 1] < MIN_LADDER_STEP * step(0.0) {
            out.pop();
        }
    } else {
        out.push(total);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A straight open curve along x from 0 to `length` in `n` edges.
    fn line(length: f64, n: usize) -> (TriMesh, BoundaryCurve) {
        let positions: Vec<DVec3> = (0..=n)
            .map(|k| DVec3::new(length * k as f64 / n as f64, 0.0, 0.0))
            .collect();
        let mesh = TriMesh {
            positions,
            triangles: vec![[0, 1, 2]],
        };
        let curve = BoundaryCurve {
            vertices: (0..=n as u32).collect(),
            faces: vec![0; n],
            closed: false,
        };
        (mesh, curve)
    }

    #[test]
    fn the_stations_are_where_the_samples_beside_project_and_too_close_ones_merge() {
        let (mesh, curve) = line(10.0, 5);
        // Samples of a crease 0.3 above, every 2 units, one 0.1 after another, one out of reach.
        let beside: Vec<DVec3> = [2.0, 4.0, 4.1, 6.0, 8.0]
            .iter()
            .map(|&x| DVec3::new(x, 0.3, 0.0))
            .chain([DVec3::new(5.0, 3.0, 0.0)])
            .collect();
        let arcs = ladder_arcs(&mesh, &curve, &beside, |_| 1.0, &[], |_| 2.0).unwrap();
        assert_eq!(arcs, vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0]);
        // Nothing within reach: no ladder.
        assert!(ladder_arcs(&mesh, &curve, &beside, |_| 0.2, &[], |_| 2.0).is_none());
    }

    #[test]
    fn a_closed_ladder_stops_short_of_its_first_vertex_and_keeps_the_step_across_it() {
        // A square loop of side 4 (length 16), a crease beside it 0.3 outside every 1.
        let corners = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(4.0, 0.0, 0.0),
            DVec3::new(4.0, 4.0, 0.0),
            DVec3::new(0.0, 4.0, 0.0),
        ];
        let mesh = TriMesh {
            positions: corners.to_vec(),
            triangles: vec![[0, 1, 2]],
        };
        let curve = BoundaryCurve {
            vertices: vec![0, 1, 2, 3],
            faces: vec![0; 4],
            closed: true,
        };
        let beside: Vec<DVec3> = (0..4)
            .map(|k| DVec3::new(k as f64 + 0.05, -0.3, 0.0))
            .chain([DVec3::new(-0.3, 0.1, 0.0)])
            .collect();
        let arcs = ladder_arcs(&mesh, &curve, &beside, |_| 1.0, &[], |_| 1.0).unwrap();
        // 0.05 is merged into 0; the point beside the last side projects to 15.9, within a
        // quarter step of 16 (the first vertex again), and is merged too.
        assert_eq!(arcs, vec![0.0, 1.05, 2.05, 3.05]);
    }

    #[test]
    fn its_own_clear_samples_fill_where_nothing_is_beside() {
        let (mesh, curve) = line(10.0, 5);
        let beside = [DVec3::new(2.0, 0.3, 0.0), DVec3::new(4.0, 0.3, 0.0)];
        // Its own even samples every 2; the one at 2 is crowded (and a station anyway), those at
        // 6 and 8 clear.
        let own = [(2.0, false), (4.0, true), (6.0, true), (8.0, true)];
        let arcs = ladder_arcs(&mesh, &curve, &beside, |_| 1.0, &own, |_| 2.0).unwrap();
        assert_eq!(arcs, vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0]);
    }
}
