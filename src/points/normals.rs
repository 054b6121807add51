//! Normals for point sets that have none: a plane fitted to each point's nearest neighbours
//! (principal component analysis), then a consistent orientation propagated along a minimum
//! spanning tree of the Riemannian graph (Hoppe, DeRose, Duchamp, McDonald, Stuetzle 1992,
//! "Surface reconstruction from unorganized points", Sec. 3.3).

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use glam::DVec3;
use nalgebra::{Matrix3, SymmetricEigen};
use rayon::prelude::*;

use crate::spatial::StaticTree;

/// How normals are oriented after the plane fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NormalOrientation {
    /// Propagated along the minimum spanning tree of the k-nearest-neighbour graph, weights
    /// 1 − |n_i · n_j| (Hoppe 1992), leaving out edges more than 30° off both ends' tangent
    /// planes (across a part thinner than the neighbourhood), each connected part seeded at its highest point (largest
    /// z) with its normal pointing up (+z): outward on a closed surface.
    SpanningTree,
    /// Towards this viewpoint (a single scan): propagated as by `SpanningTree`, then each
    /// connected part turned as a whole to face the viewpoint, by the vote of its normals, each
    /// weighted by the cosine between it and its line of sight (so points seen at a grazing
    /// angle, whose own side is a toss-up, follow their neighbours).
    Viewpoint(DVec3),
}

impl NormalOrientation {
    /// The same orientation for points in `normalization`'s bbox-100 frame: a viewpoint is
    /// given in model units and moves with the points.
    pub fn in_frame(self, normalization: &crate::mesh::Normalization) -> Self {
        match self {
            NormalOrientation::Viewpoint(v) => NormalOrientation::Viewpoint(normalization.apply(v)),
            o => o,
        }
    }
}

/// Fills the normals a file left unusable (zero or not finite: PCL's normal estimation writes
/// NaN where a point had too few neighbours): each such point's is the least-variance
/// direction of its `k` nearest neighbours, turned to agree with the given normals among its
/// `k` nearest points that have one (their sum's side; kept as fitted where none is near).
/// Returns how many were filled. Deterministic.
pub fn fill_missing_normals(points: &[DVec3], normals: &mut [DVec3], k: usize) -> usize {
    let usable = |n: &DVec3| n.is_finite() && n.length_squared() > 0.0;
    let missing: Vec<usize> = (0..normals.len())
        .filter(|&i| !usable(&normals[i]))
        .collect();
    if missing.is_empty() {
        return 0;
    }
    let k = k.max(3);
    let tree = StaticTree::new(points);
    let given: Vec<u32> = (0..points.len() as u32)
        .filter(|&i| usable(&normals[i as usize]))
        .collect();
    let given_points: Vec<DVec3> = given.iter().map(|&i| points[i as usize]).collect();
    let given_tree = StaticTree::new(&given_points);
    let filled: Vec<DVec3> = missing
        .par_iter()
        .map_init(Vec::new, |found, &i| {
            tree.nearest_n(points[i], k, found);
            let near: Vec<DVec3> = found.iter().map(|&(j, _)| points[j as usize]).collect();
            let fitted = plane_normal(&near);
            given_tree.nearest_n(points[i], k, found);
            let side: DVec3 = found
                .iter()
                .map(|&(j, _)| normals[given[j as usize] as usize].normalize())
                .sum();
            if side.dot(fitted) < 0.0 {
                -fitted
            } else {
                fitted
            }
        })
        .collect();
    for (&i, n) in missing.iter().zip(filled) {
        normals[i] = n;
    }
    missing.len()
}

