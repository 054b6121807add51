//! Local optimization of the triangulated samples against the input surface: the few places the
//! spectral sampling cannot resolve (tips and rims thinner than the sample spacing) are mended
//! with the input surface at hand.
//!
//! The operations and their guards are described on [`optimize`].

use crate::geometry::crossing_curve::CrossingCurve;
use crate::geometry::tolerance::IMPROVEMENT_TOLERANCE;
use glam::DVec3;
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::Triangle;

use crate::geometry::triangle::{triangle_min_angle_deg, triangle_q, AngleBounds};
use crate::mesh::crossing_guard::CrossingGuard;
use crate::mesh::edit::{starting_at, EditMesh, SlotPolicy};
use crate::mesh::TriMesh;
use crate::surface::feature_lines::FeatureLines;
use crate::surface::mesh_projection::MeshSurface;
use crate::surface::SurfaceQuery;

mod angles;
mod collapse;
mod cover;
mod relax;
mod smooth;

use angles::mend_faces;
pub use angles::{FacesLeft, MendStats};
use collapse::collapse_short;
use cover::cover;
use relax::{flip_poor, relax_poor};
use smooth::smooth;
pub use smooth::SmoothStats;

/// The iterations of the tangential relaxation with valence flips by default (the measured
/// choice: `docs/decisions/finishing-relaxation.md`).
pub const SMOOTH_ITERATIONS: usize = 10;

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
    /// The last pass mends the faces whose smallest angle is still below this, degrees
    /// (default 35), and the faces that cross another.
    pub final_theta_deg: f64,
    /// The last pass also mends the faces whose largest angle is above this, degrees
    /// (default 100): it works on the angle score min(θmin, `final_theta_deg` +
    /// `final_theta_max_deg` − θmax), which is below `final_theta_deg` exactly when an angle is
    /// out of bounds.
    pub final_theta_max_deg: f64,
    /// Rounds of the last pass at most (default 8).
    pub final_rounds: usize,
    /// Iterations of the tangential relaxation with valence flips before covering (`smooth.rs`;
    /// default [`SMOOTH_ITERATIONS`], 0 turns it off).
    pub smooth_iterations: usize,
    /// Faces nearer than this count as crossing for the operations' crossing guard and the last
    /// pass's crossing faces (bbox-100 units, not σ_p): faces that would share a point once the
    /// mesh is written, whose coordinates are rounded (the finishing stage sets it, as
    /// [`UntangleParams::near`](crate::finish::untangle::UntangleParams::near), to
    /// [`Normalization::written_rounding`](crate::internal::Normalization::written_rounding)).
    /// Default 0: the exact test alone.
    pub near: f64,
}

impl OptimizeParams {
    /// The angle bounds the last pass works towards ([`OptimizeParams::final_theta_deg`],
    /// [`OptimizeParams::final_theta_max_deg`]).
    pub fn angle_bounds(&self) -> AngleBounds {
        AngleBounds {
            min_deg: self.final_theta_deg,
            max_deg: self.final_theta_max_deg,
        }
    }
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
            final_theta_deg: 35.0,
            final_theta_max_deg: 100.0,
            final_rounds: 8,
            smooth_iterations: SMOOTH_ITERATIONS,
            near: 0.0,
        }
    }
}

