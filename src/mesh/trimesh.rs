//! The indexed triangle mesh used throughout the pipeline, with the bounding-box normalization of
//! Sec. 7 of the paper (longest side scaled to 100).

use glam::DVec3;
use rustc_hash::{FxHashMap, FxHashSet};

use crate::disjoint_sets::Dsu;
use crate::error::{Error, Result};
use crate::geometry::triangle::face_key;
use crate::geometry::triangle_intersection::collinear;
use crate::mesh::edit::starting_at;

/// An indexed triangle mesh: `positions` is `V × 3` (model units, or bbox-100 units after
/// [`Normalization::apply`]), `triangles` is `F × 3` indices into `positions`, counter-clockwise
/// seen from the outside (the side the face normal points to).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Triangles as vertex indices.
    pub triangles: Vec<[u32; 3]>,
}

/// Axis-aligned bounding box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: DVec3,
    /// Upper corner.
    pub max: DVec3,
}

impl Aabb {
    /// The bounding box of `points`; `None` when `points` is empty.
    pub fn of(points: &[DVec3]) -> Option<Self> {
        let first = *points.first()?;
        let (min, max) = points
            .iter()
            .fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        Some(Aabb { min, max })
    }

    /// The length of the longest side.
    pub fn longest_side(&self) -> f64 {
        (self.max - self.min).max_element()
    }

    /// The length of the diagonal.
    pub fn diagonal(&self) -> f64 {
        (self.max - self.min).length()
    }

