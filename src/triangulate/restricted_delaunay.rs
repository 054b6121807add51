//! The restricted Delaunay triangulation of surface samples, as the dual of their Voronoi cells
//! restricted to the input mesh: each sample's cell is the part of the surface nearer to it than
//! to any other sample, grown over the mesh from the sample (so a cell never jumps across a thin
//! part to the sheet on its other side, as a cell of the plain restricted Voronoi diagram does
//! where the closed-ball property fails: H. Edelsbrunner, N. Shah, "Triangulating topological
//! spaces", IJCGA 1997). Three cells meeting at a point of the surface give a triangle.
//!
//! The cells are computed on the input refined by edge bisection to a fraction of the sample
//! spacing (`mesh::bisect`): every refined vertex takes the sample nearest to it among those
//! whose cell reaches it through the mesh (a multi-source Dijkstra search with the Euclidean
//! distance to the sample as key, as the discrete restricted Voronoi diagrams of clustering
//! remeshers: S. Valette, J.-M. Chassery, R. Prost, "Generic remeshing of 3D triangular meshes
//! with metric-dependent discrete Voronoi diagrams", TVCG 2008). A refined face whose three
//! corners lie in three cells is a vertex of the diagram; its dual triangle is oriented like the
//! input.

use glam::DVec3;
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::Triangle;
use rayon::prelude::*;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::rows::Rows;
use super::tangent_delaunay::VotedTriangle;
use super::topological_ball::{self, TopologicalBallParams, TopologicalBallStats};
use crate::mesh::bisect::bisect_to_length;
use crate::mesh::sheets::Sheets;
use crate::sampling::sizing::SizingField;
use crate::spatial::StaticTree;
use crate::surface::{MeshSurface, SurfacePoint};

/// Parameters of `restricted_delaunay`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestrictedDelaunayParams {
    /// Longest edge of the refined input, as a fraction of the sample spacing (default 0.5:
    /// about 15 refined vertices per cell; finer and coarser settings changed no topology, see
    /// `docs/decisions/restricted-delaunay-default.md`).
    pub resolution: f64,
    /// The most vertices the refinement adds per sample (default 200, room for the CAD parts'
    /// sliver tessellations): beyond, `restricted_delaunay` gives up and the umbrellas connect
    /// the samples (a degenerate sliver, whose bisection makes ever thinner slivers). The
    /// figures behind 200: `docs/decisions/restricted-delaunay-default.md`.
    pub max_added_per_sample: usize,
    /// Whether the cells are clipped exactly from the input's facets
    /// (`restricted_voronoi::restricted_voronoi`, as
    /// [`triangulate_restricted`](super::triangulate_restricted) calls it) rather than grown
    /// over the input refined to `resolution` (this module's search, kept as the oracle the
    /// clipped cells are tested against). `resolution` and `max_added_per_sample` apply to
    /// the refined cells only.
    pub clipped: bool,
    /// The check of the topological ball property on the refined cells and the samples it
    /// inserts where a cell is not a disc or two cells meet twice (refined cells only).
    pub topological_ball: TopologicalBallParams,
}

impl Default for RestrictedDelaunayParams {
    fn default() -> Self {
        RestrictedDelaunayParams {
            resolution: 0.5,
            max_added_per_sample: 200,
            clipped: false,
            topological_ball: TopologicalBallParams::default(),
        }
    }
}

/// What `restricted_delaunay` did.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct RestrictedDelaunayStats {
    /// Vertices of the refined input (0 for clipped cells).
    pub refined_vertices: usize,
    /// (Sample, facet) pairs clipped (0 for refined cells).
    pub clipped_facets: usize,
    /// Facets clipped again where the grown cells left them uncovered (0 for refined cells).
    pub reclipped_facets: usize,
    /// Distinct dual triangles.
    pub triangles: usize,
    /// Samples in no dual triangle (refined cells: whose cell holds no vertex of the refined
    /// input).
    pub empty_cells: usize,
    /// The check of the topological ball property and the samples it inserted (refined cells
    /// only).
    pub topological_ball: TopologicalBallStats,
}

