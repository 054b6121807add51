//! The restricted Voronoi diagram of surface samples on the input mesh, computed exactly by
//! clipping the input's facets (D.-M. Yan, B. Lévy, Y. Liu, F. Sun, W. Wang, "Isotropic remeshing
//! with fast and exact computation of restricted Voronoi diagram", SGP 2009; B. Lévy, N. Bonneel,
//! "Variational anisotropic surface meshing with Voronoi parallel linear enumeration", IMR 2012),
//! and its dual, the restricted Delaunay triangulation: every point of the surface where three
//! cells meet gives the triangle of their three samples.
//!
//! Each sample's cell is grown over the mesh from the facet the sample lies on, facet by facet
//! across the facet edges its cell reaches: on each facet it meets, the facet (a triangle) is
//! clipped by the bisector planes of the sample and its nearest samples, nearest first, until the
//! next sample is farther than twice the farthest corner of what is left (the security radius:
//! no farther sample can cut it). A part of the plain restricted Voronoi cell that the sample
//! does not reach over the mesh (across a thin part, on the sheet on its other side) is not
//! grown, as in the refined oracle (`restricted_delaunay`), and for the same reason
//! (H. Edelsbrunner, N. Shah, "Triangulating topological spaces", IJCGA 1997).
//!
//! The cost grows with the samples and the facets their cells meet, not with a refined copy of
//! the input; the samples are taken in parallel, each on its own.

use glam::DVec3;
use rayon::prelude::*;
use rustc_hash::FxHashSet;

use super::restricted_delaunay::{tally_triples, voted, RestrictedDelaunayStats};
use super::tangent_delaunay::VotedTriangle;
use crate::mesh::sheets::Sheets;
use crate::mesh::TriMesh;
use crate::spatial::StaticTree;
use crate::surface::MeshSurface;

/// The label of a cell's edge that lies on edge `k` (0, 1, 2: from corner k to corner k + 1)
/// of its facet is `FACET_EDGE + k`; any smaller label is the sample across a bisector.
const FACET_EDGE: u32 = u32::MAX - 3;

/// Samples asked of the kd-tree first for each cell (more when the security radius needs them).
const FIRST_NEIGHBOURS: usize = 32;

/// Samples per parallel task.
const CHUNK: usize = 512;

/// One sample's cell, or a facet's cells when it is clipped again.
#[derive(Default)]
struct Cell {
    /// Dual triangles and the facet each was met on: the cell's own sample first,
    /// counter-clockwise about the facet.
    triangles: Vec<(u32, [u32; 3])>,
    /// Pieces: the facet, the sample, the piece's area (units of the mesh, squared) and which
    /// of the facet's edges it reaches (bit k: edge k, from corner k to corner k + 1).
    pieces: Vec<(u32, u32, f64, u8)>,
    /// Facets clipped (those with no piece of the cell included).
    clipped: usize,
}

/// Rounds of clipping again the facets the cells leave uncovered, at most.
const RECLIP_ROUNDS: usize = 3;

/// A facet counts as covered when its cells' pieces leave less than this fraction of its area
/// (the pieces' areas are summed in floating point: an exactly covered facet misses by about
/// 1e-15 of its area).
const UNCOVERED_RELATIVE: f64 = 1e-9;

