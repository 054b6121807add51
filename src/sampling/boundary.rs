//! The boundary curves of an open input and their sampling.
//!
//! A surface with boundary is sampled in two steps: its boundary curves (the 1-manifold where it
//! ends) first, evenly by arc length at the spacing the surface sampling will have, then the
//! surface by the linear scan with those samples already in the output set. The boundary samples
//! stay fixed during gradient ascent, and consecutive ones become the output mesh's boundary
//! edges, so every hole of the input stays a hole of the output and no other hole appears.

use glam::DVec3;
use rustc_hash::FxHashMap;

use crate::mesh::TriMesh;
use crate::sampling::features::{graded_points, FeaturePiece};
use crate::sampling::WidthField;
use crate::surface::SurfaceSample;

/// One boundary curve of a mesh: input vertex indices in order, the surface on the left (the
/// direction the boundary edges have in their faces).
#[derive(Debug, Clone, PartialEq)]
pub struct BoundaryCurve {
    /// Vertex indices; for a closed loop the first vertex is not repeated at the end.
    pub vertices: Vec<u32>,
    /// For each edge `vertices[k] → vertices[k+1]` (and, for a loop, last → first): the face it
    /// belongs to.
    pub faces: Vec<u32>,
    /// Whether the curve closes on itself (the usual case); open chains end at vertices where
    /// several boundary curves meet.
    pub closed: bool,
}

/// The boundary curves of `mesh`: chains of edges that belong to exactly one triangle.
/// Deterministic (ordered by the lowest vertex index each curve starts from).
pub fn boundary_curves(mesh: &TriMesh) -> Vec<BoundaryCurve> {
    // Count undirected edges; remember the direction and face of the single use.
    let mut uses: FxHashMap<(u32, u32), (u32, u32, u32, u32)> = FxHashMap::default();
    for (f, t) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let key = (a.min(b), a.max(b));
            let e = uses.entry(key).or_insert((0, a, b, f as u32));
            e.0 += 1;
        }
    }
    let mut directed: Vec<(u32, u32, u32)> = uses
        .values()
        .filter(|e| e.0 == 1)
        .map(|e| (e.1, e.2, e.3))
        .collect();
    directed.sort_unstable();
    let mut out_deg: FxHashMap<u32, u32> = FxHashMap::default();
    let mut in_deg: FxHashMap<u32, u32> = FxHashMap::default();
    for &(a, b, _) in &directed {
        *out_deg.entry(a).or_default() += 1;
        *in_deg.entry(b).or_default() += 1;
    }
    let regular = |v: u32| out_deg.get(&v) == Some(&1) && in_deg.get(&v) == Some(&1);
    // Outgoing edges per vertex, in sorted order.
    let mut next: FxHashMap<u32, Vec<usize>> = FxHashMap::default();
    for (i, &(a, _, _)) in directed.iter().enumerate() {
        next.entry(a).or_default().push(i);
    }
    let mut used = vec![false; directed.len()];
    let mut curves = Vec::new();
    let walk = |start_edge: usize, used: &mut Vec<bool>| -> BoundaryCurve {
        let mut vertices = vec![directed[start_edge].0];
        let mut faces = Vec::new();
        let mut e = start_edge;
        loop {
            used[e] = true;
            let (_, b, f) = directed[e];
            faces.push(f);
            if b == vertices[0] {
                return BoundaryCurve {
                    vertices,
                    faces,
                    closed: true,
                };
            }
            vertices.push(b);
            if !regular(b) {
                return BoundaryCurve {
                    vertices,
                    faces,
                    closed: false,
                };
            }
            match next
                .get(&b)
                .and_then(|v| v.iter().copied().find(|&i| !used[i]))
            {
                Some(n) => e = n,
                None => {
                    return BoundaryCurve {
                        vertices,
                        faces,
                        closed: false,
                    }
                }
            }
        }
    };
    // Open chains start at irregular vertices; what is left are closed loops.
    for i in 0..directed.len() {
        if !used[i] && !regular(directed[i].0) {
            curves.push(walk(i, &mut used));
        }
    }
    for i in 0..directed.len() {
        if !used[i] {
            curves.push(walk(i, &mut used));
        }
    }
    curves
}

