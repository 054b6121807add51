//! Sharp-feature curves as curves to sample, like the boundary: fixed samples evenly along each
//! crease from corner to corner, in the output set from the start of the linear scan.
//!
//! A crease is a 1-manifold; the spectral measure restricted to it is maximized by even spacing
//! (the 1-D case of the paper's Sec. 3 analysis: samples on a line are a blue-noise set exactly
//! when their gaps are equal), so the curve samples are placed at equal arc-length steps, as the
//! boundary's are. The surface samples then keep away from them through the measure.

use glam::DVec3;
use rustc_hash::{FxHashMap, FxHashSet};

use crate::mesh::TriMesh;
use crate::sampling::boundary::{arc_lengths, curve_length, curve_points, BoundaryCurve};
use crate::surface::features::Features;

/// The least distance between the samples of two feature curves, in units of the spacing
/// (apart from a corner they share): where two kept curves would come closer, the shorter is
/// left out, so curves meeting at a corner at less than about 50° are not both kept. Measured
/// with `--feature-angle 60` at seeds 1–5: at 0.5, horse 8600 θmin 26.7 and bunny 9635 25.1
/// at worst (creases round the tail and ear tips, whose samples make thin triangles among
/// themselves); at 0.85, 28.6 and 33.0; fandisk, bracket and flange the same at both.
pub const CURVE_SAMPLE_GAP: f64 = 0.85;

/// A feature curve to sample: the curve, and the arc length (bbox-100 units) at its start and at
/// its end that gets no sample but the corner (`bare`), where it leaves a corner at a small
/// angle to a curve kept before it (see [`feature_pieces`]). Its first edge then runs from the
/// corner to its first sample beyond that length, along the crease.
#[derive(Debug, Clone, PartialEq)]
pub struct FeaturePiece {
    /// The crease, as a curve with a face per edge.
    pub curve: BoundaryCurve,
    /// Arc length without samples at the start and at the end (0 for none).
    pub bare: [f64; 2],
}

/// Which of an open curve's samples to keep, given which are `clear` of the samples of curves
/// kept before: every clear one, where the crowded ones are the first few after the start or
/// the last few before the end (leaving a corner at a small angle to another curve). None when
/// a corner, a closed curve's sample, or a sample with clear ones on both sides is crowded (the
/// curve runs beside another), or when every sample between the corners is.
fn trim_at_ends(clear: &[bool], closed: bool) -> Option<Vec<bool>> {
    if clear.iter().all(|&c| c) {
        return Some(clear.to_vec());
    }
    let n = clear.len();
    if closed || n < 2 || !clear[0] || !clear[n - 1] {
        return None;
    }
    let first_clear = (1..n - 1).find(|&k| clear[k])?;
    let last_clear = (1..n - 1).rev().find(|&k| clear[k])?;
    (first_clear..=last_clear)
        .all(|k| clear[k])
        .then(|| clear.to_vec())
}

