//! The cost of the exact free flow: `exact` against the default `splitting` on the same scene,
//! ECS, one thread, in the same run (the ratio is what the exact-rotation issue bounds).

use serde::Serialize;
use tumble_core::Integrator;
use tumble_ecs::parallel::Parallelism;

use crate::engines::{Ecs, Engine};
use crate::measure::{Effort, compare};
use crate::population;

/// One size: ns per body-step of both methods.
#[derive(Debug, Clone, Serialize)]
pub struct ExactRow {
    /// Bodies in the scene.
    pub bodies: usize,
    /// `splitting`, ECS, one thread (ns per body-step).
    pub splitting_ns: f64,
    /// `exact`, ECS, one thread (ns per body-step).
    pub exact_ns: f64,
}

impl ExactRow {
    /// `exact / splitting`.
    pub fn ratio(&self) -> f64 {
        self.exact_ns / self.splitting_ns
    }
}

/// Times both methods on the benchmark population at each of `sizes`.
pub fn run(sizes: &[usize], effort: &Effort, mut progress: impl FnMut(&str)) -> Vec<ExactRow> {
    sizes
        .iter()
        .map(|&n| {
            progress(&format!("{n} bodies · exact vs splitting"));
            let scene = population::scene(n);
            let single = Parallelism::SINGLE_THREAD;
            let mut splitting = Ecs::new(&scene, Integrator::Splitting, single);
            let mut exact = Ecs::new(&scene, Integrator::Exact, single);
            let mut engines: Vec<&mut dyn Engine> = vec![&mut splitting, &mut exact];
            let ns = compare(&mut engines, n, effort);
            ExactRow {
                bodies: n,
                splitting_ns: ns[0],
                exact_ns: ns[1],
            }
        })
        .collect()
}