/// Unit normals of `points` (any units): the least-variance direction of each point's `k`
/// nearest neighbours (itself included), oriented as `orientation` says. `k` below 3 is taken
/// as 3. Deterministic.
pub fn estimate_normals(points: &[DVec3], k: usize, orientation: NormalOrientation) -> Vec<DVec3> {
    let k = k.max(3);
    let tree = StaticTree::new(points);
    let (mut normals, neighbors): (Vec<DVec3>, Vec<Vec<u32>>) = points
        .par_iter()
        .map_init(Vec::new, |found, &p| {
            tree.nearest_n(p, k, found);
            let near: Vec<DVec3> = found.iter().map(|&(j, _)| points[j as usize]).collect();
            let normal = plane_normal(&near);
            let ids = found.iter().map(|x| x.0).collect();
            (normal, ids)
        })
        .unzip();
    orient(points, &mut normals, &neighbors, orientation);
    normals
}

/// Turns `normals` (lines: unit, any sign) consistent along the spanning tree
/// ([`NormalOrientation::SpanningTree`]), each part of the forest then turned as a whole to face
/// the viewpoint when `orientation` gives one.
fn orient(
    points: &[DVec3],
    normals: &mut [DVec3],
    neighbors: &[Vec<u32>],
    orientation: NormalOrientation,
) {
    let parts = orient_by_spanning_tree(points, normals, neighbors);
    if let NormalOrientation::Viewpoint(v) = orientation {
        // Each part of the spanning forest, consistent in itself, turned as a whole to face
        // the viewpoint: by the vote of its normals, each weighted by the cosine to its line of
        // sight (a point seen at a grazing angle, where a flying pixel's strand is, has little
        // say, and its neighbours decide its side).
        let mut votes = vec![0.0; parts.iter().max().map_or(0, |&m| m as usize + 1)];
        for ((n, &p), &part) in normals.iter().zip(points).zip(&parts) {
            votes[part as usize] += n.dot((v - p).normalize_or_zero());
        }
        for (n, &part) in normals.iter_mut().zip(&parts) {
            if votes[part as usize] < 0.0 {
                *n = -*n;
            }
        }
    }
}

/// The share of neighbouring normals along one line (|n_i · n_j| > 0.7) that may point to
/// opposite sides before a file's normals are taken as unoriented: on an oriented surface
/// only points across a part thinner than the neighbourhood disagree, a few per cent; normals
/// of random signs (as Open3D leaves them unless asked to orient) disagree about half the time.
pub const UNORIENTED_SHARE: f64 = 0.2;

/// A file's normals checked for a consistent orientation: when more than [`UNORIENTED_SHARE`]
/// of neighbouring pairs (`k` nearest) along one line point to opposite sides, their lines are
/// kept and their signs set again as estimated normals' are (`orientation`). Returns how many
/// were turned (0 when they were consistent). Deterministic.
pub fn orient_given_normals(
    points: &[DVec3],
    normals: &mut [DVec3],
    k: usize,
    orientation: NormalOrientation,
) -> usize {
    let k = k.max(3);
    let tree = StaticTree::new(points);
    let neighbors: Vec<Vec<u32>> = points
        .par_iter()
        .map_init(Vec::new, |found, &p| {
            tree.nearest_n(p, k, found);
            found.iter().map(|x| x.0).collect()
        })
        .collect();
    let (mut along, mut opposite) = (0usize, 0usize);
    for (i, near) in neighbors.iter().enumerate() {
        for &j in near {
            let d = normals[i].dot(normals[j as usize]);
            if d.abs() > 0.7 {
                along += 1;
                opposite += usize::from(d < 0.0);
            }
        }
    }
    if (opposite as f64) <= UNORIENTED_SHARE * along as f64 {
        return 0;
    }
    let given = normals.to_vec();
    orient(points, normals, &neighbors, orientation);
    normals
        .iter()
        .zip(&given)
        .filter(|(n, g)| n.dot(**g) < 0.0)
        .count()
}

/// The least-variance direction of `points` (unit; zero when undefined).
pub(crate) fn plane_normal(points: &[DVec3]) -> DVec3 {
    let mean = points.iter().sum::<DVec3>() / points.len().max(1) as f64;
    let mut c = Matrix3::<f64>::zeros();
    for p in points {
        let d = *p - mean;
        let v = nalgebra::Vector3::new(d.x, d.y, d.z);
        c += v * v.transpose();
    }
    let eig = SymmetricEigen::new(c);
    let e = eig.eigenvectors.column(eig.eigenvalues.imin());
    DVec3::new(e[0], e[1], e[2]).normalize_or_zero()
}