/// The dual triangles of the samples' restricted Voronoi cells on `surface`'s mesh, clipped
/// exactly (see the module), as candidates for [`assemble`](super::assemble): each with 3 votes,
/// oriented like the input, the ones more cells met in that orientation first. `sheets`: those of `surface`'s mesh
/// (closed parts that meet at a non-manifold edge are kept apart: no cell grows from one onto
/// the other). `positions`: the samples (units of the mesh, on or near the surface), distinct;
/// `normals`: the surface's unit normal at each (which side of a thin part a sample is on:
/// `SAME_SIDE_COS`); `tolerance`: about how far a sample lies from the surface (same units; a
/// hint to the closest point search). `None` when no three cells meet.
///
/// Where the grown cells leave part of a facet uncovered (the sample nearest there reaches it
/// only across a thin part), the facet is clipped again among the samples whose cells reach it
/// or a facet beside it, as the refined oracle gives such a place to the nearest sample whose
/// cell reaches it over the mesh; up to `RECLIP_ROUNDS` times, each reaching one facet
/// further.
///
/// The stats' `refined_vertices` is 0 (nothing is refined); `clipped_facets` counts the
/// (sample, facet) pairs clipped, `reclipped_facets` the facets clipped again.
pub fn restricted_voronoi(
    surface: &MeshSurface,
    sheets: &Sheets,
    positions: &[DVec3],
    normals: &[DVec3],
    tolerance: f64,
) -> Option<(Vec<VotedTriangle>, RestrictedDelaunayStats)> {
    let split = sheets.split(surface.mesh());
    let mesh = split.as_ref().unwrap_or(surface.mesh());
    let facet_normals: Vec<DVec3> = (0..mesh.triangles.len())
        .into_par_iter()
        .map(|f| surface.face_normal(f as u32))
        .collect();
    let across = FacetNeighbours::new(mesh);
    let tree = StaticTree::new(positions);
    let n = positions.len();
    let cells = Cells {
        surface,
        mesh,
        across: &across,
        tree: &tree,
        positions,
        normals,
        facet_normals: &facet_normals,
        tolerance,
    };
    // Per sample, in parallel: its cell grown over the mesh.
    let grown: Vec<Cell> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .flat_map_iter(|c| {
            let mut scratch = Scratch::default();
            (c * CHUNK..((c + 1) * CHUNK).min(n))
                .map(|i| cells.cell(i as u32, &mut scratch))
                .collect::<Vec<_>>()
        })
        .collect();
    let mut clipped_facets = 0;
    let mut triangles = Vec::new();
    let mut pieces = Vec::new();
    for c in grown {
        clipped_facets += c.clipped;
        triangles.extend(c.triangles);
        pieces.extend(c.pieces);
    }
    // The facets left uncovered clipped again, among the samples that reach them.
    let mut reclipped_facets = 0;
    for _ in 0..RECLIP_ROUNDS {
        pieces.par_sort_unstable_by(|a, b| (a.0, a.1).cmp(&(b.0, b.1)));
        let mut covered = vec![0.0; mesh.triangles.len()];
        for &(f, _, a, _) in &pieces {
            covered[f as usize] += a;
        }
        let uncovered: Vec<u32> = (0..mesh.triangles.len() as u32)
            .filter(|&f| {
                let area = mesh.face_area(f as usize);
                area - covered[f as usize] > UNCOVERED_RELATIVE * area
            })
            .collect();
        if uncovered.is_empty() {
            break;
        }
        reclipped_facets += uncovered.len();
        let again: Vec<Cell> = uncovered
            .par_iter()
            .map_init(Scratch::default, |s, &f| cells.facet_again(f, &pieces, s))
            .collect();
        let mut redone = vec![false; mesh.triangles.len()];
        for &f in &uncovered {
            redone[f as usize] = true;
        }
        triangles.retain(|t| !redone[t.0 as usize]);
        pieces.retain(|p| !redone[p.0 as usize]);
        for c in again {
            clipped_facets += c.clipped;
            triangles.extend(c.triangles);
            pieces.extend(c.pieces);
        }
    }
    let empty_cells = {
        let mut in_one = vec![false; n];
        for (_, t) in &triangles {
            for &v in t {
                in_one[v as usize] = true;
            }
        }
        in_one.iter().filter(|x| !**x).count()
    };
    if triangles.is_empty() {
        return None;
    }
    // Per triple, the orientation most cells give and how many gave it.
    let tally = tally_triples(triangles.into_iter().map(|(_, t)| t));
    let stats = RestrictedDelaunayStats {
        refined_vertices: 0,
        clipped_facets,
        reclipped_facets,
        triangles: tally.len(),
        empty_cells,
        topological_ball: Default::default(),
    };
    Some((voted(tally, true), stats))
}

/// The facets across each facet edge: facets that share the edge's two vertices.
struct FacetNeighbours {
    /// (lower vertex, higher vertex, facet), sorted.
    sides: Vec<(u32, u32, u32)>,
}

impl FacetNeighbours {
    fn new(mesh: &TriMesh) -> Self {
        let mut sides: Vec<(u32, u32, u32)> = mesh
            .triangles
            .iter()
            .enumerate()
            .flat_map(|(f, t)| {
                (0..3).map(move |k| {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    (a.min(b), a.max(b), f as u32)
                })
            })
            .collect();
        sides.par_sort_unstable();
        FacetNeighbours { sides }
    }