    /// The centre.
    pub fn center(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    /// Whether `p` lies in the box (its faces included).
    pub fn contains(&self, p: DVec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }
}

/// The most vertices one cell of [`TriMesh::weld_close_positions`]'s grid keeps as merge
/// targets: a seam repeats a corner a few times, never dozens.
pub(crate) const WELD_CELL_CAP: usize = 32;

/// How near the middle of its cell (along an axis, in cells) a vertex has
/// [`TriMesh::weld_close_positions`] look in both neighbouring cells: rounding puts a point's
/// cell coordinate off by about 1e-6 of a cell at the readers' tolerance (1e-10 of the diagonal).
const WELD_CELL_MIDDLE: f64 = 1e-3;

impl TriMesh {
    /// A mesh from positions and triangles, taken as they are (see [`TriMesh::check_indices`]).
    pub fn new(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Self {
        TriMesh {
            positions,
            triangles,
        }
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn face_count(&self) -> usize {
        self.triangles.len()
    }

    /// The three corner positions of triangle `f`.
    #[inline]
    pub fn corners(&self, f: usize) -> [DVec3; 3] {
        let [a, b, c] = self.triangles[f];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    /// Twice the area vector of triangle `f` ((b-a)×(c-a)): its direction is the face normal,
    /// its length twice the area.
    #[inline]
    pub fn face_cross(&self, f: usize) -> DVec3 {
        let [a, b, c] = self.corners(f);
        (b - a).cross(c - a)
    }

    /// Unit normal of triangle `f` (zero for a degenerate triangle).
    #[inline]
    pub fn face_normal(&self, f: usize) -> DVec3 {
        self.face_cross(f).normalize_or_zero()
    }

    /// Area of triangle `f`.
    #[inline]
    pub fn face_area(&self, f: usize) -> f64 {
        0.5 * self.face_cross(f).length()
    }

    /// Total surface area.
    pub fn area(&self) -> f64 {
        (0..self.face_count()).map(|f| self.face_area(f)).sum()
    }

    /// Signed volume enclosed (units³): Σ over faces of a·(b×c)/6. Positive when a closed mesh's
    /// faces are oriented outward (counter-clockwise seen from outside), negative when inward;
    /// for an open mesh, the volume of the cone from the origin, whose sign still tells the
    /// orientation of a mostly closed surface whose holes are small.
    pub fn signed_volume(&self) -> f64 {
        self.signed_volume_of(0..self.face_count())
    }

    /// [`signed_volume`](Self::signed_volume) of the faces `faces` only (a part of the mesh).
    pub fn signed_volume_of(&self, faces: impl IntoIterator<Item = usize>) -> f64 {
        faces
            .into_iter()
            .map(|f| {
                let [a, b, c] = self.corners(f);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// Reverses every face's orientation (and so the vertex normals).
    pub fn flip_orientation(&mut self) {
        for t in &mut self.triangles {
            t.swap(1, 2);
        }
    }

    /// Bounding box of the vertices; `None` for an empty mesh.
    pub fn bbox(&self) -> Option<Aabb> {
        Aabb::of(&self.positions)
    }

    /// Each undirected edge `(a, b)`, `a < b`, with the first two faces that use it (in face
    /// order; the second is 0 when only one does) and how many do: 1 on a boundary, 2 inside a
    /// manifold, more on a non-manifold edge.
    pub fn edge_uses(&self) -> FxHashMap<(u32, u32), ([u32; 2], u32)> {
        let mut uses: FxHashMap<(u32, u32), ([u32; 2], u32)> = FxHashMap::default();
        for (f, t) in self.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let e = uses.entry((a.min(b), a.max(b))).or_insert(([0; 2], 0));
                if e.1 < 2 {
                    e.0[e.1 as usize] = f as u32;
                }
                e.1 += 1;
            }
        }
        uses
    }

    /// Unit vertex normals, `V × 3`: the angle-weighted average of the incident face normals
    /// (Thürmer & Wüthrich 1998). A vertex in no triangle, or only in degenerate ones, gets zero.
    pub fn vertex_normals(&self) -> Vec<DVec3> {
        let mut normals = vec![DVec3::ZERO; self.positions.len()];
        for (f, tri) in self.triangles.iter().enumerate() {
            let n = self.face_normal(f);
            if n == DVec3::ZERO {
                continue;
            }
            let p = self.corners(f);
            for k in 0..3 {
                let e1 = p[(k + 1) % 3] - p[k];
                let e2 = p[(k + 2) % 3] - p[k];
                let angle = e1.angle_between(e2);
                if angle.is_finite() {
                    normals[tri[k] as usize] += angle * n;
                }
            }
        }
        for n in &mut normals {
            *n = n.normalize_or_zero();
        }
        normals
    }

    /// Unit normals per face corner, `F × 3`, with a crease angle: corner k of face f gets the
    /// angle-weighted average of the normals of the faces around its vertex whose normal is
    /// within `crease_angle_deg` of face f's own (smooth shading with a crease angle, as
    /// renderers' "auto smooth" does, comparing normals rather than walking the fan). Across
    /// an edge sharper than the angle the two sides keep their own normals; 180° or more gives
    /// the vertex normals ([`TriMesh::vertex_normals`]) at every corner, 0° the face normal
    /// wherever no neighbour is exactly parallel. A degenerate face's corners get zero.
    pub fn corner_normals(&self, crease_angle_deg: f64) -> Vec<[DVec3; 3]> {
        let face_normals: Vec<DVec3> = (0..self.triangles.len())
            .map(|f| self.face_normal(f))
            .collect();
        // Faces around each vertex, with the corner angle there.
        let mut around: Vec<Vec<(u32, f64)>> = vec![Vec::new(); self.positions.len()];
        for (f, tri) in self.triangles.iter().enumerate() {
            if face_normals[f] == DVec3::ZERO {
                continue;
            }
            let p = self.corners(f);
            for k in 0..3 {
                let angle = (p[(k + 1) % 3] - p[k]).angle_between(p[(k + 2) % 3] - p[k]);
                if angle.is_finite() {
                    around[tri[k] as usize].push((f as u32, angle));
                }
            }
        }
        let cos_crease = crease_angle_deg.to_radians().cos();
        let all = crease_angle_deg >= 180.0;
        self.triangles
            .iter()
            .enumerate()
            .map(|(f, tri)| {
                let nf = face_normals[f];
                if nf == DVec3::ZERO {
                    return [DVec3::ZERO; 3];
                }
                tri.map(|v| {
                    around[v as usize]
                        .iter()
                        .filter(|&&(g, _)| all || face_normals[g as usize].dot(nf) >= cos_crease)
                        .fold(DVec3::ZERO, |acc, &(g, angle)| {
                            acc + angle * face_normals[g as usize]
                        })
                        .normalize_or_zero()
                })
            })
            .collect()
    }

    /// The first triangle that names a vertex index `>= V`, as `(face, index)`.
    pub fn check_indices(&self) -> Option<(usize, u32)> {
        let n = self.positions.len() as u64;
        self.triangles
            .iter()
            .enumerate()
            .find_map(|(f, t)| t.iter().find(|&&i| u64::from(i) >= n).map(|&i| (f, i)))
    }

    /// The first vertex with a NaN or infinite coordinate.
    pub fn first_non_finite_vertex(&self) -> Option<usize> {
        self.positions.iter().position(|p| !p.is_finite())
    }

    /// Checks that every index is in range and every coordinate finite.
    ///
    /// # Errors
    /// [`Error::InvalidMesh`] (with an empty path, for the caller to fill in) naming the
    /// first face with an index out of range or the first vertex with a non-finite coordinate.
    pub fn check_geometry(&self) -> Result<()> {
        if let Some((f, i)) = self.check_indices() {
            return Err(Error::invalid_mesh(
                "",
                format!(
                    "face {f} refers to vertex {i}, but there are {} vertices",
                    self.vertex_count()
                ),
            ));
        }
        if let Some(v) = self.first_non_finite_vertex() {
            return Err(Error::invalid_mesh(
                "",
                format!("vertex {v} has a non-finite coordinate"),
            ));
        }
        Ok(())
    }

    /// Removes the vertices no triangle uses, renumbering the triangles. Returns how many were
    /// removed.
    pub fn remove_unreferenced_vertices(&mut self) -> usize {
        let before = self.positions.len();
        self.compact_vertices();
        before - self.positions.len()
    }

    /// [`TriMesh::remove_unreferenced_vertices`], returning each old vertex's new index
    /// (`u32::MAX` for a removed one), `V` entries.
    pub fn compact_vertices(&mut self) -> Vec<u32> {
        let mut new_index = vec![u32::MAX; self.positions.len()];
        for t in &self.triangles {
            for &i in t {
                new_index[i as usize] = 0;
            }
        }
        let mut kept = Vec::with_capacity(self.positions.len());
        for (i, slot) in new_index.iter_mut().enumerate() {
            if *slot == 0 {
                *slot = kept.len() as u32;
                kept.push(self.positions[i]);
            }
        }
        for t in &mut self.triangles {
            for i in t.iter_mut() {
                *i = new_index[*i as usize];
            }
        }
        self.positions = kept;
        new_index
    }

    /// Removes the faces a remesh cannot use, in one pass in face order: faces whose corners are
    /// collinear (exactly zero area, decided by Shewchuk's exact orientation predicate on the
    /// three coordinate-plane projections; faces of almost no area stay, for the pipeline's own
    /// checks to name), and faces with the same three vertices as an earlier face, in either
    /// winding (duplicated faces, and the second sheet of a double-sided export). The first of a
    /// set of duplicates stays. Then the faces that came in both windings go as well where they
    /// make a wall between two volumes (`walls_among`: two closed parts glued at those faces,
    /// as two tetrahedra joined into a bipyramid or the stories of a building stacked on each
    /// other's floors), inside the solid the parts make together; a double-sided sheet, whose
    /// edges are left with one or two faces, stays. Vertices stay (see
    /// [`TriMesh::remove_unreferenced_vertices`]). O(faces).
    pub fn remove_duplicate_and_zero_area_faces(&mut self) -> FaceCleanup {
        let mut seen: FxHashMap<[u32; 3], [u32; 3]> = FxHashMap::default();
        let mut out = FaceCleanup::default();
        let mut both_windings: Vec<[u32; 3]> = Vec::new();
        let positions = &self.positions;
        self.triangles.retain(|&t| {
            if collinear(t.map(|i| positions[i as usize])) {
                out.zero_area += 1;
                return false;
            }
            let key = face_key(t);
            match seen.get(&key) {
                Some(first) => {
                    out.duplicates += 1;
                    if starting_at(t, first[0]) != *first {
                        out.opposite_duplicates += 1;
                        both_windings.push(key);
                    }
                    false
                }
                None => {
                    seen.insert(key, t);
                    true
                }
            }
        });
        if both_windings.is_empty() {
            return out;
        }
        let mut faces_on_edge: FxHashMap<(u32, u32), u32> = FxHashMap::default();
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *faces_on_edge.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        let mut patch = both_windings.clone();
        patch.sort_unstable();
        patch.dedup();
        let walls = walls_among(&patch, &faces_on_edge);
        // A wall's other winding is no double-sided face.
        out.opposite_duplicates -= both_windings.iter().filter(|k| walls.contains(*k)).count();
        if !walls.is_empty() {
            self.triangles.retain(|&t| {
                let mut key = t;
                key.sort_unstable();
                !walls.contains(&key)
            });
            out.internal_walls = walls.len();
        }
        out
    }

    /// The mesh without the faces on the same three vertices as an earlier face (in any order
    /// or winding: [`face_key`], as [`TriMesh::remove_duplicate_and_zero_area_faces`] finds
    /// them), the first of each set kept, with how many were left out. The surface is the same;
    /// what measures it (its area, the distance to it) counts each face once. O(faces).
    pub fn without_duplicate_faces(&self) -> (TriMesh, usize) {
        let mut seen: FxHashSet<[u32; 3]> = FxHashSet::default();
        let triangles: Vec<[u32; 3]> = self
            .triangles
            .iter()
            .copied()
            .filter(|&t| seen.insert(face_key(t)))
            .collect();
        let left_out = self.triangles.len() - triangles.len();
        let mesh = TriMesh {
            positions: self.positions.clone(),
            triangles,
        };
        (mesh, left_out)
    }

    /// Merges vertices with bit-identical positions (as glTF files split vertices at texture
    /// seams), renumbering the triangles, and drops triangles that then repeat a vertex. Returns
    /// how many vertices were merged away.
    pub fn weld_identical_positions(&mut self) -> usize {
        let mut first: rustc_hash::FxHashMap<[u64; 3], u32> = Default::default();
        let mut remap = Vec::with_capacity(self.positions.len());
        let mut kept = Vec::with_capacity(self.positions.len());
        for p in &self.positions {
            // +0.0 and -0.0 are the same point.
            let key = [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
            let idx = *first.entry(key).or_insert_with(|| {
                kept.push(*p);
                (kept.len() - 1) as u32
            });
            remap.push(idx);
        }
        let merged = self.positions.len() - kept.len();
        self.merge_vertices(kept, &remap);
        merged
    }

    /// Replaces the positions by `kept`, renumbers the triangles by `remap` (old index → index
    /// into `kept`) and drops the triangles that then repeat a vertex: the welds' last step.
    fn merge_vertices(&mut self, kept: Vec<DVec3>, remap: &[u32]) {
        self.positions = kept;
        for t in &mut self.triangles {
            for i in t.iter_mut() {
                *i = remap[*i as usize];
            }
        }
        self.triangles
            .retain(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
    }

    /// The length of the shortest edge at each vertex (model units; infinite at a vertex no
    /// triangle uses). Shape: one per position.
    pub fn shortest_edges(&self) -> Vec<f64> {
        let mut shortest = vec![f64::INFINITY; self.positions.len()];
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                let l = self.positions[a].distance(self.positions[b]);
                shortest[a] = shortest[a].min(l);
                shortest[b] = shortest[b].min(l);
            }
        }
        shortest
    }

    /// Merges vertices whose positions lie within `tolerance` (model units) of each other and
    /// within `edge_fraction` of the shortest edge at either: first those at bit-identical
    /// positions ([`weld_identical_positions`](Self::weld_identical_positions)), then each
    /// remaining vertex, in index order, into the first vertex kept before it within reach (no
    /// chains: a vertex is compared with kept vertices only). Triangles are renumbered and those
    /// that then repeat a vertex are dropped. This is how a CAD export whose seams repeat a
    /// corner with positions a rounding apart (1e-16 of the model's size) is read as the closed
    /// solid it is, not as one with cracks along its seams; the bound by the edges keeps apart
    /// two vertices a mesh spanning many scales holds close on purpose (a stray triangle 1e12
    /// away makes any fraction of the box too coarse for a unit part). Returns how many vertices
    /// were merged away. O(n), deterministic (a vertex is compared with at most 8 · 32 kept
    /// ones, 27 · 32 near a cell's middle: in a cluster of more distinct vertices within `tolerance` than 32 to a grid cell,
    /// the later ones are not merge targets); a `tolerance` of zero (or not finite) merges
    /// identical positions only.
    pub fn weld_close_positions(&mut self, tolerance: f64, edge_fraction: f64) -> usize {
        let identical = self.weld_identical_positions();
        if !(tolerance > 0.0 && tolerance.is_finite()) || self.positions.is_empty() {
            return identical;
        }
        // At scales where squared lengths leave f64's range (a model 1e-200 across: its edges'
        // squares underflow to 0), the lengths are taken on the positions scaled by a power of
        // two (exact), with the tolerance alike; the merged vertices keep their own positions.
        let k = scale_exponent(tolerance);
        if k != 0 {
            let f = 2f64.powi(k);
            let mut scaled = TriMesh {
                positions: self.positions.iter().map(|&p| p * f).collect(),
                triangles: self.triangles.clone(),
            };
            let near =
                scaled.weld_close_scaled(tolerance * f, edge_fraction, Some(&self.positions));
            self.positions = scaled.positions;
            self.triangles = scaled.triangles;
            return identical + near;
        }
        identical + self.weld_close_scaled(tolerance, edge_fraction, None)
    }

    /// The second step of [`TriMesh::weld_close_positions`] on positions whose squared lengths
    /// are in range; `original`: the positions to keep (unscaled) when these are scaled.
    fn weld_close_scaled(
        &mut self,
        tolerance: f64,
        edge_fraction: f64,
        original: Option<&[DVec3]>,
    ) -> usize {
        let shortest = self.shortest_edges();
        let lo = self
            .positions
            .iter()
            .fold(DVec3::splat(f64::INFINITY), |a, &p| a.min(p));
        // Cells of side 2 · `tolerance`: along each axis, a point within `tolerance` of p lies in
        // p's cell or in the neighbour on the side of the half p lies in, so 8 cells are looked
        // in, not 27 (both neighbours within WELD_CELL_MIDDLE of the middle, where rounding
        // could put it either way). `as i64` saturates, so a far point cannot wrap around.
        let side = 2.0 * tolerance;
        let mut grid: FxHashMap<[i64; 3], Vec<u32>> = FxHashMap::default();
        let mut kept: Vec<(DVec3, f64)> = Vec::with_capacity(self.positions.len());
        let mut remap = Vec::with_capacity(self.positions.len());
        for (&p, &short) in self.positions.iter().zip(&shortest) {
            let at = (p - lo) / side;
            let c = at.floor().to_array().map(|c| c as i64);
            let reach = (at - at.floor()).to_array().map(|f| {
                if f < 0.5 - WELD_CELL_MIDDLE {
                    -1..=0
                } else if f > 0.5 + WELD_CELL_MIDDLE {
                    0..=1
                } else {
                    -1..=1
                }
            });
            let mut into: Option<u32> = None;
            for dx in reach[0].clone() {
                for dy in reach[1].clone() {
                    for dz in reach[2].clone() {
                        let key = [c[0] + dx, c[1] + dy, c[2] + dz];
                        for &j in grid.get(&key).into_iter().flatten() {
                            let (q, q_short) = kept[j as usize];
                            let d = q.distance(p);
                            if d <= tolerance
                                && d <= edge_fraction * short.min(q_short)
                                && into.is_none_or(|k| j < k)
                            {
                                into = Some(j);
                            }
                        }
                    }
                }
            }
            let idx = into.unwrap_or_else(|| {
                kept.push((p, short));
                let j = (kept.len() - 1) as u32;
                // A cell holds at most WELD_CELL_CAP merge targets: a cluster of distinct
                // vertices within one cell (tiny faces, kept apart by the edge bound) would
                // otherwise be compared pairwise.
                let cell = grid.entry(c).or_default();
                if cell.len() < WELD_CELL_CAP {
                    cell.push(j);
                }
                j
            });
            remap.push(idx);
        }
        let near = self.positions.len() - kept.len();
        if let Some(original) = original {
            // Back to the positions as given: each kept vertex's own.
            let mut first = vec![u32::MAX; kept.len()];
            for (i, &j) in remap.iter().enumerate() {
                if first[j as usize] == u32::MAX {
                    first[j as usize] = i as u32;
                }
            }
            self.positions = original.to_vec();
            if near == 0 {
                return 0;
            }
            let kept = first.iter().map(|&i| original[i as usize]).collect();
            self.merge_vertices(kept, &remap);
            return near;
        }
        if near == 0 {
            return 0;
        }
        self.merge_vertices(kept.into_iter().map(|(p, _)| p).collect(), &remap);
        near
    }
}

/// The power of two that brings a length `tolerance` (a share of a model's size) to where squared
/// lengths of the model stay in f64's normal range: 0 for tolerances from 2^-400 to 2^400 (models
/// from about 2^-370 to 2^430 across at the weld's 1e-10), else the exponent that brings the
/// tolerance to about 2^-34 (a model about 1 across).
fn scale_exponent(tolerance: f64) -> i32 {
    let e = tolerance.log2();
    if (-400.0..=400.0).contains(&e) {
        0
    } else {
        (-34.0 - e).round() as i32
    }
}

/// The faces of `both_windings` (faces given in both windings, vertices sorted, each once)
/// that are walls between two volumes: the faces of `both_windings` joined across their shared
/// edges make patches, and a patch is a wall when it has a rim (edges of one face of the patch)
/// and each edge on its rim has at least two faces besides the patch's, one on either side
/// (`faces_on_edge`: the faces on each edge, one copy of each face counted). A single face is a
/// patch of its own; a floor between two stories, triangulated as a fan, is one patch whose
/// inner edges have the patch's faces only. A double-sided sheet's rim has at most one other
/// face on an edge, and a closed surface given double-sided has no rim. O(the faces given),
/// deterministic.
fn walls_among(
    both_windings: &[[u32; 3]],
    faces_on_edge: &FxHashMap<(u32, u32), u32>,
) -> FxHashSet<[u32; 3]> {
    let edges = |[a, b, c]: [u32; 3]| [(a, b), (b, c), (a, c)];
    // The patch faces on each edge, in order.
    let mut on_edge: FxHashMap<(u32, u32), Vec<usize>> = FxHashMap::default();
    for (i, &t) in both_windings.iter().enumerate() {
        for e in edges(t) {
            on_edge.entry(e).or_default().push(i);
        }
    }
    // Patches: faces joined across shared edges.
    let mut patches = Dsu::new(both_windings.len());
    for faces in on_edge.values() {
        for &j in &faces[1..] {
            patches.union(faces[0], j, false);
        }
    }
    // Per patch: whether it has a rim, and whether an edge of the rim has fewer than two other
    // faces.
    let mut rim = vec![false; both_windings.len()];
    let mut open_rim = vec![false; both_windings.len()];
    for (e, faces) in &on_edge {
        if faces.len() != 1 {
            continue;
        }
        let all = faces_on_edge.get(e).copied().unwrap_or(0) as usize;
        let r = patches.find(faces[0]).0;
        rim[r] = true;
        open_rim[r] |= all.saturating_sub(1) < 2;
    }
    (0..both_windings.len())
        .filter(|&i| {
            let r = patches.find(i).0;
            rim[r] && !open_rim[r]
        })
        .map(|i| both_windings[i])
        .collect()
}

/// What [`TriMesh::remove_duplicate_and_zero_area_faces`] removed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct FaceCleanup {
    /// Faces whose corners are collinear (exactly zero area).
    pub zero_area: usize,
    /// Faces with the same three vertices as an earlier face, in either winding.
    pub duplicates: usize,
    /// Of those, the ones whose winding is the opposite of the earlier face's (double-sided).
    pub opposite_duplicates: usize,
    /// Faces given in both windings that are walls between two volumes (every edge shared by
    /// more than two faces), removed with their copies (which count in `duplicates`, not in
    /// `opposite_duplicates`).
    pub internal_walls: usize,
}

impl FaceCleanup {
    /// Whether anything was removed.
    pub fn any(&self) -> bool {
        self.zero_area + self.duplicates + self.internal_walls > 0
    }
}

/// The similarity transform that maps a model into the bbox-100 frame of Sec. 7: centred on its
/// bounding box, longest side 100. All sigma_p, distances and tolerances of the pipeline are in
/// that frame; outputs are mapped back to model units with [`Normalization::invert`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Normalization {
    /// The model-space centre of the bounding box.
    pub center: DVec3,
    /// Model units to bbox-100 units (100 / longest side).
    pub scale: f64,
}

impl Normalization {
    /// The longest side of the bounding box after normalization.
    pub const TARGET_SIZE: f64 = 100.0;

    /// The normalization of `bbox`; `None` when its longest side is zero or not finite.
    pub fn for_bbox(bbox: &Aabb) -> Option<Self> {
        let side = bbox.longest_side();
        if !(side.is_finite() && side > 0.0) {
            return None;
        }
        let scale = Self::TARGET_SIZE / side;
        if !scale.is_finite() {
            return None;
        }
        Some(Normalization {
            center: bbox.center(),
            scale,
        })
    }

    /// Why [`Normalization::for_bbox`] gives no normalization for `bbox`, as a message naming
    /// the box's actual size: zero size (every vertex at one point), a longest side too large
    /// for `f64`, or one so small (below about 5.6e-307 model units, subnormal coordinates) that
    /// `100 / side` overflows.
    pub(crate) fn refusal(bbox: &Aabb) -> String {
        let side = bbox.longest_side();
        if side == 0.0 {
            let c = bbox.min;
            format!(
                "the bounding box has zero size (every vertex at ({:e}, {:e}, {:e}))",
                c.x, c.y, c.z
            )
        } else if !side.is_finite() {
            "the bounding box's longest side is too large for 64-bit floating point (coordinates \
             span more than 1.8e308 model units)"
                .to_string()
        } else {
            format!(
                "the bounding box's longest side is {side:e} model units, too small to scale to \
                 {} (coordinates below about 1e-306 are subnormal numbers); scale the model up",
                Self::TARGET_SIZE
            )
        }
    }

    /// The identity transform.
    pub fn identity() -> Self {
        Normalization {
            center: DVec3::ZERO,
            scale: 1.0,
        }
    }

    /// Model units to bbox-100 units.
    #[inline]
    pub fn apply(&self, p: DVec3) -> DVec3 {
        (p - self.center) * self.scale
    }

    /// bbox-100 units back to model units.
    #[inline]
    pub fn invert(&self, p: DVec3) -> DVec3 {
        p / self.scale + self.center
    }

    /// How far apart, in bbox-100 units, two faces of a mesh in this frame must be to stay
    /// apart once written in model units as `f32` (the coarsest coordinates any of our formats
    /// writes): four times the distance a corner moves when each coordinate of a point of the
    /// bounding box is rounded to `f32` (half its unit in the last place, √3 times, in bbox-100
    /// units), the mapping's own `f64` rounding far below it. For a model centred near the
    /// origin about 2e-5; larger for one far from it (a scan in UTM coordinates).
    pub fn written_rounding(&self) -> f64 {
        let half_side = 0.5 * Self::TARGET_SIZE / self.scale;
        let largest = self.center.abs().max_element() + half_side;
        4.0 * 3f64.sqrt() * 0.5 * f64::from(f32::EPSILON) * largest * self.scale
    }

    /// A copy of `mesh` in bbox-100 units.
    pub fn apply_mesh(&self, mesh: &TriMesh) -> TriMesh {
        TriMesh {
            positions: mesh.positions.iter().map(|&p| self.apply(p)).collect(),
            triangles: mesh.triangles.clone(),
        }
    }

    /// A copy of `mesh` back in model units.
    pub fn invert_mesh(&self, mesh: &TriMesh) -> TriMesh {
        TriMesh {
            positions: mesh.positions.iter().map(|&p| self.invert(p)).collect(),
            triangles: mesh.triangles.clone(),
        }
    }
}

/// Meshes for tests.
#[cfg(test)]
pub(crate) mod test_meshes {
    use super::TriMesh;
    use glam::DVec3;

    /// The two meshes as one (the second's vertices after the first's).
    pub fn union_of(a: &TriMesh, b: &TriMesh) -> TriMesh {
        let mut m = a.clone();
        let off = m.positions.len() as u32;
        m.positions.extend(b.positions.iter().copied());
        m.triangles
            .extend(b.triangles.iter().map(|t| t.map(|v| v + off)));
        m
    }

    /// `n` nearly evenly spread unit vectors: the Fibonacci spiral (z from 1 to -1, longitude
    /// advancing by the golden angle).
    pub fn fibonacci_sphere(n: usize) -> Vec<DVec3> {
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let s = (1.0 - z * z).sqrt();
                let a = golden * i as f64;
                DVec3::new(s * a.cos(), s * a.sin(), z)
            })
            .collect()
    }

