//! The self-intersection predicate against an oracle (issue 55): whether two faces of a mesh
//! intersect by the standard definition (CGAL's `self_intersections`): the part of the two
//! closed triangles' intersection outside what their shared vertex indices make them share is
//! not empty.
//!
//! The oracle computes that intersection itself, in exact rational arithmetic (every `f64` is a
//! rational): the second triangle clipped by the first one's plane (both half-spaces) and by the
//! three planes through its edges along its normal (Sutherland–Hodgman), whose corners span
//! the intersection exactly. Two faces sharing one vertex intersect when a corner of that set
//! is not the vertex; two sharing an edge, when a corner is off the edge's segment; two sharing
//! none, when the set is not empty. Nothing of the predicate's case analysis (opposite edges,
//! orientation signs) is used.
//!
//! The cases are the awkward ones: fans wrapped twice round their vertex, faces folded onto a
//! neighbour, coplanar faces along an edge on the same or opposite sides, faces touching at one
//! point, T-junctions, and near-coplanar faces at 1e-12 offsets; then whole meshes, where the
//! BVH search must find every pair the oracle finds over all pairs.

use glam::DVec3;
use num_rational::BigRational;
use num_traits::{Signed, Zero};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use spectral_remesh::geometry::{
    faces_intersect, intersecting_pairs, is_degenerate_face, PairKind,
};

type Q = BigRational;
type P = [Q; 3];

fn q(x: f64) -> Q {
    BigRational::from_float(x).expect("finite")
}

fn qp(p: DVec3) -> P {
    [q(p.x), q(p.y), q(p.z)]
}

fn sub(a: &P, b: &P) -> P {
    [&a[0] - &b[0], &a[1] - &b[1], &a[2] - &b[2]]
}

fn dot(a: &P, b: &P) -> Q {
    &a[0] * &b[0] + &a[1] * &b[1] + &a[2] * &b[2]
}

fn cross(a: &P, b: &P) -> P {
    [
        &a[1] * &b[2] - &a[2] * &b[1],
        &a[2] * &b[0] - &a[0] * &b[2],
        &a[0] * &b[1] - &a[1] * &b[0],
    ]
}

/// The polygon `poly` (a corner list, possibly degenerate) clipped to h(x) = n·x - d ≥ 0.
fn clip(poly: &[P], n: &P, d: &Q) -> Vec<P> {
    let h = |x: &P| dot(n, x) - d;
    let mut out: Vec<P> = Vec::new();
    let k = poly.len();
    for i in 0..k {
        let (a, b) = (&poly[i], &poly[(i + 1) % k]);
        let (ha, hb) = (h(a), h(b));
        if !ha.is_negative() {
            out.push(a.clone());
        }
        if (ha.is_positive() && hb.is_negative()) || (ha.is_negative() && hb.is_positive()) {
            let t = &ha / (&ha - &hb);
            let ab = sub(b, a);
            out.push([
                &a[0] + &t * &ab[0],
                &a[1] + &t * &ab[1],
                &a[2] + &t * &ab[2],
            ]);
        }
    }
    out
}

/// Corners whose convex hull is the intersection of the closed triangles `a` and `b`
/// (non-degenerate), exactly.
fn intersection(a: &[P; 3], b: &[P; 3]) -> Vec<P> {
    let n = cross(&sub(&a[1], &a[0]), &sub(&a[2], &a[0]));
    let d = dot(&n, &a[0]);
    let neg = |v: &P| [-&v[0], -&v[1], -&v[2]];
    let mut poly: Vec<P> = b.to_vec();
    poly = clip(&poly, &n, &d);
    poly = clip(&poly, &neg(&n), &-&d);
    for i in 0..3 {
        let (p, r, other) = (&a[i], &a[(i + 1) % 3], &a[(i + 2) % 3]);
        let m = cross(&n, &sub(r, p));
        // Oriented towards the third corner.
        let m = if dot(&m, &sub(other, p)).is_negative() {
            neg(&m)
        } else {
            m
        };
        let dm = dot(&m, p);
        poly = clip(&poly, &m, &dm);
        if poly.is_empty() {
            break;
        }
    }
    poly
}

/// Whether `x` lies on the closed segment `p q`, exactly.
fn on_segment(x: &P, p: &P, r: &P) -> bool {
    let (d, e) = (sub(r, p), sub(x, p));
    cross(&d, &e).iter().all(|c| c.is_zero()) && {
        let t = dot(&e, &d);
        !t.is_negative() && t <= dot(&d, &d)
    }
}

