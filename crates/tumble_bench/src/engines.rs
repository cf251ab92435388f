//! The three things measured on the same bodies: tumble through its ECS schedule, a raw loop
//! over plain arrays calling the same `tumble_core` entry point (the practical limit), and
//! rapier 0.36.

use std::sync::Mutex;
use tumble_core::integrate::{ExactSwitch, FreeFlow};
use tumble_core::math::{Real, Vec3};

use tumble_core::{BodyState, Integrator, MassProperties, Wrench};
use tumble_ecs::parallel::{Parallelism, scope};
use tumble_rapier::{ComparisonScene, RapierScene, TumbleScene};

/// Something that advances all its bodies by one step.
pub trait Engine {
    /// One step of every body.
    fn step(&mut self);
    /// The state of body `i` (to check that the engines really moved the bodies).
    fn state(&self, i: usize) -> BodyState;
}

/// tumble's math without the ECS: structure of arrays, the batched core step
/// (`Integrator::try_step_many`), split over threads exactly as the ECS splits a table.
pub struct RawLoop {
    states: Vec<BodyState>,
    masses: Vec<MassProperties>,
    wrenches: Vec<Wrench>,
    integrator: Integrator,
    dt: Real,
    parallelism: Parallelism,
}

impl RawLoop {
    /// The bodies of `scene` in plain arrays (gravity as a constant force per body).
    pub fn new(scene: &ComparisonScene, integrator: Integrator, parallelism: Parallelism) -> Self {
        let g = scene.gravity.unwrap_or(Vec3::ZERO);
        // Zeroed and written field by field, as the ECS does (`BodyState::copy_fields_from`
        // says why; stale padding made this loop 2–4× slower in some builds).
        let mut states = vec![BodyState::ZEROED; scene.bodies.len()];
        for (state, body) in states.iter_mut().zip(&scene.bodies) {
            state.copy_fields_from(&body.state);
        }
        Self {
            states,
            masses: scene.bodies.iter().map(|b| b.mass).collect(),
            wrenches: scene
                .bodies
                .iter()
                .map(|b| Wrench {
                    force: (b.mass.mass() * b.gravity_scale) * g,
                    torque: Vec3::ZERO,
                })
                .collect(),
            integrator,
            dt: scene.dt,
            parallelism,
        }
    }
}

impl Engine for RawLoop {
    fn step(&mut self) {
        let (integrator, dt) = (self.integrator, self.dt);
        // The free-flow switch a world's step makes by default (`FreeFlow::Auto`), so that the
        // raw loop does the ECS's work and ECS/raw stays the cost of the layer alone.
        let switch = ExactSwitch::new(integrator, FreeFlow::Auto, dt);
        let threads = self.parallelism.threads_for(self.states.len());
        if threads <= 1 {
            let diverged = integrator.try_step_many_switched(
                &mut self.states,
                &self.masses,
                &self.wrenches,
                dt,
                switch,
            );
            assert!(diverged.is_empty(), "benchmark bodies stay finite");
            return;
        }
        let per = self.states.len().div_ceil(threads);
        let diverged = Mutex::new(0usize);
        scope(|spawn| {
            let parts = self
                .states
                .chunks_mut(per)
                .zip(self.masses.chunks(per))
                .zip(self.wrenches.chunks(per));
            for ((states, masses), wrenches) in parts {
                let diverged = &diverged;
                spawn(Box::new(move || {
                    let bad = integrator
                        .try_step_many_switched(states, masses, wrenches, dt, switch)
                        .len();
                    *diverged.lock().unwrap_or_else(|p| p.into_inner()) += bad;
                }));
            }
        });
        assert_eq!(*diverged.lock().unwrap_or_else(|p| p.into_inner()), 0);
    }

    fn state(&self, i: usize) -> BodyState {
        self.states[i]
    }
}

/// tumble through the planned ECS schedule, as a game runs it.
pub struct Ecs(TumbleScene);

impl Ecs {
    /// The bodies of `scene` as entities, with the given threading policy.
    pub fn new(scene: &ComparisonScene, integrator: Integrator, parallelism: Parallelism) -> Self {
        let mut tumble = TumbleScene::new(scene, integrator);
        tumble.world_mut().insert_resource(parallelism);
        Self(tumble)
    }
}

impl Engine for Ecs {
    fn step(&mut self) {
        self.0.step();
    }

    fn state(&self, i: usize) -> BodyState {
        self.0.state(i)
    }
}

/// The world of an [`Ecs`] whose "step" is only the runner's check of the world before a step
/// ([`PhysicsRunner::prepare`](tumble_ecs::schedule::PhysicsRunner::prepare)): what the check
/// costs on its own.
pub struct RunnerCheck(Ecs);

impl RunnerCheck {
    /// The bodies of `scene` as entities, one thread.
    pub fn new(scene: &ComparisonScene, integrator: Integrator) -> Self {
        Self(Ecs::new(scene, integrator, Parallelism::SINGLE_THREAD))
    }
}

impl Engine for RunnerCheck {
    fn step(&mut self) {
        self.0.0.prepare_step();
    }

    fn state(&self, i: usize) -> BodyState {
        self.0.state(i)
    }
}

/// rapier 0.36 with its default solver settings (4 iterations), gyroscopic term on, sleeping off.
pub struct Rapier(RapierScene);

impl Rapier {
    /// rapier's default number of solver iterations.
    pub const SOLVER_ITERATIONS: usize = 4;

    /// The bodies of `scene` in a rapier world.
    pub fn new(scene: &ComparisonScene) -> Self {
        Self(RapierScene::new(scene, true, Self::SOLVER_ITERATIONS))
    }
}

impl Engine for Rapier {
    fn step(&mut self) {
        self.0.step();
    }

    fn state(&self, i: usize) -> BodyState {
        self.0.state(i)
    }
}