/// Samples of the boundary curves and the boundary edges between them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BoundarySamples {
    /// Points on the boundary curves (bbox-100 units), each with the normal of its face.
    pub samples: Vec<SurfaceSample>,
    /// Consecutive samples along a curve, `[from, to]` indices into `samples`, directed with the
    /// surface on the left.
    pub edges: Vec<[u32; 2]>,
    /// Consecutive samples along a sharp-feature curve (`sample_curves_and_features`),
    /// `[from, to]` indices into `samples`: edges the output should have, with a face either
    /// side.
    pub feature_edges: Vec<[u32; 2]>,
}

/// The arc length of `curve` (bbox-100 units when `mesh` is normalized).
pub fn curve_length(mesh: &TriMesh, curve: &BoundaryCurve) -> f64 {
    edge_lengths(mesh, curve).iter().sum()
}

/// The length of each edge `k → k+1` of `curve` (units of the mesh).
pub(crate) fn edge_lengths(mesh: &TriMesh, curve: &BoundaryCurve) -> Vec<f64> {
    let nv = curve.vertices.len();
    let pos = |k: usize| mesh.positions[curve.vertices[k % nv] as usize];
    (0..curve.faces.len())
        .map(|k| pos(k).distance(pos(k + 1)))
        .collect()
}

/// How many samples [`sample_boundary`] places at `spacing` on `curves` of `mesh`, without
/// placing them: the whole-number steps of each curve, at least 3 on a loop, counting each end
/// of an open chain once per chain (an upper bound there, as chains that meet share their ends).
/// A float, so that a spacing far below the curves' length gives a large number rather than an
/// overflow.
pub fn boundary_sample_count<'a>(
    mesh: &TriMesh,
    curves: impl IntoIterator<Item = &'a BoundaryCurve>,
    spacing: f64,
) -> f64 {
    curves
        .into_iter()
        .map(|curve| (curve, curve_length(mesh, curve)))
        .filter(|(_, total)| *total > 0.0)
        .map(|(curve, total)| {
            let steps = curve_steps(total, spacing, curve.closed);
            if curve.closed {
                steps
            } else {
                steps + 1.0
            }
        })
        .sum()
}

/// The whole number of equal steps closest to `spacing` along a curve of length `total`: at
/// least 3 on a closed loop, at least 1 on an open chain. A float, so that a spacing far below
/// the length gives a large number rather than an overflow.
fn curve_steps(total: f64, spacing: f64, closed: bool) -> f64 {
    (total / spacing)
        .round()
        .max(if closed { 3.0 } else { 1.0 })
}

/// [`sample_boundary`] on the boundary curves and on sharp-feature curves together (the pieces
/// of [`feature_pieces`](crate::sampling::features::feature_pieces), given as curves with a face
/// per edge): one sample shared where curves meet, the feature curves' consecutive samples in
/// `feature_edges` rather than `edges`. The boundary at `spacing`, the feature curves at
/// `feature_spacing` (bbox-100 units). With a `width` field the spacing follows it: the samples
/// are at equal steps of ∫ ds / (`width(x)` · `spacing`) along each curve (the width taken at
/// the curve's vertices, linear in between), their number that integral rounded (at least 3 on
/// a loop, 1 step on a chain).
pub fn sample_curves_and_features(
    mesh: &TriMesh,
    curves: &[BoundaryCurve],
    features: &[FeaturePiece],
    spacing: f64,
    feature_spacing: f64,
    width: Option<WidthField>,
) -> BoundarySamples {
    let scale = feature_spacing / spacing;
    match width {
        None => sample_curves(mesh, curves, features, spacing, spacing, scale, None),
        Some(_) => sample_curves(mesh, curves, features, 1.0, spacing, scale, width),
    }
}

/// Places samples along every boundary curve of `mesh` at equal arc-length steps as close to
/// `spacing` (bbox-100 units) as a whole number of steps allows: a closed loop gets at least 3,
/// and the ends of open chains are shared between the chains that meet there.
pub fn sample_boundary(mesh: &TriMesh, curves: &[BoundaryCurve], spacing: f64) -> BoundarySamples {
    sample_curves(mesh, curves, &[], spacing, spacing, 1.0, None)
}

