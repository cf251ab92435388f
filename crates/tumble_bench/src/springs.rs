//! Spring worlds: what stiffness costs (one chain, explicit against implicit spring steps, at
//! ωΔt from 0.5 to 100) and how many springs a step gets through (chains of chains, with gravity,
//! a force at a body point and damping on every body).

use bevy_ecs::prelude::*;
use bevy_ecs::schedule::Schedule;
use serde::Serialize;
use tumble_core::math::{Real, Vec3};
use tumble_core::{BodyState, Integrator};
use tumble_ecs::components::body_state;
use tumble_ecs::prelude::*;
use tumble_scene::presets::{ChainStart, SpringChain};

use crate::engines::Engine;
use crate::measure::{Effort, compare};

/// The step every spring world runs at (s).
const DT: Real = 1.0 / 60.0;

/// A world of spring chains through tumble's ECS schedule.
pub struct SpringWorld {
    world: World,
    schedule: Schedule,
    bodies: Vec<Entity>,
}

/// How a spring world is loaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Loads {
    /// Springs only.
    None,
    /// Gravity, a constant force at a point of every body, and damping of every body.
    GravityForcesDamping,
}

impl SpringWorld {
    /// `chains` chains of [`SpringChain`] side by side (2 m apart along z), stepped with
    /// `springs`.
    pub fn new(
        chains: usize,
        omega_dt: Real,
        start: ChainStart,
        springs: SpringSolver,
        loads: Loads,
    ) -> Self {
        let mut world = World::new();
        world.insert_resource(
            PhysicsSettings::new(DT, Integrator::default())
                .expect("a valid step")
                .with_springs(springs),
        );
        if loads == Loads::GravityForcesDamping {
            world.insert_resource(Gravity::EARTH_Y_DOWN);
        }
        let mut bodies = Vec::new();
        for c in 0..chains {
            let mut chain = SpringChain::new(omega_dt, DT, start);
            chain.origin = Vec3::new(0.0, 0.0, 2.0 * c as Real);
            let spawned = chain.spawn(&mut world);
            if loads == Loads::GravityForcesDamping {
                for &body in &spawned {
                    world.spawn(ConstantForce {
                        body,
                        force: Vec3::new(0.5, 0.0, 0.0),
                        local_point: Some(Vec3::new(0.0, 0.05, 0.02)),
                    });
                    world.entity_mut(body).insert(Damping {
                        linear: 0.05,
                        angular: 0.05,
                    });
                }
            }
            bodies.extend(spawned);
        }
        let schedule = PhysicsPlan::for_world(&mut world).build_schedule();
        Self {
            world,
            schedule,
            bodies,
        }
    }
}

impl Engine for SpringWorld {
    fn step(&mut self) {
        self.schedule.run(&mut self.world);
        self.world.clear_trackers();
    }

    fn state(&self, i: usize) -> BodyState {
        let e = self.bodies[i];
        match (
            self.world.get::<Transform>(e),
            self.world.get::<Velocity>(e),
            self.world.get::<MassProps>(e),
        ) {
            (Some(t), Some(v), Some(m)) => body_state(t, v, m),
            _ => BodyState {
                position: Vec3::NAN,
                ..BodyState::default()
            },
        }
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
    /// `"explicit"` or `"implicit"`.
    pub mode: String,
    /// Nominal `√(k/μ)Δt`.
    pub omega_dt: f64,
    /// Median ns per spring-step.
    pub ns_per_spring_step: f64,
}

/// Everything the spring part of the bench measured.
#[derive(Debug, Clone, Serialize)]
pub struct SpringResults {
    /// One chain at each stiffness.
    pub stiffness: Vec<StiffnessRow>,
    /// Many chains with loads.
    pub throughput: Vec<ThroughputRow>,
}

impl SpringResults {
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
            let clean = (0..world.bodies.len()).all(|i| world.state(i).is_finite())
                && world
                    .world
                    .query::<&Rejected>()
                    .iter(&world.world)
                    .next()
                    .is_none();
            stiffness.push(StiffnessRow {
                start: start_name.to_owned(),
                springs: mode_name(springs).to_owned(),
                omega_dt: f64::from(omega_dt),
                us_per_step: ns / 1000.0,
                clean,
            });
        }
    }
    let mut throughput = Vec::new();
    let sizes: &[usize] = if quick { &[1_000] } else { &[1_000, 100_000] };
    for &springs in sizes {
        let chains = springs / 10;
        let effort = Effort {
            body_steps: if quick { 10_000 } else { 300_000 },
            min_steps: 2,
            max_steps: 200,
            repetitions: 3,
        };
        for (mode, omega_dt) in [
            (SpringSolver::Explicit, 0.5),
            (SpringSolver::Implicit, 0.5),
            (SpringSolver::Implicit, 10.0),
        ] {
            progress(&format!(
                "{springs} springs, {} at ωΔt {omega_dt}",
                mode_name(mode)
            ));
            let mut world = SpringWorld::new(
                chains,
                omega_dt,
                ChainStart::Relaxed,
                mode,
                Loads::GravityForcesDamping,
            );
            let ns = compare(&mut [&mut world], springs, &effort)[0];
            throughput.push(ThroughputRow {
                springs,
                mode: mode_name(mode).to_owned(),
                omega_dt: f64::from(omega_dt),
                ns_per_spring_step: ns,
            });
        }
    }
    SpringResults {
        stiffness,
        throughput,
    }
}
