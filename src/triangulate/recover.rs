//! Recovery of required edges missing from a triangulation: the creases' consecutive samples,
//! which the restricted Delaunay triangulation connects wherever their Voronoi cells meet but not
//! where a crease leaves a corner at a small angle to another (the cells of the two creases'
//! samples crowd each other out there).
//!
//! The edge insertion of constrained Delaunay triangulation (Anglada, "An improved incremental
//! algorithm for constructing restricted Delaunay triangulations", Computers & Graphics 21(2),
//! 1997; Shewchuk, "Constrained Delaunay tetrahedralizations and provably good boundary
//! recovery", IMR 2002, Sec. 2), on a surface: the faces that the segment between the two ends
//! crosses are found by a walk from one end in the plane normal to the mean normal of the faces
//! around the ends, cut out, and the two sides of the cavity triangulated again (ear clipping,
//! the best-shaped ear first) with the segment as an edge. Where that projection is not
//! one-to-one on the faces it touches, the walk meets a vertex on the segment, or a new
//! triangle would be a sliver (an angle below `RECOVERY_MIN_ANGLE_DEG`: a vertex a hair off the
//! segment), the edge stays missing (the report counts it), unless flips put it in: the one
//! edge between its ends when they are the opposite corners of its two faces, or that after
//! a flip of an edge of one end's link (a crease sample whose faces all lie on one side of the
//! crease, under a face that spans it).

use glam::{DVec2, DVec3};
use robust::{orient2d, Coord};
use rustc_hash::{FxHashMap, FxHashSet};

use crate::geometry::tolerance::RECOVERY_MIN_ANGLE_DEG;
use crate::geometry::triangle::{
    is_degenerate_triangle, triangle_angles_deg, triangle_min_angle_deg,
};
use crate::mesh::edit::{starting_at, EditMesh};

/// The longest walk (faces crossed) one edge may take: a segment crossing more faces than this
/// is not a crease edge between neighbouring samples.
const MAX_CROSSED_FACES: usize = 64;

/// The angle (degrees) at the middle of three consecutive crease samples above which a face on
/// them lies along the crease (its smallest angle is below 30°) and its long side is flipped
/// ([`flip_crease_slivers`]).
const CREASE_SLIVER_DEG: f64 = 120.0;

/// What [`recover_edges`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RecoverStats {
    /// Required edges that were not in the mesh.
    pub missing: usize,
    /// Of those, the ones put in.
    pub recovered: usize,
}

/// Puts each edge of `edges` (vertex pairs of `m`) that is not in `m` into it, where its
/// segment crosses a near-planar strip of faces (see the module's description), and protects
/// every edge of `edges` that is then in `m` ([`EditMesh::protect_edge`]). New faces get
/// `label`. Deterministic (edges in the order given).
pub fn recover_edges<L: Copy>(m: &mut EditMesh<L>, edges: &[[u32; 2]], label: L) -> RecoverStats {
    let mut stats = RecoverStats::default();
    for &[a, b] in edges {
        if a == b {
            continue;
        }
        if !m.has_edge(a, b) {
            stats.missing += 1;
            if insert_edge(m, a, b, label)
                || flip_into(m, a, b, label)
                || insert_edge_after_link_flip(m, a, b, label)
            {
                stats.recovered += 1;
            }
        }
        if m.has_edge(a, b) {
            m.protect_edge(a, b);
        }
    }
    stats
}

/// Puts `a`–`b` in ([`insert_edge`]) after flipping one edge of the link of `a` or `b`: a crease
/// sample whose faces all lie on one side of the crease (three faces tucked under a face that
/// spans the crease, as the triangulation can leave where two creases run a third of a spacing
/// apart) has no fan the walk can start from; the flip of the link edge it shares with that face
/// gives it a face on the other side. Each unprotected link edge is tried in turn (`a`'s first,
/// in face order); the flip is kept only when its two faces are [`well_flipped`] and the
/// insertion (or [`flip_into`]) then succeeds; otherwise the two faces are put back as they
/// were. Deterministic.
fn insert_edge_after_link_flip<L: Copy>(m: &mut EditMesh<L>, a: u32, b: u32, label: L) -> bool {
    for end in [a, b] {
        let link: Vec<(u32, u32)> = m
            .faces_around(end)
            .iter()
            .filter_map(|&f| m.face(f))
            .map(|t| {
                let t = starting_at(t, end);
                (t[1], t[2])
            })
            .collect();
        for (p, q) in link {
            let kept = flip_or_undo(m, p, q, label, |m, new| {
                well_flipped(m, new, true)
                    && (insert_edge(m, a, b, label) || flip_into(m, a, b, label))
            });
            if kept {
                return true;
            }
        }
    }
    false
}

