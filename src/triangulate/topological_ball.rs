//! The topological ball property of the restricted Voronoi cells, checked on the discrete cells
//! of `restricted_delaunay` (each refined vertex of the input labelled with its sample) and
//! enforced by inserting samples where it fails.
//!
//! When every restricted Voronoi cell is a closed disc and every two cells meet in at most one
//! arc, the restricted Delaunay triangulation is homeomorphic to the surface (H. Edelsbrunner,
//! N. Shah, "Triangulating topological spaces", IJCGA 7(4), 1997). Where a cell is not a disc (it
//! wraps around a tube or a hole thinner than the spacing, or covers a small part whole) or two
//! cells meet in two arcs (across a wall or a gap), a sample is inserted at the point of the
//! offending cell farthest from its sample, the discrete counterpart of the centre of its
//! largest surface Delaunay ball, and only the cells it takes over change: the refinement of
//! J.-D. Boissonnat, S. Oudot, "Provably good sampling and meshing of surfaces", Graphical
//! Models 67(5), 2005, and of CGAL's surface mesher with `Manifold_tag` (a vertex is bad when its
//! restricted facets do not form one disc); S.-W. Cheng, T. K. Dey, E. A. Ramos, "Manifold
//! reconstruction from point samples", SODA 2005 / "Delaunay refinement for piecewise smooth
//! complexes", DCG 2007.
//!
//! On the discrete cells: a cell (the refined vertices of one label, the edges and faces among
//! them) is a disc when it is connected and its Euler characteristic V − E + F is 1 (a
//! connected part of an orientable surface with χ = 1 is a disc); two cells meet in one arc when
//! the refined edges between them (mixed edges of that pair) form one chain of faces, and that
//! chain ends (at a face of three cells or on the input's boundary) rather than closing on
//! itself.

use glam::DVec3;
use rustc_hash::FxHashMap;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

use rayon::prelude::*;

use super::rows::Rows;
use crate::disjoint_sets::Dsu;

/// Parameters of [`enforce`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TopologicalBallParams {
    /// Whether the property is checked and enforced at all (default true).
    pub enabled: bool,
    /// The most rounds of check and insertion (default 24): each round inserts one sample per
    /// offending cell or pair.
    pub max_rounds: usize,
    /// The most samples inserted, as a fraction of the samples (default 0.5), plus
    /// [`MIN_INSERTIONS`].
    pub max_added_fraction: f64,
}

impl Default for TopologicalBallParams {
    fn default() -> Self {
        TopologicalBallParams {
            enabled: true,
            max_rounds: 24,
            max_added_fraction: 0.5,
        }
    }
}

/// Insertions allowed whatever the sample count (a small closed part needs four samples to be a
/// tetrahedron).
pub const MIN_INSERTIONS: usize = 64;

/// What [`enforce`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct TopologicalBallStats {
    /// Samples inserted.
    pub inserted: usize,
    /// Rounds of check and insertion run.
    pub rounds: usize,
    /// Cells that were not discs at the first check.
    pub bad_cells_first: usize,
    /// Pairs of cells meeting in more than one arc at the first check.
    pub bad_pairs_first: usize,
    /// Cells still not discs after the last round (0 when the property holds).
    pub bad_cells_left: usize,
    /// Pairs of cells still meeting in more than one arc after the last round.
    pub bad_pairs_left: usize,
}

/// The refined input the cells live on.
pub(super) struct Refined<'a> {
    pub positions: &'a [DVec3],
    pub triangles: &'a [[u32; 3]],
    pub neighbours: &'a Rows,
}

/// Checks the cells `label` (one sample index per refined vertex, `u32::MAX` for none) of the
/// samples `samples` and inserts samples until every cell is a disc and every two cells meet in
/// at most one arc, or the rounds or the insertions run out. Returns the inserted samples (at
/// refined vertices, so on the input; their labels are `samples.len()` onwards, in order) and
/// what was done; `label` is updated.
pub(super) fn enforce(
    refined: &Refined,
    samples: &[DVec3],
    label: &mut [u32],
    params: &TopologicalBallParams,
) -> (Vec<DVec3>, TopologicalBallStats) {
    checked_in_scope(refined, samples, label, params, true)
}