    /// A UV sphere of radius `r` at the origin, outward: the poles (vertices 0 and 1), then
    /// `rings − 1` latitude circles of `segments` vertices; the two polar caps' faces first,
    /// then the bands ring by ring.
    pub fn uv_sphere(r: f64, rings: usize, segments: usize) -> TriMesh {
        let mut positions = vec![DVec3::new(0.0, 0.0, r), DVec3::new(0.0, 0.0, -r)];
        for k in 1..rings {
            let t = std::f64::consts::PI * k as f64 / rings as f64;
            for i in 0..segments {
                let a = std::f64::consts::TAU * i as f64 / segments as f64;
                positions.push(r * DVec3::new(t.sin() * a.cos(), t.sin() * a.sin(), t.cos()));
            }
        }
        let id = |k: usize, i: usize| (2 + (k - 1) * segments + i % segments) as u32;
        let mut triangles = Vec::new();
        for i in 0..segments {
            triangles.push([0, id(1, i), id(1, i + 1)]);
            triangles.push([1, id(rings - 1, i + 1), id(rings - 1, i)]);
        }
        for k in 1..rings - 1 {
            for i in 0..segments {
                triangles.push([id(k, i), id(k + 1, i), id(k + 1, i + 1)]);
                triangles.push([id(k, i), id(k + 1, i + 1), id(k, i + 1)]);
            }
        }
        TriMesh::new(positions, triangles)
    }

