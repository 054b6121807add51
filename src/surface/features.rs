//! Sharp features of an input mesh: crease edges, chained into curves, and their corners.
//!
//! A feature edge is an interior edge of two faces whose normals differ by at least the feature
//! angle, and nearly as much near it (the faces within a quarter of the scale, by area: a sliver
//! whose normal noise in the positions has tilted is no crease), and still do at the sampling's
//! scale: the surface within `scale` of the edge, on either side of it, has mean normals that
//! differ by the feature angle too. The test at the scale is what tells
//! a crease of a part (fandisk, a CSG flange) from the folds and spikes a scan leaves at the scale
//! of its own triangles (horse, bunny), which are sharp between two faces but smooth a sample
//! spacing away; an edge that continues a crease (a crease fading out) is one too. Feature edges
//! are chained into curves that end at corners: vertices where one, three or more feature edges
//! meet, where a feature curve meets the boundary, or where a curve turns by the feature angle
//! or more, between its two edges and still between its chords a quarter of the scale long (a
//! crease's short edges, turned by noise in a CAD export's positions, make no corner).
//!
//! # References
//! The dihedral-angle test is the one of MeshLab's and CGAL's feature detection
//! (`CGAL::Polygon_mesh_processing::detect_sharp_edges`); the scale test is ours.

use glam::DVec3;
use rayon::prelude::*;
use rustc_hash::{FxHashMap, FxHashSet};

use crate::geometry::segment::distance_to_segment;
use crate::mesh::TriMesh;
use crate::surface::MeshSurface;

/// How [`remesh`](crate::remesh) finds the sharp features of its input.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum FeatureDetection {
    /// No detection: every part of the input is sampled alike.
    Off,
    /// Detection at [`CAD_FEATURE_ANGLE_DEG`], the creases kept when they are a part's: when at
    /// least [`AUTO_FEATURE_MIN_SHARE`] of their length lies in curves at least
    /// [`LONG_CURVE_SPACINGS`] sample spacings long ([`long_curve_share`]); or when that share
    /// of their length lies in curves that are long or run from junction to junction
    /// ([`junction_curve_share`]), the creases lie more than a spacing apart on average (length
    /// times spacing over area at most [`MAX_CREASE_DENSITY`]) and the surface shows a gap
    /// between its creases and the rest: detection at [`GAP_ANGLE_DEG`] finds at most
    /// [`MAX_GAP_RATIO`] times the length it finds at the feature angle. The creases of a CAD
    /// part run from corner to corner, and between them the surface is smooth; a scan's folds
    /// are sharp at its own scale in short pieces, the sharp end of bends of every angle, and
    /// sampled as creases they leave poor triangles and no closer surface (the shares and
    /// figures: `docs/decisions/feature-angle-auto.md`). The default.
    #[default]
    Auto,
    /// Detection at this feature angle (degrees; 180 or more: off), every crease kept.
    Angle(f64),
}

impl FeatureDetection {
    /// The feature angle detection runs at, degrees (180: none).
    pub fn angle_deg(&self) -> f64 {
        match self {
            FeatureDetection::Off => 180.0,
            FeatureDetection::Auto => CAD_FEATURE_ANGLE_DEG,
            FeatureDetection::Angle(a) => *a,
        }
    }
}

/// Feature curves at least this many sample spacings long are long ([`long_curve_share`]).
pub const LONG_CURVE_SPACINGS: f64 = 3.0;

/// The least share of the creases' length in long curves for [`FeatureDetection::Auto`] to keep
/// them.
pub const AUTO_FEATURE_MIN_SHARE: f64 = 0.9;

/// The angle (degrees) of the second detection that tells a part's creases from a scan's folds
/// ([`FeatureDetection::Auto`]): half the feature angle, where a scan's bends are still found
/// and a part's smooth surfaces show nothing.
pub const GAP_ANGLE_DEG: f64 = 10.0;

/// The most crease length times the sample spacing over the surface's area for short creases
/// to be a part's ([`FeatureDetection::Auto`]): creases more than one spacing apart on average,
/// their samples under half of all. A surface crumpled at the spacing has a crease along most
/// of its edges (2.8-3.0 on a noisy sphere); the gear of eval/cad_parts.py at 3,000 vertices 0.33.
pub const MAX_CREASE_DENSITY: f64 = 1.0;

/// The most length detection at [`GAP_ANGLE_DEG`] may find, relative to that at the feature
/// angle, for the creases to stand apart from the rest of the surface. Measured at the sample
/// spacing of 3,000 and 13,000 vertices: the CAD parts 1.00-1.12 (fandisk, bracket, flange and
/// the parts of eval/cad_parts.py), the scans 1.6-5.6 (beetle 1.6, cow 2.0, spot 2.6, pymeshlab's
/// airplane 2.9, horse 4.2, bunny 4.6, bone 5.5).
pub const MAX_GAP_RATIO: f64 = 1.3;

/// The share of the total length of `features`' curves (positions `positions`) that lies in
/// curves at least [`LONG_CURVE_SPACINGS`] · `spacing` long; 0 without curves.
pub fn long_curve_share(features: &Features, positions: &[DVec3], spacing: f64) -> f64 {
    curve_share(features, positions, |_, l| {
        l >= LONG_CURVE_SPACINGS * spacing
    })
}

/// The share of the total length of `features`' curves (positions `positions`) that lies in
/// curves that are closed, at least [`LONG_CURVE_SPACINGS`] · `spacing` long, or run from
/// junction to junction (both ends at vertices where three or more feature edges meet): the
/// short edges of a part, such as a gear's tooth flanks, run between such junctions. 0 without
/// curves.
pub fn junction_curve_share(features: &Features, positions: &[DVec3], spacing: f64) -> f64 {
    let mut valence = vec![0u8; positions.len()];
    for v in features.edges.iter().flatten() {
        valence[*v as usize] = valence[*v as usize].saturating_add(1);
    }
    let junction = |v: Option<&u32>| v.is_some_and(|&v| valence[v as usize] >= 3);
    curve_share(features, positions, |c, l| {
        c.closed
            || l >= LONG_CURVE_SPACINGS * spacing
            || (junction(c.vertices.first()) && junction(c.vertices.last()))
    })
}

/// The share of the total length of `features`' curves in those `counts` takes (given the curve
/// and its length); 0 without curves.
fn curve_share(
    features: &Features,
    positions: &[DVec3],
    counts: impl Fn(&FeatureCurve, f64) -> bool,
) -> f64 {
    let (mut total, mut counted) = (0.0, 0.0);
    for c in &features.curves {
        let l = c.length(positions);
        total += l;
        if counts(c, l) {
            counted += l;
        }
    }
    if !(total > 0.0) {
        return 0.0;
    }
    counted / total
}

/// The feature angle (degrees) measured for CAD parts: on fandisk the Hausdorff distance falls
/// from 55° down to 20°, as a crease that fades is followed further, and below 20° nothing
/// improves; parts not tuned on are the same or better at 20° than at 55° (the figures:
/// `docs/decisions/feature-angle-20.md`).
pub const CAD_FEATURE_ANGLE_DEG: f64 = 20.0;

/// Parameters of [`detect_features`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeatureParams {
    /// The least angle (degrees) between the normals either side of an edge for it to be a
    /// crease, and the least turn of a feature curve at a vertex for the vertex to be a corner
    /// (between its two edges and between its chords a quarter of `scale` long).
    /// 180 or more turns detection off (see [`FeatureDetection`]).
    pub angle_deg: f64,
    /// How far across an edge (bbox-100 units when the mesh is normalized) the surface must
    /// still show the angle: the sample spacing, so that a crease is one the samples can follow.
    /// 0 tests the two faces of the edge only.
    pub scale: f64,
}

/// A chain of feature edges: input vertex indices in order. An open curve runs from a corner to
/// a corner; a closed one has no corner and does not repeat its first vertex.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureCurve {
    /// Input vertex indices along the curve.
    pub vertices: Vec<u32>,
    /// For each edge `vertices[k] → vertices[k+1]` (and, for a closed curve, last → first): a
    /// face on it, the one that has the edge in this direction where one does.
    pub faces: Vec<u32>,
    /// Whether the curve closes on itself.
    pub closed: bool,
}

/// What [`detect_features`] found.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Features {
    /// The feature edges, each `[a, b]` with `a < b`, sorted.
    pub edges: Vec<[u32; 2]>,
    /// The edges chained into curves (every feature edge in exactly one curve).
    pub curves: Vec<FeatureCurve>,
    /// The corners, ascending: the ends of the open curves.
    pub corners: Vec<u32>,
}

impl FeatureCurve {
    /// An open curve through `vertices`, every edge on face 0 (tests' curves).
    #[cfg(test)]
    pub(crate) fn open(vertices: Vec<u32>) -> Self {
        FeatureCurve {
            faces: vec![0; vertices.len() - 1],
            vertices,
            closed: false,
        }
    }

    /// The curve's length: the sum of its edges, `vertices[k] → vertices[k+1]` and, closed,
    /// the last back to the first (units of `positions`).
    pub fn length(&self, positions: &[DVec3]) -> f64 {
        let nv = self.vertices.len();
        let pos = |k: usize| positions[self.vertices[k % nv] as usize];
        (0..self.faces.len())
            .map(|k| pos(k).distance(pos(k + 1)))
            .sum()
    }
}

