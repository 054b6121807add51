//! From voted umbrella triangles to a manifold mesh: accept the triangles every corner agrees on,
//! add the best of the others where they fit, fill the holes that remain, and repair vertices
//! whose faces do not form one fan.
//!
//! The faces are assembled in an [`EditMesh`]: every accepted face must use each directed edge
//! at most once. That single rule keeps every edge in at most two faces and the orientation
//! consistent. Boundary edges of an open input are usable in their own direction only (the
//! other is blocked), so they stay boundary edges.

use crate::geometry::polygon_triangulation::max_min_triangulation;
use glam::{DVec2, DVec3};
use rustc_hash::{FxHashMap, FxHashSet};

use super::refine::{flip_edges, insert_loose_samples, oriented_quality, RefineParams};
use super::tangent_delaunay::VotedTriangle;
use crate::mesh::edit::{EditMesh, SlotPolicy};

/// The weight of a folded triangle's Q (one turned against the samples' normals) when a hole's
/// polygon can be closed no other way: far below any unfolded triangle, so folds are the last
/// resort of the max-min polygon triangulation.
const FOLD_WEIGHT: f64 = 1e-3;

/// The mesh being assembled: faces in the order they were made, each with how it came in.
type Assembly = EditMesh<FaceSource>;

/// Parameters of the assembly.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AssemblyParams {
    /// Holes with more edges than this are left open (default 100).
    pub max_hole_edges: usize,
    /// Accept two-vote triangles greedily before filling holes (default false: the hole filler
    /// chooses better triangles where the umbrellas disagree).
    pub two_vote_phase: bool,
    /// Insertion of left-over samples and edge flips after the holes are closed.
    pub refine: RefineParams,
    /// Close loops whose only fill faces every triangle against its corners' normals (default
    /// true: on a closed surface every loop is a hole). False where the surface has edges (an
    /// open scan): such a loop is a sheet's outline seen from behind, left open and counted in
    /// [`AssemblyStats::outlines_left`].
    pub fill_outlines: bool,
}

impl Default for AssemblyParams {
    fn default() -> Self {
        AssemblyParams {
            max_hole_edges: 100,
            two_vote_phase: false,
            refine: RefineParams::default(),
            fill_outlines: true,
        }
    }
}

/// What the assembly did.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct AssemblyStats {
    /// Candidate triangles from all umbrellas.
    pub candidates: usize,
    /// Triangles with three votes accepted.
    pub accepted_three_votes: usize,
    /// Triangles with two votes accepted.
    pub accepted_two_votes: usize,
    /// Holes closed by the clean-up.
    pub holes_filled: usize,
    /// Triangles added to close them.
    pub hole_triangles: usize,
    /// Holes that could not be closed (too large, or no valid triangulation).
    pub holes_left: usize,
    /// Loops left open because the only way to close them faced every triangle against its
    /// corners' normals: the outline of a sheet seen from behind (a strip of an open scan a
    /// sample or two wide), not a hole.
    pub outlines_left: usize,
    /// Faces removed to repair vertices whose faces formed several fans.
    pub faces_removed_at_pinched_vertices: usize,
    /// Faces removed around holes that could not be closed, to retry them larger.
    pub faces_removed_growing_holes: usize,
    /// Samples in no face after hole filling that were inserted into a face.
    pub samples_inserted: usize,
    /// Edge flips of the refinement.
    pub edge_flips: usize,
}

/// How a face of the assembled mesh came in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum FaceSource {
    /// In the umbrellas of all three corners.
    ThreeVotes,
    /// In the umbrellas of two corners.
    TwoVotes,
    /// Added to close a hole.
    HoleFill,
    /// Made by an edge flip or a sample insertion of the refinement (see `refine`).
    Refined,
}