    /// The facets other than `f` on the edge `a`–`b`.
    fn across(&self, a: u32, b: u32, f: u32) -> impl Iterator<Item = u32> + '_ {
        let key = (a.min(b), a.max(b));
        let start = self.sides.partition_point(|s| (s.0, s.1) < key);
        self.sides[start..]
            .iter()
            .take_while(move |s| (s.0, s.1) == key)
            .map(|s| s.2)
            .filter(move |&g| g != f)
    }
}

/// A thread's buffers for [`Cells::cell`].
#[derive(Default)]
struct Scratch {
    neighbours: Vec<(u32, f64)>,
    polygon: Vec<(DVec3, u32)>,
    clipped: Vec<(DVec3, u32)>,
    visited: FxHashSet<u32>,
    stack: Vec<u32>,
}

/// What every cell reads.
struct Cells<'a> {
    surface: &'a MeshSurface,
    /// The mesh the cells grow over (the input, its closed sheets split apart).
    mesh: &'a TriMesh,
    across: &'a FacetNeighbours,
    tree: &'a StaticTree,
    positions: &'a [DVec3],
    /// The samples' unit normals (the surface's at each).
    normals: &'a [DVec3],
    /// The facets' unit normals.
    facet_normals: &'a [DVec3],
    tolerance: f64,
}

/// A sample takes part in the diagram on a facet when its normal is within 120° of the facet's
/// (cos 120° = -0.5): the samples on the other side of a part thinner than the spacing (normals
/// opposite) neither cut a facet's cells nor grow onto it, so each side's cells are its own.
/// A crease sample's normal (the surface's, averaged across the crease) is within that of both
/// sides of any crease of more than 60°; a right-angled crease's samples on either side (90°)
/// meet across it.
const SAME_SIDE_COS: f64 = -0.5;

