use super::*;

#[test]
fn written_rounding_bounds_the_f32_rounding_of_the_model_frame() {
    // A box near the origin and the same box at UTM-like coordinates: every corner and a
    // grid of points inside, written as f32 model coordinates, move by at most a quarter
    // of the written rounding (bbox-100 units); the far box's rounding is far larger.
    let mut last = 0.0;
    for offset in [DVec3::ZERO, DVec3::new(512_345.0, 4_123_456.0, 120.0)] {
        let lo = offset + DVec3::new(-3.0, 1.0, 2.0);
        let hi = offset + DVec3::new(7.0, 4.5, 2.5);
        let n = Normalization::for_bbox(&Aabb::of(&[lo, hi]).unwrap()).unwrap();
        let r = n.written_rounding();
        for k in 0..=1000 {
            let t = DVec3::new(
                (k % 11) as f64 / 10.0,
                (k / 11 % 11) as f64 / 10.0,
                (k / 121 % 9) as f64 / 8.0,
            );
            let p = lo + (hi - lo) * t;
            let written = p.as_vec3().as_dvec3();
            let moved = n.apply(written).distance(n.apply(p));
            assert!(moved <= 0.25 * r, "{moved:e} > {r:e} / 4 at {p}");
        }
        assert!(r > last);
        last = r;
    }
    assert!(last > 0.1, "{last}");
}

#[test]
fn normalization_round_trips_and_scales_longest_side_to_100() {
    let pts = vec![DVec3::new(1.0, 2.0, 3.0), DVec3::new(3.0, 7.0, 4.0)];
    let bbox = Aabb::of(&pts).unwrap();
    let n = Normalization::for_bbox(&bbox).unwrap();
    let q: Vec<_> = pts.iter().map(|&p| n.apply(p)).collect();
    let nb = Aabb::of(&q).unwrap();
    assert!((nb.longest_side() - 100.0).abs() < 1e-12);
    assert!(nb.center().length() < 1e-12);
    for (p, q) in pts.iter().zip(&q) {
        assert!((n.invert(*q) - *p).length() < 1e-12);
    }
    let flat = Aabb::of(&[DVec3::ONE, DVec3::ONE]).unwrap();
    assert!(Normalization::for_bbox(&flat).is_none());
}

#[test]
fn a_face_in_both_windings_goes_when_it_is_a_wall_and_stays_when_it_is_a_sheet() {
    // Two tetrahedra glued at the face 0-1-2, each with its copy of it.
    let positions = vec![
        DVec3::ZERO,
        DVec3::X,
        DVec3::Y,
        DVec3::Z,
        DVec3::new(0.2, 0.2, -1.0),
    ];
    let mut glued = TriMesh::new(
        positions.clone(),
        vec![
            [0, 2, 1],
            [0, 1, 3],
            [1, 2, 3],
            [2, 0, 3],
            [0, 1, 2],
            [0, 4, 1],
            [1, 4, 2],
            [2, 4, 0],
        ],
    );
    let c = glued.remove_duplicate_and_zero_area_faces();
    assert_eq!(
        (c.duplicates, c.opposite_duplicates, c.internal_walls),
        (1, 0, 1)
    );
    assert_eq!(glued.triangles.len(), 6);
    assert!(!glued.triangles.iter().any(|t| {
        let mut k = *t;
        k.sort_unstable();
        k == [0, 1, 2]
    }));
    // One sheet of two faces, exported double-sided: the backs go, the fronts stay.
    let mut sheet = TriMesh::new(
        positions[..4].to_vec(),
        vec![[0, 1, 2], [1, 3, 2], [0, 2, 1], [1, 2, 3]],
    );
    let c = sheet.remove_duplicate_and_zero_area_faces();
    assert_eq!(
        (c.duplicates, c.opposite_duplicates, c.internal_walls),
        (2, 2, 0)
    );
    assert_eq!(sheet.triangles, vec![[0, 1, 2], [1, 3, 2]]);
}