/// Assembles a mesh from voted triangles. `boundary_edges` (directed, surface on the left) may
/// only be used in their own direction. Returns the faces, how each came in, and what was done.
pub fn assemble(
    positions: &[DVec3],
    normals: &[DVec3],
    voted: &[VotedTriangle],
    boundary_edges: &[[u32; 2]],
    params: &AssemblyParams,
) -> (Vec<[u32; 3]>, Vec<FaceSource>, AssemblyStats) {
    let mut b: Assembly = EditMesh::new(positions.to_vec(), SlotPolicy::Append);
    let mut stats = AssemblyStats {
        candidates: voted.len(),
        ..Default::default()
    };
    for &[x, y] in boundary_edges {
        b.block_directed_edge(y, x);
    }
    for t in voted
        .iter()
        .filter(|t| t.votes >= 3 && !t.orientation_conflict)
    {
        if b.add_face(t.corners, FaceSource::ThreeVotes).is_ok() {
            stats.accepted_three_votes += 1;
        }
    }
    let mut two: Vec<(f64, [u32; 3])> = voted
        .iter()
        .filter(|t| params.two_vote_phase && t.votes == 2 && !t.orientation_conflict)
        .map(|t| (oriented_quality(&b, normals, t.corners), t.corners))
        .filter(|x| x.0 > 0.0)
        .collect();
    two.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
    for (_, t) in two {
        if b.add_face(t, FaceSource::TwoVotes).is_ok() {
            stats.accepted_two_votes += 1;
        }
    }
    for round in 0..6 {
        let mut failed = Vec::new();
        let FillResult {
            filled,
            added,
            left,
            outlines,
        } = fill_holes(&mut b, normals, params, &mut failed);
        if round < 4 {
            // Grow each hole that could not be closed by the faces around its corners: the
            // larger polygon (with the samples inside it) often has a valid triangulation where
            // the small one did not, as at thin parts where the local views disagreed.
            stats.faces_removed_growing_holes += grow_holes(&mut b, &failed);
        }
        stats.holes_filled += filled;
        stats.hole_triangles += added;
        stats.holes_left = left;
        stats.outlines_left = outlines;
        let removed = repair_pinched_vertices(&mut b);
        stats.faces_removed_at_pinched_vertices += removed;
        if removed == 0 && left == 0 {
            break;
        }
    }
    if params.refine.insert_loose_samples {
        stats.samples_inserted = insert_loose_samples(&mut b, normals, FaceSource::Refined);
    }
    stats.edge_flips = flip_edges(&mut b, normals, &params.refine, FaceSource::Refined);
    let (_, faces, sources) = b.into_parts();
    (faces, sources, stats)
}

/// Removes the faces that touch a corner of any of `holes`. Returns how many were removed.
fn grow_holes(b: &mut Assembly, holes: &[Vec<u32>]) -> usize {
    let corners: FxHashSet<u32> = holes.iter().flatten().copied().collect();
    let mut removed = 0;
    for f in 0..b.slots() as u32 {
        if let Some(t) = b.face(f) {
            if t.iter().any(|v| corners.contains(v)) && b.remove_face(f).is_ok() {
                removed += 1;
            }
        }
    }
    removed
}

/// Splits a closed walk at repeated vertices into simple loops.
fn simple_loops(walk: &[u32]) -> Vec<Vec<u32>> {
    let mut out = Vec::new();
    let mut stack: Vec<u32> = Vec::new();
    let mut pos: FxHashMap<u32, usize> = FxHashMap::default();
    for &v in walk {
        if let Some(&k) = pos.get(&v) {
            let cycle: Vec<u32> = stack.drain(k..).collect();
            for x in &cycle {
                pos.remove(x);
            }
            out.push(cycle);
        }
        pos.insert(v, stack.len());
        stack.push(v);
    }
    if !stack.is_empty() {
        out.push(stack);
    }
    out
}

