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
use rustc_hash::FxHashMap;

use super::cleanup::{Builder, FaceSource, BLOCKED};
use crate::geometry::triangle::triangle_angles_deg;
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

fn unit_normal(b: &Builder, t: [u32; 3]) -> Option<DVec3> {
    let [p, q, r] = t.map(|i| b.positions[i as usize]);
    (q - p).cross(r - p).try_normalize()
}

fn min_angle(b: &Builder, t: [u32; 3]) -> f64 {
    let a = triangle_angles_deg(t.map(|i| b.positions[i as usize]));
    a[0].min(a[1]).min(a[2])
}

/// Rotates `t` so that it starts with `v` (which must be a corner).
pub(super) fn starting_at(t: [u32; 3], v: u32) -> [u32; 3] {
    if t[0] == v {
        t
    } else if t[1] == v {
        [t[1], t[2], t[0]]
    } else {
        [t[2], t[0], t[1]]
    }
}

/// The face on the directed edge `a → b`, if any.
fn face_on(b: &Builder, a: u32, c: u32) -> Option<u32> {
    b.directed.get(&(a, c)).copied().filter(|&f| f != BLOCKED)
}

/// Lawson flips: an interior edge a-b with faces [a, b, c] and [b, a, d] becomes c-d when that
/// raises the smaller of the two faces' minimum angles, c-d is not an edge yet, a and b keep at
/// least three faces each, both new faces agree with their corners' normals, and the normals of
/// both pairs of faces are within `max_flip_dihedral_deg`. Returns the number of flips.
pub(super) fn flip_edges(b: &mut Builder, params: &RefineParams) -> usize {
    let cos_max = params.max_flip_dihedral_deg.to_radians().cos();
    let mut degree: FxHashMap<u32, u32> = FxHashMap::default();
    for t in b.faces.iter().flatten() {
        for &v in t {
            *degree.entry(v).or_default() += 1;
        }
    }
    let mut flips = 0;
    for _ in 0..params.max_flip_sweeps {
        let mut edges: Vec<(u32, u32)> = b
            .directed
            .iter()
            .filter(|(&(x, y), &f)| f != BLOCKED && x < y)
            .map(|(&e, _)| e)
            .collect();
        edges.sort_unstable();
        let mut flipped_this_sweep = 0;
        for (x, y) in edges {
            let (Some(f1), Some(f2)) = (face_on(b, x, y), face_on(b, y, x)) else {
                continue;
            };
            let (Some(t1), Some(t2)) = (b.faces[f1 as usize], b.faces[f2 as usize]) else {
                continue;
            };
            let t1 = starting_at(t1, x); // [x, y, c]
            let t2 = starting_at(t2, y); // [y, x, d]
            if t1[1] != y || t2[1] != x {
                continue;
            }
            let (c, d) = (t1[2], t2[2]);
            if c == d
                || b.directed.contains_key(&(c, d))
                || b.directed.contains_key(&(d, c))
                || degree.get(&x).copied().unwrap_or(0) <= 3
                || degree.get(&y).copied().unwrap_or(0) <= 3
            {
                continue;
            }
            let (n1, n2) = match (unit_normal(b, t1), unit_normal(b, t2)) {
                (Some(n1), Some(n2)) => (n1, n2),
                _ => (DVec3::ZERO, DVec3::ZERO),
            };
            let new1 = [x, d, c];
            let new2 = [y, c, d];
            let (Some(m1), Some(m2)) = (unit_normal(b, new1), unit_normal(b, new2)) else {
                continue;
            };
            // A degenerate old face may always be flipped away; otherwise both pairs must be
            // nearly coplanar.
            let old_degenerate = n1 == DVec3::ZERO;
            if (!old_degenerate && n1.dot(n2) < cos_max) || m1.dot(m2) < cos_max {
                continue;
            }
            let old = min_angle(b, t1).min(min_angle(b, t2));
            let new = min_angle(b, new1).min(min_angle(b, new2));
            if new <= old + 1e-6 || b.quality(new1) <= 0.0 || b.quality(new2) <= 0.0 {
                continue;
            }
            let (s1, s2) = (b.sources[f1 as usize], b.sources[f2 as usize]);
            b.remove(f1);
            b.remove(f2);
            let ok1 = b.add(new1, FaceSource::Refined);
            let ok2 = b.add(new2, FaceSource::Refined);
            if !(ok1 && ok2) {
                // Cannot happen after the checks above; restore the old faces to be safe.
                let n = b.faces.len();
                if ok2 {
                    b.remove(n as u32 - 1);
                }
                if ok1 {
                    b.remove(n as u32 - 1 - ok2 as u32);
                }
                b.add(t1, s1);
                b.add(t2, s2);
                continue;
            }
            *degree.entry(x).or_default() -= 1;
            *degree.entry(y).or_default() -= 1;
            *degree.entry(c).or_default() += 1;
            *degree.entry(d).or_default() += 1;
            flipped_this_sweep += 1;
        }
        flips += flipped_this_sweep;
        if flipped_this_sweep == 0 {
            break;
        }
    }
    flips
}