/// The dual triangles of the samples' restricted Voronoi cells on `surface`'s mesh, as
/// candidates for [`assemble`](super::assemble): each with 3 votes, oriented like the input,
/// the ones met at more refined faces first. `sheets`: those of `surface`'s mesh (closed parts
/// that meet at a non-manifold edge are refined apart). `positions`: the samples (units of the
/// mesh, on or near the surface); `spacing`: the sample spacing (same units). Also returns the
/// samples inserted where the cells failed the topological ball property
/// ([`topological_ball`](super::topological_ball)): on the input, numbered after `positions`
/// in the triangles. `None` when the refinement would add more than
/// `params.max_added_per_sample` vertices per sample.
pub fn restricted_delaunay(
    surface: &MeshSurface,
    sheets: &Sheets,
    positions: &[DVec3],
    spacing: f64,
    field: &dyn SizingField,
    params: &RestrictedDelaunayParams,
) -> Option<(Vec<VotedTriangle>, RestrictedDelaunayStats, Vec<DVec3>)> {
    let budget = params
        .max_added_per_sample
        .saturating_mul(positions.len().max(1));
    // Parts that meet at non-manifold edges are refined apart (each sheet with its
    // own copy of the vertices it shares), so that no cell grows from one onto the other: each
    // part's triangles join only its own samples.
    let split = sheets.split(surface.mesh());
    let sheet = &sheets.part;
    // The input refined to a fraction of the local spacing: the sizing field's where the
    // samples are graded.
    let width = |p: DVec3| field.width(p);
    let refined = bisect_to_length(
        split.as_ref().unwrap_or(surface.mesh()),
        params.resolution * spacing,
        (!field.is_uniform()).then_some(&width as &(dyn Fn(DVec3) -> f64 + Sync)),
        budget,
    )?;
    let n = refined.positions.len();
    // The sheet of each refined vertex, where there are sheets to tell apart.
    let vertex_sheet: Option<Vec<u32>> = split.as_ref().map(|_| {
        let mut of = vec![0u32; n];
        for (t, &f) in refined.triangles.iter().zip(&refined.parent) {
            for &v in t {
                of[v as usize] = sheet[f as usize];
            }
        }
        of
    });
    let on_sheet = |v: u32, f: u32| {
        vertex_sheet
            .as_ref()
            .is_none_or(|of| of[v as usize] == sheet[f as usize])
    };
    // Vertex -> its neighbours.
    let neighbours = Rows::new(n, &refined.triangles);
    let radius = params.resolution * spacing * 1.01;
    let tolerance = crate::geometry::tolerance::ON_SURFACE_RELATIVE * spacing;
    let labels = Labels {
        surface,
        refined: &refined,
        neighbours: &neighbours,
        positions,
        radius,
        tolerance,
        on_sheet: &on_sheet,
    };
    let mut label = labels.grow();
    let cells = topological_ball::Refined {
        positions: &refined.positions,
        triangles: &refined.triangles,
        neighbours: &neighbours,
    };
    let (added, ball) =
        topological_ball::enforce(&cells, positions, &mut label, &params.topological_ball);
    // Dual triangles: refined faces with three labels, counted per triple and orientation.
    let tally = tally_triples(
        refined
            .triangles
            .iter()
            .map(|t| t.map(|v| label[v as usize]))
            .filter(|l| l[0] != l[1] && l[1] != l[2] && l[0] != l[2] && !l.contains(&u32::MAX)),
    );
    let mut owned = vec![false; positions.len() + added.len()];
    for &l in &label {
        if l != u32::MAX {
            owned[l as usize] = true;
        }
    }
    let stats = RestrictedDelaunayStats {
        refined_vertices: n,
        clipped_facets: 0,
        reclipped_facets: 0,
        triangles: tally.len(),
        empty_cells: owned.iter().filter(|o| !**o).count(),
        topological_ball: ball,
    };
    Some((voted(tally, false), stats, added))
}