impl Features {
    /// Total length of the feature edges (units of the mesh).
    pub fn length(&self, positions: &[DVec3]) -> f64 {
        self.edges
            .iter()
            .map(|e| positions[e[0] as usize].distance(positions[e[1] as usize]))
            .sum()
    }
}

/// The sharp features of `surface`'s mesh (see the module docs). The mesh should be oriented
/// consistently (the pipeline's `orient_consistently`): two faces of an edge with opposite
/// orientations read as a fold of 180°. Edges of one face (the boundary) or of three or more
/// (non-manifold) are not feature edges, and degenerate faces give none. Deterministic.
///
/// # Runtime
/// One pass over the edges; for each edge that passes the dihedral test, a walk over the faces
/// within a quarter of `scale` of it and, for those that pass that, over the faces within
/// `scale` (both in parallel); for each crease edge longer than half of `scale`, a walk per
/// piece of it; for each crease edge, a search of at most `CHORD_PATH_STEPS` steps over the
/// creases beside it.
pub fn detect_features(surface: &MeshSurface, params: &FeatureParams) -> Features {
    let mesh = surface.mesh();
    if !(params.angle_deg < 180.0) {
        return Features::default();
    }
    let cos_bound = params.angle_deg.to_radians().cos();
    // The near test's radius and the cosine of the turn it asks for.
    let r = NEAR_SCALE_SHARE * params.scale;
    let cos_near = (NEAR_TURN_SHARE * params.angle_deg).to_radians().cos();
    // Undirected edge -> the faces that use it (the first two) and how many do.
    let uses = mesh.edge_uses();
    let mut boundary_vertex = vec![false; mesh.positions.len()];
    let mut candidates: Vec<([u32; 2], [u32; 2])> = Vec::new();
    for (&(a, b), &(faces, n)) in &uses {
        if n == 1 {
            boundary_vertex[a as usize] = true;
            boundary_vertex[b as usize] = true;
        } else if n == 2 {
            let (n0, n1) = (surface.face_normal(faces[0]), surface.face_normal(faces[1]));
            if n0 != DVec3::ZERO && n1 != DVec3::ZERO && n0.dot(n1) <= cos_bound {
                candidates.push(([a, b], faces));
            }
        }
    }
    candidates.sort_unstable();
    let mut adjacency = FaceAdjacency::new(mesh, &uses);
    // Near the edge too, not only between its two faces: a sliver's normal, tilted or flipped
    // by noise in a CAD export's positions, turns by the angle on a flat.
    if params.scale > 0.0 {
        candidates = candidates
            .into_par_iter()
            .map_init(
                || PatchScratch::new(mesh.triangles.len()),
                |scratch, (e, faces)| {
                    sharp_near_edge(&adjacency, scratch, e, faces, r, cos_near, false)
                        .then_some((e, faces))
                },
            )
            .flatten()
            .collect();
    }
    // The scale test, in two steps (hysteresis, as in Canny's edge detection): an edge is a
    // crease when the surface a spacing either side of it bends by the angle; and an edge joined
    // through a chain of such edges to a crease is one too when the smooth sheets beside it (not
    // crossing any other dihedral candidate) bend by the angle, or when it continues the crease
    // (the only other candidate at their vertex, turning by less than the angle there). The
    // second step keeps a crease whole up to a corner where it meets another at a small angle
    // (within a spacing of the corner, a patch either side takes in the sheet beyond the other
    // crease), and leaves alone a fold narrower than the spacing that no crease leads to (its
    // flanks are sheets between candidates too).
    adjacency.mark_candidates(&candidates);
    let mut sharp: Vec<bool> = candidates
        .par_iter()
        .map_init(
            || PatchScratch::new(mesh.triangles.len()),
            |scratch, (e, faces)| {
                sharp_at_scale(
                    &adjacency,
                    false,
                    scratch,
                    *e,
                    *faces,
                    params.scale,
                    cos_bound,
                )
            },
        )
        .collect();
    if params.scale > 0.0 && sharp.iter().any(|&s| !s) {
        let mut at_vertex: FxHashMap<u32, Vec<usize>> = FxHashMap::default();
        for (i, (e, _)) in candidates.iter().enumerate() {
            at_vertex.entry(e[0]).or_default().push(i);
            at_vertex.entry(e[1]).or_default().push(i);
        }
        // Whether candidate `j` continues crease `i` through their vertex `v`: the only two
        // candidates there, off the boundary, turning there by less than the angle (chained into
        // one curve). A crease fading out (fandisk's: 36°, 32°, 28°, 24°, 23° on its last
        // edges) keeps its last edges that way, where a spacing either side no longer bends by
        // the angle.
        let continues = |i: usize, j: usize, v: u32| -> bool {
            let p = mesh.positions[v as usize];
            let far = |k: usize| {
                let e = candidates[k].0;
                mesh.positions[if e[0] == v { e[1] } else { e[0] } as usize]
            };
            at_vertex[&v].len() == 2
                && !boundary_vertex[v as usize]
                && turns_less_than(far(i), p, far(j), cos_bound)
        };
        let mut scratch = PatchScratch::new(mesh.triangles.len());
        // Grown from the creases, one vertex at a time; each edge's patch tested at most once
        // (a continuation is taken whenever the crease it continues is, so the set grown does
        // not depend on the order).
        let mut tested = sharp.clone();
        let mut stack: Vec<usize> = (0..candidates.len()).filter(|&i| sharp[i]).collect();
        while let Some(i) = stack.pop() {
            for v in candidates[i].0 {
                for &j in &at_vertex[&v] {
                    if sharp[j] {
                        continue;
                    }
                    let take = continues(i, j, v)
                        || (!tested[j] && {
                            tested[j] = true;
                            let (e, faces) = candidates[j];
                            sharp_at_scale(
                                &adjacency,
                                true,
                                &mut scratch,
                                e,
                                faces,
                                params.scale,
                                cos_bound,
                            )
                        });
                    if take {
                        sharp[j] = true;
                        stack.push(j);
                    }
                }
            }
        }
    }
    // After the scale test: gaps in crease chains closed, long crease edges tested along their
    // length, chords across a path of creases dropped (noise in a CAD export's positions).
    if params.scale > 0.0 {
        close_gaps(
            &adjacency,
            &uses,
            &boundary_vertex,
            &mut candidates,
            &mut sharp,
            r,
            cos_near,
            cos_bound,
        );
        drop_long_edges_turning_short(&adjacency, &candidates, &mut sharp, r, cos_near);
        drop_chords(mesh, &candidates, &mut sharp, r);
    }
    // Sorted by edge (the gaps closed came last).
    let mut kept: Vec<([u32; 2], [u32; 2])> = candidates
        .iter()
        .zip(&sharp)
        .filter(|(_, &s)| s)
        .map(|(c, _)| *c)
        .collect();
    kept.sort_unstable();
    let (edges, edge_faces): (Vec<[u32; 2]>, Vec<[u32; 2]>) = kept.into_iter().unzip();
    let (curves, corners) = chain(mesh, &edges, &edge_faces, &boundary_vertex, cos_bound, r);
    Features {
        edges,
        curves,
        corners,
    }
}

/// Closes gaps in the crease chains of `candidates` (those marked in `sharp`): from a chain's
/// end off the boundary, the mesh edges (of two faces in `uses`) that go on most straight,
/// turning by less than the angle whose cosine is `cos_bound` at each vertex and passing the
/// near test ([`sharp_near_edge`] at `r`, `cos_near`), at most [`GAP_STEPS`], are added as
/// creases when they reach another crease. Noise in a CAD export's positions tilts the slivers
/// beside a rim until their edges no longer pass the dihedral test, and the rim falls into
/// pieces. Deterministic (chain ends in vertex order).
#[allow(clippy::too_many_arguments)]
fn close_gaps(
    adjacency: &FaceAdjacency,
    uses: &FxHashMap<(u32, u32), ([u32; 2], u32)>,
    boundary_vertex: &[bool],
    candidates: &mut Vec<([u32; 2], [u32; 2])>,
    sharp: &mut Vec<bool>,
    r: f64,
    cos_near: f64,
    cos_bound: f64,
) {
    let mesh = adjacency.mesh;
    let mut degree: FxHashMap<u32, Vec<u32>> = FxHashMap::default();
    for (i, (e, _)) in candidates.iter().enumerate() {
        if sharp[i] {
            degree.entry(e[0]).or_default().push(e[1]);
            degree.entry(e[1]).or_default().push(e[0]);
        }
    }
    let mut ends: Vec<(u32, u32)> = degree
        .iter()
        .filter(|(&v, list)| list.len() == 1 && !boundary_vertex[v as usize])
        .map(|(&v, list)| (v, list[0]))
        .collect();
    ends.sort_unstable();
    if ends.is_empty() {
        return;
    }
    // Each vertex's neighbours across edges of two faces, in index order.
    let mut neighbours: FxHashMap<u32, Vec<u32>> = FxHashMap::default();
    for (&(a, b), &(_, n)) in uses {
        if n == 2 {
            neighbours.entry(a).or_default().push(b);
            neighbours.entry(b).or_default().push(a);
        }
    }
    for list in neighbours.values_mut() {
        list.sort_unstable();
    }
    let mut scratch = PatchScratch::new(mesh.triangles.len());
    let mut added: Vec<([u32; 2], [u32; 2])> = Vec::new();
    let mut taken: FxHashSet<(u32, u32)> = FxHashSet::default();
    for (end, before) in ends {
        let (mut x, mut from) = (end, mesh.positions[before as usize]);
        let mut path: Vec<([u32; 2], [u32; 2])> = Vec::new();
        let mut joined = false;
        for _ in 0..GAP_STEPS {
            let px = mesh.positions[x as usize];
            let d = (px - from).normalize_or_zero();
            let next = neighbours.get(&x).and_then(|list| {
                list.iter()
                    .copied()
                    .map(|y| {
                        (
                            d.dot((mesh.positions[y as usize] - px).normalize_or_zero()),
                            y,
                        )
                    })
                    .filter(|&(c, _)| c > cos_bound)
                    .max_by(|a, b| a.0.total_cmp(&b.0).then(b.1.cmp(&a.1)))
            });
            let Some((_, y)) = next else { break };
            let e = [x.min(y), x.max(y)];
            if taken.contains(&(e[0], e[1])) || degree.get(&x).is_some_and(|l| l.contains(&y)) {
                break;
            }
            let Some(&(faces, 2)) = uses.get(&(e[0], e[1])) else {
                break;
            };
            if !sharp_near_edge(adjacency, &mut scratch, e, faces, r, cos_near, false) {
                break;
            }
            path.push((e, faces));
            if degree.contains_key(&y) {
                joined = true;
                break;
            }
            (from, x) = (px, y);
        }
        if joined {
            for (e, faces) in path {
                if taken.insert((e[0], e[1])) {
                    added.push((e, faces));
                }
            }
        }
    }
    for c in added {
        candidates.push(c);
        sharp.push(true);
    }
}

