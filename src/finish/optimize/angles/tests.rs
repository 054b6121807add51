use super::*;
use crate::geometry::self_intersection::classified_pairs;
use crate::geometry::self_intersection::intersecting_pairs;
use crate::mesh::test_meshes::grid;

/// The smallest angle of the live faces, degrees.
fn theta_min(m: &Mesh) -> f64 {
    m.live_faces()
        .0
        .into_iter()
        .map(|t| min_angle(m, t))
        .fold(f64::INFINITY, f64::min)
}

/// A flat `n × n` grid of unit squares as the mesh to mend (every face labelled with its
/// index) and as the surface.
fn flat(n: usize) -> (TriMesh, MeshSurface) {
    let g = grid(n, |i, j| DVec3::new(i as f64, j as f64, 0.0));
    let surface = MeshSurface::new(&g).unwrap();
    (g, surface)
}

/// The intersecting pairs of `m`'s live faces ([`intersecting_pairs`]), as slots, the smaller
/// first, sorted: a search of the whole mesh.
fn slot_pairs(m: &Mesh) -> Vec<[u32; 2]> {
    as_slots(m, intersecting_pairs)
}

/// The pairs `search` finds over `m`'s live faces (indices into them), as slots, the smaller
/// first, sorted.
fn as_slots(m: &Mesh, search: impl Fn(&[DVec3], &[[u32; 3]]) -> Vec<[u32; 2]>) -> Vec<[u32; 2]> {
    let (live, slots) = m.live_faces();
    let mut pairs: Vec<[u32; 2]> = search(m.positions(), &live)
        .into_iter()
        .map(|p| {
            let [a, b] = p.map(|i| slots[i as usize]);
            [a.min(b), a.max(b)]
        })
        .collect();
    pairs.sort_unstable();
    pairs
}

fn limits() -> Limits {
    Limits::new(&OptimizeParams::default(), 1.0)
}

#[test]
fn the_faces_left_out_of_bounds_are_counted_by_where_they_are() {
    // A 6 × 6 grid of unit squares (45°, 45°, 90°: in bounds) with an interior vertex pulled
    // most of the way to a neighbour (its faces out of bounds), then a boundary one.
    let (g, _) = flat(6);
    let mut m: Mesh = EditMesh::from_trimesh(&g, Some, SlotPolicy::Reuse);
    let none = |_: [u32; 3]| false;
    assert_eq!(faces_left(&m, &limits(), none), FacesLeft::default());
    let v = 3 * 7 + 3;
    let p = m.position(v);
    m.relocate_vertex(v, p + DVec3::new(0.8, 0.0, 0.0)).unwrap();
    let left = faces_left(&m, &limits(), none);
    assert!(left.total > 0);
    assert_eq!((left.at_creases, left.on_boundary), (0, 0));
    assert_eq!(
        faces_left(&m, &limits(), |_| true).at_input_crossings,
        left.total
    );
    m.protect_edge(v, v + 1);
    assert_eq!(faces_left(&m, &limits(), none).at_creases, left.total);
    let b = 3 * 7;
    let q = m.position(b);
    m.relocate_vertex(b, q + DVec3::new(0.8, 0.0, 0.0)).unwrap();
    let more = faces_left(&m, &limits(), none);
    assert!(more.on_boundary > 0);
    assert_eq!(more.total, more.at_creases + more.on_boundary);
}

