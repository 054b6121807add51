//! Tests of the edit mesh: every operator on small meshes built in code, with exact counts,
//! each ending in `sanity_check()`.

use super::*;
use crate::mesh::test_meshes::grid;

/// A regular tetrahedron's corners and outward faces.
fn tetrahedron(policy: SlotPolicy) -> EditMesh<()> {
    let positions = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    let mesh = TriMesh::new(positions, vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]);
    EditMesh::from_trimesh(&mesh, |_| (), policy)
}

/// The octahedron with corners ±x (0, 1), ±y (2, 3), ±z (4, 5), faces outward.
fn octahedron(policy: SlotPolicy) -> EditMesh<u32> {
    let positions = vec![
        DVec3::X,
        -DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
    ];
    let faces = vec![
        [4, 0, 2],
        [4, 2, 1],
        [4, 1, 3],
        [4, 3, 0],
        [5, 2, 0],
        [5, 1, 2],
        [5, 3, 1],
        [5, 0, 3],
    ];
    EditMesh::from_trimesh(&TriMesh::new(positions, faces), |f| f, policy)
}

/// A triangular bipyramid: equator 0, 1, 2 at z = 0, apexes 3 (+z) and 4 (−z).
fn bipyramid() -> EditMesh<()> {
    let a = std::f64::consts::TAU / 3.0;
    let mut positions: Vec<DVec3> = (0..3)
        .map(|k| DVec3::new((a * k as f64).cos(), (a * k as f64).sin(), 0.0))
        .collect();
    positions.extend([DVec3::Z, -DVec3::Z]);
    let faces = vec![
        [3, 0, 1],
        [3, 1, 2],
        [3, 2, 0],
        [4, 1, 0],
        [4, 2, 1],
        [4, 0, 2],
    ];
    EditMesh::from_trimesh(&TriMesh::new(positions, faces), |_| (), SlotPolicy::Reuse)
}

/// A flat fan: centre 0 and a hexagon 1..=6 around it.
fn fan() -> EditMesh<()> {
    let mut positions = vec![DVec3::ZERO];
    let a = std::f64::consts::TAU / 6.0;
    positions.extend((0..6).map(|k| DVec3::new((a * k as f64).cos(), (a * k as f64).sin(), 0.0)));
    let faces = (1..=6u32).map(|k| [0, k, k % 6 + 1]).collect();
    EditMesh::from_trimesh(&TriMesh::new(positions, faces), |_| (), SlotPolicy::Reuse)
}

fn live_count<L: Copy>(m: &EditMesh<L>) -> usize {
    m.live_faces().0.len()
}

/// V − E + F over the vertices in a face.
fn euler<L: Copy>(m: &EditMesh<L>) -> i64 {
    let (faces, _) = m.live_faces();
    let v = (0..m.vertex_count() as u32)
        .filter(|&v| m.degree(v) > 0)
        .count() as i64;
    let e = m
        .directed_edges()
        .filter(|&(a, b)| a < b || m.face_on(b, a).is_none())
        .count();
    v - e as i64 + faces.len() as i64
}

#[test]
fn meshes_built_in_code_are_sane() {
    let t = tetrahedron(SlotPolicy::Reuse);
    assert_eq!(t.sanity_check(), Ok(()));
    assert_eq!((live_count(&t), euler(&t)), (4, 2));
    let o = octahedron(SlotPolicy::Reuse);
    assert_eq!(o.sanity_check(), Ok(()));
    assert!((0..6).all(|v| o.degree(v) == 4 && !o.is_boundary_vertex(v)));
    assert!(o.boundary_half_edges().is_empty());
    assert_eq!(o.ring(4), vec![0, 1, 2, 3]);
    let g = EditMesh::from_trimesh(
        &grid(4, |i, j| DVec3::new(i as f64, j as f64, 0.0)),
        |_| (),
        SlotPolicy::Reuse,
    );
    assert_eq!(g.sanity_check(), Ok(()));
    assert_eq!((live_count(&g), euler(&g)), (32, 1));
    assert_eq!(g.boundary_half_edges().len(), 16);
    assert!(g.is_boundary_vertex(0) && !g.is_boundary_vertex(2 * 5 + 2));
    let f = fan();
    assert_eq!(f.sanity_check(), Ok(()));
    assert_eq!(f.degree(0), 6);
}

