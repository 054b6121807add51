//! The first stages: the input normalized to bbox 100 and oriented consistently, its index (the
//! search structure of its surface, the buried-point test, where it crosses itself), and the
//! candidate pool of the linear scan drawn on it.

use glam::DVec3;

use super::params::Target;
use super::RemeshParams;
use crate::error::{Error, Result};
use crate::geometry::tolerance::DEGENERATE_AREA_TOLERANCE;
use crate::mesh::sheets::Sheets;
use crate::mesh::{orient_consistently, Normalization, OrientStats, TriMesh};
use crate::sampling::boundary::{boundary_curves, BoundaryCurve};
use crate::sampling::curves::curve_length;
use crate::sampling::sizing::SizingField;
use crate::sampling::spacing::{expected_samples, BOUNDARY_SPACING_PER_SIGMA, SAMPLES_PER_SIGMA2};
use crate::surface::candidates::{graded_candidates, shuffle_candidates, surface_candidates};
use crate::surface::feature_lines::FeatureLines;
use crate::surface::winding::BuriedTest;
use crate::surface::{MeshSurface, SurfaceSample};
use rayon::prelude::*;

use super::MAX_POINTS;

/// The input in bbox-100 units, oriented consistently, with its area and boundary curves.
pub(super) struct NormalizedInput {
    /// Model units ↔ bbox-100 units.
    pub normalization: Normalization,
    /// The input in bbox-100 units, oriented consistently.
    pub mesh: TriMesh,
    /// What orienting it did.
    pub orientation: OrientStats,
    /// Its area (bbox-100 units²).
    pub area: f64,
    /// Its boundary curves and their total length.
    pub curves: Vec<BoundaryCurve>,
    pub boundary_length: f64,
    /// The boundary curves as segments, which the last pass of the optimization slides boundary
    /// vertices along.
    pub boundary_lines: Option<FeatureLines>,
}

impl NormalizedInput {
    /// `input` (model units) scaled by `normalization` and oriented consistently; with the mesh
    /// as read, before orienting (the candidates are drawn on it).
    ///
    /// # Errors
    /// [`Error::InvalidMesh`] for a surface of almost no area for its boundary's length.
    pub(super) fn new(input: &TriMesh, normalization: Normalization) -> Result<(Self, TriMesh)> {
        let as_read = normalization.apply_mesh(input);
        let mut mesh = as_read.clone();
        // Every later stage takes the faces' orientation at face value (normals, tangent planes,
        // the triangulation's orientation): the input is oriented consistently first. Its closed
        // parts are turned outward on the output instead: the sampling does not depend on which
        // way a consistent input faces, but the projections' rounding does, so an inward input
        // that is otherwise fine (horse) keeps its output and only the orientation changes.
        let orientation = orient_consistently(&mut mesh, false);
        let area = mesh.area();
        let curves = boundary_curves(&mesh);
        let boundary_length: f64 = curves.iter().map(|c| curve_length(&mesh, c)).sum();
        let boundary_lines = FeatureLines::new(
            &mesh.positions,
            curves.iter().flat_map(|c| {
                let n = c.vertices.len();
                let edges = if c.closed { n } else { n.saturating_sub(1) };
                (0..edges).map(move |k| [c.vertices[k], c.vertices[(k + 1) % n]])
            }),
        );
        // A surface thinner everywhere than the zero-area test's tolerance of its own length (a
        // strip of colinear faces, a needle): every triangle on it would be degenerate, and
        // sampling its boundary curves at a spacing its area suggests would take without bound.
        if area <= DEGENERATE_AREA_TOLERANCE * boundary_length * boundary_length {
            return Err(Error::invalid_mesh(
                "",
                format!(
                    "the surface has almost no area ({area:.1e}) but boundary curves \
                     {boundary_length:.3} long (bbox-100 units): its faces are (nearly) \
                     colinear, so every triangle on it would be degenerate"
                ),
            ));
        }
        let input = NormalizedInput {
            normalization,
            mesh,
            orientation,
            area,
            curves,
            boundary_length,
            boundary_lines,
        };
        Ok((input, as_read))
    }

