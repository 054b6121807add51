//! Lawson's edge flips with the max-min angle rule (C. L. Lawson, "Software for C¹ surface
//! interpolation", Mathematical Software III, 1977): an interior edge is flipped when the
//! smaller of the smallest angles of its two faces grows. In the plane, flipping until no edge
//! qualifies gives the Delaunay triangulation; on a surface each caller adds its own guard (the
//! assembly's refinement: the faces stay nearly coplanar and agree with the samples' normals;
//! the optimizer: the new faces stay on the input surface).

use crate::geometry::tolerance::FLIP_MIN_ANGLE_GAIN_DEG;
use crate::geometry::triangle::triangle_min_angle_deg;
use crate::mesh::edit::{starting_at, EditMesh};

/// A flip that the max-min rule asks for: the edge `x`–`y` with faces `old = [[x, y, c],
/// [y, x, d]]` (in slots `slots`) would become `c`–`d` with faces `new = [[x, d, c], [y, c, d]]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FlipCandidate {
    /// The old faces, `[x, y, c]` and `[y, x, d]`.
    pub old: [[u32; 3]; 2],
    /// Their slots.
    pub slots: [u32; 2],
    /// The new faces, `[x, d, c]` and `[y, c, d]`.
    pub new: [[u32; 3]; 2],
}

/// The smallest angle of the triangle `t`, degrees.
fn min_angle<L: Copy>(m: &EditMesh<L>, t: [u32; 3]) -> f64 {
    triangle_min_angle_deg(m.corners(t))
}

/// The flip of the edge `x`–`y` when the max-min rule asks for it: the edge is interior, `c`–`d`
/// is not an edge yet (nor a blocked direction), `x` and `y` keep at least three faces each, and
/// the smaller of the two faces' smallest angles grows by more than 10⁻⁶ degrees.
pub(crate) fn max_min_candidate<L: Copy>(m: &EditMesh<L>, x: u32, y: u32) -> Option<FlipCandidate> {
    let (f1, f2) = (m.face_on(x, y)?, m.face_on(y, x)?);
    let t1 = starting_at(m.face(f1)?, x); // [x, y, c]
    let t2 = starting_at(m.face(f2)?, y); // [y, x, d]
    if t1[1] != y || t2[1] != x {
        return None;
    }
    let (c, d) = (t1[2], t2[2]);
    if c == d
        || m.is_used_or_blocked(c, d)
        || m.is_used_or_blocked(d, c)
        || m.degree(x) <= 3
        || m.degree(y) <= 3
    {
        return None;
    }
    let new1 = [x, d, c];
    let new2 = [y, c, d];
    let old = min_angle(m, t1).min(min_angle(m, t2));
    let new = min_angle(m, new1).min(min_angle(m, new2));
    if new <= old + FLIP_MIN_ANGLE_GAIN_DEG {
        return None;
    }
    Some(FlipCandidate {
        old: [t1, t2],
        slots: [f1, f2],
        new: [new1, new2],
    })
}

/// Below this many edges [`max_min_flips_after`] runs sequentially: the parallel evaluation pays off
/// on whole meshes, not on the few edges around a poor triangle.
const PARALLEL_EDGES: usize = 512;