/// [`enforce`], the checks after the first one over the cells a round changed, and the cells
/// made connected again among those the round took vertices from (`incremental`), or over
/// every cell (the same answer, at more cost: the tests compare them).
fn checked_in_scope(
    refined: &Refined,
    samples: &[DVec3],
    label: &mut [u32],
    params: &TopologicalBallParams,
    incremental: bool,
) -> (Vec<DVec3>, TopologicalBallStats) {
    let mut stats = TopologicalBallStats::default();
    let mut added: Vec<DVec3> = Vec::new();
    if !params.enabled {
        return (added, stats);
    }
    let budget = (params.max_added_fraction * samples.len() as f64) as usize + MIN_INSERTIONS;
    let site = |l: u32, added: &[DVec3]| {
        let l = l as usize;
        if l < samples.len() {
            samples[l]
        } else {
            added[l - samples.len()]
        }
    };
    let mut dist: Vec<f64> = label
        .iter()
        .zip(refined.positions)
        .map(|(&l, &p)| {
            if l == u32::MAX {
                f64::INFINITY
            } else {
                p.distance(site(l, &added))
            }
        })
        .collect();
    // A cell grown in pieces (a piece reached through vertices later taken by a nearer sample)
    // is made one before it is judged: its other pieces go to the cells around them.
    connect_cells(refined, label, &mut dist, samples.len(), None, |l| {
        site(l, &added)
    });
    // The first check looks at every cell; the next ones only at the cells a round changed
    // (that lost or gained refined vertices, or border one that did) and at those that failed
    // before: the others are as they were, and passed.
    let mut scope: Option<Scope> = None;
    loop {
        let count = samples.len() + added.len();
        let (cells, pairs) = offending(refined, label, count, scope.as_ref());
        if stats.rounds == 0 {
            stats.bad_cells_first = cells.len();
            stats.bad_pairs_first = pairs.len();
        }
        stats.bad_cells_left = cells.len();
        stats.bad_pairs_left = pairs.len();
        if (cells.is_empty() && pairs.is_empty())
            || stats.rounds >= params.max_rounds
            || added.len() >= budget
        {
            break;
        }
        stats.rounds += 1;
        let candidates = insertion_points(refined, label, &dist, &cells, &pairs, scope.as_ref());
        let before = label.to_vec();
        // One insertion per offending cell or pair, farthest first; a candidate whose vertex an
        // earlier insertion of this round took over is left (its cell changed).
        let start_label: Vec<(u32, u32)> = candidates
            .iter()
            .map(|&(_, v)| (v, label[v as usize]))
            .collect();
        // The cells the insertions took refined vertices from: only they can have come apart.
        let mut lost: Vec<u32> = Vec::new();
        for (&(_, v), &(_, l0)) in candidates.iter().zip(&start_label) {
            if added.len() >= budget {
                break;
            }
            if label[v as usize] != l0 || dist[v as usize] == 0.0 {
                continue;
            }
            let x = refined.positions[v as usize];
            let s = (samples.len() + added.len()) as u32;
            added.push(x);
            take_over(refined, label, &mut dist, s, v, x, &mut lost);
        }
        let count = samples.len() + added.len();
        let mut torn = vec![false; count];
        for l in lost {
            torn[l as usize] = true;
        }
        let torn = incremental.then_some(&torn[..]);
        connect_cells(refined, label, &mut dist, count, torn, |l| site(l, &added));
        stats.inserted = added.len();
        scope = incremental.then(|| Scope::changed(refined, &before, label, count, &cells, &pairs));
    }
    (added, stats)
}

/// The refined vertices nearer to the new sample `s` at `x` (refined vertex `v`) than to their
/// own, reached from `v` through such vertices, relabelled `s`; the labels they had are pushed
/// to `lost` (`u32::MAX` left out; a label may come more than once).
fn take_over(
    refined: &Refined,
    label: &mut [u32],
    dist: &mut [f64],
    s: u32,
    v: u32,
    x: DVec3,
    lost: &mut Vec<u32>,
) {
    let mut take = |u: u32, d: f64, label: &mut [u32], dist: &mut [f64]| {
        let l = std::mem::replace(&mut label[u as usize], s);
        if l != u32::MAX && lost.last() != Some(&l) {
            lost.push(l);
        }
        dist[u as usize] = d;
    };
    take(v, 0.0, label, dist);
    let mut stack = vec![v];
    while let Some(a) = stack.pop() {
        for &b in refined.neighbours.row(a) {
            let d = refined.positions[b as usize].distance(x);
            if d < dist[b as usize] {
                take(b, d, label, dist);
                stack.push(b);
            }
        }
    }
}

