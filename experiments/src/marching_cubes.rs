//! Marching cubes on a sparse grid: the zero set of an implicit function that is defined only
//! near a surface (RIMLS is undefined outside the support of its points), triangulated densely,
//! as the paper does before measuring reconstructions with Metro (Sec. 7.2).
//!
//! The grid is the lattice `origin + cell · (i, j, k)`. Only cells near the surface are visited:
//! the cells holding a seed point (and those within `dilation` cells of one), then, repeatedly,
//! the neighbours across every cube face the surface crosses, until the surface closes or leaves
//! the region where the function is defined. A cell is triangulated when f is defined at all 8
//! of its corners; cells with an undefined corner are skipped (the surface has a hole there).
//!
//! The case table is built at first use from the cube's faces instead of being written out: on
//! each face, the surface's crossings of the face's edges are joined in pairs into segments, and
//! the segments are chained into the cycles that become the polygons of the cell. A face with
//! four crossings (positive corners on one diagonal, negative ones on the other) separates the
//! positive corners: the negative (inside) ones stay joined across the face. The choice depends
//! on the face's four signs only, so the two cells sharing a face agree on it and the output has
//! no cracks: it is an edge- and vertex-manifold, consistently oriented surface (closed wherever
//! f is defined), with its triangles' normals towards positive f (outward for a signed distance
//! that is positive outside). Polygons (3 to 7 vertices) are triangulated as fans from a vertex
//! chosen so that no diagonal lies in a cube face (where the neighbouring cell could draw the
//! same diagonal: two sheets touching along it), or, when no vertex qualifies (a polygon through
//! both crossing pairs of an ambiguous face), around an extra vertex at their centroid. A corner
//! with f = 0 counts as positive.
//!
//! # References
//! - W. E. Lorensen, H. E. Cline. *Marching Cubes: A High Resolution 3D Surface Construction
//!   Algorithm.* SIGGRAPH 1987, doi:10.1145/37401.37422.
//! - G. M. Nielson, B. Hamann. *The Asymptotic Decider: Resolving the Ambiguity in Marching
//!   Cubes.* IEEE Visualization 1991, doi:10.1109/VISUAL.1991.175782: why the ambiguous faces
//!   need one consistent rule (here a fixed one rather than their decider).
//! - A. C. Öztireli, M. Alexa, M. Gross. *Spectral Sampling of Manifolds.* SIGGRAPH Asia 2010,
//!   Sec. 7.2: "after densely triangulating the implicit function we use for reconstructions".
//!
//! # Accuracy
//! Vertices lie on the cube edges where the linear interpolation of f vanishes: for a smooth
//! signed distance the error is O(cell²) (curvature times cell², about a tenth of the cell on a
//! sphere of radius 2 cells, a few thousandths of it at 20 cells; the tests measure it).
//!
//! # Runtime
//! One evaluation of f per corner of a visited cell, in parallel (rayon), in batches: one batch
//! for the seeded cells, then one per round of growth. Visited cells are about the cells the
//! surface crosses plus a layer around them.

use std::sync::OnceLock;

use glam::DVec3;
use rayon::prelude::*;
use rustc_hash::{FxHashMap, FxHashSet};

use spectral_remesh::internal::Rimls;
use spectral_remesh::{Error, Result, TriMesh};

/// An implicit function f: R³ → R whose zero set is a surface, defined (`Some`) near it and
/// possibly undefined (`None`) elsewhere. Positive on the outside by this crate's convention.
pub trait ImplicitFunction: Sync {
    /// f at `x`, or `None` where f is undefined.
    fn value(&self, x: DVec3) -> Option<f64>;

    /// f at every point of `xs` (result `i` for `xs[i]`), in parallel. Implementations may
    /// override it to reuse scratch space between evaluations.
    fn values(&self, xs: &[DVec3]) -> Vec<Option<f64>> {
        xs.par_iter().map(|&x| self.value(x)).collect()
    }
}

impl<F: Fn(DVec3) -> Option<f64> + Sync> ImplicitFunction for F {
    fn value(&self, x: DVec3) -> Option<f64> {
        self(x)
    }
}

impl ImplicitFunction for Rimls {
    /// f of [`Rimls::value_and_gradient`]; `None` outside the support.
    fn value(&self, x: DVec3) -> Option<f64> {
        self.value_and_gradient(x).map(|(f, _)| f)
    }

    /// [`Rimls::value_all`]: in parallel, reusing each thread's neighbour buffer.
    fn values(&self, xs: &[DVec3]) -> Vec<Option<f64>> {
        self.value_all(xs)
    }
}

