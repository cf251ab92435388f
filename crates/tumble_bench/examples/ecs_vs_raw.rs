//! A quick look at the ECS layer's cost: tumble's ECS schedule against the raw loop on one
//! thread, for one world size and integrator, in a few seconds. Handy under a profiler
//! (`perf record`), and for checking an optimisation before the full `tumble bench` run.
//!
//! `cargo run --release -p tumble_bench --example ecs_vs_raw -- [BODIES] [INTEGRATOR] [ENGINE]`
//! with ENGINE `both` (default), `ecs` or `raw`.

use tumble_bench::engines::{Ecs, Engine, RawLoop};
use tumble_bench::measure::{Effort, compare};
use tumble_bench::population;
use tumble_core::Integrator;
use tumble_ecs::parallel::Parallelism;

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let bodies: usize = args
        .next()
        .map_or(Ok(10_000), |s| s.parse())
        .map_err(|e| format!("bodies: {e}"))?;
    let integrator: Integrator = args
        .next()
        .map_or(Ok(Integrator::Splitting), |s| s.parse())
        .map_err(|e| format!("integrator: {e}"))?;
    let which = args.next().unwrap_or_else(|| "both".to_owned());
    let scene = population::scene(bodies);
    let single = Parallelism::SINGLE_THREAD;
    let mut raw = RawLoop::new(&scene, integrator, single);
    let mut ecs = Ecs::new(&scene, integrator, single);
    let effort = Effort {
        body_steps: 20_000_000,
        min_steps: 3,
        max_steps: 2_000_000,
        repetitions: 7,
    };
    let mut engines: Vec<&mut dyn Engine> = match which.as_str() {
        "ecs" => vec![&mut ecs],
        "raw" => vec![&mut raw],
        "both" => vec![&mut raw, &mut ecs],
        other => return Err(format!("engine: expected both, ecs or raw, got {other}")),
    };
    let ns = compare(&mut engines, bodies, &effort);
    let names: &[&str] = match which.as_str() {
        "ecs" => &["ecs"],
        "raw" => &["raw"],
        _ => &["raw", "ecs"],
    };
    for (name, ns) in names.iter().zip(&ns) {
        println!("{bodies} bodies · {integrator} · {name}: {ns:.1} ns per body-step");
    }
    if ns.len() == 2 {
        println!("ecs/raw {:.2}", ns[1] / ns[0]);
    }
    Ok(())
}