/// Flips the edges `edges` (pairs of vertices), in order, that the max-min rule asks for
/// ([`max_min_candidate`]) and `accept` allows (it sees the mesh and the flip before it is
/// made), with [`EditMesh::flip_edge`]; new faces get `label`. Returns the number of flips.
/// `accept` decides from the flip's four vertices alone ([`flip_in_order`]).
///
/// As a sweep after another: `last` flags the vertices of the quads the sweep before came to
/// flip, whose edges are decided again; an edge none of whose four
/// vertices is flagged was left by that sweep on the same four vertices and is taken as left
/// without deciding it (unless a flip earlier in this pass touched it). Marks in `touched` (one
/// flag per vertex) the four vertices of every quad this pass comes to flip, whether the flip
/// then succeeds or not: `last` of the next sweep. With `last` `None` every edge is decided.
/// The same flips as deciding every edge.
pub(crate) fn max_min_flips_after<L: Copy + Send + Sync>(
    m: &mut EditMesh<L>,
    edges: &[(u32, u32)],
    label: L,
    last: Option<&[bool]>,
    touched: &mut [bool],
    accept: impl Fn(&EditMesh<L>, &FlipCandidate) -> bool + Sync,
) -> usize {
    passes(
        m,
        edges,
        label,
        |m, x, y| max_min_candidate(m, x, y).is_some_and(|flip| accept(m, &flip)),
        |m, x, y| {
            for v in quad(m, x, y).unwrap_or([x, y, x, y]) {
                if let Some(t) = touched.get_mut(v as usize) {
                    *t = true;
                }
            }
            true
        },
        |_, _| {},
        last,
    )
}

/// Flips, in order, the edges of `edges` for which `decide` says yes on the mesh as it is when
/// the pass reaches them; new faces get `label`. Returns the number of flips.
///
/// `decide` must answer from the edge's four vertices alone (the edge's ends and the apexes of
/// its two faces: their positions, degrees and edges, and data no flip changes). Every edge is
/// first decided in parallel on the mesh as it is, and the pass in order then takes that answer
/// for each edge none of whose four vertices a flip earlier in the pass touched: a flip changes
/// only the degrees of its own four vertices and the faces on the edges among them, so such an
/// edge would be decided alike. The result is the sequential pass's, to the bit.
pub(crate) fn flip_in_order<L: Copy + Send + Sync>(
    m: &mut EditMesh<L>,
    edges: &[(u32, u32)],
    label: L,
    decide: impl Fn(&EditMesh<L>, u32, u32) -> bool + Sync,
) -> usize {
    flip_in_order_vetoed(m, edges, label, decide, |_, _, _| true, |_, _| {})
}

/// [`flip_in_order`] with a last word read from the whole mesh: `veto(m, x, y)`, asked in
/// order right before each flip `decide` allows (false: the edge is left), and `flipped(m,
/// [x, y, c, d])` told after each flip (the new edge is `c`–`d`). Both run sequentially, so
/// they may read and keep anything (a crossing guard over every face); the result stays the
/// sequential pass's.
pub(crate) fn flip_in_order_vetoed<L: Copy + Send + Sync>(
    m: &mut EditMesh<L>,
    edges: &[(u32, u32)],
    label: L,
    decide: impl Fn(&EditMesh<L>, u32, u32) -> bool + Sync,
    veto: impl FnMut(&EditMesh<L>, u32, u32) -> bool,
    flipped: impl FnMut(&EditMesh<L>, [u32; 4]),
) -> usize {
    passes(m, edges, label, decide, veto, flipped, None)
}

