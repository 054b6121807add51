//! Stray shells at unresolved tips: a tip thinner than the sampling can resolve (a cone's apex,
//! a horse's tail tip at the grading's finest width) can leave a handful of samples that close
//! into a tiny shell of their own (four samples, a tetrahedron) apart from the surface. When
//! the output has more components than the input, such shells are removed, smallest first,
//! down to the input's count: the tip comes out blunted (the report says where) instead of as
//! an extra component. On a point set, pieces open or closed too small to be a surface at the
//! output's spacing (a few stray points meshed on their own) go too, all but the largest
//! piece ([`remove_tiny_pieces`]).

use glam::DVec3;

use crate::mesh::parts::parts;
use crate::mesh::TriMesh;
use crate::triangulate::FaceSource;

/// What `remove_stray_shells` removed: the tiny closed shells the pipelines leave out.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StrayShells {
    /// Shells removed.
    pub shells: usize,
    /// Their vertices.
    pub vertices: usize,
    /// Bounding box of the removed vertices (bbox-100 units; meaningless when none).
    pub min: DVec3,
    /// Bounding box of the removed vertices (bbox-100 units).
    pub max: DVec3,
}

/// Removes closed components (no boundary edge) of `mesh` with at most `max_vertices`
/// vertices that `stray(positions of its vertices)` calls stray (the pipeline: smaller than
/// the sample spacing, or every vertex at a thin part),
/// smallest first, while `mesh` has more components than `keep`. `face_sources` (one per face)
/// is filtered along. The removed vertices stay in `positions` unreferenced.
pub fn remove_stray_shells(
    mesh: &mut TriMesh,
    face_sources: &mut Vec<FaceSource>,
    keep: usize,
    max_vertices: usize,
    stray: impl Fn(&[DVec3]) -> bool,
) -> StrayShells {
    remove_parts(mesh, face_sources, keep, |closed, points| {
        closed && points.len() <= max_vertices && stray(points)
    })
}

/// Removes the pieces of `mesh`, open or closed, that `tiny(positions of its vertices)` calls
/// too small to be a surface at the output's spacing (on a point set: a few stray points, such
/// as flying pixels at a depth jump, meshed on their own), smallest first, while more than one
/// piece is left: the largest always stays. `face_sources` (one per face) is filtered along;
/// the removed vertices stay in `positions` unreferenced.
pub fn remove_tiny_pieces(
    mesh: &mut TriMesh,
    face_sources: &mut Vec<FaceSource>,
    tiny: impl Fn(&[DVec3]) -> bool,
) -> StrayShells {
    remove_parts(mesh, face_sources, 1, |_, points| tiny(points))
}