/// The feature curves of `features` worth sampling at `spacing` (bbox-100 units), as curves with
/// a face per edge (the face that has the edge in the curve's direction, else the other), and
/// the boundary `curves` cut at the corners where those feature curves meet them, so that a
/// crease ending on the boundary ends on a boundary sample. Returns (boundary pieces, feature
/// pieces).
///
/// A feature curve shorter than `spacing` is left out unless both its ends are ends of longer
/// kept curves (then it only adds the edge between two corners sampled anyway): alone, it
/// cannot hold a sample between its corners, and two corners closer than the spacing would
/// only give thin triangles (the folds a scan leaves are such bits). Curves are then taken
/// longest first, and one whose samples come closer than [`CURVE_SAMPLE_GAP`] spacings to
/// those of a curve taken before (apart from a shared corner) is left out, unless the crowded
/// samples are only its first or last few, where it leaves a corner at a small angle to a kept
/// curve: those are left out and the rest kept (a [`FeaturePiece`]'s `bare` ends; the angle at
/// such a corner is the input's, and its triangles cannot have a larger one). Deterministic.
pub fn feature_pieces(
    mesh: &TriMesh,
    curves: &[BoundaryCurve],
    features: &Features,
    spacing: f64,
) -> (Vec<BoundaryCurve>, Vec<FeaturePiece>) {
    if features.curves.is_empty() {
        return (curves.to_vec(), Vec::new());
    }
    // The curves as curves to sample, with their lengths.
    let all: Vec<(f64, BoundaryCurve)> = features
        .curves
        .iter()
        .map(|c| {
            let piece = BoundaryCurve {
                vertices: c.vertices.clone(),
                faces: c.faces.clone(),
                closed: c.closed,
            };
            (curve_length(mesh, &piece), piece)
        })
        .collect();
    let ends = |c: &BoundaryCurve| [c.vertices[0], c.vertices[c.vertices.len() - 1]];
    // Curves long enough for the spacing, then the short ones between two of their ends (an
    // edge between corners that are sampled anyway).
    let long_ends: FxHashSet<u32> = all
        .iter()
        .filter(|(l, c)| *l >= spacing && !c.closed)
        .flat_map(|(_, c)| ends(c))
        .collect();
    let mut candidates: Vec<(f64, BoundaryCurve)> = all
        .into_iter()
        .filter(|(l, c)| {
            *l >= spacing || (!c.closed && ends(c).iter().all(|v| long_ends.contains(v)))
        })
        .collect();
    // Longest first, each kept only where its samples keep their distance from those of the
    // curves kept before (apart from a shared corner): two creases closer than the spacing (a
    // scan's fold beside another, a thin part's rims) would only give thin triangles.
    candidates.sort_by(|x, y| y.0.total_cmp(&x.0));
    let gap = CURVE_SAMPLE_GAP * spacing;
    let cell = |p: DVec3| (p / gap).floor().as_i64vec3().to_array();
    let mut placed: FxHashMap<[i64; 3], Vec<(DVec3, Option<u32>)>> = FxHashMap::default();
    let mut pieces = Vec::new();
    for (_, piece) in candidates {
        let points = curve_points(mesh, &piece, spacing, |a, b| a.distance(b));
        let last = points.len().saturating_sub(1);
        let corner = |k: usize| -> Option<u32> {
            (!piece.closed && (k == 0 || k == last))
                .then(|| piece.vertices[if k == 0 { 0 } else { piece.vertices.len() - 1 }])
        };
        let clear: Vec<bool> = points
            .iter()
            .enumerate()
            .map(|(k, &(p, _))| {
                let c = cell(p);
                let here = corner(k);
                (-1..=1).all(|dx| {
                    (-1..=1).all(|dy| {
                        (-1..=1).all(|dz| {
                            placed
                                .get(&[c[0] + dx, c[1] + dy, c[2] + dz])
                                .is_none_or(|v| {
                                    v.iter().all(|&(q, at)| {
                                        (here.is_some() && at == here) || p.distance(q) >= gap
                                    })
                                })
                        })
                    })
                })
            })
            .collect();
        // Where the curve leaves a corner at a small angle to a curve kept before, its first
        // samples crowd that curve's: they are left out, and the curve's first edge runs from
        // the corner to its first clear sample (still on the crease). A crowded sample
        // anywhere else (a crease beside another along its length) leaves the whole curve out.
        let keep = match trim_at_ends(&clear, piece.closed) {
            Some(keep) => keep,
            None => continue,
        };
        for (k, &(p, _)) in points.iter().enumerate() {
            if keep[k] {
                placed.entry(cell(p)).or_default().push((p, corner(k)));
            }
        }
        // The bare lengths: halfway between the last left-out sample and the next kept one.
        let mut bare = [0.0; 2];
        if keep.iter().any(|&k| !k) {
            let arc = arc_lengths(mesh, &piece, &points);
            let total = curve_length(mesh, &piece);
            if let Some(k) = (1..points.len()).find(|&k| keep[k]).filter(|&k| k > 1) {
                bare[0] = 0.5 * (arc[k - 1] + arc[k]);
            }
            if let Some(k) = (0..last).rev().find(|&k| keep[k]).filter(|&k| k + 1 < last) {
                bare[1] = total - 0.5 * (arc[k] + arc[k + 1]);
            }
        }
        pieces.push(FeaturePiece { curve: piece, bare });
    }
    // The ends of the kept feature curves, where boundary curves must be cut.
    let ends: FxHashSet<u32> = pieces
        .iter()
        .filter(|p| !p.curve.closed)
        .flat_map(|p| {
            [
                p.curve.vertices[0],
                p.curve.vertices[p.curve.vertices.len() - 1],
            ]
        })
        .collect();
    (split_at(curves, &ends), pieces)
}

