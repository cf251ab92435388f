//! The physics schedule, built from what a world needs and nothing more.
//!
//! One step runs these sets in order:
//!
//! 0. [`PhysicsSet::Prepare`] — only for drift–kick–drift integrators (`splitting`, `yoshida4`,
//!    `rk4`): half a drift, so forces are sampled at the midpoint of the step.
//! 1. [`PhysicsSet::Gravity`] — `m g s` into each accumulator; only if a [`Gravity`] resource
//!    exists.
//! 2. [`PhysicsSet::Forces`] — force generators that exist in the world (constant forces,
//!    torques, springs), and any game system placed in this set.
//! 3. [`PhysicsSet::Integrate`] — the selected integrator. It *consumes* each accumulator (reads
//!    and zeroes it in the same pass, so there is no separate "clear forces" pass and a force
//!    added before a step is applied exactly once) and renormalizes each quaternion as part of
//!    the rotation update (so there is no separate "renormalize" pass either).

use std::fmt;

use bevy_ecs::prelude::*;
use bevy_ecs::schedule::{ScheduleBuildSettings, ScheduleLabel};

use crate::components::{ForceAccumulator, Gravity, PhysicsSettings};
use crate::forces::{
    ConstantForce, ConstantTorque, Spring, apply_constant_forces, apply_constant_torques,
    apply_gravity, apply_springs,
};
use crate::systems::{HalfDrifted, begin_step, integrate_with_forces, integrate_without_forces};

/// Label of the schedule that advances physics by one fixed step.
#[derive(ScheduleLabel, Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct PhysicsSchedule;

/// The ordered stages of one physics step.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PhysicsSet {
    /// First half-drift of drift–kick–drift integrators.
    Prepare,
    /// Gravity into the accumulators.
    Gravity,
    /// Force generators and user force systems.
    Forces,
    /// Integration (consumes accumulators, renormalizes rotations).
    Integrate,
}

/// One system of the physics step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Stage {
    /// [`begin_step`].
    BeginStep,
    /// [`apply_gravity`].
    Gravity,
    /// [`apply_constant_forces`].
    ConstantForces,
    /// [`apply_constant_torques`].
    ConstantTorques,
    /// [`apply_springs`].
    Springs,
    /// [`integrate_with_forces`].
    IntegrateWithForces,
    /// [`integrate_without_forces`].
    IntegrateWithoutForces,
}

impl Stage {
    /// The system's name.
    pub fn name(self) -> &'static str {
        match self {
            Stage::BeginStep => "begin_step",
            Stage::Gravity => "apply_gravity",
            Stage::ConstantForces => "apply_constant_forces",
            Stage::ConstantTorques => "apply_constant_torques",
            Stage::Springs => "apply_springs",
            Stage::IntegrateWithForces => "integrate_with_forces",
            Stage::IntegrateWithoutForces => "integrate_without_forces",
        }
    }
}

/// Which systems a world needs, decided from its resources and entities.
///
/// Build it after spawning the force generators; plan again when the world gains a kind of
/// generator or a [`Gravity`] resource it did not have.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PhysicsPlan {
    stages: Vec<Stage>,
}

impl PhysicsPlan {
    /// Plans the step for `world`. Inserts default [`PhysicsSettings`] if the world has none.
    /// Settings outside the integrator's stable region are reported through `tracing` (see
    /// [`check_stability`](crate::stability::check_stability)).
    pub fn for_world(world: &mut World) -> Self {
        let settings = *world.get_resource_or_init::<PhysicsSettings>();
        for warning in crate::stability::check_stability(world) {
            tracing::warn!("{warning}");
        }
        world.init_resource::<HalfDrifted>();
        let mut stages = Vec::with_capacity(7);
        if settings.integrator.samples_forces_at_midpoint() && has_any::<ForceAccumulator>(world) {
            stages.push(Stage::BeginStep);
        }
        if world.contains_resource::<Gravity>() {
            stages.push(Stage::Gravity);
        }
        if has_any::<ConstantForce>(world) {
            stages.push(Stage::ConstantForces);
        }
        if has_any::<ConstantTorque>(world) {
            stages.push(Stage::ConstantTorques);
        }
        if has_any::<Spring>(world) {
            stages.push(Stage::Springs);
        }
        stages.push(Stage::IntegrateWithForces);
        stages.push(Stage::IntegrateWithoutForces);
        Self { stages }
    }

    /// The planned systems, in run order.
    pub fn stages(&self) -> &[Stage] {
        &self.stages
    }

    /// True when `stage` is part of the plan.
    pub fn contains(&self, stage: Stage) -> bool {
        self.stages.contains(&stage)
    }

    /// Builds the [`PhysicsSchedule`] holding exactly the planned systems, strictly ordered (so
    /// forces are summed in the same order every run: bit-identical results).
    pub fn build_schedule(&self) -> Schedule {
        let mut schedule = Schedule::new(PhysicsSchedule);
        // The stages run strictly one after another, so a multi-threaded executor (bevy's
        // default with `multi_threaded`) could only add overhead: ~45 µs per step measured.
        // Parallelism lives inside the integrate systems instead (see `crate::parallel`).
        schedule.set_executor(bevy_ecs::schedule::SingleThreadedExecutor::new());
        // Commands (quarantine of a bad body) are rare: apply them once at the end of the step
        // instead of paying for sync points between the stages.
        schedule.set_build_settings(ScheduleBuildSettings {
            auto_insert_apply_deferred: false,
            ..Default::default()
        });
        schedule.configure_sets(
            (
                PhysicsSet::Gravity,
                PhysicsSet::Forces,
                PhysicsSet::Integrate,
            )
                .chain(),
        );
        let mut previous: Option<Stage> = None;
        for &stage in &self.stages {
            let set = match stage {
                Stage::BeginStep => PhysicsSet::Prepare,
                Stage::Gravity => PhysicsSet::Gravity,
                Stage::IntegrateWithForces | Stage::IntegrateWithoutForces => PhysicsSet::Integrate,
                _ => PhysicsSet::Forces,
            };
            add_stage(&mut schedule, stage, set, previous);
            previous = Some(stage);
        }
        schedule
    }
}

/// A marker set per stage, used to chain the stages in plan order.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
struct StageSet(Stage);

fn add_stage(schedule: &mut Schedule, stage: Stage, set: PhysicsSet, after: Option<Stage>) {
    let config = match stage {
        Stage::BeginStep => begin_step.into_configs(),
        Stage::Gravity => apply_gravity.into_configs(),
        Stage::ConstantForces => apply_constant_forces.into_configs(),
        Stage::ConstantTorques => apply_constant_torques.into_configs(),
        Stage::Springs => apply_springs.into_configs(),
        Stage::IntegrateWithForces => integrate_with_forces.into_configs(),
        Stage::IntegrateWithoutForces => integrate_without_forces.into_configs(),
    };
    let config = config.in_set(set).in_set(StageSet(stage));
    match after {
        Some(prev) => schedule.add_systems(config.after(StageSet(prev))),
        None => schedule.add_systems(config),
    };
}

fn has_any<C: Component>(world: &mut World) -> bool {
    world.query::<&C>().iter(world).next().is_some()
}

impl fmt::Display for PhysicsPlan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = self.stages.iter().map(|s| s.name()).collect();
        write!(f, "{}", names.join(" → "))
    }
}