impl Cells<'_> {
    /// Whether sample `j` takes part in the diagram on facet `f` (`SAME_SIDE_COS`).
    fn on_side(&self, j: u32, f: u32) -> bool {
        self.normals[j as usize].dot(self.facet_normals[f as usize]) > SAME_SIDE_COS
    }

    /// Sample `i`'s cell grown over the mesh from the facet it lies on.
    fn cell(&self, i: u32, s: &mut Scratch) -> Cell {
        let p = self.positions[i as usize];
        let mut cell = Cell::default();
        let Some(anchor) = self
            .surface
            .closest_point_hinted(p, self.tolerance, f64::MAX)
        else {
            return cell;
        };
        s.neighbours.clear();
        self.tree.nearest_n(p, FIRST_NEIGHBOURS, &mut s.neighbours);
        s.neighbours.retain(|&(j, _)| j != i);
        // The squared radius within which `s.neighbours` holds every sample (0: only the
        // nearest ones asked for first, unless that was all of them).
        let mut fetched = if self.positions.len() <= FIRST_NEIGHBOURS {
            f64::INFINITY
        } else {
            0.0
        };
        s.visited.clear();
        s.stack.clear();
        s.stack.push(anchor.face);
        s.visited.insert(anchor.face);
        while let Some(f) = s.stack.pop() {
            if !self.on_side(i, f) {
                continue;
            }
            cell.clipped += 1;
            let neighbours = std::mem::take(&mut s.neighbours);
            let complete = self.clip_facet(i, f, &neighbours, s);
            s.neighbours = neighbours;
            // The samples ran out before the security radius held: all samples within twice
            // the facet's farthest corner (no piece of it is farther), unless the list holds
            // them already, and the facet clipped again from the start by them.
            let t = self.mesh.triangles[f as usize];
            let reach = 4.0
                * (0..3)
                    .map(|k| self.mesh.positions[t[k] as usize].distance_squared(p))
                    .fold(0.0, f64::max)
                * (1.0 + 1e-9);
            if !complete && reach > fetched {
                fetched = reach;
                self.tree.within(p, reach, &mut s.neighbours);
                s.neighbours.retain(|&(j, _)| j != i);
                let neighbours = std::mem::take(&mut s.neighbours);
                self.clip_facet(i, f, &neighbours, s);
                s.neighbours = neighbours;
            }
            if self.emit(i, f, s, &mut cell) {
                for k in 0..s.polygon.len() {
                    let label = s.polygon[k].1;
                    if label >= FACET_EDGE {
                        let e = (label - FACET_EDGE) as usize;
                        let (a, b) = (t[e], t[(e + 1) % 3]);
                        for g in self.across.across(a, b, f) {
                            if s.visited.insert(g) {
                                s.stack.push(g);
                            }
                        }
                    }
                }
            }
        }
        cell
    }

    /// Facet `f`'s cells again, among the samples that reach it over the mesh: those whose
    /// cells have a piece on it, or a piece on a facet across one of its edges that reaches that
    /// edge (`pieces`: by facet, then sample), and that take part on it.
    fn facet_again(&self, f: u32, pieces: &[(u32, u32, f64, u8)], s: &mut Scratch) -> Cell {
        let on = |g: u32| {
            let start = pieces.partition_point(|p| p.0 < g);
            pieces[start..].iter().take_while(move |p| p.0 == g)
        };
        let t = self.mesh.triangles[f as usize];
        let mut reach: Vec<u32> = on(f).map(|p| p.1).collect();
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            for g in self.across.across(a, b, f) {
                // The edge a-b as an edge of g.
                let u = self.mesh.triangles[g as usize];
                let Some(e) = (0..3).find(|&e| {
                    let (c, d) = (u[e], u[(e + 1) % 3]);
                    (c, d) == (a, b) || (c, d) == (b, a)
                }) else {
                    continue;
                };
                reach.extend(on(g).filter(|p| p.3 & (1 << e) != 0).map(|p| p.1));
            }
        }
        reach.retain(|&j| self.on_side(j, f));
        reach.sort_unstable();
        reach.dedup();
        let mut cell = Cell::default();
        let mut others = Vec::with_capacity(reach.len());
        for &i in &reach {
            let p = self.positions[i as usize];
            others.clear();
            others.extend(
                reach
                    .iter()
                    .filter(|&&j| j != i)
                    .map(|&j| (j, self.positions[j as usize].distance_squared(p))),
            );
            others.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
            cell.clipped += 1;
            self.clip_facet(i, f, &others, s);
            self.emit(i, f, s, &mut cell);
        }
        cell
    }

    /// Facet `f` clipped to sample `i`'s cell among `others` (nearest first: sample and squared
    /// distance to sample `i`), into `s.polygon` (empty when nothing is left), until the next
    /// sample is farther than twice the farthest corner left. False when `others` ran out before
    /// that.
    fn clip_facet(&self, i: u32, f: u32, others: &[(u32, f64)], s: &mut Scratch) -> bool {
        let p = self.positions[i as usize];
        let t = self.mesh.triangles[f as usize];
        s.polygon.clear();
        s.polygon
            .extend((0..3).map(|k| (self.mesh.positions[t[k] as usize], FACET_EDGE + k as u32)));
        for &(j, d2) in others {
            let r2 = s
                .polygon
                .iter()
                .map(|v| v.0.distance_squared(p))
                .fold(0.0, f64::max);
            if d2 > 4.0 * r2 {
                return true;
            }
            if !self.on_side(j, f) {
                continue;
            }
            if d2 == 0.0 {
                // The same position (the caller's samples are distinct: no cell then).
                s.polygon.clear();
                return true;
            }
            clip(&s.polygon, p, self.positions[j as usize], j, &mut s.clipped);
            std::mem::swap(&mut s.polygon, &mut s.clipped);
            if s.polygon.len() < 3 {
                s.polygon.clear();
                return true;
            }
        }
        false
    }

    /// The piece of sample `i`'s cell on facet `f` in `s.polygon` into `cell`: its area and the
    /// dual triangles at its corners where two bisectors meet. False when there is no piece.
    fn emit(&self, i: u32, f: u32, s: &Scratch, cell: &mut Cell) -> bool {
        let polygon = &s.polygon;
        let m = polygon.len();
        if m < 3 {
            return false;
        }
        let o = polygon[0].0;
        let twice_area = (1..m - 1)
            .map(|k| (polygon[k].0 - o).cross(polygon[k + 1].0 - o))
            .fold(DVec3::ZERO, |a, b| a + b)
            .length();
        let edges = polygon
            .iter()
            .filter(|v| v.1 >= FACET_EDGE)
            .fold(0u8, |m, v| m | 1 << (v.1 - FACET_EDGE));
        cell.pieces.push((f, i, 0.5 * twice_area, edges));
        for k in 0..m {
            let incoming = polygon[(k + m - 1) % m].1;
            let outgoing = polygon[k].1;
            if incoming < FACET_EDGE && outgoing < FACET_EDGE && incoming != outgoing {
                cell.triangles.push((f, [i, incoming, outgoing]));
            }
        }
        true
    }
}

