//! Spring worlds: what stiffness costs (one chain, explicit against implicit spring steps, at
//! ωΔt from 0.5 to 100) and how many springs a step gets through (chains of chains, with gravity,
//! a force at a body point and damping on every body).

use serde::Serialize;
use std::num::NonZeroU32;
use tumble_core::math::{Real, Vec3, to_f64};
use tumble_core::{BodyState, Integrator};
use tumble_ecs::prelude::{Parallelism, PhysicsSettings, SpringSolver};
use tumble_rapier::presets::{ChainStart, spring_chain};
use tumble_rapier::{ComparisonScene, Load, TumbleScene};

use crate::engines::{Engine, Rapier};
use crate::measure::{Effort, compare};

/// How a spring world is loaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Loads {
    /// Springs only.
    None,
    /// Gravity, a constant force at a point of every body, and damping of every body.
    GravityForcesDamping,
}

/// `chains` spring chains ([`spring_chain`]) loaded as `loads` says: the scene both engines
/// step.
pub fn chains_scene(
    chains: usize,
    omega_dt: Real,
    start: ChainStart,
    loads: Loads,
) -> ComparisonScene {
    let mut scene = spring_chain(omega_dt, start, chains);
    if loads == Loads::GravityForcesDamping {
        scene.gravity = Some(Vec3::new(0.0, -9.81, 0.0));
        for body in &mut scene.bodies {
            body.loads.push(Load::Force {
                force: Vec3::new(0.5, 0.0, 0.0),
                local_point: Some(Vec3::new(0.0, 0.05, 0.02)),
            });
            body.linear_damping = 0.05;
            body.angular_damping = 0.05;
        }
    }
    scene
}

/// `chains` spring chains ([`spring_chain`]) through tumble's ECS schedule, the springs
/// stepped as `springs` says.
pub struct SpringWorld {
    tumble: TumbleScene,
    bodies: usize,
}

impl SpringWorld {
    /// The world, stepped by the default integrator in one stage; see [`Loads`] for what acts
    /// besides the springs.
    pub fn new(
        chains: usize,
        omega_dt: Real,
        start: ChainStart,
        springs: SpringSolver,
        loads: Loads,
    ) -> Self {
        Self::staged(
            chains,
            omega_dt,
            start,
            springs,
            loads,
            Integrator::default(),
            1,
        )
    }

    /// [`new`](Self::new) stepped by `integrator` in `substeps` substeps.
    pub fn staged(
        chains: usize,
        omega_dt: Real,
        start: ChainStart,
        springs: SpringSolver,
        loads: Loads,
        integrator: Integrator,
        substeps: u32,
    ) -> Self {
        let scene = chains_scene(chains, omega_dt, start, loads);
        let mut tumble = TumbleScene::with_springs(&scene, integrator, springs);
        if substeps > 1 {
            let substeps = NonZeroU32::new(substeps).expect("more than one substep");
            tumble
                .world_mut()
                .resource_mut::<PhysicsSettings>()
                .set_substeps(substeps)
                .expect("substeps of a step the precision can take");
        }
        Self {
            tumble,
            bodies: scene.bodies.len(),
        }
    }

    /// The same world stepped under `parallelism`.
    pub fn with_parallelism(mut self, parallelism: Parallelism) -> Self {
        self.tumble.world_mut().insert_resource(parallelism);
        self
    }

    /// The world (for the rollback measurements).
    pub fn world_mut(&mut self) -> &mut bevy_ecs::world::World {
        self.tumble.world_mut()
    }

    /// True when every body is finite and none was quarantined.
    pub fn is_clean(&self) -> bool {
        (0..self.bodies).all(|i| self.tumble.state(i).is_finite() && !self.tumble.is_rejected(i))
    }
}

impl Engine for SpringWorld {
    fn step(&mut self) {
        self.tumble.step();
    }

    fn state(&self, i: usize) -> BodyState {
        self.tumble.state(i)
    }
}

/// One chain at one stiffness and spring step: wall time per step.
#[derive(Debug, Clone, Serialize)]
pub struct StiffnessRow {
    /// `"stretched"` or `"relaxed"` (see [`ChainStart`]).
    pub start: String,
    /// `"explicit"` or `"implicit"`.
    pub springs: String,
    /// Nominal `√(k/μ)Δt`.
    pub omega_dt: f64,
    /// Median µs per step of the whole ten-body chain.
    pub us_per_step: f64,
    /// Whether every body stayed finite and unquarantined.
    pub clean: bool,
}

/// Many chains: ns per spring-step.
#[derive(Debug, Clone, Serialize)]
pub struct ThroughputRow {
    /// Number of springs (ten per chain).
    pub springs: usize,
    /// `"explicit"` or `"implicit"` (tumble), or `"rapier SpringJoint"` (the same loaded
    /// chains in rapier, each spring its `SpringJoint`).
    pub mode: String,
    /// Nominal `√(k/μ)Δt`.
    pub omega_dt: f64,
    /// Threads that stepped the world.
    pub threads: usize,
    /// Median ns per spring-step (chains of ten: one spring per body, so also per body-step).
    pub ns_per_spring_step: f64,
}