/// [`OptimizeParams`] with its lengths resolved to bbox-100 units for one sigma_p: what the
/// operations read.
#[derive(Debug, Clone, Copy)]
pub(super) struct Limits {
    /// [`OptimizeParams::q_below`].
    pub(super) q_below: f64,
    /// [`OptimizeParams::theta_below_deg`], degrees.
    pub(super) theta_below_deg: f64,
    /// [`OptimizeParams::sweeps`].
    pub(super) sweeps: usize,
    /// [`OptimizeParams::max_normal_turn_deg`], degrees.
    pub(super) max_normal_turn_deg: f64,
    /// [`OptimizeParams::max_offset_sigma_p`] · sigma_p, bbox-100 units.
    pub(super) max_offset: f64,
    /// [`OptimizeParams::cover_distance_sigma_p`] · sigma_p, bbox-100 units.
    pub(super) cover_distance: f64,
    /// [`OptimizeParams::cover_rounds`].
    pub(super) cover_rounds: usize,
    /// [`OptimizeParams::short_edge_ratio`].
    pub(super) short_edge_ratio: f64,
    /// [`OptimizeParams::collapse_offset_sigma_p`] · sigma_p, bbox-100 units.
    pub(super) collapse_offset: f64,
    /// [`OptimizeParams::final_theta_deg`], degrees.
    pub(super) final_theta_deg: f64,
    /// [`OptimizeParams::final_theta_max_deg`], degrees.
    pub(super) final_theta_max_deg: f64,
    /// [`OptimizeParams::final_rounds`].
    pub(super) final_rounds: usize,
    /// [`OptimizeParams::smooth_iterations`].
    pub(super) smooth_iterations: usize,
    /// [`OptimizeParams::near`], bbox-100 units.
    pub(super) near: f64,
}

impl Limits {
    /// The last pass's angle bounds ([`OptimizeParams::angle_bounds`]).
    pub(super) fn angle_bounds(&self) -> AngleBounds {
        AngleBounds {
            min_deg: self.final_theta_deg,
            max_deg: self.final_theta_max_deg,
        }
    }

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
            final_theta_deg: params.final_theta_deg,
            final_theta_max_deg: params.final_theta_max_deg,
            final_rounds: params.final_rounds,
            smooth_iterations: params.smooth_iterations,
            near: params.near.max(0.0),
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
    /// Operations of the last pass on the faces with a small angle or a crossing (flips,
    /// collapses, moves, splits).
    pub mends: usize,
    /// The last pass's work: faces tried, its budget, and whether it ran out.
    pub mend: MendStats,
    /// What the tangential relaxation with valence flips did.
    pub smooth: SmoothStats,
}

/// The mesh being optimized: each face labelled with the index of the input face it still is
/// (`None` once an operation made or changed it).
pub(super) type Mesh = EditMesh<Option<u32>>;

pub(super) fn normal(m: &Mesh, t: [u32; 3]) -> DVec3 {
    let [a, b, c] = m.corners(t);
    (b - a).cross(c - a).normalize_or_zero()
}

pub(super) fn min_angle(m: &Mesh, t: [u32; 3]) -> f64 {
    triangle_min_angle_deg(m.corners(t))
}

pub(super) fn q(m: &Mesh, t: [u32; 3]) -> f64 {
    triangle_q(m.corners(t))
}

/// The last pass's angle score of `t` (see [`OptimizeParams::final_theta_max_deg`]), degrees.
pub(super) fn angle_score(m: &Mesh, t: [u32; 3], params: &Limits) -> f64 {
    params.angle_bounds().score(m.corners(t))
}

/// The shape score the operations maximize at their worst face: Q and the smallest angle, each
/// relative to a good level (Q 0.6, 30°), whichever is lower.
pub(super) fn score(m: &Mesh, t: [u32; 3]) -> f64 {
    (q(m, t) / 0.6).min(min_angle(m, t) / 30.0)
}

/// Whether `t` is one of the triangles the operations work on.
pub(super) fn is_poor(m: &Mesh, t: [u32; 3], params: &Limits) -> bool {
    q(m, t) < params.q_below || min_angle(m, t) < params.theta_below_deg
}

/// The face in slot `f`, which must be live.
pub(super) fn face(m: &Mesh, f: u32) -> [u32; 3] {
    m.face(f)
        .unwrap_or_else(|| unreachable!("face {f} is live"))
}

/// Whether collapsing edge a–b (its opposite vertices `c` and `d`) keeps the mesh's links: a and
/// b share exactly the two neighbours c and d (the link condition), and c and d keep at least
/// three faces each.
pub(super) fn collapse_keeps_links(m: &Mesh, a: u32, b: u32, c: u32, d: u32) -> bool {
    let (ra, rb) = (m.ring(a), m.ring(b));
    let common: Vec<u32> = ra.iter().copied().filter(|u| rb.contains(u)).collect();
    c != d
        && common.len() == 2
        && common.contains(&c)
        && common.contains(&d)
        && m.degree(c) > 3
        && m.degree(d) > 3
}