    /// The size of the linear scan's candidate pool for `target`: `candidates_per_sample` per
    /// expected sample, 16 to 2·10^8.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a sigma_p that would give more than [`MAX_POINTS`]
    /// samples (the message gives the smallest it takes).
    pub(super) fn pool_size(&self, target: Target, params: &RemeshParams) -> Result<usize> {
        let (area, boundary_length) = (self.area, self.boundary_length);
        // Candidates are drawn for the samples expected inside the surface.
        let expected = match target {
            Target::Points(n) => n as f64,
            Target::SigmaP(s) => SAMPLES_PER_SIGMA2 * area / (s * s),
        };
        if let Target::SigmaP(s) = target {
            // The same bound as a count: the candidate pool and the samples, those on the
            // boundary curves included, must fit in memory.
            let expected = expected_samples(area, boundary_length, s);
            if !(expected <= MAX_POINTS as f64) {
                // The positive root of expected_samples(s) = MAX_POINTS.
                let (n, a) = (MAX_POINTS as f64, SAMPLES_PER_SIGMA2 * area);
                let b = boundary_length / BOUNDARY_SPACING_PER_SIGMA;
                let smallest = (b + (b * b + 4.0 * n * a).sqrt()) / (2.0 * n);
                return Err(Error::InvalidParameter {
                    name: "sigma_p",
                    message: format!(
                        "sigma_p {} would give {} samples on this surface, more than the \
                         {MAX_POINTS} this remesher holds in memory; the smallest sigma_p it \
                         takes here is {smallest:.4} (bbox-100 units)",
                        crate::error::shown(s),
                        if expected.is_finite() {
                            format!("about {expected:.2e}")
                        } else {
                            "too many".to_string()
                        }
                    ),
                });
            }
        }
        Ok((params.candidates_per_sample * expected)
            .ceil()
            .clamp(16.0, 2e8) as usize)
    }
}

/// What the stages ask about the input: the search structure of its surface (closest points,
/// projection, normals), the test for points buried inside its own solid (an input that passes
/// through itself), the pairs of its faces that cross, and where its parts meet at non-manifold
/// edges.
pub(super) struct InputIndex<'a> {
    pub surface: MeshSurface,
    pub buried_test: Option<BuriedTest<'a>>,
    /// Pairs of faces that cross (looked for only when the input passes through itself), also
    /// when there is no buried test.
    pub crossing_pairs: Vec<[u32; 2]>,
    pub sheets: Sheets,
    /// The non-manifold edges (of more than two faces: where sheets meet), as vertex pairs
    /// (lower first), ascending.
    pub junction: Vec<[u32; 2]>,
    /// Of those, the edges where closed parts meet (both ends on the sheets' junction): the
    /// finishing stage leaves the output's crossings there alone.
    pub part_junction: Vec<[u32; 2]>,
    /// Whether every edge of the input has at most two faces: only then is the input's topology
    /// one the output can keep, and the triangulation inserts samples for it.
    pub manifold_edges: bool,
}

/// The samples per input face from which the input surface builds its faces' rings
/// (`geometry::closest_point_walk`): the build costs about four tree queries per face and each
/// walk saves a fraction of one, over some 30 warm queries per sample (gradient ascent,
/// relaxation, fit). Horse (96,966 faces), processor s: at 8,600 samples the build (0.37)
/// outweighs the walks' gain (2.47 -> 2.56 in all), at 200,000 it pays (40.7 -> 37.3).
pub(crate) const RINGS_FROM_SAMPLES_PER_FACE: f64 = 0.5;

impl<'a> InputIndex<'a> {
    /// The index of `mesh` (bbox-100 units), its buried test sized for `points` queries, its
    /// surface with the faces' rings for warm-started closest points where `samples` (the
    /// samples expected) make the walks pay ([`RINGS_FROM_SAMPLES_PER_FACE`]).
    ///
    /// # Errors
    /// Those of [`MeshSurface::new`].
    pub(super) fn new(mesh: &'a TriMesh, points: usize, samples: usize) -> Result<Self> {
        let rings = samples as f64 >= RINGS_FROM_SAMPLES_PER_FACE * mesh.triangles.len() as f64;
        // Each builds a BVH of the input's faces on one thread.
        // With the buried test, where the input's own faces cross (looked for on the test's
        // BVH): the finishing stage leaves the output's crossings there alone.
        let (surface, (buried_test, crossing_pairs)) = rayon::join(
            || {
                let surface = MeshSurface::new(mesh)?;
                Ok(if rings {
                    surface.with_face_rings()
                } else {
                    surface
                })
            },
            || BuriedTest::with_crossings(mesh, points),
        );
        let surface = surface?;
        // Where parts of the input meet at non-manifold edges (the triangulation keeps them
        // apart).
        let sheets = Sheets::new(mesh);
        let mut junction: Vec<[u32; 2]> = mesh
            .edge_uses()
            .into_iter()
            .filter(|&(_, (_, uses))| uses > 2)
            .map(|((a, b), _)| [a, b])
            .collect();
        junction.sort_unstable();
        let on_junction = |v: u32| sheets.junction.binary_search(&v).is_ok();
        let part_junction: Vec<[u32; 2]> = junction
            .iter()
            .copied()
            .filter(|&[a, b]| on_junction(a) && on_junction(b))
            .collect();
        let manifold_edges = junction.is_empty();
        Ok(InputIndex {
            surface,
            buried_test,
            crossing_pairs,
            sheets,
            junction,
            part_junction,
            manifold_edges,
        })
    }
}