/// The tallied dual triangles ([`tally_triples`]) as candidates of 3 votes each, in order;
/// `conflicts`: whether a triple met in both orientations is marked so (the refined cells
/// never mark it).
pub(super) fn voted(tally: Vec<(usize, [u32; 3], bool)>, conflicts: bool) -> Vec<VotedTriangle> {
    tally
        .into_iter()
        .map(|(_, corners, conflict)| VotedTriangle {
            corners,
            votes: 3,
            orientation_conflict: conflicts && conflict,
        })
        .collect()
}

/// Dual triangles as they were met (each its three samples, counter-clockwise about the input),
/// one per distinct triple: how many met it in the orientation most of them give, its corners
/// in that orientation (the ascending one, after rotating the smallest first, on a tie), and
/// whether the other orientation was met too; the most met first, then by corners.
pub(super) fn tally_triples(
    met: impl IntoIterator<Item = [u32; 3]>,
) -> Vec<(usize, [u32; 3], bool)> {
    // Each triple with its orientation: whether its corners ascend after rotating the smallest
    // first.
    let mut seen: Vec<([u32; 3], bool)> = met
        .into_iter()
        .map(|l| {
            let k = (0..3).min_by_key(|&k| l[k]).unwrap_or(0);
            let r = [l[k], l[(k + 1) % 3], l[(k + 2) % 3]];
            if r[1] < r[2] {
                (r, true)
            } else {
                ([r[0], r[2], r[1]], false)
            }
        })
        .collect();
    seen.par_sort_unstable();
    let mut tally: Vec<(usize, [u32; 3], bool)> = seen
        .chunk_by(|a, b| a.0 == b.0)
        .map(|group| {
            let t = group[0].0;
            let forward = group.iter().filter(|x| x.1).count();
            let backward = group.len() - forward;
            let corners = if forward >= backward {
                t
            } else {
                [t[0], t[2], t[1]]
            };
            (forward.max(backward), corners, forward > 0 && backward > 0)
        })
        .collect();
    tally.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    tally
}

/// The search of `restricted_delaunay` for each refined vertex's sample: the nearest sample
/// whose cell reaches the vertex over the refined mesh, as a multi-source Dijkstra search from
/// each sample's seeds (the refined vertices within `radius` of its closest point on the input
/// that lie on its face) with the Euclidean distance to the sample as key, ties to the lower
/// sample index.
///
/// Most vertices are settled without the search: a vertex whose nearest sample of all is s, and
/// that a path of such vertices joins to a seed of s, is labelled s by the search too (every
/// vertex on the path is offered s, and nothing is nearer). Those are found in parallel
/// (nearest samples through a kd-tree of the samples, which also lists each vertex's seeds) and
/// by a flood over the vertices with the same nearest sample; the search then runs over the
/// rest only (where a cell would reach over a thin part to the other side, or through another
/// sheet), from the settled vertices around them. No index of the refined vertices is built.
struct Labels<'a> {
    surface: &'a MeshSurface,
    refined: &'a crate::mesh::bisect::Refined,
    neighbours: &'a Rows,
    positions: &'a [DVec3],
    radius: f64,
    tolerance: f64,
    on_sheet: &'a (dyn Fn(u32, u32) -> bool + Sync),
}

/// One parallel task's part of [`Labels::grow`]: its vertices' nearest samples and its
/// (sample, vertex) seed pairs.
type LabelChunk = (Vec<u32>, Vec<(u32, u32)>);

/// Refined vertices per parallel task of [`Labels::grow`].
const LABEL_CHUNK: usize = 4096;

/// Samples asked of the kd-tree per refined vertex: the nearest, its ties, and the seeds
/// (closest points within `radius`, of which a vertex has one or two); more are listed by a
/// search within the radius when the last of these is still within it.
const LABEL_NEAREST: usize = 4;