#[test]
fn a_vertex_of_three_faces_near_an_edge_is_collapsed_away() {
    // (Horse at 2000, seed 4: a vertex of three faces with a 137° angle, 17.6° beside it.)
    // One grid triangle split at a point near the middle of its long edge.
    let (g, surface) = flat(6);
    let mut m: Mesh = EditMesh::from_trimesh(&g, Some, SlotPolicy::Reuse);
    let f = g.triangles.iter().position(|&t| t == [14, 15, 22]).unwrap() as u32;
    let [a, _, c] = m.corners([14, 15, 22]);
    let v = m.add_vertex(a.lerp(c, 0.5) + DVec3::new(0.12, -0.12, 0.0));
    m.split_face(f, v, None).unwrap();
    let before = theta_min(&m);
    assert!(before < 20.0, "{before}");
    let fixed = vec![false; m.vertex_count()];
    let (made, _) = mend_faces(&mut m, &surface, None, None, &fixed, &limits(), None, None);
    assert!(made.ops >= 1);
    assert_eq!(m.degree(v), 0, "the vertex is gone");
    assert!(theta_min(&m) >= 30.0, "{before} -> {}", theta_min(&m));
    assert_eq!(m.sanity_check(), Ok(()));
}

#[test]
fn a_sliver_on_a_short_fixed_boundary_edge_is_mended_and_the_boundary_stays() {
    // (Bunny's small hole: two boundary samples 0.4 spacings apart, the interior vertex
    // across them a whole spacing away.) A boundary vertex of the grid moved along the
    // boundary towards its neighbour; the boundary is fixed.
    let (mut g, surface) = flat(6);
    g.positions[3] = DVec3::new(2.6, 0.0, 0.0);
    let mut m: Mesh = EditMesh::from_trimesh(&g, Some, SlotPolicy::Reuse);
    let fixed: Vec<bool> = (0..m.vertex_count() as u32)
        .map(|v| m.is_boundary_vertex(v))
        .collect();
    let before = theta_min(&m);
    assert!(before < 25.0, "{before}");
    let boundary: Vec<DVec3> = (0..m.vertex_count())
        .filter(|&v| fixed[v])
        .map(|v| m.position(v as u32))
        .collect();
    mend_faces(&mut m, &surface, None, None, &fixed, &limits(), None, None);
    assert!(theta_min(&m) >= 25.0, "{before} -> {}", theta_min(&m));
    let after: Vec<DVec3> = (0..m.vertex_count())
        .filter(|&v| fixed[v])
        .map(|v| m.position(v as u32))
        .collect();
    assert_eq!(boundary, after);
    assert!(m.positions().iter().all(|p| p.z == 0.0));
    assert_eq!(m.sanity_check(), Ok(()));
}

#[test]
fn a_mesh_without_small_angles_is_left_alone() {
    let (g, surface) = flat(4);
    let mut m: Mesh = EditMesh::from_trimesh(&g, Some, SlotPolicy::Reuse);
    let fixed = vec![false; m.vertex_count()];
    assert_eq!(
        mend_faces(&mut m, &surface, None, None, &fixed, &limits(), None, None)
            .0
            .ops,
        0
    );
    assert_eq!(m.to_trimesh(), g);
}

/// Two parallel 6 × 6 grids 0.2 apart: (the input surface, the mesh with vertex `poke` of
/// the upper grid pushed to z = -0.3, through the lower grid).
fn poked_sheets() -> (MeshSurface, TriMesh, usize) {
    let a = grid(6, |i, j| DVec3::new(i as f64, j as f64, 0.0));
    let b = grid(6, |i, j| DVec3::new(i as f64 + 0.3, j as f64 + 0.4, 0.2));
    let mut both = a.clone();
    let off = both.positions.len() as u32;
    both.positions.extend(b.positions.iter().copied());
    both.triangles
        .extend(b.triangles.iter().map(|t| t.map(|v| v + off)));
    let surface = MeshSurface::new(&both).unwrap();
    let poke = off as usize + 3 * 7 + 3;
    both.positions[poke].z = -0.3;
    (surface, both, poke)
}