/// The oracle: whether faces `a`, `b` (indices) with corners `pa`, `pb` intersect by the
/// standard definition, and of which kind; `None` for pairs the definition leaves to other
/// checks (three shared indices).
fn oracle(a: [u32; 3], pa: [DVec3; 3], b: [u32; 3], pb: [DVec3; 3]) -> Option<PairKind> {
    let shared: Vec<(usize, usize)> = (0..3)
        .flat_map(|i| (0..3).map(move |j| (i, j)))
        .filter(|&(i, j)| a[i] == b[j])
        .collect();
    let (qa, qb) = (pa.map(qp), pb.map(qp));
    let s = intersection(&qa, &qb);
    match shared.len() {
        0 => (!s.is_empty()).then_some(PairKind::Apart),
        1 => {
            let v = &qa[shared[0].0];
            s.iter().any(|x| x != v).then_some(PairKind::AtVertex)
        }
        2 => {
            let (p, r) = (&qa[shared[0].0], &qa[shared[1].0]);
            s.iter()
                .any(|x| !on_segment(x, p, r))
                .then_some(PairKind::AlongEdge)
        }
        _ => None,
    }
}

/// Checks the predicate against the oracle on one pair, both ways round; returns whether it
/// intersects.
fn agree(a: [u32; 3], pa: [DVec3; 3], b: [u32; 3], pb: [DVec3; 3]) -> bool {
    let want = oracle(a, pa, b, pb);
    let got = faces_intersect(a, pa, b, pb);
    assert_eq!(got, want, "faces {a:?} {pa:?} and {b:?} {pb:?}");
    assert_eq!(
        faces_intersect(b, pb, a, pa),
        want,
        "swapped: {a:?} {pa:?} {b:?} {pb:?}"
    );
    want.is_some()
}

/// Dyadic coordinates (multiples of 1/64 in [-2, 2]): exact in every sum below.
fn dyadic(rng: &mut ChaCha8Rng) -> f64 {
    rng.random_range(-128..=128) as f64 / 64.0
}

/// A point of the plane z = x + 2y (exact for dyadic x, y), lifted by `off` along z.
fn in_plane(rng: &mut ChaCha8Rng, off: f64) -> DVec3 {
    let (x, y) = (dyadic(rng), dyadic(rng));
    DVec3::new(x, y, x + 2.0 * y + off)
}

fn offset(rng: &mut ChaCha8Rng) -> f64 {
    [0.0, 0.0, 1e-12, -1e-12, 3e-13, -1e-300][rng.random_range(0..6)]
}

fn degenerate(p: [DVec3; 3]) -> bool {
    is_degenerate_face(&p, [0, 1, 2])
}

/// Counts of the cases that intersect and those that do not, for one family.
#[derive(Default)]
struct Seen {
    yes: usize,
    no: usize,
}

impl Seen {
    fn add(&mut self, hit: bool) {
        if hit {
            self.yes += 1;
        } else {
            self.no += 1;
        }
    }
    fn both(&self, family: &str) {
        assert!(
            self.yes >= 20 && self.no >= 20,
            "{family}: {} intersecting and {} clean cases: the family tests too little",
            self.yes,
            self.no
        );
    }
}

#[test]
fn fans_wrapped_twice_round_their_vertex() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut seen = Seen::default();
    for _ in 0..200 {
        // Faces around vertex 0 turning by 1.1 to 2.2 turns in all, in the plane z = x + 2y or
        // off it by tiny offsets; each face's far corners at dyadic radii.
        let turns = rng.random_range(1.1..2.2);
        let k = rng.random_range(5..12);
        let v = DVec3::new(dyadic(&mut rng), dyadic(&mut rng), 0.0);
        let v = DVec3::new(v.x, v.y, v.x + 2.0 * v.y);
        let ring: Vec<DVec3> = (0..=k)
            .map(|i| {
                let a = std::f64::consts::TAU * turns * i as f64 / k as f64;
                let r = rng.random_range(1..=4) as f64 / 2.0;
                let (x, y) = (
                    v.x + (r * a.cos() * 64.0).round() / 64.0,
                    v.y + (r * a.sin() * 64.0).round() / 64.0,
                );
                DVec3::new(x, y, x + 2.0 * y + offset(&mut rng))
            })
            .collect();
        let faces: Vec<([u32; 3], [DVec3; 3])> = (0..k)
            .map(|i| ([0, 1 + i as u32, 2 + i as u32], [v, ring[i], ring[i + 1]]))
            .filter(|(_, p)| !degenerate(*p))
            .collect();
        for i in 0..faces.len() {
            for j in i + 1..faces.len() {
                seen.add(agree(faces[i].0, faces[i].1, faces[j].0, faces[j].1));
            }
        }
    }
    seen.both("fans");
}

