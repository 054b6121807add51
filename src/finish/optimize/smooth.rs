//! Tangential relaxation with valence flips: the finishing stage that takes the triangles of a
//! blue-noise sampling to those of a centroidal Voronoi tessellation.
//!
//! The spectral sampling spaces the samples evenly, but their restricted Delaunay triangulation
//! keeps the irregular valences and the spread of edge lengths of any blue-noise set (Qave about
//! 0.90). Each iteration here
//! - flips the interior edges whose flip brings the four vertices' valences closer to 6 (4 on a
//!   boundary), as the isotropic remeshing of Botsch and Kobbelt ("A remeshing approach to
//!   multiresolution modeling", SGP 2004, Sec. 3) does, guarded against the input surface;
//! - moves every free vertex towards the area-weighted mean of the centroids of its faces (a
//!   Lloyd step of the restricted centroidal Voronoi tessellation on the mesh, Du, Faber and
//!   Gunzburger 1999), in the tangent plane, then onto the input surface.
//!
//! Then the max-min flips make the result Delaunay again. The vertex count does not change.

use glam::DVec3;
use rayon::prelude::*;

use crate::geometry::self_intersection::{crossing_faces, undo_new_crossings};
use crate::surface::SurfacePoint;
use crate::triangulate::flip::flip_in_order;

use super::*;

/// The smallest angle a valence flip may leave in its two faces, unless the faces it replaces
/// had a smaller one, degrees: a flip towards valence 6 that makes a sliver would only be
/// undone (what the valence flips add: `docs/decisions/finishing-relaxation.md`).
const VALENCE_FLIP_MIN_ANGLE_DEG: f64 = 20.0;

/// What the finishing relaxation (`optimize`'s first step, [`OptimizeParams::smooth_iterations`])
/// did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct SmoothStats {
    /// Valence flips.
    pub valence_flips: usize,
    /// Max-min (Delaunay) flips after the relaxation.
    pub delaunay_flips: usize,
    /// Vertex moves, summed over the iterations.
    pub moves: usize,
}

/// Flips the interior edges whose flip lowers the squared deviation of the four vertices'
/// valences from their targets, when the new faces face the way the old ones did, their smallest
/// angle is at least `min_angle_deg` (or no worse than before), and the new edge's midpoint is
/// within `max_offset` of the surface. Returns the number of flips.
fn valence_flips<S: SurfaceQuery + ?Sized>(
    m: &mut Mesh,
    surface: &S,
    boundary: &[bool],
    params: &Limits,
    min_angle_deg: f64,
) -> usize {
    let mut edges: Vec<(u32, u32)> = m
        .directed_edges()
        .filter(|&(a, b)| a < b && m.face_on(b, a).is_some())
        .collect();
    edges.sort_unstable();
    let decide = |m: &Mesh, a: u32, b: u32| {
        let Ok((f1, f2, c, d)) = m.edge_faces(a, b) else {
            return false;
        };
        if c == d || m.is_protected(a, b) || m.has_edge(c, d) || m.has_edge(d, c) {
            return false;
        }
        if m.degree(a) <= 3 || m.degree(b) <= 3 {
            return false;
        }
        let dev = |v: u32, delta: i64| {
            // A boundary vertex has one edge more than faces; its target is 4, inside 6.
            let (valence, target) = match boundary[v as usize] {
                true => (m.degree(v) as i64 + 1, 4),
                false => (m.degree(v) as i64, 6),
            };
            let e = valence + delta - target;
            e * e
        };
        let before = dev(a, 0) + dev(b, 0) + dev(c, 0) + dev(d, 0);
        let after = dev(a, -1) + dev(b, -1) + dev(c, 1) + dev(d, 1);
        if after >= before {
            return false;
        }
        let (t1, t2) = (face(m, f1), face(m, f2));
        let (new1, new2) = ([a, d, c], [b, c, d]);
        let old_min = min_angle(m, t1).min(min_angle(m, t2));
        let new_min = min_angle(m, new1).min(min_angle(m, new2));
        if new_min < min_angle_deg.min(old_min) {
            return false;
        }
        let (n1, n2) = (normal(m, new1), normal(m, new2));
        let mean_old = normal(m, t1) + normal(m, t2);
        if n1.dot(mean_old) <= 0.0 || n2.dot(mean_old) <= 0.0 || n1.dot(n2) < 0.5 {
            return false;
        }
        matches!(
            surface.closest_point_to_midpoint(m.position(c), m.position(d)),
            Some(sp) if sp.distance <= params.max_offset
        )
    };
    // The decision reads the four vertices of the edge's faces alone.
    flip_in_order(m, &edges, None, decide)
}

