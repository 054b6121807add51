//! One sweep of the sequential gradient ascent (Sec. 6.2), shared by the surface sampler
//! (`sampling::gradient_ascent`) and the sampler in R^d (`manifold::gradient_ascent`): the samples
//! are visited in a seeded random order, each move seeing the moves before it. Consecutive
//! samples of that order of which no two are neighbours form a batch: their moves read only
//! samples outside it, so a batch is computed in parallel with the result of one at a time.

/// The most samples moved together in one batch.
pub(crate) const MAX_BATCH: usize = 64;

/// The batches of sweeps over `n` samples (which batch each sample was last put in).
pub(crate) struct Batches {
    batch_of: Vec<u64>,
    batch_id: u64,
    max_batch: usize,
}

impl Batches {
    /// For `n` samples, at most `max_batch` in a batch.
    pub(crate) fn new(n: usize, max_batch: usize) -> Self {
        Batches {
            batch_of: vec![0; n],
            batch_id: 0,
            max_batch: max_batch.max(1),
        }
    }

    /// Cuts `order` (sample indices below `n`) into batches of consecutive samples of which no
    /// two are neighbours (`neighbours(i)`: the indices of sample i's neighbours) and calls
    /// `visit` on each batch in order; stops at the first error.
    pub(crate) fn sweep<'a, E>(
        &mut self,
        order: &[usize],
        neighbours: impl Fn(usize) -> &'a [u32],
        mut visit: impl FnMut(&[usize]) -> Result<(), E>,
    ) -> Result<(), E> {
        let mut start = 0;
        while start < order.len() {
            self.batch_id += 1;
            let mut end = start;
            while end < order.len() && end - start < self.max_batch {
                let i = order[end];
                if neighbours(i)
                    .iter()
                    .any(|&j| self.batch_of[j as usize] == self.batch_id)
                {
                    break;
                }
                self.batch_of[i] = self.batch_id;
                end += 1;
            }
            visit(&order[start..end])?;
            start = end;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every sample is visited once, in order, and no batch holds two neighbours.
    #[test]
    fn batches_cover_the_order_without_neighbours() {
        // A path 0 - 1 - 2 - ... - 9: i's neighbours are i - 1 and i + 1.
        let lists: Vec<Vec<u32>> = (0..10u32)
            .map(|i| {
                [i.wrapping_sub(1), i + 1]
                    .into_iter()
                    .filter(|&j| j < 10)
                    .collect()
            })
            .collect();
        let order = [3, 5, 4, 0, 9, 8, 1, 2, 7, 6];
        let mut batches = Batches::new(10, 3);
        let mut seen = Vec::new();
        batches
            .sweep(
                &order,
                |i| &lists[i],
                |batch| {
                    assert!(batch.len() <= 3);
                    for (k, &a) in batch.iter().enumerate() {
                        for &b in &batch[k + 1..] {
                            assert!(!lists[a].contains(&(b as u32)), "{batch:?}");
                        }
                    }
                    seen.extend_from_slice(batch);
                    Ok::<(), ()>(())
                },
            )
            .unwrap();
        assert_eq!(seen, order);
        // Errors stop the sweep.
        let mut visits = 0;
        let r = Batches::new(10, 3).sweep(
            &order,
            |i| &lists[i],
            |_| {
                visits += 1;
                Err("stop")
            },
        );
        assert_eq!((r, visits), (Err("stop"), 1));
    }
}