/// `polygon` (corners with the label of the edge from each to the next) clipped to the half
/// space nearer to `p` than to `q`; the new edge along the bisector is labelled `j`. Written to
/// `out` (Sutherland–Hodgman).
fn clip(polygon: &[(DVec3, u32)], p: DVec3, q: DVec3, j: u32, out: &mut Vec<(DVec3, u32)>) {
    out.clear();
    let normal = q - p;
    let offset = normal.dot((p + q) * 0.5);
    let m = polygon.len();
    for k in 0..m {
        let (x, label) = polygon[k];
        let y = polygon[(k + 1) % m].0;
        let (dx, dy) = (normal.dot(x) - offset, normal.dot(y) - offset);
        if dx <= 0.0 {
            out.push((x, label));
            if dy > 0.0 {
                out.push((x + (y - x) * (dx / (dx - dy)), j));
            }
        } else if dy <= 0.0 {
            out.push((x + (y - x) * (dx / (dx - dy)), label));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes;
    use crate::sampling::sizing::Uniform;
    use crate::triangulate::restricted_delaunay::{restricted_delaunay, RestrictedDelaunayParams};
    use rand::{RngExt, SeedableRng};
    use std::collections::BTreeSet;

    fn clipped(mesh: &TriMesh, positions: &[DVec3]) -> Vec<[u32; 3]> {
        let surface = MeshSurface::new(mesh).unwrap();
        let sheets = Sheets::new(mesh);
        let normals: Vec<DVec3> = positions
            .iter()
            .map(|&p| surface.smooth_normal(&surface.closest_point(p).unwrap()))
            .collect();
        restricted_voronoi(&surface, &sheets, positions, &normals, 1e-9)
            .map(|(v, _)| v.into_iter().map(|t| t.corners).collect())
            .unwrap_or_default()
    }

    /// Corners rotated to put the smallest first (orientation kept).
    fn rotated(t: [u32; 3]) -> [u32; 3] {
        let k = (0..3).min_by_key(|&k| t[k]).unwrap();
        [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
    }

    /// The Delaunay triangles (spade's) of `positions` (on z = 0) whose circumcentres lie in the
    /// square [0, 10]², each rotated to put the smallest first.
    fn delaunay_centred_in_the_square(positions: &[DVec3]) -> BTreeSet<[u32; 3]> {
        use spade::{DelaunayTriangulation, Point2, Triangulation};
        let mut dt = DelaunayTriangulation::<Point2<f64>>::new();
        for p in positions {
            dt.insert(Point2::new(p.x, p.y)).unwrap();
        }
        let mut expected = BTreeSet::new();
        for face in dt.inner_faces() {
            let v = face.vertices().map(|v| v.fix().index() as u32);
            let [a, b, c] = v.map(|i| positions[i as usize]);
            // The circumcentre of a, b, c.
            let (ab, ac) = (b - a, c - a);
            let d = 2.0 * (ab.x * ac.y - ab.y * ac.x);
            let ux = (ac.y * ab.length_squared() - ab.y * ac.length_squared()) / d;
            let uy = (ab.x * ac.length_squared() - ac.x * ab.length_squared()) / d;
            let centre = a + DVec3::new(ux, uy, 0.0);
            let inside = |x: f64| x > 1e-6 && x < 10.0 - 1e-6;
            let near_side = |x: f64| (x.abs() < 1e-6) || ((x - 10.0).abs() < 1e-6);
            assert!(
                !near_side(centre.x) && !near_side(centre.y),
                "a degenerate case"
            );
            if inside(centre.x) && inside(centre.y) {
                expected.insert(rotated(v));
            }
        }
        expected
    }

    /// On a plane the cells are the plane's Voronoi cells cut to the square: their duals are the
    /// Delaunay triangles (spade's) whose circumcentres lie in the square, counter-clockwise as
    /// the square's facets. Samples spread evenly, and a dense cluster with a few samples far
    /// from it (whose cells reach over many facets, past the first nearest samples asked for).
    #[test]
    fn on_a_plane_the_duals_are_the_delaunay_triangles_centred_on_it() {
        let mesh = test_meshes::grid(8, |i, j| DVec3::new(i as f64 * 1.25, j as f64 * 1.25, 0.0));
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let spread: Vec<DVec3> = (0..150)
            .map(|_| DVec3::new(rng.random_range(0.5..9.5), rng.random_range(0.5..9.5), 0.0))
            .collect();
        let mut clustered: Vec<DVec3> = (0..80)
            .map(|_| DVec3::new(rng.random_range(0.3..2.5), rng.random_range(0.3..2.5), 0.0))
            .collect();
        clustered.extend([
            DVec3::new(8.1, 7.9, 0.0),
            DVec3::new(8.6, 2.2, 0.0),
            DVec3::new(2.3, 8.7, 0.0),
            DVec3::new(5.6, 5.2, 0.0),
        ]);
        for (what, positions, least) in [("spread", spread, 200), ("clustered", clustered, 100)] {
            let expected = delaunay_centred_in_the_square(&positions);
            let got: BTreeSet<[u32; 3]> = clipped(&mesh, &positions)
                .into_iter()
                .map(rotated)
                .collect();
            assert!(expected.len() > least, "{what}: {}", expected.len());
            assert_eq!(got, expected, "{what}");
        }
    }

    /// Samples spread over a sphere: the duals close into a sphere (every edge on two faces, in
    /// opposite directions; Euler characteristic 2 over all samples), facing out, and agree
    /// with the cells grown over the refined input (the oracle) but for a few near ties.
    #[test]
    fn on_a_sphere_the_duals_close_and_agree_with_the_refined_cells() {
        let mesh = test_meshes::uv_sphere(10.0, 48, 96);
        let surface = MeshSurface::new(&mesh).unwrap();
        let positions: Vec<DVec3> = test_meshes::fibonacci_sphere(400)
            .into_iter()
            .map(|u| surface.closest_point(u * 10.0).unwrap().position)
            .collect();
        let got = clipped(&mesh, &positions);
        let mut directed = BTreeSet::new();
        for t in &got {
            for k in 0..3 {
                assert!(
                    directed.insert((t[k], t[(k + 1) % 3])),
                    "an edge twice one way"
                );
            }
            let [a, b, c] = t.map(|v| positions[v as usize]);
            assert!(
                (b - a).cross(c - a).dot(a + b + c) > 0.0,
                "a face facing in"
            );
        }
        for &(a, b) in &directed {
            assert!(directed.contains(&(b, a)), "an edge on one face");
        }
        let (v, e, f) = (positions.len(), directed.len() / 2, got.len());
        assert_eq!(v as i64 - e as i64 + f as i64, 2);
        let params = RestrictedDelaunayParams {
            resolution: 0.1,
            max_added_per_sample: 10_000,
            // The oracle's cells as grown, no sample inserted.
            topological_ball: crate::triangulate::topological_ball::TopologicalBallParams {
                enabled: false,
                ..Default::default()
            },
            ..Default::default()
        };
        let spacing = (4.0 * std::f64::consts::PI * 100.0 / 400.0).sqrt();
        let (oracle, _, _) = restricted_delaunay(
            &surface,
            &Sheets::new(&mesh),
            &positions,
            spacing,
            &Uniform,
            &params,
        )
        .unwrap();
        let oracle: BTreeSet<[u32; 3]> = oracle.iter().map(|t| rotated(t.corners)).collect();
        let got: BTreeSet<[u32; 3]> = got.into_iter().map(rotated).collect();
        let shared = got.intersection(&oracle).count();
        assert!(
            shared as f64 >= 0.97 * oracle.len() as f64,
            "{shared} of {} oracle triangles",
            oracle.len()
        );
    }

    /// The same triangles on one thread and on several.
    #[test]
    fn the_same_duals_on_any_number_of_threads() {
        let mesh = test_meshes::uv_sphere(10.0, 24, 48);
        let surface = MeshSurface::new(&mesh).unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let positions: Vec<DVec3> = (0..2000)
            .map(|_| {
                let u = DVec3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                surface.closest_point(u * 10.0).unwrap().position
            })
            .collect();
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| clipped(&mesh, &positions))
        };
        let one = run(1);
        assert!(one.len() > 3000);
        assert_eq!(one, run(2));
        assert_eq!(one, run(3));
    }
}