/// One relaxation step over the `movable` vertices. Each vertex's target is the area-weighted
/// mean, over its faces, of the apex of the equilateral triangle on the face's far edge (in the
/// face's plane, on the vertex's side): where the vertex would make each face equilateral, as
/// in angle-based smoothing (Zhou and Shimada, "An angle-based approach to two-dimensional mesh
/// smoothing", IMR 2000), which raises the triangles' quality faster than the centroid of a
/// Lloyd step does. The targets are found from the positions before the step, in parallel
/// (Jacobi), the move taken in the plane of the vertex's normal and then onto the surface. The
/// moves are then made in index order, each kept when no face around the vertex turns by more
/// than `max_normal_turn_deg`, and when the surface point is within 4 `max_offset` of the target
/// and faces the way the vertex does (not another sheet of a thin part). Returns the number of
/// moves.
fn relax<S: SurfaceQuery + ?Sized>(
    m: &mut Mesh,
    surface: &S,
    movable: &[bool],
    pins: &[DVec3],
    last: &mut [Option<SurfacePoint>],
    params: &Limits,
) -> usize {
    let cos_turn = params.max_normal_turn_deg.to_radians().cos();
    let mesh = &*m;
    let targets: Vec<(u32, SurfacePoint, bool)> = (0..mesh.vertex_count() as u32)
        .into_par_iter()
        .filter(|&v| movable[v as usize] && mesh.faces_around(v).len() >= 3)
        .filter_map(|v| {
            let old = mesh.position(v);
            let mut weighted = DVec3::ZERO;
            let mut area = 0.0;
            let mut n = DVec3::ZERO;
            for &f in mesh.faces_around(v) {
                let t = starting_at(face(mesh, f), v);
                let [p, q, r] = mesh.corners(t);
                let cross = (q - p).cross(r - p);
                n += cross;
                if let Some(apex) = equilateral_apex(p, q, r) {
                    let a = 0.5 * cross.length();
                    weighted += a * apex;
                    area += a;
                }
            }
            let n = n.normalize_or_zero();
            if area <= 0.0 || n == DVec3::ZERO {
                return None;
            }
            let mut d = weighted / area - old;
            d -= n * n.dot(d);
            // The vertex lies on the surface: the target is within the move's length of it, and
            // near the vertex's last target.
            let (p, reach) = (old + d, 4.0 * params.max_offset);
            let sp = match &last[v as usize] {
                Some(from) => surface.closest_point_near(p, from, reach),
                None => surface.closest_point_hinted(p, d.length(), reach),
            }?;
            Some((v, sp, surface.smooth_normal(&sp).dot(n) >= 0.5))
        })
        .collect();
    for &(v, sp, _) in &targets {
        last[v as usize] = Some(sp);
    }
    let targets = targets
        .into_iter()
        .filter(|t| t.2)
        .map(|(v, sp, _)| (v, sp.position));
    let mut moves = 0;
    let mut old_normals: Vec<DVec3> = Vec::new();
    for (v, p) in targets {
        let old = m.position(v);
        old_normals.clear();
        old_normals.extend(m.faces_around(v).iter().map(|&f| normal(m, face(m, f))));
        if m.relocate_vertex(v, p).is_err() {
            continue;
        }
        let turned = m
            .faces_around(v)
            .iter()
            .zip(&old_normals)
            .any(|(&f, &n0)| normal(m, face(m, f)).dot(n0) < cos_turn);
        // The vertex's position before the relaxation is a point of the surface: the faces
        // around it must stay near it (a vertex does not slide off a tip or a ridge).
        let off = distance_to_faces(m, m.faces_around(v), pins[v as usize]) > params.max_offset;
        if turned || off {
            let _ = m.relocate_vertex(v, old);
        } else {
            moves += 1;
        }
    }
    moves
}

/// Tangential relaxation with valence flips (see the module), `iterations` times, then max-min
/// flips to a Delaunay mesh. Vertices with `fixed[v]`, on a boundary or at a protected edge do
/// not move; protected and boundary edges are not flipped.
pub(super) fn smooth<S: SurfaceQuery + ?Sized>(
    m: &mut Mesh,
    surface: &S,
    fixed: &[bool],
    params: &Limits,
    iterations: usize,
) -> SmoothStats {
    let mut stats = SmoothStats::default();
    if iterations == 0 {
        return stats;
    }
    let movable: Vec<bool> = (0..m.vertex_count() as u32)
        .map(|v| {
            !fixed.get(v as usize).copied().unwrap_or(false)
                && !m.is_boundary_vertex(v)
                && !m.ring(v).iter().any(|&u| m.is_protected(v, u))
        })
        .collect();
    let pins: Vec<DVec3> = m.positions().to_vec();
    let crossing_before = crossing_faces(m.positions(), &m.live_faces().0);
    // Interior flips do not change which vertices are on the boundary.
    let boundary: Vec<bool> = (0..m.vertex_count() as u32)
        .map(|v| m.is_boundary_vertex(v))
        .collect();
    // Each vertex's last target on the surface, where its next search starts.
    let mut last = vec![None; m.vertex_count()];
    for _ in 0..iterations {
        stats.valence_flips +=
            valence_flips(m, surface, &boundary, params, VALENCE_FLIP_MIN_ANGLE_DEG);
        stats.moves += relax(m, surface, &movable, &pins, &mut last, params);
    }
    let mut positions = m.positions().to_vec();
    undo_new_crossings(&mut positions, &m.live_faces().0, &pins, &crossing_before);
    for (v, &p) in positions.iter().enumerate() {
        if p != m.position(v as u32) {
            // A position the mesh had: finite.
            let _ = m.relocate_vertex(v as u32, p);
        }
    }
    let mut edges: Vec<(u32, u32)> = m.directed_edges().filter(|&(a, b)| a < b).collect();
    edges.sort_unstable();
    for _ in 0..3 {
        let f = super::relax::flip_all(m, surface, params, &edges, None);
        stats.delaunay_flips += f;
        if f == 0 {
            break;
        }
        edges = m.directed_edges().filter(|&(a, b)| a < b).collect();
        edges.sort_unstable();
    }
    stats
}