#[test]
fn removing_the_vertex_of_a_folded_fan_unfolds_it_and_a_peak_is_not_removed() {
    // An interior vertex of a flat grid pushed past its neighbour: part of its fan turns over
    // and lies on the rest (folds: pairs sharing a vertex that overlap). A move or collapse
    // compares its new faces with the folded faces' own (turned over) normals; the removal
    // triangulates the link on the side of the fan's mean normal.
    let (g, _) = flat(6);
    let mut m: Mesh = EditMesh::from_trimesh(&g, Some, SlotPolicy::Reuse);
    let v = 3 * 7 + 3;
    let p = m.position(v);
    m.relocate_vertex(v, p + DVec3::new(1.4, 0.3, 0.0)).unwrap();
    let folded = m.to_trimesh();
    let (pairs, _) = classified_pairs(&folded.positions, &folded.triangles);
    assert!(
        pairs.iter().any(|&([f, g], _)| share_a_vertex(
            folded.triangles[f as usize],
            folded.triangles[g as usize]
        )),
        "the case must fold: {pairs:?}"
    );
    let guard = CrossingGuard::new(&m);
    // sigma_p 4: the old position (1.4 from the grid's vertex) may be that far from the faces.
    let wide = Limits::new(&OptimizeParams::default(), 4.0);
    let ((old, new), faces) = try_remove(&m, &guard, v, &wide).expect("a removal");
    assert!(new > old, "{old} -> {new}");
    assert_eq!(faces.len(), m.degree(v) - 2);
    remove_vertex(&mut m, v, &faces).unwrap();
    assert_eq!(m.degree(v), 0);
    let out = m.to_trimesh();
    let (pairs, _) = classified_pairs(&out.positions, &out.triangles);
    assert!(pairs.is_empty(), "{pairs:?}");
    // Every face faces up again, and together they cover the grid once.
    let area: f64 = out
        .triangles
        .iter()
        .map(|&t| {
            let [a, b, c] = t.map(|i| out.positions[i as usize]);
            let z = (b - a).cross(c - a).z;
            assert!(z > 0.0, "{t:?} faces down");
            0.5 * z
        })
        .sum();
    assert!((area - 36.0).abs() < 1e-9, "{area}");
    assert_eq!(m.sanity_check(), Ok(()));

    // A vertex lifted 2 off the grid: its removal would leave it farther from the faces than
    // a collapse may (0.25 at sigma_p 1), so it is not offered.
    let (g, _) = flat(6);
    let mut m: Mesh = EditMesh::from_trimesh(&g, Some, SlotPolicy::Reuse);
    m.relocate_vertex(v, p + DVec3::new(0.0, 0.0, 2.0)).unwrap();
    let guard = CrossingGuard::new(&m);
    assert!(try_remove(&m, &guard, v, &limits()).is_none());
    assert!(try_remove(
        &m,
        &guard,
        v,
        &Limits::new(&OptimizeParams::default(), 16.0)
    )
    .is_some());
}

#[test]
fn a_face_through_another_sheet_is_mended_and_nothing_crosses_after() {
    let (surface, mesh, poke) = poked_sheets();
    assert!(!intersecting_pairs(&mesh.positions, &mesh.triangles).is_empty());
    let mut m: Mesh = EditMesh::from_trimesh(&mesh, Some, SlotPolicy::Reuse);
    let fixed = vec![false; m.vertex_count()];
    // sigma_p 4: the pass may move the mesh by up to 1 off the surface, more than the poke.
    let wide = Limits::new(&OptimizeParams::default(), 4.0);
    let (made, left) = mend_faces(&mut m, &surface, None, None, &fixed, &wide, None, None);
    assert!(made.ops >= 1);
    let out = m.to_trimesh();
    let pairs = intersecting_pairs(&out.positions, &out.triangles);
    assert!(pairs.is_empty(), "{pairs:?}");
    // The pairs the pass kept up to date are what a search finds (none: those of the start
    // are gone).
    assert_eq!(left, slot_pairs(&m));
    assert!(
        m.position(poke as u32).z > 0.0,
        "{}",
        m.position(poke as u32)
    );
    assert!(theta_min(&m) >= 30.0, "{}", theta_min(&m));
    assert_eq!(m.sanity_check(), Ok(()));
    // Without moves that far (sigma_p 1: 0.25), nothing is made that would cross.
    let mut m: Mesh = EditMesh::from_trimesh(&mesh, Some, SlotPolicy::Reuse);
    let (_, left) = mend_faces(&mut m, &surface, None, None, &fixed, &limits(), None, None);
    assert_eq!(left, slot_pairs(&m));
    let out = m.to_trimesh();
    assert!(
        intersecting_pairs(&out.positions, &out.triangles).len()
            <= intersecting_pairs(&mesh.positions, &mesh.triangles).len()
    );
    assert_eq!(m.sanity_check(), Ok(()));
}