/// The linear scan's candidate pool on the input.
pub(super) struct Candidates {
    /// Area-uniform random points with their face's normal (bbox-100 units).
    pub pool: Vec<SurfaceSample>,
    /// The input's vertices, those buried left out: with the pool as drawn, the points the
    /// optimization keeps covered ([`Candidates::cover_points`]).
    input_points: Vec<DVec3>,
    /// Candidates left out as buried inside the input's own solid.
    pub buried: usize,
    /// The pool as drawn, area-uniform, and its density per unit area, while a graded
    /// supplement is in `pool` (for the next grading; `None` while `pool` is as drawn).
    uniform: Option<(Vec<SurfaceSample>, f64)>,
}

impl Candidates {
    /// `size` candidates drawn on `as_read` (the input before orienting) with `seed`, their
    /// normals those of `input`'s oriented faces; those the index finds buried left out.
    pub(super) fn draw(
        as_read: TriMesh,
        input: &NormalizedInput,
        index: &InputIndex,
        size: usize,
        seed: u64,
    ) -> Self {
        let normalized = &input.mesh;
        // The candidates are drawn on the faces as read, and a reversed face's candidates take
        // its reversed normal: orienting the input changes the sign of normals, not where points
        // land (the draw depends on a face's corner order), so it changes the output's
        // orientation and nothing else of the sampling.
        let mut pool = surface_candidates(&as_read, size, seed);
        if input.orientation.faces_flipped > 0 {
            for c in &mut pool {
                if normalized.triangles[c.face as usize] != as_read.triangles[c.face as usize] {
                    c.normal = -c.normal;
                }
            }
        }
        drop(as_read);
        // Where the input passes through itself, the candidates inside its own solid are left
        // out (and samples the gradient ascent moves there are put back): the output follows
        // the outer surface and does not cross itself there.
        let mut buried = 0;
        let mut input_points: Vec<DVec3> = normalized.positions.clone();
        if let Some(test) = &index.buried_test {
            buried = test.remove_buried(&mut pool, |c| (c.position, c.normal, Some(c.face)));
            let mut vertices = BuriedTest::vertex_points(normalized);
            test.remove_buried(&mut vertices, |&v| v);
            input_points = vertices.into_iter().map(|(p, _, _)| p).collect();
        }
        Candidates {
            pool,
            input_points,
            buried,
            uniform: None,
        }
    }

    /// Input-surface points the optimization keeps within its cover distance of the output:
    /// the input's vertices and the candidates as drawn (area-uniform), those buried left out.
    /// Made when the finishing stage needs them, not kept (bbox-100 units).
    pub(super) fn cover_points(&self) -> Vec<DVec3> {
        let drawn = self.uniform.as_ref().map_or(&self.pool, |u| &u.0);
        self.input_points
            .iter()
            .copied()
            .chain(drawn.iter().map(|c| c.position))
            .collect()
    }

    /// The pool made to follow the sizing `field` (relative widths in (0, 1]): the area-uniform
    /// pool as drawn, and where the field is below 1, as many more candidates as the finer
    /// spacing takes ([`graded_candidates`]; a face's width: the field's at its centroid, and
    /// the smallest at its corners too where the face is larger than that spacing), those
    /// the index finds buried left out, visited in a seeded random order. `round`: a new seed
    /// for each grading of one run. A uniform field leaves the pool as drawn.
    pub(super) fn grade(
        &mut self,
        input: &NormalizedInput,
        index: &InputIndex,
        field: &dyn SizingField,
        sigma_p: f64,
        seed: u64,
        round: u64,
    ) {
        if field.is_uniform() {
            // The pool as drawn again (no copy of it is kept while the pool is that).
            if let Some((uniform, _)) = self.uniform.take() {
                self.pool = uniform;
            }
            return;
        }
        let (uniform, density) = self.uniform.get_or_insert_with(|| {
            let density = self.pool.len() as f64 / input.area.max(f64::MIN_POSITIVE);
            (self.pool.clone(), density)
        });
        let mesh = &input.mesh;
        let widths: Vec<f64> = (0..mesh.face_count())
            .into_par_iter()
            .map(|f| {
                let c = mesh.corners(f);
                let w = field.width((c[0] + c[1] + c[2]) / 3.0);
                let size = c[0]
                    .distance(c[1])
                    .max(c[1].distance(c[2]))
                    .max(c[2].distance(c[0]));
                if size > w * sigma_p {
                    c.iter().map(|&p| field.width(p)).fold(w, f64::min)
                } else {
                    w
                }
            })
            .collect();
        let salt = seed ^ (0x9e37_79b9_7f4a_7c15u64.wrapping_mul(round + 1));
        let mut extra = graded_candidates(mesh, *density, |f| widths[f], salt);
        if let Some(test) = &index.buried_test {
            self.buried += test.remove_buried(&mut extra, |c| (c.position, c.normal, Some(c.face)));
        }
        // A field of 1 wherever a face is (no candidate added) leaves the pool as drawn.
        let mut pool = uniform.clone();
        if !extra.is_empty() {
            pool.extend(extra);
            shuffle_candidates(&mut pool, salt);
        }
        self.pool = pool;
    }
}