#[test]
fn faces_folded_onto_a_neighbour_and_coplanar_along_an_edge() {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let mut seen = Seen::default();
    for _ in 0..3000 {
        let (p, r) = (in_plane(&mut rng, 0.0), in_plane(&mut rng, 0.0));
        let c = in_plane(&mut rng, 0.0);
        let o = offset(&mut rng);
        let s = in_plane(&mut rng, o);
        let (a, b) = ([0, 1, 2], [1, 0, 3]);
        let (pa, pb) = ([p, r, c], [r, p, s]);
        if degenerate(pa) || degenerate(pb) {
            continue;
        }
        seen.add(agree(a, pa, b, pb));
    }
    seen.both("edge-sharing");
}

#[test]
fn faces_touching_at_a_point_and_t_junctions() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut seen = Seen::default();
    for _ in 0..3000 {
        let pa = [0, 1, 2].map(|_| in_plane(&mut rng, 0.0));
        if degenerate(pa) {
            continue;
        }
        // A corner of the second face on the first one: at a corner, on an edge's midpoint (a
        // T-junction), at a dyadic point of the plane, or 1e-12 off it; the others anywhere.
        let k = rng.random_range(0..3);
        let touch = match rng.random_range(0..4) {
            0 => pa[k],
            1 => 0.5 * (pa[k] + pa[(k + 1) % 3]),
            2 => in_plane(&mut rng, 0.0),
            _ => {
                let o = offset(&mut rng);
                in_plane(&mut rng, o)
            }
        };
        let o = offset(&mut rng);
        let pb = [touch, in_plane(&mut rng, 1.0), in_plane(&mut rng, o)];
        if degenerate(pb) {
            continue;
        }
        // Sharing no index; then sharing the first one's corner k when they touch there.
        seen.add(agree([0, 1, 2], pa, [3, 4, 5], pb));
        if touch == pa[k] {
            let mut b = [3, 4, 5];
            b[0] = k as u32;
            seen.add(agree([0, 1, 2], pa, b, pb));
        }
    }
    seen.both("touching");
}

#[test]
fn random_faces_sharing_a_vertex_in_space() {
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let mut seen = Seen::default();
    for _ in 0..3000 {
        let v = in_plane(&mut rng, 0.0);
        let mut r = || DVec3::new(dyadic(&mut rng), dyadic(&mut rng), dyadic(&mut rng) / 8.0);
        let pa = [v, v + r(), v + r()];
        let pb = [v + r(), v, v + r()];
        if degenerate(pa) || degenerate(pb) {
            continue;
        }
        seen.add(agree([0, 1, 2], pa, [3, 0, 4], pb));
    }
    seen.both("vertex-sharing in space");
}

/// A wavy grid whose vertices are pushed about (some far enough to fold faces over their
/// neighbours), searched whole: the BVH search finds exactly the pairs the oracle finds over
/// all pairs of non-degenerate faces.
#[test]
fn whole_meshes_agree_with_the_oracle_over_all_pairs() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let (mut total, mut by_kind) = (0, [0usize; 3]);
    for round in 0..12 {
        let n = 7usize;
        let mut positions: Vec<DVec3> = (0..n * n)
            .map(|k| {
                let (i, j) = ((k % n) as f64, (k / n) as f64);
                DVec3::new(i, j, 0.0)
            })
            .collect();
        for p in positions.iter_mut() {
            if rng.random_range(0..4) == 0 {
                let s = if round % 2 == 0 { 1.5 } else { 0.6 };
                *p += DVec3::new(
                    (dyadic(&mut rng) * s * 64.0).round() / 64.0,
                    (dyadic(&mut rng) * s * 64.0).round() / 64.0,
                    [0.0, 1e-12, dyadic(&mut rng) / 4.0][rng.random_range(0..3)],
                );
            }
        }
        let mut triangles = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let k = (j * n + i) as u32;
                let n = n as u32;
                triangles.push([k, k + 1, k + n + 1]);
                triangles.push([k, k + n + 1, k + n]);
            }
        }
        let found = intersecting_pairs(&positions, &triangles);
        let usable = |f: usize| !is_degenerate_face(&positions, triangles[f]);
        let mut want = Vec::new();
        for f in 0..triangles.len() {
            for g in f + 1..triangles.len() {
                if !usable(f) || !usable(g) {
                    continue;
                }
                let (a, b) = (triangles[f], triangles[g]);
                let c = |t: [u32; 3]| t.map(|v| positions[v as usize]);
                if let Some(kind) = oracle(a, c(a), b, c(b)) {
                    want.push([f as u32, g as u32]);
                    by_kind[kind as usize] += 1;
                }
            }
        }
        assert_eq!(found, want, "round {round}");
        total += want.len();
    }
    assert!(
        total > 0 && by_kind.iter().all(|&k| k > 0),
        "pairs by kind (apart, at a vertex, along an edge): {by_kind:?}: the meshes test too little"
    );
}