/// The name of the rapier rows of the spring throughput.
pub const RAPIER_JOINT: &str = "rapier SpringJoint";

/// Steps of several stages: a loaded spring world stepped with substeps or the fourth-order
/// composition, against the same world in one stage.
#[derive(Debug, Clone, Serialize)]
pub struct StagesRow {
    /// Bodies (ten per chain).
    pub bodies: usize,
    /// The integrator.
    pub integrator: String,
    /// Substeps per step.
    pub substeps: u32,
    /// Stages per step (substeps × the integrator's composition).
    pub stages: usize,
    /// Median ns per body-step.
    pub ns_per_body_step: f64,
    /// Relative to the same world with `splitting` in one stage.
    pub ratio: f64,
}

/// Everything the spring part of the bench measured.
#[derive(Debug, Clone, Serialize)]
pub struct SpringResults {
    /// One chain at each stiffness.
    pub stiffness: Vec<StiffnessRow>,
    /// Steps per timing of the loaded chains, the same at every size (after one warm-up step).
    pub window_steps: usize,
    /// Timings of each loaded-chain row (the median is kept).
    pub repetitions: usize,
    /// Many chains with loads.
    pub throughput: Vec<ThroughputRow>,
    /// Steps of several stages on the loaded chains.
    pub stages: Vec<StagesRow>,
}

impl SpringResults {
    /// ns per spring-step of the loaded chains with `springs` springs stepped as `mode` (a
    /// `ThroughputRow::mode`) on one thread.
    pub fn throughput_one_thread(&self, springs: usize, mode: &str) -> Option<f64> {
        self.throughput
            .iter()
            .find(|r| r.springs == springs && r.mode == mode && r.threads == 1)
            .map(|r| r.ns_per_spring_step)
    }

    /// µs per step of the explicit step on the relaxed chain at ωΔt = 0.5, the reference of
    /// the cost targets.
    pub fn explicit_reference(&self) -> Option<f64> {
        self.stiffness
            .iter()
            .find(|r| r.springs == "explicit" && r.start == "relaxed" && r.omega_dt == 0.5)
            .map(|r| r.us_per_step)
    }
}

fn mode_name(springs: SpringSolver) -> &'static str {
    match springs {
        SpringSolver::Explicit => "explicit",
        _ => "implicit",
    }
}

/// The ωΔt the stiffness rows sweep.
pub const OMEGA_DTS: [Real; 5] = [0.5, 2.0, 10.0, 30.0, 100.0];

/// Runs the spring measurements; `progress` receives one line per measurement.
pub fn run(quick: bool, mut progress: impl FnMut(&str)) -> SpringResults {
    let stiffness = stiffness_rows(quick, &mut progress);
    let sizes: &[usize] = if quick { &[1_000] } else { &[1_000, 100_000] };
    let effort = same_window(
        sizes,
        Effort {
            body_steps: if quick { 10_000 } else { 300_000 },
            min_steps: 2,
            max_steps: 200,
            // See the free-body rows' effort: the median of five survives two spoiled timings.
            repetitions: if quick { 3 } else { 5 },
        },
    );
    SpringResults {
        stiffness,
        window_steps: effort.min_steps,
        repetitions: effort.repetitions,
        throughput: throughput_rows(sizes, &effort, &mut progress),
        stages: stage_rows(sizes, &effort, &mut progress),
    }
}

/// `effort` with the steps per timing of the largest of `sizes` for every size: a loaded
/// chain's cost follows its motion (bodies its loads spin up take the exact free flow, at
/// several times the split's cost), so every size is timed over the same steps of the same
/// motion, from the scene's start, and the rows differ only in how many chains step.
fn same_window(sizes: &[usize], effort: Effort) -> Effort {
    let largest = sizes.iter().copied().max().unwrap_or(1);
    let window = effort.steps(largest);
    Effort {
        min_steps: window,
        max_steps: window,
        ..effort
    }
}

/// One chain, relaxed and stretched, explicit at ωΔt 0.5 and implicit at every ωΔt of
/// [`OMEGA_DTS`]: microseconds per step.
fn stiffness_rows(quick: bool, progress: &mut impl FnMut(&str)) -> Vec<StiffnessRow> {
    let chain_effort = Effort {
        body_steps: if quick { 30 } else { 600 },
        min_steps: 1,
        max_steps: 600,
        repetitions: 3,
    };
    let mut stiffness = Vec::new();
    for start in [ChainStart::Relaxed, ChainStart::Stretched] {
        let start_name = match start {
            ChainStart::Relaxed => "relaxed",
            ChainStart::Stretched => "stretched",
        };
        let settings = std::iter::once((SpringSolver::Explicit, 0.5))
            .chain(OMEGA_DTS.iter().map(|&w| (SpringSolver::Implicit, w)));
        for (springs, omega_dt) in settings {
            progress(&format!(
                "spring chain, {start_name}, {} at ωΔt {omega_dt}",
                mode_name(springs)
            ));
            let mut world = SpringWorld::new(1, omega_dt, start, springs, Loads::None);
            let ns = compare(&mut [&mut world], 1, &chain_effort)[0];
            let clean = world.is_clean();
            stiffness.push(StiffnessRow {
                start: start_name.to_owned(),
                springs: mode_name(springs).to_owned(),
                omega_dt: to_f64(omega_dt),
                us_per_step: ns / 1000.0,
                clean,
            });
        }
    }
    stiffness
}

