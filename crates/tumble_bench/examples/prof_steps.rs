//! Temporary profiling driver (not committed): K steps of N bodies, raw or ecs, one thread.
use tumble_bench::engines::{Ecs, Engine, RawLoop};
use tumble_bench::population;
use tumble_core::Integrator;
use tumble_ecs::parallel::Parallelism;

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().unwrap().parse().unwrap();
    let steps: usize = args.next().unwrap().parse().unwrap();
    let which = args.next().unwrap();
    let scene = population::scene(n);
    let single = Parallelism::SINGLE_THREAD;
    let mut engine: Box<dyn Engine> = if which == "implicit" {
        Box::new(tumble_bench::springs::SpringWorld::new(
            1,
            n as tumble_core::math::Real,
            tumble_rapier::presets::ChainStart::Relaxed,
            tumble_ecs::prelude::SpringSolver::Implicit,
            tumble_bench::springs::Loads::None,
        ))
    } else if which == "springs" {
        Box::new(
            tumble_bench::springs::SpringWorld::new(
                n / 10,
                0.5,
                tumble_rapier::presets::ChainStart::Relaxed,
                tumble_ecs::prelude::SpringSolver::Explicit,
                tumble_bench::springs::Loads::GravityForcesDamping,
            )
            .with_parallelism(single),
        )
    } else if which == "raw" {
        Box::new(RawLoop::new(&scene, Integrator::Splitting, single))
    } else {
        Box::new(Ecs::new(&scene, Integrator::Splitting, single))
    };
    for _ in 0..steps {
        engine.step();
    }
    println!("{:?}", engine.state(n / 2).position);
}
