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
use crate::sampling::crease_ladder::ladder_arcs;
use crate::sampling::curves::{
    curve_length, curve_points, edge_lengths, graded_points, points_along, width_steps,
    BoundaryCurve, FeaturePiece,
};
use crate::sampling::sizing::SizingField;
use crate::spatial::StaticTree;
use crate::surface::features::Features;

/// The least distance between the samples of two feature curves, in units of the spacing
/// (apart from a corner they share): where two kept curves would come closer, the shorter is
/// left out, so curves meeting at a corner at less than about 50° are not both kept (closer
/// curves' samples make thin triangles among themselves: `docs/decisions/
/// feature-curve-separation.md`), unless grading towards their corner or beside them parts
/// them; with `ladders` ([`feature_pieces`]) the shorter is then sampled beside the other.
pub const CURVE_SAMPLE_GAP: f64 = 0.85;

/// The smallest angle (degrees) between two creases leaving a corner that the sampling grades
/// towards (see [`feature_pieces`]); at a smaller one the shorter crease is left out, as it would
/// take too many samples (about 1 / angle) to follow both.
pub const MIN_GRADED_CORNER_DEG: f64 = 8.0;

/// The distances from a corner (decreasing, the first `reach`) of the samples graded towards a
/// corner where two creases meet at `angle` (radians): the gap between the creases at distance
/// r is 2 r sin(angle / 2), and each step inward shrinks by the same factor 1 + 2 sin(angle / 2),
/// so that the strip between the two creases is cut into trapezoids whose legs equal their
/// shorter side (their triangles keep angles near 60° and above the corner's); down to half
/// the spacing, where the triangle at the corner (isosceles, the corner's angle at its apex)
/// takes over. `reach` is where the gap is the spacing, at most `cap`.
fn graded_distances(angle: f64, spacing: f64, cap: f64) -> Vec<f64> {
    let g = 2.0 * (0.5 * angle).sin();
    let ratio = 1.0 + g;
    let reach = (spacing / g).min(cap);
    let mut out = vec![reach];
    let mut r = reach / ratio;
    while r >= 0.5 * spacing && out.len() < 64 {
        out.push(r);
        r /= ratio;
    }
    out
}

/// The smallest relative width [`corner_width`] gives (half the spacing, as the curvature
/// grading's): the graded samples nearest a corner are closer still, but there the corner's own
/// triangle takes over (at a quarter, the wedge of `tests/features.rs` lost crease edges where a
/// third crease meets its corner).
pub const CORNER_MIN_WIDTH: f64 = 0.5;

/// A corner that feature pieces are graded towards ([`graded_corners`]).
#[derive(Debug, Clone, PartialEq)]
pub struct GradedCorner {
    /// Its position (bbox-100 units).
    pub position: DVec3,
    /// g = 2 sin(angle / 2): the gap between two of its creases at distance r is g r (the largest
    /// g of its graded pieces: the widest angle, the gentlest grading).
    pub g: f64,
    /// The unit directions its graded pieces leave it in.
    pub directions: Vec<DVec3>,
}

/// The corners that feature pieces are graded towards: from each graded end, its corner, the
/// direction it leaves it in (towards its nearest graded sample) and g = d0 / d1 − 1 from its two
/// farthest graded distances (the steps shrink by 1 + g), or spacing / d0 with a single one (d0
/// is where the gap is the spacing). One entry per corner.
pub fn graded_corners(mesh: &TriMesh, pieces: &[FeaturePiece], spacing: f64) -> Vec<GradedCorner> {
    let mut out: Vec<(u32, GradedCorner)> = Vec::new();
    for piece in pieces
        .iter()
        .filter(|p| p.graded.iter().any(|g| !g.is_empty()))
    {
        let nv = piece.curve.vertices.len();
        let lengths = edge_lengths(mesh, &piece.curve);
        let total: f64 = lengths.iter().sum();
        for (end, d) in piece.graded.iter().enumerate() {
            let (Some(&d0), Some(&nearest)) = (d.first(), d.last()) else {
                continue;
            };
            let g = match d.get(1) {
                Some(&d1) if d1 > 0.0 => d0 / d1 - 1.0,
                _ => spacing / d0,
            };
            if !(g > 0.0) {
                continue;
            }
            let v = piece.curve.vertices[if end == 0 { 0 } else { nv - 1 }];
            let corner = mesh.positions[v as usize];
            let arc = if end == 0 { nearest } else { total - nearest };
            let (p, _) = points_along(mesh, &piece.curve, &lengths, [arc])[0];
            let direction = (p - corner).normalize_or_zero();
            match out.iter_mut().find(|(u, _)| *u == v) {
                Some((_, c)) => {
                    c.g = c.g.max(g);
                    c.directions.push(direction);
                }
                None => out.push((
                    v,
                    GradedCorner {
                        position: corner,
                        g,
                        directions: vec![direction],
                    },
                )),
            }
        }
    }
    out.into_iter().map(|(_, c)| c).collect()
}