/// Inserts every sample that no face uses into the face it projects into (or, near an edge,
/// into that edge's two faces): the face must lie within half its mean edge length of the
/// sample and face the same way as the sample's normal. Returns the number inserted.
pub(super) fn insert_loose_samples(b: &mut Builder) -> usize {
    let n = b.positions.len();
    let mut incident: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (f, t) in b.faces.iter().enumerate() {
        if let Some(t) = t {
            for &v in t {
                incident[v as usize].push(f as u32);
            }
        }
    }
    let loose: Vec<u32> = (0..n as u32)
        .filter(|&v| incident[v as usize].is_empty())
        .collect();
    if loose.is_empty() {
        return 0;
    }
    let tree = StaticTree::new(b.positions);
    let mut found = Vec::new();
    let mut inserted = 0;
    for v in loose {
        let p = b.positions[v as usize];
        let normal = b.normals[v as usize];
        tree.nearest_n(p, 10, &mut found);
        // Best face: the largest smallest barycentric coordinate of the projection.
        let mut best: Option<(f64, u32, [f64; 3])> = None;
        for &(w, _) in found.iter() {
            for &f in &incident[w as usize] {
                let Some(t) = b.faces[f as usize] else {
                    continue;
                };
                let [a, c, e] = t.map(|i| b.positions[i as usize]);
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
        let t = b.faces[f as usize].unwrap();
        let mut new_faces: Vec<(u32, [u32; 3])> = Vec::new();
        if m >= 0.05 {
            new_faces.push((f, [t[0], t[1], v]));
            new_faces.push((f, [t[1], t[2], v]));
            new_faces.push((f, [t[2], t[0], v]));
        } else {
            // Split the edge opposite the corner with the smallest coordinate.
            let k = (0..3).min_by(|&i, &j| bary[i].total_cmp(&bary[j])).unwrap();
            let (x, y, z) = (t[(k + 1) % 3], t[(k + 2) % 3], t[k]);
            let Some(g) = face_on(b, y, x) else {
                continue;
            };
            let Some(u) = b.faces[g as usize] else {
                continue;
            };
            let w = starting_at(u, y)[2];
            new_faces.push((f, [x, v, z]));
            new_faces.push((f, [v, y, z]));
            new_faces.push((g, [y, v, w]));
            new_faces.push((g, [v, x, w]));
        }
        let mut old: Vec<(u32, [u32; 3], FaceSource)> = new_faces
            .iter()
            .map(|x| x.0)
            .collect::<Vec<_>>()
            .into_iter()
            .map(|g| (g, b.faces[g as usize].unwrap(), b.sources[g as usize]))
            .collect();
        old.dedup_by_key(|x| x.0);
        if new_faces.iter().any(|&(_, t)| b.quality(t) <= 0.0) {
            continue;
        }
        for &(g, _, _) in &old {
            b.remove(g);
        }
        let mut added = Vec::new();
        let mut ok = true;
        for &(_, t) in &new_faces {
            if b.add(t, FaceSource::Refined) {
                added.push(b.faces.len() as u32 - 1);
            } else {
                ok = false;
                break;
            }
        }
        if !ok {
            for g in added {
                b.remove(g);
            }
            for &(_, t, s) in &old {
                b.add(t, s);
            }
            continue;
        }
        for &g in &added {
            for &x in b.faces[g as usize].as_ref().unwrap() {
                if !incident[x as usize].contains(&g) {
                    incident[x as usize].push(g);
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

    fn builder<'a>(positions: &'a [DVec3], normals: &'a [DVec3]) -> Builder<'a> {
        Builder {
            positions,
            normals,
            faces: Vec::new(),
            sources: Vec::new(),
            directed: FxHashMap::default(),
        }
    }

    fn live(b: &Builder) -> Vec<[u32; 3]> {
        b.faces.iter().flatten().copied().collect()
    }

    /// A hexagon fan around a centre, with one long thin diagonal forced in: the flips must
    /// restore the Delaunay triangulation (raise the smallest angle) and keep every directed
    /// edge once.
    #[test]
    fn flips_raise_the_smallest_angle_and_keep_the_mesh_manifold() {
        // Convex quad 0-3-1-2 split along its long diagonal 0-1, inside a ring 6-5-7-4 so that
        // 0 and 1 have six faces each.
        let positions: Vec<DVec3> = [
            (0.0, 0.0),
            (2.0, 0.0),
            (1.0, 0.3),
            (1.0, -0.3),
            (1.0, 2.0),
            (1.0, -2.0),
            (-1.5, 0.0),
            (3.5, 0.0),
        ]
        .iter()
        .map(|&(x, y)| DVec3::new(x, y, 0.0))
        .collect();
        let normals = vec![DVec3::Z; positions.len()];
        let mut b = builder(&positions, &normals);
        for t in [
            [0, 1, 2],
            [1, 0, 3],
            [0, 2, 4],
            [2, 1, 4],
            [3, 0, 5],
            [1, 3, 5],
            [6, 0, 4],
            [6, 5, 0],
            [1, 7, 4],
            [1, 5, 7],
        ] {
            assert!(b.add(t, FaceSource::ThreeVotes));
        }
        let worst_before = live(&b)
            .iter()
            .filter(|t| t.contains(&0) && t.contains(&1))
            .map(|&t| min_angle(&b, t))
            .fold(f64::INFINITY, f64::min);
        let flips = flip_edges(&mut b, &RefineParams::default());
        assert!(flips >= 1);
        // The long edge 0-1 is gone, 2-3 is there.
        assert!(!b.directed.contains_key(&(0, 1)) && !b.directed.contains_key(&(1, 0)));
        assert!(b.directed.contains_key(&(2, 3)) || b.directed.contains_key(&(3, 2)));
        let around: Vec<[u32; 3]> = live(&b)
            .into_iter()
            .filter(|t| t.contains(&2) && t.contains(&3))
            .collect();
        assert_eq!(around.len(), 2);
        for t in around {
            assert!(min_angle(&b, t) > worst_before);
        }
        // Every directed edge at most once, and the face list matches the edge map.
        let mut seen = std::collections::HashSet::new();
        for t in live(&b) {
            for k in 0..3 {
                assert!(seen.insert((t[k], t[(k + 1) % 3])));
            }
        }
        assert_eq!(seen.len(), b.directed.len());
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
        let mut b = builder(&positions, &normals);
        assert!(b.add([0, 1, 2], FaceSource::ThreeVotes));
        assert!(b.add([1, 0, 3], FaceSource::ThreeVotes));
        assert_eq!(flip_edges(&mut b, &RefineParams::default()), 0);
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
        let mut b = builder(&positions, &normals);
        assert!(b.add([0, 1, 2], FaceSource::ThreeVotes));
        assert_eq!(insert_loose_samples(&mut b), 1);
        let faces = live(&b);
        assert_eq!(faces.len(), 3);
        for t in faces {
            assert!(t.contains(&3));
            assert!(b.quality(t) > 0.0);
        }
    }

    /// The reverse of an existing face does not fit (it would close a two-face pillow).
    #[test]
    fn the_reverse_of_a_face_does_not_fit() {
        let positions = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
        let normals = vec![DVec3::Z; 3];
        let mut b = builder(&positions, &normals);
        assert!(b.add([0, 1, 2], FaceSource::ThreeVotes));
        assert!(!b.fits([0, 2, 1]));
    }
}
