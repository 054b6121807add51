//! Lawson's edge flips with the max-min angle rule (C. L. Lawson, "Software for C¹ surface
//! interpolation", Mathematical Software III, 1977): an interior edge is flipped when the
//! smaller of the smallest angles of its two faces grows. In the plane, flipping until no edge
//! qualifies gives the Delaunay triangulation; on a surface each caller adds its own guard (the
//! assembly's refinement: the faces stay nearly coplanar and agree with the samples' normals;
//! the optimizer: the new faces stay on the input surface).

use crate::geometry::tolerance::FLIP_MIN_ANGLE_GAIN_DEG;
use crate::geometry::triangle::triangle_min_angle_deg;
use crate::mesh::edit::{starting_at, EditMesh};

/// A flip that the max-min rule asks for: the edge `x`–`y` with faces `old = [[x, y, c],
/// [y, x, d]]` (in slots `slots`) would become `c`–`d` with faces `new = [[x, d, c], [y, c, d]]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FlipCandidate {
    /// The old faces, `[x, y, c]` and `[y, x, d]`.
    pub old: [[u32; 3]; 2],
    /// Their slots.
    pub slots: [u32; 2],
    /// The new faces, `[x, d, c]` and `[y, c, d]`.
    pub new: [[u32; 3]; 2],
}

/// The smallest angle of the triangle `t`, degrees.
fn min_angle<L: Copy>(m: &EditMesh<L>, t: [u32; 3]) -> f64 {
    triangle_min_angle_deg(m.corners(t))
}

/// The flip of the edge `x`–`y` when the max-min rule asks for it: the edge is interior, `c`–`d`
/// is not an edge yet (nor a blocked direction), `x` and `y` keep at least three faces each, and
/// the smaller of the two faces' smallest angles grows by more than 10⁻⁶ degrees.
pub(crate) fn max_min_candidate<L: Copy>(m: &EditMesh<L>, x: u32, y: u32) -> Option<FlipCandidate> {
    let (f1, f2) = (m.face_on(x, y)?, m.face_on(y, x)?);
    let t1 = starting_at(m.face(f1)?, x); // [x, y, c]
    let t2 = starting_at(m.face(f2)?, y); // [y, x, d]
    if t1[1] != y || t2[1] != x {
        return None;
    }
    let (c, d) = (t1[2], t2[2]);
    if c == d
        || m.is_used_or_blocked(c, d)
        || m.is_used_or_blocked(d, c)
        || m.degree(x) <= 3
        || m.degree(y) <= 3
    {
        return None;
    }
    let new1 = [x, d, c];
    let new2 = [y, c, d];
    let old = min_angle(m, t1).min(min_angle(m, t2));
    let new = min_angle(m, new1).min(min_angle(m, new2));
    if new <= old + FLIP_MIN_ANGLE_GAIN_DEG {
        return None;
    }
    Some(FlipCandidate {
        old: [t1, t2],
        slots: [f1, f2],
        new: [new1, new2],
    })
}

/// Flips the edges `edges` (pairs of vertices), in order, that the max-min rule asks for
/// ([`max_min_candidate`]) and `accept` allows (it sees the mesh and the flip before it is
/// made), with [`EditMesh::flip_edge`]; new faces get `label`. Returns the number of flips.
pub(crate) fn max_min_flips<L: Copy>(
    m: &mut EditMesh<L>,
    edges: &[(u32, u32)],
    label: L,
    mut accept: impl FnMut(&EditMesh<L>, &FlipCandidate) -> bool,
) -> usize {
    let mut flips = 0;
    for &(x, y) in edges {
        let Some(flip) = max_min_candidate(m, x, y) else {
            continue;
        };
        if accept(m, &flip) && m.flip_edge(x, y, label).is_ok() {
            flips += 1;
        }
    }
    flips
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::edit::SlotPolicy;

    /// A convex quad 0-3-1-2 split along its long diagonal 0-1, alone or inside a ring 4..=7
    /// that gives 0 and 1 six faces each.
    fn quad(with_ring: bool) -> EditMesh<()> {
        let (positions, faces) = crate::mesh::test_meshes::quad_in_ring();
        let mut m = EditMesh::new(positions, SlotPolicy::Reuse);
        for &t in &faces[..if with_ring { 10 } else { 2 }] {
            assert!(m.add_face(t, ()).is_ok());
        }
        m
    }

    #[test]
    fn the_long_diagonal_is_flipped_and_the_short_one_kept() {
        let mut m = quad(true);
        let flip = max_min_candidate(&m, 0, 1).expect("the long diagonal is a candidate");
        assert_eq!(flip.old, [[0, 1, 2], [1, 0, 3]]);
        assert_eq!(flip.new, [[0, 3, 2], [1, 2, 3]]);
        assert_eq!(max_min_flips(&mut m, &[(0, 1)], (), |_, _| true), 1);
        assert!(m.has_edge(2, 3) && !m.has_edge(0, 1));
        // Flipping back would lower the smallest angle.
        assert_eq!(max_min_candidate(&m, 2, 3), None);
        assert_eq!(max_min_flips(&mut m, &[(2, 3)], (), |_, _| true), 0);
        assert_eq!(m.sanity_check(), Ok(()));
    }

    #[test]
    fn no_candidate_at_a_vertex_of_three_faces_or_when_the_guard_says_no() {
        // Alone, 0 and 1 have two faces each: a flip would leave them with one.
        let m = quad(false);
        assert_eq!(max_min_candidate(&m, 0, 1), None);
        let mut m = quad(true);
        assert_eq!(max_min_flips(&mut m, &[(0, 1)], (), |_, _| false), 0);
        assert!(m.has_edge(0, 1));
        // A boundary edge is never a candidate.
        assert_eq!(max_min_candidate(&m, 6, 0), None);
        assert_eq!(m.sanity_check(), Ok(()));
    }
}