/// The points of one curve at equal steps of a measure along it: `measure(a, b)` of each edge
/// from a to b, the step count the whole number of `unit`s closest to the curve's total
/// ([`curve_steps`]), positions linear in the measure within an edge. Each point with the
/// index of the edge it lies on; an open curve's first and last points are its end vertices.
/// Empty for a curve of measure 0.
pub(crate) fn curve_points(
    mesh: &TriMesh,
    curve: &BoundaryCurve,
    unit: f64,
    measure: impl Fn(DVec3, DVec3) -> f64,
) -> Vec<(DVec3, usize)> {
    let nv = curve.vertices.len();
    let ne = curve.faces.len();
    let pos = |k: usize| mesh.positions[curve.vertices[k % nv] as usize];
    let lengths: Vec<f64> = (0..ne).map(|k| measure(pos(k), pos(k + 1))).collect();
    let total: f64 = lengths.iter().sum();
    if !(total > 0.0) {
        return Vec::new();
    }
    let steps = curve_steps(total, unit, curve.closed) as usize;
    let count = if curve.closed { steps } else { steps + 1 };
    let mut out = points_along(
        mesh,
        curve,
        &lengths,
        (0..count).map(|s| total * s as f64 / steps as f64),
    );
    out[0].0 = pos(0);
    if !curve.closed {
        out[steps].0 = pos(nv - 1);
    }
    out
}

