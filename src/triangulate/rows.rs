//! Each vertex's neighbours in a triangle mesh as rows of one array (compressed sparse rows):
//! the graph the restricted Delaunay triangulation grows its cells over and the topological ball
//! check reads them on.

use rayon::prelude::*;

/// Each vertex's neighbours in a triangle mesh, as rows of one array (compressed sparse rows),
/// each neighbour once (an interior edge is on two faces: offering a vertex twice the same
/// sample at the same distance changes nothing in the search, so the second entry only cost a
/// look).
pub(super) struct Rows {
    start: Vec<u32>,
    values: Vec<u32>,
}

impl Rows {
    /// The neighbours of the vertices `0..n` in `triangles`. Each face lists the head of each of
    /// its directed edges in the row of the edge's tail (three entries per face, not six: an
    /// edge inside a consistently oriented surface is listed once from each of its two faces);
    /// each row is then sorted and its repeats dropped, and the entries whose reverse is missing
    /// (boundary edges, faces oriented against their neighbours) are added: the same rows as
    /// listing both other corners of every face at each corner, in half the memory.
    pub(super) fn new(n: usize, triangles: &[[u32; 3]]) -> Self {
        let directed = |t: &[u32; 3]| {
            let t = *t;
            (0..3).map(move |k| (t[k], t[(k + 1) % 3]))
        };
        let (start, values) = Self::gather(n, triangles.iter().flat_map(directed));
        let rows = Rows { start, values };
        // The reverse entries that are missing, by row.
        let missing: Vec<(u32, u32)> = (0..n as u32)
            .into_par_iter()
            .flat_map_iter(|a| {
                let rows = &rows;
                rows.row(a)
                    .iter()
                    .filter(move |&&b| rows.row(b).binary_search(&a).is_err())
                    .map(move |&b| (b, a))
            })
            .collect();
        if missing.is_empty() {
            return rows;
        }
        let Rows { start, values } = rows;
        let existing = (0..n).flat_map(|v| {
            values[start[v] as usize..start[v + 1] as usize]
                .iter()
                .map(move |&u| (v as u32, u))
        });
        let (start, values) = Self::gather(n, existing.chain(missing.iter().copied()));
        Rows { start, values }
    }

    /// Rows of the pairs `(row, value)` (given twice: once to count, once to fill), each row
    /// sorted and its repeats dropped, in parallel over runs of rows.
    fn gather<I: Iterator<Item = (u32, u32)> + Clone>(n: usize, pairs: I) -> (Vec<u32>, Vec<u32>) {
        let mut start = vec![0u32; n + 1];
        for (r, _) in pairs.clone() {
            start[r as usize + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut fill: Vec<u32> = start[..n].to_vec();
        let mut values = vec![0u32; start[n] as usize];
        for (r, v) in pairs {
            values[fill[r as usize] as usize] = v;
            fill[r as usize] += 1;
        }
        drop(fill);
        // Sort and deduplicate each row in place, in parallel over runs of ROW_RUN rows; each
        // row's kept length, then the gaps closed.
        const ROW_RUN: usize = 1 << 14;
        let mut runs: Vec<(usize, &mut [u32])> = Vec::with_capacity(n.div_ceil(ROW_RUN));
        let mut rest = values.as_mut_slice();
        for first in (0..n).step_by(ROW_RUN) {
            let last = (first + ROW_RUN).min(n);
            let (run, tail) = rest.split_at_mut((start[last] - start[first]) as usize);
            runs.push((first, run));
            rest = tail;
        }
        let kept: Vec<u32> = runs
            .into_par_iter()
            .flat_map_iter(|(first, run)| {
                let last = (first + ROW_RUN).min(n);
                let base = start[first] as usize;
                let mut kept = Vec::with_capacity(last - first);
                for v in first..last {
                    let row = &mut run[start[v] as usize - base..start[v + 1] as usize - base];
                    row.sort_unstable();
                    let mut k = 0;
                    for i in 0..row.len() {
                        if i == 0 || row[i] != row[k - 1] {
                            row[k] = row[i];
                            k += 1;
                        }
                    }
                    kept.push(k as u32);
                }
                kept
            })
            .collect();
        let mut write = 0usize;
        let mut compact = vec![0u32; n + 1];
        for v in 0..n {
            let from = start[v] as usize;
            let len = kept[v] as usize;
            values.copy_within(from..from + len, write);
            write += len;
            compact[v + 1] = write as u32;
        }
        values.truncate(write);
        values.shrink_to_fit();
        (compact, values)
    }

    /// The index in `values` of `u` in the row of `v` (an edge's slot), if it is there.
    pub(super) fn slot(&self, v: u32, u: u32) -> Option<u32> {
        let from = self.start[v as usize];
        self.row(v).binary_search(&u).ok().map(|k| from + k as u32)
    }

    pub(super) fn row(&self, r: u32) -> &[u32] {
        &self.values[self.start[r as usize] as usize..self.start[r as usize + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes;
    use glam::DVec3;

    /// The rows from the directed edges are each vertex's neighbours over all its faces, on a
    /// closed surface, an open one (boundary edges are listed from one face only), one with
    /// faces turned against their neighbours and one with an edge of three faces.
    #[test]
    fn the_rows_list_every_neighbour_once() {
        let reference = |n: usize, triangles: &[[u32; 3]]| {
            let mut rows = vec![Vec::new(); n];
            for t in triangles {
                for k in 0..3 {
                    rows[t[k] as usize].extend([t[(k + 1) % 3], t[(k + 2) % 3]]);
                }
            }
            for r in &mut rows {
                r.sort_unstable();
                r.dedup();
            }
            rows
        };
        let sphere = test_meshes::uv_sphere(1.0, 8, 16);
        let open = test_meshes::grid(6, |i, j| DVec3::new(i as f64, j as f64, 0.0));
        let mut turned = open.clone();
        for t in turned.triangles.iter_mut().step_by(3) {
            t.swap(1, 2);
        }
        let mut fin = open.clone();
        fin.positions.push(DVec3::new(0.5, 0.0, 1.0));
        let apex = fin.positions.len() as u32 - 1;
        fin.triangles.push([0, 1, apex]);
        for mesh in [sphere, open, turned, fin] {
            let n = mesh.positions.len();
            let rows = Rows::new(n, &mesh.triangles);
            let want = reference(n, &mesh.triangles);
            for (v, want) in want.iter().enumerate() {
                assert_eq!(rows.row(v as u32), want.as_slice(), "vertex {v}");
            }
        }
    }
}