#[test]
fn the_crossing_guard_sees_faces_near_and_faces_changed() {
    // Two parallel grids 0.2 apart.
    let (both, off) = crate::mesh::test_meshes::stacked_grids(4);
    assert!(intersecting_pairs(&both.positions, &both.triangles).is_empty());
    let mut m: Mesh = EditMesh::from_trimesh(&both, Some, SlotPolicy::Reuse);
    let mut guard = CrossingGuard::new(&m);
    // The faces around an upper vertex, were it pushed through the lower grid.
    let v = off + 2 * 5 + 2;
    let slots = m.faces_around(v).to_vec();
    let faces: Vec<[u32; 3]> = slots.iter().map(|&f| face(&m, f)).collect();
    assert!(!guard.crosses(&m, &faces, &slots));
    let p = m.position(v);
    m.relocate_vertex(v, p - DVec3::new(0.0, 0.0, 0.5)).unwrap();
    assert!(guard.crosses(&m, &faces, &slots));
    // Moved back, and recorded: a lower face moved up through them is seen crossing them
    // at their updated leaves.
    m.relocate_vertex(v, p).unwrap();
    guard.changed(&m, &slots);
    assert!(!guard.crosses(&m, &faces, &slots));
    let u = 2 * 5 + 2;
    let lower = m.faces_around(u).to_vec();
    let lower_faces: Vec<[u32; 3]> = lower.iter().map(|&f| face(&m, f)).collect();
    m.relocate_vertex(u, m.position(u) + DVec3::new(0.0, 0.0, 0.5))
        .unwrap();
    guard.changed(&m, &lower);
    assert!(guard.crosses(&m, &lower_faces, &lower));
    assert!(!guard.crosses(&m, &lower_faces, &[lower.clone(), slots.clone()].concat()));
}

/// The largest angle of the live faces, degrees.
fn theta_max(m: &Mesh) -> f64 {
    m.live_faces()
        .0
        .into_iter()
        .map(|t| {
            let [a, b, c] = m.corners(t);
            let angle = |p: DVec3, q: DVec3, r: DVec3| (q - p).angle_between(r - p).to_degrees();
            angle(a, b, c).max(angle(b, c, a)).max(angle(c, a, b))
        })
        .fold(0.0, f64::max)
}

/// A fan of six faces round a fixed vertex c at the origin, its ring a unit hexagon with one
/// corner v pulled in to `inset` of the way: the boundary turns by more than 180° at v, whose
/// two faces share that angle (103° each at 0.3).
fn fan_with_a_reflex_corner(inset: f64) -> (TriMesh, u32) {
    let mut positions = vec![DVec3::ZERO];
    for k in 0..6 {
        let a = k as f64 * std::f64::consts::FRAC_PI_3;
        let r = if k == 0 { inset } else { 1.0 };
        positions.push(DVec3::new(r * a.cos(), r * a.sin(), 0.0));
    }
    let triangles = (0..6).map(|k| [0, 1 + k, 1 + (k + 1) % 6]).collect();
    (TriMesh::new(positions, triangles), 1)
}