/// The faces that an edit of edge a–b changes besides its own two faces `f1` and `f2`: every
/// face around a or b, once each, in index order.
pub(super) fn faces_around_edge(m: &Mesh, a: u32, b: u32, f1: u32, f2: u32) -> Vec<u32> {
    let mut involved: Vec<u32> = m
        .faces_around(a)
        .iter()
        .chain(m.faces_around(b))
        .copied()
        .filter(|&g| g != f1 && g != f2)
        .collect();
    involved.sort_unstable();
    involved.dedup();
    involved
}

/// The apex of the equilateral triangle on edge pb–pc on the side of `old` (in the plane of
/// the three): where a vertex at `old` would make the face opposite it equilateral; `None` when
/// `old` lies on the edge's line.
pub(super) fn equilateral_apex(old: DVec3, pb: DVec3, pc: DVec3) -> Option<DVec3> {
    let mid = 0.5 * (pb + pc);
    let e = pc - pb;
    let height = old - mid;
    let across = (height - e * (height.dot(e) / e.length_squared().max(f64::MIN_POSITIVE)))
        .normalize_or_zero();
    (across != DVec3::ZERO).then(|| mid + across * (0.75f64.sqrt() * e.length()))
}

pub(super) fn distance_to_faces(m: &Mesh, faces: &[u32], p: DVec3) -> f64 {
    distance_to(m, faces.iter().map(|&f| face(m, f)), p)
}