/// Parameters of [`marching_cubes`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MarchingCubesParams {
    /// Edge length of a grid cell (> 0, finite; the units of f's domain: bbox-100 units in this
    /// crate). Default 0.5; reconstructions use about σ_p/2.
    pub cell: f64,
    /// A lattice point (finite): the grid's corners are `origin + cell · (i, j, k)`. Two
    /// surfaces extracted on the same lattice share its discretization. Default the origin.
    pub origin: DVec3,
    /// Seeded cells: the cell of each seed and every cell within this many cells of it along
    /// each axis (a (2d+1)³ block). Default 1.
    pub dilation: usize,
    /// Most cells visited (seeded and grown) before the extraction stops with
    /// `complete = false`. Default 50,000,000.
    pub max_cells: usize,
}

impl Default for MarchingCubesParams {
    fn default() -> Self {
        MarchingCubesParams {
            cell: 0.5,
            origin: DVec3::ZERO,
            dilation: 1,
            max_cells: 50_000_000,
        }
    }
}

impl MarchingCubesParams {
    /// The defaults with this cell size.
    pub fn with_cell(cell: f64) -> Self {
        MarchingCubesParams {
            cell,
            ..Self::default()
        }
    }

    /// Checks every field's range.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first field out of range.
    pub fn validate(&self) -> Result<()> {
        if !(self.cell.is_finite() && self.cell > 0.0) {
            return Err(Error::InvalidParameter {
                name: "cell",
                message: format!("must be a positive finite number, got {}", self.cell),
            });
        }
        if !self.origin.is_finite() {
            return Err(Error::InvalidParameter {
                name: "origin",
                message: format!("must be finite, got {}", self.origin),
            });
        }
        if self.dilation > 64 {
            return Err(Error::InvalidParameter {
                name: "dilation",
                message: format!("at most 64 cells, got {}", self.dilation),
            });
        }
        Ok(())
    }
}

/// The output of [`marching_cubes`].
#[derive(Debug, Clone)]
pub struct MarchingCubesResult {
    /// The triangulated zero set, in the units of f's domain, triangles oriented with their
    /// normals towards positive f.
    pub mesh: TriMesh,
    /// Evaluations of f (one per distinct corner of a visited cell).
    pub evaluations: usize,
    /// Corners where f was undefined.
    pub undefined_corners: usize,
    /// Cells visited, seeded and grown.
    pub cells_visited: usize,
    /// Of those, the cells reached by following the surface beyond the seeded ones.
    pub cells_grown: usize,
    /// Cells with an undefined corner whose defined corners have both signs: the surface
    /// probably passes there but cannot be triangulated (a hole in the output).
    pub cells_skipped: usize,
    /// False when `max_cells` stopped the growth (the surface may be cut off).
    pub complete: bool,
}

// ---------------------------------------------------------------------------------------------
// Lattice keys
// ---------------------------------------------------------------------------------------------

/// Bits per axis of a corner key.
const KEY_BITS: u32 = 20;
/// Offset that makes lattice coordinates non-negative in a key.
const KEY_OFFSET: i64 = 1 << (KEY_BITS - 1);
/// Largest |coordinate| a key holds (one less, so that a cell's far corners fit too).
const KEY_LIMIT: i64 = KEY_OFFSET - 2;
const KEY_MASK: u64 = (1 << KEY_BITS) - 1;

/// The key of lattice point (i, j, k); the caller keeps |i|, |j|, |k| <= KEY_LIMIT + 1.
#[inline]
fn key(c: [i64; 3]) -> u64 {
    ((c[0] + KEY_OFFSET) as u64) << (2 * KEY_BITS)
        | ((c[1] + KEY_OFFSET) as u64) << KEY_BITS
        | (c[2] + KEY_OFFSET) as u64
}

/// Lattice coordinates of a key.
#[inline]
fn unkey(k: u64) -> [i64; 3] {
    [
        ((k >> (2 * KEY_BITS)) & KEY_MASK) as i64 - KEY_OFFSET,
        ((k >> KEY_BITS) & KEY_MASK) as i64 - KEY_OFFSET,
        (k & KEY_MASK) as i64 - KEY_OFFSET,
    ]
}

/// What adding one along `axis` adds to a key.
#[inline]
fn axis_step(axis: usize) -> u64 {
    1 << (KEY_BITS * (2 - axis as u32))
}

/// Offset of cube corner `c` (bit 0: x, bit 1: y, bit 2: z) as a key increment.
#[inline]
fn corner_step(c: usize) -> u64 {
    (0..3).filter(|&a| c >> a & 1 == 1).map(axis_step).sum()
}