    /// The flip tests' fixture: the 8 corners (z = 0) of a convex quad 0-3-1-2 whose long
    /// diagonal is 0-1 and of a ring 6-5-7-4 around it, and the faces: the quad split along 0-1
    /// (the first two), then the ring's eight, which give 0 and 1 six faces each.
    pub fn quad_in_ring() -> (Vec<DVec3>, [[u32; 3]; 10]) {
        let positions: Vec<DVec3> = [
            (0.0, 0.0),
            (2.0, 0.0),
            (1.0, 0.3),
            (1.0, -0.3),
            (1.0, 2.0),
            (1.0, -2.0),
            (-1.5, 0.0),
            (3.5, 0.0),
        ]
        .iter()
        .map(|&(x, y)| DVec3::new(x, y, 0.0))
        .collect();
        let faces = [
            [0, 1, 2],
            [1, 0, 3],
            [0, 2, 4],
            [2, 1, 4],
            [3, 0, 5],
            [1, 3, 5],
            [6, 0, 4],
            [6, 5, 0],
            [1, 7, 4],
            [1, 5, 7],
        ];
        (positions, faces)
    }

    /// A closed axis-aligned box from `lo` to `hi`, faces outward.
    pub fn cuboid(lo: DVec3, hi: DVec3) -> TriMesh {
        let p = |x: usize, y: usize, z: usize| {
            DVec3::new(
                if x == 0 { lo.x } else { hi.x },
                if y == 0 { lo.y } else { hi.y },
                if z == 0 { lo.z } else { hi.z },
            )
        };
        let positions = vec![
            p(0, 0, 0),
            p(1, 0, 0),
            p(1, 1, 0),
            p(0, 1, 0),
            p(0, 0, 1),
            p(1, 0, 1),
            p(1, 1, 1),
            p(0, 1, 1),
        ];
        let triangles = vec![
            [0, 2, 1],
            [0, 3, 2],
            [4, 5, 6],
            [4, 6, 7],
            [0, 1, 5],
            [0, 5, 4],
            [1, 2, 6],
            [1, 6, 5],
            [2, 3, 7],
            [2, 7, 6],
            [3, 0, 4],
            [3, 4, 7],
        ];
        TriMesh::new(positions, triangles)
    }