/// Each cell made connected again after insertions took parts of it over: the vertices of a
/// cell not joined to its vertex nearest its sample through the cell are labelled anew, by a
/// search from the cells around them (the nearest sample that reaches them, as
/// `restricted_delaunay` grows the cells). Afterwards every cell is connected.
///
/// `torn`: per label, whether the cell may have come apart (the others are connected, as this
/// function left them); `None`: any may have.
fn connect_cells(
    refined: &Refined,
    label: &mut [u32],
    dist: &mut [f64],
    count: usize,
    torn: Option<&[bool]>,
    site: impl Fn(u32) -> DVec3,
) {
    let n = refined.positions.len();
    let checked = |l: u32| l != u32::MAX && torn.is_none_or(|t| t[l as usize]);
    if torn.is_some_and(|t| !t.contains(&true)) {
        return;
    }
    let mut anchor = vec![(f64::INFINITY, u32::MAX); count];
    for v in 0..n {
        let l = label[v];
        if checked(l) && (dist[v], v as u32) < anchor[l as usize] {
            anchor[l as usize] = (dist[v], v as u32);
        }
    }
    // Per refined vertex: whether it is labelled and joined to its cell's anchor (the cells not
    // checked are).
    let mut joined: Vec<bool> = label
        .iter()
        .map(|&l| l != u32::MAX && !checked(l))
        .collect();
    let mut stack: Vec<u32> = anchor
        .iter()
        .filter(|a| a.1 != u32::MAX)
        .map(|a| a.1)
        .collect();
    for &v in &stack {
        joined[v as usize] = true;
    }
    while let Some(v) = stack.pop() {
        let l = label[v as usize];
        for &u in refined.neighbours.row(v) {
            if !joined[u as usize] && label[u as usize] == l {
                joined[u as usize] = true;
                stack.push(u);
            }
        }
    }
    let mut heap: BinaryHeap<Reverse<(u64, u32, u32)>> = BinaryHeap::new();
    let mut orphans = false;
    for v in 0..n {
        if label[v] != u32::MAX && !joined[v] {
            label[v] = u32::MAX;
            dist[v] = f64::INFINITY;
            orphans = true;
        }
    }
    if !orphans {
        return;
    }
    for v in 0..n as u32 {
        let l = label[v as usize];
        if l != u32::MAX
            && refined
                .neighbours
                .row(v)
                .iter()
                .any(|&u| label[u as usize] == u32::MAX && dist[u as usize].is_infinite())
        {
            heap.push(Reverse((dist[v as usize].to_bits(), l, v)));
        }
    }
    let mut done = joined;
    while let Some(Reverse((_, s, v))) = heap.pop() {
        if label[v as usize] != s {
            continue;
        }
        let x = site(s);
        for &u in refined.neighbours.row(v) {
            let i = u as usize;
            if done[i] {
                continue;
            }
            let d = refined.positions[i].distance(x);
            if d < dist[i] || (d == dist[i] && s < label[i]) {
                dist[i] = d;
                label[i] = s;
                heap.push(Reverse((d.to_bits(), s, u)));
            }
        }
        done[v as usize] = true;
    }
}

/// The part of the refined input a check looks at: the cells of some labels (`dirty`), all of
/// their refined vertices and the faces at them. Cells, pairs and triples of cells none of
/// which is dirty are not judged.
struct Scope {
    /// Per label: whether it is checked.
    dirty: Vec<bool>,
    /// The refined vertices with a dirty label, ascending.
    vertices: Vec<u32>,
    /// The refined faces with a corner of a dirty label, ascending.
    faces: Vec<u32>,
}