// ---------------------------------------------------------------------------------------------
// The case table
// ---------------------------------------------------------------------------------------------

/// Cube edge `e` (0..12) runs along axis `e / 4` from corner [`EDGE_BASE`]`[e]`.
const fn edge_bases() -> [usize; 12] {
    let mut out = [0; 12];
    let mut axis = 0;
    while axis < 3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let mut k = 0;
        while k < 4 {
            out[axis * 4 + k] = ((k & 1) << u) | ((k >> 1 & 1) << v);
            k += 1;
        }
        axis += 1;
    }
    out
}
const EDGE_BASE: [usize; 12] = edge_bases();

/// The cube edge joining corners `a` and `b` (which differ in one bit).
fn edge_of(a: usize, b: usize) -> usize {
    let axis = (a ^ b).trailing_zeros() as usize;
    let base = a & b;
    (0..4)
        .map(|k| axis * 4 + k)
        .find(|&e| EDGE_BASE[e] == base)
        .unwrap_or(0)
}

/// The six faces' corners in counter-clockwise order seen from outside the cube: face
/// `2 · axis + side` holds the corners whose bit `axis` is `side`.
const fn face_rings() -> [[usize; 4]; 6] {
    let mut out = [[0; 4]; 6];
    let mut axis = 0;
    while axis < 3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let mut side = 0;
        while side < 2 {
            // (u, v) = (0,0), (1,0), (1,1), (0,1) turns counter-clockwise about +axis; the face
            // at side 0 looks along -axis, so its ring is reversed.
            let steps = [(0, 0), (1, 0), (1, 1), (0, 1)];
            let mut k = 0;
            while k < 4 {
                let (du, dv) = steps[if side == 1 { k } else { 3 - k }];
                out[axis * 2 + side][k] = side << axis | du << u | dv << v;
                k += 1;
            }
            side += 1;
        }
        axis += 1;
    }
    out
}
const FACES: [[usize; 4]; 6] = face_rings();

/// The six faces' corner rings ([`FACES`]).
fn faces() -> [[usize; 4]; 6] {
    FACES
}

/// One polygon of a sign case: a cycle of cube edges in the order that makes its normal point
/// to the positive side, and how to triangulate it.
#[derive(Debug, Clone, PartialEq)]
struct Polygon {
    /// Cube edges (0..12).
    edges: Vec<u8>,
    /// Triangulate as a fan from `edges[0]` (false), or around an extra vertex at the centroid
    /// (true) when every fan would put a diagonal into a cube face.
    center: bool,
}

/// Polygons of every sign case (`TABLE[mask]`, bit c of `mask`: corner c positive).
fn table() -> &'static [Vec<Polygon>] {
    static TABLE: OnceLock<Vec<Vec<Polygon>>> = OnceLock::new();
    TABLE.get_or_init(|| (0..256).map(build_case).collect())
}

/// Whether cube edges `a` and `b` lie on a common face.
fn share_face(a: usize, b: usize) -> bool {
    faces().iter().any(|ring| {
        let on = |e: usize| (0..4).any(|k| edge_of(ring[k], ring[(k + 1) % 4]) == e);
        on(a) && on(b)
    })
}

/// The polygons of one sign case (see the module documentation).
fn build_case(mask: usize) -> Vec<Polygon> {
    let positive = |c: usize| mask >> c & 1 == 1;
    // next[e]: the edge the segment leaving crossing e goes to.
    let mut next = [u8::MAX; 12];
    for ring in faces() {
        // Crossings in counter-clockwise order: (edge, rising = negative to positive).
        let crossings: Vec<(usize, bool)> = (0..4)
            .filter_map(|k| {
                let (a, b) = (ring[k], ring[(k + 1) % 4]);
                (positive(a) != positive(b)).then(|| (edge_of(a, b), positive(b)))
            })
            .collect();
        let n = crossings.len();
        for (k, &(edge, rising)) in crossings.iter().enumerate() {
            if rising {
                continue;
            }
            // A falling crossing pairs with the rising one just before it: the positive corners
            // between them are cut off (positive corners are separated on ambiguous faces).
            let previous = crossings[(k + n - 1) % n];
            debug_assert!(previous.1);
            next[edge] = previous.0 as u8;
        }
    }
    let mut done = [false; 12];
    let mut polygons = Vec::new();
    for start in 0..12 {
        if next[start] == u8::MAX || done[start] {
            continue;
        }
        let mut cycle = Vec::new();
        let mut e = start;
        while !done[e] {
            done[e] = true;
            cycle.push(e as u8);
            e = next[e] as usize;
        }
        // A fan from vertex s draws diagonals to every vertex but its two neighbours. A
        // diagonal between two edges of one cube face would lie in that face, where the
        // neighbouring cell's polygon may draw the same one (two surfaces touching): choose a
        // start without such diagonals, or triangulate around the centroid.
        let n = cycle.len();
        let fan_ok = |s: usize| {
            (2..n - 1).all(|j| !share_face(cycle[s] as usize, cycle[(s + j) % n] as usize))
        };
        match (0..n).find(|&s| fan_ok(s)) {
            Some(s) => {
                cycle.rotate_left(s);
                polygons.push(Polygon {
                    edges: cycle,
                    center: false,
                });
            }
            None => polygons.push(Polygon {
                edges: cycle,
                center: true,
            }),
        }
    }
    polygons
}