/// An edge whose |cos| with both ends' normals exceeds this (more than 30° off both tangent
/// planes) is across a thin part.
const TANGENT_SLOPE: f64 = 0.5;

#[derive(PartialEq)]
struct Edge {
    weight: f64,
    from: u32,
    to: u32,
}

impl Eq for Edge {}

impl Ord for Edge {
    fn cmp(&self, other: &Self) -> Ordering {
        // Smallest weight first (BinaryHeap is a max-heap), ties by indices for determinism.
        other
            .weight
            .total_cmp(&self.weight)
            .then_with(|| other.to.cmp(&self.to))
            .then_with(|| other.from.cmp(&self.from))
    }
}

impl PartialOrd for Edge {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Prim's algorithm over the symmetric k-nearest-neighbour graph (without edges more than 30°
/// off both ends' tangent planes), flipping each newly reached
/// normal to agree with the one it is reached from. Returns each point's part (the tree it was
/// reached in, numbered from 0).
fn orient_by_spanning_tree(
    points: &[DVec3],
    normals: &mut [DVec3],
    neighbors: &[Vec<u32>],
) -> Vec<u32> {
    let n = points.len();
    // Symmetric adjacency.
    // No edge straight across a thin part (the other side of an ear): one that leaves both
    // ends' tangent planes steeply, where 1 - |n_i . n_j| would be small for the wrong reason.
    // Edges across a crease leave only one end's plane and stay.
    let along = |i: usize, j: usize| {
        let d = points[j] - points[i];
        let l = d.length();
        l > 0.0
            && (d.dot(normals[i]).abs() <= TANGENT_SLOPE * l
                || d.dot(normals[j]).abs() <= TANGENT_SLOPE * l)
    };
    let mut adjacency: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (i, list) in neighbors.iter().enumerate() {
        for &j in list {
            if j as usize != i && along(i, j as usize) {
                adjacency[i].push(j);
                adjacency[j as usize].push(i as u32);
            }
        }
    }
    for list in &mut adjacency {
        list.sort_unstable();
        list.dedup();
    }
    let mut reached = vec![false; n];
    // Seeds in order of decreasing height, so each connected part starts at its top.
    let mut order: Vec<u32> = (0..n as u32).collect();
    order.sort_by(|&a, &b| {
        points[b as usize]
            .z
            .total_cmp(&points[a as usize].z)
            .then(a.cmp(&b))
    });
    let mut heap = BinaryHeap::new();
    let mut parts = vec![0u32; n];
    let mut part = 0u32;
    for seed in order {
        if reached[seed as usize] {
            continue;
        }
        reached[seed as usize] = true;
        parts[seed as usize] = part;
        if normals[seed as usize].z < 0.0 {
            normals[seed as usize] = -normals[seed as usize];
        }
        let push = |heap: &mut BinaryHeap<Edge>, i: u32, normals: &[DVec3], reached: &[bool]| {
            for &j in &adjacency[i as usize] {
                if !reached[j as usize] {
                    let w = 1.0 - normals[i as usize].dot(normals[j as usize]).abs();
                    heap.push(Edge {
                        weight: w,
                        from: i,
                        to: j,
                    });
                }
            }
        };
        push(&mut heap, seed, normals, &reached);
        while let Some(Edge { from, to, .. }) = heap.pop() {
            if reached[to as usize] {
                continue;
            }
            reached[to as usize] = true;
            parts[to as usize] = part;
            if normals[to as usize].dot(normals[from as usize]) < 0.0 {
                normals[to as usize] = -normals[to as usize];
            }
            push(&mut heap, to, normals, &reached);
        }
        part += 1;
    }
    parts
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_normals_point_outward() {
        // A Fibonacci sphere.
        let n = 2000;
        let points: Vec<DVec3> = crate::mesh::test_meshes::fibonacci_sphere(n)
            .into_iter()
            .map(|u| DVec3::new(u.x, u.z, u.y) * 3.0)
            .collect();
        let normals = estimate_normals(&points, 12, NormalOrientation::SpanningTree);
        for (p, n) in points.iter().zip(&normals) {
            assert!(n.dot(p.normalize()) > 0.99, "{p:?} {n:?}");
        }
        // A viewpoint inside turns them all inward.
        let inward = estimate_normals(&points, 12, NormalOrientation::Viewpoint(DVec3::ZERO));
        assert!(inward.iter().zip(&points).all(|(n, p)| n.dot(*p) < 0.0));
    }

    /// Issue 76 (R12): normals a file left NaN or zero at some points are fitted there and turned
    /// to the side of the given ones; the given ones are kept.
    #[test]
    fn missing_normals_are_filled_on_the_given_ones_side() {
        let points: Vec<DVec3> = crate::mesh::test_meshes::fibonacci_sphere(2000)
            .into_iter()
            .map(|u| u * 3.0)
            .collect();
        let mut normals: Vec<DVec3> = points.iter().map(|p| p.normalize()).collect();
        let given = normals.clone();
        for i in (0..2000).step_by(7) {
            normals[i] = if i % 2 == 0 { DVec3::NAN } else { DVec3::ZERO };
        }
        assert_eq!(fill_missing_normals(&points, &mut normals, 10), 286);
        for (i, (n, g)) in normals.iter().zip(&given).enumerate() {
            if i % 7 == 0 {
                assert!(n.dot(*g) > 0.99, "point {i}: {n} against {g}");
            } else {
                assert_eq!(n, g);
            }
        }
        assert_eq!(fill_missing_normals(&points, &mut normals, 10), 0);
    }

    /// Issue 76 (R13): a file's normals of random signs are turned consistent (outward on a
    /// closed surface); oriented normals are left as they are.
    #[test]
    fn normals_of_random_signs_are_oriented_again() {
        let points: Vec<DVec3> = crate::mesh::test_meshes::fibonacci_sphere(2000)
            .into_iter()
            .map(|u| u * 3.0)
            .collect();
        let outward: Vec<DVec3> = points.iter().map(|p| p.normalize()).collect();
        let mut normals = outward.clone();
        let orientation = NormalOrientation::SpanningTree;
        assert_eq!(
            orient_given_normals(&points, &mut normals, 10, orientation),
            0
        );
        assert_eq!(normals, outward);
        let mut flipped = 0;
        for (i, n) in normals.iter_mut().enumerate() {
            if (i * 7919) % 13 < 6 {
                *n = -*n;
                flipped += 1;
            }
        }
        assert_eq!(
            orient_given_normals(&points, &mut normals, 10, orientation),
            flipped
        );
        for (n, o) in normals.iter().zip(&outward) {
            assert!(n.dot(*o) > 0.999, "{n} against {o}");
        }
    }

    #[test]
    fn a_scan_past_its_silhouette_keeps_one_side() {
        // A cylinder (radius 1, along z) scanned from far along +y, its points reaching a
        // little past the silhouette (y down to -0.3): there the outward normals face away from
        // the scanner, and each normal turned on its own to face it would point inward.
        let mut points = Vec::new();
        for i in 0..120 {
            let t =
                -0.3f64.asin() + (std::f64::consts::PI + 2.0 * 0.3f64.asin()) * i as f64 / 119.0;
            for j in 0..30 {
                points.push(DVec3::new(t.cos(), t.sin(), j as f64 * 0.03));
            }
        }
        assert!(points.iter().any(|p| p.y < -0.29));
        let viewpoint = DVec3::new(0.0, 40.0, 0.5);
        let normals = estimate_normals(&points, 12, NormalOrientation::Viewpoint(viewpoint));
        for (p, n) in points.iter().zip(&normals) {
            let outward = DVec3::new(p.x, p.y, 0.0).normalize();
            assert!(n.dot(outward) > 0.9, "{p:?} {n:?}");
        }
    }
}