/// Regression (issue 15, bunny's small hole): a vertex next to the boundary, whose faces have
/// boundary edges it is not on, is not a boundary vertex; it counted as one, so the optimizer
/// never moved it and a sliver on the hole stayed.
#[test]
fn a_vertex_beside_the_boundary_is_not_on_it() {
    let g = EditMesh::from_trimesh(
        &grid(4, |i, j| DVec3::new(i as f64, j as f64, 0.0)),
        |_| (),
        SlotPolicy::Reuse,
    );
    // (1, 1) is in the face [0, 1, 6], whose edge 0-1 is on the boundary.
    assert!(g
        .faces_around(6)
        .iter()
        .any(|&f| g.face(f) == Some([0, 1, 6])));
    assert!(!g.is_boundary_vertex(6));
    let on: Vec<u32> = (0..25).filter(|&v| g.is_boundary_vertex(v)).collect();
    let expected: Vec<u32> = (0..25u32)
        .filter(|v| v % 5 == 0 || v % 5 == 4 || v / 5 == 0 || v / 5 == 4)
        .collect();
    assert_eq!(on, expected);
}

#[test]
fn flip_turns_an_edge_of_the_octahedron() {
    let mut m = octahedron(SlotPolicy::Reuse);
    // Edge 4–0 has faces [4, 0, 2] (slot 0) and [0, 4, 3] (slot 3): it becomes 2–3.
    assert_eq!(m.flip_edge(4, 0, 99), Ok([0, 3]));
    assert_eq!(m.face(0), Some([4, 3, 2]));
    assert_eq!(m.face(3), Some([0, 2, 3]));
    assert_eq!((m.label(0), m.label(1), m.label(3)), (99, 1, 99));
    assert!(!m.has_edge(4, 0) && m.has_edge(2, 3));
    assert_eq!([0, 2, 3, 4].map(|v| m.degree(v)), [3, 5, 5, 3]);
    assert_eq!(m.sanity_check(), Ok(()));
    assert_eq!((live_count(&m), euler(&m)), (8, 2));
    // And back.
    // (the face on 2 → 3 is [0, 2, 3], in slot 3).
    assert_eq!(m.flip_edge(2, 3, 7), Ok([3, 0]));
    assert!(m.has_edge(4, 0) && !m.has_edge(2, 3));
    assert_eq!(m.sanity_check(), Ok(()));
}

#[test]
fn flip_with_append_policy_puts_the_new_faces_at_the_end() {
    let mut m = octahedron(SlotPolicy::Append);
    assert_eq!(m.flip_edge(4, 0, 99), Ok([8, 9]));
    assert_eq!((m.slots(), live_count(&m)), (10, 8));
    assert_eq!((m.face(0), m.face(3)), (None, None));
    assert_eq!(m.sanity_check(), Ok(()));
}

#[test]
fn flip_refuses_boundary_edges_and_duplicate_edges() {
    let mut f = fan();
    assert_eq!(
        f.flip_edge(1, 2, ()),
        Err(EditError::NotInteriorEdge { edge: [1, 2] })
    );
    // In the tetrahedron the two opposite corners of every edge are already joined.
    let mut t = tetrahedron(SlotPolicy::Reuse);
    assert!(matches!(
        t.flip_edge(0, 1, ()),
        Err(EditError::FlipWouldDuplicateEdge { .. })
    ));
    // A blocked direction counts as an edge.
    let mut o = octahedron(SlotPolicy::Reuse);
    o.block_directed_edge(3, 2);
    assert_eq!(
        o.flip_edge(4, 0, 9),
        Err(EditError::FlipWouldDuplicateEdge { edge: [2, 3] })
    );
    assert_eq!(o.face(0), Some([4, 0, 2]));
    for m in [&f, &t] {
        assert_eq!(m.sanity_check(), Ok(()));
    }
    assert_eq!(o.sanity_check(), Ok(()));
}

#[test]
fn face_split_makes_three_faces_around_a_new_vertex() {
    let mut m = tetrahedron(SlotPolicy::Reuse);
    let v = m.add_vertex(DVec3::splat(0.4));
    assert_eq!(m.split_face(3, v, ()), Ok([3, 4, 5]));
    assert_eq!(
        (m.face(3), m.face(4), m.face(5)),
        (Some([1, 2, v]), Some([2, 3, v]), Some([3, 1, v]))
    );
    assert_eq!(m.degree(v), 3);
    assert_eq!(m.sanity_check(), Ok(()));
    assert_eq!((live_count(&m), euler(&m)), (6, 2));
    // The vertex is in use now; a vertex on a corner would make faces without area.
    assert_eq!(
        m.split_face(0, v, ()),
        Err(EditError::VertexInUse { vertex: v })
    );
    let w = m.add_vertex(DVec3::X);
    assert!(matches!(
        m.split_face(0, w, ()),
        Err(EditError::Degenerate { .. })
    ));
    assert_eq!(m.pop_vertex(), Some(DVec3::X));
    assert_eq!(m.pop_vertex(), None, "vertex {v} is in a face");
    assert_eq!(m.sanity_check(), Ok(()));
    assert_eq!(live_count(&m), 6);
}