/// Loaded chains of `sizes` springs: tumble explicit (one thread and the pool), implicit at
/// ωΔt 0.5 and 10, and rapier's `SpringJoint`, in ns per spring-step.
fn throughput_rows(
    sizes: &[usize],
    effort: &Effort,
    progress: &mut impl FnMut(&str),
) -> Vec<ThroughputRow> {
    let mut throughput = Vec::new();
    for &springs in sizes {
        let chains = springs / 10;
        // One thread, as the free-body rows they are compared with; the explicit step again on
        // every pool thread, to show what the threaded path gains with springs.
        let threaded = Parallelism::default();
        let runs = [
            (SpringSolver::Explicit, 0.5, Parallelism::SINGLE_THREAD),
            (SpringSolver::Explicit, 0.5, threaded),
            (SpringSolver::Implicit, 0.5, Parallelism::SINGLE_THREAD),
            (SpringSolver::Implicit, 10.0, Parallelism::SINGLE_THREAD),
        ];
        for (mode, omega_dt, parallelism) in runs {
            let threads = parallelism.threads_for(springs);
            if threads == 1 && parallelism != Parallelism::SINGLE_THREAD {
                // Too small a world for the pool: the one-thread row already says it all.
                continue;
            }
            progress(&format!(
                "{springs} springs, {} at ωΔt {omega_dt}, {threads} thread(s)",
                mode_name(mode)
            ));
            let mut world = SpringWorld::new(
                chains,
                omega_dt,
                ChainStart::Relaxed,
                mode,
                Loads::GravityForcesDamping,
            )
            .with_parallelism(parallelism);
            let ns = compare(&mut [&mut world], springs, effort)[0];
            throughput.push(ThroughputRow {
                springs,
                mode: mode_name(mode).to_owned(),
                omega_dt: to_f64(omega_dt),
                threads,
                ns_per_spring_step: ns,
            });
        }
        progress(&format!(
            "{springs} springs in rapier, SpringJoint at ωΔt 0.5"
        ));
        let scene = chains_scene(
            chains,
            0.5,
            ChainStart::Relaxed,
            Loads::GravityForcesDamping,
        );
        let mut rapier = Rapier::new(&scene);
        let ns = compare(&mut [&mut rapier], springs, effort)[0];
        throughput.push(ThroughputRow {
            springs,
            mode: RAPIER_JOINT.to_owned(),
            omega_dt: 0.5,
            threads: 1,
            ns_per_spring_step: ns,
        });
    }
    throughput
}

/// Loaded chains stepped in several stages (substeps, `yoshida4`), against one stage.
fn stage_rows(sizes: &[usize], effort: &Effort, progress: &mut impl FnMut(&str)) -> Vec<StagesRow> {
    let mut stages = Vec::new();
    for &springs in sizes {
        let chains = springs / 10;
        // The first row of each size: `splitting` in one stage.
        let mut one_stage = None;
        for (integrator, substeps) in [
            (Integrator::Splitting, 1),
            (Integrator::Splitting, 4),
            (Integrator::Yoshida4, 1),
            (Integrator::Yoshida4, 2),
        ] {
            progress(&format!(
                "{springs} springs with forces, {integrator} × {substeps} substeps"
            ));
            let mut world = SpringWorld::staged(
                chains,
                0.5,
                ChainStart::Relaxed,
                SpringSolver::Explicit,
                Loads::GravityForcesDamping,
                integrator,
                substeps,
            );
            let ns = compare(&mut [&mut world], chains * 10, effort)[0];
            let base = *one_stage.get_or_insert(ns);
            stages.push(StagesRow {
                bodies: chains * 10,
                integrator: integrator.name().to_owned(),
                substeps,
                stages: substeps as usize * integrator.composition().len(),
                ns_per_body_step: ns,
                ratio: ns / base,
            });
        }
    }
    stages
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every size gets the largest size's steps per timing, so that the rows time the same
    /// stretch of the motion.
    #[test]
    fn every_size_is_timed_over_the_largest_sizes_window() {
        let effort = same_window(
            &[1_000, 100_000],
            Effort {
                body_steps: 300_000,
                min_steps: 2,
                max_steps: 200,
                repetitions: 5,
            },
        );
        assert_eq!(effort.steps(1_000), 3);
        assert_eq!(effort.steps(100_000), 3);
        assert_eq!(effort.steps(10), 3);
        assert_eq!(effort.repetitions, 5);
    }
}