    /// Two parallel `n × n` unit grids 0.2 apart, the upper one shifted by (0.3, 0.4) so that no
    /// vertex lies above another; returns the mesh and the index of the upper grid's first
    /// vertex.
    pub fn stacked_grids(n: usize) -> (TriMesh, u32) {
        let a = grid(n, |i, j| DVec3::new(i as f64, j as f64, 0.0));
        let b = grid(n, |i, j| DVec3::new(i as f64 + 0.3, j as f64 + 0.4, 0.2));
        let mut m = a;
        let off = m.positions.len() as u32;
        m.positions.extend(b.positions.iter().copied());
        m.triangles
            .extend(b.triangles.iter().map(|t| t.map(|v| v + off)));
        (m, off)
    }

    /// An open cylinder of radius `r` round the z axis from z = 0: `sides` facets round, `rings`
    /// bands of height `band`, each quad split along a diagonal; outward. Vertex `k · sides + i`
    /// is ring k's i-th.
    pub fn open_cylinder(r: f64, sides: usize, rings: usize, band: f64) -> TriMesh {
        let mut positions = Vec::new();
        for k in 0..=rings {
            for i in 0..sides {
                let a = std::f64::consts::TAU * i as f64 / sides as f64;
                positions.push(DVec3::new(r * a.cos(), r * a.sin(), band * k as f64));
            }
        }
        let at = |k: usize, i: usize| (k * sides + i % sides) as u32;
        let mut triangles = Vec::new();
        for k in 0..rings {
            for i in 0..sides {
                triangles.push([at(k, i), at(k, i + 1), at(k + 1, i + 1)]);
                triangles.push([at(k, i), at(k + 1, i + 1), at(k + 1, i)]);
            }
        }
        TriMesh::new(positions, triangles)
    }

    /// An `n × n` grid of squares, each cut by a diagonal; vertex `(i, j)` (0 ..= n each) is at
    /// `position(i, j)`.
    pub fn grid(n: usize, position: impl Fn(usize, usize) -> DVec3) -> TriMesh {
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                positions.push(position(i, j));
            }
        }
        let mut triangles = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let v = (j * (n + 1) + i) as u32;
                let w = v + n as u32 + 1;
                triangles.push([v, v + 1, w + 1]);
                triangles.push([v, w + 1, w]);
            }
        }
        TriMesh::new(positions, triangles)
    }
}

#[cfg(test)]
mod tests;
