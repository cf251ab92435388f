//! Every integrator's free-body step through the ECS and the raw loop, on one and two threads,
//! against the default `splitting` on the same scene (the ratios are what the speed issue
//! bounds: [`METHOD_BOUNDS`], and the ECS layer's cost per method).

use serde::Serialize;
use tumble_core::Integrator;
use tumble_ecs::parallel::Parallelism;

use crate::engines::{Ecs, Engine, RawLoop};
use crate::measure::{Effort, compare};
use crate::population;

/// What a method's cost is bounded against: `bound ×` the cost of `relative_to`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MethodBound {
    /// The method bounded.
    pub integrator: Integrator,
    /// The method it is measured against.
    pub relative_to: Integrator,
    /// The largest ratio met.
    pub bound: f64,
}

/// The bounds of the speed issue, as data: the first-order methods do less work than
/// `splitting` and must cost no more; the second-order split methods at most 3×; the
/// three-stage compositions at most 3.5× their one-stage method; the exact flow at most 10×.
pub const METHOD_BOUNDS: [MethodBound; 9] = {
    use Integrator::*;
    const fn b(integrator: Integrator, relative_to: Integrator, bound: f64) -> MethodBound {
        MethodBound {
            integrator,
            relative_to,
            bound,
        }
    }
    [
        b(SymplecticEuler, Splitting, 1.0),
        b(SymplecticEulerLinear, Splitting, 1.0),
        b(Lclamp, Splitting, 1.0),
        b(ImplicitGyroscopic, Splitting, 1.0),
        b(SplittingXyz, Splitting, 3.0),
        b(Rk4, Splitting, 3.0),
        b(Yoshida4, Splitting, 3.5),
        b(Exact, Splitting, 10.0),
        b(Exact4, Exact, 3.5),
    ]
};

/// One method at one size: ns per body-step through the raw loop and the ECS, on one thread
/// and on the pool, and `splitting`'s ECS step on one thread timed in the same interleaved run
/// (the reference its ratios are taken against).
#[derive(Debug, Clone, Serialize)]
pub struct MethodRow {
    /// The method.
    pub integrator: Integrator,
    /// Bodies in the scene.
    pub bodies: usize,
    /// Raw loop, one thread.
    pub raw_1t: f64,
    /// ECS, one thread.
    pub ecs_1t: f64,
    /// Raw loop, the pool's threads.
    pub raw_2t: f64,
    /// ECS, the pool's threads.
    pub ecs_2t: f64,
    /// `splitting` through the ECS, one thread, in the same run.
    pub splitting_ecs_1t: f64,
}

impl MethodRow {
    /// The ECS step over `splitting`'s, one thread.
    pub fn per_splitting(&self) -> f64 {
        self.ecs_1t / self.splitting_ecs_1t
    }
}

/// The cost of `integrator` over that of `relative_to` at `bodies`, each against the
/// `splitting` of its own run (`None` when either was not measured).
pub fn ratio(
    rows: &[MethodRow],
    bodies: usize,
    integrator: Integrator,
    relative_to: Integrator,
) -> Option<f64> {
    let of = |i: Integrator| {
        rows.iter()
            .find(|r| r.bodies == bodies && r.integrator == i)
            .map(MethodRow::per_splitting)
    };
    Some(of(integrator)? / of(relative_to)?)
}

/// Times every integrator on the benchmark population at each of `sizes`: one interleaved run
/// per method, of its four engines and `splitting`'s ECS step (five worlds in memory at once,
/// not forty).
pub fn run(sizes: &[usize], effort: &Effort, mut progress: impl FnMut(&str)) -> Vec<MethodRow> {
    let single = Parallelism::SINGLE_THREAD;
    let threaded = Parallelism::default();
    let mut rows = Vec::new();
    for &n in sizes {
        let scene = population::scene(n);
        for &integrator in Integrator::ALL {
            progress(&format!(
                "{n} bodies · {integrator}: ECS and raw, 1 and 2 threads"
            ));
            let mut raw1 = RawLoop::new(&scene, integrator, single);
            let mut ecs1 = Ecs::new(&scene, integrator, single);
            let mut raw2 = RawLoop::new(&scene, integrator, threaded);
            let mut ecs2 = Ecs::new(&scene, integrator, threaded);
            let mut reference = Ecs::new(&scene, Integrator::Splitting, single);
            let mut engines: Vec<&mut dyn Engine> =
                vec![&mut raw1, &mut ecs1, &mut raw2, &mut ecs2, &mut reference];
            let ns = compare(&mut engines, n, effort);
            // The same steps through the same core: the raw loop is the ECS's work, bit for bit.
            crate::check_moved(&raw1, &ecs1, &scene);
            crate::check_moved(&raw2, &ecs2, &scene);
            rows.push(MethodRow {
                integrator,
                bodies: n,
                raw_1t: ns[0],
                ecs_1t: ns[1],
                raw_2t: ns[2],
                ecs_2t: ns[3],
                splitting_ecs_1t: ns[4],
            });
        }
    }
    rows
}