/// The relative kernel width at `x` that matches the graded creases around `corners` (from
/// [`graded_corners`]): at distance r from a corner the graded steps are about g r, so the width
/// is g r / `spacing`, between [`CORNER_MIN_WIDTH`] and 1; the smallest over the corners. With
/// it, the surface samples on the sheets beside two graded creases are as close as the creases'
/// samples, and the triangles between them keep their shape. Between two of a corner's creases
/// (x seen from the corner within their angle) the width is 1: that strip takes no surface
/// sample, the creases' graded samples make its triangles.
pub fn corner_width(corners: &[GradedCorner], x: DVec3, spacing: f64) -> f64 {
    corners
        .iter()
        .map(|c| width_at(c, x, spacing))
        .fold(1.0, f64::min)
}

/// [`corner_width`] of the one corner `c`.
fn width_at(c: &GradedCorner, x: DVec3, spacing: f64) -> f64 {
    let graded = c.g * x.distance(c.position) / spacing;
    if graded >= 1.0 {
        return 1.0;
    }
    let v = (x - c.position).normalize_or_zero();
    let between = c.directions.iter().enumerate().any(|(i, &a)| {
        c.directions[i + 1..].iter().any(|&b| {
            let ab = a.angle_between(b);
            v.angle_between(a) + v.angle_between(b) <= ab + 1e-3
        })
    });
    if between {
        1.0
    } else {
        graded.max(CORNER_MIN_WIDTH)
    }
}

