//! Every integrator's free-body step against the default `splitting`, on the same scene, ECS,
//! one thread, in one interleaved timing (the ratios are what the speed issue bounds).

use serde::Serialize;
use tumble_core::Integrator;
use tumble_ecs::parallel::Parallelism;

use crate::engines::{Ecs, Engine};
use crate::measure::{Effort, compare};
use crate::population;

/// What a method's cost is bounded against: `bound ×` the cost of `relative_to`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
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

/// One size: ns per body-step of every integrator, in [`Integrator::ALL`] order.
#[derive(Debug, Clone, Serialize)]
pub struct MethodRow {
    /// Bodies in the scene.
    pub bodies: usize,
    /// `(integrator, ns per body-step)`, ECS, one thread.
    pub ns: Vec<(Integrator, f64)>,
}

impl MethodRow {
    /// ns per body-step of `integrator` (NaN when it was not measured).
    pub fn ns_of(&self, integrator: Integrator) -> f64 {
        self.ns
            .iter()
            .find(|(i, _)| *i == integrator)
            .map_or(f64::NAN, |&(_, ns)| ns)
    }

    /// The cost of `integrator` over that of `relative_to`.
    pub fn ratio(&self, integrator: Integrator, relative_to: Integrator) -> f64 {
        self.ns_of(integrator) / self.ns_of(relative_to)
    }
}

/// Times every integrator on the benchmark population at each of `sizes`.
pub fn run(sizes: &[usize], effort: &Effort, mut progress: impl FnMut(&str)) -> Vec<MethodRow> {
    sizes
        .iter()
        .map(|&n| {
            progress(&format!("{n} bodies · every integrator"));
            let scene = population::scene(n);
            let single = Parallelism::SINGLE_THREAD;
            let mut worlds: Vec<Ecs> = Integrator::ALL
                .iter()
                .map(|&i| Ecs::new(&scene, i, single))
                .collect();
            let mut engines: Vec<&mut dyn Engine> =
                worlds.iter_mut().map(|w| w as &mut dyn Engine).collect();
            let ns = compare(&mut engines, n, effort);
            MethodRow {
                bodies: n,
                ns: Integrator::ALL.iter().copied().zip(ns).collect(),
            }
        })
        .collect()
}