impl Labels<'_> {
    /// Each refined vertex's label (`u32::MAX`: reached by no cell).
    fn grow(&self) -> Vec<u32> {
        let (refined, positions) = (self.refined, self.positions);
        let n = refined.positions.len();
        let anchors = self.anchors();
        // The seeds are listed around the samples, wider by how far a sample lies from its
        // closest point.
        let offset = anchors
            .iter()
            .zip(positions)
            .filter_map(|(a, &x)| a.map(|a| a.position.distance(x)))
            .fold(0.0, f64::max);
        let reach_2 = (self.radius + offset).powi(2);
        let tree = StaticTree::new(positions);
        // Per vertex, in parallel: its nearest sample, and the (sample, vertex) seed pairs.
        let chunks: Vec<LabelChunk> = (0..n.div_ceil(LABEL_CHUNK))
            .into_par_iter()
            .map_init(Vec::new, |found, c| {
                let vertices = c * LABEL_CHUNK..((c + 1) * LABEL_CHUNK).min(n);
                let mut nearest = Vec::with_capacity(vertices.len());
                let mut seeds = Vec::new();
                for v in vertices {
                    let p = refined.positions[v];
                    tree.nearest_n(p, LABEL_NEAREST, found);
                    if found.len() == LABEL_NEAREST
                        && found.last().is_some_and(|&(_, d2)| d2 <= reach_2)
                    {
                        tree.within_unsorted(p, reach_2, found);
                    }
                    let best = found
                        .iter()
                        .map(|&(s, _)| (p.distance(positions[s as usize]), s))
                        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                    nearest.push(best.map_or(u32::MAX, |b| b.1));
                    for &(s, d2) in found.iter() {
                        if d2 <= reach_2 && self.is_seed(&anchors, s, v as u32) {
                            seeds.push((s, v as u32));
                        }
                    }
                }
                (nearest, seeds)
            })
            .collect();
        let mut label = Vec::with_capacity(n);
        let mut seeds = Vec::new();
        for (l, s) in chunks {
            label.extend(l);
            seeds.extend(s);
        }
        seeds.sort_unstable();
        seeds.extend(self.fallback_seeds(&anchors, &seeds));
        // Settled: joined to a seed of their nearest sample through vertices of that sample.
        let mut settled = vec![false; n];
        let mut stack: Vec<u32> = Vec::new();
        for &(s, v) in &seeds {
            if label[v as usize] == s && !settled[v as usize] {
                settled[v as usize] = true;
                stack.push(v);
            }
        }
        while let Some(v) = stack.pop() {
            let s = label[v as usize];
            for &u in self.neighbours.row(v) {
                if !settled[u as usize] && label[u as usize] == s {
                    settled[u as usize] = true;
                    stack.push(u);
                }
            }
        }
        self.search(&seeds, &settled, label)
    }

    /// The Dijkstra search over the vertices not `settled`, from the settled ones beside them
    /// (which keep their `label`) and from the `seeds` (sample, vertex) among them: each
    /// vertex's label (`u32::MAX`: reached by no cell).
    fn search(&self, seeds: &[(u32, u32)], settled: &[bool], mut label: Vec<u32>) -> Vec<u32> {
        let (refined, positions) = (self.refined, self.positions);
        let n = refined.positions.len();
        let mut dist = vec![f64::INFINITY; n];
        for v in 0..n {
            if settled[v] {
                dist[v] = refined.positions[v].distance(positions[label[v] as usize]);
            } else {
                label[v] = u32::MAX;
            }
        }
        let mut heap: BinaryHeap<Reverse<(u64, u32, u32)>> = BinaryHeap::new();
        for v in 0..n as u32 {
            if settled[v as usize] && self.neighbours.row(v).iter().any(|&u| !settled[u as usize]) {
                heap.push(Reverse((dist[v as usize].to_bits(), label[v as usize], v)));
            }
        }
        let offer = |v: u32,
                     s: u32,
                     d: f64,
                     dist: &mut [f64],
                     label: &mut [u32],
                     heap: &mut BinaryHeap<_>| {
            let i = v as usize;
            if !settled[i] && (d < dist[i] || (d == dist[i] && s < label[i])) {
                dist[i] = d;
                label[i] = s;
                heap.push(Reverse((d.to_bits(), s, v)));
            }
        };
        for &(s, v) in seeds {
            let d = refined.positions[v as usize].distance(positions[s as usize]);
            offer(v, s, d, &mut dist, &mut label, &mut heap);
        }
        while let Some(Reverse((d, s, v))) = heap.pop() {
            let i = v as usize;
            if d != dist[i].to_bits() || s != label[i] {
                continue;
            }
            let x = positions[s as usize];
            for &u in self.neighbours.row(v) {
                let du = refined.positions[u as usize].distance(x);
                offer(u, s, du, &mut dist, &mut label, &mut heap);
            }
        }
        label
    }

    /// Each sample's closest point on the input (a sample lies on it, up to rounding).
    fn anchors(&self) -> Vec<Option<SurfacePoint>> {
        self.positions
            .par_iter()
            .map(|&x| {
                self.surface
                    .closest_point_hinted(x, self.tolerance, f64::MAX)
            })
            .collect()
    }

    /// Whether refined vertex `v` is a seed of sample `s` (closest points `anchors`): within
    /// `radius` of its closest point, on its sheet, and lying in its face.
    fn is_seed(&self, anchors: &[Option<SurfacePoint>], s: u32, v: u32) -> bool {
        anchors[s as usize].is_some_and(|sp| {
            let p = self.refined.positions[v as usize];
            (p - sp.position).length_squared() <= self.radius * self.radius
                && (self.on_sheet)(v, sp.face)
                && lies_in(self.surface, sp.face, p, self.tolerance)
        })
    }

    /// Seeds of the samples that have none within the radius on their face (a face of the
    /// input smaller than the refinement's resolution): the refined vertex of the sample's face
    /// nearest to its closest point. `seeds`: the others', sorted.
    fn fallback_seeds(
        &self,
        anchors: &[Option<SurfacePoint>],
        seeds: &[(u32, u32)],
    ) -> Vec<(u32, u32)> {
        let mut without: rustc_hash::FxHashMap<u32, Vec<u32>> = Default::default();
        for (s, a) in anchors.iter().enumerate() {
            let s = s as u32;
            if let Some(sp) = a {
                if seeds.binary_search_by(|&(t, _)| t.cmp(&s)).is_err() {
                    without.entry(sp.face).or_default().push(s);
                }
            }
        }
        if without.is_empty() {
            return Vec::new();
        }
        // (distance, vertex) of the best vertex so far per sample.
        let mut best: std::collections::BTreeMap<u32, (f64, u32)> = Default::default();
        for (t, &f) in self.refined.triangles.iter().zip(&self.refined.parent) {
            let Some(samples) = without.get(&f) else {
                continue;
            };
            for &s in samples {
                let sp = anchors[s as usize].expect("listed with a closest point");
                for &v in t {
                    let d = self.refined.positions[v as usize].distance(sp.position);
                    let e = best.entry(s).or_insert((f64::INFINITY, u32::MAX));
                    if (d, v) < *e && (self.on_sheet)(v, f) {
                        *e = (d, v);
                    }
                }
            }
        }
        best.into_iter().map(|(s, (_, v))| (s, v)).collect()
    }
}