// ---------------------------------------------------------------------------------------------
// Extraction
// ---------------------------------------------------------------------------------------------

/// Marks a vertex key as an extra (centroid) vertex of a [`CellOutput`], numbered within it.
const EXTRA: u64 = 1 << 63;

/// What one batch of cells contributes: triangles as triples of vertex keys (an edge key, or
/// `EXTRA | i` for `extras[i]`), the extra vertices, the neighbours the surface leads to, and how
/// many cells were skipped for an undefined corner while the surface crossed them.
#[derive(Default)]
struct CellOutput {
    triangles: Vec<[u64; 3]>,
    extras: Vec<DVec3>,
    neighbours: Vec<u64>,
    skipped: usize,
}

/// The key of the lattice edge from corner key `corner` along `axis`.
#[inline]
fn edge_key(corner: u64, axis: usize) -> u64 {
    corner << 2 | axis as u64
}

/// The position of the vertex on the lattice edge `edge` (a key from [`edge_key`]) where the
/// linear interpolation between its end values `fa` and `fb` (of different signs) vanishes.
#[inline]
fn edge_vertex(edge: u64, fa: f64, fb: f64, params: &MarchingCubesParams) -> DVec3 {
    let (corner, axis) = (edge >> 2, (edge & 3) as usize);
    let t = (fa / (fa - fb)).clamp(0.0, 1.0);
    let [i, j, l] = unkey(corner);
    let mut p = DVec3::new(i as f64, j as f64, l as f64);
    p[axis] += t;
    params.origin + params.cell * p
}

/// Triangulates cell `cell` from the corner values in `values` (NaN: undefined) and lists the
/// neighbours across the faces its surface crosses.
fn polygonize(
    cell: u64,
    values: &FxHashMap<u64, f64>,
    params: &MarchingCubesParams,
    out: &mut CellOutput,
) {
    let mut f = [0.0; 8];
    for (c, v) in f.iter_mut().enumerate() {
        *v = values
            .get(&(cell + corner_step(c)))
            .copied()
            .unwrap_or(f64::NAN);
    }
    if f.iter().any(|v| v.is_nan()) {
        let defined = f.iter().filter(|v| !v.is_nan());
        let (mut pos, mut neg) = (false, false);
        for &v in defined {
            pos |= v >= 0.0;
            neg |= v < 0.0;
        }
        if pos && neg {
            out.skipped += 1;
        }
        return;
    }
    let mask = (0..8).fold(0usize, |m, c| m | usize::from(f[c] >= 0.0) << c);
    if mask == 0 || mask == 255 {
        return;
    }
    let mut keys: Vec<u64> = Vec::with_capacity(12);
    for polygon in &table()[mask] {
        keys.clear();
        keys.extend(polygon.edges.iter().map(|&e| {
            let e = e as usize;
            edge_key(cell + corner_step(EDGE_BASE[e]), e / 4)
        }));
        if polygon.center {
            let centroid = polygon
                .edges
                .iter()
                .zip(&keys)
                .map(|(&e, &k)| {
                    let base = EDGE_BASE[e as usize];
                    edge_vertex(k, f[base], f[base | 1 << (e / 4)], params)
                })
                .sum::<DVec3>()
                / keys.len() as f64;
            let c = EXTRA | out.extras.len() as u64;
            out.extras.push(centroid);
            for k in 0..keys.len() {
                out.triangles.push([c, keys[k], keys[(k + 1) % keys.len()]]);
            }
        } else {
            for k in 1..keys.len() - 1 {
                out.triangles.push([keys[0], keys[k], keys[k + 1]]);
            }
        }
    }
    for (face, ring) in faces().iter().enumerate() {
        let signs = ring.map(|c| f[c] >= 0.0);
        if signs.iter().any(|&s| s != signs[0]) {
            let (axis, side) = (face / 2, face % 2);
            out.neighbours.push(if side == 1 {
                cell + axis_step(axis)
            } else {
                cell - axis_step(axis)
            });
        }
    }
}

