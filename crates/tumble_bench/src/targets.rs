//! The speed targets the bench checks, as data: each a measured quantity, a relation and a
//! bound ([`TARGETS`]), evaluated on a run's results by [`evaluate`]. Only the targets of the
//! open speed issue are here; what else the bench measures is in its tables.

use tumble_core::Integrator;

use crate::methods::{self, METHOD_BOUNDS};
use crate::{BenchResults, Target};

/// Which way a bound holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Relation {
    /// The measured value must not exceed the bound.
    AtMost,
    /// The measured value must reach the bound.
    AtLeast,
}

impl Relation {
    /// `"<="` or `">="`.
    pub fn symbol(self) -> &'static str {
        match self {
            Relation::AtMost => "<=",
            Relation::AtLeast => ">=",
        }
    }

    /// True when `value` meets `bound`.
    pub fn holds(self, value: f64, bound: f64) -> bool {
        match self {
            Relation::AtMost => value <= bound,
            Relation::AtLeast => value >= bound,
        }
    }
}

/// A quantity the bench measures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Measure {
    /// Loaded explicit spring chains of `springs` springs, one thread: ns per body-step over a
    /// free body's (the default integrator through the ECS, one thread, same `N`).
    SpringsOverFree {
        /// Springs (and bodies) in the world.
        springs: usize,
    },
    /// rapier's `SpringJoint` chains over tumble's explicit ones, per body-step, one thread.
    RapierOverSprings {
        /// Springs (and bodies) in the world.
        springs: usize,
    },
    /// Loaded explicit spring chains: one thread's ns per body-step over the pool's.
    SpringsThreadSpeedup {
        /// Springs (and bodies) in the world.
        springs: usize,
    },
    /// The ten-body chain: the implicit step from `start` at `omega_dt` over the explicit step
    /// of the relaxed chain at ωΔt 0.5, per step.
    ImplicitOverExplicit {
        /// `"relaxed"` or `"stretched"`.
        start: &'static str,
        /// Nominal `√(k/μ)Δt`.
        omega_dt: f64,
    },
    /// Every bound of [`METHOD_BOUNDS`] at `bodies` free bodies (one target each).
    MethodBounds {
        /// Free bodies in the world.
        bodies: usize,
    },
    /// Every integrator's ECS step over its raw loop, the worst over the sizes measured from
    /// 1e3 bodies up, on `threads` (1, or the pool's); one target per integrator.
    EcsOverRaw {
        /// 1 for one thread, 2 for the pool.
        threads: usize,
    },
    /// The default integrator at 1e5 free bodies: one thread over two, divided by the most two
    /// threads gain on this machine (the two-copy ceiling).
    ThreadsOverCeiling,
    /// The whole run's wall-clock time (s), of a full run (`quick: false`) or of `--quick`.
    Seconds {
        /// Which kind of run the bound is for.
        quick: bool,
    },
}

/// A target: `measure relation bound`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TargetSpec {
    /// What is measured.
    pub measure: Measure,
    /// Which way the bound holds.
    pub relation: Relation,
    /// The bound.
    pub bound: f64,
}

const fn at_most(measure: Measure, bound: f64) -> TargetSpec {
    TargetSpec {
        measure,
        relation: Relation::AtMost,
        bound,
    }
}

const fn at_least(measure: Measure, bound: f64) -> TargetSpec {
    TargetSpec {
        measure,
        relation: Relation::AtLeast,
        bound,
    }
}

/// The speed issue's targets, in its order: springs near free bodies and far ahead of rapier,
/// threads that help with springs; the implicit step affordable where chains move; every
/// integrator batched within its bound; a thin ECS layer; a bench that fits a working day.
pub const TARGETS: &[TargetSpec] = {
    use Measure::*;
    &[
        at_most(SpringsOverFree { springs: 1_000 }, 2.5),
        at_most(SpringsOverFree { springs: 100_000 }, 2.5),
        at_least(RapierOverSprings { springs: 1_000 }, 10.0),
        at_least(RapierOverSprings { springs: 100_000 }, 10.0),
        at_least(SpringsThreadSpeedup { springs: 100_000 }, 1.6),
        at_most(
            ImplicitOverExplicit {
                start: "relaxed",
                omega_dt: 0.5,
            },
            4.0,
        ),
        at_most(
            ImplicitOverExplicit {
                start: "relaxed",
                omega_dt: 10.0,
            },
            4.0,
        ),
        at_most(
            ImplicitOverExplicit {
                start: "stretched",
                omega_dt: 100.0,
            },
            20.0,
        ),
        // Each entry's bound is its own, from METHOD_BOUNDS.
        at_most(MethodBounds { bodies: 1_000 }, f64::NAN),
        at_most(MethodBounds { bodies: 100_000 }, f64::NAN),
        at_most(EcsOverRaw { threads: 1 }, 1.15),
        at_most(EcsOverRaw { threads: 2 }, 1.15),
        at_least(ThreadsOverCeiling, 0.9),
        at_most(Seconds { quick: false }, 180.0),
        at_most(Seconds { quick: true }, 20.0),
    ]
};