/// Whether the two faces in slots `new` (an edge flip's) have no angle below
/// [`RECOVERY_MIN_ANGLE_DEG`] and, with `unfolded`, do not fold onto each other (their normals
/// less than 90° apart; a flip onto a crease edge makes the crease's own angle there).
fn well_flipped<L: Copy>(m: &EditMesh<L>, new: [u32; 2], unfolded: bool) -> bool {
    let faces = new.map(|g| m.face(g).map(|t| m.corners(t)));
    let normal = |c: [DVec3; 3]| (c[1] - c[0]).cross(c[2] - c[0]);
    match faces {
        [Some(x), Some(y)] => {
            triangle_min_angle_deg(x) >= RECOVERY_MIN_ANGLE_DEG
                && triangle_min_angle_deg(y) >= RECOVERY_MIN_ANGLE_DEG
                && (!unfolded || normal(x).dot(normal(y)) > 0.0)
        }
        _ => false,
    }
}

/// Puts `a`–`b` in by flipping the one edge between them, when `a` and `b` are the opposite
/// corners of its two faces and that edge is not protected: the one crossing that
/// [`insert_edge`]'s walk needs no projection for (its fans need not project one-to-one). The
/// flip is kept when its faces have no angle below [`RECOVERY_MIN_ANGLE_DEG`], else undone.
/// Deterministic.
fn flip_into<L: Copy>(m: &mut EditMesh<L>, a: u32, b: u32, label: L) -> bool {
    let across = m.faces_around(a).iter().find_map(|&f| {
        let t = starting_at(m.face(f)?, a);
        let g = m.face_on(t[2], t[1])?;
        (starting_at(m.face(g)?, t[2])[2] == b).then_some((t[1], t[2]))
    });
    let Some((x, y)) = across else {
        return false;
    };
    flip_or_undo(m, x, y, label, |m, new| well_flipped(m, new, false))
}

/// Flips the unprotected edge `p`–`q` and keeps the flip when `keep` (given the mesh after it
/// and the new faces' slots) says so, having made any further changes it keeps; otherwise the
/// two faces are put back as they were ([`unflip`]: the flip's faces are there again when
/// `keep`'s own changes failed, maybe in other slots). Whether the flip was kept.
fn flip_or_undo<L: Copy>(
    m: &mut EditMesh<L>,
    p: u32,
    q: u32,
    label: L,
    keep: impl FnOnce(&mut EditMesh<L>, [u32; 2]) -> bool,
) -> bool {
    if m.is_protected(p, q) {
        return false;
    }
    let Ok((f1, f2, _, _)) = m.edge_faces(p, q) else {
        return false;
    };
    let (Some(old1), Some(old2)) = (m.face(f1), m.face(f2)) else {
        return false;
    };
    let (l1, l2) = (m.label(f1), m.label(f2));
    let Ok(new) = m.flip_edge(p, q, label) else {
        return false;
    };
    let flipped = new.map(|g| m.face(g));
    if keep(m, new) {
        return true;
    }
    unflip(m, flipped, [(old1, l1), (old2, l2)]);
    false
}

/// Undoes an edge flip: removes its two faces `flipped` (found by their corners, in whatever
/// slots they are) and puts the faces `old` back with their labels.
fn unflip<L: Copy>(m: &mut EditMesh<L>, flipped: [Option<[u32; 3]>; 2], old: [([u32; 3], L); 2]) {
    for t in flipped.into_iter().flatten() {
        if let Some(f) = m.face_on(t[0], t[1]) {
            if m.face(f).is_some_and(|u| starting_at(u, t[0]) == t) {
                let _ = m.remove_face(f);
            }
        }
    }
    for (t, l) in old {
        let _ = m.add_face(t, l);
    }
}