/// Unmarks in `sharp` each crease edge of `candidates` longer than the near test's ball (2 `r`)
/// that does not turn along at least half of its length ([`sharp_near_edge`] with `along`): a
/// CAD export's long sliver edge tangent to a hole's rim is within `r` of the rim at its middle
/// only. Run after the scale test, whose patches stop at the candidates as they were. In
/// parallel; deterministic.
fn drop_long_edges_turning_short(
    adjacency: &FaceAdjacency,
    candidates: &[([u32; 2], [u32; 2])],
    sharp: &mut [bool],
    r: f64,
    cos_near: f64,
) {
    let mesh = adjacency.mesh;
    let long: Vec<usize> = (0..candidates.len())
        .filter(|&i| {
            let e = candidates[i].0;
            sharp[i]
                && mesh.positions[e[0] as usize].distance(mesh.positions[e[1] as usize]) > 2.0 * r
        })
        .collect();
    let fails: Vec<usize> = long
        .into_par_iter()
        .map_init(
            || PatchScratch::new(mesh.triangles.len()),
            |scratch, i| {
                let (e, faces) = candidates[i];
                (!sharp_near_edge(adjacency, scratch, e, faces, r, cos_near, true)).then_some(i)
            },
        )
        .flatten()
        .collect();
    for i in fails {
        sharp[i] = false;
    }
}

/// Unmarks in `sharp` each crease edge of `candidates` that is a chord across a path of shorter
/// crease edges between its ends and beside it: within `r` of it (the near test's radius, where
/// that test cannot tell the two apart), at most [`CHORD_PATH_STEPS`] steps, each within 45° of
/// its direction ([`CHORD_PATH_COS`]). The path carries the crease: a CAD export's fan of
/// slivers from a vertex of a hole's rim to the next ones, tilted by noise; sampled too, the
/// chord would be a second crease beside it. Longest first, each path through the edges left.
/// Deterministic.
fn drop_chords(mesh: &TriMesh, candidates: &[([u32; 2], [u32; 2])], sharp: &mut [bool], r: f64) {
    let length = |i: usize| {
        let e = candidates[i].0;
        mesh.positions[e[0] as usize].distance(mesh.positions[e[1] as usize])
    };
    let mut at_vertex: FxHashMap<u32, Vec<usize>> = FxHashMap::default();
    let mut order: Vec<usize> = (0..candidates.len()).filter(|&i| sharp[i]).collect();
    for &i in &order {
        let e = candidates[i].0;
        at_vertex.entry(e[0]).or_default().push(i);
        at_vertex.entry(e[1]).or_default().push(i);
    }
    order.sort_by(|&i, &j| length(j).total_cmp(&length(i)).then(i.cmp(&j)));
    for i in order {
        let [a, b] = candidates[i].0;
        let (pa, pb, li) = (
            mesh.positions[a as usize],
            mesh.positions[b as usize],
            length(i),
        );
        let mut stack = vec![(a, 0usize)];
        let mut seen = vec![a];
        let mut chord = false;
        'search: while let Some((v, steps)) = stack.pop() {
            for &j in &at_vertex[&v] {
                if j == i || !sharp[j] || length(j) >= li {
                    continue;
                }
                let e = candidates[j].0;
                let w = if e[0] == v { e[1] } else { e[0] };
                let (pv, pw) = (mesh.positions[v as usize], mesh.positions[w as usize]);
                if (pw - pv).normalize_or_zero().dot((pb - pa) / li) < CHORD_PATH_COS {
                    continue;
                }
                if w == b {
                    chord = true;
                    break 'search;
                }
                if steps + 1 < CHORD_PATH_STEPS
                    && !seen.contains(&w)
                    && distance_to_segment(pw, pa, pb) <= r
                {
                    seen.push(w);
                    stack.push((w, steps + 1));
                }
            }
        }
        if chord {
            sharp[i] = false;
        }
    }
}

/// The faces of `mesh` and each face's neighbour across each of its edges (`tri[k]`–`tri[k + 1]`):
/// the other face of an edge with exactly two faces, [`FaceAdjacency::NONE`] across a boundary or
/// non-manifold edge; and whether that edge is a dihedral candidate. Built once, so the patches of
/// [`sharp_at_scale`] are walked by index instead of by hashing each edge.
struct FaceAdjacency<'a> {
    mesh: &'a TriMesh,
    across: Vec<[u32; 3]>,
    candidate: Vec<[bool; 3]>,
    /// Each face's centroid ([`centroid`]) and twice its area-weighted normal (the cross
    /// product of two edges), computed once: the patch tests visit a face from many edges.
    centroids: Vec<DVec3>,
    area_normals: Vec<DVec3>,
}

impl<'a> FaceAdjacency<'a> {
    const NONE: u32 = u32::MAX;

    /// The faces across each face's edges, no edge a candidate yet.
    fn new(mesh: &'a TriMesh, uses: &FxHashMap<(u32, u32), ([u32; 2], u32)>) -> Self {
        let across = mesh
            .triangles
            .iter()
            .enumerate()
            .map(|(f, tri)| {
                let mut across = [Self::NONE; 3];
                for k in 0..3 {
                    let (a, b) = (tri[k], tri[(k + 1) % 3]);
                    if let Some(&(pair, 2)) = uses.get(&(a.min(b), a.max(b))) {
                        across[k] = if pair[0] == f as u32 {
                            pair[1]
                        } else {
                            pair[0]
                        };
                    }
                }
                across
            })
            .collect();
        let area_normals = (0..mesh.triangles.len())
            .map(|f| {
                let t = mesh.corners(f);
                (t[1] - t[0]).cross(t[2] - t[0])
            })
            .collect();
        FaceAdjacency {
            mesh,
            across,
            candidate: vec![[false; 3]; mesh.triangles.len()],
            centroids: (0..mesh.triangles.len() as u32)
                .map(|f| centroid(mesh, f))
                .collect(),
            area_normals,
        }
    }

    /// Marks the edges of `candidates` (the dihedral candidates) as such.
    fn mark_candidates(&mut self, candidates: &[([u32; 2], [u32; 2])]) {
        let candidate_edges: FxHashSet<(u32, u32)> =
            candidates.iter().map(|(e, _)| (e[0], e[1])).collect();
        for (tri, flags) in self.mesh.triangles.iter().zip(&mut self.candidate) {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                flags[k] = candidate_edges.contains(&(a.min(b), a.max(b)));
            }
        }
    }
}

/// The faces a patch of [`sharp_at_scale`] or [`sharp_near_edge`] reached, with a bit per side: a byte per face of
/// the mesh and the list of those set, so each patch costs what it reaches (one per thread).
struct PatchScratch {
    bits: Vec<u8>,
    reached: Vec<u32>,
}

impl PatchScratch {
    fn new(faces: usize) -> Self {
        PatchScratch {
            bits: vec![0; faces],
            reached: Vec::new(),
        }
    }

    /// Whether face `f` has `bit` set.
    fn has(&self, f: u32, bit: u8) -> bool {
        self.bits[f as usize] & bit != 0
    }

    /// Sets `bit` on face `f`; whether it was not set before.
    fn mark(&mut self, f: u32, bit: u8) -> bool {
        let b = &mut self.bits[f as usize];
        if *b & bit != 0 {
            return false;
        }
        if *b == 0 {
            self.reached.push(f);
        }
        *b |= bit;
        true
    }