/// Removes the parts of `mesh` that `eligible(closed, positions of its vertices)` selects,
/// smallest first (ties: the smallest vertex index), while `mesh` has more parts than `keep`.
fn remove_parts(
    mesh: &mut TriMesh,
    face_sources: &mut Vec<FaceSource>,
    keep: usize,
    eligible: impl Fn(bool, &[DVec3]) -> bool,
) -> StrayShells {
    let mut record = StrayShells {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
        ..StrayShells::default()
    };
    let parts = parts(mesh);
    if parts.len() <= keep {
        return record;
    }
    let mut small: Vec<(usize, u32, usize)> = Vec::new();
    for (k, part) in parts.iter().enumerate() {
        let points: Vec<DVec3> = part
            .vertices
            .iter()
            .map(|&v| mesh.positions[v as usize])
            .collect();
        if eligible(part.closed, &points) {
            // Ties broken by the smallest vertex index (deterministic, whatever the order).
            small.push((part.vertices.len(), part.vertices[0], k));
        }
    }
    small.sort_by_key(|s| (s.0, s.1));
    let excess = parts.len() - keep;
    let mut removed_parts = Vec::new();
    for (_, _, k) in small.into_iter().take(excess) {
        record.shells += 1;
        record.vertices += parts[k].vertices.len();
        for &v in &parts[k].vertices {
            let p = mesh.positions[v as usize];
            record.min = record.min.min(p);
            record.max = record.max.max(p);
        }
        removed_parts.push(k);
    }
    if removed_parts.is_empty() {
        return record;
    }
    let mut keep_face = vec![true; mesh.triangles.len()];
    for k in removed_parts {
        for &f in &parts[k].faces {
            keep_face[f] = false;
        }
    }
    let mut k = 0;
    mesh.triangles.retain(|_| {
        k += 1;
        keep_face[k - 1]
    });
    let mut k = 0;
    face_sources.retain(|_| {
        k += 1;
        keep_face[k - 1]
    });
    record
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes::cuboid;

    fn two_parts() -> (TriMesh, Vec<FaceSource>) {
        // A big box and a tiny closed tetrahedron beside it.
        let mut m = cuboid(DVec3::ZERO, DVec3::splat(10.0));
        let o = m.positions.len() as u32;
        m.positions.extend([
            DVec3::new(11.0, 0.0, 0.0),
            DVec3::new(11.1, 0.0, 0.0),
            DVec3::new(11.0, 0.1, 0.0),
            DVec3::new(11.0, 0.0, 0.1),
        ]);
        m.triangles.extend([
            [o, o + 2, o + 1],
            [o, o + 1, o + 3],
            [o + 1, o + 2, o + 3],
            [o, o + 3, o + 2],
        ]);
        let sources = vec![FaceSource::Refined; m.triangles.len()];
        (m, sources)
    }

    #[test]
    fn a_tiny_shell_at_a_thin_tip_goes_when_the_input_has_fewer_parts() {
        let (mut m, mut sources) = two_parts();
        let r = remove_stray_shells(&mut m, &mut sources, 1, 8, |s| s.iter().all(|p| p.x > 10.5));
        assert_eq!((r.shells, r.vertices), (1, 4));
        assert_eq!(m.triangles.len(), 12);
        assert_eq!(sources.len(), 12);
        assert!(r.min.x >= 11.0 && r.max.x <= 11.1 + 1e-12);
    }

    #[test]
    fn shells_stay_when_the_input_has_as_many_parts_or_they_are_not_thin() {
        let (mut m, mut sources) = two_parts();
        assert_eq!(
            remove_stray_shells(&mut m, &mut sources, 2, 8, |_| true).shells,
            0
        );
        assert_eq!(
            remove_stray_shells(&mut m, &mut sources, 1, 8, |_| false).shells,
            0
        );
        // The box itself is small enough (8 vertices) but not thin.
        assert_eq!(
            remove_stray_shells(&mut m, &mut sources, 1, 3, |_| true).shells,
            0
        );
        assert_eq!(m.triangles.len(), 16);
    }

    #[test]
    fn tiny_open_pieces_go_and_the_largest_stays() {
        // The box, the tiny tetrahedron and a tiny open triangle: both tiny pieces go.
        let (mut m, mut sources) = two_parts();
        let o = m.positions.len() as u32;
        m.positions.extend([
            DVec3::new(-2.0, 0.0, 0.0),
            DVec3::new(-2.1, 0.0, 0.0),
            DVec3::new(-2.0, 0.1, 0.0),
        ]);
        m.triangles.push([o, o + 1, o + 2]);
        sources.push(FaceSource::Refined);
        let tiny = |s: &[DVec3]| s.len() < 8;
        let r = remove_tiny_pieces(&mut m, &mut sources, tiny);
        assert_eq!((r.shells, r.vertices), (2, 7));
        assert_eq!(m.triangles.len(), 12);
        assert_eq!(sources.len(), 12);
        // The largest piece stays even when it is called tiny.
        let r = remove_tiny_pieces(&mut m, &mut sources, |_| true);
        assert_eq!(r.shells, 0);
        assert_eq!(m.triangles.len(), 12);
    }
}