impl Scope {
    /// The cells a round changed, from the labels `before` it to `label` after it (`count`
    /// labels): those that lost or gained a refined vertex and those next to such a vertex,
    /// and the cells of the offending `cells` and `pairs` the round was for.
    fn changed(
        refined: &Refined,
        before: &[u32],
        label: &[u32],
        count: usize,
        cells: &[u32],
        pairs: &[[u32; 2]],
    ) -> Scope {
        let mut dirty = vec![false; count];
        let mut mark = |l: u32| {
            if l != u32::MAX {
                dirty[l as usize] = true;
            }
        };
        for (v, (&b, &a)) in before.iter().zip(label).enumerate() {
            if a != b {
                mark(b);
                mark(a);
                for &u in refined.neighbours.row(v as u32) {
                    mark(label[u as usize]);
                }
            }
        }
        for &c in cells {
            mark(c);
        }
        for &[a, b] in pairs {
            mark(a);
            mark(b);
        }
        let is_dirty = |v: u32| {
            let l = label[v as usize];
            l != u32::MAX && dirty[l as usize]
        };
        let vertices = (0..label.len() as u32).filter(|&v| is_dirty(v)).collect();
        let faces = (0..refined.triangles.len() as u32)
            .filter(|&f| refined.triangles[f as usize].iter().any(|&v| is_dirty(v)))
            .collect();
        Scope {
            dirty,
            vertices,
            faces,
        }
    }
}