    /// Calls `visit` with each face reached and its bits, in the order they were first reached
    /// (the same for the same input: the patches grow in a fixed order); the scratch is empty
    /// after.
    fn drain(&mut self, mut visit: impl FnMut(u32, u8)) {
        for &f in &self.reached {
            visit(f, std::mem::take(&mut self.bits[f as usize]));
        }
        self.reached.clear();
    }
}

/// The most faces [`sharp_at_scale`] and [`sharp_near_edge`] take on each side of an edge.
const PATCH_FACES: usize = 1024;

/// Whether the surface within `scale` of edge `e`'s midpoint still bends by the feature angle
/// (`cos_bound` its cosine) across the edge: the area-weighted normals of the faces on either side
/// at least the angle apart. The patch is grown from the edge's two faces across edges to faces
/// whose centroids are within `scale` (over `adjacency`), never across a dihedral candidate when
/// `barriers` is set: so near a corner where creases meet, each side is the smooth sheet beside the
/// edge and not a sheet beyond another crease. Each face of the patch counts on the side of the
/// edge it lies on (the half of the patch nearer one of the two faces' half-planes). True when
/// `scale` is 0.
fn sharp_at_scale(
    adjacency: &FaceAdjacency,
    barriers: bool,
    scratch: &mut PatchScratch,
    e: [u32; 2],
    faces: [u32; 2],
    scale: f64,
    cos_bound: f64,
) -> bool {
    if !(scale > 0.0) {
        return true;
    }
    let mesh = adjacency.mesh;
    let Some(frame) = EdgeFrame::new(mesh, e, faces) else {
        return false;
    };
    let mid = frame.mid;
    let scale_2 = scale * scale;
    // Each side's patch: grown from its face, across edges other than the dihedral candidates
    // (the edge itself included), to faces whose centroids are within `scale`. A bit per side.
    // Breadth first, at most PATCH_FACES faces a side: on a finely tessellated part (tens of
    // thousands of faces within a spacing of its creases) each patch is then the nearest faces
    // by steps, and the test costs O(PATCH_FACES) per edge whatever the tessellation.
    for (side, &seed) in faces.iter().enumerate() {
        let bit = 1u8 << side;
        scratch.mark(seed, bit);
        let mut queue = std::collections::VecDeque::from([seed]);
        let mut taken = 1;
        while let Some(f) = queue.pop_front() {
            if taken >= PATCH_FACES {
                break;
            }
            for k in 0..3 {
                let g = adjacency.across[f as usize][k];
                if g == FaceAdjacency::NONE || (barriers && adjacency.candidate[f as usize][k]) {
                    continue;
                }
                if !scratch.has(g, bit)
                    && adjacency.centroids[g as usize].distance_squared(mid) <= scale_2
                    && scratch.mark(g, bit)
                {
                    queue.push_back(g);
                    taken += 1;
                }
            }
        }
    }
    // A face reached from one side only counts on that side; one reached from both (round the
    // end of a crease, or across a fold that is not one) on the side of the edge it lies on.
    let mut sides = [DVec3::ZERO; 2];
    scratch.drain(|f, bits| {
        // Area-weighted normal: the cross product's half.
        sides[frame.side(adjacency, f, bits)] += adjacency.area_normals[f as usize];
    });
    let (n0, n1) = (sides[0].normalize_or_zero(), sides[1].normalize_or_zero());
    n0 != DVec3::ZERO && n1 != DVec3::ZERO && n0.dot(n1) <= cos_bound
}

/// The centroid of face `f` of `mesh`.
fn centroid(mesh: &TriMesh, f: u32) -> DVec3 {
    let c = mesh.corners(f as usize);
    (c[0] + c[1] + c[2]) / 3.0
}

/// An edge seen from its two faces, for the patch tests ([`sharp_at_scale`],
/// [`sharp_near_edge`]): its midpoint, and the normal of the plane through the edge that parts
/// the two faces (the difference of the directions into each, across the edge, in its plane).
struct EdgeFrame {
    mid: DVec3,
    split: DVec3,
}

impl EdgeFrame {
    /// None when the two faces lie on the same side of the edge (no plane parts them).
    fn new(mesh: &TriMesh, e: [u32; 2], faces: [u32; 2]) -> Option<Self> {
        let (pa, pb) = (mesh.positions[e[0] as usize], mesh.positions[e[1] as usize]);
        let mid = 0.5 * (pa + pb);
        let along = (pb - pa).normalize_or_zero();
        let across = |f: u32| -> DVec3 {
            let d = centroid(mesh, f) - mid;
            (d - along * d.dot(along)).normalize_or_zero()
        };
        let split = across(faces[0]) - across(faces[1]);
        (split != DVec3::ZERO).then_some(EdgeFrame { mid, split })
    }

    /// The side (0: the first face's, 1: the second's) that face `f` counts on, given the sides
    /// it was reached from (`bits`: 1, 2 or both): one reached from one side only counts on that
    /// side; one reached from both (round the end of a crease, or across a fold that is not
    /// one) on the side of the edge it lies on.
    fn side(&self, adjacency: &FaceAdjacency, f: u32, bits: u8) -> usize {
        match bits {
            1 => 0,
            2 => 1,
            _ => usize::from((adjacency.centroids[f as usize] - self.mid).dot(self.split) < 0.0),
        }
    }
}

/// The most edges of a path of creases beside a longer crease edge that make it a chord
/// ([`detect_features`]).
pub const CHORD_PATH_STEPS: usize = 16;

/// The most edges that close a gap between the end of a crease chain and another crease
/// ([`detect_features`]).
pub const GAP_STEPS: usize = 8;

/// The least cosine between each step of a path of creases and the longer crease edge it runs
/// beside for that edge to be a chord across it ([`detect_features`]): the path goes the edge's
/// way at every step (45°), as a rim's arc does under its chord (a chord 2 spacings long of a
/// rim 3 spacings round: 20° at most), where two creases a chamfer apart, joined at their ends,
/// step across.
pub const CHORD_PATH_COS: f64 = std::f64::consts::FRAC_1_SQRT_2;

/// The radius of the near test of [`detect_features`] ([`sharp_near_edge`]) as a share of the
/// scale (the sample spacing). eval/features at 3,000 vertices, seed 1, the made parts of
/// eval/cad_parts.py as CSG exports (slivers down to 1e-4 of the diagonal high) with noise in
/// their positions: at 1e-4 of the diagonal the chamfered block's Hausdorff 1.73 → 0.25 (clean:
/// 0.28) and the gear's 0.29 → 0.10; at 5e-4 the gear's creases are kept again (1.18 → 0.20,
/// MeshLab 0.21). At 0.1 the gear at 5e-4 was still refused.
pub const NEAR_SCALE_SHARE: f64 = 0.25;

/// The share of the feature angle the surface near an edge must still turn by
/// ([`sharp_near_edge`]): the faces a quarter spacing around a crease blur it a little (a
/// fandisk crease of 23.1° between its two faces turns by 19.9° there), a sliver tilted by noise
/// on a flat turns by a few degrees. At 1 (the angle itself) fandisk lost that edge and its
/// creases went from 0.055 to 0.2 output edges off at the worst seed.
pub const NEAR_TURN_SHARE: f64 = 0.85;

/// Whether the surface near edge `e` (faces `faces`) turns by the angle whose cosine is
/// `cos_bound`: the area-weighted normals of the faces that come within `r` of the edge's
/// midpoint, grown from each of its two faces over any edge but `e`, differ by the angle; with
/// `along`, at the middles of pieces at most 2 `r` long instead, at half of them or more. A face
/// reached from one side counts on that side, one reached from both on the side of the edge it
/// lies on; a face longer than the ball (2 `r`) counts with the share of it that can lie in the
/// ball (2 `r` over its longest edge: a CAD export's long sliver beside a hole's rim reaches
/// round the rim's curve, where it is on neither side). A sliver's normal thus counts with its
/// area: tilted or flipped by noise on a flat, it turns nothing, where a crease turns about as
/// much near it as between its two faces. Deterministic (faces summed in the order they are reached).
fn sharp_near_edge(
    adjacency: &FaceAdjacency,
    scratch: &mut PatchScratch,
    e: [u32; 2],
    faces: [u32; 2],
    r: f64,
    cos_bound: f64,
    along: bool,
) -> bool {
    let mesh = adjacency.mesh;
    // Two faces on the same side of their edge (a fold of 180°): nothing to tell near it.
    let Some(frame) = EdgeFrame::new(mesh, e, faces) else {
        return true;
    };
    let (pa, pb) = (mesh.positions[e[0] as usize], mesh.positions[e[1] as usize]);
    // Along it, an edge longer than the ball is tested at the middles of pieces at most 2 r
    // long: it is a crease where at least half of them turn (a CAD export's long sliver edge
    // tangent to a hole's rim is within r of the rim at its middle only).
    let pieces = if along {
        (pa.distance(pb) / (2.0 * r)).ceil().max(1.0) as usize
    } else {
        1
    };
    let turning = (0..pieces)
        .filter(|&k| {
            let at = pa.lerp(pb, (k as f64 + 0.5) / pieces as f64);
            turns_near(adjacency, scratch, &frame, e, faces, at, r, cos_bound)
        })
        .count();
    2 * turning >= pieces
}