#[test]
fn a_floor_between_two_stacked_boxes_is_a_wall_though_its_diagonal_has_two_faces() {
    // Two unit cubes stacked; each has the square between them as two triangles, the
    // lower one's top in one winding, the upper one's bottom in the other. The square's
    // diagonal has only the square's two faces; its rim has the sides of both cubes.
    let mut positions = Vec::new();
    for z in 0..3 {
        for (x, y) in [(0, 0), (1, 0), (1, 1), (0, 1)] {
            positions.push(DVec3::new(x as f64, y as f64, z as f64));
        }
    }
    let quad = |a: u32, b: u32, c: u32, d: u32| [[a, b, c], [a, c, d]];
    let cube = |lo: u32| {
        let hi = lo + 4;
        let mut t = Vec::new();
        t.extend(quad(lo, lo + 3, lo + 2, lo + 1));
        t.extend(quad(hi, hi + 1, hi + 2, hi + 3));
        for k in 0..4 {
            let (a, b) = (lo + k, lo + (k + 1) % 4);
            t.extend(quad(a, b, b + 4, a + 4));
        }
        t
    };
    let mut triangles = cube(0);
    triangles.extend(cube(4));
    let mut stacked = TriMesh::new(positions, triangles);
    let c = stacked.remove_duplicate_and_zero_area_faces();
    assert_eq!(
        (c.duplicates, c.opposite_duplicates, c.internal_walls),
        (2, 0, 2)
    );
    // One closed box of 20 faces: every edge has two.
    assert_eq!(stacked.triangles.len(), 20);
    let mut on_edge: FxHashMap<(u32, u32), usize> = FxHashMap::default();
    for t in &stacked.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *on_edge.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    assert!(on_edge.values().all(|&n| n == 2), "{on_edge:?}");
    // A closed surface given in both windings has no rim: no wall, it is made single.
    let mut tet = TriMesh::new(
        vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
        vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
    );
    let backs: Vec<[u32; 3]> = tet.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect();
    tet.triangles.extend(backs);
    let c = tet.remove_duplicate_and_zero_area_faces();
    assert_eq!(
        (c.duplicates, c.opposite_duplicates, c.internal_walls),
        (4, 4, 0)
    );
    assert_eq!(tet.triangles.len(), 4);
}

#[test]
fn weld_merges_identical_positions_and_drops_collapsed_faces() {
    let mut m = TriMesh::new(
        vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::X, // duplicate of 1
            DVec3::new(1.0, 1.0, 0.0),
        ],
        vec![[0, 1, 2], [3, 4, 2], [1, 3, 2]],
    );
    assert_eq!(m.weld_identical_positions(), 1);
    assert_eq!(m.positions.len(), 4);
    assert_eq!(m.triangles, vec![[0, 1, 2], [1, 3, 2]]);
}

#[test]
fn weld_close_merges_a_seams_corners_a_rounding_apart_and_keeps_points_farther_apart() {
    // Two triangles of a square whose shared edge's ends are repeated a rounding apart (as a
    // CAD export writes a seam), and a third triangle with a vertex 1e-6 from a corner.
    let e = 2.7e-16;
    let mut m = TriMesh::new(
        vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::new(1.0 + e, 0.0, 0.0),
            DVec3::new(0.0, 1.0 - e, e),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(1.0 + 1e-6, 1.0, 0.0),
            DVec3::new(2.0, 1.0, 0.0),
        ],
        vec![[0, 1, 2], [3, 5, 4], [5, 6, 7]],
    );
    assert_eq!(m.weld_close_positions(1e-10, 1e-7), 2);
    assert_eq!(m.positions.len(), 6);
    // The square's diagonal is one edge of both its triangles.
    assert_eq!(m.triangles[..2], [[0, 1, 2], [1, 3, 2]]);
    // 1e-6 apart is two vertices, and no triangle collapsed.
    assert_eq!(m.triangles.len(), 3);
    // Zero merges identical positions only.
    let mut n = TriMesh::new(
        vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::new(1.0 + e, 0.0, 0.0),
        ],
        vec![[0, 1, 2], [3, 2, 1]],
    );
    assert_eq!(n.weld_close_positions(0.0, 1e-7), 0);
    assert_eq!(n.positions.len(), 4);
}

