//! How much a second thread can gain on this machine at all, measured in the same run as the
//! engines: two independent copies of the one-thread raw loop, each stepping its own world on its
//! own thread at the same time, against one copy alone.
//!
//! Two threads that share nothing still share the core's execution units when the two virtual
//! CPUs are hyperthreads of one physical core (a 2-vCPU cloud machine often is, whatever its
//! `lscpu` says), and the memory and last-level cache with a busy neighbour. The ratio
//! `2 t_alone / t_together` is then below 2 for *any* two-thread code, tumble's included: it is
//! the ceiling the "2 threads / 1 thread" target is measured against.

use std::sync::Barrier;
use std::time::Instant;

use tumble_core::Integrator;
use tumble_ecs::parallel::Parallelism;

use crate::engines::{Engine, RawLoop};
use crate::measure::median;
use crate::population;

/// Wall time of `steps` steps of every world in `worlds`, each on its own thread (the first on
/// the calling thread, so that no third thread waits for a core to take the time), all started
/// together.
fn run_together(worlds: &mut [RawLoop], steps: usize) -> f64 {
    let Some((first, others)) = worlds.split_first_mut() else {
        return 0.0;
    };
    let start_line = Barrier::new(others.len() + 1);
    let run = |world: &mut RawLoop| {
        for _ in 0..steps {
            world.step();
        }
    };
    let start = std::thread::scope(|s| {
        for world in others {
            let (start_line, run) = (&start_line, &run);
            s.spawn(move || {
                start_line.wait();
                run(world);
            });
        }
        start_line.wait();
        let start = Instant::now();
        run(first);
        start
    });
    // `scope` returns once it has joined the other threads: their steps are inside the time.
    start.elapsed().as_secs_f64()
}

/// The two-copy ceiling `2 t_alone / t_together` for worlds of `bodies` free bodies under the
/// default integrator, `steps` steps per timing, median of `repetitions` interleaved pairs of
/// timings (alone, then together).
pub fn two_copy_ceiling(bodies: usize, steps: usize, repetitions: usize) -> f64 {
    let scene = population::scene(bodies);
    let world = || RawLoop::new(&scene, Integrator::default(), Parallelism::SINGLE_THREAD);
    let mut alone = [world()];
    let mut pair = [world(), world()];
    // Warm-up: first touches, the kernel path's detection, the threads' stacks.
    run_together(&mut alone, 1);
    run_together(&mut pair, 1);
    let ratios = (0..repetitions.max(1))
        .map(|_| {
            let t_alone = run_together(&mut alone, steps);
            let t_together = run_together(&mut pair, steps);
            2.0 * t_alone / t_together
        })
        .collect();
    median(ratios)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every world runs all its steps, on its own thread: each ends where the same world
    /// stepped alone on this thread ends, bit for bit.
    #[test]
    fn every_world_runs_every_step() {
        let scene = population::scene(300);
        let world = || RawLoop::new(&scene, Integrator::default(), Parallelism::SINGLE_THREAD);
        let mut pair = [world(), world()];
        run_together(&mut pair, 7);
        let mut serial = world();
        for _ in 0..7 {
            serial.step();
        }
        for together in &pair {
            for i in [0, 150, 299] {
                assert_eq!(together.state(i), serial.state(i), "body {i}");
            }
        }
        assert_ne!(serial.state(0), world().state(0), "the worlds moved");
    }

    /// The ceiling is a ratio of two measured times: finite and positive. Whether it lies
    /// between 1 and 2 depends on the machine and its neighbours at that moment (a timed
    /// bound failed here with 4.6 while another build ran), so the bench reports it and no
    /// test bounds it.
    #[test]
    fn the_ceiling_is_a_finite_positive_ratio() {
        let ceiling = two_copy_ceiling(2_000, 20, 3);
        assert!(ceiling.is_finite() && ceiling > 0.0, "{ceiling}");
    }
}
