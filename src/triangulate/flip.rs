//! Lawson's edge flips with the max-min angle rule (C. L. Lawson, "Software for C¹ surface
//! interpolation", Mathematical Software III, 1977): an interior edge is flipped when the
//! smaller of the smallest angles of its two faces grows. In the plane, flipping until no edge
//! qualifies gives the Delaunay triangulation; on a surface each caller adds its own guard (the
//! assembly's refinement: the faces stay nearly coplanar and agree with the samples' normals;
//! the optimizer: the new faces stay on the input surface).

use crate::mesh::edit::{starting_at, EditMesh};
use crate::quality::triangle_angles_deg;

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
    let a = triangle_angles_deg(m.corners(t));
    a[0].min(a[1]).min(a[2])
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
    if new <= old + 1e-6 {
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