/// The cells that are not discs, or that meet two others in more than one point (labels,
/// ascending), and the pairs of cells that meet in more than one arc or in a closed curve
/// (ascending), of `count` labels.
fn offending(
    refined: &Refined,
    label: &[u32],
    count: usize,
    scope: Option<&Scope>,
) -> (Vec<u32>, Vec<[u32; 2]>) {
    let n = refined.positions.len();
    // The vertices and faces looked at: all, or the scope's (one of the two parts of each
    // chain is empty).
    let (all_vertices, all_faces, listed_vertices, listed_faces) = match scope {
        Some(s) => (0..0, 0..0, &s.vertices[..], &s.faces[..]),
        None => (
            0..n as u32,
            0..refined.triangles.len() as u32,
            &[][..],
            &[][..],
        ),
    };
    let vertices = || all_vertices.clone().chain(listed_vertices.iter().copied());
    let faces = || all_faces.clone().chain(listed_faces.iter().copied());
    let judged = |l: u32| l != u32::MAX && scope.is_none_or(|s| s.dirty[l as usize]);
    // Per label: vertices, edges and faces inside the cell. Every cell is connected
    // (`connect_cells` made it so), so a cell is a disc when its Euler characteristic is 1.
    let mut chi = vec![0i64; count];
    let mut present = vec![false; count];
    for v in vertices() {
        let l = label[v as usize];
        if l == u32::MAX {
            continue;
        }
        chi[l as usize] += 1;
        present[l as usize] = true;
        for &u in refined.neighbours.row(v) {
            if u > v && label[u as usize] == l {
                chi[l as usize] -= 1;
            }
        }
    }
    for f in faces() {
        let t = refined.triangles[f as usize];
        let l = label[t[0] as usize];
        if l != u32::MAX && label[t[1] as usize] == l && label[t[2] as usize] == l {
            chi[l as usize] += 1;
        }
    }
    let cells: Vec<u32> = (0..count)
        .filter(|&l| judged(l as u32) && present[l] && chi[l] != 1)
        .map(|l| l as u32)
        .collect();
    // Pairs of cells that meet in more than one arc or in a closed curve, from the faces at
    // their mixed edges (edges between two cells): one record per face and mixed edge, sorted
    // by pair, each pair's arcs counted on its own (`pair_offends`). The pairs judged are those
    // with a judged cell: all their mixed edges and the faces on them are in the scope.
    let records = |f: u32| {
        let t = refined.triangles[f as usize];
        let l = t.map(|v| label[v as usize]);
        let key = |a: u32, b: u32| (u64::from(a.min(b)) << 32) | u64::from(a.max(b));
        let labelled = !l.contains(&u32::MAX);
        let three = labelled && l[0] != l[1] && l[1] != l[2] && l[0] != l[2];
        let mixed = [0, 1, 2].map(|k| {
            let (a, b) = (l[k], l[(k + 1) % 3]);
            a != b && a != u32::MAX && b != u32::MAX && (judged(a) || judged(b))
        });
        // An edge by its slot in the row of its lower vertex.
        let edge = |k: usize| {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            refined
                .neighbours
                .slot(a.min(b), a.max(b))
                .unwrap_or(NO_PARTNER)
        };
        // A face of two cells (no vertex unlabelled) has two mixed edges, which it joins: one
        // record for both.
        if labelled && !three && mixed.iter().filter(|&&m| m).count() == 2 {
            let mut two = (0..3).filter(|&k| mixed[k]);
            let (a, b) = (two.next().unwrap_or(0), two.next().unwrap_or(0));
            let (ea, eb) = (edge(a), edge(b));
            return [
                Some((key(l[a], l[(a + 1) % 3]), ea.min(eb), ea.max(eb))),
                None,
                None,
            ];
        }
        [0, 1, 2].map(|k| {
            mixed[k].then(|| {
                let partner = if three { ARC_END } else { NO_PARTNER };
                (key(l[k], l[(k + 1) % 3]), edge(k), partner)
            })
        })
    };
    let mut recs: Vec<(u64, u32, u32)> = match scope {
        Some(s) => s
            .faces
            .par_iter()
            .flat_map_iter(|&f| records(f).into_iter().flatten())
            .collect(),
        None => (0..refined.triangles.len() as u32)
            .into_par_iter()
            .flat_map_iter(|f| records(f).into_iter().flatten())
            .collect(),
    };
    recs.par_sort_unstable();
    let pairs: Vec<[u32; 2]> = recs
        .par_chunk_by(|a, b| a.0 == b.0)
        .map_init(Vec::new, |edges, group| {
            let pair = [(group[0].0 >> 32) as u32, group[0].0 as u32];
            pair_offends(group, edges).then_some(pair)
        })
        .flatten()
        .collect();
    drop(recs);
    // Three cells meet in at most one point: the faces of three cells of one triple, joined
    // where they share an edge, are one group. Where they are not, the three cells are judged
    // as cells that are not discs.
    let mut triples: Vec<([u32; 3], usize)> = faces()
        .filter_map(|f| {
            let f = f as usize;
            let mut l = refined.triangles[f].map(|v| label[v as usize]);
            if l.contains(&u32::MAX) || l[0] == l[1] || l[1] == l[2] || l[0] == l[2] {
                return None;
            }
            l.sort_unstable();
            Some((l, f))
        })
        .collect();
    triples.sort_unstable();
    let mut cells = cells;
    for group in triples.chunk_by(|a, b| a.0 == b.0) {
        if group.len() < 2 || !group[0].0.iter().any(|&l| judged(l)) {
            continue;
        }
        let shares_edge = |f: usize, g: usize| {
            let (a, b) = (refined.triangles[f], refined.triangles[g]);
            a.iter().filter(|v| b.contains(v)).count() >= 2
        };
        let mut sets = Dsu::new(group.len());
        for i in 0..group.len() {
            for j in i + 1..group.len() {
                if shares_edge(group[i].1, group[j].1) {
                    sets.union(i, j, false);
                }
            }
        }
        if (0..group.len()).any(|i| sets.find(i).0 != sets.find(0).0) {
            cells.extend(group[0].0);
        }
    }
    cells.sort_unstable();
    cells.dedup();
    (cells, pairs)
}

/// [`offending`]'s record of a mixed edge on a face of three cells: it ends the arc through it.
const ARC_END: u32 = u32::MAX;
/// [`offending`]'s record of a mixed edge on a face with an unlabelled vertex: neither joined
/// nor ended there.
const NO_PARTNER: u32 = u32::MAX - 1;

