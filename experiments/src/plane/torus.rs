//! The periodic unit square (the torus [0, 1)²): wrapping, toroidal differences and distances,
//! and a uniform grid of cells for neighbour queries that wraps around the edges.
//!
//! All coordinates are in units of the square's side (1).

use glam::DVec2;

/// `p` wrapped into [0, 1)² (each coordinate modulo 1).
#[inline]
pub fn wrap(p: DVec2) -> DVec2 {
    DVec2::new(wrap1(p.x), wrap1(p.y))
}

#[inline]
fn wrap1(x: f64) -> f64 {
    let w = x - x.floor();
    // x = -1e-17 gives 1 - 1e-17 = 1.0 in floating point; keep the half-open interval.
    if w >= 1.0 {
        0.0
    } else {
        w
    }
}

/// The shortest toroidal difference `b - a`: each coordinate in [-1/2, 1/2]. `a + delta(a, b)` is
/// the periodic image of `b` nearest to `a`.
#[inline]
pub fn delta(a: DVec2, b: DVec2) -> DVec2 {
    let d = b - a;
    d - d.round()
}

/// Squared toroidal distance between `a` and `b` (at most 1/2).
#[inline]
pub fn dist2(a: DVec2, b: DVec2) -> f64 {
    delta(a, b).length_squared()
}

/// The periodic images `p + (i, j)` (`i, j` in {-1, 0, 1}, not both 0) of `p` in [0, 1)² that
/// lie within `margin` of the square (in [-margin, 1 + margin)²; `margin` < 1/2): the copies a
/// neighbour query of radius `margin` from inside the square needs across its edges. None for a
/// point farther than `margin` from every edge, up to 3 near a corner.
pub fn periodic_images(p: DVec2, margin: f64) -> impl Iterator<Item = DVec2> {
    // The shifts of each coordinate that keep its image within the margin.
    let shifts = |x: f64| {
        [
            (-1.0, x - 1.0 >= -margin),
            (0.0, true),
            (1.0, x + 1.0 < 1.0 + margin),
        ]
    };
    let (sx, sy) = (shifts(p.x), shifts(p.y));
    sx.into_iter()
        .flat_map(move |(dx, ok_x)| sy.into_iter().map(move |(dy, ok_y)| (dx, dy, ok_x && ok_y)))
        .filter(|&(dx, dy, ok)| ok && (dx, dy) != (0.0, 0.0))
        .map(move |(dx, dy, _)| p + DVec2::new(dx, dy))
}

/// A uniform grid of `cells × cells` square cells over the torus, holding point indices. A query
/// of radius `r <= cell side` visits the 3 × 3 block of cells around the query's cell (wrapping
/// around the edges), so it finds every point within toroidal distance r. Points can move
/// ([`TorusGrid::relocate`]), so the grid serves the gradient ascent as well as static queries.
#[derive(Debug, Clone)]
pub struct TorusGrid {
    cells: usize,
    buckets: Vec<Vec<u32>>,
    /// Cell of each point (`u32::MAX` for points not in the grid).
    cell_of: Vec<u32>,
}

impl TorusGrid {
    /// An empty grid whose cells are at least `min_side` wide (the largest query radius), with
    /// at most `max_cells` per side. `cells` per side = floor(1 / min_side), at least 1; a grid
    /// with fewer than 3 cells per side visits some cells twice, which [`TorusGrid::for_each_near`]
    /// avoids by visiting every cell once.
    pub fn new(min_side: f64, max_cells: usize) -> Self {
        let cells = if min_side.is_finite() && min_side > 0.0 {
            ((1.0 / min_side).floor() as usize).clamp(1, max_cells.max(1))
        } else {
            1
        };
        TorusGrid {
            cells,
            buckets: vec![Vec::new(); cells * cells],
            cell_of: Vec::new(),
        }
    }

    /// A grid holding `points` (indices 0..len), cells at least `min_side` wide and about
    /// `points.len()` cells at most.
    pub fn with_points(points: &[DVec2], min_side: f64) -> Self {
        let max_cells = ((points.len().max(1) as f64).sqrt().ceil() as usize).max(1);
        let mut g = TorusGrid::new(min_side, max_cells);
        for (i, &p) in points.iter().enumerate() {
            g.insert(i as u32, p);
        }
        g
    }

    /// Cells per side.
    pub fn cells(&self) -> usize {
        self.cells
    }

    #[inline]
    fn cell_xy(&self, p: DVec2) -> (usize, usize) {
        let c = self.cells;
        let q = wrap(p);
        let x = ((q.x * c as f64) as usize).min(c - 1);
        let y = ((q.y * c as f64) as usize).min(c - 1);
        (x, y)
    }

    /// Adds point `index` at `p` (any coordinates; wrapped).
    pub fn insert(&mut self, index: u32, p: DVec2) {
        let (x, y) = self.cell_xy(p);
        let cell = (y * self.cells + x) as u32;
        let i = index as usize;
        if self.cell_of.len() <= i {
            self.cell_of.resize(i + 1, u32::MAX);
        }
        self.cell_of[i] = cell;
        self.buckets[cell as usize].push(index);
    }

