//! Samples along curves of a mesh: the boundary curves and the sharp-feature curves are sampled
//! alike, at equal steps of arc length (or of a width field's measure) as close to the spacing as
//! a whole number of steps allows, one sample shared where open curves meet. A crease that leaves
//! a corner at a small angle to another has graded ends ([`FeaturePiece`]).

use glam::DVec3;
use rustc_hash::FxHashMap;

use crate::geometry::tolerance::CURVE_SAMPLE_COINCIDENT;
use crate::mesh::TriMesh;
use crate::sampling::sizing::{SizingField, Uniform};
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

/// How many samples [`sample_boundary`](crate::sampling::boundary::sample_boundary) places at
/// `spacing` on `curves` of `mesh`, without placing them: the whole-number steps of each curve, at
/// least 3 on a loop, counting each end of an open chain once per chain (an upper bound there, as
/// chains that meet share their ends). A float, so that a spacing far below the curves' length
/// gives a large number rather than an overflow.
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

/// [`sample_boundary`](crate::sampling::boundary::sample_boundary) on the boundary curves and on
/// sharp-feature curves together (the pieces of
/// [`feature_pieces`](crate::sampling::features::feature_pieces), given as curves with a face per
/// edge): one sample shared where curves meet, the feature curves' consecutive samples in
/// `feature_edges` rather than `edges`. The boundary at `spacing`, the feature curves at
/// `feature_spacing` (bbox-100 units). With a `width` field the spacing follows it: the samples are
/// at equal steps of ∫ ds / (`width(x)` · `spacing`) along each curve (the width taken at the
/// curve's vertices, linear in between), their number that integral rounded (at least 3 on a loop,
/// 1 step on a chain).
pub fn sample_curves_and_features(
    mesh: &TriMesh,
    curves: &[BoundaryCurve],
    features: &[FeaturePiece],
    spacing: f64,
    feature_spacing: f64,
    field: &dyn SizingField,
) -> BoundarySamples {
    let scale = feature_spacing / spacing;
    if field.is_uniform() {
        sample_curves(mesh, curves, features, spacing, spacing, scale, &Uniform)
    } else {
        sample_curves(mesh, curves, features, 1.0, spacing, scale, field)
    }
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
pub(crate) fn width_steps(field: &dyn SizingField, a: DVec3, b: DVec3) -> f64 {
    0.5 * a.distance(b) * (1.0 / field.width(a).max(1e-6) + 1.0 / field.width(b).max(1e-6))
}

/// The samples of every curve ([`curve_points`]), one shared sample where open curves meet;
/// the feature pieces at `feature_scale` times the boundary's steps, those with graded ends at
/// their own points ([`graded_points`]).
pub(crate) fn sample_curves(
    mesh: &TriMesh,
    curves: &[BoundaryCurve],
    features: &[FeaturePiece],
    unit: f64,
    spacing: f64,
    feature_scale: f64,
    field: &dyn SizingField,
) -> BoundarySamples {
    let width = (!field.is_uniform()).then_some(field);
    // Per edge: its length, or with a width field its steps (the trapezoid rule in 1/w, in
    // units of one step of `spacing`).
    let measure = |a: DVec3, b: DVec3| match width {
        None => a.distance(b),
        Some(w) => width_steps(w, a, b) / spacing,
    };
    let mut out = BoundarySamples::default();
    let mut at_vertex: FxHashMap<u32, u32> = FxHashMap::default();
    let mut coincident = Coincident::default();
    let mut seen_edges: rustc_hash::FxHashSet<[u32; 2]> = Default::default();
    let all = curves
        .iter()
        .map(|c| (c, None))
        .chain(features.iter().map(|f| (&f.curve, Some(f))));
    for (curve, feature) in all {
        let nv = curve.vertices.len();
        let points = match feature {
            Some(f) if f.ladder.is_some() || f.graded.iter().any(|g| !g.is_empty()) => {
                graded_points(mesh, f, spacing * feature_scale, field)
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
            // A sample already placed at this point (by a curve along coincident edges) is
            // this one.
            if let Some(id) = coincident.find(position) {
                ids.push(id);
                continue;
            }
            let face = curve.faces[edge];
            let id = out.samples.len() as u32;
            coincident.insert(position, id);
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
        let closing = curve.closed.then(|| [ids[ids.len() - 1], ids[0]]);
        // An edge of no length or one already taken (along coincident curves) is left out.
        for e in ids.windows(2).map(|w| [w[0], w[1]]).chain(closing) {
            if e[0] != e[1] && seen_edges.insert([e[0].min(e[1]), e[0].max(e[1])]) {
                edges.push(e);
            }
        }
    }
    out
}

/// The curve samples placed so far on a grid of [`CURVE_SAMPLE_COINCIDENT`] cells: the one
/// within that distance of a point, if any.
#[derive(Default)]
struct Coincident(FxHashMap<[i64; 3], Vec<(DVec3, u32)>>);

impl Coincident {
    fn cell(p: DVec3) -> [i64; 3] {
        (p / CURVE_SAMPLE_COINCIDENT)
            .floor()
            .as_i64vec3()
            .to_array()
    }

    fn insert(&mut self, p: DVec3, id: u32) {
        self.0.entry(Self::cell(p)).or_default().push((p, id));
    }

    fn find(&self, p: DVec3) -> Option<u32> {
        let [x, y, z] = Self::cell(p);
        (-1..=1)
            .flat_map(|i| (-1..=1).flat_map(move |j| (-1..=1).map(move |k| [x + i, y + j, z + k])))
            .filter_map(|c| self.0.get(&c))
            .flatten()
            .find(|(q, _)| q.distance(p) <= CURVE_SAMPLE_COINCIDENT)
            .map(|&(_, id)| id)
    }
}

/// A feature curve to sample: the curve, and at each end where it leaves a corner at a small angle
/// to another kept curve, the arc lengths from that end (bbox-100 units, decreasing) of the samples
/// graded towards the corner (see [`feature_pieces`](crate::sampling::features::feature_pieces));
/// empty where the samples are even up to the end.
#[derive(Debug, Clone, PartialEq)]
pub struct FeaturePiece {
    /// The crease, as a curve with a face per edge.
    pub curve: BoundaryCurve,
    /// Per end (start, end): the graded samples' distances along the curve from that end, the
    /// first the farthest (where the even spacing starts).
    pub graded: [Vec<f64>; 2],
    /// The arc lengths from the start (units of the mesh, increasing, from 0 to the length) of
    /// the samples of a crease sampled as a ladder beside others
    /// ([`crease_ladder`](crate::sampling::crease_ladder)); `None` otherwise.
    pub ladder: Option<Vec<f64>>,
}

impl FeaturePiece {
    /// The arc lengths from the start (units of the mesh) of the samples of a piece of length
    /// `total` with graded ends at `spacing`: 0, the start's graded samples, even steps as close
    /// to `spacing` as a whole number allows in between, the end's graded samples, `total`.
    /// Only for open curves with a graded end.
    pub(crate) fn arcs(&self, total: f64, spacing: f64) -> Vec<f64> {
        let r0 = self.graded[0].first().copied().unwrap_or(0.0);
        let r1 = self.graded[1].first().copied().unwrap_or(0.0);
        let middle = (total - r0 - r1).max(0.0);
        let steps = (middle / spacing).round().max(1.0) as usize;
        self.with_graded_ends(
            total,
            (1..steps).map(|k| r0 + middle * k as f64 / steps as f64),
        )
    }

    /// [`FeaturePiece::arcs`] with the even steps between the graded ends taken in a measure
    /// along the curve (edge `k` has length `lengths[k]` and measure `measures[k]`, in units of
    /// length): as many steps as `spacing` fits into the middle part's measure, equal in it.
    pub(crate) fn arcs_in_measure(
        &self,
        lengths: &[f64],
        measures: &[f64],
        spacing: f64,
    ) -> Vec<f64> {
        let total: f64 = lengths.iter().sum();
        let r0 = self.graded[0].first().copied().unwrap_or(0.0);
        let r1 = self.graded[1].first().copied().unwrap_or(0.0);
        let m0 = convert(lengths, measures, r0, true);
        let m1 = convert(lengths, measures, (total - r1).max(r0), true);
        let steps = ((m1 - m0) / spacing).round().max(1.0) as usize;
        self.with_graded_ends(
            total,
            (1..steps).map(|k| {
                let m = m0 + (m1 - m0) * k as f64 / steps as f64;
                convert(lengths, measures, m, false)
            }),
        )
    }

    /// The arc lengths of a piece of length `total`: 0, the start's graded samples, the
    /// `middle` ones, the end's graded samples, `total` (coincident ones once).
    fn with_graded_ends(&self, total: f64, middle: impl Iterator<Item = f64>) -> Vec<f64> {
        let mut out = vec![0.0];
        out.extend(self.graded[0].iter().rev().copied());
        out.extend(middle);
        out.extend(self.graded[1].iter().map(|&r| total - r));
        out.push(total);
        out.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * total.max(1.0));
        out
    }
}

/// The points of a feature piece with graded ends ([`FeaturePiece::arcs`]), corners exact. With
/// a `width` field the even steps between the graded ends follow it (equal steps of ∫ ds / w,
/// the width taken at the curve's vertices, linear in between, as on the other curves); the
/// graded distances stay as they are (they were set at the corner's width). A ladder's points are
/// at its own arcs ([`FeaturePiece::ladder`]).
pub(crate) fn graded_points(
    mesh: &TriMesh,
    piece: &FeaturePiece,
    spacing: f64,
    field: &dyn SizingField,
) -> Vec<(DVec3, usize)> {
    let width = (!field.is_uniform()).then_some(field);
    let lengths = edge_lengths(mesh, &piece.curve);
    let total: f64 = lengths.iter().sum();
    let arcs = match (&piece.ladder, width) {
        (Some(arcs), _) => arcs.clone(),
        (None, None) => piece.arcs(total, spacing),
        (None, Some(w)) => {
            let nv = piece.curve.vertices.len();
            let pos = |k: usize| mesh.positions[piece.curve.vertices[k % nv] as usize];
            let measures: Vec<f64> = (0..lengths.len())
                .map(|k| width_steps(w, pos(k), pos(k + 1)))
                .collect();
            piece.arcs_in_measure(&lengths, &measures, spacing)
        }
    };
    let mut points = points_along(mesh, &piece.curve, &lengths, arcs);
    let (last, nv) = (points.len() - 1, piece.curve.vertices.len());
    points[0].0 = mesh.positions[piece.curve.vertices[0] as usize];
    if !piece.curve.closed {
        points[last].0 = mesh.positions[piece.curve.vertices[nv - 1] as usize];
    }
    points
}

/// Along a curve of edge `lengths` whose edges have `measures`, the measure at arc length `t`
/// (`to_measure`) or the arc length at measure `m` (`!to_measure`), linear within an edge.
fn convert(lengths: &[f64], measures: &[f64], x: f64, to_measure: bool) -> f64 {
    let (from, to) = if to_measure {
        (lengths, measures)
    } else {
        (measures, lengths)
    };
    let (mut a, mut b) = (0.0, 0.0);
    for k in 0..from.len() {
        if a + from[k] >= x || k + 1 == from.len() {
            let u = if from[k] > 0.0 {
                ((x - a) / from[k]).clamp(0.0, 1.0)
            } else {
                0.0
            };
            return b + u * to[k];
        }
        a += from[k];
        b += to[k];
    }
    0.0
}