#[test]
fn a_reflex_boundary_corner_with_two_faces_gets_its_edge_split() {
    let (g, v) = fan_with_a_reflex_corner(0.3);
    let surface = MeshSurface::new(&g).unwrap();
    let mut m: Mesh = EditMesh::from_trimesh(&g, Some, SlotPolicy::Reuse);
    assert!(theta_max(&m) > 102.0, "{}", theta_max(&m));
    // The corner is on the boundary, the centre fixed (a covering vertex), and the corner's
    // neighbours on the boundary have two faces each (no collapse): no flip, collapse or move
    // mends the corner's faces, whose angles at it add up to 206°.
    let fixed = vec![true; m.vertex_count()];
    let (made, _) = mend_faces(&mut m, &surface, None, None, &fixed, &limits(), None, None);
    assert!(made.ops >= 1);
    assert!(m.vertex_count() > 7, "no vertex added");
    assert!(m.degree(v) >= 3, "the corner has {} faces", m.degree(v));
    assert!(theta_max(&m) <= 100.0, "{}", theta_max(&m));
    assert!(theta_min(&m) >= 35.0, "{}", theta_min(&m));
    assert_eq!(m.sanity_check(), Ok(()));
}

#[test]
fn a_boundary_vertex_slides_along_the_boundary_to_mend_its_face() {
    // A strip along a straight boundary (y = 0): boundary vertices at x = 0, 0.12 and 1, and
    // above them two fixed vertices; the face on the short boundary edge has a small angle.
    let positions = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(0.12, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 0.9, 0.0),
        DVec3::new(1.0, 0.9, 0.0),
    ];
    let triangles = vec![[0, 1, 3], [1, 4, 3], [1, 2, 4]];
    let g = TriMesh::new(positions, triangles);
    let surface = MeshSurface::new(&g).unwrap();
    let boundary =
        FeatureLines::new(&g.positions, [[0, 1], [1, 2], [2, 4], [4, 3], [3, 0]]).unwrap();
    let fixed = vec![true; 5];
    let mut m: Mesh = EditMesh::from_trimesh(&g, Some, SlotPolicy::Reuse);
    let before = theta_min(&m);
    assert!(before < 10.0, "{before}");
    // Without the boundary's lines, vertex 1 stays and nothing mends the face.
    mend_faces(&mut m, &surface, None, None, &fixed, &limits(), None, None);
    assert_eq!(m.position(1), DVec3::new(0.12, 0.0, 0.0));
    let (made, _) = mend_faces(
        &mut m,
        &surface,
        Some(&boundary),
        None,
        &fixed,
        &limits(),
        None,
        None,
    );
    assert!(made.ops >= 1);
    let p = m.position(1);
    assert!(p.y.abs() < 1e-12 && p.x > 0.12 && p.x < 1.0, "{p}");
    assert!(
        theta_min(&m) > before + 10.0,
        "{before} -> {}",
        theta_min(&m)
    );
    assert_eq!(m.sanity_check(), Ok(()));
}

#[test]
fn the_compass_search_finds_the_best_angle_position_of_a_ring() {
    // An interior vertex of a flat grid whose ring is distorted: the centroid of the ring
    // is not where the smallest angle score of its faces is largest.
    let g = grid(6, |i, j| {
        let (x, y) = (i as f64, j as f64);
        match (i, j) {
            (4, 3) => DVec3::new(x + 0.45, y - 0.2, 0.0),
            (2, 2) => DVec3::new(x - 0.1, y + 0.35, 0.0),
            (3, 4) => DVec3::new(x + 0.3, y + 0.25, 0.0),
            _ => DVec3::new(x, y, 0.0),
        }
    });
    let surface = MeshSurface::new(&grid(6, |i, j| DVec3::new(i as f64, j as f64, 0.0))).unwrap();
    let m: Mesh = EditMesh::from_trimesh(&g, Some, SlotPolicy::Reuse);
    let params = limits();
    let v = 3 * 7 + 3;
    let ring: Vec<[DVec3; 2]> = m
        .faces_around(v)
        .iter()
        .map(|&f| {
            let t = starting_at(face(&m, f), v);
            [m.position(t[1]), m.position(t[2])]
        })
        .collect();
    let ring_score = |p: DVec3| ring_score(&ring, p, &params.angle_bounds());
    // The best score by brute force over a fine grid of positions around the vertex.
    let old = m.position(v);
    let mut brute = f64::NEG_INFINITY;
    for i in -200..=200 {
        for j in -200..=200 {
            let p = old + DVec3::new(i as f64, j as f64, 0.0) * 0.004;
            brute = brute.max(ring_score(p));
        }
    }
    let centroid = m
        .ring(v)
        .iter()
        .map(|&u| m.position(u))
        .fold(DVec3::ZERO, |a, b| a + b)
        / m.ring(v).len() as f64;
    let found = best_angle_position(&m, &surface, v, &params).expect("a better position");
    let (at_found, at_centroid) = (ring_score(found), ring_score(centroid));
    assert!(
        at_found >= brute - 0.5,
        "compass {at_found} against the best {brute}"
    );
    assert!(
        at_found > at_centroid + 1.0,
        "compass {at_found}, centroid {at_centroid}"
    );
    assert!(found.z.abs() < 1e-12);
}