/// Whether the faces that come within `r` of the point `at` of edge `e` (faces `faces`, seen
/// from `frame`) turn by the angle whose cosine is `cos_bound` ([`sharp_near_edge`]).
#[allow(clippy::too_many_arguments)]
fn turns_near(
    adjacency: &FaceAdjacency,
    scratch: &mut PatchScratch,
    frame: &EdgeFrame,
    e: [u32; 2],
    faces: [u32; 2],
    at: DVec3,
    r: f64,
    cos_bound: f64,
) -> bool {
    let mesh = adjacency.mesh;
    // Whether face f comes within r of the point (an edge of it, or its centroid).
    let near = |f: u32| -> bool {
        let c = mesh.corners(f as usize);
        (0..3).any(|k| distance_to_segment(at, c[k], c[(k + 1) % 3]) <= r)
            || adjacency.centroids[f as usize].distance(at) <= r
    };
    // The faces near the edge, a bit per side they were reached from (depth first over any
    // edge but `e`).
    for (side, &seed) in faces.iter().enumerate() {
        let bit = 1u8 << side;
        scratch.mark(seed, bit);
        let mut stack = vec![seed];
        let mut taken = 1;
        while let Some(f) = stack.pop() {
            let t = mesh.triangles[f as usize];
            for k in 0..3 {
                let (u, v) = (t[k], t[(k + 1) % 3]);
                let g = adjacency.across[f as usize][k];
                if (u.min(v), u.max(v)) == (e[0], e[1])
                    || taken >= PATCH_FACES
                    || g == FaceAdjacency::NONE
                {
                    continue;
                }
                if !scratch.has(g, bit) && near(g) {
                    scratch.mark(g, bit);
                    stack.push(g);
                    taken += 1;
                }
            }
        }
    }
    let mut sides = [DVec3::ZERO; 2];
    scratch.drain(|f, bits| {
        let side = frame.side(adjacency, f, bits);
        let t = mesh.corners(f as usize);
        let longest = (0..3)
            .map(|k| t[k].distance(t[(k + 1) % 3]))
            .fold(0.0, f64::max);
        let share = if longest > 2.0 * r {
            2.0 * r / longest
        } else {
            1.0
        };
        sides[side] += share * adjacency.area_normals[f as usize];
    });
    let (n0, n1) = (sides[0].normalize_or_zero(), sides[1].normalize_or_zero());
    n0 != DVec3::ZERO && n1 != DVec3::ZERO && n0.dot(n1) <= cos_bound
}

/// Whether the path `a` → `v` → `b` turns at `v` by less than the angle whose cosine is
/// `cos_bound` (a curve through `v` goes on there; a degenerate step turns by 90°).
fn turns_less_than(a: DVec3, v: DVec3, b: DVec3, cos_bound: f64) -> bool {
    (v - a).normalize_or_zero().dot((b - v).normalize_or_zero()) > cos_bound
}

