//! Frames of planes in 3D.

use glam::DVec3;

/// An orthonormal basis (u, v) of the plane orthogonal to the unit vector `n`, with
/// u × v = n: the tangent plane of a sample (the local Delaunay umbrellas), or the plane a
/// polygon or a hole is triangulated in. Deterministic: u is the projection of X (or of Y
/// when `n` is close to X) onto the plane.
pub fn tangent_basis(n: DVec3) -> (DVec3, DVec3) {
    let a = if n.x.abs() < 0.6 { DVec3::X } else { DVec3::Y };
    let u = (a - n * n.dot(a)).normalize();
    let v = n.cross(u);
    (u, v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tangent_basis_is_orthonormal() {
        for n in [DVec3::Z, DVec3::X, DVec3::new(1.0, -2.0, 0.5).normalize()] {
            let (u, v) = tangent_basis(n);
            assert!(u.dot(n).abs() < 1e-12 && v.dot(n).abs() < 1e-12 && u.dot(v).abs() < 1e-12);
            assert!((u.length() - 1.0).abs() < 1e-12 && (v.length() - 1.0).abs() < 1e-12);
            // Right-handed: u × v = n.
            assert!(u.cross(v).distance(n) < 1e-12);
        }
    }
}
