//! Max-min flips and relaxation of the vertices of poor triangles, guarded against the input
//! surface and, with a [`CrossingGuard`], against making a crossing.

use glam::DVec3;

use super::*;
use crate::triangulate::flip::{flip_in_order_vetoed, max_min_candidate};

/// Max-min angle flips ([`max_min_candidate`]) of the edges of the faces around `poor_vertices`
/// (the poor triangles' vertices, [`PoorFaces::vertices`]), where the new faces face the way
/// the old ones did, stay within `max_offset` of the surface and cross no face (`guard`).
/// Returns the number of flips.
pub(super) fn flip_poor<S: SurfaceQuery + ?Sized>(
    m: &mut Mesh,
    surface: &S,
    params: &Limits,
    poor_vertices: &[u32],
    guard: &mut SweepGuard,
) -> usize {
    let mut edges: Vec<(u32, u32)> = Vec::new();
    for &v in poor_vertices {
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
    flip_all(m, surface, params, &edges, Some(guard))
}

/// Max-min angle flips ([`max_min_candidate`]) of `edges`, in order, where the new faces face
/// the way the old ones did and stay within `max_offset` of the surface, and with a `guard`,
/// cross no face (the guard is kept up to date). Returns the number of flips.
pub(super) fn flip_all<S: SurfaceQuery + ?Sized>(
    m: &mut Mesh,
    surface: &S,
    params: &Limits,
    edges: &[(u32, u32)],
    mut guard: Option<&mut SweepGuard>,
) -> usize {
    let accept = |m: &Mesh, x: u32, y: u32| {
        let Some(flip) = max_min_candidate(m, x, y) else {
            return false;
        };
        let [t1, t2] = flip.old;
        let [new1, new2] = flip.new;
        let (c, d) = (t1[2], t2[2]);
        // The new faces must face the way the old ones did and stay on the surface.
        let (n1, n2) = (normal(m, t1), normal(m, t2));
        let (m1, m2) = (normal(m, new1), normal(m, new2));
        let mean_old = n1 + n2;
        if m1.dot(mean_old) <= 0.0 || m2.dot(mean_old) <= 0.0 || m1.dot(m2) < 0.0 {
            return false;
        }
        let (px, py, pc, pd) = (m.position(x), m.position(y), m.position(c), m.position(d));
        let Some(new_mid) = surface.closest_point_to_midpoint(pc, pd) else {
            return false;
        };
        if new_mid.distance > params.max_offset {
            return false;
        }
        let Some(old_mid) = surface.closest_point_to_midpoint(px, py) else {
            return false;
        };
        distance_to(m, [new1, new2], old_mid.position) <= params.max_offset
    };
    let guarded = guard.is_some();
    let cell = std::cell::RefCell::new(guard.take());
    flip_in_order_vetoed(
        m,
        edges,
        None,
        accept,
        |m, x, y| {
            !guarded
                || max_min_candidate(m, x, y).is_some_and(|flip| {
                    cell.borrow()
                        .as_ref()
                        .is_some_and(|g| !g.refuses(m, &flip.new, &flip.slots))
                })
        },
        |m, [_, _, c, d]| {
            if let Some(g) = cell.borrow_mut().as_mut() {
                let slots: Vec<u32> = [m.face_on(c, d), m.face_on(d, c)]
                    .into_iter()
                    .flatten()
                    .collect();
                g.changed(m, &slots);
            }
        },
    )
}

/// One sweep of relaxation over `poor_vertices` (the poor triangles' vertices,
/// [`PoorFaces::vertices`]; see [`optimize`]).
/// Returns the number of moves.
pub(super) fn relax_poor<S: SurfaceQuery + ?Sized>(
    m: &mut Mesh,
    surface: &S,
    fixed: &[bool],
    params: &Limits,
    poor_vertices: &[u32],
    guard: &mut SweepGuard,
) -> usize {
    let cos_turn = params.max_normal_turn_deg.to_radians().cos();
    let mut moves = 0;
    let mut ring: Vec<u32> = Vec::new();
    for &v in poor_vertices {
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
            targets.extend(equilateral_apex(old, m.position(t[1]), m.position(t[2])));
        }
        let mut best = (worst_q(m), old);
        for (target, t) in targets
            .iter()
            .flat_map(|&c| [1.0, 0.5, 0.25].map(|t| (c, t)))
        {
            let Some(sp) = surface.closest_point_hinted(
                old.lerp(target, t),
                t * old.distance(target),
                f64::MAX,
            ) else {
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
                && !crosses_around(m, guard, &faces)
            {
                best = (q, sp.position);
            }
        }
        if m.relocate_vertex(v, best.1).is_ok() && best.1 != old {
            moves += 1;
            guard.changed(m, &faces);
        }
    }
    moves
}

/// Whether the faces in `slots` of `m`, as they are now, cross a face of `guard` (theirs left
/// out) or one another.
pub(super) fn crosses_around(m: &Mesh, guard: &SweepGuard, slots: &[u32]) -> bool {
    let faces: Vec<[u32; 3]> = slots.iter().filter_map(|&f| m.face(f)).collect();
    guard.refuses(m, &faces, slots)
}