/// Every target of [`TARGETS`] this run measured, with its value and verdict (a
/// [`MethodBounds`](Measure::MethodBounds) or [`EcsOverRaw`](Measure::EcsOverRaw) entry gives
/// one target per bound or integrator).
pub fn evaluate(results: &BenchResults) -> Vec<Target> {
    let mut out = Vec::new();
    for spec in TARGETS {
        for (name, value, bound) in measured(results, spec.measure, spec.bound) {
            out.push(Target {
                name,
                value,
                bound,
                relation: spec.relation.symbol().to_owned(),
                met: spec.relation.holds(value, bound),
            });
        }
    }
    out
}

/// `(name, value, bound)` of each target `measure` stands for in `results` (none where the run
/// did not measure it).
fn measured(results: &BenchResults, measure: Measure, bound: f64) -> Vec<(String, f64, f64)> {
    let springs = &results.springs;
    let free_ecs = |n: usize| {
        results
            .rows
            .iter()
            .find(|r| r.integrator == Integrator::default().name() && r.bodies == n)
            .map(|r| (r.ecs_1t, r.ecs_2t))
    };
    let explicit = |n: usize, threads: usize| {
        springs
            .throughput
            .iter()
            .find(|r| r.springs == n && r.mode == "explicit" && (r.threads == 1) == (threads == 1))
            .map(|r| r.ns_per_spring_step)
    };
    let one = |name: String, value: Option<f64>| -> Vec<(String, f64, f64)> {
        value.map(|v| (name, v, bound)).into_iter().collect()
    };
    match measure {
        Measure::SpringsOverFree { springs: n } => one(
            format!(
                "loaded explicit spring chains, {n} springs, 1 thread: per body-step / free body"
            ),
            over(explicit(n, 1), free_ecs(n).map(|(one, _)| one)),
        ),
        Measure::RapierOverSprings { springs: n } => one(
            format!("loaded spring chains, {n} springs: rapier SpringJoint / tumble explicit"),
            over(
                springs.throughput_one_thread(n, crate::springs::RAPIER_JOINT),
                explicit(n, 1),
            ),
        ),
        Measure::SpringsThreadSpeedup { springs: n } => one(
            format!("loaded explicit spring chains, {n} springs: 1 thread / 2 threads"),
            over(explicit(n, 1), explicit(n, 2)),
        ),
        Measure::ImplicitOverExplicit { start, omega_dt } => one(
            format!(
                "spring chain: implicit, {start}, at ωΔt {omega_dt} / explicit, relaxed, at 0.5"
            ),
            over(
                springs
                    .stiffness
                    .iter()
                    .find(|r| r.springs == "implicit" && r.start == start && r.omega_dt == omega_dt)
                    .map(|r| r.us_per_step),
                springs.explicit_reference(),
            ),
        ),
        Measure::MethodBounds { bodies } => METHOD_BOUNDS
            .iter()
            .filter_map(|b| {
                let value = methods::ratio(&results.methods, bodies, b.integrator, b.relative_to)?;
                Some((
                    format!(
                        "{} / {}, ECS 1 thread, {bodies} bodies",
                        b.integrator, b.relative_to
                    ),
                    value,
                    b.bound,
                ))
            })
            .collect(),
        Measure::EcsOverRaw { threads } => Integrator::ALL
            .iter()
            .filter_map(|&integrator| {
                let worst = results
                    .methods
                    .iter()
                    .filter(|r| r.integrator == integrator && r.bodies >= 1_000)
                    .map(|r| match threads {
                        1 => r.ecs_1t / r.raw_1t,
                        _ => r.ecs_2t / r.raw_2t,
                    })
                    .reduce(f64::max)?;
                Some((
                    format!("{integrator}: ECS / raw, {threads} thread(s), worst N ≥ 1e3"),
                    worst,
                    bound,
                ))
            })
            .collect(),
        Measure::ThreadsOverCeiling => one(
            "default integrator, 1e5 free bodies: 2 threads / 1 thread over the two-copy ceiling"
                .to_owned(),
            free_ecs(100_000).map(|(one, two)| one / two / results.two_copy_ceiling),
        ),
        Measure::Seconds { quick } => one(
            format!(
                "the whole {} run, seconds",
                if quick { "--quick" } else { "full" }
            ),
            (results.quick == quick).then_some(results.seconds),
        ),
    }
}

/// `a / b` where both were measured.
fn over(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    Some(a? / b?)
}