/// The distance from `p` to the nearest of the triangles `faces` (vertex indices).
pub(super) fn distance_to(m: &Mesh, faces: impl IntoIterator<Item = [u32; 3]>, p: DVec3) -> f64 {
    faces
        .into_iter()
        .map(|t| {
            let [a, b, c] = m.corners(t);
            Triangle::new(a, b, c).distance_to_local_point(p, true)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Whether some face `faces[i]` has turned from its old normal `old_normals[i]` by more than the
/// angle whose cosine is `cos_turn`.
pub(super) fn turned(m: &Mesh, faces: &[[u32; 3]], old_normals: &[DVec3], cos_turn: f64) -> bool {
    faces
        .iter()
        .zip(old_normals)
        .any(|(&t, &n0)| normal(m, t).dot(n0) < cos_turn)
}

/// Optimizes `mesh` (bbox-100 units, edge-manifold and consistently oriented) against `surface`
/// (the input, same units): covers the input points of `cover_points` that are farther than
/// `params.cover_distance_sigma_p` · `sigma_p` from it, then flips edges and relaxes vertices
/// around the triangles with Q below `params.q_below`. Vertices with `fixed[v]` (boundary
/// samples) do not move, except that the last pass slides boundary vertices along `boundary`
/// (the input's boundary curves, same units; with `None` they stay); a face that crosses another
/// inside `input_crossings` (where the input's own faces cross) is not mended as crossing;
/// boundary edges are not
/// flipped, and the `protected` edges (the creases kept as edges) are neither flipped nor
/// collapsed. New vertices are appended, so
/// existing indices stay valid; vertices merged away by a collapse are left unreferenced.
/// Returns what was done, and the faces' origins (the index of the face of `mesh` each face of
/// the result still is) and intersecting pairs (`Edited`). Deterministic.
///
/// # Operations
///
/// Four local operations, each kept only when it keeps the mesh near the input surface (see the
/// offsets in [`OptimizeParams`]); collapse, flip and relax also only when their new faces cross
/// no face, except where they meet `input_crossings` (`SweepGuard`;
/// `docs/decisions/sweeps-crossing-guard.md`):
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
/// Then a last pass (`angles.rs`) takes the faces whose smallest angle is still below
/// `final_theta_deg` and the faces that cross another (the sweeps' guards refuse what would leave
/// the surface, so a sliver on a tip or beside a short fixed edge, or a fold at a crease, can
/// stay): each gets the best of a flip, a collapse or a move of its own, accepted only when it
/// raises the smallest angle there (a crossing face: removes the crossing without a new angle
/// below the bound), keeps the mesh within `collapse_offset_sigma_p` · sigma_p of the surface
/// and makes no crossing (exact test against the faces near it).
///
/// Everything else stays as the sampler and the triangulation left it (how much moves on a scan:
/// `docs/decisions/optimize-cover.md`).
#[allow(clippy::too_many_arguments)] // the mesh, the input and its creases and boundary, the limits
pub fn optimize<S: SurfaceQuery + ?Sized>(
    mesh: &mut TriMesh,
    surface: &S,
    cover_points: &[DVec3],
    fixed: &[bool],
    protected: &[[u32; 2]],
    boundary: Option<&FeatureLines>,
    input_crossings: Option<&CrossingCurve>,
    sigma_p: f64,
    params: &OptimizeParams,
) -> (OptimizeStats, Edited) {
    let params = &Limits::new(params, sigma_p);
    let mut stats = OptimizeStats::default();
    let (mut m, mut fixed) = editable(mesh, fixed, protected);
    let short = params.short_edge_ratio * median_edge_length(&m);
    let mut watch = None;
    stats.smooth = smooth(&mut m, surface, &fixed, params, params.smooth_iterations);
    // The sweeps' poor faces, kept up to date as covering and the sweeps change the mesh.
    let mut poor = PoorFaces::new(&mut m, params);
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
        // The sweeps make no crossing: each operation is checked against every face.
        let mut guard = SweepGuard {
            faces: CrossingGuard::new(&m),
            input_crossings,
        };
        for _ in 0..params.sweeps {
            poor.refresh(&mut m, params);
            let c = collapse_short(&mut m, surface, &fixed, short, params, &poor, &mut guard);
            poor.refresh(&mut m, params);
            let vertices = poor.vertices(&m);
            let f = flip_poor(&mut m, surface, params, &vertices, &mut guard);
            poor.refresh(&mut m, params);
            let vertices = poor.vertices(&m);
            let r = relax_poor(&mut m, surface, &fixed, params, &vertices, &mut guard);
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
    m.stop_tracking();
    let pairs;
    (stats.mend, pairs) = mend_faces(
        &mut m,
        surface,
        boundary,
        input_crossings,
        &fixed,
        params,
        None,
        None,
    );
    stats.mends = stats.mend.ops;
    (stats, written(m, mesh, &pairs))
}

/// The crossing guard of the sweeps (collapses, flips and moves of poor faces): an operation
/// is refused when its new faces cross a face, except where they meet the regions where the
/// input's own faces cross (there the output crosses as its input does, and the sweeps may
/// still better its angles, as the last pass may).
pub(super) struct SweepGuard<'a> {
    pub faces: CrossingGuard,
    pub input_crossings: Option<&'a CrossingCurve>,
}

impl SweepGuard<'_> {
    /// Whether the faces `new` (as `m` places their corners now) would make a crossing, the
    /// faces in `replaced` left out.
    pub(super) fn refuses(&self, m: &Mesh, new: &[[u32; 3]], replaced: &[u32]) -> bool {
        let at_input_crossing = self
            .input_crossings
            .is_some_and(|r| new.iter().any(|&t| r.near(m.corners(t))));
        !at_input_crossing && self.faces.crosses(m, new, replaced)
    }

    /// The faces in `slots` were made or moved.
    pub(super) fn changed(&mut self, m: &Mesh, slots: &[u32]) {
        self.faces.changed(m, slots);
    }
}

/// `mesh` as the mesh the operations edit (each face labelled with its index), its `protected`
/// edges protected, and `fixed` extended to every vertex.
fn editable(mesh: &TriMesh, fixed: &[bool], protected: &[[u32; 2]]) -> (Mesh, Vec<bool>) {
    let mut m: Mesh = EditMesh::from_trimesh(mesh, Some, SlotPolicy::Reuse);
    for &[a, b] in protected {
        m.protect_edge(a, b);
    }
    let mut fixed = fixed.to_vec();
    fixed.resize(m.vertex_count(), false);
    (m, fixed)
}

/// Writes the edited `m` back into `mesh`, with `pairs` (slots of `m`) as the indices of the
/// faces written.
fn written(m: Mesh, mesh: &mut TriMesh, pairs: &[[u32; 2]]) -> Edited {
    // Slots to the indices of the faces written (the live ones in slot order).
    let (_, slots) = m.live_faces();
    let index = |f: u32| slots.binary_search(&f).map_or(u32::MAX, |i| i as u32);
    let intersecting = pairs.iter().map(|p| p.map(index)).collect();
    let (positions, faces, origin) = m.into_parts();
    *mesh = TriMesh::new(positions, faces);
    Edited {
        origin,
        intersecting,
    }
}

/// What [`optimize`] and [`mend_near`] leave besides their stats.
pub struct Edited {
    /// For each face of the result, the index of the face of the mesh before it still is
    /// (`None` for a new or changed face).
    pub origin: Vec<Option<u32>>,
    /// The pairs of faces of the result that intersect (indices, the smaller first, sorted):
    /// those [`intersecting_pairs`](crate::geometry::intersecting_pairs) finds.
    pub intersecting: Vec<[u32; 2]>,
}

/// The last pass of [`optimize`] alone, on the faces of small angle with a corner marked in
/// `near` (`V` flags; the faces a later stage changed, such as untangle's collapses, and their
/// neighbours) and on every face that crosses another, with the same guards (same arguments
/// and units as [`optimize`]). Returns what it did, and the faces' origins and intersecting
/// pairs ([`Edited`]). `known`: the pairs of faces of `mesh` within `params.near` of each
/// other (indices into its triangles), when the caller has them (else searched for over the
/// whole mesh). Deterministic.
#[allow(clippy::too_many_arguments)] // optimize's arguments, and where to work
pub fn mend_near<S: SurfaceQuery + ?Sized>(
    mesh: &mut TriMesh,
    surface: &S,
    fixed: &[bool],
    protected: &[[u32; 2]],
    boundary: Option<&FeatureLines>,
    input_crossings: Option<&CrossingCurve>,
    sigma_p: f64,
    params: &OptimizeParams,
    near: &[bool],
    known: Option<Vec<[u32; 2]>>,
) -> (MendStats, Edited) {
    let params = &Limits::new(params, sigma_p);
    let (mut m, fixed) = editable(mesh, fixed, protected);
    // A fresh edit mesh's slots are the faces' indices.
    let known = known.filter(|_| {
        m.live_faces()
            .1
            .iter()
            .enumerate()
            .all(|(k, &f)| f as usize == k)
    });
    let (stats, pairs) = mend_faces(
        &mut m,
        surface,
        boundary,
        input_crossings,
        &fixed,
        params,
        Some(near),
        known,
    );
    (stats, written(m, mesh, &pairs))
}

/// The faces the sweeps work on ([`is_poor`]), kept up to date from the changes the mesh
/// records ([`EditMesh::track_changes`]) instead of being found again over every face: after
/// an operation, only the faces it made, replaced or removed and the faces around the vertices
/// it moved are looked at again. The set is that of a scan of every live face.
pub(super) struct PoorFaces {
    /// The poor faces' slots.
    poor: std::collections::BTreeSet<u32>,
}

impl PoorFaces {
    /// The poor faces of `m`, which from now on records its changes.
    pub(super) fn new(m: &mut Mesh, params: &Limits) -> Self {
        m.track_changes();
        let (live, slots) = m.live_faces();
        let poor = live
            .into_iter()
            .zip(slots)
            .filter(|&(t, _)| is_poor(m, t, params))
            .map(|(_, f)| f)
            .collect();
        PoorFaces { poor }
    }

    /// Brings the set up to date with the changes `m` recorded since the last call.
    pub(super) fn refresh(&mut self, m: &mut Mesh, params: &Limits) {
        let changes = m.take_changes();
        let mut look = changes.faces;
        for v in changes.vertices {
            look.extend_from_slice(m.faces_around(v));
        }
        look.sort_unstable();
        look.dedup();
        for f in look {
            match m.face(f) {
                Some(t) if is_poor(m, t, params) => self.poor.insert(f),
                _ => self.poor.remove(&f),
            };
        }
    }

    /// The poor faces' slots, in order.
    pub(super) fn slots(&self) -> impl Iterator<Item = u32> + '_ {
        self.poor.iter().copied()
    }

    /// The vertices of the poor faces, sorted.
    pub(super) fn vertices(&self, m: &Mesh) -> Vec<u32> {
        let mut v: Vec<u32> = self.poor.iter().flat_map(|&f| face(m, f)).collect();
        v.sort_unstable();
        v.dedup();
        v
    }
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

    /// [`optimize`] with no cover points, creases or boundary lines, sigma_p 1 and no cover.
    fn optimize_plain(
        mesh: &mut TriMesh,
        surface: &MeshSurface,
        fixed: &[bool],
    ) -> (OptimizeStats, Vec<Option<u32>>) {
        let (stats, edited) =
            optimize(mesh, surface, &[], fixed, &[], None, None, 1.0, &no_cover());
        (stats, edited.origin)
    }

    fn no_cover() -> OptimizeParams {
        OptimizeParams {
            cover_distance_sigma_p: f64::INFINITY,
            ..Default::default()
        }
    }

    /// The poor faces of a scan of every live face of `m`.
    fn scanned_poor(m: &Mesh, params: &Limits) -> Vec<u32> {
        let (live, slots) = m.live_faces();
        live.into_iter()
            .zip(slots)
            .filter(|&(t, _)| is_poor(m, t, params))
            .map(|(_, f)| f)
            .collect()
    }

    #[test]
    fn the_poor_faces_kept_up_to_date_are_those_a_scan_finds() {
        let params = Limits::new(&OptimizeParams::default(), 1.0);
        let mut m: Mesh = EditMesh::from_trimesh(&grid(8, 1.0), Some, SlotPolicy::Reuse);
        let mut poor = PoorFaces::new(&mut m, &params);
        assert!(
            poor.slots().next().is_none(),
            "a grid of right triangles is not poor"
        );
        let check = |m: &mut Mesh, poor: &mut PoorFaces, what: &str| {
            poor.refresh(m, &params);
            let kept: Vec<u32> = poor.slots().collect();
            assert_eq!(kept, scanned_poor(m, &params), "after {what}");
            kept.len()
        };
        // A move makes faces poor, a move back mends them.
        let v = 3 * 9 + 3;
        let p = m.position(v);
        m.relocate_vertex(v, p + DVec3::new(0.7, 0.2, 0.0)).unwrap();
        assert!(check(&mut m, &mut poor, "a move") > 0);
        m.relocate_vertex(v, p).unwrap();
        assert_eq!(check(&mut m, &mut poor, "a move back"), 0);
        // A flip, a split, a collapse (which removes faces, whose slots a split then reuses).
        m.flip_edge(4 * 9 + 4, 5 * 9 + 5, None).unwrap();
        check(&mut m, &mut poor, "a flip");
        let w = m.add_vertex(m.position(6 * 9 + 1).lerp(m.position(6 * 9 + 2), 0.1));
        m.split_edge(6 * 9 + 1, 6 * 9 + 2, w, None).unwrap();
        assert!(check(&mut m, &mut poor, "a split") > 0);
        m.collapse_edge(w, 6 * 9 + 1, m.position(6 * 9 + 1), None)
            .unwrap();
        check(&mut m, &mut poor, "a collapse");
        let u = m.add_vertex(m.position(2 * 9 + 6).lerp(m.position(2 * 9 + 7), 0.05));
        m.split_edge(2 * 9 + 6, 2 * 9 + 7, u, None).unwrap();
        assert!(check(&mut m, &mut poor, "a split into free slots") > 0);
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
        let (stats, _) = optimize_plain(&mut mesh, &surface, &fixed);
        let after = triangle_quality(&mesh);
        assert!(stats.moves + stats.flips + stats.collapses + stats.smooth.moves > 0);
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
        let (_, origin) = optimize_plain(&mut mesh, &surface, &fixed);
        assert_eq!(origin.len(), mesh.face_count());
        assert!(origin.iter().any(|o| o.is_none()) && origin.iter().any(|o| o.is_some()));
        assert_eq!(mesh.positions[3], original[3]);
        assert_eq!(mesh.positions[3 * 7 + 3], original[3 * 7 + 3]);
        assert_eq!(topology(&mesh).boundary_edges, 24);
        assert_sane(&mesh);
    }

    /// A 4 × 4 grid of unit squares whose middle square's diagonal (0,0)–(1,1), shifted to
    /// the grid's middle, is the long one: its other corners are pulled in and lifted by 0.04,
    /// so the max-min rule flips it, and the flipped faces rise to 0.04 over the square's
    /// centre. A small upright triangle stands there, from 0.005 to 0.06 high: clear of the
    /// faces before the flip, through them after.
    fn fold_under_a_fin() -> (TriMesh, [u32; 2]) {
        let mut mesh = grid(4, 1.0);
        let at = |i: usize, j: usize| j * 5 + i;
        let (p10, p01) = (at(2, 1), at(1, 2));
        let centre = DVec3::new(1.5, 1.5, 0.0);
        for v in [p10, p01] {
            let p = mesh.positions[v];
            mesh.positions[v] = p + (centre - p) * 0.2 + DVec3::new(0.0, 0.0, 0.04);
        }
        let along = DVec3::new(1.0, 1.0, 0.0).normalize() * 0.02;
        let base = mesh.positions.len() as u32;
        mesh.positions.extend([
            centre - along + DVec3::new(0.0, 0.0, 0.005),
            centre + along + DVec3::new(0.0, 0.0, 0.005),
            centre + DVec3::new(0.0, 0.0, 0.06),
        ]);
        mesh.triangles.push([base, base + 1, base + 2]);
        (mesh, [at(1, 1) as u32, at(2, 2) as u32])
    }

    #[test]
    fn the_sweeps_flips_make_no_crossing_with_the_guard() {
        use crate::geometry::self_intersection::intersecting_pairs;
        let crossings = |m: &Mesh| intersecting_pairs(m.positions(), &m.live_faces().0).len();
        let params = Limits::new(&OptimizeParams::default(), 1.0);
        let (mesh, [a, b]) = fold_under_a_fin();
        let surface = MeshSurface::new(&mesh).unwrap();
        let edges = [(a.min(b), a.max(b))];
        // Without the guard the flip is made and crosses the fin.
        let mut m: Mesh = EditMesh::from_trimesh(&mesh, Some, SlotPolicy::Reuse);
        assert_eq!(crossings(&m), 0);
        assert_eq!(relax::flip_all(&mut m, &surface, &params, &edges, None), 1);
        assert!(crossings(&m) > 0);
        // With it, the flip is refused.
        let mut m: Mesh = EditMesh::from_trimesh(&mesh, Some, SlotPolicy::Reuse);
        let mut guard = SweepGuard {
            faces: CrossingGuard::new(&m),
            input_crossings: None,
        };
        assert_eq!(
            relax::flip_all(&mut m, &surface, &params, &edges, Some(&mut guard)),
            0
        );
        assert_eq!(crossings(&m), 0);
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
        let (stats, _) = optimize_plain(&mut mesh, &surface, &fixed);
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
            &[],
            None,
            None,
            1.0,
            &OptimizeParams::default(),
        );
        assert!(stats.covered >= 1, "{stats:?}");
        assert!(mesh.positions.contains(&apex));
        // Vertices merged away by a collapse are left unreferenced (see `optimize`).
        mesh.remove_unreferenced_vertices();
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