/// Chains `edges` (sorted) into curves between corners: vertices of feature degree other than
/// 2, on the boundary, or where the curve turns by more than the angle whose cosine is
/// `cos_bound`, both between its two edges and (`reach` > 0) between the chords to its points
/// `reach` along it either side, with no other corner within `reach` along it that turns more.
/// What is left after the open curves are closed loops without a corner. Deterministic.
fn chain(
    mesh: &TriMesh,
    edges: &[[u32; 2]],
    edge_faces: &[[u32; 2]],
    boundary_vertex: &[bool],
    cos_bound: f64,
    reach: f64,
) -> (Vec<FeatureCurve>, Vec<u32>) {
    let positions = &mesh.positions;
    // The face of edge `e` that has it as `a → b` (the later one if both do), else the later
    // one that has `b → a`.
    let face_along = |e: usize, a: u32, b: u32| -> u32 {
        let has = |f: u32, a: u32, b: u32| {
            let t = mesh.triangles[f as usize];
            (0..3).any(|k| t[k] == a && t[(k + 1) % 3] == b)
        };
        let [f0, f1] = edge_faces[e];
        [(f1, a, b), (f0, a, b), (f1, b, a)]
            .into_iter()
            .find(|&(f, a, b)| has(f, a, b))
            .map_or(f0, |(f, _, _)| f)
    };
    let mut incident: FxHashMap<u32, Vec<usize>> = FxHashMap::default();
    for (i, e) in edges.iter().enumerate() {
        incident.entry(e[0]).or_default().push(i);
        incident.entry(e[1]).or_default().push(i);
    }
    let other = |i: usize, v: u32| {
        if edges[i][0] == v {
            edges[i][1]
        } else {
            edges[i][0]
        }
    };
    // Where curves end whatever their turn: not two feature edges, or on the boundary.
    let ends = |v: u32| incident[&v].len() != 2 || boundary_vertex[v as usize];
    let mut corners: Vec<u32> = incident.keys().copied().filter(|&v| ends(v)).collect();
    // Where a curve turns by the angle: between its two edges, and (at `reach` > 0) between the
    // chords to the points `reach` along it either side, no end within `reach`; of two such
    // vertices within `reach` along the curve, the one that turns more. Noise in a CAD export's
    // positions turns a crease's short edges by the angle on a straight line, and two corners
    // a hundredth of a spacing apart, both sampled, make a sliver.
    let mut turning: Vec<(f64, u32, Vec<u32>)> = Vec::new();
    for (&v, inc) in &incident {
        if ends(v) {
            continue;
        }
        let p = positions[v as usize];
        let ab = [other(inc[0], v), other(inc[1], v)];
        if turns_less_than(
            positions[ab[0] as usize],
            p,
            positions[ab[1] as usize],
            cos_bound,
        ) {
            continue;
        }
        if !(reach > 0.0) {
            turning.push((0.0, v, Vec::new()));
            continue;
        }
        // Each way: the point `reach` along the curve, and the vertices passed; `None` when an
        // end (or `v` again, round a short loop) comes first.
        let mut passed = Vec::new();
        let mut arm = |first: usize| -> Option<DVec3> {
            let (mut u, mut e) = (v, inc[first]);
            let mut left = reach;
            loop {
                let w = other(e, u);
                let (a, b) = (positions[u as usize], positions[w as usize]);
                let l = a.distance(b);
                if l >= left {
                    return Some(a.lerp(b, left / l));
                }
                if w == v || ends(w) {
                    return None;
                }
                left -= l;
                passed.push(w);
                e = *incident[&w].iter().find(|&&i| i != e)?;
                u = w;
            }
        };
        let (Some(a), Some(b)) = (arm(0), arm(1)) else {
            continue;
        };
        let cos = (p - a).normalize_or_zero().dot((b - p).normalize_or_zero());
        if cos <= cos_bound {
            turning.push((cos, v, passed));
        }
    }
    // The most turning first (the least cosine), then by vertex: the same corners in any order.
    turning.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    let mut within_reach_of_corner: FxHashSet<u32> = Default::default();
    for (_, v, passed) in turning {
        if within_reach_of_corner.insert(v) {
            corners.push(v);
            within_reach_of_corner.extend(passed);
        }
    }
    corners.sort_unstable();
    let corner_set: FxHashSet<u32> = corners.iter().copied().collect();
    let mut used = vec![false; edges.len()];
    let mut curves = Vec::new();
    // Walks from `start` along edge `first` until a corner (or back to `start`).
    let walk = |start: u32, first: usize, used: &mut Vec<bool>| -> FeatureCurve {
        let mut vertices = vec![start];
        let mut faces = Vec::new();
        let (mut v, mut e) = (start, first);
        loop {
            used[e] = true;
            let w = other(e, v);
            let closed = w == start && !corner_set.contains(&start);
            if closed || w != start {
                faces.push(face_along(e, v, w));
            }
            if w == start {
                return FeatureCurve {
                    vertices,
                    faces,
                    closed,
                };
            }
            vertices.push(w);
            if corner_set.contains(&w) {
                break;
            }
            match incident[&w].iter().copied().find(|&i| !used[i]) {
                Some(n) => (v, e) = (w, n),
                None => break,
            }
        }
        FeatureCurve {
            vertices,
            faces,
            closed: false,
        }
    };
    for &c in &corners {
        for &i in &incident[&c] {
            if !used[i] {
                curves.push(walk(c, i, &mut used));
            }
        }
    }
    for i in 0..edges.len() {
        if !used[i] {
            curves.push(walk(edges[i][0], i, &mut used));
        }
    }
    (curves, corners)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An axis-aligned box [0, s]³ with each side an `n × n` grid of quads, outward.
    fn cube(s: f64, n: usize) -> TriMesh {
        let mut positions: Vec<DVec3> = Vec::new();
        let mut index: FxHashMap<[i64; 3], u32> = FxHashMap::default();
        let mut triangles = Vec::new();
        let mut vertex = |p: [i64; 3], positions: &mut Vec<DVec3>| -> u32 {
            *index.entry(p).or_insert_with(|| {
                positions.push(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) * s / n as f64);
                (positions.len() - 1) as u32
            })
        };
        let n_i = n as i64;
        for axis in 0..3 {
            for side in [0, n_i] {
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                for i in 0..n_i {
                    for j in 0..n_i {
                        let at = |di: i64, dj: i64| {
                            let mut p = [0i64; 3];
                            p[axis] = side;
                            p[u] = i + di;
                            p[v] = j + dj;
                            p
                        };
                        let q = [at(0, 0), at(1, 0), at(1, 1), at(0, 1)]
                            .map(|p| vertex(p, &mut positions));
                        if side == 0 {
                            triangles.push([q[0], q[2], q[1]]);
                            triangles.push([q[0], q[3], q[2]]);
                        } else {
                            triangles.push([q[0], q[1], q[2]]);
                            triangles.push([q[0], q[2], q[3]]);
                        }
                    }
                }
            }
        }
        TriMesh::new(positions, triangles)
    }

    /// A closed cylinder of radius `r` and height `h` round the z axis: `sides` facets round,
    /// `rings` bands of quads, caps fanned from their centres. Outward.
    fn cylinder(r: f64, h: f64, sides: usize, rings: usize) -> TriMesh {
        let side = crate::mesh::test_meshes::open_cylinder(r, sides, rings, h / rings as f64);
        let (mut positions, mut triangles) = (side.positions, side.triangles);
        let at = |k: usize, i: usize| (k * sides + i % sides) as u32;
        let bottom = positions.len() as u32;
        positions.push(DVec3::ZERO);
        let top = positions.len() as u32;
        positions.push(DVec3::new(0.0, 0.0, h));
        for i in 0..sides {
            triangles.push([bottom, at(0, i + 1), at(0, i)]);
            triangles.push([top, at(rings, i), at(rings, i + 1)]);
        }
        TriMesh::new(positions, triangles)
    }

    /// A fixed pseudo-random sequence (xorshift64 from `state`) of offsets in [-`amplitude`,
    /// `amplitude`].
    fn jitter(mut state: u64, amplitude: f64) -> impl FnMut() -> f64 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            amplitude * (2.0 * (state >> 11) as f64 / (1u64 << 53) as f64 - 1.0)
        }
    }

    fn detect(mesh: &TriMesh, angle_deg: f64, scale: f64) -> Features {
        let surface = MeshSurface::new(mesh).unwrap();
        detect_features(&surface, &FeatureParams { angle_deg, scale })
    }

    #[test]
    fn a_cube_has_twelve_curves_and_eight_corners() {
        let m = cube(100.0, 6);
        for scale in [0.0, 5.0] {
            let f = detect(&m, CAD_FEATURE_ANGLE_DEG, scale);
            assert_eq!(f.edges.len(), 12 * 6, "scale {scale}");
            assert_eq!(f.curves.len(), 12);
            assert!(f.curves.iter().all(|c| !c.closed && c.vertices.len() == 7));
            assert_eq!(f.corners.len(), 8);
            for &c in &f.corners {
                let p = m.positions[c as usize];
                assert!(
                    [p.x, p.y, p.z].iter().all(|&x| x == 0.0 || x == 100.0),
                    "{p}"
                );
            }
            assert!((f.length(&m.positions) - 1200.0).abs() < 1e-9);
        }
        // Off at 180°.
        assert!(detect(&m, 180.0, 5.0).edges.is_empty());
    }

    /// A cube [0, 100]³, each face fanned from a corner, its top edge y = 100 in steps of 0.5
    /// (vertices `edge`, from x = 0 to 100), whose inner vertices are moved by up to `noise` in
    /// z (a fixed pseudo-random sequence; in the plane of the side y = 100, so its slivers stay in
    /// that plane). The top is fanned from (0, 0, 100): face `[4, edge[k + 1], edge[k]]`.
    fn cube_with_a_fine_top_edge(noise: f64) -> (Vec<DVec3>, Vec<[u32; 3]>, Vec<u32>) {
        let c = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let mut positions = vec![
            c(0.0, 0.0, 0.0),
            c(100.0, 0.0, 0.0),
            c(100.0, 100.0, 0.0),
            c(0.0, 100.0, 0.0),
            c(0.0, 0.0, 100.0),
            c(100.0, 0.0, 100.0),
        ];
        let (b, t) = ([0u32, 1, 2, 3], [4u32, 5]);
        let mut jitter = jitter(0x9e37_79b9_7f4a_7c15, noise);
        // The top edge from (0, 100, 100) to (100, 100, 100).
        let edge: Vec<u32> = (0..=200)
            .map(|k| {
                let inner = k > 0 && k < 200;
                let dz = if inner { jitter() } else { 0.0 };
                positions.push(c(0.5 * k as f64, 100.0, 100.0 + dz));
                (positions.len() - 1) as u32
            })
            .collect();
        let (t3, t2) = (edge[0], edge[200]);
        let mut triangles: Vec<[u32; 3]> = Vec::new();
        // A convex polygon (counterclockwise seen from outside) fanned from its first vertex.
        let mut fan = |poly: &[u32]| {
            for k in 1..poly.len() - 1 {
                triangles.push([poly[0], poly[k], poly[k + 1]]);
            }
        };
        fan(&[b[0], b[3], b[2], b[1]]);
        fan(&[b[0], b[1], t[1], t[0]]);
        fan(&[b[1], b[2], t2, t[1]]);
        fan(&[b[3], b[0], t[0], t3]);
        let mut side = vec![b[2], b[3]];
        side.extend(&edge);
        fan(&side);
        let mut top = vec![t[0], t[1]];
        top.extend(edge.iter().rev());
        fan(&top);
        (positions, triangles, edge)
    }

    #[test]
    fn a_creases_short_edges_turned_by_noise_make_no_corner() {
        // The cube's top edge zigzags by up to 0.1 in steps of 0.5, its edges turning by up to
        // 77°, but it is straight at the spacing.
        let (positions, triangles, _) = cube_with_a_fine_top_edge(0.1);
        let m = TriMesh::new(positions, triangles);
        // Between its edges the crease turns by the angle at many vertices (and the slivers of
        // the top, tilted by the steps, turn between their faces).
        let f = detect(&m, CAD_FEATURE_ANGLE_DEG, 0.0);
        assert!(f.edges.len() > 11 + 200);
        assert!(f.corners.len() > 8 + 20, "{} corners", f.corners.len());
        // A quarter of a spacing of 20 either side, it turns only at the cube's corners.
        let f = detect(&m, CAD_FEATURE_ANGLE_DEG, 20.0);
        assert_eq!(f.edges.len(), 11 + 200);
        assert_eq!((f.curves.len(), f.corners.len()), (12, 8));
    }

    #[test]
    fn a_crease_edge_whose_face_beside_it_is_tilted_closes_the_gap() {
        // A roof over [0, 100]² in a 40 × 40 grid, its two sides sloping by 12.5° from the ridge
        // y = 50 (a crease of 25°); one vertex beside the ridge raised to halve its side's slope
        // there, as noise tilts a sliver beside a rim: the ridge edges of its faces turn by less
        // than 20° between their two faces, but the ridge goes on either side of them.
        let n = 40usize;
        let slope = 12.5f64.to_radians().tan();
        let raised = (20, n / 2 + 1);
        let m = crate::mesh::test_meshes::grid(n, |i, j| {
            let (x, y) = (100.0 * i as f64 / n as f64, 100.0 * j as f64 / n as f64);
            let z = -slope * (y - 50.0).abs();
            DVec3::new(x, y, if (i, j) == raised { 0.45 * z } else { z })
        });
        let on_ridge = |e: &[u32; 2]| e.iter().all(|&v| m.positions[v as usize].y == 50.0);
        // Between their two faces some ridge edges do not turn by the angle.
        let f = detect(&m, CAD_FEATURE_ANGLE_DEG, 0.0);
        let found = f.edges.iter().filter(|e| on_ridge(e)).count();
        assert!(found < n, "{found}");
        // At a spacing of 20 the ridge is whole, one curve.
        let f = detect(&m, CAD_FEATURE_ANGLE_DEG, 20.0);
        assert_eq!(f.edges.iter().filter(|e| on_ridge(e)).count(), n);
        assert!(f.edges.iter().all(on_ridge), "{:?}", f.edges);
        assert_eq!(f.curves.len(), 1);
    }

    #[test]
    fn a_cylinder_has_its_two_rims_as_closed_curves() {
        let m = cylinder(30.0, 100.0, 48, 10);
        let f = detect(&m, CAD_FEATURE_ANGLE_DEG, 4.0);
        assert_eq!(f.curves.len(), 2);
        assert!(f.corners.is_empty());
        for c in &f.curves {
            assert!(c.closed);
            assert_eq!(c.vertices.len(), 48);
            let z = m.positions[c.vertices[0] as usize].z;
            assert!(z == 0.0 || z == 100.0);
            assert!(c.vertices.iter().all(|&v| m.positions[v as usize].z == z));
        }
    }

    /// The edges of a hexagonal prism turn by 60°, a common CAD angle: the CAD feature angle
    /// keeps all of them with its coordinates rounded as a file stores them (to `f32`; at a
    /// feature angle of 60 the rounding loses some).
    #[test]
    fn a_hexagonal_prism_has_all_its_edges_at_the_cad_angle() {
        let mut m = cylinder(30.0, 80.0, 6, 1);
        for p in &mut m.positions {
            *p = p.as_vec3().as_dvec3();
        }
        let f = detect(&m, CAD_FEATURE_ANGLE_DEG, 3.0);
        assert_eq!(f.edges.len(), 18, "{f:?}");
        assert_eq!((f.curves.len(), f.corners.len()), (18, 12));
    }

    #[test]
    fn a_smooth_sphere_has_no_feature() {
        let m = crate::mesh::test_meshes::uv_sphere(50.0, 24, 48);
        assert!(detect(&m, CAD_FEATURE_ANGLE_DEG, 0.0).edges.is_empty());
    }

    /// A flat square with a narrow sharp ridge across it: a fold at the scale of its own
    /// triangles is a crease between two faces but not at a sample spacing.
    /// A box [-50, 50]² × [0, 20] as a CAD export can come: its top face holds a strip of
    /// slivers `eps` wide at y = 48 (two rows of vertices every 4 along x, 2 from the box's edge
    /// y = 50), the rest of each face fanned from a corner; every vertex moved by up to `noise` in
    /// each coordinate (a fixed pseudo-random sequence). Outward orientation.
    fn box_with_slivers(eps: f64, noise: f64) -> TriMesh {
        let mut positions: Vec<DVec3> = Vec::new();
        let add = |p: DVec3, positions: &mut Vec<DVec3>| {
            positions.push(p);
            (positions.len() - 1) as u32
        };
        let (lo, hi, top) = (-50.0, 50.0, 20.0);
        let c = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        // Corners: bottom 0..4, top 4..8 (counterclockwise from (lo, lo)).
        let corners = [(lo, lo), (hi, lo), (hi, hi), (lo, hi)];
        let b: Vec<u32> = corners
            .iter()
            .map(|&(x, y)| add(c(x, y, 0.0), &mut positions))
            .collect();
        let t: Vec<u32> = corners
            .iter()
            .map(|&(x, y)| add(c(x, y, top), &mut positions))
            .collect();
        let xs: Vec<f64> = (0..=25).map(|k| lo + 4.0 * k as f64).collect();
        let row_a: Vec<u32> = xs
            .iter()
            .map(|&x| add(c(x, 48.0, top), &mut positions))
            .collect();
        let row_b: Vec<u32> = xs
            .iter()
            .map(|&x| add(c(x, 48.0 + eps, top), &mut positions))
            .collect();
        let mut triangles: Vec<[u32; 3]> = Vec::new();
        // A convex polygon (counterclockwise seen from outside) fanned from its first vertex.
        let mut fan = |poly: &[u32]| {
            for k in 1..poly.len() - 1 {
                triangles.push([poly[0], poly[k], poly[k + 1]]);
            }
        };
        let n = xs.len();
        // Bottom (seen from below), the sides y = lo and y = hi.
        fan(&[b[0], b[3], b[2], b[1]]);
        fan(&[b[0], b[1], t[1], t[0]]);
        fan(&[b[2], b[3], t[3], t[2]]);
        // The side x = hi: its top edge passes through the rows' last vertices.
        fan(&[b[1], b[2], t[2], row_b[n - 1], row_a[n - 1], t[1]]);
        // The side x = lo: through their first ones.
        fan(&[b[3], b[0], t[0], row_a[0], row_b[0], t[3]]);
        // The top: below the strip, the strip, above it.
        let mut below = vec![t[0], t[1]];
        below.extend(row_a.iter().rev());
        fan(&below);
        let mut above = vec![t[3]];
        above.extend(row_b.iter());
        above.push(t[2]);
        fan(&above);
        for k in 0..n - 1 {
            triangles.push([row_a[k], row_a[k + 1], row_b[k + 1]]);
            triangles.push([row_a[k], row_b[k + 1], row_b[k]]);
        }
        let mut jitter = jitter(0x2545_f491_4f6c_dd1d, noise);
        for p in &mut positions {
            *p += DVec3::new(jitter(), jitter(), jitter());
        }
        TriMesh::new(positions, triangles)
    }

    #[test]
    fn a_cad_exports_slivers_tilted_by_noise_beside_a_crease_are_not_creases() {
        // Clean, the box's edges are its creases; with noise of half the slivers' width in the
        // positions the slivers tilt and flip (their edges turn by up to 180° on the flat top, a
        // tenth of the spacing from its edge), and the creases are still the box's edges only.
        for noise in [0.0, 0.005] {
            let m = box_with_slivers(0.01, noise);
            let on_box_edge = |p: DVec3| {
                let near = |x: f64, a: f64| (x - a).abs() < 0.1;
                let n = [
                    near(p.x, -50.0) || near(p.x, 50.0),
                    near(p.y, -50.0) || near(p.y, 50.0),
                    near(p.z, 0.0) || near(p.z, 20.0),
                ];
                n.iter().filter(|&&b| b).count() >= 2
            };
            let turns = m
                .edge_uses()
                .iter()
                .filter(|(e, (f, k))| {
                    *k == 2
                        && !(on_box_edge(m.positions[e.0 as usize])
                            && on_box_edge(m.positions[e.1 as usize]))
                        && m.face_normal(f[0] as usize)
                            .dot(m.face_normal(f[1] as usize))
                            < 0.9
                })
                .count();
            let f = detect(&m, CAD_FEATURE_ANGLE_DEG, 5.0);
            let stray: Vec<_> = f
                .edges
                .iter()
                .filter(|e| {
                    !(on_box_edge(m.positions[e[0] as usize])
                        && on_box_edge(m.positions[e[1] as usize]))
                })
                .collect();
            assert!(
                stray.is_empty(),
                "noise {noise}: {} edges off the box's edges: {stray:?}",
                stray.len()
            );
            assert_eq!(f.corners.len(), 8, "noise {noise}");
            assert_eq!(f.curves.len(), 12, "noise {noise}");
            if noise > 0.0 {
                // There are slivers turning on the flat for the test to judge.
                assert!(
                    turns >= 10,
                    "only {turns} edges off the box's edges turn by 25° or more"
                );
            }
        }
    }

    /// A block [-50, 50] × [-50, rim(x)] × [0, 20] whose side y = rim(x) = 50 + x²/100 is curved
    /// (a vertex every 1 along x), as a CAD export can come: its top holds a strip of slivers
    /// `eps` wide whose two rows have vertices at x = -50, -25, 25 and 50 only, the upper one
    /// `gap` below the rim's lowest point: its edge from x = -25 to 25 is tangent to the rim's
    /// curve in its middle. The rest of each face is zipped between chains of vertices. The lower
    /// row's middle vertices are raised by `lift`, tilting the strip's slivers as noise in the
    /// positions does. Outward orientation. Returns the mesh and that edge.
    fn block_with_a_tangent_strip(gap: f64, eps: f64, lift: f64) -> (TriMesh, [u32; 2]) {
        let rim = |x: f64| 50.0 + x * x / 100.0;
        let mut positions: Vec<DVec3> = Vec::new();
        let mut chain = |points: &[(f64, f64, f64)]| -> Vec<u32> {
            points
                .iter()
                .map(|&(x, y, z)| {
                    positions.push(DVec3::new(x, y, z));
                    (positions.len() - 1) as u32
                })
                .collect()
        };
        let xs: Vec<f64> = (0..=100).map(|k| -50.0 + k as f64).collect();
        let along = |y: &dyn Fn(f64) -> f64, z: f64| -> Vec<(f64, f64, f64)> {
            xs.iter().map(|&x| (x, y(x), z)).collect()
        };
        let front_bottom = chain(&along(&|_| -50.0, 0.0));
        let front_top = chain(&along(&|_| -50.0, 20.0));
        let back_bottom = chain(&along(&rim, 0.0));
        let back_top = chain(&along(&rim, 20.0));
        let row_x: [f64; 4] = [-50.0, -25.0, 25.0, 50.0];
        let y0 = 50.0 - gap - eps;
        let row_a = chain(&row_x.map(|x| (x, y0, if x.abs() < 50.0 { 20.0 + lift } else { 20.0 })));
        let row_b = chain(&row_x.map(|x| (x, y0 + eps, 20.0)));
        let x = |v: u32| positions[v as usize].x;
        let mut triangles: Vec<[u32; 3]> = Vec::new();
        // Between two chains along x, the upper one at larger y: counterclockwise seen from +z.
        // Each lower edge takes the upper vertices up to its middle (the rim above the tangent
        // edge is seen from its ends only).
        let zip = |lower: &[u32], upper: &[u32], triangles: &mut Vec<[u32; 3]>| {
            let (mut i, mut j) = (0, 0);
            while i + 1 < lower.len() || j + 1 < upper.len() {
                if j + 1 == upper.len()
                    || (i + 1 < lower.len()
                        && x(upper[j + 1]) > 0.5 * (x(lower[i]) + x(lower[i + 1])))
                {
                    triangles.push([lower[i], lower[i + 1], upper[j]]);
                    i += 1;
                } else {
                    triangles.push([lower[i], upper[j + 1], upper[j]]);
                    j += 1;
                }
            }
        };
        zip(&front_top, &row_a, &mut triangles);
        zip(&row_a, &row_b, &mut triangles);
        zip(&row_b, &back_top, &mut triangles);
        let mut bottom = Vec::new();
        zip(&front_bottom, &back_bottom, &mut bottom);
        triangles.extend(bottom.iter().map(|t| [t[0], t[2], t[1]]));
        // The walls y = -50 (seen from -y) and y = rim(x) (seen from +y).
        for k in 0..100 {
            let (b, t) = (&front_bottom, &front_top);
            triangles.push([b[k], b[k + 1], t[k + 1]]);
            triangles.push([b[k], t[k + 1], t[k]]);
            let (b, t) = (&back_bottom, &back_top);
            triangles.push([b[k + 1], b[k], t[k]]);
            triangles.push([b[k + 1], t[k], t[k + 1]]);
        }
        // The ends x = -50 and x = 50, fanned from a bottom corner.
        let mut fan = |poly: &[u32]| {
            for k in 1..poly.len() - 1 {
                triangles.push([poly[0], poly[k], poly[k + 1]]);
            }
        };
        fan(&[
            back_bottom[0],
            front_bottom[0],
            front_top[0],
            row_a[0],
            row_b[0],
            back_top[0],
        ]);
        fan(&[
            front_bottom[100],
            back_bottom[100],
            back_top[100],
            row_b[3],
            row_a[3],
            front_top[100],
        ]);
        (TriMesh::new(positions, triangles), [row_b[1], row_b[2]])
    }

    #[test]
    fn a_sliver_edge_tangent_to_a_curved_crease_is_no_crease() {
        // The strip's edges 0.3 from the rim at their middle (0.06 of the spacing of 5), 6.55
        // away from it at x = ±25; the strip's slivers, 0.01 wide, tilted by 63°.
        let (m, tangent) = block_with_a_tangent_strip(0.3, 0.01, 0.02);
        let e = [tangent[0].min(tangent[1]), tangent[0].max(tangent[1])];
        // Between its two faces, the tangent edge turns by the angle.
        assert!(detect(&m, CAD_FEATURE_ANGLE_DEG, 0.0).edges.contains(&e));
        let f = detect(&m, CAD_FEATURE_ANGLE_DEG, 5.0);
        // Each crease lies on the block's rims: top or bottom, at the front, the back or an end.
        let rim = |x: f64| 50.0 + x * x / 100.0;
        let stray: Vec<_> = f
            .edges
            .iter()
            .filter(|e| {
                let p = 0.5 * (m.positions[e[0] as usize] + m.positions[e[1] as usize]);
                let near = |a: f64, b: f64| (a - b).abs() < 0.1;
                let sides = [
                    near(p.z, 0.0) || near(p.z, 20.0),
                    near(p.y, -50.0) || near(p.y, rim(p.x)),
                    near(p.x, -50.0) || near(p.x, 50.0),
                ];
                sides.iter().filter(|&&s| s).count() < 2
            })
            .collect();
        assert!(
            stray.is_empty(),
            "{} edges off the rims: {stray:?}",
            stray.len()
        );
        assert!(!f.edges.contains(&e));
    }

    #[test]
    fn chords_of_a_rim_across_a_fan_of_slivers_are_not_creases() {
        // A cylinder of radius 30 and height 100, 48 sides: its top cap fanned from the centre
        // but for the first five rim edges, which are fanned from rim vertex 0 instead (chords
        // 0-2, 0-3, 0-4 within 1 of the rim: slivers, as a CAD export fans a hole's rim). Rim
        // vertices 2 and 4 raised by 0.5 tilt the slivers, so the chords turn between their faces.
        let mut m = cylinder(30.0, 100.0, 48, 10);
        let rim = |i: usize| (10 * 48 + i % 48) as u32;
        let top = (m.positions.len() - 1) as u32;
        m.triangles
            .retain(|t| !(t[0] == top && t[1] < rim(5) && t[1] >= rim(0)));
        for k in 1..5 {
            m.triangles.push([rim(0), rim(k), rim(k + 1)]);
        }
        m.triangles.push([top, rim(0), rim(5)]);
        for i in [2, 4] {
            m.positions[rim(i) as usize].z += 0.5;
        }
        let m = TriMesh::new(m.positions, m.triangles);
        let chords: Vec<[u32; 2]> = (2..5).map(|k| [rim(0), rim(k)]).collect();
        // Between their two faces the chords turn by the angle.
        let f = detect(&m, CAD_FEATURE_ANGLE_DEG, 0.0);
        assert!(chords.iter().all(|c| f.edges.contains(c)), "{:?}", f.edges);
        // At a spacing of 20 the creases are the two rims, closed, and no chord.
        let f = detect(&m, CAD_FEATURE_ANGLE_DEG, 20.0);
        assert!(chords.iter().all(|c| !f.edges.contains(c)));
        assert_eq!(f.edges.len(), 2 * 48);
        assert!(f.curves.len() == 2 && f.curves.iter().all(|c| c.closed));
    }

    #[test]
    fn a_fold_narrower_than_the_scale_is_not_a_crease() {
        // Grid 40 × 40 over [0, 100]²; the row of vertices at y = 50 raised by 2 (the ridge's
        // flanks 2.5 wide: 39° from the plane, 77° between them).
        let n = 40usize;
        let m = crate::mesh::test_meshes::grid(n, |i, j| {
            let z = if j == n / 2 { 2.0 } else { 0.0 };
            DVec3::new(100.0 * i as f64 / n as f64, 100.0 * j as f64 / n as f64, z)
        });
        // Between two faces the ridge is sharp: its top and its two feet.
        assert!(detect(&m, CAD_FEATURE_ANGLE_DEG, 0.0).edges.len() >= n);
        // At a spacing of 20 (eight grid cells) the surface either side is mostly the flat
        // square.
        assert!(detect(&m, CAD_FEATURE_ANGLE_DEG, 20.0).edges.is_empty());
        // At a spacing of 2 (less than the flanks' width) the ridge is resolved: its top and
        // feet are three straight creases from boundary to boundary.
        let resolved = detect(&m, CAD_FEATURE_ANGLE_DEG, 2.0);
        assert_eq!(resolved.edges.len(), 3 * n);
        assert_eq!(resolved.curves.len(), 3);
        assert!(resolved
            .curves
            .iter()
            .all(|c| !c.closed && c.vertices.len() == n + 1));
        assert_eq!(resolved.corners.len(), 6);
    }

    /// A ridge z = tan(d / 2) |x| along y whose dihedral d fades: from 30° at y = 0 to 21° at
    /// y = 1.5, then to 5° at y = 1.6 and on. A spacing either side of its last edges over 20°
    /// takes in the gentler part beyond and bends by less than 20°; they continue the crease all
    /// the same, and are kept.
    #[test]
    fn a_fading_crease_keeps_its_edges_up_to_where_it_fades_below_the_angle() {
        let n = 40;
        let dihedral = |y: f64| -> f64 {
            if y <= 1.5 {
                30.0 - 6.0 * y
            } else if y <= 1.6 {
                21.0 - 160.0 * (y - 1.5)
            } else {
                5.0
            }
        };
        let m = crate::mesh::test_meshes::grid(n, |i, j| {
            let (x, y) = ((i as f64 - 20.0) * 0.01, j as f64 * 0.05);
            DVec3::new(x, y, (0.5 * dihedral(y)).to_radians().tan() * x.abs())
        });
        let on_ridge = |e: &[u32; 2]| e.iter().all(|&v| v as usize % (n + 1) == 20);
        let f = detect(&m, 20.0, 0.3);
        assert!(f.edges.iter().all(on_ridge), "only the ridge");
        let kept = |y: f64| {
            f.edges.iter().any(|e| {
                let (a, b) = (m.positions[e[0] as usize].y, m.positions[e[1] as usize].y);
                (a.max(b) - y).abs() < 1e-9
            })
        };
        // Its 30 edges up to y = 1.5 (the face normals at their ends 21° or more apart), none
        // beyond 1.55.
        for k in 1..=30 {
            assert!(kept(0.05 * k as f64), "the edge to y = {}", 0.05 * k as f64);
        }
        assert!((32..=40).all(|k| !kept(0.05 * k as f64)));
    }

    #[test]
    fn short_curves_count_towards_the_junction_share_only_between_junctions() {
        // Vertices on a line 1 apart, a junction at 0 (edges to 1, 2 and 3) and at 4 (to 5, 6
        // and 7); a curve's length is the distance between its ends.
        let positions: Vec<DVec3> = (0..8).map(|k| DVec3::new(k as f64, 0.0, 0.0)).collect();
        let curve = FeatureCurve::open;
        let mut edges = vec![[0, 1], [0, 2], [0, 3], [4, 5], [4, 6], [4, 7]];
        edges.sort_unstable();
        // 0 -> 1, 0 -> 2 and 0 -> 3 end free (at 1, 2, 3), none long at a spacing of 2 (6).
        let free = Features {
            edges: edges.clone(),
            curves: vec![curve(vec![0, 1]), curve(vec![0, 2]), curve(vec![0, 3])],
            corners: vec![],
        };
        assert_eq!(junction_curve_share(&free, &positions, 2.0), 0.0);
        assert_eq!(long_curve_share(&free, &positions, 2.0), 0.0);
        // A curve from junction 0 to junction 4 counts (length 4 of the 4 + 1 + 2 = 7), and
        // would as a long one at a spacing of 1 (4 >= 3); at a spacing of 2 only as between
        // junctions.
        let between = Features {
            edges,
            curves: vec![curve(vec![0, 4]), curve(vec![0, 1]), curve(vec![0, 2])],
            corners: vec![],
        };
        assert!((junction_curve_share(&between, &positions, 2.0) - 4.0 / 7.0).abs() < 1e-12);
        assert_eq!(long_curve_share(&between, &positions, 2.0), 0.0);
        assert!((long_curve_share(&between, &positions, 1.0) - 4.0 / 7.0).abs() < 1e-12);
    }
}