    /// Moves point `index` (already in the grid) to `p`.
    pub fn relocate(&mut self, index: u32, p: DVec2) {
        let (x, y) = self.cell_xy(p);
        let cell = (y * self.cells + x) as u32;
        let old = self.cell_of[index as usize];
        if old == cell {
            return;
        }
        let bucket = &mut self.buckets[old as usize];
        if let Some(k) = bucket.iter().position(|&j| j == index) {
            bucket.swap_remove(k);
        }
        self.cell_of[index as usize] = cell;
        self.buckets[cell as usize].push(index);
    }

    /// Calls `f(j)` for every point j in the cells around `p` (the 3 × 3 block, each cell once):
    /// a superset of the points within one cell side of `p`.
    pub fn for_each_near(&self, p: DVec2, mut f: impl FnMut(u32)) {
        let c = self.cells;
        let (x, y) = self.cell_xy(p);
        if c < 3 {
            for b in &self.buckets {
                b.iter().for_each(|&j| f(j));
            }
            return;
        }
        for dy in [c - 1, 0, 1] {
            let yy = (y + dy) % c;
            for dx in [c - 1, 0, 1] {
                let xx = (x + dx) % c;
                self.buckets[yy * c + xx].iter().for_each(|&j| f(j));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn toroidal_distance_wraps_around_the_edges() {
        let a = DVec2::new(0.02, 0.5);
        let b = DVec2::new(0.98, 0.5);
        assert!((dist2(a, b).sqrt() - 0.04).abs() < 1e-12);
        assert!((delta(a, b) - DVec2::new(-0.04, 0.0)).length() < 1e-12);
        // Across the corner.
        let c = DVec2::new(0.99, 0.995);
        let d = DVec2::new(0.01, 0.005);
        assert!((dist2(c, d).sqrt() - (0.02f64.powi(2) + 0.01f64.powi(2)).sqrt()).abs() < 1e-12);
        // Never more than half a side per axis.
        assert!((dist2(DVec2::new(0.0, 0.0), DVec2::new(0.5, 0.5)) - 0.5).abs() < 1e-12);
        assert_eq!(wrap(DVec2::new(-0.25, 1.25)), DVec2::new(0.75, 0.25));
        assert!(wrap(DVec2::new(-1e-18, 0.0)).x < 1.0);
    }

    #[test]
    fn grid_finds_every_point_within_a_cell_side_as_brute_force_does() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let pts: Vec<DVec2> = (0..2000)
            .map(|_| DVec2::new(rng.random::<f64>(), rng.random::<f64>()))
            .collect();
        let r = 0.06;
        let mut grid = TorusGrid::with_points(&pts, r);
        assert_eq!(grid.cells(), 16);
        let check = |grid: &TorusGrid, pts: &[DVec2], rng: &mut ChaCha8Rng| {
            for _ in 0..300 {
                let q = DVec2::new(rng.random::<f64>(), rng.random::<f64>());
                let mut found: Vec<u32> = Vec::new();
                grid.for_each_near(q, |j| {
                    if dist2(q, pts[j as usize]) <= r * r {
                        found.push(j)
                    }
                });
                found.sort_unstable();
                let brute: Vec<u32> = (0..pts.len() as u32)
                    .filter(|&j| dist2(q, pts[j as usize]) <= r * r)
                    .collect();
                assert_eq!(found, brute);
            }
        };
        check(&grid, &pts, &mut rng);
        // Move every point and query again.
        let moved: Vec<DVec2> = pts
            .iter()
            .map(|&p| wrap(p + DVec2::new(rng.random_range(-0.1..0.1), 0.37)))
            .collect();
        for (i, &p) in moved.iter().enumerate() {
            grid.relocate(i as u32, p);
        }
        check(&grid, &moved, &mut rng);
    }

    #[test]
    fn periodic_images_are_the_copies_near_the_square() {
        let m = 0.1;
        let count = |p: DVec2| periodic_images(p, m).count();
        assert_eq!(count(DVec2::new(0.5, 0.5)), 0);
        assert_eq!(count(DVec2::new(0.05, 0.5)), 1);
        assert_eq!(count(DVec2::new(0.95, 0.02)), 3);
        let images: Vec<DVec2> = periodic_images(DVec2::new(0.95, 0.5), m).collect();
        assert_eq!(images, [DVec2::new(-0.050000000000000044, 0.5)]);
        // Every image is within the margin of the square and is a copy of the point.
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for _ in 0..1000 {
            let p = DVec2::new(rng.random(), rng.random());
            for q in periodic_images(p, m) {
                assert!(q.min_element() >= -m && q.max_element() < 1.0 + m, "{q}");
                assert!(delta(p, q).length() < 1e-12 && (q - p).length() > 0.99);
            }
        }
    }
}