/// The points of `curve` at the positions `targets` along it (non-decreasing, in the units of
/// `lengths`, the length of each edge `k → k+1`), each with the index of the edge it lies on:
/// linear in the length within an edge, clamped to the curve's ends. One walk along the curve.
pub(crate) fn points_along(
    mesh: &TriMesh,
    curve: &BoundaryCurve,
    lengths: &[f64],
    targets: impl IntoIterator<Item = f64>,
) -> Vec<(DVec3, usize)> {
    let nv = curve.vertices.len();
    let ne = lengths.len();
    let pos = |k: usize| mesh.positions[curve.vertices[k % nv] as usize];
    let (mut edge, mut edge_start) = (0usize, 0.0f64);
    targets
        .into_iter()
        .map(|t| {
            while edge + 1 < ne && edge_start + lengths[edge] < t {
                edge_start += lengths[edge];
                edge += 1;
            }
            let u = if lengths[edge] > 0.0 {
                ((t - edge_start) / lengths[edge]).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (pos(edge).lerp(pos(edge + 1), u), edge)
        })
        .collect()
}

/// The length of the edge a–b in a width field, ∫ ds / w by the trapezoid rule (the width
/// taken at both ends, at least 1e-6): the steps it takes at a spacing of 1 where w is 1.
pub(crate) fn width_steps(width: WidthField, a: DVec3, b: DVec3) -> f64 {
    0.5 * a.distance(b) * (1.0 / width(a).max(1e-6) + 1.0 / width(b).max(1e-6))
}

/// The samples of every curve ([`curve_points`]), one shared sample where open curves meet;
/// the feature pieces at `feature_scale` times the boundary's steps, those with graded ends at
/// their own points ([`graded_points`]).
fn sample_curves(
    mesh: &TriMesh,
    curves: &[BoundaryCurve],
    features: &[FeaturePiece],
    unit: f64,
    spacing: f64,
    feature_scale: f64,
    width: Option<WidthField>,
) -> BoundarySamples {
    // Per edge: its length, or with a width field its steps (the trapezoid rule in 1/w, in
    // units of one step of `spacing`).
    let measure = |a: DVec3, b: DVec3| match width {
        None => a.distance(b),
        Some(w) => width_steps(w, a, b) / spacing,
    };
    let mut out = BoundarySamples::default();
    let mut at_vertex: FxHashMap<u32, u32> = FxHashMap::default();
    let all = curves
        .iter()
        .map(|c| (c, None))
        .chain(features.iter().map(|f| (&f.curve, Some(f))));
    for (curve, feature) in all {
        let nv = curve.vertices.len();
        let points = match feature {
            Some(f) if f.graded.iter().any(|g| !g.is_empty()) => {
                graded_points(mesh, f, spacing * feature_scale, width)
            }
            Some(_) => curve_points(mesh, curve, unit * feature_scale, measure),
            None => curve_points(mesh, curve, unit, measure),
        };
        if points.is_empty() {
            continue;
        }
        let feature = feature.is_some();
        let last = points.len() - 1;
        let mut ids = Vec::with_capacity(points.len());
        for (s, &(position, edge)) in points.iter().enumerate() {
            let endpoint = if !curve.closed && s == 0 {
                Some(curve.vertices[0])
            } else if !curve.closed && s == last {
                Some(curve.vertices[nv - 1])
            } else {
                None
            };
            if let Some(&id) = endpoint.and_then(|v| at_vertex.get(&v)) {
                ids.push(id);
                continue;
            }
            let face = curve.faces[edge];
            let id = out.samples.len() as u32;
            out.samples.push(SurfaceSample {
                position,
                normal: mesh.face_normal(face as usize),
                face,
            });
            if let Some(v) = endpoint {
                at_vertex.insert(v, id);
            }
            ids.push(id);
        }
        let edges = if feature {
            &mut out.feature_edges
        } else {
            &mut out.edges
        };
        for k in 0..ids.len() - 1 {
            edges.push([ids[k], ids[k + 1]]);
        }
        if curve.closed {
            edges.push([ids[ids.len() - 1], ids[0]]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// A square grid of `n × n` quads in the plane z = 0, side 1, with the quad `hole` removed.
    fn grid(n: usize, hole: Option<(usize, usize)>) -> TriMesh {
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                positions.push(DVec3::new(i as f64 / n as f64, j as f64 / n as f64, 0.0));
            }
        }
        let mut triangles = Vec::new();
        for j in 0..n {
            for i in 0..n {
                if hole == Some((i, j)) {
                    continue;
                }
                let v = (j * (n + 1) + i) as u32;
                let w = v + n as u32 + 1;
                triangles.push([v, v + 1, w + 1]);
                triangles.push([v, w + 1, w]);
            }
        }
        TriMesh::new(positions, triangles)
    }

    #[test]
    fn finds_outer_boundary_and_hole_with_surface_on_the_left() {
        let mesh = grid(4, Some((1, 2)));
        let curves = boundary_curves(&mesh);
        assert_eq!(curves.len(), 2);
        assert!(curves.iter().all(|c| c.closed));
        let mut sizes: Vec<usize> = curves.iter().map(|c| c.vertices.len()).collect();
        sizes.sort();
        assert_eq!(sizes, vec![4, 16]);
        for c in &curves {
            // Signed area in the plane: outer loop counter-clockwise (positive), hole clockwise.
            let area: f64 = (0..c.vertices.len())
                .map(|k| {
                    let a = mesh.positions[c.vertices[k] as usize];
                    let b = mesh.positions[c.vertices[(k + 1) % c.vertices.len()] as usize];
                    a.x * b.y - b.x * a.y
                })
                .sum::<f64>()
                * 0.5;
            if c.vertices.len() == 16 {
                assert!((area - 1.0).abs() < 1e-12);
            } else {
                assert!((area + 1.0 / 16.0).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn boundary_samples_are_evenly_spaced_loops() {
        let mesh = grid(4, None);
        let curves = boundary_curves(&mesh);
        let b = sample_boundary(&mesh, &curves, 0.1);
        assert_eq!(b.samples.len(), 40);
        assert_eq!(b.edges.len(), 40);
        for e in &b.edges {
            let d = b.samples[e[0] as usize]
                .position
                .distance(b.samples[e[1] as usize].position);
            assert!(
                (d - 0.1).abs() < 1e-9 || (d - 0.1f64.hypot(0.0)).abs() < 1e-9,
                "{d}"
            );
        }
        // A closed mesh has none.
        assert!(boundary_curves(&TriMesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        ))
        .is_empty());
    }
}
