//! Lloyd's method on the periodic unit square (the baseline of the paper's Fig. 11, 100
//! iterations): every point moves to the centroid of its periodic Voronoi cell.
//!
//! S. P. Lloyd, "Least squares quantization in PCM", IEEE Trans. Inf. Theory 28(2), 1982,
//! doi:10.1109/TIT.1982.1056489.
//!
//! The periodic Voronoi cells are exact: the points and their periodic copies within a margin
//! around the square are triangulated (Delaunay, spade); a triangle at an original point is a
//! triangle of the periodic Delaunay triangulation when its circumcircle lies inside the region
//! the copies cover (no point of the periodic tiling can then be inside it). The margin starts at
//! 2.5 mean spacings and doubles until every such circumcircle fits. The cell of a point is then
//! the polygon of the circumcentres of its triangles.

use glam::DVec2;
use spade::handles::FixedVertexHandle;
use spade::{DelaunayTriangulation, Point2, Triangulation};

use super::torus::wrap;
use spectral_remesh::{Error, Result};

/// What Lloyd's method did.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
pub struct LloydResult {
    /// Per iteration, the mean distance a point moved (units of the square's side).
    pub mean_move: Vec<f64>,
    /// The largest margin (units of the square's side) an iteration needed.
    pub max_margin: f64,
}

/// The centroids of the periodic Voronoi cells of `points` (in [0, 1)², wrapped on entry), each
/// wrapped into [0, 1)², and the margin that was needed (see the module docs).
///
/// # Errors
/// [`Error::InvalidParameter`] for fewer than 3 points or for two points at the same place
/// (their cells are undefined); [`Error::Internal`] if the triangulation fails.
pub fn periodic_voronoi_centroids(points: &[DVec2]) -> Result<(Vec<DVec2>, f64)> {
    let n = points.len();
    if n < 3 {
        return Err(Error::InvalidParameter {
            name: "--n",
            message: format!("Lloyd's method needs at least 3 points, got {n}"),
        });
    }
    let base: Vec<DVec2> = points.iter().map(|&p| wrap(p)).collect();
    let mut margin = (2.5 / (n as f64).sqrt()).min(1.0);
    loop {
        if let Some(c) = centroids_with_margin(&base, margin)? {
            return Ok((c, margin));
        }
        if margin >= 1.0 {
            return Err(Error::Internal {
                stage: "periodic Voronoi",
                message: "a Delaunay circumcircle does not fit in three periods".into(),
            });
        }
        margin = (2.0 * margin).min(1.0);
    }
}

/// The centroids with copies within `margin` of the square, or `None` when a circumcircle at an
/// original point leaves the covered region (the margin is too small).
fn centroids_with_margin(base: &[DVec2], margin: f64) -> Result<Option<Vec<DVec2>>> {
    let n = base.len();
    let (lo, hi) = (-margin, 1.0 + margin);
    let mut all: Vec<Point2<f64>> = base.iter().map(|p| Point2::new(p.x, p.y)).collect();
    for p in base {
        for sy in [-1.0, 0.0, 1.0] {
            for sx in [-1.0, 0.0, 1.0] {
                if sx == 0.0 && sy == 0.0 {
                    continue;
                }
                let q = *p + DVec2::new(sx, sy);
                if q.x >= lo && q.x <= hi && q.y >= lo && q.y <= hi {
                    all.push(Point2::new(q.x, q.y));
                }
            }
        }
    }
    let total = all.len();
    let tri: DelaunayTriangulation<Point2<f64>> = DelaunayTriangulation::bulk_load_stable(all)
        .map_err(|e| Error::Internal {
            stage: "periodic Voronoi",
            message: format!("triangulation failed: {e:?}"),
        })?;
    if tri.num_vertices() < total {
        return Err(Error::InvalidParameter {
            name: "points",
            message: "two points coincide; their Voronoi cells are undefined".into(),
        });
    }
    let mut out = Vec::with_capacity(n);
    let mut ring: Vec<DVec2> = Vec::new();
    for (i, &p) in base.iter().enumerate() {
        let v = tri.vertex(FixedVertexHandle::from_index(i));
        ring.clear();
        for e in v.out_edges() {
            let Some(face) = e.face().as_inner() else {
                return Ok(None);
            };
            let (c, r2) = face.circumcircle();
            let r = r2.sqrt();
            if c.x - r < lo || c.x + r > hi || c.y - r < lo || c.y + r > hi {
                return Ok(None);
            }
            ring.push(DVec2::new(c.x, c.y) - p);
        }
        // Shoelace centroid of the cell, relative to p.
        let (mut area2, mut cx, mut cy) = (0.0, 0.0, 0.0);
        for k in 0..ring.len() {
            let a = ring[k];
            let b = ring[(k + 1) % ring.len()];
            let cross = a.x * b.y - b.x * a.y;
            area2 += cross;
            cx += (a.x + b.x) * cross;
            cy += (a.y + b.y) * cross;
        }
        let centroid = if area2.abs() > 0.0 {
            p + DVec2::new(cx, cy) / (3.0 * area2)
        } else {
            p
        };
        out.push(wrap(centroid));
    }
    Ok(Some(out))
}

