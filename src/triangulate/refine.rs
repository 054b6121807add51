//! Local refinement of the assembled mesh: samples that ended in no face are inserted into the
//! face they project into, then edges are flipped towards the local Delaunay triangulation
//! (Lawson's flips with the max-min angle rule) wherever the two faces of an edge are nearly
//! coplanar. Both keep the mesh edge- and vertex-manifold and its orientation: a flip replaces
//! two faces by two faces on the same four vertices, and an insertion replaces one face (or the
//! two faces of an edge) by a fan around the new vertex.
//!
//! The umbrella triangles with three votes are already Delaunay in the tangent planes of their
//! corners; the flips mostly act on the triangles that closed holes, where the local views
//! disagreed.

use glam::DVec3;

use super::flip::max_min_flips_after;
use crate::geometry::triangle::triangle_q;
use crate::mesh::edit::{starting_at, EditMesh};
use crate::spatial::StaticTree;

/// Parameters of the refinement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefineParams {
    /// Largest angle between the normals of the two faces of an edge, before and after a flip,
    /// for the flip to be allowed, degrees (default 20). Keeps flips from cutting across creases
    /// and ridges, where they would move the surface.
    pub max_flip_dihedral_deg: f64,
    /// Sweeps of edge flips at most (default 8).
    pub max_flip_sweeps: usize,
    /// Insert the samples that no face uses (default true).
    pub insert_loose_samples: bool,
}

impl Default for RefineParams {
    fn default() -> Self {
        RefineParams {
            max_flip_dihedral_deg: 20.0,
            max_flip_sweeps: 8,
            insert_loose_samples: true,
        }
    }
}

fn unit_normal<L: Copy>(b: &EditMesh<L>, t: [u32; 3]) -> Option<DVec3> {
    let [p, q, r] = b.corners(t);
    (q - p).cross(r - p).try_normalize()
}

/// Quality Q = 6S/(√3 p h) of the triangle `t` of `b` ([`triangle_q`]), or -1 when its normal
/// opposes the sum of its corners' `normals` (a fold).
pub(super) fn oriented_quality<L: Copy>(b: &EditMesh<L>, normals: &[DVec3], t: [u32; 3]) -> f64 {
    let [a, p, c] = b.corners(t);
    let n = (p - a).cross(c - a);
    let avg = t.iter().map(|&i| normals[i as usize]).sum::<DVec3>();
    if n.dot(avg) <= 0.0 {
        return -1.0;
    }
    triangle_q([a, p, c])
}

/// Lawson flips ([`max_min_flips_after`]) in sweeps over every interior edge, until a sweep flips
/// nothing or `params.max_flip_sweeps` have run. An edge is flipped only when both new faces
/// agree with their corners' `normals` and the normals of both pairs of faces, old and new, are
/// within `max_flip_dihedral_deg` (an old pair with a degenerate face may always be flipped
/// away). New faces get `label`. Returns the number of flips.
///
/// A sweep after the first decides only the edges with one of their four vertices (ends and
/// apexes) among those the sweep before came to flip, or touched by a flip earlier in the
/// sweep ([`max_min_flips_after`]): the decision reads only those four vertices, so every other
/// edge, left the sweep before, would be left again. The same flips as deciding every edge, in
/// fewer tests.
pub(super) fn flip_edges<L: Copy + Send + Sync>(
    b: &mut EditMesh<L>,
    normals: &[DVec3],
    params: &RefineParams,
    label: L,
) -> usize {
    let cos_max = params.max_flip_dihedral_deg.to_radians().cos();
    let mut flips = 0;
    // The vertices of the quads the last sweep came to flip (`None`: every edge is decided).
    let mut touched: Option<Vec<bool>> = None;
    for _ in 0..params.max_flip_sweeps {
        let mut edges: Vec<(u32, u32)> = b.directed_edges().filter(|&(x, y)| x < y).collect();
        edges.sort_unstable();
        let mut now = vec![false; b.vertex_count()];
        let last = touched.as_deref();
        let flipped_this_sweep =
            max_min_flips_after(b, &edges, label, last, &mut now, |b, flip| {
                let [t1, t2] = flip.old;
                let [new1, new2] = flip.new;
                let (n1, n2) = match (unit_normal(b, t1), unit_normal(b, t2)) {
                    (Some(n1), Some(n2)) => (n1, n2),
                    _ => (DVec3::ZERO, DVec3::ZERO),
                };
                let (Some(m1), Some(m2)) = (unit_normal(b, new1), unit_normal(b, new2)) else {
                    return false;
                };
                // A degenerate old face may always be flipped away; otherwise both pairs must be
                // nearly coplanar.
                let old_degenerate = n1 == DVec3::ZERO;
                if (!old_degenerate && n1.dot(n2) < cos_max) || m1.dot(m2) < cos_max {
                    return false;
                }
                oriented_quality(b, normals, new1) > 0.0 && oriented_quality(b, normals, new2) > 0.0
            });
        flips += flipped_this_sweep;
        if flipped_this_sweep == 0 {
            break;
        }
        touched = Some(now);
    }
    flips
}