/// Triangulates the zero set of `f` near `seeds` (see the module documentation): cells of the
/// lattice `params.origin + params.cell · (i, j, k)` are visited from the seeds' cells and grown
/// along the surface; corners are evaluated in parallel batches. Deterministic: the output does
/// not depend on the number of threads.
///
/// `seeds` are points on or near the surface (the input points of a point set surface); at least
/// one cell of every connected part of the surface should hold one (with `dilation` 1, be within
/// a cell of one).
///
/// # Errors
/// [`Error::InvalidParameter`] when the parameters are out of range
/// ([`MarchingCubesParams::validate`]), a seed is not finite, or a seed or a grown cell lies
/// more than about 500,000 cells from the origin (the lattice keys' range).
pub fn marching_cubes(
    f: &dyn ImplicitFunction,
    seeds: &[DVec3],
    params: &MarchingCubesParams,
) -> Result<MarchingCubesResult> {
    params.validate()?;
    let to_cell = |p: DVec3| -> Option<[i64; 3]> {
        let q = ((p - params.origin) / params.cell).floor();
        let c = [q.x, q.y, q.z];
        c.iter()
            .all(|v| v.abs() < KEY_LIMIT as f64)
            .then(|| c.map(|v| v as i64))
    };
    if let Some(i) = seeds.iter().position(|p| !p.is_finite()) {
        return Err(Error::InvalidParameter {
            name: "seeds",
            message: format!("seed {i} is not finite: {}", seeds[i]),
        });
    }
    let mut seed_cells: Vec<[i64; 3]> = Vec::with_capacity(seeds.len());
    for (i, &p) in seeds.iter().enumerate() {
        match to_cell(p) {
            Some(c) => seed_cells.push(c),
            None => {
                return Err(Error::InvalidParameter {
                    name: "seeds",
                    message: format!(
                        "seed {i} at {p} is more than {KEY_LIMIT} cells of {} from the origin",
                        params.cell
                    ),
                })
            }
        }
    }
    seed_cells.par_sort_unstable();
    seed_cells.dedup();
    let d = params.dilation as i64;
    let limit = KEY_LIMIT - d;
    if let Some(c) = seed_cells
        .iter()
        .find(|c| c.iter().any(|v| v.abs() > limit))
    {
        return Err(Error::InvalidParameter {
            name: "seeds",
            message: format!("a seed's cell {c:?} is too far from the origin for the lattice keys"),
        });
    }
    let mut frontier: Vec<u64> = seed_cells
        .par_iter()
        .flat_map_iter(|c| {
            let c = *c;
            (-d..=d).flat_map(move |x| {
                (-d..=d)
                    .flat_map(move |y| (-d..=d).map(move |z| key([c[0] + x, c[1] + y, c[2] + z])))
            })
        })
        .collect();
    frontier.par_sort_unstable();
    frontier.dedup();

    let mut values: FxHashMap<u64, f64> = FxHashMap::default();
    let mut visited: FxHashSet<u64> = FxHashSet::default();
    let mut triangles: Vec<[u64; 3]> = Vec::new();
    let mut extras: Vec<DVec3> = Vec::new();
    let seeded = frontier.len();
    let (mut skipped, mut undefined, mut complete) = (0usize, 0usize, true);
    while !frontier.is_empty() {
        if visited.len() + frontier.len() > params.max_cells {
            complete = false;
            frontier.truncate(params.max_cells.saturating_sub(visited.len()));
            if frontier.is_empty() {
                break;
            }
        }
        // Corners not evaluated yet.
        let mut corners: Vec<u64> = frontier
            .par_iter()
            .flat_map_iter(|&cell| (0..8).map(move |c| cell + corner_step(c)))
            .filter(|k| !values.contains_key(k))
            .collect();
        corners.par_sort_unstable();
        corners.dedup();
        let points: Vec<DVec3> = corners
            .par_iter()
            .map(|&k| {
                let [i, j, l] = unkey(k);
                params.origin + params.cell * DVec3::new(i as f64, j as f64, l as f64)
            })
            .collect();
        let found = f.values(&points);
        values.reserve(corners.len());
        for (k, v) in corners.iter().zip(found) {
            let v = v.filter(|v| v.is_finite());
            undefined += usize::from(v.is_none());
            values.insert(*k, v.unwrap_or(f64::NAN));
        }
        visited.extend(frontier.iter().copied());
        let outputs: Vec<CellOutput> = frontier
            .par_chunks(1024)
            .map(|chunk| {
                let mut out = CellOutput::default();
                for &cell in chunk {
                    polygonize(cell, &values, params, &mut out);
                }
                out
            })
            .collect();
        let mut next: Vec<u64> = Vec::new();
        for out in outputs {
            // Number this batch's extra vertices globally.
            let offset = extras.len() as u64;
            triangles.extend(
                out.triangles
                    .into_iter()
                    .map(|t| t.map(|k| if k & EXTRA != 0 { k + offset } else { k })),
            );
            extras.extend(out.extras);
            skipped += out.skipped;
            next.extend(out.neighbours.into_iter().filter(|c| !visited.contains(c)));
        }
        next.par_sort_unstable();
        next.dedup();
        if let Some(&c) = next
            .iter()
            .find(|&&c| unkey(c).iter().any(|v| v.abs() > KEY_LIMIT - 1))
        {
            return Err(Error::InvalidParameter {
                name: "cell",
                message: format!(
                    "the surface reaches cell {:?}, beyond the lattice keys' range; use a larger cell",
                    unkey(c)
                ),
            });
        }
        frontier = next;
    }

    // Vertices: one per distinct lattice edge, where the linear interpolation of f vanishes,
    // then the centroids.
    let mut edges: Vec<u64> = triangles
        .par_iter()
        .flat_map_iter(|t| t.iter().copied().filter(|k| k & EXTRA == 0))
        .collect();
    edges.par_sort_unstable();
    edges.dedup();
    let mut positions: Vec<DVec3> = edges
        .par_iter()
        .map(|&e| {
            let (corner, axis) = (e >> 2, (e & 3) as usize);
            let fa = values.get(&corner).copied().unwrap_or(f64::NAN);
            let fb = values
                .get(&(corner + axis_step(axis)))
                .copied()
                .unwrap_or(f64::NAN);
            edge_vertex(e, fa, fb, params)
        })
        .collect();
    positions.extend(extras);
    let index = |k: u64| -> u32 {
        if k & EXTRA != 0 {
            (edges.len() as u64 + (k & !EXTRA)) as u32
        } else {
            edges
                .binary_search(&k)
                .map(|i| i as u32)
                .unwrap_or(u32::MAX)
        }
    };
    let tris: Vec<[u32; 3]> = triangles
        .par_iter()
        .map(|t| [index(t[0]), index(t[1]), index(t[2])])
        .collect();
    if positions.len() >= u32::MAX as usize {
        return Err(Error::InvalidParameter {
            name: "cell",
            message: format!("{} vertices, more than 2^32 - 1", positions.len()),
        });
    }
    Ok(MarchingCubesResult {
        mesh: TriMesh::new(positions, tris),
        evaluations: values.len(),
        undefined_corners: undefined,
        cells_visited: visited.len(),
        cells_grown: visited.len().saturating_sub(seeded),
        cells_skipped: skipped,
        complete,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use spectral_remesh::{check_invariants, topology};

    /// Every case's cycles use each crossing edge exactly once and no other edge.
    #[test]
    fn every_case_uses_each_crossing_edge_once() {
        for mask in 0..256usize {
            let positive = |c: usize| mask >> c & 1 == 1;
            let mut used = [0usize; 12];
            for polygon in &table()[mask] {
                let cycle = &polygon.edges;
                assert!(cycle.len() >= 3, "case {mask}: cycle {cycle:?}");
                for &e in cycle {
                    used[e as usize] += 1;
                }
            }
            for e in 0..12 {
                let (a, b) = (EDGE_BASE[e], EDGE_BASE[e] | 1 << (e / 4));
                let crossing = positive(a) != positive(b);
                assert_eq!(used[e], usize::from(crossing), "case {mask}, edge {e}");
            }
        }
        // One positive corner: one triangle; complementary cases have reversed polygons.
        assert_eq!(table()[1].len(), 1);
        assert_eq!(table()[1][0].edges.len(), 3);
        assert_eq!(
            table()[0b0110_1001].len(),
            4,
            "two opposite tetrahedral corner sets"
        );
    }

    /// A sphere of radius r about c as a signed distance, undefined beyond `reach` from it.
    fn sphere(c: DVec3, r: f64, reach: f64) -> impl Fn(DVec3) -> Option<f64> + Sync {
        move |x: DVec3| {
            let d = (x - c).length() - r;
            (d.abs() <= reach).then_some(d)
        }
    }

    /// A torus about the z axis through `c`: major radius `big`, minor `small`.
    fn torus(c: DVec3, big: f64, small: f64) -> impl Fn(DVec3) -> Option<f64> + Sync {
        move |x: DVec3| {
            let p = x - c;
            let q = (p.x * p.x + p.y * p.y).sqrt() - big;
            Some((q * q + p.z * p.z).sqrt() - small)
        }
    }

    fn seeds_on_sphere(c: DVec3, r: f64, n: usize) -> Vec<DVec3> {
        crate::test_points::fibonacci_sphere(n)
            .into_iter()
            .map(|u| c + r * u)
            .collect()
    }

    #[test]
    fn sphere_is_closed_oriented_outward_and_close_to_the_true_surface() {
        let c = DVec3::new(0.13, -0.07, 0.31);
        for (r, cell) in [(1.0, 0.1), (1.0, 0.05), (5.0, 0.5), (0.3, 0.1)] {
            let f = sphere(c, r, 3.0 * cell);
            let seeds = seeds_on_sphere(c, r, 50);
            let out = marching_cubes(&f, &seeds, &MarchingCubesParams::with_cell(cell)).unwrap();
            let mesh = &out.mesh;
            assert!(
                check_invariants(mesh).is_empty(),
                "{:?}",
                check_invariants(mesh)
            );
            let t = topology(mesh);
            assert!(t.is_closed_manifold(), "r {r}, cell {cell}: {t:?}");
            assert_eq!((t.components, t.genus), (1, Some(0)), "r {r}, cell {cell}");
            assert!(out.complete && out.cells_skipped == 0);
            if r / cell >= 10.0 {
                assert!(
                    out.cells_grown > 0,
                    "50 seeds do not cover the sphere's cells"
                );
            }
            // Distance of the vertices to the true sphere, relative to the cell.
            let worst = mesh
                .positions
                .iter()
                .map(|p| ((*p - c).length() - r).abs())
                .fold(0.0, f64::max);
            // Linear interpolation of the distance along a chord at distance h from the
            // centre: at most about cell²/(8 r) plus rounding; at least the vertices lie on
            // the grid's edges inside the cell.
            let bound = cell * cell / (2.0 * r) + 1e-9;
            assert!(
                worst <= bound,
                "r {r}, cell {cell}: worst {worst} > {bound}"
            );
            // Oriented outward: the signed volume is close to the ball's.
            let volume: f64 = mesh
                .triangles
                .iter()
                .map(|t| {
                    let [a, b, d] = t.map(|i| mesh.positions[i as usize] - c);
                    a.dot(b.cross(d)) / 6.0
                })
                .sum();
            let ball = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
            assert!(
                (volume / ball - 1.0).abs() < 3.0 * bound / r,
                "r {r}, cell {cell}: volume {volume} vs {ball}"
            );
        }
    }

    #[test]
    fn torus_has_genus_one_and_vertices_near_the_true_surface() {
        let c = DVec3::new(0.01, 0.02, -0.03);
        let (big, small, cell) = (2.0, 0.6, 0.07);
        let f = torus(c, big, small);
        // A few seeds on the outer equator only: the rest is found by growth.
        let seeds: Vec<DVec3> = (0..8)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 8.0;
                c + (big + small) * DVec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let out = marching_cubes(&f, &seeds, &MarchingCubesParams::with_cell(cell)).unwrap();
        let mesh = &out.mesh;
        assert!(
            check_invariants(mesh).is_empty(),
            "{:?}",
            check_invariants(mesh)
        );
        let t = topology(mesh);
        assert!(t.is_closed_manifold());
        assert_eq!((t.components, t.genus), (1, Some(1)), "{t:?}");
        let worst = mesh
            .positions
            .iter()
            .map(|p| f(*p).unwrap().abs())
            .fold(0.0, f64::max);
        // The tighter curvature is 1/small.
        assert!(worst < cell * cell / small, "worst {worst}");
        // Every visited cell is near the surface: no flood of the volume.
        let crossing_cells = mesh.triangles.len(); // at least one triangle per crossing cell
        assert!(
            out.cells_visited < 4 * crossing_cells,
            "{} visited",
            out.cells_visited
        );
    }

    #[test]
    fn random_signs_give_a_manifold_consistently_oriented_surface() {
        // Values drawn at random per lattice point exercise every case, the ambiguous faces
        // included; the surface must still be an oriented manifold (with a boundary where the
        // function's box ends).
        use rand::{RngExt, SeedableRng};
        let cell = 0.1;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let n = 21;
        let table: Vec<f64> = (0..n * n * n)
            .map(|_| rng.random_range(-1.0..1.0))
            .collect();
        let f = move |x: DVec3| {
            let q = (x / cell).round();
            let inside = [q.x, q.y, q.z].iter().all(|v| (0.0..n as f64).contains(v));
            inside.then(|| table[(q.x as usize * n + q.y as usize) * n + q.z as usize])
        };
        let seeds: Vec<DVec3> = (0..20)
            .map(|k| DVec3::splat(0.05 + 0.1 * k as f64))
            .collect();
        let out = marching_cubes(&f, &seeds, &MarchingCubesParams::with_cell(cell)).unwrap();
        let problems = check_invariants(&out.mesh);
        assert!(problems.is_empty(), "{problems:?}");
        let t = topology(&out.mesh);
        assert!(t.faces > 10_000, "{t:?}");
        // Every mask occurs.
        let mut seen = [false; 256];
        for i in 0..n - 1 {
            for j in 0..n - 1 {
                for k in 0..n - 1 {
                    let mask = (0..8).fold(0usize, |m, c| {
                        let p = DVec3::new(
                            (i + (c & 1)) as f64,
                            (j + (c >> 1 & 1)) as f64,
                            (k + (c >> 2 & 1)) as f64,
                        ) * cell;
                        m | usize::from(f(p).unwrap() >= 0.0) << c
                    });
                    seen[mask] = true;
                }
            }
        }
        assert!(seen.iter().filter(|&&s| s).count() > 250);
    }

    #[test]
    fn undefined_corners_leave_holes_not_garbage() {
        // A sphere whose function is undefined for x > 0.5: the cap beyond is cut off, the rest
        // is a manifold disc with one boundary loop.
        let c = DVec3::ZERO;
        let f = |x: DVec3| (x.x <= 0.5).then(|| x.length() - 1.0);
        let seeds = seeds_on_sphere(c, 1.0, 200);
        let params = MarchingCubesParams {
            origin: DVec3::splat(0.0123),
            ..MarchingCubesParams::with_cell(0.1)
        };
        let out = marching_cubes(&f, &seeds, &params).unwrap();
        let t = topology(&out.mesh);
        assert!(t.is_manifold());
        assert_eq!(t.boundary_loops, 1, "{t:?}");
        assert!(out.cells_skipped > 0 && out.undefined_corners > 0);
        assert!(out.mesh.positions.iter().all(|p| p.x <= 0.5 + 1e-12));
    }

    #[test]
    fn the_lattice_is_shared_and_the_result_repeats() {
        let c = DVec3::new(0.3, 0.2, 0.1);
        let f = sphere(c, 1.0, 0.5);
        let seeds = seeds_on_sphere(c, 1.0, 30);
        let params = MarchingCubesParams::with_cell(0.1);
        let a = marching_cubes(&f, &seeds, &params).unwrap();
        let b = marching_cubes(&f, &seeds[..5], &params).unwrap();
        assert_eq!(a.mesh.positions, b.mesh.positions);
        // The same triangles (visited in another order).
        let canonical = |m: &TriMesh| {
            let mut t: Vec<[u32; 3]> = m
                .triangles
                .iter()
                .map(|t| {
                    let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
                    [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
                })
                .collect();
            t.sort_unstable();
            t
        };
        assert_eq!(canonical(&a.mesh), canonical(&b.mesh));
        // Every vertex lies on a lattice edge: two of its coordinates are lattice values.
        for p in &a.mesh.positions {
            let q = (*p - params.origin) / params.cell;
            let on = [q.x, q.y, q.z]
                .iter()
                .filter(|v| (*v - v.round()).abs() < 1e-9)
                .count();
            assert!(on >= 2, "{p}");
        }
    }

    #[test]
    fn bad_parameters_are_errors() {
        let f = |x: DVec3| Some(x.length() - 1.0);
        let seeds = [DVec3::X];
        for params in [
            MarchingCubesParams::with_cell(0.0),
            MarchingCubesParams::with_cell(f64::NAN),
            MarchingCubesParams {
                origin: DVec3::splat(f64::INFINITY),
                ..Default::default()
            },
        ] {
            assert!(marching_cubes(&f, &seeds, &params).is_err());
        }
        let far = [DVec3::splat(1e9)];
        assert!(marching_cubes(&f, &far, &MarchingCubesParams::default()).is_err());
        assert!(marching_cubes(&f, &[DVec3::NAN], &MarchingCubesParams::default()).is_err());
        // No seeds: nothing visited, an empty mesh.
        let out = marching_cubes(&f, &[], &MarchingCubesParams::default()).unwrap();
        assert_eq!(out.mesh.triangles.len(), 0);
    }
}