/// [`flip_in_order_vetoed`], where `settled` (when given: one flag per vertex) says which
/// edges are known to be left at the start of the pass: those none of whose four vertices is
/// flagged. They are not decided unless a flip earlier in the pass touched them.
fn passes<L: Copy + Send + Sync>(
    m: &mut EditMesh<L>,
    edges: &[(u32, u32)],
    label: L,
    decide: impl Fn(&EditMesh<L>, u32, u32) -> bool + Sync,
    mut veto: impl FnMut(&EditMesh<L>, u32, u32) -> bool,
    mut flipped: impl FnMut(&EditMesh<L>, [u32; 4]),
    settled: Option<&[bool]>,
) -> usize {
    use rayon::prelude::*;
    let mut flips = 0;
    let left = |x: u32, y: u32, apexes: [u32; 2]| {
        settled.is_some_and(|flag| {
            [x, y, apexes[0], apexes[1]]
                .iter()
                .all(|&v| !flag.get(v as usize).copied().unwrap_or(true))
        })
    };
    if edges.len() < PARALLEL_EDGES {
        for &(x, y) in edges {
            if !(decide(m, x, y) && veto(m, x, y)) {
                continue;
            }
            let [_, _, c, d] = quad(m, x, y).unwrap_or([x, y, x, y]);
            if m.flip_edge(x, y, label).is_ok() {
                flips += 1;
                flipped(m, [x, y, c, d]);
            }
        }
        return flips;
    }
    let first: Vec<([u32; 2], bool)> = {
        let m = &*m;
        edges
            .par_iter()
            .map(|&(x, y)| {
                let apexes = quad(m, x, y).map_or([x, y], |[_, _, c, d]| [c, d]);
                (apexes, !left(x, y, apexes) && decide(m, x, y))
            })
            .collect()
    };
    let mut touched = vec![false; m.vertex_count()];
    for (&(x, y), &(apexes, yes)) in edges.iter().zip(&first) {
        let stale = [x, y, apexes[0], apexes[1]]
            .iter()
            .any(|&v| touched.get(v as usize).copied().unwrap_or(true));
        if !(if stale { decide(m, x, y) } else { yes }) || !veto(m, x, y) {
            continue;
        }
        let [_, _, c, d] = quad(m, x, y).unwrap_or([x, y, x, y]);
        if m.flip_edge(x, y, label).is_ok() {
            flips += 1;
            for v in [x, y, c, d] {
                touched[v as usize] = true;
            }
            flipped(m, [x, y, c, d]);
        }
    }
    flips
}