/// `iterations` steps of Lloyd's method on the torus, in place (points in [0, 1)²).
///
/// # Errors
/// As [`periodic_voronoi_centroids`].
pub fn lloyd(points: &mut [DVec2], iterations: usize) -> Result<LloydResult> {
    let mut result = LloydResult::default();
    for _ in 0..iterations {
        let (c, margin) = periodic_voronoi_centroids(points)?;
        let total: f64 = points
            .iter()
            .zip(&c)
            .map(|(a, b)| super::torus::dist2(*a, *b).sqrt())
            .sum();
        result.mean_move.push(total / points.len() as f64);
        result.max_margin = result.max_margin.max(margin);
        points.copy_from_slice(&c);
    }
    Ok(result)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plane::spectral::uniform_random;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn cells_tile_the_square_and_a_lattice_is_a_fixed_point() {
        // A square lattice (offset so no point is on the square's edge): every centroid is the
        // point itself.
        let m = 12;
        let lattice: Vec<DVec2> = (0..m * m)
            .map(|k| DVec2::new((k % m) as f64 + 0.3, (k / m) as f64 + 0.6) / m as f64)
            .collect();
        let (c, _) = periodic_voronoi_centroids(&lattice).unwrap();
        for (a, b) in lattice.iter().zip(&c) {
            assert!(super::super::torus::dist2(*a, *b).sqrt() < 1e-9);
        }
    }

    #[test]
    fn centroids_agree_with_a_brute_force_cell_estimate_and_energy_falls() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let mut pts = uniform_random(200, &mut rng);
        let (c, _) = periodic_voronoi_centroids(&pts).unwrap();
        // Brute force: a fine grid of the torus, each sample to its nearest point (toroidal).
        let g = 400;
        let mut sum = vec![DVec2::ZERO; pts.len()];
        let mut cnt = vec![0usize; pts.len()];
        for iy in 0..g {
            for ix in 0..g {
                let q = DVec2::new((ix as f64 + 0.5) / g as f64, (iy as f64 + 0.5) / g as f64);
                let (j, _) = pts
                    .iter()
                    .enumerate()
                    .map(|(j, p)| (j, super::super::torus::dist2(q, *p)))
                    .min_by(|a, b| a.1.total_cmp(&b.1))
                    .unwrap();
                // Offset from the point to the sample's image nearest to it.
                sum[j] += super::super::torus::delta(pts[j], q);
                cnt[j] += 1;
            }
        }
        let mut worst: f64 = 0.0;
        for j in 0..pts.len() {
            let est = wrap(pts[j] + sum[j] / cnt[j] as f64);
            worst = worst.max(super::super::torus::dist2(est, c[j]).sqrt());
        }
        // The grid step is 1/400 = 0.0025; the mean spacing is 0.07.
        assert!(worst < 0.002, "largest centroid difference {worst}");
        let energy = |pts: &[DVec2]| -> f64 {
            let mut e = 0.0;
            for iy in 0..100 {
                for ix in 0..100 {
                    let q = DVec2::new((ix as f64 + 0.5) / 100.0, (iy as f64 + 0.5) / 100.0);
                    e += pts
                        .iter()
                        .map(|p| super::super::torus::dist2(q, *p))
                        .fold(f64::INFINITY, f64::min);
                }
            }
            e
        };
        let e0 = energy(&pts);
        let r = lloyd(&mut pts, 20).unwrap();
        assert!(energy(&pts) < 0.8 * e0);
        assert!(r.mean_move.last().unwrap() < &r.mean_move[0]);
    }

    #[test]
    fn coincident_points_are_an_error() {
        let pts = vec![
            DVec2::new(0.2, 0.2),
            DVec2::new(0.2, 0.2),
            DVec2::new(0.7, 0.4),
            DVec2::new(0.5, 0.9),
        ];
        assert!(matches!(
            periodic_voronoi_centroids(&pts),
            Err(Error::InvalidParameter { .. })
        ));
        assert!(periodic_voronoi_centroids(&pts[..2]).is_err());
    }
}