/// Closes the slits a triangulation can leave along a crease with graded samples: a hole of
/// three edges whose corners lie on a line (one crease sample between two others, which one
/// sheet's faces skip). The face across the hole's long side is split at the middle corner.
/// Returns how many were closed. Deterministic.
pub fn close_slits<L: Copy>(m: &mut EditMesh<L>, label: L) -> usize {
    let half = m.boundary_half_edges();
    let missing: FxHashSet<(u32, u32)> = half.iter().copied().collect();
    let mut from: FxHashMap<u32, Vec<u32>> = FxHashMap::default();
    for &(p, q) in &half {
        from.entry(p).or_default().push(q);
    }
    let mut closed = 0;
    for &(p, q) in &half {
        let Some(rs) = from.get(&q) else { continue };
        for &r in rs {
            // Each hole once: from its smallest corner.
            if !missing.contains(&(r, p)) || p > q || p > r {
                continue;
            }
            let corners = [p, q, r].map(|v| m.position(v));
            if !is_degenerate_triangle(corners) {
                continue;
            }
            // The longest side u → v (a missing direction) and the corner w between.
            let sides = [(p, q, r), (q, r, p), (r, p, q)];
            let (u, v, w) = sides
                .into_iter()
                .max_by(|x, y| {
                    let l = |s: &(u32, u32, u32)| m.position(s.0).distance(m.position(s.1));
                    l(x).total_cmp(&l(y))
                })
                .unwrap_or((p, q, r));
            let Some(f) = m.face_on(v, u) else { continue };
            let Some(t) = m.face(f) else { continue };
            let x = starting_at(t, v)[2];
            let l = m.label(f);
            if m.remove_face(f).is_err() {
                continue;
            }
            if m.fill_hole(&[[v, w, x], [w, u, x]], label).is_ok() {
                closed += 1;
            } else {
                let _ = m.add_face(t, l);
            }
        }
    }
    closed
}

/// Flips the long side of the faces that lie along a crease: three consecutive crease samples
/// (two protected edges meeting at the middle one) joined by a face whose angle at the middle is
/// over [`CREASE_SLIVER_DEG`], when the two faces after the flip have a larger smallest angle
/// than the two before. The face across the long side takes the middle sample instead, and the
/// crease keeps both edges. A flip that the mesh refuses (the new edge already there) leaves the
/// face. Returns how many were flipped. Deterministic.
pub fn flip_crease_slivers<L: Copy>(m: &mut EditMesh<L>, label: L) -> usize {
    let (faces, _) = m.live_faces();
    let mut flipped = 0;
    for t in faces {
        if !m.has_edge(t[0], t[1]) || !m.has_edge(t[1], t[2]) || !m.has_edge(t[2], t[0]) {
            continue;
        }
        let angles = triangle_angles_deg(m.corners(t));
        if !(angles[0].max(angles[1]).max(angles[2]) > CREASE_SLIVER_DEG) {
            continue;
        }
        // The middle corner: the largest angle, its two sides crease edges.
        let k = (0..3)
            .max_by(|&i, &j| angles[i].total_cmp(&angles[j]))
            .unwrap_or(0);
        let (w, u, v) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
        if m.is_protected(u, v) || !m.is_protected(w, u) || !m.is_protected(v, w) {
            continue;
        }
        // The face across u–v, [v, u, d]; after the flip [u, d, w] and [v, w, d].
        let Some(d) = m
            .face_on(v, u)
            .and_then(|f| m.face(f))
            .map(|t| starting_at(t, v)[2])
        else {
            continue;
        };
        let smallest = |t: [u32; 3]| triangle_min_angle_deg(m.corners(t));
        let before = smallest(t).min(smallest([v, u, d]));
        let after = smallest([u, d, w]).min(smallest([v, w, d]));
        if after > before && m.flip_edge(u, v, label).is_ok() {
            flipped += 1;
        }
    }
    flipped
}

