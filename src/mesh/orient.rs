//! Consistent orientation of a triangle mesh: faces flipped so that each edge shared by two
//! faces is traversed once each way, per connected component, with closed components turned
//! outward.
//!
//! Source: the breadth-first re-orientation every mesh tool has: trimesh's
//! `repair.fix_winding` / `fix_inversion` (`fix_normals`), MeshLab's "Re-Orient all faces
//! coherently" (`vcg::tri::Clean::OrientCoherentlyMesh`); see Botsch, Kobbelt, Pauly, Alliez,
//! Lévy, *Polygon Mesh Processing*, 2010, Ch. 1 (orientability).

use serde::Serialize;

use super::TriMesh;

/// What [`orient_consistently`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct OrientStats {
    /// Components: faces connected through manifold edges (edges in exactly two faces).
    pub components: usize,
    /// Manifold edges whose two faces traversed them the same way in the input (0 for a
    /// consistently oriented input).
    pub inconsistent_edges: usize,
    /// Faces whose orientation was reversed.
    pub faces_flipped: usize,
    /// Closed components (no boundary and no non-manifold edge) whose faces mostly (by area)
    /// faced inward, turned outward as a whole (with `closed_outward` only).
    pub components_turned_outward: usize,
    /// Components that cannot be oriented consistently (a Möbius strip, a Klein bottle).
    pub non_orientable_components: usize,
    /// Faces in those components.
    pub non_orientable_faces: usize,
    /// Edges of those components whose two faces still traverse them the same way after the
    /// walk (the seam where the orientation has to reverse; at least one per such component).
    pub seam_edges: usize,
}

/// No neighbour across a face side.
const NONE: u32 = u32::MAX;