fn fill_holes(
    b: &mut Assembly,
    normals: &[DVec3],
    params: &AssemblyParams,
    failed: &mut Vec<Vec<u32>>,
) -> FillResult {
    let edges = b.boundary_half_edges();
    let mut referenced = vec![false; b.vertex_count()];
    for t in b.live_faces().0 {
        for v in t {
            referenced[v as usize] = true;
        }
    }
    let mut loose: Vec<u32> = (0..b.vertex_count() as u32)
        .filter(|&v| !referenced[v as usize])
        .collect();
    let mut from: FxHashMap<u32, Vec<u32>> = FxHashMap::default();
    for &(x, y) in &edges {
        from.entry(x).or_default().push(y);
    }
    let mut used: FxHashSet<(u32, u32)> = FxHashSet::default();
    let (mut filled, mut added, mut left, mut outlines) = (0, 0, 0, 0);
    for &(x0, y0) in &edges {
        if used.contains(&(x0, y0)) {
            continue;
        }
        // Walk the hole.
        let mut walk = vec![x0];
        let (mut x, mut y) = (x0, y0);
        loop {
            used.insert((x, y));
            if y == x0 {
                break;
            }
            walk.push(y);
            let next = from
                .get(&y)
                .and_then(|v| v.iter().copied().find(|&z| !used.contains(&(y, z))));
            match next {
                Some(z) => {
                    x = y;
                    y = z;
                }
                None => break,
            }
            if walk.len() > 100_000 {
                break;
            }
        }
        for lp in simple_loops(&walk) {
            if lp.len() < 3 {
                continue;
            }
            if lp.len() > params.max_hole_edges {
                left += 1;
                continue;
            }
            let tris = triangulate_hole_with_interior(b, normals, &lp, &loose)
                .or_else(|| triangulate_polygon(b, normals, &lp, false))
                .or_else(|| triangulate_polygon(b, normals, &lp, true));
            // Every triangle of the only fill facing against its corners' normals: the loop
            // is a sheet's outline seen from behind (a strip of data a sample or two wide,
            // covered from one side), not a hole; closing it would give the strip a second
            // side on top of the first.
            if !params.fill_outlines
                && tris
                    .as_ref()
                    .is_some_and(|t| t.iter().all(|&t| oriented_quality(b, normals, t) <= 0.0))
            {
                outlines += 1;
                continue;
            }
            match tris {
                Some(tris) => match b.fill_hole(&tris, FaceSource::HoleFill) {
                    Ok(done) => {
                        filled += 1;
                        added += done.len();
                        for t in &tris {
                            for &v in t {
                                referenced[v as usize] = true;
                            }
                        }
                        loose.retain(|&v| !referenced[v as usize]);
                    }
                    // A fill the mesh refuses (a triangle of zero area: three samples on a
                    // line at a thin tip) is grown like one that was not found.
                    Err(_) => {
                        failed.push(lp);
                        left += 1
                    }
                },
                None => {
                    failed.push(lp);
                    left += 1
                }
            }
        }
    }
    FillResult {
        filled,
        added,
        left,
        outlines,
    }
}

/// What one round of [`fill_holes`] did.
struct FillResult {
    /// Loops closed.
    filled: usize,
    /// Triangles added to close them.
    added: usize,
    /// Loops that could not be closed.
    left: usize,
    /// Loops left open as outlines (see [`AssemblyStats::outlines_left`]).
    outlines: usize,
}

/// Whether segments p1-p2 and q1-q2 properly cross (shared endpoints do not count).
fn segments_cross(p1: DVec2, p2: DVec2, q1: DVec2, q2: DVec2) -> bool {
    let orient = |a: DVec2, b: DVec2, c: DVec2| (b - a).perp_dot(c - a);
    let (d1, d2) = (orient(q1, q2, p1), orient(q1, q2, p2));
    let (d3, d4) = (orient(p1, p2, q1), orient(p1, p2, q2));
    d1 * d2 < 0.0 && d3 * d4 < 0.0
}

/// Whether `p` is inside the polygon `poly` (even-odd rule).
fn inside_polygon(p: DVec2, poly: &[DVec2]) -> bool {
    let mut inside = false;
    let m = poly.len();
    for i in 0..m {
        let (a, c) = (poly[i], poly[(i + 1) % m]);
        if (a.y > p.y) != (c.y > p.y) && p.x < a.x + (p.y - a.y) * (c.x - a.x) / (c.y - a.y) {
            inside = !inside;
        }
    }
    inside
}

