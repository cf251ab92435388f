//! How the integrate systems spread bodies over threads.
//!
//! With the `parallel` feature the integrate systems split each body table into one run per
//! thread of bevy's `ComputeTaskPool`; without it, or for small worlds, they run on the calling
//! thread. (The split is ours rather than `contiguous_par_iter_mut`'s: bevy 0.20.1 trips a
//! debug assertion when it hands out part of a table.) Every body is stepped by the same code whichever batch or thread it
//! lands in, so the results are bit-identical for any thread count (tested).

mod cuts;

pub(crate) use cuts::{MAX_RUNS, Runs, in_runs_of_sums};

use bevy_ecs::prelude::*;

/// Threading policy of the physics systems. Optional resource: without it the defaults apply.
#[derive(Resource, Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Parallelism {
    /// Use the thread pool at all (only has an effect with the `parallel` feature).
    pub enabled: bool,
    /// Worlds with fewer bodies than this run on the calling thread: below a few thousand
    /// bodies, waking the pool costs more than it saves.
    pub min_bodies: usize,
    /// The smallest batch handed to one task.
    pub min_batch: usize,
}

impl Default for Parallelism {
    /// Enabled from 4096 bodies, batches of at least 1024.
    fn default() -> Self {
        Self {
            enabled: true,
            min_bodies: 4096,
            min_batch: 1024,
        }
    }
}

impl Parallelism {
    /// Everything on the calling thread.
    pub const SINGLE_THREAD: Self = Self {
        enabled: false,
        min_bodies: usize::MAX,
        min_batch: usize::MAX,
    };

    /// How many threads to spread `bodies` bodies over: 1 unless the `parallel` feature is on,
    /// the policy allows it and the run is big enough; never more than the pool has, and never
    /// batches smaller than `min_batch`.
    pub fn threads_for(&self, bodies: usize) -> usize {
        if !cfg!(feature = "parallel") || !self.enabled || bodies < self.min_bodies {
            return 1;
        }
        pool_threads().min(bodies / self.min_batch.max(1)).max(1)
    }
}

/// A unit of work for [`scope`].
pub type Job<'a> = Box<dyn FnOnce() + Send + 'a>;

/// Runs every job handed to `spawn` on the compute pool and returns when all are done.
#[cfg(feature = "parallel")]
pub fn scope<'env>(jobs: impl FnOnce(&mut dyn FnMut(Job<'env>))) {
    let pool = compute_pool();
    pool.scope(|s| {
        jobs(&mut |job: Job<'env>| s.spawn(async move { job() }));
    });
}

/// Without the `parallel` feature the jobs run one after another on this thread.
#[cfg(not(feature = "parallel"))]
pub fn scope<'env>(jobs: impl FnOnce(&mut dyn FnMut(Job<'env>))) {
    jobs(&mut |job: Job<'env>| job());
}

/// Threads that work on a split table: the compute pool's workers plus the calling thread,
/// creating the pool (one worker per core but one) on first use. Measured on 2 cores at 10⁵
/// bodies: with one worker per core (the caller then competing with both) the split ran 1.4×
/// faster than one thread; with one worker fewer, 1.9×.
#[cfg(feature = "parallel")]
pub fn pool_threads() -> usize {
    // The thread that opens a scope runs tasks too, so the pool's workers plus this one.
    compute_pool().thread_num() + 1
}

/// bevy's compute pool, created on first use with one worker per core but one: the thread that
/// runs the schedule works in every scope as well, so the cores are not oversubscribed.
#[cfg(feature = "parallel")]
fn compute_pool() -> &'static bevy_tasks::ComputeTaskPool {
    bevy_tasks::ComputeTaskPool::get_or_init(|| {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        bevy_tasks::TaskPoolBuilder::new()
            .num_threads(cores.saturating_sub(1).max(1))
            .thread_name("tumble compute".to_owned())
            .build()
    })
}

/// Without the `parallel` feature there is one thread.
#[cfg(not(feature = "parallel"))]
pub fn pool_threads() -> usize {
    1
}

/// Runs `work` on `items` cut into `threads` runs of nearly equal length, one job per run on
/// the compute pool (on this thread alone when `threads` is 1), each with the index of its first
/// item; true when `work` returned true for every run. For passes whose items are independent:
/// each item is worked by the same code in any cut, so the results do not depend on the number
/// of threads.
pub(crate) fn in_runs<T: Send>(
    threads: usize,
    items: &mut [T],
    work: impl Fn(usize, &mut [T]) -> bool + Sync,
) -> bool {
    let len = items.len();
    each_run(threads, items, len, |s, n| s.split_at_mut(n), &work)
}

/// [`in_runs`] over items that are only read.
pub(crate) fn all_runs<T: Sync>(
    threads: usize,
    items: &[T],
    work: impl Fn(usize, &[T]) -> bool + Sync,
) -> bool {
    each_run(threads, items, items.len(), |s, n| s.split_at(n), &work)
}

/// The cut of [`in_runs`] and [`all_runs`]: `items` (of `len` items) into `threads` runs,
/// `split` taking the first `n` items off a run.
fn each_run<S: Send>(
    threads: usize,
    items: S,
    len: usize,
    split: fn(S, usize) -> (S, S),
    work: &(impl Fn(usize, S) -> bool + Sync),
) -> bool {
    if threads <= 1 {
        return work(0, items);
    }
    let failed = std::sync::atomic::AtomicBool::new(false);
    let failed_ref = &failed;
    scope(|spawn| {
        let (mut rest, mut left, mut first) = (Some(items), len, 0);
        for k in (1..=threads).rev() {
            let take = left / k;
            let Some(items) = rest.take() else { break };
            let (run, tail) = split(items, take);
            spawn(Box::new(move || {
                if !work(first, run) {
                    failed_ref.store(true, std::sync::atomic::Ordering::Relaxed);
                }
            }));
            (rest, left, first) = (Some(tail), left - take, first + take);
        }
    });
    !failed.into_inner()
}
