//! Local optimization of the triangulated samples against the input surface: the few places the
//! spectral sampling cannot resolve (tips and rims thinner than the sample spacing) are mended
//! with the input surface at hand.
//!
//! The operations and their guards are described on [`optimize`].

use crate::geometry::tolerance::IMPROVEMENT_TOLERANCE;
use glam::DVec3;
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::Triangle;
use rayon::prelude::*;

use super::flip::max_min_flips;
use crate::geometry::triangle::{triangle_angles_deg, triangle_q};
use crate::mesh::edit::{starting_at, EditMesh, SlotPolicy};
use crate::mesh::TriMesh;
use crate::surface::mesh_projection::MeshSurface;

/// Parameters of [`optimize`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OptimizeParams {
    /// Triangles with a shape quality Q below this are worked on (default 0.7).
    pub q_below: f64,
    /// Triangles with a smallest angle below this are worked on too, degrees (default 35).
    pub theta_below_deg: f64,
    /// Sweeps of flips and relaxation at most (default 6).
    pub sweeps: usize,
    /// Largest turn of a face's normal a relaxation move may cause, degrees (default 45).
    pub max_normal_turn_deg: f64,
    /// Largest distance an operation may put between the mesh and the input surface, in units of
    /// sigma_p (default 0.1): a moved vertex's old position must stay within it of its faces; a
    /// flipped edge's midpoint (on the surface) within it of the new faces, and the new edge's
    /// midpoint within it of the surface.
    pub max_offset_sigma_p: f64,
    /// Input-surface points farther than this from the mesh become vertices, in units of sigma_p
    /// (default 0.42; `f64::INFINITY` turns covering off).
    pub cover_distance_sigma_p: f64,
    /// Rounds of covering at most (default 3).
    pub cover_rounds: usize,
    /// Edges of poor triangles shorter than this fraction of the median edge length are
    /// collapsed (default 0.5).
    pub short_edge_ratio: f64,
    /// Largest distance a collapse may put between the removed vertex's position and the mesh, in
    /// units of sigma_p (default 0.25).
    pub collapse_offset_sigma_p: f64,
}

impl Default for OptimizeParams {
    fn default() -> Self {
        OptimizeParams {
            q_below: 0.7,
            theta_below_deg: 35.0,
            sweeps: 6,
            max_normal_turn_deg: 45.0,
            max_offset_sigma_p: 0.1,
            cover_distance_sigma_p: 0.42,
            cover_rounds: 3,
            short_edge_ratio: 0.5,
            collapse_offset_sigma_p: 0.25,
        }
    }
}

/// [`OptimizeParams`] with its lengths resolved to bbox-100 units for one sigma_p: what the
/// operations read.
#[derive(Debug, Clone, Copy)]
struct Limits {
    /// [`OptimizeParams::q_below`].
    q_below: f64,
    /// [`OptimizeParams::theta_below_deg`], degrees.
    theta_below_deg: f64,
    /// [`OptimizeParams::sweeps`].
    sweeps: usize,
    /// [`OptimizeParams::max_normal_turn_deg`], degrees.
    max_normal_turn_deg: f64,
    /// [`OptimizeParams::max_offset_sigma_p`] · sigma_p, bbox-100 units.
    max_offset: f64,
    /// [`OptimizeParams::cover_distance_sigma_p`] · sigma_p, bbox-100 units.
    cover_distance: f64,
    /// [`OptimizeParams::cover_rounds`].
    cover_rounds: usize,
    /// [`OptimizeParams::short_edge_ratio`].
    short_edge_ratio: f64,
    /// [`OptimizeParams::collapse_offset_sigma_p`] · sigma_p, bbox-100 units.
    collapse_offset: f64,
}

impl Limits {
    fn new(params: &OptimizeParams, sigma_p: f64) -> Self {
        Limits {
            q_below: params.q_below,
            theta_below_deg: params.theta_below_deg,
            sweeps: params.sweeps,
            max_normal_turn_deg: params.max_normal_turn_deg,
            max_offset: params.max_offset_sigma_p * sigma_p,
            cover_distance: params.cover_distance_sigma_p * sigma_p,
            cover_rounds: params.cover_rounds,
            short_edge_ratio: params.short_edge_ratio,
            collapse_offset: params.collapse_offset_sigma_p * sigma_p,
        }
    }
}