#[test]
fn edge_split_makes_four_faces_around_a_new_vertex() {
    let mut m = octahedron(SlotPolicy::Reuse);
    let v = m.add_vertex(DVec3::new(0.6, 0.0, 0.6));
    // [4, 0, 2] in slot 0 and [0, 4, 3] in slot 3.
    assert_eq!(m.split_edge(4, 0, v, 9), Ok([0, 8, 3, 9]));
    assert_eq!(m.face(0), Some([4, v, 2]));
    assert_eq!(m.face(8), Some([v, 0, 2]));
    assert_eq!(m.face(3), Some([0, v, 3]));
    assert_eq!(m.face(9), Some([v, 4, 3]));
    assert!(!m.has_edge(4, 0));
    assert_eq!(m.degree(v), 4);
    assert_eq!(m.sanity_check(), Ok(()));
    assert_eq!((live_count(&m), euler(&m)), (10, 2));
    let mut f = fan();
    let w = f.add_vertex(DVec3::new(0.9, 0.5, 0.0));
    assert_eq!(
        f.split_edge(1, 2, w, ()),
        Err(EditError::NotInteriorEdge { edge: [1, 2] })
    );
    assert_eq!(f.sanity_check(), Ok(()));
}

#[test]
fn collapse_keeps_the_link_condition() {
    let mut m = octahedron(SlotPolicy::Reuse);
    // 0 (+x) into 4 (+z): the ends share exactly 2 and 3, which have four faces each.
    assert_eq!(m.collapse_edge(0, 4, DVec3::new(0.5, 0.0, 0.5), 9), Ok(()));
    assert_eq!(m.degree(0), 0);
    assert_eq!(m.position(4), DVec3::new(0.5, 0.0, 0.5));
    assert_eq!((live_count(&m), euler(&m)), (6, 2));
    assert_eq!((m.face(0), m.face(3)), (None, None));
    assert_eq!(m.face(4), Some([5, 2, 4]));
    assert_eq!(m.label(4), 9);
    assert_eq!(m.sanity_check(), Ok(()));
    // The result is a triangular bipyramid: every equatorial edge now fails.
    let mut b = bipyramid();
    assert_eq!(
        b.collapse_edge(0, 1, DVec3::ZERO, ()),
        Err(EditError::LinkCondition { edge: [0, 1] })
    );
    // The tetrahedron: the opposite corners have three faces only.
    let mut t = tetrahedron(SlotPolicy::Reuse);
    assert_eq!(
        t.collapse_edge(0, 1, DVec3::ZERO, ()),
        Err(EditError::LinkCondition { edge: [0, 1] })
    );
    // A boundary edge is not collapsed here.
    let mut f = fan();
    assert_eq!(
        f.collapse_edge(1, 2, DVec3::X, ()),
        Err(EditError::NotInteriorEdge { edge: [1, 2] })
    );
    for m in [&b, &t, &f] {
        assert_eq!(m.sanity_check(), Ok(()));
        assert_eq!(live_count(m), if m.vertex_count() == 4 { 4 } else { 6 });
    }
}

#[test]
fn collapse_on_a_grid_and_its_refusals() {
    let mut g = EditMesh::from_trimesh(
        &grid(6, |i, j| DVec3::new(i as f64, j as f64, 0.0)),
        |_| (),
        SlotPolicy::Append,
    );
    // Interior edge (2,2)–(3,2): vertices 16 and 17, opposite vertices (2,1) and (3,3) with
    // six faces each.
    assert_eq!(
        g.collapse_edge(17, 16, DVec3::new(2.5, 2.0, 0.0), ()),
        Ok(())
    );
    assert_eq!(g.sanity_check(), Ok(()));
    assert_eq!((live_count(&g), euler(&g)), (70, 1));
    assert_eq!((g.degree(17), g.degree(16)), (0, 8));
    // Next to the boundary, the edge (1,1)–(2,1) has the opposite vertex (1,0) with three
    // faces: refused.
    let mut h = EditMesh::from_trimesh(
        &grid(4, |i, j| DVec3::new(i as f64, j as f64, 0.0)),
        |_| (),
        SlotPolicy::Append,
    );
    assert_eq!(
        h.collapse_edge(7, 6, DVec3::new(1.5, 1.0, 0.0), ()),
        Err(EditError::LinkCondition { edge: [7, 6] })
    );
    assert_eq!(h.sanity_check(), Ok(()));
    // An interior edge between two boundary vertices (the diagonal of a corner square of a
    // 1 × 1 grid) is refused.
    let mut one = EditMesh::from_trimesh(
        &grid(1, |i, j| DVec3::new(i as f64, j as f64, 0.0)),
        |_| (),
        SlotPolicy::Reuse,
    );
    assert!(matches!(
        one.collapse_edge(0, 3, DVec3::ZERO, ()),
        Err(EditError::LinkCondition { .. })
    ));
    assert_eq!(one.sanity_check(), Ok(()));
}

