//! Collapses of the short edges of poor triangles, under the link condition and guarded against
//! the input surface and against making a crossing.

use glam::DVec3;

use super::*;

/// Collapses the interior edges of the poor triangles `poor` shorter than `short`, shortest first: one end
/// merges into the other, at the kept end's position (a fixed end is always the kept one) or at
/// the surface point nearest the edge's midpoint, whichever leaves the best smallest Q. A
/// collapse is made only when it keeps the mesh manifold (the link condition: the two ends share
/// exactly the two opposite vertices), raises the smallest Q of the faces involved, turns no face
/// by more than `max_normal_turn_deg`, and leaves both old positions within `collapse_offset` of
/// the new faces. Returns the number of collapses.
pub(super) fn collapse_short<S: SurfaceQuery + ?Sized>(
    m: &mut Mesh,
    surface: &S,
    fixed: &[bool],
    short: f64,
    params: &Limits,
    poor: &PoorFaces,
    guard: &mut SweepGuard,
) -> usize {
    let cos_turn = params.max_normal_turn_deg.to_radians().cos();
    let mut edges: Vec<(f64, u32, u32)> = Vec::new();
    for t in poor.slots().map(|f| face(m, f)) {
        for k in 0..3 {
            let (x, y) = (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]));
            let l = m.position(x).distance(m.position(y));
            if l < short {
                edges.push((l, x, y));
            }
        }
    }
    edges.sort_by(|a, b| a.0.total_cmp(&b.0).then((a.1, a.2).cmp(&(b.1, b.2))));
    edges.dedup();
    let is_fixed = |v: u32| fixed.get(v as usize).copied().unwrap_or(false);
    let mut collapses = 0;
    for (_, a, b) in edges {
        let Ok((f1, f2, c, d)) = m.edge_faces(a, b) else {
            continue;
        };
        let (pa, pb) = (m.position(a), m.position(b));
        if pa.distance(pb) >= short {
            continue;
        }
        if !collapse_keeps_links(m, a, b, c, d) {
            continue;
        }
        let keep_a = is_fixed(a) || m.is_boundary_vertex(a);
        let keep_b = is_fixed(b) || m.is_boundary_vertex(b);
        // (removed, kept, position of the kept vertex)
        let mut options: Vec<(u32, u32, DVec3)> = Vec::new();
        match (keep_a, keep_b) {
            (true, true) => continue,
            (true, false) => options.push((b, a, pa)),
            (false, true) => options.push((a, b, pb)),
            (false, false) => {
                options.push((b, a, pa));
                options.push((a, b, pb));
                if let Some(sp) = surface.closest_point_to_midpoint(pa, pb) {
                    options.push((b, a, sp.position));
                }
            }
        }
        // The faces that change: all around a and b but f1 and f2.
        let involved = faces_around_edge(m, a, b, f1, f2);
        let before = involved
            .iter()
            .chain([&f1, &f2])
            .map(|&g| score(m, face(m, g)))
            .fold(f64::INFINITY, f64::min);
        let old_normals: Vec<DVec3> = involved.iter().map(|&g| normal(m, face(m, g))).collect();
        let replaced: Vec<u32> = involved.iter().copied().chain([f1, f2]).collect();
        let mut best: Option<(f64, u32, u32, DVec3)> = None;
        for (removed, kept, q) in options {
            let saved = m.position(kept);
            if m.relocate_vertex(kept, q).is_err() {
                continue;
            }
            let new_faces: Vec<[u32; 3]> = involved
                .iter()
                .map(|&g| face(m, g).map(|u| if u == removed { kept } else { u }))
                .collect();
            let turned = turned(m, &new_faces, &old_normals, cos_turn);
            let worst = new_faces
                .iter()
                .map(|&t| score(m, t))
                .fold(f64::INFINITY, f64::min);
            let dist = |p: DVec3| distance_to(m, new_faces.iter().copied(), p);
            let near = dist(pa) <= params.collapse_offset && dist(pb) <= params.collapse_offset;
            let wanted = !turned
                && near
                && worst > before + IMPROVEMENT_TOLERANCE
                && best.is_none_or(|b| worst > b.0);
            // The faces after the collapse (the kept vertex at q) must cross none.
            let crossing = wanted && guard.refuses(m, &new_faces, &replaced);
            // The old position was finite: restoring it cannot fail.
            let _ = m.relocate_vertex(kept, saved);
            if wanted && !crossing {
                best = Some((worst, removed, kept, q));
            }
        }
        let Some((_, removed, kept, q)) = best else {
            continue;
        };
        if m.collapse_edge(removed, kept, q, None).is_ok() {
            collapses += 1;
            let around = m.faces_around(kept).to_vec();
            guard.changed(m, &around);
        }
    }
    collapses
}