/// The vertices `[x, y, c, d]` of the two faces on the interior edge `x`–`y` (`c` the apex of
/// the face on `x`→`y`, `d` of the face on `y`→`x`), or `None` when it is not interior.
pub(crate) fn quad<L: Copy>(m: &EditMesh<L>, x: u32, y: u32) -> Option<[u32; 4]> {
    let c = starting_at(m.face(m.face_on(x, y)?)?, x)[2];
    let d = starting_at(m.face(m.face_on(y, x)?)?, y)[2];
    Some([x, y, c, d])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::edit::SlotPolicy;

    /// A convex quad 0-3-1-2 split along its long diagonal 0-1, alone or inside a ring 4..=7
    /// that gives 0 and 1 six faces each.
    fn quad(with_ring: bool) -> EditMesh<()> {
        let (positions, faces) = crate::mesh::test_meshes::quad_in_ring();
        let mut m = EditMesh::new(positions, SlotPolicy::Reuse);
        for &t in &faces[..if with_ring { 10 } else { 2 }] {
            assert!(m.add_face(t, ()).is_ok());
        }
        m
    }

    #[test]
    fn the_long_diagonal_is_flipped_and_the_short_one_kept() {
        let mut m = quad(true);
        let flip = max_min_candidate(&m, 0, 1).expect("the long diagonal is a candidate");
        assert_eq!(flip.old, [[0, 1, 2], [1, 0, 3]]);
        assert_eq!(flip.new, [[0, 3, 2], [1, 2, 3]]);
        assert_eq!(
            max_min_flips_after(&mut m, &[(0, 1)], (), None, &mut [], |_, _| true),
            1
        );
        assert!(m.has_edge(2, 3) && !m.has_edge(0, 1));
        // Flipping back would lower the smallest angle.
        assert_eq!(max_min_candidate(&m, 2, 3), None);
        assert_eq!(
            max_min_flips_after(&mut m, &[(2, 3)], (), None, &mut [], |_, _| true),
            0
        );
        assert_eq!(m.sanity_check(), Ok(()));
    }

    /// A jittered grid: most of its edges are not Delaunay, and flips chain into each other.
    fn jittered(n: usize, seed: u64) -> EditMesh<()> {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let jitter: Vec<(f64, f64)> = (0..(n + 1) * (n + 1))
            .map(|_| (rng.random_range(-0.3..0.3), rng.random_range(-0.3..0.3)))
            .collect();
        let mesh = crate::mesh::test_meshes::grid(n, |i, j| {
            let (dx, dy) = jitter[i * (n + 1) + j];
            glam::DVec3::new(i as f64 + dx, j as f64 + dy, 0.0)
        });
        EditMesh::from_trimesh(&mesh, |_| (), SlotPolicy::Reuse)
    }

    /// Sweeps over every edge until none flips, the later ones told which vertices the sweep
    /// before came to flip at, make the flips of sweeps that decide every edge, sweep by sweep.
    #[test]
    fn sweeps_that_skip_the_settled_edges_flip_what_full_sweeps_flip() {
        for seed in 0..4 {
            let mut skipping = jittered(30, seed);
            let mut full = skipping.clone();
            // A guard that reads the four vertices only, to make some refusals.
            let accept = |m: &EditMesh<()>, f: &FlipCandidate| {
                let [c, d] = [f.new[0][2], f.new[0][1]];
                m.position(c).x + m.position(d).x > 1.5
            };
            let edges = |m: &EditMesh<()>| {
                let mut e: Vec<(u32, u32)> = m.directed_edges().filter(|&(x, y)| x < y).collect();
                e.sort_unstable();
                e
            };
            let (mut a, mut b) = (Vec::new(), Vec::new());
            let mut last: Option<Vec<bool>> = None;
            loop {
                let (ea, eb) = (edges(&skipping), edges(&full));
                assert_eq!(ea, eb);
                let mut now = vec![false; skipping.vertex_count()];
                let fa =
                    max_min_flips_after(&mut skipping, &ea, (), last.as_deref(), &mut now, accept);
                let fb = max_min_flips_after(&mut full, &eb, (), None, &mut [], accept);
                a.push(fa);
                b.push(fb);
                if fa == 0 && fb == 0 {
                    break;
                }
                last = Some(now);
            }
            assert!(
                a.len() >= 3 && a[1] > 0,
                "{a:?}: the case should take sweeps"
            );
            assert_eq!(a, b);
            assert_eq!(skipping.live_faces(), full.live_faces());
        }
    }

    #[test]
    fn the_parallel_pass_flips_what_the_sequential_pass_flips() {
        for seed in 0..4 {
            let mut parallel = jittered(30, seed);
            let mut sequential = parallel.clone();
            let mut edges: Vec<(u32, u32)> =
                parallel.directed_edges().filter(|&(x, y)| x < y).collect();
            edges.sort_unstable();
            assert!(edges.len() >= PARALLEL_EDGES);
            // A guard that reads the four vertices only (here: refuse flips whose new edge
            // would run up and to the right of vertex 0's column, to make some refusals).
            let accept = |m: &EditMesh<()>, f: &FlipCandidate| {
                let [c, d] = [f.new[0][2], f.new[0][1]];
                m.position(c).x + m.position(d).x > 1.5
            };
            let a = max_min_flips_after(&mut parallel, &edges, (), None, &mut [], accept);
            // One edge at a time: below PARALLEL_EDGES, so the plain sequential pass.
            let b: usize = edges
                .iter()
                .map(|e| {
                    max_min_flips_after(
                        &mut sequential,
                        std::slice::from_ref(e),
                        (),
                        None,
                        &mut [],
                        accept,
                    )
                })
                .sum();
            assert!(a > 50, "{a} flips: the case should chain flips");
            assert_eq!(a, b);
            assert_eq!(parallel.live_faces(), sequential.live_faces());
            assert_eq!(parallel.sanity_check(), Ok(()));
        }
    }

    #[test]
    fn no_candidate_at_a_vertex_of_three_faces_or_when_the_guard_says_no() {
        // Alone, 0 and 1 have two faces each: a flip would leave them with one.
        let m = quad(false);
        assert_eq!(max_min_candidate(&m, 0, 1), None);
        let mut m = quad(true);
        assert_eq!(
            max_min_flips_after(&mut m, &[(0, 1)], (), None, &mut [], |_, _| false),
            0
        );
        assert!(m.has_edge(0, 1));
        // A boundary edge is never a candidate.
        assert_eq!(max_min_candidate(&m, 6, 0), None);
        assert_eq!(m.sanity_check(), Ok(()));
    }
}