#[test]
fn relocation_moves_a_vertex_and_refuses_non_finite_positions() {
    let mut m = fan();
    assert_eq!(m.relocate_vertex(0, DVec3::new(0.1, 0.1, 0.0)), Ok(()));
    assert_eq!(m.position(0), DVec3::new(0.1, 0.1, 0.0));
    assert_eq!(
        m.relocate_vertex(0, DVec3::NAN),
        Err(EditError::NonFinitePosition { vertex: 0 })
    );
    assert_eq!(
        m.relocate_vertex(7, DVec3::ZERO),
        Err(EditError::NoSuchVertex { vertex: 7 })
    );
    assert_eq!(m.position(0), DVec3::new(0.1, 0.1, 0.0));
    assert_eq!(m.sanity_check(), Ok(()));
}

#[test]
fn a_removed_face_leaves_a_hole_that_fill_hole_closes() {
    let mut m = octahedron(SlotPolicy::Append);
    assert_eq!(m.remove_face(0), Ok(()));
    assert_eq!(m.remove_face(0), Err(EditError::NoSuchFace { face: 0 }));
    assert_eq!(m.boundary_half_edges(), vec![(0, 2), (2, 4), (4, 0)]);
    assert_eq!(m.sanity_check(), Ok(()));
    assert_eq!(euler(&m), 1);
    // All or nothing: the second triangle repeats the first's directed edges.
    assert!(matches!(
        m.fill_hole(&[[4, 0, 2], [4, 0, 2]], 9),
        Err(EditError::EdgeInUse { .. })
    ));
    assert_eq!(m.boundary_half_edges().len(), 3);
    assert_eq!(live_count(&m), 7);
    assert_eq!(m.sanity_check(), Ok(()));
    // The reverse would close the hole inside out.
    assert!(m.fill_hole(&[[4, 2, 0]], 9).is_err());
    assert_eq!(m.fill_hole(&[[4, 0, 2]], 9), Ok(vec![9]));
    assert!(m.boundary_half_edges().is_empty());
    assert_eq!((live_count(&m), euler(&m)), (8, 2));
    assert_eq!(m.sanity_check(), Ok(()));
}

#[test]
fn add_face_refuses_what_would_break_an_invariant() {
    let positions = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z, 2.0 * DVec3::X];
    let mut m: EditMesh<()> = EditMesh::new(positions, SlotPolicy::Append);
    assert_eq!(m.add_face([0, 1, 2], ()), Ok(0));
    assert_eq!(
        m.add_face([0, 0, 1], ()),
        Err(EditError::RepeatedCorner { face: [0, 0, 1] })
    );
    assert_eq!(
        m.add_face([0, 1, 9], ()),
        Err(EditError::NoSuchVertex { vertex: 9 })
    );
    assert_eq!(
        m.add_face([0, 1, 3], ()),
        Err(EditError::EdgeInUse { edge: [0, 1] })
    );
    assert_eq!(
        m.add_face([0, 2, 1], ()),
        Err(EditError::ReverseOfFace {
            face: [0, 2, 1],
            existing: 0
        })
    );
    assert_eq!(
        m.add_face([4, 1, 0], ()),
        Err(EditError::Degenerate { face: [4, 1, 0] })
    );
    m.block_directed_edge(2, 1);
    assert_eq!(
        m.add_face([2, 1, 3], ()),
        Err(EditError::EdgeInUse { edge: [2, 1] })
    );
    assert_eq!(m.add_face([1, 0, 3], ()), Ok(1));
    assert_eq!(m.sanity_check(), Ok(()));
    // 2 → 1 is blocked: not a hole's half-edge.
    assert_eq!(m.boundary_half_edges(), vec![(0, 2), (1, 3), (3, 0)]);
}