/// What [`optimize`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct OptimizeStats {
    /// Input-surface points inserted as vertices.
    pub covered: usize,
    /// Edges collapsed.
    pub collapses: usize,
    /// Edges flipped.
    pub flips: usize,
    /// Vertex moves.
    pub moves: usize,
}

/// The mesh being optimized: each face labelled with the index of the input face it still is
/// (`None` once an operation made or changed it).
type Mesh = EditMesh<Option<u32>>;

fn normal(m: &Mesh, t: [u32; 3]) -> DVec3 {
    let [a, b, c] = m.corners(t);
    (b - a).cross(c - a).normalize_or_zero()
}

fn min_angle(m: &Mesh, t: [u32; 3]) -> f64 {
    let a = triangle_angles_deg(m.corners(t));
    a[0].min(a[1]).min(a[2])
}

fn q(m: &Mesh, t: [u32; 3]) -> f64 {
    triangle_q(m.corners(t))
}

/// The shape score the operations maximize at their worst face: Q and the smallest angle, each
/// relative to a good level (Q 0.6, 30°), whichever is lower.
fn score(m: &Mesh, t: [u32; 3]) -> f64 {
    (q(m, t) / 0.6).min(min_angle(m, t) / 30.0)
}

/// Whether `t` is one of the triangles the operations work on.
fn is_poor(m: &Mesh, t: [u32; 3], params: &Limits) -> bool {
    q(m, t) < params.q_below || min_angle(m, t) < params.theta_below_deg
}

/// The face in slot `f`, which must be live.
fn face(m: &Mesh, f: u32) -> [u32; 3] {
    m.face(f)
        .unwrap_or_else(|| unreachable!("face {f} is live"))
}