#[test]
fn mending_near_marked_vertices_leaves_the_other_faces_as_they_are() {
    // Two interior vertices of a 10 × 10 grid pulled most of the way to a neighbour, far apart:
    // only the one whose faces are marked is mended.
    let (g, surface) = flat(10);
    let pulled = |m: &mut Mesh, v: u32| {
        let p = m.position(v);
        m.relocate_vertex(v, p + DVec3::new(0.8, 0.0, 0.0)).unwrap();
    };
    let (a, b) = (2 * 11 + 2, 7 * 11 + 7);
    let mut m: Mesh = EditMesh::from_trimesh(&g, Some, SlotPolicy::Reuse);
    pulled(&mut m, a);
    pulled(&mut m, b);
    let worst_at = |m: &Mesh, v: u32| {
        m.faces_around(v)
            .iter()
            .map(|&f| min_angle(m, face(m, f)))
            .fold(f64::INFINITY, f64::min)
    };
    assert!(
        worst_at(&m, a) < 20.0 && worst_at(&m, b) < 20.0,
        "the test case"
    );
    let before_b = m.position(b);
    let mut near = vec![false; m.vertex_count()];
    near[a as usize] = true;
    let fixed = vec![false; m.vertex_count()];
    let (made, _) = mend_faces(
        &mut m,
        &surface,
        None,
        None,
        &fixed,
        &limits(),
        Some(&near),
        None,
    );
    assert!(made.ops >= 1);
    assert!(m.degree(a) == 0 || worst_at(&m, a) >= 30.0);
    assert_eq!(m.position(b), before_b);
    assert!(worst_at(&m, b) < 20.0);
    assert_eq!(m.sanity_check(), Ok(()));
}