#[test]
fn sanity_check_finds_broken_invariants() {
    let p = vec![
        DVec3::ZERO,
        DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::X - DVec3::Y,
    ];
    let check = |faces: Vec<[u32; 3]>| {
        EditMesh::<()>::from_trimesh(&TriMesh::new(p.clone(), faces), |_| (), SlotPolicy::Reuse)
            .sanity_check()
    };
    // Three faces on the edge 0–1 (two of them on the direction 0 → 1).
    assert!(matches!(
        check(vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]]),
        Err(EditViolation::DirectedEdge { edge: [0, 1], .. })
    ));
    // Two faces on the same vertices, oriented oppositely.
    assert_eq!(
        check(vec![[0, 1, 2], [0, 2, 1]]),
        Err(EditViolation::DuplicateFace { faces: [0, 1] })
    );
    // A bow tie: two fans at vertex 0.
    assert_eq!(
        check(vec![[0, 1, 2], [0, 3, 5]]),
        Err(EditViolation::NonManifoldVertex { vertex: 0, fans: 2 })
    );
    // A face without area.
    let mut q = p.clone();
    q[2] = 2.0 * DVec3::X;
    let flat =
        EditMesh::<()>::from_trimesh(&TriMesh::new(q, vec![[0, 1, 2]]), |_| (), SlotPolicy::Reuse);
    assert_eq!(
        flat.sanity_check(),
        Err(EditViolation::DegenerateFace { face: 0 })
    );
}

/// The octahedron with every face split in four `level` times, on the unit sphere.
fn octasphere(level: usize) -> EditMesh<()> {
    let o = octahedron(SlotPolicy::Reuse);
    let mut positions = o.positions().to_vec();
    let mut faces = o.live_faces().0;
    for _ in 0..level {
        let mut mid: FxHashMap<(u32, u32), u32> = FxHashMap::default();
        let mut next = Vec::new();
        for t in faces {
            let mut m = [0u32; 3];
            for k in 0..3 {
                let (a, b) = (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]));
                m[k] = *mid.entry((a, b)).or_insert_with(|| {
                    let p = (positions[a as usize] + positions[b as usize]).normalize();
                    positions.push(p);
                    (positions.len() - 1) as u32
                });
            }
            next.extend([
                [t[0], m[0], m[2]],
                [t[1], m[1], m[0]],
                [t[2], m[2], m[1]],
                m,
            ]);
        }
        faces = next;
    }
    EditMesh::from_trimesh(&TriMesh::new(positions, faces), |_| (), SlotPolicy::Reuse)
}

/// Seeded random sequences of every operator on a sphere: each either refuses (the mesh
/// unchanged) or keeps every invariant and the Euler characteristic 2.
#[test]
fn random_operator_sequences_keep_every_invariant() {
    for policy in [SlotPolicy::Reuse, SlotPolicy::Append] {
        let mut m = octasphere(2);
        m.policy = policy;
        assert_eq!((m.live_faces().0.len(), euler(&m)), (128, 2));
        let mut state = 1u64;
        let mut next = |n: usize| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 33) as usize) % n
        };
        let mut done = [0usize; 5];
        for _ in 0..1500 {
            let (_, slots) = m.live_faces();
            let f = slots[next(slots.len())];
            let t = m.face(f).unwrap_or_else(|| unreachable!());
            let k = next(3);
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let before = (m.live_faces().0.len(), m.vertex_count());
            let op = next(5);
            let ok = match op {
                0 => m.flip_edge(a, b, ()).is_ok(),
                1 => {
                    let p = m.corners(t).iter().sum::<DVec3>().normalize();
                    let v = m.add_vertex(p);
                    let ok = m.split_face(f, v, ()).is_ok();
                    if !ok {
                        m.pop_vertex();
                    }
                    ok
                }
                2 => {
                    let v = m.add_vertex((m.position(a) + m.position(b)).normalize());
                    let ok = m.split_edge(a, b, v, ()).is_ok();
                    if !ok {
                        m.pop_vertex();
                    }
                    ok
                }
                3 => {
                    let p = (m.position(a) + m.position(b)).normalize();
                    m.collapse_edge(a, b, p, ()).is_ok()
                }
                _ => {
                    let p = m.position(a) + 0.01 * (m.position(b) - m.position(a));
                    m.relocate_vertex(a, p.normalize()).is_ok()
                }
            };
            if ok {
                done[op] += 1;
            } else {
                assert_eq!(before, (m.live_faces().0.len(), m.vertex_count()));
            }
            assert_eq!(m.sanity_check(), Ok(()), "after operator {op} on {a}-{b}");
            assert_eq!(euler(&m), 2);
        }
        // Every operator ran, and some refusals happened too.
        assert!(done.iter().all(|&d| d > 50), "{done:?}");
        assert!(done.iter().sum::<usize>() < 1500, "{done:?}");
    }
}