fn distance_to_faces(m: &Mesh, faces: &[u32], p: DVec3) -> f64 {
    faces
        .iter()
        .map(|&f| {
            let [a, b, c] = m.corners(face(m, f));
            Triangle::new(a, b, c).distance_to_local_point(p, true)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Optimizes `mesh` (bbox-100 units, edge-manifold and consistently oriented) against `surface`
/// (the input, same units): covers the input points of `cover_points` that are farther than
/// `params.cover_distance_sigma_p` · `sigma_p` from it, then flips edges and relaxes vertices
/// around the triangles with Q below `params.q_below`. Vertices with `fixed[v]` (boundary
/// samples) do not move; boundary edges are not flipped. New vertices are appended, so
/// existing indices stay valid; vertices merged away by a collapse are left unreferenced.
/// Returns what was done and, for each face of the result, the index of the face of `mesh` it
/// still is (`None` for a new or changed face). Deterministic.
///
/// # Operations
///
/// Four local operations, each kept only when it keeps the mesh near the input surface (see the
/// offsets in [`OptimizeParams`]):
/// - **Cover:** an input-surface point farther than `cover_distance_sigma_p` · sigma_p from the
///   mesh (the tip of an ear or a horn that the samples around it cut off) becomes a vertex: it
///   splits the face it is closest to, or the edge it lies beyond. This bounds the one-sided
///   (input → output) Hausdorff distance.
/// - **Collapse:** a short edge of a poor triangle merges its ends (link condition kept).
/// - **Flip:** an edge near a poor triangle is flipped when that raises the smaller minimum angle
///   of its two faces (Lawson's max-min rule) and the new faces stay on the surface.
/// - **Relax:** a vertex of a poor triangle moves towards the centroid of its neighbours or the
///   apex of an equilateral triangle on a poor face's far edge, projected back onto the surface,
///   when that raises the worst shape score min(Q / 0.6, θmin / 30°) of its faces and turns none
///   of them much (Laplacian smoothing with projection, as in Botsch & Kobbelt 2004, Sec. 3,
///   restricted to the poor triangles).
///
/// Everything else stays as the sampler and the tangent-plane Delaunay left it. On horse at 8600
/// about 16 points are covered and 600 of the 8600 vertices move (most by a fraction of the
/// spacing).
pub fn optimize(
    mesh: &mut TriMesh,
    surface: &MeshSurface,
    cover_points: &[DVec3],
    fixed: &[bool],
    sigma_p: f64,
    params: &OptimizeParams,
) -> (OptimizeStats, Vec<Option<u32>>) {
    let params = &Limits::new(params, sigma_p);
    let mut stats = OptimizeStats::default();
    let mut m: Mesh = EditMesh::from_trimesh(mesh, Some, SlotPolicy::Reuse);
    let mut fixed = fixed.to_vec();
    fixed.resize(m.vertex_count(), false);
    let short = params.short_edge_ratio * median_edge_length(&m);
    let mut watch = None;
    for round in 0..params.cover_rounds.max(1) {
        if params.cover_distance.is_finite() {
            let added = cover(&mut m, cover_points, &mut watch, params);
            // Covering vertices stay where they are.
            fixed.resize(m.vertex_count(), true);
            stats.covered += added;
            if added == 0 && round > 0 {
                break;
            }
        }
        for _ in 0..params.sweeps {
            let c = collapse_short(&mut m, surface, &fixed, short, params);
            let f = flip_poor(&mut m, surface, params);
            let r = relax_poor(&mut m, surface, &fixed, params);
            stats.collapses += c;
            stats.flips += f;
            stats.moves += r;
            if c + f + r == 0 {
                break;
            }
        }
        if !params.cover_distance.is_finite() {
            break;
        }
    }
    let (positions, faces, origin) = m.into_parts();
    *mesh = TriMesh::new(positions, faces);
    (stats, origin)
}

/// One round of covering: the points of `points` farther than `cover_distance` from the mesh,
/// farthest first and at most one per face, each split into the face nearest to it. `watch`
/// carries, from the first round to the next, the points worth looking at again. Returns how
/// many were inserted.
fn cover(m: &mut Mesh, points: &[DVec3], watch: &mut Option<Vec<u32>>, params: &Limits) -> usize {
    let (live, slot) = m.live_faces();
    let current = TriMesh::new(m.positions().to_vec(), live);
    let Ok(output) = MeshSurface::new(&current) else {
        return 0;
    };
    // The points to look at: all of them the first time; then those that could come farther
    // than the cover distance: a collapse moves the mesh by up to `collapse_offset` from a
    // surface point, relaxation by less.
    if watch.is_none() {
        *watch = Some(
            points
                .par_iter()
                .enumerate()
                .filter(|(_, &p)| {
                    output
                        .closest_point_within(
                            p,
                            (params.cover_distance - params.collapse_offset).max(0.0),
                        )
                        .is_none()
                })
                .map(|(i, _)| i as u32)
                .collect(),
        );
    }
    let watched = watch.as_deref().unwrap_or_default();
    let mut far: Vec<(f64, usize, u32)> = watched
        .par_iter()
        .filter_map(|&i| {
            let i = i as usize;
            let sp = output.closest_point(points[i])?;
            (sp.distance > params.cover_distance).then_some((
                sp.distance,
                i,
                slot[sp.face as usize],
            ))
        })
        .collect();
    far.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let mut touched = vec![false; m.slots()];
    let mut added = 0;
    for (_, i, f) in far {
        let t = face(m, f);
        // One insertion per face and its neighbours per round: the next round sees the result.
        if touched[f as usize] {
            continue;
        }
        let p = points[i];
        let [pa, pb, pc] = m.corners(t);
        let n = (pb - pa).cross(pc - pa);
        let corner = [pa, pb, pc];
        let v = m.vertex_count() as u32;
        // Which side of each edge k (corner k → k+1) p is on, in the face's plane.
        let outside: Vec<usize> = (0..3)
            .filter(|&k| {
                let (x, y) = (corner[k], corner[(k + 1) % 3]);
                (y - x).cross(p - x).dot(n) <= 0.0
            })
            .collect();
        // (new face, the old face it comes from), and the edge to split (`None`: the face).
        let (plan, split): (SplitPlan, Option<(u32, u32)>) = if outside.is_empty() {
            // Inside the face: split it in three.
            let [a, b, c] = t;
            (vec![([a, b, v], t), ([b, c, v], t), ([c, a, v], t)], None)
        } else {
            // Beyond an edge (or a corner: the nearer of its two edges): split that edge and
            // the face across it.
            let k = *outside
                .iter()
                .min_by(|&&k1, &&k2| {
                    let d = |k: usize| segment_distance(corner[k], corner[(k + 1) % 3], p);
                    d(k1).total_cmp(&d(k2))
                })
                .unwrap_or(&outside[0]);
            let (x, y, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            // A boundary edge stays as the boundary samples made it.
            let Some(g) = m.face_on(y, x) else {
                continue;
            };
            if touched[g as usize] {
                continue;
            }
            let u = face(m, g);
            let d = starting_at(u, y)[2];
            (
                vec![
                    ([x, v, c], t),
                    ([v, y, c], t),
                    ([y, v, d], u),
                    ([v, x, d], u),
                ],
                Some((x, y)),
            )
        };
        // Every new face must face the way the face it comes from did.
        let at = |u: u32| if u == v { p } else { m.position(u) };
        let unit = |t: [u32; 3]| {
            let [a, b, c] = t.map(at);
            (b - a).cross(c - a).normalize_or_zero()
        };
        let fits = plan
            .iter()
            .all(|&(new, old)| unit(new).dot(normal(m, old)) > 0.0);
        if !fits {
            continue;
        }
        m.add_vertex(p);
        let done = match split {
            None => m.split_face(f, v, None).map(|_| ()),
            Some((x, y)) => m.split_edge(x, y, v, None).map(|_| ()),
        };
        if done.is_err() {
            m.pop_vertex();
            continue;
        }
        touched.resize(m.slots(), true);
        for &u in plan.iter().flat_map(|x| x.0.iter()) {
            for &g in m.faces_around(u) {
                touched[g as usize] = true;
            }
        }
        added += 1;
    }
    added
}

/// The faces a split makes: (new face, the old face it comes from).
type SplitPlan = Vec<([u32; 3], [u32; 3])>;

/// The distance from `p` to the segment `a`–`b`.
fn segment_distance(a: DVec3, b: DVec3, p: DVec3) -> f64 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 {
        ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + t * ab)
}

/// The vertices of the faces with Q below `q_below`, sorted.
fn poor_vertices(m: &Mesh, params: &Limits) -> Vec<u32> {
    let mut v: Vec<u32> = m
        .live_faces()
        .0
        .into_iter()
        .filter(|&t| is_poor(m, t, params))
        .flatten()
        .collect();
    v.sort_unstable();
    v.dedup();
    v
}

/// Max-min angle flips ([`max_min_flips`]) of the edges of the faces around poor triangles'
/// vertices, where the new faces face the way the old ones did and stay within `max_offset` of
/// the surface. Returns the number of flips.
fn flip_poor(m: &mut Mesh, surface: &MeshSurface, params: &Limits) -> usize {
    let mut edges: Vec<(u32, u32)> = Vec::new();
    for v in poor_vertices(m, params) {
        for &f in m.faces_around(v) {
            let t = face(m, f);
            for k in 0..3 {
                let (x, y) = (t[k], t[(k + 1) % 3]);
                edges.push((x.min(y), x.max(y)));
            }
        }
    }
    edges.sort_unstable();
    edges.dedup();
    max_min_flips(m, &edges, None, |m, flip| {
        let [t1, t2] = flip.old;
        let [new1, new2] = flip.new;
        let (x, y, c, d) = (t1[0], t1[1], t1[2], t2[2]);
        // The new faces must face the way the old ones did and stay on the surface.
        let (n1, n2) = (normal(m, t1), normal(m, t2));
        let (m1, m2) = (normal(m, new1), normal(m, new2));
        let mean_old = n1 + n2;
        if m1.dot(mean_old) <= 0.0 || m2.dot(mean_old) <= 0.0 || m1.dot(m2) < 0.0 {
            return false;
        }
        let (px, py, pc, pd) = (m.position(x), m.position(y), m.position(c), m.position(d));
        let Some(new_mid) = surface.closest_point(0.5 * (pc + pd)) else {
            return false;
        };
        if new_mid.distance > params.max_offset {
            return false;
        }
        let Some(old_mid) = surface.closest_point(0.5 * (px + py)) else {
            return false;
        };
        let tri_dist = |t: [u32; 3], p: DVec3| {
            let [a, b, c] = m.corners(t);
            Triangle::new(a, b, c).distance_to_local_point(p, true)
        };
        tri_dist(new1, old_mid.position).min(tri_dist(new2, old_mid.position)) <= params.max_offset
    })
}

/// One sweep of relaxation over the vertices of poor triangles (see [`optimize`]).
/// Returns the number of moves.
fn relax_poor(m: &mut Mesh, surface: &MeshSurface, fixed: &[bool], params: &Limits) -> usize {
    let cos_turn = params.max_normal_turn_deg.to_radians().cos();
    let mut moves = 0;
    let mut ring: Vec<u32> = Vec::new();
    for v in poor_vertices(m, params) {
        if fixed.get(v as usize).copied().unwrap_or(false) {
            continue;
        }
        let faces = m.faces_around(v).to_vec();
        if faces.is_empty() {
            continue;
        }
        // A vertex on a boundary edge stays.
        if m.is_boundary_vertex(v) {
            continue;
        }
        let old_normals: Vec<DVec3> = faces.iter().map(|&f| normal(m, face(m, f))).collect();
        let worst_q = |m: &Mesh| {
            faces
                .iter()
                .map(|&f| score(m, face(m, f)))
                .fold(f64::INFINITY, f64::min)
        };
        ring.clear();
        for &f in &faces {
            ring.extend(face(m, f).iter().filter(|&&u| u != v));
        }
        ring.sort_unstable();
        ring.dedup();
        let centroid = ring
            .iter()
            .map(|&u| m.position(u))
            .fold(DVec3::ZERO, |a, b| a + b)
            / ring.len() as f64;
        let old = m.position(v);
        // Targets: the centroid, and for each poor face the apex of the equilateral triangle on
        // the edge opposite v (in the face's plane, on v's side).
        let mut targets = vec![centroid];
        for &f in &faces {
            let t = starting_at(face(m, f), v);
            if !is_poor(m, t, params) {
                continue;
            }
            let (pb, pc) = (m.position(t[1]), m.position(t[2]));
            let mid = 0.5 * (pb + pc);
            let e = pc - pb;
            let height = old - mid;
            let across = (height - e * (height.dot(e) / e.length_squared().max(f64::MIN_POSITIVE)))
                .normalize_or_zero();
            if across != DVec3::ZERO {
                targets.push(mid + across * (0.75f64.sqrt() * e.length()));
            }
        }
        let mut best = (worst_q(m), old);
        for (target, t) in targets
            .iter()
            .flat_map(|&c| [1.0, 0.5, 0.25].map(|t| (c, t)))
        {
            let Some(sp) = surface.closest_point(old.lerp(target, t)) else {
                continue;
            };
            if m.relocate_vertex(v, sp.position).is_err() {
                continue;
            }
            let turned = faces
                .iter()
                .zip(&old_normals)
                .any(|(&f, &n0)| normal(m, face(m, f)).dot(n0) < cos_turn);
            let q = worst_q(m);
            if !turned
                && q > best.0 + IMPROVEMENT_TOLERANCE
                && distance_to_faces(m, &faces, old) <= params.max_offset
            {
                best = (q, sp.position);
            }
        }
        if m.relocate_vertex(v, best.1).is_ok() && best.1 != old {
            moves += 1;
        }
    }
    moves
}

/// The median edge length of the live faces (0 for an empty mesh).
fn median_edge_length(m: &Mesh) -> f64 {
    let (live, _) = m.live_faces();
    let mut lengths: Vec<f64> = live
        .iter()
        .flat_map(|t| {
            let [a, b, c] = m.corners(*t);
            [a.distance(b), b.distance(c), c.distance(a)]
        })
        .collect();
    if lengths.is_empty() {
        return 0.0;
    }
    let mid = lengths.len() / 2;
    *lengths.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// Collapses the interior edges of poor triangles shorter than `short`, shortest first: one end
/// merges into the other, at the kept end's position (a fixed end is always the kept one) or at
/// the surface point nearest the edge's midpoint, whichever leaves the best smallest Q. A
/// collapse is made only when it keeps the mesh manifold (the link condition: the two ends share
/// exactly the two opposite vertices), raises the smallest Q of the faces involved, turns no face
/// by more than `max_normal_turn_deg`, and leaves both old positions within `collapse_offset` of
/// the new faces. Returns the number of collapses.
fn collapse_short(
    m: &mut Mesh,
    surface: &MeshSurface,
    fixed: &[bool],
    short: f64,
    params: &Limits,
) -> usize {
    let cos_turn = params.max_normal_turn_deg.to_radians().cos();
    let mut edges: Vec<(f64, u32, u32)> = Vec::new();
    for t in m.live_faces().0 {
        if !is_poor(m, t, params) {
            continue;
        }
        for k in 0..3 {
            let (x, y) = (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]));
            let l = m.position(x).distance(m.position(y));
            if l < short {
                edges.push((l, x, y));
            }
        }
    }
    edges.sort_by(|a, b| a.0.total_cmp(&b.0).then((a.1, a.2).cmp(&(b.1, b.2))));
    edges.dedup();
    let is_fixed = |v: u32| fixed.get(v as usize).copied().unwrap_or(false);
    let mut collapses = 0;
    for (_, a, b) in edges {
        let Ok((f1, f2, c, d)) = m.edge_faces(a, b) else {
            continue;
        };
        let (pa, pb) = (m.position(a), m.position(b));
        if pa.distance(pb) >= short {
            continue;
        }
        let (ra, rb) = (m.ring(a), m.ring(b));
        let common: Vec<u32> = ra.iter().copied().filter(|u| rb.contains(u)).collect();
        if c == d
            || common.len() != 2
            || !common.contains(&c)
            || !common.contains(&d)
            || m.degree(c) <= 3
            || m.degree(d) <= 3
        {
            continue;
        }
        let keep_a = is_fixed(a) || m.is_boundary_vertex(a);
        let keep_b = is_fixed(b) || m.is_boundary_vertex(b);
        // (removed, kept, position of the kept vertex)
        let mut options: Vec<(u32, u32, DVec3)> = Vec::new();
        match (keep_a, keep_b) {
            (true, true) => continue,
            (true, false) => options.push((b, a, pa)),
            (false, true) => options.push((a, b, pb)),
            (false, false) => {
                options.push((b, a, pa));
                options.push((a, b, pb));
                if let Some(sp) = surface.closest_point(0.5 * (pa + pb)) {
                    options.push((b, a, sp.position));
                }
            }
        }
        // The faces that change: all around a and b but f1 and f2.
        let mut involved: Vec<u32> = m
            .faces_around(a)
            .iter()
            .chain(m.faces_around(b))
            .copied()
            .filter(|&g| g != f1 && g != f2)
            .collect();
        involved.sort_unstable();
        involved.dedup();
        let before = involved
            .iter()
            .chain([&f1, &f2])
            .map(|&g| score(m, face(m, g)))
            .fold(f64::INFINITY, f64::min);
        let old_normals: Vec<DVec3> = involved.iter().map(|&g| normal(m, face(m, g))).collect();
        let mut best: Option<(f64, u32, u32, DVec3)> = None;
        for (removed, kept, q) in options {
            let saved = m.position(kept);
            if m.relocate_vertex(kept, q).is_err() {
                continue;
            }
            let new_faces: Vec<[u32; 3]> = involved
                .iter()
                .map(|&g| face(m, g).map(|u| if u == removed { kept } else { u }))
                .collect();
            let turned = new_faces
                .iter()
                .zip(&old_normals)
                .any(|(&t, &n0)| normal(m, t).dot(n0) < cos_turn);
            let worst = new_faces
                .iter()
                .map(|&t| score(m, t))
                .fold(f64::INFINITY, f64::min);
            let dist = |p: DVec3| {
                new_faces
                    .iter()
                    .map(|&t| {
                        let [x, y, z] = m.corners(t);
                        Triangle::new(x, y, z).distance_to_local_point(p, true)
                    })
                    .fold(f64::INFINITY, f64::min)
            };
            let near = dist(pa) <= params.collapse_offset && dist(pb) <= params.collapse_offset;
            // The old position was finite: restoring it cannot fail.
            let _ = m.relocate_vertex(kept, saved);
            if !turned
                && near
                && worst > before + IMPROVEMENT_TOLERANCE
                && best.is_none_or(|b| worst > b.0)
            {
                best = Some((worst, removed, kept, q));
            }
        }
        let Some((_, removed, kept, q)) = best else {
            continue;
        };
        if m.collapse_edge(removed, kept, q, None).is_ok() {
            collapses += 1;
        }
    }
    collapses
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::{check_invariants, topology};
    use crate::report::triangle_quality;

    /// An `n × n` grid of squares of side `h` in the plane z = 0.
    fn grid(n: usize, h: f64) -> TriMesh {
        crate::mesh::test_meshes::grid(n, |i, j| DVec3::new(i as f64 * h, j as f64 * h, 0.0))
    }

    /// A manifold single disk (after dropping unreferenced vertices) that passes every invariant.
    fn assert_manifold_disk(mesh: &mut TriMesh) {
        mesh.remove_unreferenced_vertices();
        let t = topology(mesh);
        assert!(t.is_manifold() && t.euler_characteristic == 1 && t.components == 1);
        let problems = check_invariants(mesh);
        assert!(problems.is_empty(), "{problems:?}");
        assert_sane(mesh);
    }

    /// The mesh passes every invariant of the edit mesh.
    fn assert_sane(mesh: &TriMesh) {
        let m: EditMesh = EditMesh::from_trimesh(mesh, |_| (), SlotPolicy::Reuse);
        assert_eq!(m.sanity_check(), Ok(()));
    }

    fn no_cover() -> OptimizeParams {
        OptimizeParams {
            cover_distance_sigma_p: f64::INFINITY,
            ..Default::default()
        }
    }

    #[test]
    fn a_distorted_flat_patch_is_relaxed_in_its_plane() {
        let surface = MeshSurface::new(&grid(10, 1.0)).unwrap();
        let mut mesh = grid(10, 1.0);
        // Pull one interior vertex most of the way towards a neighbour: slivers around it.
        let v = 5 * 11 + 5;
        mesh.positions[v] += DVec3::new(0.8, 0.1, 0.0);
        let before = triangle_quality(&mesh);
        let fixed: Vec<bool> = vec![false; mesh.vertex_count()];
        let (stats, _) = optimize(&mut mesh, &surface, &[], &fixed, 1.0, &no_cover());
        let after = triangle_quality(&mesh);
        assert!(stats.moves + stats.flips + stats.collapses > 0);
        assert!(
            after.q_min > before.q_min + 0.2,
            "{} -> {}",
            before.q_min,
            after.q_min
        );
        assert!(mesh.positions.iter().all(|p| p.z.abs() < 1e-12));
        assert_manifold_disk(&mut mesh);
    }

    #[test]
    fn fixed_and_boundary_vertices_do_not_move() {
        let surface = MeshSurface::new(&grid(6, 1.0)).unwrap();
        let mut mesh = grid(6, 1.0);
        // Distort a boundary vertex (y = 0 row) and an interior one that is fixed.
        mesh.positions[3] += DVec3::new(0.45, 0.0, 0.0);
        mesh.positions[3 * 7 + 3] += DVec3::new(0.45, 0.4, 0.0);
        let original = mesh.positions.clone();
        let mut fixed = vec![false; mesh.vertex_count()];
        fixed[3 * 7 + 3] = true;
        let (_, origin) = optimize(&mut mesh, &surface, &[], &fixed, 1.0, &no_cover());
        assert_eq!(origin.len(), mesh.face_count());
        assert!(origin.iter().any(|o| o.is_none()) && origin.iter().any(|o| o.is_some()));
        assert_eq!(mesh.positions[3], original[3]);
        assert_eq!(mesh.positions[3 * 7 + 3], original[3 * 7 + 3]);
        assert_eq!(topology(&mesh).boundary_edges, 24);
        assert_sane(&mesh);
    }

    #[test]
    fn a_very_short_edge_is_collapsed_and_the_mesh_stays_manifold() {
        let surface = MeshSurface::new(&grid(8, 1.0)).unwrap();
        let mut mesh = grid(8, 1.0);
        // Split the diagonal of one interior square very close to its corner: a vertex 0.1 from
        // another, with slivers around it.
        let (a, b) = (3 * 9 + 3, 4 * 9 + 4);
        let p = mesh.positions[a].lerp(mesh.positions[b], 0.07);
        let v = mesh.positions.len() as u32;
        mesh.positions.push(p);
        let (a, b) = (a as u32, b as u32);
        let mut triangles = Vec::new();
        for t in &mesh.triangles {
            let has = |x: u32| t.contains(&x);
            if has(a) && has(b) {
                let t = starting_at(*t, a);
                let (x, y, c) = (t[0], t[1], t[2]);
                // [a, b, c] or [a, c, b] around the diagonal: split the edge a-b at v.
                if y == b {
                    triangles.push([x, v, c]);
                    triangles.push([v, y, c]);
                } else {
                    triangles.push([x, y, v]);
                    triangles.push([v, y, c]);
                }
            } else {
                triangles.push(*t);
            }
        }
        mesh.triangles = triangles;
        let t0 = topology(&mesh);
        assert!(t0.is_manifold() && t0.euler_characteristic == 1);
        let fixed = vec![false; mesh.vertex_count()];
        let (stats, _) = optimize(&mut mesh, &surface, &[], &fixed, 1.0, &no_cover());
        assert!(stats.collapses >= 1, "{stats:?}");
        assert_manifold_disk(&mut mesh);
        assert!(triangle_quality(&mesh).theta_min > 30.0);
    }

    #[test]
    fn a_cut_off_tip_is_covered() {
        // Input: a square pyramid, apex at height 8. Output to mend: the same pyramid cut flat
        // at height 4 (the apex 4 units from it).
        let base = [
            DVec3::new(-5.0, -5.0, 0.0),
            DVec3::new(5.0, -5.0, 0.0),
            DVec3::new(5.0, 5.0, 0.0),
            DVec3::new(-5.0, 5.0, 0.0),
        ];
        let apex = DVec3::new(0.0, 0.0, 8.0);
        let mut positions = base.to_vec();
        positions.push(apex);
        let input = TriMesh::new(
            positions,
            vec![
                [0, 2, 1],
                [0, 3, 2],
                [0, 1, 4],
                [1, 2, 4],
                [2, 3, 4],
                [3, 0, 4],
            ],
        );
        let surface = MeshSurface::new(&input).unwrap();
        let mut positions = base.to_vec();
        positions.extend(base.iter().map(|&p| p.lerp(apex, 0.5)));
        let mut triangles = vec![[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7]];
        for k in 0..4u32 {
            let (a, b) = (k, (k + 1) % 4);
            triangles.push([a, b, b + 4]);
            triangles.push([a, b + 4, a + 4]);
        }
        let mut mesh = TriMesh::new(positions, triangles);
        assert!(topology(&mesh).is_closed_manifold());
        let fixed = vec![false; mesh.vertex_count()];
        let (stats, _) = optimize(
            &mut mesh,
            &surface,
            &input.positions,
            &fixed,
            1.0,
            &OptimizeParams::default(),
        );
        assert!(stats.covered >= 1, "{stats:?}");
        assert!(mesh.positions.contains(&apex));
        let t = topology(&mesh);
        assert!(
            t.is_closed_manifold() && t.euler_characteristic == 2,
            "{t:?}"
        );
        assert!(
            check_invariants(&mesh).is_empty(),
            "{:?}",
            check_invariants(&mesh)
        );
        assert_sane(&mesh);
    }
}
