//! Disjoint sets (union-find with union by size and path compression), with a parity per
//! element relative to its root: the topology check's connectivity and orientability, the
//! grading's groups of graded samples and the stray-shell pass's components.

/// Disjoint sets over `0..n` with, for each element, a parity relative to its root (used for
/// orientability; plain connectivity ignores the parity).
pub(crate) struct Dsu {
    parent: Vec<u32>,
    parity: Vec<bool>,
    size: Vec<u32>,
}

impl Dsu {
    pub(crate) fn new(n: usize) -> Self {
        Dsu {
            parent: (0..n as u32).collect(),
            parity: vec![false; n],
            size: vec![1; n],
        }
    }

    /// The root of `x` and the parity of `x` relative to it, compressing the path.
    pub(crate) fn find(&mut self, x: usize) -> (usize, bool) {
        let mut root = x;
        let mut acc = false;
        while self.parent[root] as usize != root {
            acc ^= self.parity[root];
            root = self.parent[root] as usize;
        }
        let mut y = x;
        let mut py = acc;
        while self.parent[y] as usize != y {
            let next = self.parent[y] as usize;
            let old = self.parity[y];
            self.parent[y] = root as u32;
            self.parity[y] = py;
            py ^= old;
            y = next;
        }
        (root, acc)
    }

    /// Joins `a` and `b` with relative parity `rel`; returns `false` when they were already
    /// joined with the other parity.
    pub(crate) fn union(&mut self, a: usize, b: usize, rel: bool) -> bool {
        let (ra, pa) = self.find(a);
        let (rb, pb) = self.find(b);
        if ra == rb {
            return (pa ^ pb) == rel;
        }
        let (big, small) = if self.size[ra] >= self.size[rb] {
            (ra, rb)
        } else {
            (rb, ra)
        };
        self.parent[small] = big as u32;
        self.parity[small] = pa ^ pb ^ rel;
        self.size[big] += self.size[small];
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parity_dsu_detects_odd_cycles() {
        let mut d = Dsu::new(4);
        assert!(d.union(0, 1, true));
        assert!(d.union(1, 2, true));
        // 0 and 2 have even relative parity.
        assert!(d.union(0, 2, false));
        assert!(!d.union(0, 2, true));
        assert_eq!(d.find(0).0, d.find(2).0);
        assert_ne!(d.find(3).0, d.find(0).0);
        let (r, p0) = d.find(0);
        let (_, p1) = d.find(1);
        assert!(p0 ^ p1);
        assert!(!d.find(r).1);
    }
}