/// `curves` cut at the vertices in `at`: a closed curve through k ≥ 1 of them becomes k open
/// pieces from one to the next (a single one: from it round to itself); an open curve is cut
/// at each one inside it.
pub fn split_at(curves: &[BoundaryCurve], at: &FxHashSet<u32>) -> Vec<BoundaryCurve> {
    let mut out = Vec::with_capacity(curves.len());
    for curve in curves {
        let nv = curve.vertices.len();
        let cuts: Vec<usize> = (0..nv)
            .filter(|&k| at.contains(&curve.vertices[k]))
            .filter(|&k| curve.closed || (k > 0 && k + 1 < nv))
            .collect();
        if cuts.is_empty() {
            out.push(curve.clone());
            continue;
        }
        let piece = |from: usize, to: usize| BoundaryCurve {
            vertices: (from..=to).map(|k| curve.vertices[k % nv]).collect(),
            faces: (from..to).map(|k| curve.faces[k % nv]).collect(),
            closed: false,
        };
        if curve.closed {
            for (i, &c) in cuts.iter().enumerate() {
                let next = cuts[(i + 1) % cuts.len()];
                out.push(piece(c, if next > c { next } else { next + nv }));
            }
        } else {
            let mut from = 0;
            for &c in &cuts {
                out.push(piece(from, c));
                from = c;
            }
            out.push(piece(from, nv - 1));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::boundary::{boundary_curves, sample_curves_and_features};
    use crate::surface::features::{detect_features, FeatureParams};
    use glam::DVec3;

    /// A unit square in z = 0 folded along x = 0.5 (the half x > 0.5 rises at 60°), as an
    /// `n × n` grid: one crease from boundary to boundary.
    fn folded_sheet(n: usize) -> (TriMesh, Vec<u32>) {
        let mesh = crate::mesh::test_meshes::grid(n, |i, j| {
            let x = i as f64 / n as f64;
            let (px, pz) = if x > 0.5 {
                (0.5 + (x - 0.5) * 0.5, (x - 0.5) * 3f64.sqrt() / 2.0)
            } else {
                (x, 0.0)
            };
            DVec3::new(px, j as f64 / n as f64, pz)
        });
        let crease = (0..=n).map(|j| (j * (n + 1) + n / 2) as u32).collect();
        (mesh, crease)
    }

    #[test]
    fn a_crease_is_sampled_evenly_and_cuts_the_boundary_where_it_ends() {
        let (mesh, crease) = folded_sheet(8);
        // The fold is 60° between faces: a crease at 45°, from boundary to boundary.
        let surface = crate::surface::MeshSurface::new(&mesh).unwrap();
        let features = detect_features(
            &surface,
            &FeatureParams {
                angle_deg: 45.0,
                scale: 0.0,
            },
        );
        assert_eq!(features.curves.len(), 1);
        assert_eq!(features.curves[0].vertices, crease);
        let curves = boundary_curves(&mesh);
        assert_eq!(curves.len(), 1);
        let (boundary, feature) = feature_pieces(&mesh, &curves, &features, 0.1);
        assert_eq!(
            boundary.len(),
            2,
            "the loop is cut at the crease's two ends"
        );
        assert_eq!(feature.len(), 1);
        let b = sample_curves_and_features(&mesh, &boundary, &feature, 0.1, None);
        // 10 steps along the crease (length 1), its ends shared with the boundary.
        assert_eq!(b.feature_edges.len(), 10);
        for e in &b.feature_edges {
            let (p, q) = (
                b.samples[e[0] as usize].position,
                b.samples[e[1] as usize].position,
            );
            assert!((p.distance(q) - 0.1).abs() < 1e-9);
            assert!((p.x - 0.5).abs() < 1e-12 && p.z.abs() < 1e-12);
        }
        let ends = [b.feature_edges[0][0], b.feature_edges[9][1]];
        for end in ends {
            assert_eq!(
                b.edges.iter().filter(|e| e.contains(&end)).count(),
                2,
                "a crease end is a boundary sample"
            );
        }
        // The boundary stays one closed chain of edges through every boundary sample.
        let mut degree = vec![0; b.samples.len()];
        for e in &b.edges {
            degree[e[0] as usize] += 1;
            degree[e[1] as usize] += 1;
        }
        let on_crease_only = (0..b.samples.len()).filter(|&i| degree[i] == 0).count();
        assert_eq!(on_crease_only, 9);
        assert!(degree.iter().all(|&d| d == 0 || d == 2));
        // A crease shorter than the spacing is left out, and the loop stays whole.
        let (boundary, feature) = feature_pieces(&mesh, &curves, &features, 1.5);
        assert!(feature.is_empty());
        assert_eq!(boundary, curves);
    }
}
