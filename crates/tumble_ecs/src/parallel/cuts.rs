//! Cutting an ordered pass into runs that share nothing, so that it runs on several threads
//! with the same bits as on one.
//!
//! Some passes must add items into shared sums in item order: force pushes into the bodies'
//! accumulators, energies into their groups' balances. A sum's bits depend on its order, so
//! such a pass runs on several threads only where its items cut into consecutive runs whose
//! sums are disjoint: each sum then takes all of its terms, in order, on one thread. Each item
//! names the sums it adds to by ordered *keys* (a body's table and row, a group's number); a
//! cut before item `s` is clean when every key of the items before it is below every key of
//! the items after it, and the run after the cut then owns the keys from the smallest of its
//! items on. Chains of bodies, groups numbered as they are met, generators spawned body by body
//! have clean cuts every few items; where an item near every even cut reaches across (one
//! network, or items in no order), the pass stays on one thread.

use std::ops::Range;

/// Most runs a pass is cut into (their parts are held on the stack).
pub(crate) const MAX_RUNS: usize = 8;

/// How far from an even cut (in items) a clean one is looked for.
pub(crate) const CUT_WINDOW: usize = 256;

/// A pass cut into runs of consecutive items that share no key.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Runs {
    count: usize,
    /// Run `k` is items `starts[k]..starts[k + 1]`.
    starts: [usize; MAX_RUNS + 1],
    /// Run `k ≥ 1` holds the keys from `bounds[k − 1]` on, every earlier run only smaller ones.
    bounds: [u64; MAX_RUNS],
}

impl Runs {
    /// All `len` items in one run.
    pub(crate) fn whole(len: usize) -> Self {
        let mut starts = [0; MAX_RUNS + 1];
        starts[1] = len;
        Self {
            count: 1,
            starts,
            bounds: [0; MAX_RUNS],
        }
    }

    /// The number of runs.
    pub(crate) fn count(&self) -> usize {
        self.count
    }

    /// The items of run `k`.
    pub(crate) fn items(&self, k: usize) -> Range<usize> {
        self.starts[k]..self.starts[k + 1]
    }

    /// The first key of each run but the first.
    pub(crate) fn bounds(&self) -> &[u64] {
        &self.bounds[..self.count - 1]
    }

    /// The items, over all runs.
    pub(crate) fn len(&self) -> usize {
        self.starts[self.count]
    }

    /// Takes the clean cut nearest `even` within [`CUT_WINDOW`] after the last cut, if any.
    fn cut_near(&mut self, even: usize, clean: impl Fn(usize) -> Option<u64>) {
        let (last, len) = (self.starts[self.count - 1], self.starts[self.count]);
        let found = (0..=CUT_WINDOW)
            .flat_map(|d| [even + d, even.wrapping_sub(d)])
            .filter(|&s| s > last && s < len)
            .find_map(|s| clean(s).map(|bound| (s, bound)));
        if let Some((s, bound)) = found {
            self.starts[self.count] = s;
            self.bounds[self.count - 1] = bound;
            self.count += 1;
            self.starts[self.count] = len;
        }
    }

    /// Chooses the cuts of `len` items into at most `threads` runs: for each even cut
    /// `k·len/threads`, the clean cut nearest it within [`CUT_WINDOW`] after the last one
    /// taken, if any. `key(i)` is the smallest and the largest key of item `i` (`None` for an
    /// item with none), read where it lies: one pass over the items for the extremes outside
    /// the windows around the even cuts, and each window item by item. No memory per item.
    pub(crate) fn of_keys(
        len: usize,
        threads: usize,
        key: impl Fn(usize) -> Option<(u64, u64)>,
    ) -> Self {
        let threads = threads.clamp(1, MAX_RUNS);
        let mut runs = Self::whole(len);
        if len < 2 {
            return runs;
        }
        let key = |i: usize| key(i).unwrap_or((u64::MAX, 0));
        // The cut positions around even cut `k` (cut `s` has items `..s` before it).
        let window = |k: usize| {
            let even = k * len / threads;
            even.saturating_sub(CUT_WINDOW).max(1)..(even + CUT_WINDOW + 1).min(len)
        };
        // The largest key before each window (of the items before its first cut) and the
        // smallest after it. Where windows overlap these take in more items than that, which
        // can only hide a clean cut, never make an unclean one look clean.
        let mut before = [0; MAX_RUNS];
        let (mut largest, mut at) = (0, 0);
        for (k, slot) in before.iter_mut().enumerate().take(threads).skip(1) {
            let first = window(k).start - 1;
            for i in at..first {
                largest = largest.max(key(i).1);
            }
            at = at.max(first);
            *slot = largest;
        }
        let mut after = [u64::MAX; MAX_RUNS];
        let (mut smallest, mut at) = (u64::MAX, len);
        for k in (1..threads).rev() {
            let end = window(k).end;
            for i in end.min(at)..at {
                smallest = smallest.min(key(i).0);
            }
            at = at.min(end);
            after[k] = smallest;
        }
        // Within each window: the largest key before each cut and the smallest from it.
        let mut below = [0u64; 2 * CUT_WINDOW + 1];
        let mut from = [u64::MAX; 2 * CUT_WINDOW + 1];
        for k in 1..threads {
            let w = window(k);
            let mut largest = before[k];
            for (j, s) in w.clone().enumerate() {
                largest = largest.max(key(s - 1).1);
                below[j] = largest;
            }
            let mut smallest = after[k];
            for (j, s) in w.clone().enumerate().rev() {
                smallest = smallest.min(key(s).0);
                from[j] = smallest;
            }
            runs.cut_near(k * len / threads, |s| {
                let j = s.checked_sub(w.start).filter(|_| s < w.end)?;
                (below[j] < from[j]).then_some(from[j])
            });
        }
        runs
    }
}

