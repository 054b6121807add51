//! The pairs of faces of an indexed triangle set that intersect by the standard definition
//! ([`faces_intersect`]: faces that share no vertex and meet, share one vertex and meet elsewhere
//! too, or share an edge and overlap), found through a bounding-volume hierarchy (parry's) and
//! decided by exact predicates.

use glam::DVec3;
use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::partitioning::Bvh;
use rayon::prelude::*;

#[cfg(doc)]
use super::face_intersection::faces_intersect;
use super::face_intersection::{faces_within, PairKind};
use super::triangle::{face_key, is_degenerate_face};

/// The pairs of `boxes` (items of [`face_boxes`]: a face index and its bounding box) whose
/// closed boxes overlap, each once as `[f, g]` with f < g (face indices), sorted. The boxes go
/// into a BVH that is traversed against itself (parry's parallel traversal, whose pairs come in
/// the order of the sequential one): O(F + pairs) for boxes small against the model, and the
/// same result for any number of threads.
pub(crate) fn overlapping_box_pairs(boxes: &[(usize, Aabb)]) -> Vec<[u32; 2]> {
    if boxes.len() < 2 {
        return Vec::new();
    }
    box_pairs_in(&crate::geometry::bvh::bvh_of(boxes.iter().copied()))
}

/// The pairs of [`overlapping_box_pairs`] in a BVH already built over the boxes (leaf data: the
/// face index; at least two boxes).
fn box_pairs_in(bvh: &Bvh) -> Vec<[u32; 2]> {
    let mut pairs: Vec<[u32; 2]> = bvh
        .traverse_bvtt_single_tree_parallel::<false>()
        .into_par_iter()
        .map(|(a, b)| [a.min(b), a.max(b)])
        .collect();
    pairs.par_sort_unstable();
    pairs
}

/// What the search of [`classified_pairs`] took on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PairSearch {
    /// Faces that entered the search: every index in range, every corner finite, not
    /// [`is_degenerate_face`], and of the faces on the same three vertices ([`face_key`]) only
    /// the first.
    pub faces: usize,
    /// Pairs of those faces whose bounding boxes overlap: the exact tests made.
    pub candidates: usize,
}