/// Orients `mesh` consistently, in place: in each component (faces connected through manifold
/// edges, edges in exactly two faces), every manifold edge ends up traversed once each way.
///
/// A breadth-first walk from each component's first face flips a neighbour that traverses the
/// shared edge in the same direction as the current face. Of the two consistent orientations
/// of a component, an open one keeps the one that keeps more of its area as it was (so a small
/// reversed region is what gets flipped, not the rest), and so does a closed one (every side
/// of its faces on a manifold edge) unless `closed_outward`, which gives it the orientation of
/// positive signed volume (outward). A component the walk
/// reaches with both orientations at some face is non-orientable: it keeps the walk's
/// orientation (consistent everywhere but across [`OrientStats::seam_edges`]), with the larger
/// area as it was, and is counted. Sides with a repeated index (`[a, a, b]`) and edges in one
/// or in three or more faces join nothing; the faces' corners are rotated only by a flip
/// (`[a, b, c]` → `[a, c, b]`), never reordered otherwise, and face order is kept, so a mesh
/// that is already consistently oriented (and outward where closed, with `closed_outward`) is
/// left exactly as it is.
///
/// Time: O(V + F) (a counting sort of the edges by their lower vertex, one walk), times the
/// log of the largest vertex degree (each vertex's edges are sorted).
///
/// Does not fail; indices must be in range (as [`TriMesh::check_indices`] ensures).
///
/// Source: trimesh's `repair.fix_winding` and `fix_inversion`; MeshLab's "Re-Orient all faces
/// coherently" (`vcg::tri::Clean::OrientCoherentlyMesh`).
pub fn orient_consistently(mesh: &mut TriMesh, closed_outward: bool) -> OrientStats {
    let n = mesh.triangles.len();
    // Half-edge h = 3f + k is side k of face f, from corner k to corner k + 1.
    let tail = |h: usize| mesh.triangles[h / 3][h % 3];
    let head = |h: usize| mesh.triangles[h / 3][(h % 3 + 1) % 3];
    // The half-edges of each undirected edge {lo, hi}, bucketed by lo (a counting sort) and
    // sorted by hi within a bucket (a vertex's few edges).
    let v = mesh.positions.len();
    let mut start = vec![0u32; v + 1];
    for h in 0..3 * n {
        let (a, b) = (tail(h), head(h));
        if a != b {
            start[a.min(b) as usize + 1] += 1;
        }
    }
    for i in 0..v {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    // (hi, half-edge) per bucket.
    let mut bucket = vec![(0u32, 0u32); start[v] as usize];
    for h in 0..3 * n {
        let (a, b) = (tail(h), head(h));
        if a != b {
            let slot = &mut fill[a.min(b) as usize];
            bucket[*slot as usize] = (a.max(b), h as u32);
            *slot += 1;
        }
    }
    drop(fill);
    // The twin of each half-edge across a manifold edge (two sides of two different faces).
    let mut twin = vec![NONE; 3 * n];
    // Whether each side lies on a boundary or non-manifold edge (the face's component is open).
    let mut open_side = vec![false; 3 * n];
    let mut inconsistent_edges = 0;
    for lo in 0..v {
        let edges = &mut bucket[start[lo] as usize..start[lo + 1] as usize];
        edges.sort_unstable();
        for group in edges.chunk_by(|x, y| x.0 == y.0) {
            let (h1, h2) = (group[0].1 as usize, group[group.len() - 1].1 as usize);
            if group.len() == 2 && h1 / 3 != h2 / 3 {
                twin[h1] = h2 as u32;
                twin[h2] = h1 as u32;
                if tail(h1) == tail(h2) {
                    inconsistent_edges += 1;
                }
            } else {
                for &(_, h) in group.iter() {
                    open_side[h as usize] = true;
                }
            }
        }
    }
    drop(bucket);

    let mut stats = OrientStats {
        inconsistent_edges,
        ..OrientStats::default()
    };
    // flip[f]: whether face f is reversed relative to the input, once visited.
    let mut flip: Vec<Option<bool>> = vec![None; n];
    let mut queue: Vec<u32> = Vec::with_capacity(n);
    for seed in 0..n {
        if flip[seed].is_some() {
            continue;
        }
        stats.components += 1;
        let start = queue.len();
        flip[seed] = Some(false);
        queue.push(seed as u32);
        let mut head_index = start;
        let mut closed = true;
        let mut seams = 0;
        while head_index < queue.len() {
            let f = queue[head_index] as usize;
            head_index += 1;
            let of = flip[f] == Some(true);
            for h in 3 * f..3 * f + 3 {
                closed &= !open_side[h];
                let t = twin[h];
                if t == NONE {
                    continue;
                }
                let g = t as usize / 3;
                // Consistent when the twin runs the other way: g keeps f's relation to the input.
                let same_direction = tail(h) == tail(t as usize);
                let want = of ^ same_direction;
                match flip[g] {
                    None => {
                        flip[g] = Some(want);
                        queue.push(g as u32);
                    }
                    Some(og) if og != want && h < t as usize => seams += 1,
                    Some(_) => {}
                }
            }
        }
        let faces = &queue[start..];
        // Of the two orientations, the one that keeps more area as it was.
        let (mut kept, mut flipped) = (0.0, 0.0);
        for &f in faces {
            let a = mesh.face_area(f as usize);
            if flip[f as usize] == Some(true) {
                flipped += a;
            } else {
                kept += a;
            }
        }
        let mut invert = flipped > kept;
        if seams > 0 {
            stats.non_orientable_components += 1;
            stats.non_orientable_faces += faces.len();
            stats.seam_edges += seams;
        } else if closed && closed_outward {
            // Signed volume of the component as it would be oriented, about one of its corners
            // (closed, so the origin does not matter; this one keeps the products small).
            let origin = mesh.positions[mesh.triangles[seed][0] as usize];
            let volume: f64 = faces
                .iter()
                .map(|&f| {
                    let [a, b, c] = mesh.corners(f as usize).map(|p| p - origin);
                    let v = a.dot(b.cross(c));
                    if (flip[f as usize] == Some(true)) != invert {
                        -v
                    } else {
                        v
                    }
                })
                .sum();
            if volume < 0.0 {
                invert = !invert;
                stats.components_turned_outward += 1;
            }
        }
        if invert {
            for &f in faces {
                flip[f as usize] = flip[f as usize].map(|b| !b);
            }
        }
    }
    for (t, f) in mesh.triangles.iter_mut().zip(&flip) {
        if *f == Some(true) {
            t.swap(1, 2);
            stats.faces_flipped += 1;
        }
    }
    stats
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::topology;
    use crate::mesh::test_meshes::{cuboid, grid, uv_sphere};
    use glam::DVec3;

    fn consistent(m: &TriMesh) -> bool {
        topology(m).inconsistent_orientation_edges == 0
    }

    /// A 20 × 20 grid in the plane z = 0, faces up.
    fn plane() -> TriMesh {
        grid(20, |i, j| DVec3::new(i as f64, j as f64, 0.0))
    }

    /// A Möbius strip: `n` quads around a circle of radius 3, width 1, half a turn of twist;
    /// the last column of vertices is the first one swapped.
    fn moebius(n: usize) -> TriMesh {
        let mut positions = Vec::new();
        for i in 0..n {
            let u = std::f64::consts::TAU * i as f64 / n as f64;
            for w in [-0.5, 0.5] {
                let r = 3.0 + w * (u / 2.0).cos();
                positions.push(DVec3::new(r * u.cos(), r * u.sin(), w * (u / 2.0).sin()));
            }
        }
        let mut triangles = Vec::new();
        for i in 0..n {
            let (a, b) = (2 * i as u32, 2 * i as u32 + 1);
            let (c, d) = if i + 1 < n {
                (2 * (i as u32 + 1), 2 * (i as u32 + 1) + 1)
            } else {
                (1, 0)
            };
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
        TriMesh::new(positions, triangles)
    }

    #[test]
    fn a_consistent_mesh_is_left_exactly_as_it_is() {
        for m in [
            plane(),
            cuboid(DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0)),
            uv_sphere(1.0, 12, 16),
        ] {
            let mut o = m.clone();
            let stats = orient_consistently(&mut o, true);
            assert_eq!(o, m);
            assert_eq!((stats.faces_flipped, stats.inconsistent_edges), (0, 0));
            assert_eq!(stats.components, 1);
            assert_eq!(stats.non_orientable_components, 0);
        }
        // Two components, one open and one closed, both consistent.
        let mut two = plane();
        let b = cuboid(DVec3::splat(30.0), DVec3::splat(31.0));
        let offset = two.positions.len() as u32;
        two.positions.extend(&b.positions);
        two.triangles
            .extend(b.triangles.iter().map(|t| t.map(|v| v + offset)));
        let mut o = two.clone();
        let stats = orient_consistently(&mut o, true);
        assert_eq!((o == two, stats.components), (true, 2));
    }

    #[test]
    fn a_reversed_patch_is_flipped_back() {
        for (m, radius) in [(plane(), 5.0), (uv_sphere(1.0, 12, 16), 0.8)] {
            let centre = m.positions[m.triangles[m.triangles.len() / 3][0] as usize];
            let mut reversed = m.clone();
            let mut count = 0;
            for f in 0..m.triangles.len() {
                if m.corners(f).iter().all(|p| p.distance(centre) < radius) {
                    reversed.triangles[f].swap(1, 2);
                    count += 1;
                }
            }
            assert!(count > 4 && 2 * count < m.triangles.len());
            assert!(!consistent(&reversed));
            let stats = orient_consistently(&mut reversed, true);
            assert_eq!(reversed, m, "the patch is flipped back and nothing else");
            assert_eq!(stats.faces_flipped, count);
            assert!(stats.inconsistent_edges > 0);
            assert_eq!(stats.components_turned_outward, 0);
        }
    }

    #[test]
    fn an_inward_closed_mesh_is_turned_outward() {
        let m = uv_sphere(1.0, 10, 12);
        let mut inward = m.clone();
        inward.flip_orientation();
        assert!(inward.signed_volume() < 0.0);
        let stats = orient_consistently(&mut inward, true);
        assert_eq!(inward, m);
        assert_eq!(
            (stats.components_turned_outward, stats.inconsistent_edges),
            (1, 0)
        );
        assert_eq!(stats.faces_flipped, m.triangles.len());
        // Without closed_outward, a consistent inward mesh is left as it is.
        let mut kept = m.clone();
        kept.flip_orientation();
        let before = kept.clone();
        assert_eq!(orient_consistently(&mut kept, false).faces_flipped, 0);
        assert_eq!(kept, before);
        // Inward with a few faces outward: still all outward at the end.
        let mut mixed = m.clone();
        mixed.flip_orientation();
        for t in mixed.triangles.iter_mut().take(7) {
            t.swap(1, 2);
        }
        let stats = orient_consistently(&mut mixed, true);
        assert_eq!(mixed, m);
        assert_eq!(stats.components_turned_outward, 1);
        assert_eq!(stats.faces_flipped, m.triangles.len() - 7);
        // An open inward-looking mesh is left as its larger part is: only closed ones have an
        // outside.
        let mut bowl = plane();
        bowl.flip_orientation();
        let before = bowl.clone();
        assert_eq!(orient_consistently(&mut bowl, true).faces_flipped, 0);
        assert_eq!(bowl, before);
    }

    #[test]
    fn a_half_reversed_sphere_comes_out_consistent_and_outward() {
        let m = uv_sphere(1.0, 16, 20);
        let mut half = m.clone();
        for f in 0..half.triangles.len() {
            if half.corners(f).iter().map(|p| p.x).sum::<f64>() > 0.0 {
                half.triangles[f].swap(1, 2);
            }
        }
        orient_consistently(&mut half, true);
        assert_eq!(half, m);
    }

    #[test]
    fn a_moebius_strip_is_reported_non_orientable() {
        let m = moebius(24);
        let mut o = m.clone();
        let stats = orient_consistently(&mut o, true);
        assert_eq!(stats.components, 1);
        assert_eq!(stats.non_orientable_components, 1);
        assert_eq!(stats.non_orientable_faces, m.triangles.len());
        assert!(stats.seam_edges >= 1);
        // Consistent everywhere but across the seam.
        assert_eq!(
            topology(&o).inconsistent_orientation_edges,
            stats.seam_edges
        );
        // The same strip next to a consistent box: only the strip is counted.
        let mut both = o.clone();
        let b = cuboid(DVec3::splat(10.0), DVec3::splat(11.0));
        let offset = both.positions.len() as u32;
        both.positions.extend(&b.positions);
        both.triangles
            .extend(b.triangles.iter().map(|t| t.map(|v| v + offset)));
        let stats = orient_consistently(&mut both, true);
        assert_eq!((stats.components, stats.non_orientable_components), (2, 1));
    }

    #[test]
    fn degenerate_and_non_manifold_faces_join_nothing_and_do_not_panic() {
        // Three faces on one edge, a face with a repeated index, a face repeated reversed.
        let positions = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::new(0.5, -1.0, 0.0),
            DVec3::new(0.5, 0.0, 1.0),
        ];
        let mut m = TriMesh::new(
            positions,
            vec![[0, 1, 2], [1, 0, 3], [0, 1, 4], [2, 2, 3], [0, 2, 1]],
        );
        let stats = orient_consistently(&mut m, true);
        assert_eq!(stats.non_orientable_components, 0);
        assert!(stats.components >= 3);
        let mut empty = TriMesh::default();
        assert_eq!(
            orient_consistently(&mut empty, true),
            OrientStats::default()
        );
    }
}