/// Fills the hole `lp` with a constrained Delaunay triangulation, in the plane of the hole's
/// Newell normal, of its boundary and of the samples that no face uses yet and that lie inside
/// it. `None` when the hole does not project to a simple polygon, faces away from its corners'
/// normals, or a triangle would not fit.
fn triangulate_hole_with_interior(
    b: &Assembly,
    normals: &[DVec3],
    lp: &[u32],
    loose: &[u32],
) -> Option<Vec<[u32; 3]>> {
    use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};
    let m = lp.len();
    let pts: Vec<DVec3> = lp.iter().map(|&v| b.position(v)).collect();
    let newell = (0..m)
        .map(|i| pts[i].cross(pts[(i + 1) % m]))
        .sum::<DVec3>();
    let n = newell.try_normalize()?;
    let avg_normal = lp.iter().map(|&v| normals[v as usize]).sum::<DVec3>();
    if n.dot(avg_normal) <= 0.0 {
        return None;
    }
    let (u, w) = crate::geometry::tangent_basis(n);
    let center = pts.iter().sum::<DVec3>() / m as f64;
    let to2 = |p: DVec3| DVec2::new((p - center).dot(u), (p - center).dot(w));
    let poly: Vec<DVec2> = pts.iter().map(|&p| to2(p)).collect();
    for i in 0..m {
        for j in i + 2..m {
            if i == 0 && j == m - 1 {
                continue;
            }
            if segments_cross(poly[i], poly[(i + 1) % m], poly[j], poly[(j + 1) % m]) {
                return None;
            }
        }
    }
    let radius2 = pts
        .iter()
        .map(|p| p.distance_squared(center))
        .fold(0.0, f64::max);
    let interior: Vec<u32> = loose
        .iter()
        .copied()
        .filter(|&v| {
            let p = b.position(v);
            p.distance_squared(center) <= radius2
                && normals[v as usize].dot(n) > 0.3
                && inside_polygon(to2(p), &poly)
        })
        .collect();
    #[derive(Clone, Copy)]
    struct V {
        p: Point2<f64>,
        index: u32,
    }
    impl spade::HasPosition for V {
        type Scalar = f64;
        fn position(&self) -> Point2<f64> {
            self.p
        }
    }
    let mut cdt: ConstrainedDelaunayTriangulation<V> = ConstrainedDelaunayTriangulation::new();
    let mut handles = Vec::with_capacity(m);
    for (k, &v) in lp.iter().enumerate() {
        let h = cdt
            .insert(V {
                p: Point2::new(poly[k].x, poly[k].y),
                index: v,
            })
            .ok()?;
        if cdt.vertex(h).data().index != v {
            return None;
        }
        handles.push(h);
    }
    for &v in &interior {
        let q = to2(b.position(v));
        let _ = cdt.insert(V {
            p: Point2::new(q.x, q.y),
            index: v,
        });
    }
    for k in 0..m {
        let (a, c) = (handles[k], handles[(k + 1) % m]);
        if !cdt.can_add_constraint(a, c) {
            return None;
        }
        cdt.add_constraint(a, c);
    }
    let mut out = Vec::new();
    for f in cdt.inner_faces() {
        let vs = f.vertices();
        let c2 = vs
            .iter()
            .map(|h| DVec2::new(h.position().x, h.position().y))
            .sum::<DVec2>()
            / 3.0;
        if inside_polygon(c2, &poly) {
            let t = vs.map(|h| h.data().index);
            if !b.fits(t) || oriented_quality(b, normals, t) <= 0.0 {
                return None;
            }
            out.push(t);
        }
    }
    if out.len() != m - 2 + 2 * interior.len() {
        return None;
    }
    Some(out)
}

/// The triangulation of the polygon `lp` (a hole's vertices in the order of its half-edges) that
/// maximizes the smallest triangle quality, with no diagonal that is already a mesh edge.
///
/// With `allow_folds`, a triangle facing away from its corners' normals is allowed but scores
/// below every triangle that does not: at a part thinner than the sampling, where the corners'
/// normals point to both sides, closing the hole matters more than the shape of its triangles.
fn triangulate_polygon(
    b: &Assembly,
    normals: &[DVec3],
    lp: &[u32],
    allow_folds: bool,
) -> Option<Vec<[u32; 3]>> {
    if lp.len() == 3 {
        let t = [lp[0], lp[1], lp[2]];
        return if b.fits(t) { Some(vec![t]) } else { None };
    }
    max_min_triangulation(
        lp,
        |x, y| !b.has_edge(x, y),
        |t| {
            let q = oriented_quality(b, normals, t);
            if q <= 0.0 && allow_folds {
                FOLD_WEIGHT * crate::geometry::triangle::triangle_q(b.corners(t))
            } else {
                q
            }
        },
    )
}