#[test]
fn mend_near_says_which_faces_of_its_result_intersect() {
    // Two sheets, a vertex of the upper one poked through the lower. In the lower sheet, whose
    // faces come first, a diagonal is split very near its end: the pass collapses the short
    // edge, and leaves the crossing (sigma_p 1: moves of at most 0.25, short of the poke). The
    // faces written after the collapse are numbered anew, and the pairs given must be.
    let (surface, mut mesh, _) = poked_sheets();
    let (a, b) = (8u32, 16u32);
    let v = mesh.positions.len() as u32;
    mesh.positions
        .push(mesh.positions[a as usize].lerp(mesh.positions[b as usize], 0.05));
    let mut split = Vec::new();
    for t in &mut mesh.triangles {
        if t.contains(&a) && t.contains(&b) {
            // From a: [a, b, c] becomes [a, v, c] (in place) and [v, b, c] (at the end);
            // [a, c, b] becomes [a, c, v] and [v, c, b].
            let [x, y, z] = starting_at(*t, a);
            if y == b {
                *t = [x, v, z];
                split.push([v, y, z]);
            } else {
                *t = [x, y, v];
                split.push([v, y, z]);
            }
        }
    }
    mesh.triangles.extend(split);
    let (n, faces) = (mesh.positions.len(), mesh.triangles.len());
    // The same pass given the crossing pairs it would search for (any order, either way round)
    // does the same.
    let mut given = mesh.clone();
    let mut known: Vec<[u32; 2]> = intersecting_pairs(&given.positions, &given.triangles)
        .into_iter()
        .map(|[f, g]| [g, f])
        .collect();
    known.reverse();
    assert!(!known.is_empty(), "the test case: a crossing to start from");
    let mend = |mesh: &mut TriMesh, known: Option<Vec<[u32; 2]>>| {
        mend_near(
            mesh,
            &surface,
            &vec![false; n],
            &[],
            None,
            None,
            1.0,
            &OptimizeParams::default(),
            &vec![true; n],
            known,
        )
    };
    let (_, mended_given) = mend(&mut given, Some(known));
    let (_, mended) = mend(&mut mesh, None);
    assert!(mesh.triangles.len() < faces, "the test case: a collapse");
    let mut found: Vec<[u32; 2]> = intersecting_pairs(&mesh.positions, &mesh.triangles)
        .into_iter()
        .map(|[f, g]| [f.min(g), f.max(g)])
        .collect();
    found.sort_unstable();
    assert!(!found.is_empty(), "the test case: a crossing left");
    assert_eq!(mended.intersecting, found);
    assert_eq!(mended.origin.len(), mesh.triangles.len());
    assert_eq!(given, mesh);
    assert_eq!(mended_given.intersecting, mended.intersecting);
}

#[test]
fn with_a_near_distance_the_pass_brings_no_faces_that_close() {
    // The poked sheets 0.2 apart, and a triangle hanging from above with its tip 0.05 over the
    // upper sheet where the poke's faces will lie once the pass lifts the poke out of the
    // lower sheet (they now slope down under it, 0.3 below the tip). With `near` 0.1 no pair
    // of faces within 0.1 is made (faces that would touch once written are as bad as faces
    // that cross), and the pairs the pass gives are those within 0.1.
    let (surface, mut mesh, poke) = poked_sheets();
    let p = mesh.positions[poke];
    let tip = DVec3::new(p.x + 0.5, p.y + 0.15, 0.25);
    let n = mesh.positions.len() as u32;
    mesh.positions.extend([
        DVec3::new(tip.x - 0.3, tip.y, 1.0),
        DVec3::new(tip.x + 0.3, tip.y, 1.0),
        tip,
    ]);
    mesh.triangles.push([n, n + 1, n + 2]);
    let near = 0.1;
    let within = |m: &Mesh| as_slots(m, |p, t| pairs_within(p, t, near));
    let start: Mesh = EditMesh::from_trimesh(&mesh, Some, SlotPolicy::Reuse);
    let before = within(&start);
    let made_close = |m: &Mesh| within(m).into_iter().any(|p| !before.contains(&p));
    // The hanging triangle is the pass's own: fixed.
    let fixed: Vec<bool> = (0..mesh.positions.len()).map(|v| v >= n as usize).collect();
    let run = |near: f64| {
        let mut m: Mesh = EditMesh::from_trimesh(&mesh, Some, SlotPolicy::Reuse);
        let params = Limits::new(
            &OptimizeParams {
                near,
                ..OptimizeParams::default()
            },
            4.0,
        );
        let (made, left) = mend_faces(&mut m, &surface, None, None, &fixed, &params, None, None);
        (m, made, left)
    };
    // The test case: with the exact guard alone, the lift crosses nothing and leaves the tip
    // closer than 0.1 to a face.
    let (m, made, _) = run(0.0);
    assert!(made.ops >= 1);
    assert!(
        slot_pairs(&m).is_empty(),
        "the test case: the crossing mended"
    );
    assert!(made_close(&m), "the test case: faces brought close");
    let (m, _, left) = run(near);
    assert_eq!(left, within(&m));
    assert!(!made_close(&m), "{left:?} from {before:?}");
    assert_eq!(m.sanity_check(), Ok(()));
}