/// Inserts the edge `a`–`b` by re-triangulating the faces its segment crosses. False (the mesh
/// unchanged) when that cannot be done cleanly.
fn insert_edge<L: Copy>(m: &mut EditMesh<L>, a: u32, b: u32, label: L) -> bool {
    // The projection plane: normal to the area-weighted mean normal of the faces at both ends.
    let mut normal = DVec3::ZERO;
    for &v in &[a, b] {
        for &f in m.faces_around(v) {
            let Some(t) = m.face(f) else { continue };
            let [p, q, r] = m.corners(t);
            normal += (q - p).cross(r - p);
        }
    }
    let Some(n) = normal.try_normalize() else {
        return false;
    };
    let (u, v) = n.any_orthonormal_pair();
    let origin = m.position(a);
    let proj = |x: u32| -> DVec2 {
        let d = m.position(x) - origin;
        DVec2::new(d.dot(u), d.dot(v))
    };
    let ccw = |t: [u32; 3]| orient(proj(t[0]), proj(t[1]), proj(t[2])) > 0.0;
    // The fans at both ends must project one-to-one (every face counter-clockwise).
    for &end in &[a, b] {
        if m.is_boundary_vertex(end) {
            return false;
        }
        for &f in m.faces_around(end) {
            if m.face(f).is_some_and(|t| !ccw(t)) {
                return false;
            }
        }
    }
    let (pa, pb) = (proj(a), proj(b));
    // The face at `a` whose corner the segment leaves through: [a, x, y] with x right of the
    // segment and y left of it.
    let Some((first, x, y)) = m.faces_around(a).iter().find_map(|&f| {
        let t = starting_at(m.face(f)?, a);
        let (px, py) = (proj(t[1]), proj(t[2]));
        (orient(pa, pb, px) < 0.0 && orient(pa, pb, py) > 0.0).then_some((f, t[1], t[2]))
    }) else {
        return false;
    };
    let mut cavity = vec![first];
    let (mut right, mut left) = (vec![x], vec![y]);
    // The crossed edge, as the face behind it has it: right → left.
    let (mut r, mut l) = (x, y);
    loop {
        if cavity.len() > MAX_CROSSED_FACES {
            return false;
        }
        let Some(f) = m.face_on(l, r) else {
            return false;
        };
        let Some(t) = m.face(f) else { return false };
        if !ccw(t) {
            return false;
        }
        cavity.push(f);
        let z = starting_at(t, l)[2];
        if z == b {
            break;
        }
        let side = orient(pa, pb, proj(z));
        if side > 0.0 {
            left.push(z);
            l = z;
        } else if side < 0.0 {
            right.push(z);
            r = z;
        } else {
            // A vertex on the segment.
            return false;
        }
    }
    // The two sides, counter-clockwise: a, b, then the left chain back; b, a, then the right
    // chain forward.
    let mut left_polygon = vec![a, b];
    left_polygon.extend(left.iter().rev());
    let mut right_polygon = vec![b, a];
    right_polygon.extend(right.iter());
    let mut triangles = Vec::new();
    for polygon in [&left_polygon, &right_polygon] {
        let points: Vec<DVec2> = polygon.iter().map(|&x| proj(x)).collect();
        let Some(ears) = ear_clip(&points, |k| m.position(polygon[k])) else {
            return false;
        };
        triangles.extend(ears.into_iter().map(|t| t.map(|k| polygon[k])));
    }
    // No sliver for a vertex a hair off the segment: the edge stays out instead.
    let sliver = triangles
        .iter()
        .any(|&t| triangle_min_angle_deg(m.corners(t)) < RECOVERY_MIN_ANGLE_DEG);
    if sliver {
        return false;
    }
    // Cut the cavity out and fill it; put the old faces back if the new ones do not fit.
    let old: Vec<[u32; 3]> = cavity.iter().filter_map(|&f| m.face(f)).collect();
    if old.len() != cavity.len() {
        return false;
    }
    let labels: Vec<L> = cavity.iter().map(|&f| m.label(f)).collect();
    for &f in &cavity {
        if m.remove_face(f).is_err() {
            return false;
        }
    }
    if m.fill_hole(&triangles, label).is_ok() {
        return true;
    }
    for (t, l) in old.into_iter().zip(labels) {
        // The faces were there a moment ago: they fit again.
        let _ = m.add_face(t, l);
    }
    false
}

/// The orientation of the triangle p, q, r in the plane (positive: counter-clockwise), exact.
fn orient(p: DVec2, q: DVec2, r: DVec2) -> f64 {
    orient2d(
        Coord { x: p.x, y: p.y },
        Coord { x: q.x, y: q.y },
        Coord { x: r.x, y: r.y },
    )
}