/// Runs `work` on each run of `runs` on the compute pool (on this thread where there is one),
/// with that run's part of `sums`: `sums` cut at the runs' bounds (indices into it), each part
/// with the index of its first sum.
pub(crate) fn in_runs_of_sums<T: Send>(
    runs: &Runs,
    sums: &mut [T],
    work: impl Fn(Range<usize>, &mut [T], usize) + Sync,
) {
    if runs.count() == 1 {
        return work(runs.items(0), sums, 0);
    }
    let work = &work;
    super::scope(|spawn| {
        let mut rest = sums;
        let mut first = 0;
        for k in 0..runs.count() {
            let end = runs
                .bounds()
                .get(k)
                .map_or(first + rest.len(), |&b| {
                    usize::try_from(b).unwrap_or(usize::MAX)
                })
                .clamp(first, first + rest.len());
            let (mine, after) = std::mem::take(&mut rest).split_at_mut(end - first);
            let items = runs.items(k);
            let at = first;
            spawn(Box::new(move || work(items, mine, at)));
            rest = after;
            first = end;
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Chains of ten items: item `i` touches keys `i + i/10` and the next.
    fn chain(i: usize) -> Option<(u64, u64)> {
        let key = (i + i / 10) as u64;
        Some((key, key + 1))
    }

    #[test]
    fn chains_are_cut_between_chains_only() {
        let runs = Runs::of_keys(1000, 4, chain);
        assert_eq!(runs.count(), 4);
        for k in 1..4 {
            let s = runs.items(k).start;
            assert_eq!(s % 10, 0, "cut {k} at {s}");
            assert_eq!(runs.bounds()[k - 1], (s + s / 10) as u64);
        }
        assert_eq!(runs.len(), 1000);
    }

    #[test]
    fn one_chain_is_not_cut() {
        let runs = Runs::of_keys(1000, 2, |i| Some((i as u64, i as u64 + 1)));
        assert_eq!(runs, Runs::whole(1000));
    }

    #[test]
    fn an_item_that_reaches_back_keeps_the_pass_whole() {
        // The last item touches key 0 again: any cut would split key 0's terms.
        let runs = Runs::of_keys(100, 2, |i| {
            Some(if i == 99 {
                (0, 0)
            } else {
                (i as u64, i as u64)
            })
        });
        assert_eq!(runs.count(), 1);
    }

    #[test]
    fn items_without_keys_never_block_a_cut() {
        let runs = Runs::of_keys(64, 2, |i| match i {
            0 => Some((5, 5)),
            63 => Some((9, 9)),
            _ => None,
        });
        assert_eq!(runs.count(), 2);
        assert_eq!(runs.items(1).start, 32);
        assert_eq!(runs.bounds(), &[9]);
    }

    #[test]
    fn long_passes_find_the_cut_nearest_the_even_one_beyond_the_window_scan() {
        // 10⁵ items in groups of 7: every even cut has a clean cut within 3 items.
        let runs = Runs::of_keys(100_000, 8, |i| Some(((i / 7) as u64, (i / 7) as u64)));
        assert_eq!(runs.count(), 8);
        for k in 1..8 {
            let s = runs.items(k).start;
            assert_eq!(s % 7, 0);
            assert!(s.abs_diff(k * 100_000 / 8) <= 3);
            assert_eq!(runs.bounds()[k - 1], (s / 7) as u64);
        }
    }

    #[test]
    fn sums_are_split_at_the_bounds() {
        let runs = Runs::of_keys(1000, 4, chain);
        let mut sums = vec![0u64; 1100];
        // Each item adds 1 to its keys' sums; each run may touch only its own part.
        in_runs_of_sums(&runs, &mut sums, |items, part, first| {
            for i in items {
                let (lo, hi) = chain(i).unwrap();
                for key in [lo, hi] {
                    part[key as usize - first] += 1;
                }
            }
        });
        let mut want = vec![0u64; 1100];
        for i in 0..1000 {
            let (lo, hi) = chain(i).unwrap();
            want[lo as usize] += 1;
            want[hi as usize] += 1;
        }
        assert_eq!(sums, want);
    }
}