/// The weld's grid keeps at most WELD_CELL_CAP merge targets per cell, so a cluster of
/// distinct vertices (tiny faces kept apart by the edge bound) costs linear time: a vertex a
/// rounding from the 40th of such a cluster stays apart, one a rounding from the 6th is welded.
#[test]
fn the_welds_cells_keep_a_bounded_number_of_merge_targets() {
    use super::WELD_CELL_CAP;
    const { assert!(WELD_CELL_CAP < 39) };
    // 13 tiny triangles (39 vertices) 1e-3 across, all in one cell of the tolerance 1.0.
    let mut positions: Vec<DVec3> = (0..39)
        .map(|i| DVec3::new(i as f64 * 1e-3, (i % 3) as f64 * 1e-3, 0.0))
        .collect();
    let mut triangles: Vec<[u32; 3]> = (0..13).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
    // Two triangles from far away, each with a corner a rounding from vertex 38 or vertex 5.
    for (near, x) in [(38usize, 10.0), (5, 20.0)] {
        let base = positions.len() as u32;
        positions.extend([
            positions[near] + DVec3::splat(1e-15),
            DVec3::new(x, 0.0, 0.0),
            DVec3::new(x, 1.0, 0.0),
        ]);
        triangles.push([base, base + 1, base + 2]);
    }
    let mut m = TriMesh::new(positions, triangles);
    assert_eq!(m.weld_close_positions(1.0, 1e-7), 1);
    // The far triangles' first corners: the one by vertex 38 stays apart, the other is 5.
    assert_eq!(m.triangles[13][0], 39);
    assert_eq!(m.triangles[14][0], 5);
}

#[test]
fn corner_normals_split_at_creases_sharper_than_the_angle() {
    // A roof: two planes meeting at a ridge along x with a 90° dihedral angle, each a 2 x 2
    // grid of squares; the ridge vertices are shared.
    let mut positions = Vec::new();
    for j in 0..=4 {
        for i in 0..=2 {
            let y = j as f64 - 2.0;
            positions.push(DVec3::new(i as f64, y, 2.0 - y.abs()));
        }
    }
    let mut triangles = Vec::new();
    for j in 0..4u32 {
        for i in 0..2u32 {
            let v = j * 3 + i;
            triangles.push([v, v + 1, v + 4]);
            triangles.push([v, v + 4, v + 3]);
        }
    }
    let m = TriMesh::new(positions, triangles);
    let vertex = m.vertex_normals();
    for (crease, sharp) in [(60.0, true), (100.0, false), (180.0, false)] {
        let corners = m.corner_normals(crease);
        for (f, tri) in m.triangles.iter().enumerate() {
            for k in 0..3 {
                let n = corners[f][k];
                assert!((n.length() - 1.0).abs() < 1e-12);
                let want = if sharp {
                    m.face_normal(f)
                } else {
                    vertex[tri[k] as usize]
                };
                assert!(
                    (n - want).length() < 1e-12,
                    "crease {crease} face {f}: {n} vs {want}"
                );
            }
        }
    }
    // On the ridge the vertex normal points straight up, between the two faces.
    let ridge = 2 * 3 + 1;
    assert_eq!(m.positions[ridge], DVec3::new(1.0, 0.0, 2.0));
    assert!(
        (vertex[ridge] - DVec3::Z).length() < 1e-12,
        "{}",
        vertex[ridge]
    );
}

#[test]
fn unreferenced_vertices_are_removed() {
    let mut m = TriMesh::new(
        vec![DVec3::ZERO, DVec3::Z, DVec3::X, DVec3::Y],
        vec![[0, 2, 3]],
    );
    assert_eq!(m.remove_unreferenced_vertices(), 1);
    assert_eq!(m.triangles, vec![[0, 1, 2]]);
    assert_eq!(m.positions[1], DVec3::X);
}