/// Ear clipping of the simple counter-clockwise polygon `points` (in the projection plane),
/// the ear whose 3-D triangle (`corner` gives the positions) has the largest smallest angle
/// first. Triangles as index triples into `points`. None when no ear is left before the end
/// (the polygon is not simple in the projection).
fn ear_clip(points: &[DVec2], corner: impl Fn(usize) -> DVec3) -> Option<Vec<[usize; 3]>> {
    let mut ring: Vec<usize> = (0..points.len()).collect();
    let mut out = Vec::with_capacity(points.len().saturating_sub(2));
    while ring.len() > 3 {
        let n = ring.len();
        let mut best: Option<(f64, usize)> = None;
        for i in 0..n {
            let (p, q, r) = (ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n]);
            if orient(points[p], points[q], points[r]) <= 0.0 {
                continue;
            }
            // No other corner inside or on the ear.
            let blocked = ring.iter().any(|&s| {
                s != p
                    && s != q
                    && s != r
                    && orient(points[p], points[q], points[s]) >= 0.0
                    && orient(points[q], points[r], points[s]) >= 0.0
                    && orient(points[r], points[p], points[s]) >= 0.0
            });
            if blocked {
                continue;
            }
            let score = triangle_min_angle_deg([corner(p), corner(q), corner(r)]);
            if best.is_none_or(|(s, _)| score > s) {
                best = Some((score, i));
            }
        }
        let (_, i) = best?;
        let n = ring.len();
        out.push([ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n]]);
        ring.remove(i);
    }
    if ring.len() == 3 {
        if orient(points[ring[0]], points[ring[1]], points[ring[2]]) <= 0.0 {
            return None;
        }
        out.push([ring[0], ring[1], ring[2]]);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::edit::{EditError, SlotPolicy};
    use crate::mesh::test_meshes::grid;

    const N: usize = 8;

    fn index(i: usize, j: usize) -> u32 {
        (j * (N + 1) + i) as u32
    }

    /// The summed area vectors of the live faces.
    fn area(m: &EditMesh<()>) -> DVec3 {
        m.live_faces()
            .0
            .iter()
            .map(|&t| {
                let [p, q, r] = m.corners(t);
                0.5 * (q - p).cross(r - p)
            })
            .sum()
    }

    #[test]
    fn a_missing_edge_across_a_grid_is_put_in_protected_and_the_surface_kept() {
        // A flat grid folded by 90° along j = 4 (a crease), and a segment from (2, 3) to (6, 5)
        // across it that no edge follows: it crosses several faces on both sheets.
        for fold in [0.0f64, 90.0] {
            let (s, c) = fold.to_radians().sin_cos();
            let mesh = grid(N, |i, j| {
                let y = j as f64 - 4.0;
                if y <= 0.0 {
                    DVec3::new(i as f64, y, 0.0)
                } else {
                    DVec3::new(i as f64, y * c, y * s)
                }
            });
            let mut m: EditMesh<()> = EditMesh::from_trimesh(&mesh, |_| (), SlotPolicy::Reuse);
            let (a, b) = (index(3, 4), index(6, 5));
            assert!(!m.has_edge(a, b));
            let before = area(&m);
            let stats = recover_edges(&mut m, &[[a, b]], ());
            assert_eq!(
                stats,
                RecoverStats {
                    missing: 1,
                    recovered: 1
                },
                "fold {fold}"
            );
            assert!(m.has_edge(a, b));
            m.sanity_check().unwrap();
            // The same surface (the cavity's two sides are planar pieces of it when the segment
            // runs in one sheet; across the fold the area vector is kept to rounding only when
            // flat, so the flat case checks it).
            if fold == 0.0 {
                assert!((area(&m) - before).length() < 1e-9);
            }
            assert_eq!(m.live_faces().0.len(), 2 * N * N);
            // Flips and collapses keep it.
            assert!(matches!(
                m.flip_edge(a, b, ()),
                Err(EditError::ProtectedEdge { .. })
            ));
            let p = m.position(a);
            assert!(m.collapse_edge(a, b, p, ()).is_err());
        }
    }

    #[test]
    fn an_edge_through_a_vertex_or_at_the_boundary_is_left_out() {
        let mesh = grid(N, |i, j| DVec3::new(i as f64, j as f64, 0.0));
        let mut m: EditMesh<()> = EditMesh::from_trimesh(&mesh, |_| (), SlotPolicy::Reuse);
        // (2, 2) to (4, 6) passes through (3, 4); (0, 2) to (3, 3) starts on the boundary.
        let stats = recover_edges(
            &mut m,
            &[[index(2, 2), index(4, 6)], [index(0, 2), index(3, 3)]],
            (),
        );
        assert_eq!(
            stats,
            RecoverStats {
                missing: 2,
                recovered: 0
            }
        );
        m.sanity_check().unwrap();
        assert_eq!(m.live_faces().0.len(), 2 * N * N);
    }

    #[test]
    fn a_face_along_three_crease_samples_has_its_long_side_flipped() {
        // a, w, v consecutive crease samples (w 0.1 off the line, 169° at it); the face a–v–w
        // lies along the crease, the face below takes a–v, two above meet at e.
        let positions = vec![
            DVec3::new(0.0, 0.0, 0.0),  // a
            DVec3::new(2.0, 0.0, 0.0),  // v
            DVec3::new(1.0, 0.1, 0.0),  // w
            DVec3::new(1.0, -1.0, 0.0), // d
            DVec3::new(1.0, 1.0, 0.0),  // e
        ];
        let faces = vec![[0, 1, 2], [1, 0, 3], [0, 2, 4], [2, 1, 4]];
        let mesh = crate::mesh::TriMesh::new(positions, faces);
        let mut m: EditMesh<()> = EditMesh::from_trimesh(&mesh, |_| (), SlotPolicy::Reuse);
        // Unprotected, the crease is not known: nothing is flipped.
        assert_eq!(flip_crease_slivers(&mut m, ()), 0);
        m.protect_edge(0, 2);
        m.protect_edge(2, 1);
        assert_eq!(flip_crease_slivers(&mut m, ()), 1);
        m.sanity_check().unwrap();
        assert!(!m.has_edge(0, 1) && m.has_edge(2, 3));
        assert!(m.has_edge(0, 2) && m.has_edge(2, 1));
        let (faces, _) = m.live_faces();
        let smallest = faces
            .iter()
            .map(|&t| triangle_min_angle_deg(m.corners(t)))
            .fold(f64::INFINITY, f64::min);
        assert!(smallest > 30.0, "{smallest}"); // 5.7° before the flip
        assert_eq!(flip_crease_slivers(&mut m, ()), 0);
    }

    #[test]
    fn a_slit_along_a_line_of_three_vertices_is_closed() {
        // a, w, b on the x axis; one face above spans a–b, two below meet at w.
        let positions = vec![
            DVec3::new(0.0, 0.0, 0.0),  // a
            DVec3::new(2.0, 0.0, 0.0),  // b
            DVec3::new(1.0, 0.0, 0.0),  // w
            DVec3::new(1.0, 1.0, 0.0),  // x
            DVec3::new(1.0, -1.0, 0.0), // y
        ];
        let mesh = crate::mesh::TriMesh::new(positions, vec![[0, 1, 3], [0, 4, 2], [2, 4, 1]]);
        let mut m: EditMesh<()> = EditMesh::from_trimesh(&mesh, |_| (), SlotPolicy::Reuse);
        assert!(!m.has_edge(2, 3));
        assert_eq!(close_slits(&mut m, ()), 1);
        m.sanity_check().unwrap();
        assert_eq!(m.live_faces().0.len(), 4);
        // Both halves of the line now have a face on either side.
        for (p, q) in [(0, 2), (2, 1)] {
            assert!(m.face_on(p, q).is_some() && m.face_on(q, p).is_some());
        }
        assert!(!m.has_edge(0, 1));
        // Nothing else to close.
        assert_eq!(close_slits(&mut m, ()), 0);
    }

    #[test]
    fn an_edge_past_a_vertex_a_hair_off_it_is_left_out_rather_than_make_a_sliver() {
        // (2, 2) to (4, 6) passes through (3, 4); move that vertex a hair aside.
        let mesh = grid(N, |i, j| {
            let x = if (i, j) == (3, 4) {
                3.0 + 1e-4
            } else {
                i as f64
            };
            DVec3::new(x, j as f64, 0.0)
        });
        let mut m: EditMesh<()> = EditMesh::from_trimesh(&mesh, |_| (), SlotPolicy::Reuse);
        let stats = recover_edges(&mut m, &[[index(2, 2), index(4, 6)]], ());
        assert_eq!(stats.recovered, 0);
        m.sanity_check().unwrap();
        let worst = m
            .live_faces()
            .0
            .iter()
            .map(|&t| triangle_min_angle_deg(m.corners(t)))
            .fold(f64::INFINITY, f64::min);
        assert!(worst > 40.0, "{worst}");
    }
}