/// Finds vertices whose faces form more than one edge-connected fan and removes the faces of
/// all fans but the largest, so that hole filling can rebuild them as one. Returns how many faces
/// were removed.
pub(crate) fn repair_pinched_vertices(b: &mut Assembly) -> usize {
    let mut around: FxHashMap<u32, Vec<u32>> = FxHashMap::default();
    let (faces, slots) = b.live_faces();
    for (t, f) in faces.into_iter().zip(slots) {
        for v in t {
            around.entry(v).or_default().push(f);
        }
    }
    let mut vertices: Vec<u32> = around.keys().copied().collect();
    vertices.sort_unstable();
    let mut removed = 0;
    for v in vertices {
        let faces = &around[&v];
        // Fans: faces around v joined through the edges at v.
        let mut fan_of: FxHashMap<u32, usize> = FxHashMap::default();
        let mut fans: Vec<Vec<u32>> = Vec::new();
        for &f in faces {
            if fan_of.contains_key(&f) || b.face(f).is_none() {
                continue;
            }
            let id = fans.len();
            let mut fan = vec![f];
            fan_of.insert(f, id);
            let mut k = 0;
            while k < fan.len() {
                let Some(t) = b.face(fan[k]) else {
                    k += 1;
                    continue;
                };
                for &w in t.iter().filter(|&&w| w != v) {
                    for e in [(v, w), (w, v)] {
                        if let Some(g) = b.face_on(e.0, e.1) {
                            if let std::collections::hash_map::Entry::Vacant(e) = fan_of.entry(g) {
                                e.insert(id);
                                fan.push(g);
                            }
                        }
                    }
                }
                k += 1;
            }
            fans.push(fan);
        }
        if fans.len() > 1 {
            let keep = (0..fans.len())
                .max_by_key(|&i| (fans[i].len(), usize::MAX - i))
                .unwrap();
            for (i, fan) in fans.iter().enumerate() {
                if i != keep {
                    for &f in fan {
                        // Fans at one vertex are disjoint and hold live faces only.
                        if b.remove_face(f).is_ok() {
                            removed += 1;
                        }
                    }
                }
            }
        }
    }
    removed
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::topology;
    use crate::mesh::test_meshes::fibonacci_sphere;
    use crate::mesh::TriMesh;
    use crate::triangulate::tangent_delaunay::{vote_triangles, SampleSet, TangentDelaunayParams};

    fn votes(positions: &[DVec3], normals: &[DVec3], boundary: &[[u32; 2]]) -> Vec<VotedTriangle> {
        let set = SampleSet {
            positions,
            normals,
            boundary_edges: boundary,
        };
        vote_triangles(&set, &TangentDelaunayParams::default())
    }

    /// The assembled faces pass every invariant of the edit mesh.
    fn assert_sane(positions: &[DVec3], faces: &[[u32; 3]]) {
        let mesh = TriMesh::new(positions.to_vec(), faces.to_vec());
        let m: EditMesh = EditMesh::from_trimesh(&mesh, |_| (), SlotPolicy::Reuse);
        assert_eq!(m.sanity_check(), Ok(()));
    }

    #[test]
    fn samples_of_a_sphere_assemble_into_a_closed_manifold() {
        let n = 400;
        let positions = fibonacci_sphere(n);
        let normals = positions.clone();
        let voted = votes(&positions, &normals, &[]);
        let (faces, sources, stats) = assemble(
            &positions,
            &normals,
            &voted,
            &[],
            &AssemblyParams::default(),
        );
        assert_sane(&positions, &faces);
        assert_eq!(faces.len(), 2 * n - 4);
        assert_eq!(sources.len(), faces.len());
        let mesh = TriMesh::new(positions, faces);
        let t = topology(&mesh);
        assert!(t.is_closed_manifold(), "{t:?}");
        assert_eq!(
            (t.vertices, t.euler_characteristic, t.components),
            (n, 2, 1)
        );
        // Outward, like the normals.
        assert!(mesh.signed_volume() > 0.0);
        assert_eq!(stats.candidates, voted.len());
        assert!(stats.accepted_three_votes > n, "{stats:?}");
    }

    #[test]
    fn a_strips_outline_is_closed_from_behind_only_when_outlines_are_filled() {
        // Two rows of samples, one sheet facing +z: the umbrellas cover it from the front;
        // its outline can only be closed by faces facing -z (a second side on the first).
        let mut positions = Vec::new();
        for i in 0..6 {
            positions.push(DVec3::new(i as f64, 0.0, 0.0));
            positions.push(DVec3::new(i as f64 + 0.3, 1.0, 0.0));
        }
        let normals = vec![DVec3::Z; positions.len()];
        let voted = votes(&positions, &normals, &[]);
        let run = |fill_outlines| {
            let params = AssemblyParams {
                fill_outlines,
                ..AssemblyParams::default()
            };
            let (faces, _, stats) = assemble(&positions, &normals, &voted, &[], &params);
            assert_sane(&positions, &faces);
            (topology(&TriMesh::new(positions.clone(), faces)), stats)
        };
        let (closed, stats) = run(true);
        assert_eq!(closed.boundary_edges, 0, "the test case closes: {stats:?}");
        let (open, stats) = run(false);
        assert_eq!(stats.outlines_left, 1);
        assert_eq!((open.faces, open.boundary_loops), (10, 1), "{stats:?}");
    }

    #[test]
    fn a_hole_left_by_the_umbrellas_is_filled_with_the_sample_inside_it() {
        let n = 400;
        let positions = fibonacci_sphere(n);
        let normals = positions.clone();
        // No candidate uses sample 200: its umbrella and its neighbours' triangles at it are
        // gone, leaving a hole with 200 loose inside.
        let voted: Vec<VotedTriangle> = votes(&positions, &normals, &[])
            .into_iter()
            .filter(|t| !t.corners.contains(&200))
            .collect();
        let (faces, _, stats) = assemble(
            &positions,
            &normals,
            &voted,
            &[],
            &AssemblyParams::default(),
        );
        assert_sane(&positions, &faces);
        assert!(
            stats.holes_filled >= 1 && stats.hole_triangles >= 3,
            "{stats:?}"
        );
        assert_eq!(stats.holes_left, 0);
        assert!(faces.iter().any(|t| t.contains(&200)));
        assert_eq!(faces.len(), 2 * n - 4);
        let t = topology(&TriMesh::new(positions, faces));
        assert!(
            t.is_closed_manifold() && t.euler_characteristic == 2,
            "{t:?}"
        );
    }

    /// A hole whose only fill is a triangle of zero area (three samples on a line, as inserted
    /// samples along a thin tip can be) is grown and closed with the faces around it.
    #[test]
    fn a_hole_whose_fill_has_zero_area_is_grown_and_closed() {
        let n = 400;
        let mut positions = fibonacci_sphere(n);
        let normals = positions.clone();
        let voted = votes(&positions, &normals, &[]);
        // One of the triangles, its third corner moved onto the middle of the other two: the
        // triangle has zero area, and so has the only fill of the hole it leaves.
        let [a, b, c] = voted[0].corners;
        positions[c as usize] = 0.5 * (positions[a as usize] + positions[b as usize]);
        let (faces, _, stats) = assemble(
            &positions,
            &normals,
            &voted,
            &[],
            &AssemblyParams::default(),
        );
        assert_sane(&positions, &faces);
        assert_eq!(stats.holes_left, 0, "{stats:?}");
        let t = topology(&TriMesh::new(positions, faces));
        assert!(
            t.is_closed_manifold() && t.euler_characteristic == 2,
            "{t:?}"
        );
    }

    /// A jittered `n × n` grid of unit squares in the plane z = 0 and its border as boundary
    /// edges, counter-clockwise (the surface on their left).
    fn jittered_grid(n: usize) -> (Vec<DVec3>, Vec<[u32; 2]>) {
        let mut state = 12345u64;
        let mut jitter = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.4
        };
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let on_x = i == 0 || i == n;
                let on_y = j == 0 || j == n;
                let dx = if on_x { 0.0 } else { jitter() };
                let dy = if on_y { 0.0 } else { jitter() };
                positions.push(DVec3::new(i as f64 + dx, j as f64 + dy, 0.0));
            }
        }
        let at = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mut ring = Vec::new();
        ring.extend((0..n).map(|i| at(i, 0)));
        ring.extend((0..n).map(|j| at(n, j)));
        ring.extend((0..n).map(|i| at(n - i, n)));
        ring.extend((0..n).map(|j| at(0, n - j)));
        let boundary = (0..ring.len())
            .map(|k| [ring[k], ring[(k + 1) % ring.len()]])
            .collect();
        (positions, boundary)
    }

    #[test]
    fn an_open_grid_assembles_into_a_disk_with_its_boundary_kept() {
        let n = 10;
        let (positions, boundary) = jittered_grid(n);
        let normals = vec![DVec3::Z; positions.len()];
        let voted = votes(&positions, &normals, &boundary);
        let (faces, _, _) = assemble(
            &positions,
            &normals,
            &voted,
            &boundary,
            &AssemblyParams::default(),
        );
        assert_sane(&positions, &faces);
        // A disk on (n + 1)² vertices with 4n boundary vertices: F = 2V − B − 2.
        let v = (n + 1) * (n + 1);
        assert_eq!(faces.len(), 2 * v - 4 * n - 2);
        let t = topology(&TriMesh::new(positions, faces.clone()));
        assert_eq!(
            (t.euler_characteristic, t.boundary_loops, t.boundary_edges),
            (1, 1, 4 * n)
        );
        for [a, b] in boundary {
            assert!(
                faces
                    .iter()
                    .any(|t| (0..3).any(|k| t[k] == a && t[(k + 1) % 3] == b)),
                "boundary edge {a} → {b} not used in its direction"
            );
        }
    }

    #[test]
    fn a_closed_walk_splits_into_simple_loops() {
        assert_eq!(
            simple_loops(&[1, 2, 3, 4, 2, 5]),
            vec![vec![2, 3, 4], vec![1, 2, 5]]
        );
        assert_eq!(simple_loops(&[7, 8, 9]), vec![vec![7, 8, 9]]);
    }

    #[test]
    fn the_smaller_fan_at_a_pinched_vertex_is_removed() {
        let positions = vec![
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(-1.0, 0.0, 0.0),
            DVec3::new(-1.0, -1.0, 0.0),
        ];
        let mut b: Assembly = EditMesh::new(positions, SlotPolicy::Append);
        for t in [[0, 1, 2], [0, 2, 3], [0, 4, 5]] {
            assert!(b.add_face(t, FaceSource::ThreeVotes).is_ok());
        }
        assert!(matches!(
            b.sanity_check(),
            Err(crate::mesh::edit::EditViolation::NonManifoldVertex { vertex: 0, fans: 2 })
        ));
        assert_eq!(repair_pinched_vertices(&mut b), 1);
        assert_eq!(b.live_faces().0, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(b.sanity_check(), Ok(()));
    }

    #[test]
    fn a_hole_polygon_is_triangulated_for_the_best_smallest_quality() {
        // A convex pentagon: the max-min triangulation has three triangles of the polygon's
        // corners, each facing like the normals.
        let a = std::f64::consts::TAU / 5.0;
        let positions: Vec<DVec3> = (0..5)
            .map(|k| DVec3::new((a * k as f64).cos(), (a * k as f64).sin(), 0.0))
            .collect();
        let normals = vec![DVec3::Z; 5];
        let b: Assembly = EditMesh::new(positions, SlotPolicy::Append);
        let lp = [0, 1, 2, 3, 4];
        let tris = triangulate_polygon(&b, &normals, &lp, false).expect("a triangulation");
        assert_eq!(tris.len(), 3);
        assert!(tris
            .iter()
            .all(|&t| oriented_quality(&b, &normals, t) > 0.0));
        // Facing away from every normal, there is none without folds.
        let down = vec![-DVec3::Z; 5];
        assert_eq!(triangulate_polygon(&b, &down, &lp, false), None);
        assert!(triangulate_polygon(&b, &down, &lp, true).is_some());
    }
}
