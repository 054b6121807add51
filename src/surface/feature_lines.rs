//! The input's feature lines: its sharp creases kept as edges and its boundary curves, as one set
//! of segments with a closest-point query. The finishing relaxation slides an output vertex that
//! lies on one of them along it (the feature vertices of Botsch and Kobbelt's isotropic
//! remeshing, "A remeshing approach to multiresolution modeling", SGP 2004, Sec. 3, move along
//! their feature line), so the faces along a crease or a boundary are relaxed like the rest.
//!
//! The projection is parry's polyline point query (a BVH over the segments).

use glam::DVec3;
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::Polyline;

/// Segments of the input's creases and boundary curves (bbox-100 units), for the closest point
/// on them.
pub struct FeatureLines {
    polyline: Polyline,
}

impl FeatureLines {
    /// The segments `edges` (index pairs into `positions`, bbox-100 units). `None` without a
    /// segment of non-zero length.
    pub fn new(positions: &[DVec3], edges: impl IntoIterator<Item = [u32; 2]>) -> Option<Self> {
        let mut vertices: Vec<DVec3> = Vec::new();
        let mut indices: Vec<[u32; 2]> = Vec::new();
        for [a, b] in edges {
            let (p, q) = (positions[a as usize], positions[b as usize]);
            if !(p.distance(q) > 0.0) {
                continue;
            }
            let base = vertices.len() as u32;
            vertices.extend([p, q]);
            indices.push([base, base + 1]);
        }
        if indices.is_empty() {
            return None;
        }
        Some(FeatureLines {
            polyline: Polyline::new(vertices, Some(indices)),
        })
    }

    /// The point of the lines nearest `p` (bbox-100 units).
    pub fn closest_point(&self, p: DVec3) -> DVec3 {
        self.polyline.project_local_point(p, true).point
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_closest_point_lies_on_the_nearest_segment() {
        // An L: (0,0,0)-(2,0,0)-(2,2,0), and a segment of zero length that is left out.
        let positions = [
            DVec3::ZERO,
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(2.0, 2.0, 0.0),
            DVec3::new(5.0, 5.0, 5.0),
        ];
        let lines = FeatureLines::new(&positions, [[0, 1], [1, 2], [3, 3]]).unwrap();
        let q = lines.closest_point(DVec3::new(1.0, 0.5, 0.3));
        assert!(q.distance(DVec3::new(1.0, 0.0, 0.0)) < 1e-12, "{q}");
        let q = lines.closest_point(DVec3::new(2.4, 1.5, 0.0));
        assert!(q.distance(DVec3::new(2.0, 1.5, 0.0)) < 1e-12, "{q}");
        // Beyond an end: the end.
        let q = lines.closest_point(DVec3::new(-1.0, -1.0, 0.0));
        assert!(q.distance(DVec3::ZERO) < 1e-12, "{q}");
        assert!(FeatureLines::new(&positions, [[3, 3]]).is_none());
    }
}