/// Whether two cells meet in more than one arc or in a closed curve, from the records of their
/// mixed edges (`group`, sorted: (pair, edge, other) per face on a mixed edge, the pair as two
/// labels, edges by their slots in the refined input's rows; a face of the two cells gives one
/// record of its two mixed edges, a face of three cells one per edge with [`ARC_END`], a face
/// with an unlabelled vertex one per edge with [`NO_PARTNER`]). The mixed edges joined through
/// faces of the two cells are arcs; an arc is ended by a face of three cells on one of its
/// edges or by an edge of one face (on the input's boundary); an arc with no end is a closed
/// curve. `edges`: scratch.
fn pair_offends(group: &[(u64, u32, u32)], edges: &mut Vec<u32>) -> bool {
    let joins = |other: u32| other != ARC_END && other != NO_PARTNER;
    edges.clear();
    for &(_, e, other) in group {
        edges.push(e);
        if joins(other) {
            edges.push(other);
        }
    }
    edges.sort_unstable();
    edges.dedup();
    let at = |e: u32| edges.binary_search(&e).unwrap_or(0);
    let mut arcs = Dsu::new(edges.len());
    // Per edge: the faces on it, and whether a face of three cells is one of them.
    let mut faces_on = vec![0u32; edges.len()];
    let mut ends = vec![false; edges.len()];
    for &(_, e, other) in group {
        let i = at(e);
        faces_on[i] += 1;
        if other == ARC_END {
            ends[i] = true;
        } else if joins(other) {
            let j = at(other);
            faces_on[j] += 1;
            arcs.union(i, j, false);
        }
    }
    let first = arcs.find(0).0;
    let one_arc = (0..edges.len()).all(|i| arcs.find(i).0 == first);
    !one_arc || !(0..edges.len()).any(|i| ends[i] || faces_on[i] == 1)
}