#[cfg(test)]
impl Labels<'_> {
    /// The search of every vertex from the seeds (the search before the settled vertices were
    /// taken out of it): the reference [`Labels::grow`] must equal.
    fn full_search(&self) -> Vec<u32> {
        let refined = self.refined;
        let n = refined.positions.len();
        let anchors = self.anchors();
        let tree = StaticTree::new(&refined.positions);
        let mut seeds = Vec::new();
        let mut near = Vec::new();
        for (s, a) in anchors.iter().enumerate() {
            if let Some(sp) = a {
                tree.within_unsorted(sp.position, self.radius * self.radius, &mut near);
                for &(v, _) in &near {
                    if self.is_seed(&anchors, s as u32, v) {
                        seeds.push((s as u32, v));
                    }
                }
            }
        }
        seeds.sort_unstable();
        seeds.extend(self.fallback_seeds(&anchors, &seeds));
        self.search(&seeds, &vec![false; n], vec![u32::MAX; n])
    }
}

/// Whether `p` lies in face `f` of `surface`'s mesh: within `tolerance` of its plane and of
/// the triangle (the refined vertices of a face are midpoints of its points, so they lie on it
/// up to rounding; a vertex of the sheet across a thin part does not).
fn lies_in(surface: &MeshSurface, f: u32, p: DVec3, tolerance: f64) -> bool {
    let [a, b, c] = surface.mesh().corners(f as usize);
    Triangle::new(a, b, c).distance_to_local_point(p, true) <= tolerance
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes;
    use crate::mesh::TriMesh;
    use crate::sampling::sizing::Uniform;
    use crate::triangulate::{triangulate, triangulate_restricted, SampleSet, TriangulateParams};

    /// Samples of a plate `w × w × t` (t far below the spacing 1): a grid on the top and the
    /// bottom, shifted against each other, and a row along the middle of each side.
    fn plate_samples(w: usize, t: f64) -> Vec<DVec3> {
        let mut p = Vec::new();
        for i in 0..w {
            for j in 0..w {
                p.push(DVec3::new(i as f64 + 0.5, j as f64 + 0.5, t));
                p.push(DVec3::new(i as f64 + 0.6, j as f64 + 0.3, 0.0));
            }
        }
        for i in 0..=w {
            let s = i as f64;
            let w = w as f64;
            p.extend([
                DVec3::new(s, 0.0, t / 2.0),
                DVec3::new(w, s, t / 2.0),
                DVec3::new(w - s, w, t / 2.0),
                DVec3::new(0.0, w - s, t / 2.0),
            ]);
        }
        p.sort_by(|a, b| a.to_array().partial_cmp(&b.to_array()).unwrap());
        p.dedup();
        p
    }

    fn faces_follow_the_input(
        surface: &MeshSurface,
        positions: &[DVec3],
        faces: &[[u32; 3]],
    ) -> usize {
        let mesh = TriMesh::new(positions.to_vec(), faces.to_vec());
        (0..faces.len())
            .filter(|&f| {
                let c = mesh.corners(f).iter().fold(DVec3::ZERO, |a, &b| a + b) / 3.0;
                let sp = surface.closest_point(c).unwrap();
                mesh.face_normal(f).dot(surface.face_normal(sp.face)) <= 0.0
            })
            .count()
    }

    /// The restricted triangulation with `rd`, or the umbrellas (`None`).
    fn run(
        surface: &MeshSurface,
        positions: &[DVec3],
        rd: Option<RestrictedDelaunayParams>,
    ) -> Vec<[u32; 3]> {
        let normals: Vec<DVec3> = positions
            .iter()
            .map(|&p| surface.smooth_normal(&surface.closest_point(p).unwrap()))
            .collect();
        let set = SampleSet {
            positions,
            normals: &normals,
            boundary_edges: &[],
        };
        let params = TriangulateParams::default();
        if let Some(rd) = rd {
            triangulate_restricted(
                &set,
                surface,
                &Sheets::new(surface.mesh()),
                1.0,
                &Uniform,
                &params,
                &rd,
            )
            .unwrap()
            .0
        } else {
            triangulate(&set, &params).0
        }
    }

    #[test]
    fn a_plate_thinner_than_the_spacing_comes_out_closed_and_in_one_piece() {
        // 10 x 10 x 0.1, sampled at spacing 1: the umbrellas of the two sides see each other
        // (the umbrella triangulation of these samples is not a closed surface following the
        // plate, measured when this test was written). The cells grown over the refined input
        // and the clipped cells alike (but for a corner sample, below).
        let mesh = test_meshes::cuboid(DVec3::ZERO, DVec3::new(10.0, 10.0, 0.1));
        let surface = MeshSurface::new(&mesh).unwrap();
        let positions = plate_samples(10, 0.1);
        for clipped in [false, true] {
            let rd = RestrictedDelaunayParams {
                clipped,
                ..Default::default()
            };
            let faces = run(&surface, &positions, Some(rd));
            let out = TriMesh::new(positions.clone(), faces.clone());
            let t = crate::check::topology(&out);
            assert_eq!(
                (
                    t.components,
                    t.euler_characteristic,
                    t.boundary_edges,
                    t.non_manifold_edges
                ),
                (1, 2, 0, 0),
                "clipped {clipped}: {t:?}"
            );
            if !clipped {
                // The clipped cells leave one corner sample, (10, 0, 0.05), out: at the plate's
                // corner the samples taking part change from facet to facet (the top's and the
                // bottom's samples face apart), and its cell's pieces meet no two others.
                assert_eq!(t.vertices, positions.len(), "every sample in a face");
            }
            assert_eq!(faces_follow_the_input(&surface, &positions, &faces), 0);
        }
    }

    /// The labels of the search that settles most vertices first are those of the search over
    /// every vertex: on a sphere, and on a plate thinner than the spacing (where cells would
    /// reach through to the other side if the nearest sample were taken alone).
    #[test]
    fn the_settled_vertices_leave_the_search_its_answer() {
        let sphere = test_meshes::uv_sphere(10.0, 24, 48);
        let surface = MeshSurface::new(&sphere).unwrap();
        let on_sphere: Vec<DVec3> = test_meshes::fibonacci_sphere(300)
            .into_iter()
            .map(|u| surface.closest_point(10.0 * u).unwrap().position)
            .collect();
        let plate = test_meshes::cuboid(DVec3::ZERO, DVec3::new(10.0, 10.0, 0.1));
        for (mesh, positions) in [(sphere, on_sphere), (plate, plate_samples(10, 0.1))] {
            let surface = MeshSurface::new(&mesh).unwrap();
            let spacing = (mesh.area() / positions.len() as f64).sqrt();
            let refined = bisect_to_length(&mesh, 0.5 * spacing, None, usize::MAX).unwrap();
            let neighbours = Rows::new(refined.positions.len(), &refined.triangles);
            let labels = Labels {
                surface: &surface,
                refined: &refined,
                neighbours: &neighbours,
                positions: &positions,
                radius: 0.505 * spacing,
                tolerance: 1e-9 * spacing,
                on_sheet: &|_, _| true,
            };
            let grown = labels.grow();
            assert!(grown.iter().all(|&l| l != u32::MAX));
            assert_eq!(grown, labels.full_search());
        }
    }

    #[test]
    fn samples_on_a_sphere_give_a_closed_sphere() {
        let mesh = test_meshes::uv_sphere(10.0, 24, 48);
        let surface = MeshSurface::new(&mesh).unwrap();
        let sheets = Sheets::new(&mesh);
        let positions: Vec<DVec3> = test_meshes::fibonacci_sphere(300)
            .into_iter()
            .map(|u| surface.closest_point(10.0 * u).unwrap().position)
            .collect();
        let spacing = (mesh.area() / 300.0).sqrt();
        let normals: Vec<DVec3> = positions.iter().map(|p| p.normalize()).collect();
        let set = SampleSet {
            positions: &positions,
            normals: &normals,
            boundary_edges: &[],
        };
        let (voted, stats, _) = restricted_delaunay(
            &surface,
            &sheets,
            &positions,
            spacing,
            &Uniform,
            &Default::default(),
        )
        .unwrap();
        assert_eq!(stats.empty_cells, 0);
        // On a sphere the dual alone is the whole triangulation: 2V - 4 faces.
        assert_eq!(voted.len(), 2 * 300 - 4);
        let (faces, _, _, _, _) = triangulate_restricted(
            &set,
            &surface,
            &sheets,
            spacing,
            &Uniform,
            &TriangulateParams::default(),
            &Default::default(),
        )
        .unwrap();
        let t = crate::check::topology(&TriMesh::new(positions.clone(), faces.clone()));
        assert_eq!(
            (t.components, t.euler_characteristic, t.boundary_edges),
            (1, 2, 0)
        );
        assert_eq!(faces_follow_the_input(&surface, &positions, &faces), 0);
    }
}