/// Whether the crowded samples of an open curve (those not `clear` of the samples of curves kept
/// before) are only its first few after the start or its last few before the end (where it
/// leaves a corner at a small angle to another curve). False when a corner, a closed curve's
/// sample, or a sample with clear ones on both sides is crowded (the curve runs beside
/// another), or when every sample between the corners is.
fn crowded_only_at_ends(clear: &[bool], closed: bool) -> bool {
    if clear.iter().all(|&c| c) {
        return true;
    }
    let n = clear.len();
    if closed || n < 2 || !clear[0] || !clear[n - 1] {
        return false;
    }
    let (Some(first), Some(last)) = (
        (1..n - 1).find(|&k| clear[k]),
        (1..n - 1).rev().find(|&k| clear[k]),
    ) else {
        return false;
    };
    (first..=last).all(|k| clear[k])
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
/// those of a curve taken before (apart from the samples at its own corners, whichever curve
/// placed them: how close its next samples come to those is its steps') is left out, unless
/// the crowded samples are only its first or last few and the curves they crowd leave the same
/// corner at [`MIN_GRADED_CORNER_DEG`] or more: then both are graded towards that corner
/// (samples at the same distances from it on both, their steps shrinking with the gap between
/// the creases: [`FeaturePiece::graded`]), so the triangles between them keep the corner's
/// angle, which no triangle there can exceed. With `ladders`, a curve that would be left out
/// for crowding is sampled as a ladder beside the curves it crowds instead ([`ladder_arcs`]:
/// its samples across from theirs; [`FeaturePiece::ladder`]). Deterministic.
pub fn feature_pieces(
    mesh: &TriMesh,
    curves: &[BoundaryCurve],
    features: &Features,
    spacing: f64,
    field: &dyn SizingField,
    ladders: bool,
) -> (Vec<BoundaryCurve>, Vec<FeaturePiece>) {
    let width = (!field.is_uniform()).then_some(field);
    let w = |p: DVec3| width.map_or(1.0, |f| f.width(p).max(1e-6));
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
            (c.length(&mesh.positions), piece)
        })
        .collect();
    let ends = |c: &BoundaryCurve| [c.vertices[0], c.vertices[c.vertices.len() - 1]];
    // Whether a curve of length `l` is long enough for the spacing: in ∫ ds / w with a width
    // field (the local spacing is w · spacing).
    let long_enough = |l: f64, c: &BoundaryCurve| match width {
        None => l >= spacing,
        Some(f) => {
            let nv = c.vertices.len();
            let pos = |k: usize| mesh.positions[c.vertices[k % nv] as usize];
            let m: f64 = (0..c.faces.len())
                .map(|k| width_steps(f, pos(k), pos(k + 1)))
                .sum();
            m >= spacing
        }
    };
    let all: Vec<(f64, BoundaryCurve, bool)> = all
        .into_iter()
        .map(|(l, c)| {
            let long = long_enough(l, &c);
            (l, c, long)
        })
        .collect();
    // Curves long enough for the spacing, then the short ones between two of their ends (an
    // edge between corners that are sampled anyway).
    let long_ends: FxHashSet<u32> = all
        .iter()
        .filter(|(_, c, long)| *long && !c.closed)
        .flat_map(|(_, c, _)| ends(c))
        .collect();
    let mut candidates: Vec<(f64, BoundaryCurve)> = all
        .into_iter()
        .filter(|(_, c, long)| {
            *long || (!c.closed && ends(c).iter().all(|v| long_ends.contains(v)))
        })
        .map(|(l, c, _)| (l, c))
        .collect();
    // Longest first, each kept only where its samples keep their distance from those of the
    // curves kept before (apart from a shared corner): two creases closer than the spacing (a
    // scan's fold beside another, a thin part's rims) would only give thin triangles.
    candidates.sort_by(|x, y| y.0.total_cmp(&x.0));
    let gap = CURVE_SAMPLE_GAP * spacing;
    let cell = |p: DVec3| (p / gap).floor().as_i64vec3().to_array();
    // The samples placed so far, by cell: position, the corner it is at (if any), which kept
    // curve it belongs to and that curve's generation (a curve graded later is placed again).
    type Placed = (DVec3, Option<u32>, usize, u32);
    let mut placed: FxHashMap<[i64; 3], Vec<Placed>> = FxHashMap::default();
    // The kept curves and their generations.
    let mut kept: Vec<(FeaturePiece, u32)> = Vec::new();
    // Whether an open curve ends at the vertex `v` (a corner's own sample is not crowded by the
    // samples of curves leaving it, which may be graded towards it).
    let ends_at = |c: &BoundaryCurve, v: u32| {
        !c.closed && (c.vertices[0] == v || c.vertices[c.vertices.len() - 1] == v)
    };
    let end_vertex = |c: &BoundaryCurve, k: usize, last: usize| -> Option<u32> {
        (!c.closed && (k == 0 || k == last))
            .then(|| c.vertices[if k == 0 { 0 } else { c.vertices.len() - 1 }])
    };
    let points_of = |piece: &FeaturePiece| -> Vec<(DVec3, usize)> {
        if piece.ladder.is_none() && piece.graded.iter().all(|g| g.is_empty()) {
            match width {
                None => curve_points(mesh, &piece.curve, spacing, |a, b| a.distance(b)),
                Some(f) => curve_points(mesh, &piece.curve, 1.0, |a, b| {
                    width_steps(f, a, b) / spacing
                }),
            }
        } else {
            graded_points(mesh, piece, spacing, field)
        }
    };
    let place = |placed: &mut FxHashMap<[i64; 3], Vec<Placed>>,
                 piece: &FeaturePiece,
                 points: &[(DVec3, usize)],
                 index: usize,
                 generation: u32| {
        let last = points.len().saturating_sub(1);
        for (k, &(p, _)) in points.iter().enumerate() {
            placed.entry(cell(p)).or_default().push((
                p,
                end_vertex(&piece.curve, k, last),
                index,
                generation,
            ));
        }
    };
    // The direction a curve leaves its end `at` (0: start, 1: end): towards its point a spacing
    // along (or half its length, if shorter).
    let leaving = |curve: &BoundaryCurve, at: usize| -> DVec3 {
        let lengths = edge_lengths(mesh, curve);
        let total: f64 = lengths.iter().sum();
        let arc = spacing.min(0.5 * total);
        let target = if at == 0 { arc } else { total - arc };
        let (p, _) = points_along(mesh, curve, &lengths, [target])[0];
        let nv = curve.vertices.len();
        let corner = mesh.positions[curve.vertices[if at == 0 { 0 } else { nv - 1 }] as usize];
        (p - corner).normalize_or_zero()
    };
    'curves: for (length, curve) in candidates {
        let mut piece = FeaturePiece {
            curve,
            graded: [Vec::new(), Vec::new()],
            ladder: None,
        };
        // Up to two rounds: the even samples; then, where the first or last few crowd a curve
        // kept before that leaves the same corner (a small angle between them), both curves
        // graded towards that corner.
        let mut regrade: Vec<(usize, usize, Vec<f64>)> = Vec::new();
        let mut points = Vec::new();
        // The samples at its own corners are its own (also where other curves placed them): how
        // close its next samples come to them is its steps' business, not crowding.
        let own_ends: &[u32] = if piece.curve.closed {
            &[]
        } else {
            &ends(&piece.curve)
        };
        // For each of `points` (the piece's samples), the kept curves whose samples it crowds
        // (apart from a shared corner and from curves being graded for it).
        let crowding = |piece: &FeaturePiece,
                        points: &[(DVec3, usize)],
                        regrade: &[(usize, usize, Vec<f64>)]|
         -> Vec<Vec<usize>> {
            let last = points.len().saturating_sub(1);
            points
                .iter()
                .enumerate()
                .map(|(k, &(p, _))| {
                    let c = cell(p);
                    let here = end_vertex(&piece.curve, k, last);
                    let mut owners = Vec::new();
                    for dx in -1..=1 {
                        for dy in -1..=1 {
                            for dz in -1..=1 {
                                let Some(v) = placed.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else {
                                    continue;
                                };
                                for &(q, at, i, generation) in v {
                                    if kept[i].1 == generation
                                        && !at.is_some_and(|v| own_ends.contains(&v))
                                        && !here.is_some_and(|v| ends_at(&kept[i].0.curve, v))
                                        && p.distance(q) < gap * w(p).min(w(q))
                                        && !regrade.iter().any(|r| r.0 == i)
                                    {
                                        owners.push(i);
                                    }
                                }
                            }
                        }
                    }
                    owners.sort_unstable();
                    owners.dedup();
                    owners
                })
                .collect()
        };
        let taken = 'take: {
            for round in 0..2 {
                points = points_of(&piece);
                let last = points.len().saturating_sub(1);
                let crowded = crowding(&piece, &points, &regrade);
                let clear: Vec<bool> = crowded.iter().map(|o| o.is_empty()).collect();
                if clear.iter().all(|&c| c) {
                    break;
                }
                // A crowded sample anywhere but in a run at an end (a crease beside another
                // along its length), or still crowded after grading: the curve is left out
                // (or, with `ladders`, sampled as a ladder beside the others).
                if round == 1 || !crowded_only_at_ends(&clear, piece.curve.closed) {
                    break 'take false;
                }
                for end in [0usize, 1] {
                    let run: Vec<usize> = if end == 0 {
                        (1..last).take_while(|&k| !clear[k]).collect()
                    } else {
                        (1..last).rev().take_while(|&k| !clear[k]).collect()
                    };
                    if run.is_empty() {
                        continue;
                    }
                    let at = end_vertex(&piece.curve, if end == 0 { 0 } else { last }, last);
                    let mut owners: Vec<usize> = run
                        .iter()
                        .flat_map(|&k| crowded[k].iter().copied())
                        .collect();
                    owners.sort_unstable();
                    owners.dedup();
                    // Each crowded curve must leave the same corner.
                    let mut grading: Option<Vec<f64>> = None;
                    for &i in &owners {
                        let other = &kept[i].0;
                        let nv = other.curve.vertices.len();
                        let other_end = match at {
                            Some(v) if !other.curve.closed && other.curve.vertices[0] == v => 0,
                            Some(v) if !other.curve.closed && other.curve.vertices[nv - 1] == v => {
                                1
                            }
                            _ => break 'take false,
                        };
                        let angle = leaving(&piece.curve, end)
                            .angle_between(leaving(&other.curve, other_end));
                        if !(angle >= MIN_GRADED_CORNER_DEG.to_radians()) {
                            break 'take false;
                        }
                        // The other curve's grading at that corner, if it has one, is the one
                        // to pair with; else both get one for this angle.
                        let distances = if other.graded[other_end].is_empty() {
                            let cap = 0.45 * length.min(curve_length(mesh, &other.curve));
                            let corner = mesh.positions[at.unwrap_or(0) as usize];
                            graded_distances(angle, spacing * w(corner), cap)
                        } else {
                            other.graded[other_end].clone()
                        };
                        if grading.as_ref().is_none_or(|g| distances[0] > g[0]) {
                            grading = Some(distances.clone());
                        }
                        if other.graded[other_end].is_empty() {
                            regrade.push((i, other_end, distances));
                        }
                    }
                    if let Some(g) = grading {
                        piece.graded[end] = g;
                    }
                }
            }
            true
        };
        if !taken {
            if !ladders {
                continue 'curves;
            }
            // A ladder: its samples where the samples beside it project onto it, its own even
            // ones where nothing is beside it.
            regrade.clear();
            piece.graded = [Vec::new(), Vec::new()];
            let even = points_of(&piece);
            let clear: Vec<bool> = crowding(&piece, &even, &[])
                .iter()
                .map(|o| o.is_empty())
                .collect();
            let lengths = edge_lengths(mesh, &piece.curve);
            let starts: Vec<f64> = lengths
                .iter()
                .scan(0.0, |s, &l| {
                    let start = *s;
                    *s += l;
                    Some(start)
                })
                .collect();
            let nv = piece.curve.vertices.len();
            let own: Vec<(f64, bool)> = even
                .iter()
                .zip(&clear)
                .map(|(&(p, e), &c)| {
                    let a = mesh.positions[piece.curve.vertices[e % nv] as usize];
                    (starts[e] + a.distance(p), c)
                })
                .collect();
            // The samples of kept curves near it (apart from those at its own corners).
            let mut cells: FxHashSet<[i64; 3]> = FxHashSet::default();
            for k in 0..piece.curve.faces.len() {
                let (a, b) = (
                    mesh.positions[piece.curve.vertices[k] as usize],
                    mesh.positions[piece.curve.vertices[(k + 1) % nv] as usize],
                );
                for p in crate::geometry::segment::points_along(a, b, 0.5 * gap) {
                    let c = cell(p);
                    for dx in -1..=1 {
                        for dy in -1..=1 {
                            for dz in -1..=1 {
                                cells.insert([c[0] + dx, c[1] + dy, c[2] + dz]);
                            }
                        }
                    }
                }
            }
            let mut cells: Vec<[i64; 3]> = cells.into_iter().collect();
            cells.sort_unstable();
            let beside: Vec<DVec3> = cells
                .iter()
                .filter_map(|c| placed.get(c))
                .flatten()
                .filter(|&&(_, at, i, generation)| {
                    kept[i].1 == generation && !at.is_some_and(|v| own_ends.contains(&v))
                })
                .map(|&(q, ..)| q)
                .collect();
            let Some(arcs) = ladder_arcs(
                mesh,
                &piece.curve,
                &beside,
                |q| gap * w(q),
                &own,
                |x| spacing * w(x),
            ) else {
                continue 'curves;
            };
            piece.ladder = Some(arcs);
            points = points_of(&piece);
        }
        // The curves graded for this one are placed again.
        for (i, end, distances) in regrade {
            kept[i].0.graded[end] = distances;
            kept[i].1 += 1;
            let (piece_i, generation) = (kept[i].0.clone(), kept[i].1);
            place(&mut placed, &piece_i, &points_of(&piece_i), i, generation);
        }
        let index = kept.len();
        place(&mut placed, &piece, &points, index, 0);
        kept.push((piece, 0));
    }
    let pieces: Vec<FeaturePiece> = kept.into_iter().map(|(p, _)| p).collect();
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