/// Where to insert for the offending `cells` and `pairs`: for a cell, its refined vertex
/// farthest from its sample; for a pair, the vertex of either cell on their common boundary
/// farthest from its own sample. (distance, vertex), farthest first, ties to the lower vertex;
/// each vertex once.
fn insertion_points(
    refined: &Refined,
    label: &[u32],
    dist: &[f64],
    cells: &[u32],
    pairs: &[[u32; 2]],
    scope: Option<&Scope>,
) -> Vec<(f64, u32)> {
    let n = refined.positions.len();
    let (all, listed) = match scope {
        Some(s) => (0..0, &s.vertices[..]),
        None => (0..n as u32, &[][..]),
    };
    let outside = |l: u32| scope.is_some_and(|s| !s.dirty[l as usize]);
    let mut cell_best: FxHashMap<u32, (f64, u32)> = cells.iter().map(|&c| (c, (-1.0, 0))).collect();
    let mut pair_best: FxHashMap<[u32; 2], (f64, u32)> =
        pairs.iter().map(|&p| (p, (-1.0, 0))).collect();
    let better = |best: &mut (f64, u32), d: f64, v: u32| {
        if d > best.0 || (d == best.0 && v < best.1) {
            *best = (d, v);
        }
    };
    for v in all.chain(listed.iter().copied()) {
        let l = label[v as usize];
        if l == u32::MAX {
            continue;
        }
        let d = dist[v as usize];
        if let Some(best) = cell_best.get_mut(&l) {
            better(best, d, v);
        }
        if !pair_best.is_empty() {
            for &u in refined.neighbours.row(v) {
                let k = label[u as usize];
                if k != l && k != u32::MAX {
                    if let Some(best) = pair_best.get_mut(&[l.min(k), l.max(k)]) {
                        better(best, d, v);
                        // A vertex outside the scope is not visited itself.
                        if outside(k) {
                            better(best, dist[u as usize], u);
                        }
                    }
                }
            }
        }
    }
    let mut out: Vec<(f64, u32)> = cell_best
        .into_values()
        .chain(pair_best.into_values())
        .filter(|&(d, _)| d > 0.0)
        .collect();
    out.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    out.dedup_by_key(|x| x.1);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes;

    fn rows(positions: &[DVec3], triangles: &[[u32; 3]]) -> Rows {
        Rows::new(positions.len(), triangles)
    }

    /// Triangles of `bands` bands of quads between rings of `around` vertices (ring j's
    /// vertices numbered j · around onward, ring `rings` being ring 0 again: a torus when
    /// `bands == rings`, a tube when `rings == bands + 1`).
    fn ring_grid(around: usize, rings: usize, bands: usize) -> Vec<[u32; 3]> {
        let id = |i: usize, j: usize| ((j % rings) * around + i % around) as u32;
        let mut triangles = Vec::new();
        for j in 0..bands {
            for i in 0..around {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        triangles
    }

    /// Nearest-sample labels (no growth: enough on convex test shapes).
    fn nearest(positions: &[DVec3], samples: &[DVec3]) -> Vec<u32> {
        positions
            .iter()
            .map(|p| {
                (0..samples.len() as u32)
                    .min_by(|&a, &b| {
                        p.distance(samples[a as usize])
                            .total_cmp(&p.distance(samples[b as usize]))
                    })
                    .unwrap()
            })
            .collect()
    }

    #[test]
    fn one_sample_on_a_sphere_is_not_a_disc_and_four_are_enough() {
        let mesh = test_meshes::uv_sphere(1.0, 24, 48);
        let neighbours = rows(&mesh.positions, &mesh.triangles);
        let refined = Refined {
            positions: &mesh.positions,
            triangles: &mesh.triangles,
            neighbours: &neighbours,
        };
        let samples = [DVec3::new(0.0, 0.0, 1.0)];
        let mut label = nearest(&mesh.positions, &samples);
        let (cells, _) = offending(&refined, &label, 1, None);
        assert_eq!(cells, vec![0]);
        let (added, stats) = enforce(&refined, &samples, &mut label, &Default::default());
        assert_eq!(stats.bad_cells_left + stats.bad_pairs_left, 0, "{stats:?}");
        assert!(added.len() >= 3 && added.len() <= 6, "{stats:?}");
        let (cells, pairs) = offending(&refined, &label, 1 + added.len(), None);
        assert!(cells.is_empty() && pairs.is_empty());
    }

    /// Whether the refined vertices of each label are joined through vertices of that label.
    fn every_cell_connected(refined: &Refined, label: &[u32]) -> bool {
        let mut dsu = Dsu::new(label.len());
        for v in 0..label.len() as u32 {
            for &u in refined.neighbours.row(v) {
                if label[u as usize] == label[v as usize] {
                    dsu.union(v as usize, u as usize, false);
                }
            }
        }
        let mut root: FxHashMap<u32, usize> = FxHashMap::default();
        (0..label.len()).all(|v| {
            let r = dsu.find(v).0;
            label[v] == u32::MAX || *root.entry(label[v]).or_insert(r) == r
        })
    }

    /// The check judges a cell by its Euler characteristic alone, which holds only for a
    /// connected cell: a cell in two pieces (each a disc: χ = 2) is made one by
    /// `connect_cells`, its far piece going to the cell around it, whether every cell is looked
    /// at or only the torn ones.
    #[test]
    fn a_cell_in_pieces_is_made_one() {
        let n = 12;
        let mesh = test_meshes::grid(n, |i, j| DVec3::new(i as f64, j as f64, 0.0));
        let neighbours = rows(&mesh.positions, &mesh.triangles);
        let refined = Refined {
            positions: &mesh.positions,
            triangles: &mesh.triangles,
            neighbours: &neighbours,
        };
        let samples = [DVec3::new(0.0, 0.0, 0.0), DVec3::new(8.0, 8.0, 0.0)];
        // Sample 0's cell: the corner square around it and the far corner's square, cut off by
        // sample 1's cell.
        let in_square = |p: DVec3, c: f64| (p.x - c).abs() <= 1.0 && (p.y - c).abs() <= 1.0;
        let start: Vec<u32> = mesh
            .positions
            .iter()
            .map(|&p| u32::from(!(in_square(p, 0.0) || in_square(p, 12.0))))
            .collect();
        assert!(!every_cell_connected(&refined, &start));
        let (cells, _) = offending(&refined, &start, 2, None);
        assert_eq!(cells, vec![0], "χ 2 for the two pieces");
        for torn in [None, Some(&[true, false][..])] {
            let mut label = start.clone();
            let mut dist: Vec<f64> = label
                .iter()
                .zip(&mesh.positions)
                .map(|(&l, p)| p.distance(samples[l as usize]))
                .collect();
            connect_cells(&refined, &mut label, &mut dist, 2, torn, |l| {
                samples[l as usize]
            });
            assert!(every_cell_connected(&refined, &label), "{torn:?}");
            let far = mesh.positions.iter().position(|p| in_square(*p, 12.0));
            assert_eq!(far.map(|v| label[v]), Some(1), "{torn:?}");
            let (cells, pairs) = offending(&refined, &label, 2, None);
            assert!(cells.is_empty() && pairs.is_empty(), "{cells:?} {pairs:?}");
        }
    }

    #[test]
    fn well_spread_samples_on_a_sphere_need_nothing() {
        let mesh = test_meshes::uv_sphere(10.0, 64, 128);
        let neighbours = rows(&mesh.positions, &mesh.triangles);
        let refined = Refined {
            positions: &mesh.positions,
            triangles: &mesh.triangles,
            neighbours: &neighbours,
        };
        let samples: Vec<DVec3> = test_meshes::fibonacci_sphere(60)
            .into_iter()
            .map(|u| 10.0 * u)
            .collect();
        let mut label = nearest(&mesh.positions, &samples);
        let (added, stats) = enforce(&refined, &samples, &mut label, &Default::default());
        assert_eq!(
            (added.len(), stats.bad_cells_first, stats.bad_pairs_first),
            (0, 0, 0)
        );
    }

    /// Two samples on a thin tube, one at each end: each cell wraps around the tube (an
    /// annulus is no disc: a sample is inserted until none does).
    #[test]
    fn cells_around_a_thin_tube_are_split() {
        // A tube of radius 0.2 and length 4 (open ends), 16 around, 40 along.
        let (around, along) = (16usize, 40usize);
        let mut positions = Vec::new();
        for j in 0..=along {
            for i in 0..around {
                let a = std::f64::consts::TAU * i as f64 / around as f64;
                positions.push(DVec3::new(
                    0.2 * a.cos(),
                    0.2 * a.sin(),
                    4.0 * j as f64 / along as f64,
                ));
            }
        }
        let triangles = ring_grid(around, along + 1, along);
        let neighbours = rows(&positions, &triangles);
        let refined = Refined {
            positions: &positions,
            triangles: &triangles,
            neighbours: &neighbours,
        };
        let samples = [DVec3::new(0.2, 0.0, 1.0), DVec3::new(-0.2, 0.0, 3.0)];
        let mut label = nearest(&positions, &samples);
        let (cells, _) = offending(&refined, &label, 2, None);
        assert_eq!(cells, vec![0, 1], "annuli");
        let (added, stats) = enforce(&refined, &samples, &mut label, &Default::default());
        assert!(!added.is_empty());
        assert_eq!(stats.bad_cells_left + stats.bad_pairs_left, 0, "{stats:?}");
    }

    /// The checks after the first look only at the cells a round changed: the same samples
    /// are inserted, the same cells come out, in the same rounds, as when every check looks at
    /// every cell. A torus (R 3, r 0.5) with a few samples: cells wrap around the tube and
    /// meet across it, over several rounds.
    #[test]
    fn the_checks_over_the_changed_cells_agree_with_checks_over_all() {
        let (around, along) = (16usize, 96usize);
        let mut positions = Vec::new();
        for j in 0..along {
            let b = std::f64::consts::TAU * j as f64 / along as f64;
            for i in 0..around {
                let a = std::f64::consts::TAU * i as f64 / around as f64;
                let rho = 3.0 + 0.5 * a.cos();
                positions.push(DVec3::new(rho * b.cos(), rho * b.sin(), 0.5 * a.sin()));
            }
        }
        let triangles = ring_grid(around, along, along);
        let neighbours = rows(&positions, &triangles);
        let refined = Refined {
            positions: &positions,
            triangles: &triangles,
            neighbours: &neighbours,
        };
        for k in [1usize, 2, 3, 5, 8] {
            let samples: Vec<DVec3> = (0..k)
                .map(|i| positions[(i * 7 * around + (i * 5) % around) % positions.len()])
                .collect();
            let start = nearest(&positions, &samples);
            let (mut a, mut b) = (start.clone(), start);
            let params = TopologicalBallParams::default();
            let scoped = checked_in_scope(&refined, &samples, &mut a, &params, true);
            let full = checked_in_scope(&refined, &samples, &mut b, &params, false);
            assert!(scoped.1.rounds >= 2, "{k} samples: {:?}", scoped.1);
            assert_eq!(scoped, full, "{k} samples");
            assert_eq!(a, b, "{k} samples");
            assert_eq!(
                scoped.1.bad_cells_left + scoped.1.bad_pairs_left,
                0,
                "{:?}",
                scoped.1
            );
        }
    }
}
