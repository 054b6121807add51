//! The triangulation of a polygon, by its corners only, that maximizes the smallest score of
//! its triangles: the dynamic programme over sub-polygons of Klincsek ("Minimal triangulations
//! of polygonal domains", Annals of Discrete Mathematics 9, 1980), with a max-min objective in
//! place of the minimum weight. O(n³) time and O(n²) memory for n corners: for the small
//! polygons it serves (a hole's outline, the link of a vertex).

use crate::geometry::tolerance::IMPROVEMENT_TOLERANCE;

/// The triangles `[lp[i], lp[j], lp[k]]` (i < j < k, so oriented like the polygon's corner
/// order `lp`) of the triangulation of the polygon `lp` whose smallest `score` is largest, or
/// `None` when every triangulation has a triangle scored at or below
/// [`IMPROVEMENT_TOLERANCE`] (or NaN). `diagonal_ok(a, b)` says whether the diagonal between
/// the corners `a` and `b` (vertex indices, not neighbours in the polygon) may be made; the
/// polygon's own edges always may. Three corners give the triangle itself when it scores above
/// the tolerance; fewer give `None`. `n - 2` triangles for `n` corners.
pub fn max_min_triangulation(
    lp: &[u32],
    diagonal_ok: impl Fn(u32, u32) -> bool,
    score: impl Fn([u32; 3]) -> f64,
) -> Option<Vec<[u32; 3]>> {
    let m = lp.len();
    if m < 3 {
        return None;
    }
    // best[i][k]: the max-min score of triangulating the sub-polygon i..=k; choice[i][k] = j.
    let idx = |i: usize, k: usize| i * m + k;
    let mut best = vec![f64::NEG_INFINITY; m * m];
    let mut choice = vec![usize::MAX; m * m];
    for i in 0..m - 1 {
        best[idx(i, i + 1)] = f64::INFINITY;
    }
    for len in 2..m {
        for i in 0..m - len {
            let k = i + len;
            let side = k == i + 1 || (i == 0 && k == m - 1);
            if !side && !diagonal_ok(lp[i], lp[k]) {
                continue;
            }
            for j in i + 1..k {
                let q = score([lp[i], lp[j], lp[k]]);
                if q.is_nan() || q <= IMPROVEMENT_TOLERANCE {
                    continue;
                }
                let v = best[idx(i, j)].min(best[idx(j, k)]).min(q);
                if v > best[idx(i, k)] {
                    best[idx(i, k)] = v;
                    choice[idx(i, k)] = j;
                }
            }
        }
    }
    let whole = best[idx(0, m - 1)];
    if whole.is_nan() || whole <= 0.0 {
        return None;
    }
    let mut out = Vec::with_capacity(m - 2);
    let mut stack = vec![(0usize, m - 1)];
    while let Some((i, k)) = stack.pop() {
        if k < i + 2 {
            continue;
        }
        let j = choice[idx(i, k)];
        out.push([lp[i], lp[j], lp[k]]);
        stack.push((i, j));
        stack.push((j, k));
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// The smallest angle of a triangle in the plane z = 0, degrees; negative when it turns
    /// clockwise.
    fn signed_min_angle(p: &[DVec3], t: [u32; 3]) -> f64 {
        let [a, b, c] = t.map(|i| p[i as usize]);
        let angle = |x: DVec3, y: DVec3, z: DVec3| (y - x).angle_between(z - x).to_degrees();
        let m = angle(a, b, c).min(angle(b, c, a)).min(angle(c, a, b));
        if (b - a).cross(c - a).z > 0.0 {
            m
        } else {
            -m
        }
    }

    #[test]
    fn a_regular_hexagon_is_split_into_four_counter_clockwise_triangles_of_thirty_degrees_or_more()
    {
        let p: Vec<DVec3> = (0..6)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 6.0;
                DVec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let lp: Vec<u32> = (0..6).collect();
        let tris = max_min_triangulation(&lp, |_, _| true, |t| signed_min_angle(&p, t))
            .expect("a triangulation");
        assert_eq!(tris.len(), 4);
        for t in &tris {
            assert!(signed_min_angle(&p, *t) >= 30.0 - 1e-9, "{t:?}");
        }
        // The best triangulation of a regular hexagon has a smallest angle of 30°; the fan
        // from one corner has the same, so check that a forbidden diagonal is avoided instead.
        let tris = max_min_triangulation(&lp, |a, b| [a, b] != [0, 3], |t| signed_min_angle(&p, t))
            .expect("a triangulation without 0-3");
        for t in &tris {
            let has = |x| t.contains(&x);
            assert!(!(has(0) && has(3)), "{t:?} uses the diagonal 0-3");
        }
    }

    #[test]
    fn a_concave_polygon_gets_no_triangle_outside_it_and_a_clockwise_one_gets_none() {
        // An L shape, counter-clockwise: the fan from the reflex corner's neighbour would leave
        // the polygon; scoring clockwise triangles negative keeps them out.
        let p = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(2.0, 1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        ];
        let lp: Vec<u32> = (0..6).collect();
        let tris = max_min_triangulation(&lp, |_, _| true, |t| signed_min_angle(&p, t))
            .expect("a triangulation");
        let area: f64 = tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| p[i as usize]);
                0.5 * (b - a).cross(c - a).z
            })
            .sum();
        assert!((area - 3.0).abs() < 1e-12, "area {area}");
        let reversed: Vec<u32> = lp.iter().rev().copied().collect();
        assert_eq!(
            max_min_triangulation(&reversed, |_, _| true, |t| signed_min_angle(&p, t)),
            None
        );
        assert_eq!(max_min_triangulation(&lp[..2], |_, _| true, |_| 1.0), None);
    }
}