/// Inserts every sample that no face uses into the face it projects into (or, near an edge,
/// into that edge's two faces, [`EditMesh::split_face`] and [`EditMesh::split_edge`]): the face
/// must lie within half its mean edge length of the sample and face the same way as the
/// sample's normal (`normals`), and every new face must agree with its corners' normals. New
/// faces get `label`. Returns the number inserted.
pub(super) fn insert_loose_samples<L: Copy>(
    b: &mut EditMesh<L>,
    normals: &[DVec3],
    label: L,
) -> usize {
    let n = b.vertex_count();
    // The faces each vertex was in when the insertion began or that the insertion made, dead
    // ones included (skipped when met), in the order they were made.
    let mut incident: Vec<Vec<u32>> = vec![Vec::new(); n];
    let (faces, slots) = b.live_faces();
    for (t, f) in faces.into_iter().zip(slots) {
        for v in t {
            incident[v as usize].push(f);
        }
    }
    let loose: Vec<u32> = (0..n as u32)
        .filter(|&v| incident[v as usize].is_empty())
        .collect();
    if loose.is_empty() {
        return 0;
    }
    let tree = StaticTree::new(b.positions());
    let mut found = Vec::new();
    let mut inserted = 0;
    for v in loose {
        let p = b.position(v);
        let normal = normals[v as usize];
        tree.nearest_n(p, 10, &mut found);
        // Best face: the largest smallest barycentric coordinate of the projection.
        let mut best: Option<(f64, u32, [f64; 3])> = None;
        for &(w, _) in found.iter() {
            for &f in &incident[w as usize] {
                let Some(t) = b.face(f) else {
                    continue;
                };
                let [a, c, e] = b.corners(t);
                let nrm = (c - a).cross(e - a);
                let area2 = nrm.length();
                if area2 <= 0.0 {
                    continue;
                }
                let un = nrm / area2;
                if un.dot(normal) < 0.5 {
                    continue;
                }
                let mean_edge = (a.distance(c) + c.distance(e) + e.distance(a)) / 3.0;
                if (p - a).dot(un).abs() > 0.5 * mean_edge {
                    continue;
                }
                let q = p - un * (p - a).dot(un);
                let bary = [
                    (e - c).cross(q - c).dot(un) / area2,
                    (a - e).cross(q - e).dot(un) / area2,
                    (c - a).cross(q - a).dot(un) / area2,
                ];
                let m = bary[0].min(bary[1]).min(bary[2]);
                if m > -0.02 && best.is_none_or(|x| m > x.0) {
                    best = Some((m, f, bary));
                }
            }
        }
        let Some((m, f, bary)) = best else {
            continue;
        };
        let Some(t) = b.face(f) else {
            continue;
        };
        let added: Vec<u32> = if m >= 0.05 {
            let new_faces = [[t[0], t[1], v], [t[1], t[2], v], [t[2], t[0], v]];
            if new_faces
                .iter()
                .any(|&t| oriented_quality(b, normals, t) <= 0.0)
            {
                continue;
            }
            match b.split_face(f, v, label) {
                Ok(added) => added.to_vec(),
                Err(_) => continue,
            }
        } else {
            // Split the edge opposite the corner with the smallest coordinate.
            let k = (0..3)
                .min_by(|&i, &j| bary[i].total_cmp(&bary[j]))
                .unwrap_or(0);
            let (x, y, z) = (t[(k + 1) % 3], t[(k + 2) % 3], t[k]);
            let Some(g) = b.face_on(y, x) else {
                continue;
            };
            let Some(u) = b.face(g) else {
                continue;
            };
            let w = starting_at(u, y)[2];
            let new_faces = [[x, v, z], [v, y, z], [y, v, w], [v, x, w]];
            if new_faces
                .iter()
                .any(|&t| oriented_quality(b, normals, t) <= 0.0)
            {
                continue;
            }
            match b.split_edge(x, y, v, label) {
                Ok(added) => added.to_vec(),
                Err(_) => continue,
            }
        };
        for &g in &added {
            if let Some(t) = b.face(g) {
                for x in t {
                    if !incident[x as usize].contains(&g) {
                        incident[x as usize].push(g);
                    }
                }
            }
        }
        inserted += 1;
    }
    inserted
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::triangle::triangle_min_angle_deg;
    use crate::mesh::edit::SlotPolicy;

    fn builder(positions: &[DVec3]) -> EditMesh<()> {
        EditMesh::new(positions.to_vec(), SlotPolicy::Append)
    }

    fn live(b: &EditMesh<()>) -> Vec<[u32; 3]> {
        b.live_faces().0
    }

    fn min_angle(b: &EditMesh<()>, t: [u32; 3]) -> f64 {
        triangle_min_angle_deg(b.corners(t))
    }

    /// A hexagon fan around a centre, with one long thin diagonal forced in: the flips must
    /// restore the Delaunay triangulation (raise the smallest angle) and keep every directed
    /// edge once.
    #[test]
    fn flips_raise_the_smallest_angle_and_keep_the_mesh_manifold() {
        // Convex quad 0-3-1-2 split along its long diagonal 0-1, inside a ring 6-5-7-4 so that
        // 0 and 1 have six faces each.
        let (positions, faces) = crate::mesh::test_meshes::quad_in_ring();
        let normals = vec![DVec3::Z; positions.len()];
        let mut b = builder(&positions);
        for t in faces {
            assert!(b.add_face(t, ()).is_ok());
        }
        let worst_before = live(&b)
            .iter()
            .filter(|t| t.contains(&0) && t.contains(&1))
            .map(|&t| min_angle(&b, t))
            .fold(f64::INFINITY, f64::min);
        let flips = flip_edges(&mut b, &normals, &RefineParams::default(), ());
        assert!(flips >= 1);
        // The long edge 0-1 is gone, 2-3 is there.
        assert!(!b.has_edge(0, 1));
        assert!(b.has_edge(2, 3));
        let around: Vec<[u32; 3]> = live(&b)
            .into_iter()
            .filter(|t| t.contains(&2) && t.contains(&3))
            .collect();
        assert_eq!(around.len(), 2);
        for t in around {
            assert!(min_angle(&b, t) > worst_before);
        }
        // Every directed edge at most once, and the face list matches the edge map.
        assert_eq!(b.sanity_check(), Ok(()));
        assert_eq!(live(&b).len(), 10);
    }

    /// No flip across a crease: two faces at 90° keep their edge.
    #[test]
    fn no_flip_across_a_crease() {
        let positions = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(1.0, 0.2, 0.0),
            DVec3::new(1.0, 0.0, -0.2),
        ];
        let normals = vec![DVec3::new(0.0, 1.0, 1.0).normalize(); 4];
        let mut b = builder(&positions);
        assert!(b.add_face([0, 1, 2], ()).is_ok());
        assert!(b.add_face([1, 0, 3], ()).is_ok());
        assert_eq!(
            flip_edges(&mut b, &normals, &RefineParams::default(), ()),
            0
        );
        assert_eq!(b.sanity_check(), Ok(()));
    }

    /// A sample inside a face is inserted by a 1-to-3 split that keeps the orientation.
    #[test]
    fn a_loose_sample_is_inserted_into_the_face_it_projects_into() {
        let positions = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(3.0, 0.0, 0.0),
            DVec3::new(0.0, 3.0, 0.0),
            DVec3::new(1.0, 1.0, 0.05),
        ];
        let normals = vec![DVec3::Z; 4];
        let mut b = builder(&positions);
        assert!(b.add_face([0, 1, 2], ()).is_ok());
        assert_eq!(insert_loose_samples(&mut b, &normals, ()), 1);
        let faces = live(&b);
        assert_eq!(faces.len(), 3);
        for t in faces {
            assert!(t.contains(&3));
            assert!(oriented_quality(&b, &normals, t) > 0.0);
        }
        assert_eq!(b.sanity_check(), Ok(()));
    }
}