/// The pairs of faces of `triangles` (indices into `positions`) that intersect
/// ([`faces_intersect`]: no vertex in common and their closed triangles share a point; one in
/// common and they meet elsewhere too; an edge in common and they overlap), each as `[f, g]`
/// with f < g with its [`PairKind`], in lexicographic order, and what the search took on
/// ([`PairSearch`]: the faces searched and the exact tests made).
///
/// Triangles with an index out of range, a non-finite corner or zero area
/// ([`is_degenerate_face`]) are left out (the invariant check reports them on their own). Faces
/// on the same three vertices as an earlier face, in any order and winding (duplicate faces,
/// reported on their own too), are searched once, as the first of them: a face repeated 20,000
/// times is one face here, not 2 · 10^8 pairs of overlapping boxes.
///
/// # Runtime
/// The pairs of overlapping bounding boxes come from a BVH traversed against itself
/// (parry's parallel BVTT), and every one is decided by [`faces_intersect`], which is exact.
/// O(F + pairs) for a mesh whose triangles are small against the model; parallel (rayon), and
/// deterministic.
pub fn classified_pairs(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> (Vec<([u32; 2], PairKind)>, PairSearch) {
    let mut seen = rustc_hash::FxHashSet::default();
    let boxes: Vec<(usize, Aabb)> = face_boxes(positions, triangles)
        .into_iter()
        .filter(|&(f, _)| seen.insert(face_key(triangles[f])))
        .collect();
    let candidates = overlapping_box_pairs(&boxes);
    let pairs: Vec<([u32; 2], PairKind)> = candidates
        .par_iter()
        .filter_map(|&[f, g]| pair_within(positions, triangles, f, g, 0.0).map(|k| ([f, g], k)))
        .collect();
    let search = PairSearch {
        faces: boxes.len(),
        candidates: candidates.len(),
    };
    (pairs, search)
}

/// The intersecting pairs of [`classified_pairs`] without their kinds, and the number of exact
/// tests made.
pub fn intersecting_pairs_counted(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> (Vec<[u32; 2]>, usize) {
    let (pairs, search) = classified_pairs(positions, triangles);
    (
        pairs.into_iter().map(|(p, _)| p).collect(),
        search.candidates,
    )
}

/// The pairs of [`intersecting_pairs`] and the pairs of faces that come within `near` of
/// intersecting ([`faces_within`]; the same units as `positions`), in the same order: the faces
/// that may intersect once their corners are rounded by up to `near / 2`. Boxes loosened by
/// `near / 2` each; the same cost as [`intersecting_pairs_counted`] for a `near` short against
/// the faces. Duplicate faces are not merged here (the stages' meshes have none): each copy is
/// a face of its own.
pub(crate) fn pairs_within(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    near: f64,
) -> Vec<[u32; 2]> {
    box_pairs(positions, triangles, near)
        .into_par_iter()
        .filter(|&[f, g]| pair_within(positions, triangles, f, g, near).is_some())
        .collect()
}

/// How faces `f` and `g` of `triangles` (indices into `positions`) intersect or come within
/// `near` of intersecting ([`faces_within`]; `near` 0: [`faces_intersect`], exact).
fn pair_within(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    f: u32,
    g: u32,
    near: f64,
) -> Option<PairKind> {
    let (a, b) = (triangles[f as usize], triangles[g as usize]);
    let corners = |t: [u32; 3]| t.map(|i| positions[i as usize]);
    faces_within(a, corners(a), b, corners(b), near)
}

/// The pairs of faces of [`face_boxes`] whose bounding boxes overlap, as
/// [`overlapping_box_pairs`] gives them, each box loosened by `near / 2`.
fn box_pairs(positions: &[DVec3], triangles: &[[u32; 3]], near: f64) -> Vec<[u32; 2]> {
    let mut boxes = face_boxes(positions, triangles);
    if near > 0.0 {
        for (_, b) in &mut boxes {
            *b = b.loosened(0.5 * near);
        }
    }
    overlapping_box_pairs(&boxes)
}

/// The axis-aligned bounding box of the triangle with corners `p`.
pub(crate) fn triangle_aabb(p: [DVec3; 3]) -> Aabb {
    Aabb::new(p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
}

/// The faces the search of [`intersecting_pairs_counted`] takes (every index in range, every
/// corner finite, not [`is_degenerate_face`]), in order, each with its bounding box.
pub(crate) fn face_boxes(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<(usize, Aabb)> {
    let n = positions.len();
    (0..triangles.len())
        .filter(|&f| {
            let t = triangles[f];
            t.iter().all(|&i| (i as usize) < n)
                && t.iter().all(|&i| positions[i as usize].is_finite())
                && !is_degenerate_face(positions, t)
        })
        .map(|f| {
            (
                f,
                triangle_aabb(triangles[f].map(|i| positions[i as usize])),
            )
        })
        .collect()
}

/// Faces per sequential run of [`has_intersecting_pair`]'s search (fixed, so the result does
/// not depend on the number of threads).
const CHUNK: usize = 1024;

/// Whether [`intersecting_pairs_counted`] would find at least one pair, given `boxes`
/// ([`face_boxes`] of the same faces) and a BVH over them (leaf data: the face index): the same
/// tests, stopping at the first pair found. In parallel; the answer does not depend on the
/// order.
pub(crate) fn has_intersecting_pair(
    bvh: &Bvh,
    boxes: &[(usize, Aabb)],
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> bool {
    boxes.par_chunks(CHUNK).any(|chunk| {
        chunk.iter().any(|&(f, aabb)| {
            bvh.intersect_aabb(&aabb).any(|g| {
                g as usize > f && pair_within(positions, triangles, f as u32, g, 0.0).is_some()
            })
        })
    })
}

/// The pairs of [`intersecting_pairs`] found on a BVH already built over `boxes` (items of
/// [`face_boxes`] of the same faces, leaf data the face index): the same pairs, sorted, without
/// building the BVH again. In parallel; the answer does not depend on the number of threads.
pub(crate) fn intersecting_pairs_in(
    bvh: &Bvh,
    boxes: &[(usize, Aabb)],
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> Vec<[u32; 2]> {
    let mut pairs: Vec<[u32; 2]> = boxes
        .par_chunks(CHUNK)
        .flat_map_iter(|chunk| {
            let mut found = Vec::new();
            for &(f, aabb) in chunk {
                for g in bvh.intersect_aabb(&aabb) {
                    if g as usize > f
                        && pair_within(positions, triangles, f as u32, g, 0.0).is_some()
                    {
                        found.push([f as u32, g]);
                    }
                }
            }
            found
        })
        .collect();
    pairs.sort_unstable();
    pairs
}

/// The intersecting pairs of [`intersecting_pairs_counted`], without the count of tests.
pub fn intersecting_pairs(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    intersecting_pairs_counted(positions, triangles).0
}

/// The faces of `triangles` that cross another face ([`intersecting_pairs`]), each as its corners
/// sorted (so a face keeps its name when an edit mesh moves it to another slot), sorted.
pub(crate) fn crossing_faces(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    faces_of_pairs(triangles, &intersecting_pairs(positions, triangles))
}

/// The faces of `triangles` in `pairs` (indices), as [`crossing_faces`] names them: each as its
/// corners sorted, sorted, once.
pub(crate) fn faces_of_pairs(triangles: &[[u32; 3]], pairs: &[[u32; 2]]) -> Vec<[u32; 3]> {
    let mut faces: Vec<[u32; 3]> = pairs
        .iter()
        .flatten()
        .map(|&i| {
            let mut t = triangles[i as usize];
            t.sort_unstable();
            t
        })
        .collect();
    faces.sort_unstable();
    faces.dedup();
    faces
}

/// Puts the corners of every face that crosses another and is not in `before` (from
/// [`crossing_faces`]) back at `start`, until no new crossing is left: how a stage that moves
/// vertices (the finishing relaxation, the least-squares fit, either of which can bring the two
/// sides of a thin part together) takes back the moves that made a crossing.
///
/// One search over the whole mesh ([`intersecting_pairs`]); after each round of putting back,
/// only the faces around the vertices put back are searched again (against a BVH of every
/// face's box at its positions now and at `start`, between which the corners only go), so the
/// answer is that of searching the whole mesh every round.
pub(crate) fn undo_new_crossings(
    positions: &mut [DVec3],
    triangles: &[[u32; 3]],
    start: &[DVec3],
    before: &[[u32; 3]],
) {
    let n = positions.len();
    let sorted = |f: u32| {
        let mut t = triangles[f as usize];
        t.sort_unstable();
        t
    };
    let is_new = |f: u32| before.binary_search(&sorted(f)).is_err();
    // The first search, over the whole mesh, and its BVH (leaf data: the face index) over the
    // faces it took, at their positions then.
    let mut seen = rustc_hash::FxHashSet::default();
    let first: Vec<bool> = triangles
        .iter()
        .map(|&t| seen.insert(face_key(t)))
        .collect();
    drop(seen);
    let boxes: Vec<(usize, Aabb)> = face_boxes(positions, triangles)
        .into_iter()
        .filter(|&(f, _)| first[f])
        .collect();
    let bvh = crate::geometry::bvh::bvh_of(boxes.iter().copied());
    let mut pairs: Vec<[u32; 2]> = if boxes.len() < 2 {
        Vec::new()
    } else {
        box_pairs_in(&bvh)
            .into_par_iter()
            .filter(|&[f, g]| pair_within(positions, triangles, f, g, 0.0).is_some())
            .collect()
    };
    let mut in_bvh = vec![false; triangles.len()];
    for &(f, _) in &boxes {
        in_bvh[f] = true;
    }
    drop(boxes);
    // Each vertex's faces, built at the first round that puts a vertex back.
    let mut faces_of: Option<Vec<Vec<u32>>> = None;
    // Faces whose corners were put back: their leaves in the BVH are stale.
    let mut moved = vec![false; triangles.len()];
    loop {
        let mut undone: Vec<u32> = Vec::new();
        for &[f, g] in &pairs {
            for h in [f, g].into_iter().filter(|&h| is_new(h)) {
                for v in triangles[h as usize] {
                    let i = v as usize;
                    if positions[i] != start[i] {
                        positions[i] = start[i];
                        undone.push(v);
                    }
                }
            }
        }
        if undone.is_empty() {
            return;
        }
        let faces_of = faces_of.get_or_insert_with(|| {
            let mut of = vec![Vec::new(); n];
            for (f, t) in triangles.iter().enumerate() {
                for &v in t {
                    if let Some(row) = of.get_mut(v as usize) {
                        row.push(f as u32);
                    }
                }
            }
            of
        });
        let mut changed = vec![false; triangles.len()];
        for v in undone {
            for &f in &faces_of[v as usize] {
                changed[f as usize] = true;
                moved[f as usize] = true;
            }
        }
        pairs.retain(|&[f, g]| !changed[f as usize] && !changed[g as usize]);
        // The faces to search again: those whose corners ever went back (their pairs with each
        // other are searched in a BVH of their own, at their positions now), each against the
        // faces that never moved (in the first BVH, whose leaves for them are exact).
        let positions = &*positions;
        let searched = |h: u32| {
            first[h as usize]
                && triangles[h as usize].iter().all(|&v| (v as usize) < n)
                && triangles[h as usize]
                    .iter()
                    .all(|&v| positions[v as usize].is_finite())
                && !is_degenerate_face(positions, triangles[h as usize])
        };
        let face_box = |h: u32| triangle_aabb(triangles[h as usize].map(|v| positions[v as usize]));
        let again: Vec<u32> = (0..triangles.len() as u32)
            .filter(|&h| moved[h as usize] && searched(h))
            .collect();
        let local = crate::geometry::bvh::bvh_of(again.iter().map(|&h| (h as usize, face_box(h))));
        let (changed, moved, in_bvh) = (&changed, &moved, &in_bvh);
        let (bvh, local) = (&bvh, &local);
        let found: Vec<[u32; 2]> = again
            .par_iter()
            .flat_map_iter(|&f| {
                let aabb = face_box(f);
                // Unmoved faces, and moved faces after f: one of each pair changed this round.
                let unmoved = bvh.intersect_aabb(&aabb).filter(move |&g| {
                    in_bvh.get(g as usize).copied().unwrap_or(false) && !moved[g as usize]
                });
                let other_moved = local
                    .intersect_aabb(&aabb)
                    .filter(move |&g| (g as usize) < triangles.len() && g > f);
                unmoved
                    .chain(other_moved)
                    .filter(move |&g| changed[f as usize] || changed[g as usize])
                    .filter(move |&g| {
                        pair_within(positions, triangles, f.min(g), f.max(g), 0.0).is_some()
                    })
                    .map(move |g| [f.min(g), f.max(g)])
                    .collect::<Vec<_>>()
            })
            .collect();
        pairs.extend(found);
        pairs.sort_unstable();
        pairs.dedup();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes::{cuboid, uv_sphere};

    /// [`undo_new_crossings`] as it was first written, searching the whole mesh every round:
    /// the reference the local searches must equal.
    fn undo_searching_whole(
        positions: &mut [DVec3],
        triangles: &[[u32; 3]],
        start: &[DVec3],
        before: &[[u32; 3]],
    ) {
        loop {
            let mut undone = false;
            for t in crossing_faces(positions, triangles) {
                if before.binary_search(&t).is_ok() {
                    continue;
                }
                for v in t.map(|v| v as usize) {
                    if positions[v] != start[v] {
                        positions[v] = start[v];
                        undone = true;
                    }
                }
            }
            if !undone {
                return;
            }
        }
    }

    /// Vertices of a sphere pushed through its far side and jittered, with crossings before
    /// the moves on one of two boxes: the moves taken back are those of the search over the
    /// whole mesh every round, position for position, and no new crossing is left.
    #[test]
    fn the_local_searches_undo_what_the_whole_search_undoes() {
        use rand::{RngExt, SeedableRng};
        let sphere = uv_sphere(1.0, 16, 32);
        let boxes = {
            let mut m = cuboid(DVec3::new(3.0, 0.0, 0.0), DVec3::new(5.0, 2.0, 2.0));
            let b = cuboid(DVec3::new(4.0, 1.0, 1.0), DVec3::new(6.0, 3.0, 3.0));
            let off = m.positions.len() as u32;
            m.positions.extend(b.positions);
            m.triangles
                .extend(b.triangles.iter().map(|t| t.map(|v| v + off)));
            m
        };
        let m = crate::mesh::test_meshes::union_of(&sphere, &boxes);
        let before = crossing_faces(&m.positions, &m.triangles);
        assert!(!before.is_empty());
        for seed in 0..6 {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let mut moved = m.positions.clone();
            for (i, p) in moved.iter_mut().enumerate() {
                if i < sphere.positions.len() && rng.random_range(0.0..1.0) < 0.05 {
                    *p = -1.3 * *p;
                } else {
                    *p += 0.02 * DVec3::new(rng.random(), rng.random(), rng.random());
                }
            }
            let mut reference = moved.clone();
            undo_searching_whole(&mut reference, &m.triangles, &m.positions, &before);
            let mut local = moved.clone();
            undo_new_crossings(&mut local, &m.triangles, &m.positions, &before);
            assert_ne!(reference, moved, "seed {seed}: nothing was put back");
            assert_eq!(local, reference, "seed {seed}");
            let after = crossing_faces(&local, &m.triangles);
            assert!(after.iter().all(|t| before.binary_search(t).is_ok()));
        }
        // A crossing that only putting a vertex back makes: x (on the upper sheet) raised
        // through the triangle above it is put back, and y (below it on the lower sheet), raised
        // under x's tent, then pierces the upper sheet: it goes back in the second round.
        let grid =
            |z: f64| crate::mesh::test_meshes::grid(4, |i, j| DVec3::new(i as f64, j as f64, z));
        let above = crate::mesh::TriMesh::new(
            vec![
                DVec3::new(1.2, 1.2, 2.0),
                DVec3::new(2.9, 1.5, 2.0),
                DVec3::new(1.8, 2.9, 2.0),
            ],
            vec![[0, 1, 2]],
        );
        let sheets = crate::mesh::test_meshes::union_of(&grid(0.0), &grid(1.0));
        let m = crate::mesh::test_meshes::union_of(&sheets, &above);
        let (y, x) = (2 * 5 + 2, 25 + 2 * 5 + 2);
        let mut moved = m.positions.clone();
        moved[x].z = 3.0;
        moved[y].z = 1.5;
        let mut reference = moved.clone();
        undo_searching_whole(&mut reference, &m.triangles, &m.positions, &[]);
        assert_eq!(reference, m.positions, "both go back");
        let mut local = moved;
        undo_new_crossings(&mut local, &m.triangles, &m.positions, &[]);
        assert_eq!(local, reference);
    }

    #[test]
    fn the_early_stopping_test_agrees_with_the_count() {
        let has = |m: &crate::mesh::TriMesh| {
            let boxes = face_boxes(&m.positions, &m.triangles);
            let bvh = crate::geometry::bvh::bvh_of(boxes.iter().copied());
            has_intersecting_pair(&bvh, &boxes, &m.positions, &m.triangles)
        };
        let mut sphere = uv_sphere(1.0, 12, 24);
        assert!(!has(&sphere));
        assert!(intersecting_pairs(&sphere.positions, &sphere.triangles).is_empty());
        // A vertex pushed through the far side: its fan crosses faces there.
        let k = 2 + 5 * 24;
        sphere.positions[k] = -1.5 * sphere.positions[k];
        assert!(has(&sphere));
        assert!(!intersecting_pairs(&sphere.positions, &sphere.triangles).is_empty());
        // Two boxes: apart, touching at a face (non-adjacent faces sharing points), crossing.
        for (lo, crossing) in [(3.0, false), (2.0, true), (1.0, true)] {
            let mut m = cuboid(DVec3::ZERO, DVec3::splat(2.0));
            let b = cuboid(DVec3::splat(lo), DVec3::splat(lo + 2.0));
            let off = m.positions.len() as u32;
            m.positions.extend(b.positions);
            m.triangles
                .extend(b.triangles.iter().map(|t| t.map(|v| v + off)));
            assert_eq!(has(&m), crossing, "{lo}");
            assert_eq!(
                !intersecting_pairs(&m.positions, &m.triangles).is_empty(),
                crossing
            );
        }
        // Fewer than two faces.
        let one = crate::mesh::TriMesh::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], vec![[0, 1, 2]]);
        assert!(!has(&one));
    }
}