/// The grading towards the corners creases are graded towards ([`corner_width`] at the creases'
/// `spacing`, bbox-100 units); 1 everywhere without corners. A corner grades only the points
/// within `spacing / g` of it, so a point asks the corners a kd-tree finds within the largest
/// such distance, not every corner (at a million samples on a scan, with thousands of corners,
/// the linear scan over them was most of the sampling's time).
pub struct Corners<'a> {
    corners: &'a [GradedCorner],
    spacing: f64,
    tree: StaticTree,
    /// The largest distance at which a corner grades, squared (`spacing / g` of the smallest g).
    reach_2: f64,
}

impl<'a> Corners<'a> {
    /// The grading towards `corners` at the creases' `spacing` (bbox-100 units).
    pub fn new(corners: &'a [GradedCorner], spacing: f64) -> Self {
        let positions: Vec<DVec3> = corners.iter().map(|c| c.position).collect();
        let reach = corners.iter().map(|c| spacing / c.g).fold(0.0f64, f64::max);
        Corners {
            corners,
            spacing,
            tree: StaticTree::new(&positions),
            // A hair more, for rounding at the edge of the reach (where the width is 1 anyway).
            reach_2: (reach * (1.0 + 1e-9)).powi(2),
        }
    }
}

impl SizingField for Corners<'_> {
    fn width(&self, p: DVec3) -> f64 {
        if !self.reach_2.is_finite() {
            // A corner of g 0 (or none finite) grades everything: ask each.
            return corner_width(self.corners, p, self.spacing);
        }
        let mut w = 1.0f64;
        self.tree.visit_within(p, self.reach_2, |i, _| {
            w = w.min(width_at(&self.corners[i as usize], p, self.spacing));
        });
        w
    }

    fn is_uniform(&self) -> bool {
        self.corners.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::boundary::boundary_curves;
    use crate::sampling::curves::sample_curves_and_features;
    use crate::sampling::sizing::Uniform;
    use crate::surface::features::{detect_features, FeatureParams};
    use glam::DVec3;

    #[test]
    fn the_indexed_corner_grading_is_the_grading_of_every_corner() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let mut v = |s: f64| {
            DVec3::new(
                rng.random_range(-s..s),
                rng.random_range(-s..s),
                rng.random_range(-s..s),
            )
        };
        let corners: Vec<GradedCorner> = (0..200)
            .map(|i| GradedCorner {
                position: v(10.0),
                g: 0.2 + (i % 7) as f64 * 0.25,
                directions: vec![v(1.0).normalize(), v(1.0).normalize()],
            })
            .collect();
        let field = Corners::new(&corners, 0.8);
        let mut graded = 0;
        for _ in 0..2000 {
            let p = v(11.0);
            let want = corner_width(&corners, p, 0.8);
            assert_eq!(field.width(p), want, "{p:?}");
            graded += usize::from(want < 1.0);
        }
        assert!(graded > 100, "{graded}: the case should grade some points");
        assert!(Corners::new(&[], 0.8).is_uniform());
        assert_eq!(Corners::new(&[], 0.8).width(DVec3::ZERO), 1.0);
    }

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
        let (boundary, feature) = feature_pieces(&mesh, &curves, &features, 0.1, &Uniform, false);
        assert_eq!(
            boundary.len(),
            2,
            "the loop is cut at the crease's two ends"
        );
        assert_eq!(feature.len(), 1);
        let b = sample_curves_and_features(&mesh, &boundary, &feature, 0.1, 0.1, &Uniform);
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
        let (boundary, feature) = feature_pieces(&mesh, &curves, &features, 1.5, &Uniform, false);
        assert!(feature.is_empty());
        assert_eq!(boundary, curves);
    }

    /// Two straight creases leaving the corner (0, 30) of a 60 × 60 grid, one along the row
    /// j = 30 and one rising 1 in 3 (18.4° between them): both are kept, graded alike towards
    /// the corner, and their samples pair up across the strip between them.
    #[test]
    fn creases_at_a_small_angle_are_graded_towards_their_corner() {
        use crate::surface::features::FeatureCurve;
        let n = 60;
        let mesh = crate::mesh::test_meshes::grid(n, |i, j| DVec3::new(i as f64, j as f64, 0.0));
        let at = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let row: Vec<u32> = (0..=n).map(|i| at(i, 30)).collect();
        let rising: Vec<u32> = (0..=20).map(|k| at(3 * k, 30 + k)).collect();
        let curve = FeatureCurve::open;
        let features = Features {
            edges: Vec::new(),
            curves: vec![curve(row), curve(rising)],
            corners: vec![at(0, 30), at(60, 30), at(60, 50)],
        };
        let spacing = 2.0;
        let (_, pieces) = feature_pieces(&mesh, &[], &features, spacing, &Uniform, false);
        assert_eq!(pieces.len(), 2, "both creases are kept");
        let angle = (1.0f64 / 3.0).atan();
        let expected = graded_distances(angle, spacing, f64::INFINITY);
        for p in &pieces {
            assert_eq!(p.graded[0].len(), expected.len());
            for (a, b) in p.graded[0].iter().zip(&expected) {
                assert!((a - b).abs() < 1e-9, "{:?}", p.graded[0]);
            }
        }
        assert_eq!(pieces[0].graded[0], pieces[1].graded[0], "the same on both");
        assert!(pieces.iter().all(|p| p.graded[1].is_empty()));
        // The graded part: from where the gap is the spacing down to half the spacing, each
        // step inward shrinking by 1 + gap / r.
        let g = 2.0 * (0.5 * angle).sin();
        assert!((expected[0] - spacing / g).abs() < 1e-12);
        assert!(*expected.last().unwrap() >= 0.5 * spacing);
        for w in expected.windows(2) {
            assert!((w[0] / w[1] - (1.0 + g)).abs() < 1e-12);
        }
        let b = sample_curves_and_features(&mesh, &[], &pieces, spacing, spacing, &Uniform);
        // One shared corner sample; samples at equal distances from it on both creases.
        let corner = DVec3::new(0.0, 30.0, 0.0);
        let dist = |s: &crate::surface::SurfaceSample| s.position.distance(corner);
        let on_row: Vec<f64> = b
            .samples
            .iter()
            .filter(|s| s.position.y == 30.0)
            .map(dist)
            .collect();
        let on_rising: Vec<f64> = b
            .samples
            .iter()
            .filter(|s| s.position.y > 30.0)
            .map(dist)
            .collect();
        for r in &expected {
            assert!(
                on_row.iter().any(|d| (d - r).abs() < 1e-9),
                "{r} on the row"
            );
            assert!(
                on_rising.iter().any(|d| (d - r).abs() < 1e-9),
                "{r} on the rising crease"
            );
        }
        // Beyond the graded part the steps are even and within 10% of the spacing.
        for e in &b.feature_edges {
            let (p, q) = (
                b.samples[e[0] as usize].position,
                b.samples[e[1] as usize].position,
            );
            let far = p.distance(corner).min(q.distance(corner)) >= expected[0] - 1e-9;
            if far {
                assert!(
                    (p.distance(q) / spacing - 1.0).abs() <= 0.1,
                    "{}",
                    p.distance(q)
                );
            }
        }
        // Without the second crease, the row is sampled evenly up to the corner.
        let alone = Features {
            curves: vec![features.curves[0].clone()],
            ..features.clone()
        };
        let (_, pieces) = feature_pieces(&mesh, &[], &alone, spacing, &Uniform, false);
        assert!(pieces[0].graded.iter().all(|g| g.is_empty()));
    }

    /// A crease 1.5 spacings long between the corners of two long parallel creases (fandisk's
    /// narrow face): its two steps of 0.75 spacing bring its middle sample closer than the gap
    /// to its own corners, which the long creases placed; that is its steps' business, and it
    /// is kept.
    #[test]
    fn a_short_crease_is_not_crowded_by_the_samples_at_its_own_corners() {
        use crate::surface::features::FeatureCurve;
        let n = 24;
        let mesh = crate::mesh::test_meshes::grid(n, |i, j| {
            DVec3::new(0.5 * i as f64, 0.5 * j as f64, 0.0)
        });
        let at = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let curve = FeatureCurve::open;
        let lower: Vec<u32> = (0..=20).rev().map(|i| at(i, 10)).collect();
        let upper: Vec<u32> = (0..=20).rev().map(|i| at(i, 13)).collect();
        let short: Vec<u32> = (10..=13).map(|j| at(20, j)).collect();
        let features = Features {
            edges: Vec::new(),
            curves: vec![curve(lower), curve(upper), curve(short)],
            corners: vec![at(20, 10), at(20, 13), at(0, 10), at(0, 13)],
        };
        let spacing = 1.0;
        let (_, pieces) = feature_pieces(&mesh, &[], &features, spacing, &Uniform, false);
        assert_eq!(pieces.len(), 3, "the short crease is kept");
        let b = sample_curves_and_features(&mesh, &[], &pieces, spacing, spacing, &Uniform);
        let on_short = b.samples.iter().filter(|s| s.position.x == 10.0).count();
        assert_eq!(on_short, 3, "its corners and one sample between them");
    }
}
