//! `PhysicsPlan`: the systems of one stage, built from what the world needs.

use std::fmt;

use arrayvec::ArrayVec;
use bevy_ecs::prelude::*;
use bevy_ecs::schedule::{ScheduleBuildSettings, ScheduleLabel};

use bevy_ecs::component::ComponentId;
use bevy_ecs::world::WorldId;

use crate::audit::{
    EnergyAudit, EnergyLedger, audit_energy, audit_energy_start, audit_external_loads,
};
use crate::components::{ConstantForce, ConstantLocalForce, ConstantTorque, Spring};
use crate::components::{ForceAccumulator, Gravity, Kinematic, PhysicsSettings, RigidBody, Static};
use crate::components::{ImplicitBody, ImplicitSpring};
use crate::forces::{apply_constant_forces, apply_constant_torques, apply_gravity, apply_springs};
use crate::integrate::{
    HalfDrifted, StageStarts, begin_stage, check_fixed_bodies, discard_fixed_body_forces,
    integrate_with_forces, integrate_without_forces,
};
use crate::integrate::{StageCursor, hold_game_loads, next_stage};
use crate::springs::solve_implicit_springs;
use crate::springs::{damp_springs_end, damp_springs_start, is_damped};

/// Label of the schedule a plan builds: one run is one stage of a step. Private, so that no
/// public label invites a game system into a schedule that only the plan's owner runs: game
/// force systems go in [`ForceSystems`](crate::schedule::ForceSystems) (every stage) or, with the
/// plugin, before `TumbleStep` (held over the step).
#[derive(ScheduleLabel, Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub(crate) struct PlannedStage;

/// The ordered phases of one run of the physics schedule (one stage of a step).
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PhysicsSet {
    /// Start of the step: the audit's start, the first half of the damping flows, the first
    /// half-drift of drift–kick–drift integrators.
    Prepare,
    /// Gravity into the accumulators.
    Gravity,
    /// Force generators and user force systems.
    Forces,
    /// Integration (consumes accumulators, renormalizes rotations), the second half of the
    /// damping flows, the audit's balance. In audited worlds it opens with the audit's reading
    /// of the loads and then the springs (see [`crate::audit`]).
    Integrate,
}

/// Declares [`PhysicsSystem`] from one list, in the order a step runs the systems, each variant with its
/// doc and its system's name: the order ([`PhysicsSystem::ALL`]) and the names ([`PhysicsSystem::name`]) are
/// made from the same list and cannot drift apart.
macro_rules! physics_systems {
    ($($(#[doc = $doc:expr])* $variant:ident => $name:literal,)*) => {
        /// One system of the physics step.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum PhysicsSystem {
            $($(#[doc = $doc])* $variant,)*
        }

        impl PhysicsSystem {
            /// Every system, in the order a step runs them.
            pub const ALL: [PhysicsSystem; [$($name),*].len()] = [$(PhysicsSystem::$variant),*];

            /// How many systems there are (a plan holds each at most once).
            pub const COUNT: usize = Self::ALL.len();

            /// The system's name.
            pub fn name(self) -> &'static str {
                match self {
                    $(PhysicsSystem::$variant => $name,)*
                }
            }
        }
    };
}

physics_systems! {
    /// [`hold_game_loads`].
    HoldGameLoads => "hold_game_loads",
    /// [`audit_energy_start`].
    AuditEnergyStart => "audit_energy_start",
    /// [`check_fixed_bodies`].
    CheckFixedBodies => "check_fixed_bodies",
    /// [`damp_springs_start`]: the spring dampers' flow over the first half step.
    DampSpringsStart => "damp_springs_start",
    /// [`begin_stage`].
    BeginStage => "begin_stage",
    /// [`apply_gravity`].
    Gravity => "apply_gravity",
    /// [`apply_constant_forces`].
    ConstantForces => "apply_constant_forces",
    /// [`apply_constant_torques`].
    ConstantTorques => "apply_constant_torques",
    /// [`audit_external_loads`].
    AuditExternalLoads => "audit_external_loads",
    /// [`apply_springs`].
    Springs => "apply_springs",
    /// [`solve_implicit_springs`].
    SolveImplicitSprings => "solve_implicit_springs",
    /// [`integrate_with_forces`].
    IntegrateWithForces => "integrate_with_forces",
    /// [`integrate_without_forces`].
    IntegrateWithoutForces => "integrate_without_forces",
    /// [`discard_fixed_body_forces`].
    DiscardFixedBodyForces => "discard_fixed_body_forces",
    /// [`damp_springs_end`]: the spring dampers' flow over the second half step, in reverse
    /// order.
    DampSpringsEnd => "damp_springs_end",
    /// [`audit_energy`].
    AuditEnergy => "audit_energy",
    /// [`next_stage`].
    NextStage => "next_stage",
}

/// Which systems a world needs, decided from its resources and entities.
///
/// - the energy audit's three systems only where [`EnergyAudit::applies`] (by default: worlds
///   with springs), `audit_external_loads` only with dynamic bodies that have accumulators;
/// - `hold_game_loads` and `next_stage` only when a step has several stages (substeps, or
///   `yoshida4`; see [`crate::integrate`]), the former only with dynamic bodies that have
///   accumulators;
/// - `begin_stage` only for a drift–kick–drift integrator and dynamic bodies with accumulators;
/// - `apply_gravity` only with a [`Gravity`] resource and dynamic bodies with accumulators
///   (bodies without one get gravity inside `integrate_without_forces`, at no extra pass);
/// - one system per kind of force generator that exists;
/// - `solve_implicit_springs` only if a spring group is stepped implicitly (see
///   [`crate::springs`]);
/// - `damp_springs_start` / `damp_springs_end` only if a [`Spring`] has `damping > 0` (one pass
///   over the springs' damping coefficients, stopping at the first damped one);
/// - `integrate_with_forces` / `integrate_without_forces` only if there are dynamic bodies with
///   / without an accumulator ([`Static`] and [`Kinematic`] bodies are never integrated);
/// - `discard_fixed_body_forces` only if a static or kinematic body has an accumulator.
///
/// [`PhysicsPlan::of`] is cheap (one pass over the archetypes, and over the springs when there
/// are any; the systems live inline), so [`PhysicsRunner`](crate::schedule::PhysicsRunner)
/// re-plans every step and rebuilds the schedule only when the plan changes; the runner keeps
/// its spring query between steps, so its re-planning does not allocate.
///
/// A plan describes a step; only a [`PhysicsRunner`](crate::schedule::PhysicsRunner) runs one,
/// after checking it against the world, so no public path steps a world by a stale plan.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PhysicsPlan {
    systems: ArrayVec<PhysicsSystem, { PhysicsSystem::COUNT }>,
    runs_per_step: usize,
}

/// What the world holds, as far as planning cares.
#[derive(Debug, Default, Clone, Copy)]
struct Contents {
    dynamic_with_accumulator: bool,
    dynamic_without_accumulator: bool,
    fixed_with_accumulator: bool,
    /// Static or kinematic bodies.
    fixed_bodies: bool,
    constant_forces: bool,
    constant_torques: bool,
    springs: bool,
    /// Springs the explicit path applies (not marked implicit).
    explicit_springs: bool,
    implicit_bodies: bool,
    damped_springs: bool,
}

/// The query [`PhysicsPlan`] reads the springs' damping coefficients through, with the world it
/// was built for.
pub(crate) type SpringQuery = (WorldId, QueryState<&'static Spring>);

impl Contents {
    /// One pass over the non-empty archetypes.
    fn of(world: &World) -> Self {
        let id = |c: Option<ComponentId>| c;
        let body = id(world.component_id::<RigidBody>());
        let acc = id(world.component_id::<ForceAccumulator>());
        let fixed = [
            world.component_id::<Static>(),
            world.component_id::<Kinematic>(),
        ];
        let force = world.component_id::<ConstantForce>();
        let local_force = world.component_id::<ConstantLocalForce>();
        let torque = world.component_id::<ConstantTorque>();
        let spring = world.component_id::<Spring>();
        let implicit = world.component_id::<ImplicitBody>();
        let implicit_spring = world.component_id::<ImplicitSpring>();
        let mut out = Contents::default();
        for archetype in world.archetypes().iter().filter(|a| !a.is_empty()) {
            let has = |c: Option<ComponentId>| c.is_some_and(|c| archetype.contains(c));
            if has(body) {
                let is_fixed = fixed.iter().any(|&c| has(c));
                out.fixed_bodies |= is_fixed;
                out.implicit_bodies |= !is_fixed && has(implicit);
                // Implicit bodies take their whole step in `solve_implicit_springs`.
                match (is_fixed || has(implicit), has(acc)) {
                    (false, true) => out.dynamic_with_accumulator = true,
                    (false, false) => out.dynamic_without_accumulator = true,
                    (true, true) if is_fixed => out.fixed_with_accumulator = true,
                    (true, _) => {}
                }
            }
            out.constant_forces |= has(force) || has(local_force);
            out.constant_torques |= has(torque);
            out.springs |= has(spring);
            out.explicit_springs |= has(spring) && !has(implicit_spring);
        }
        out
    }
}

impl PhysicsPlan {
    /// [`of`](Self::of) with the springs read through `springs`, a query kept by the caller
    /// (so that planning every step does not build a query every step). A query built for
    /// another world is replaced.
    pub(crate) fn of_with(world: &World, springs: &mut Option<SpringQuery>) -> Self {
        let mut c = Contents::of(world);
        if c.springs {
            if springs.as_ref().is_none_or(|(id, _)| *id != world.id()) {
                *springs = world.try_query::<&Spring>().map(|q| (world.id(), q));
            }
            // Stops at the first damped spring.
            c.damped_springs = springs
                .as_mut()
                .is_some_and(|(_, q)| q.iter(world).any(is_damped));
        }
        Self::from_contents(world, c)
    }

    /// Plans the step for `world`: [`of`](Self::of) after inserting default
    /// [`PhysicsSettings`] (if missing) and the bookkeeping resource, classifying the springs
    /// (explicit or implicit, see [`crate::springs::classify_springs`]), with settings outside the
    /// integrator's stable region reported through `tracing` (see
    /// [`check_stability`](crate::stability::check_stability)).
    pub fn for_world(world: &mut World) -> Self {
        world.get_resource_or_init::<PhysicsSettings>();
        crate::components::assume_missing_masses(world);
        crate::springs::classify_springs(world);
        for warning in crate::stability::check_stability(world) {
            tracing::warn!("{warning}");
        }
        world.init_resource::<HalfDrifted>();
        world.init_resource::<StageStarts>();
        // Game code reads the record from the first step on, errors or not.
        world.init_resource::<crate::components::PhysicsErrors>();
        world.init_resource::<EnergyLedger>();
        // A new plan starts at the first stage of a step.
        world.insert_resource(StageCursor::default());
        let plan = Self::of(world);
        // The step's refusals are kept for the audit's verdict, and only while it is planned.
        if plan.contains(PhysicsSystem::AuditEnergy) {
            world.init_resource::<crate::components::StepRefusals>();
        } else {
            world.remove_resource::<crate::components::StepRefusals>();
        }
        plan
    }

    /// The plan for `world` as it is now, without side effects.
    pub fn of(world: &World) -> Self {
        Self::of_with(world, &mut None)
    }

    /// The plan for a world holding `c`.
    fn from_contents(world: &World, c: Contents) -> Self {
        let settings = world
            .get_resource::<PhysicsSettings>()
            .copied()
            .unwrap_or_default();
        let midpoint = settings.integrator.samples_forces_at_midpoint();
        let runs_per_step = settings.stages().count();
        let staged = runs_per_step > 1;
        let dynamic =
            c.dynamic_with_accumulator || c.dynamic_without_accumulator || c.implicit_bodies;
        let audit = dynamic
            && world
                .get_resource::<EnergyAudit>()
                .copied()
                .unwrap_or_default()
                .applies(c.springs);
        // Whether each system is needed, in the order a step runs them (`PhysicsSystem::ALL`'s). The
        // springs come last among the forces, after the audit has read the others' loads, so
        // that the audit needs no second evaluation of every spring to take theirs out again.
        let loaded = c.dynamic_with_accumulator || c.implicit_bodies;
        let needed = [
            (PhysicsSystem::HoldGameLoads, staged && loaded),
            (PhysicsSystem::AuditEnergyStart, audit),
            (PhysicsSystem::CheckFixedBodies, c.fixed_bodies && c.springs),
            (PhysicsSystem::DampSpringsStart, c.damped_springs),
            (
                PhysicsSystem::BeginStage,
                midpoint && c.dynamic_with_accumulator,
            ),
            (
                PhysicsSystem::Gravity,
                world.contains_resource::<Gravity>() && loaded,
            ),
            (PhysicsSystem::ConstantForces, c.constant_forces),
            (PhysicsSystem::ConstantTorques, c.constant_torques),
            (PhysicsSystem::AuditExternalLoads, audit && loaded),
            (PhysicsSystem::Springs, c.explicit_springs),
            (PhysicsSystem::SolveImplicitSprings, c.implicit_bodies),
            (
                PhysicsSystem::IntegrateWithForces,
                c.dynamic_with_accumulator,
            ),
            (
                PhysicsSystem::IntegrateWithoutForces,
                c.dynamic_without_accumulator,
            ),
            (
                PhysicsSystem::DiscardFixedBodyForces,
                c.fixed_with_accumulator,
            ),
            (PhysicsSystem::DampSpringsEnd, c.damped_springs),
            (PhysicsSystem::AuditEnergy, audit),
            (PhysicsSystem::NextStage, staged),
        ];
        let systems = needed
            .into_iter()
            .filter_map(|(system, needed)| needed.then_some(system))
            .collect();
        Self {
            systems,
            runs_per_step,
        }
    }

    /// How many times the schedule runs per step: the number of stages of a step (see
    /// [`crate::integrate`]), 1 unless there are substeps or the integrator is a composition.
    pub fn runs_per_step(&self) -> usize {
        self.runs_per_step
    }

    /// Runs `schedule` — built by [`build_schedule`](Self::build_schedule) from this plan —
    /// for one whole step: once per stage ([`runs_per_step`](Self::runs_per_step) times; once
    /// unless there are substeps or a composition). A single `schedule.run` is one *stage*.
    /// Crate-private: only [`PhysicsRunner`](crate::schedule::PhysicsRunner), which checks the
    /// plan against the world before every step, runs a plan.
    pub(crate) fn run_step(&self, schedule: &mut Schedule, world: &mut World) {
        for _ in 0..self.runs_per_step {
            schedule.run(world);
        }
    }

    /// The planned systems, in run order.
    pub fn systems(&self) -> &[PhysicsSystem] {
        &self.systems
    }

    /// True when `system` is part of the plan.
    pub fn contains(&self, system: PhysicsSystem) -> bool {
        self.systems.contains(&system)
    }

    /// Builds the schedule holding exactly the planned systems, strictly ordered (so forces are
    /// summed in the same order every run: bit-identical results). One run of it is one stage
    /// of a step: [`run_step`](Self::run_step) runs a whole step.
    pub(crate) fn build_schedule(&self) -> Schedule {
        let mut schedule = Schedule::new(PlannedStage);
        // The systems run strictly one after another, so a multi-threaded executor (bevy's
        // default with `multi_threaded`) could only add its own overhead.
        // Parallelism lives inside the integrate systems instead (see `crate::parallel`).
        schedule.set_executor(bevy_ecs::schedule::SingleThreadedExecutor::new());
        // Commands (quarantine of a bad body) are rare: apply them once at the end of the step
        // instead of paying for sync points between the systems.
        schedule.set_build_settings(ScheduleBuildSettings {
            auto_insert_apply_deferred: false,
            ..Default::default()
        });
        schedule.configure_sets(
            (
                PhysicsSet::Prepare,
                PhysicsSet::Gravity,
                PhysicsSet::Forces,
                PhysicsSet::Integrate,
            )
                .chain(),
        );
        let mut previous: Option<PhysicsSystem> = None;
        for &system in &self.systems {
            let set = match system {
                PhysicsSystem::HoldGameLoads
                | PhysicsSystem::AuditEnergyStart
                | PhysicsSystem::CheckFixedBodies
                | PhysicsSystem::DampSpringsStart
                | PhysicsSystem::BeginStage => PhysicsSet::Prepare,
                PhysicsSystem::Gravity => PhysicsSet::Gravity,
                PhysicsSystem::AuditExternalLoads
                | PhysicsSystem::AuditEnergy
                | PhysicsSystem::SolveImplicitSprings
                | PhysicsSystem::IntegrateWithForces
                | PhysicsSystem::IntegrateWithoutForces
                | PhysicsSystem::DiscardFixedBodyForces
                | PhysicsSystem::DampSpringsEnd
                | PhysicsSystem::NextStage => PhysicsSet::Integrate,
                // After the audit's reading of the loads when there is one (see
                // `from_contents`), so in its set.
                PhysicsSystem::Springs if self.contains(PhysicsSystem::AuditExternalLoads) => {
                    PhysicsSet::Integrate
                }
                _ => PhysicsSet::Forces,
            };
            add_system(&mut schedule, system, set, previous);
            previous = Some(system);
        }
        schedule
    }
}

/// A marker set per system, used to chain the systems in plan order.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
struct SystemOrder(PhysicsSystem);

fn add_system(
    schedule: &mut Schedule,
    system: PhysicsSystem,
    set: PhysicsSet,
    after: Option<PhysicsSystem>,
) {
    let config = match system {
        PhysicsSystem::HoldGameLoads => hold_game_loads.into_configs(),
        PhysicsSystem::NextStage => next_stage.into_configs(),
        PhysicsSystem::AuditEnergyStart => audit_energy_start.into_configs(),
        PhysicsSystem::AuditExternalLoads => audit_external_loads.into_configs(),
        PhysicsSystem::AuditEnergy => audit_energy.into_configs(),
        PhysicsSystem::CheckFixedBodies => check_fixed_bodies.into_configs(),
        PhysicsSystem::DampSpringsStart => damp_springs_start.into_configs(),
        PhysicsSystem::DampSpringsEnd => damp_springs_end.into_configs(),
        PhysicsSystem::BeginStage => begin_stage.into_configs(),
        PhysicsSystem::Gravity => apply_gravity.into_configs(),
        PhysicsSystem::ConstantForces => apply_constant_forces.into_configs(),
        PhysicsSystem::ConstantTorques => apply_constant_torques.into_configs(),
        PhysicsSystem::Springs => apply_springs.into_configs(),
        PhysicsSystem::SolveImplicitSprings => solve_implicit_springs.into_configs(),
        PhysicsSystem::IntegrateWithForces => integrate_with_forces.into_configs(),
        PhysicsSystem::IntegrateWithoutForces => integrate_without_forces.into_configs(),
        PhysicsSystem::DiscardFixedBodyForces => discard_fixed_body_forces.into_configs(),
    };
    let config = config.in_set(set).in_set(SystemOrder(system));
    match after {
        Some(prev) => schedule.add_systems(config.after(SystemOrder(prev))),
        None => schedule.add_systems(config),
    };
}

impl fmt::Display for PhysicsPlan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = self.systems.iter().map(|s| s.name()).collect();
        write!(f, "{}", names.join(" → "))?;
        if self.runs_per_step > 1 {
            write!(f, " (× {} stages per step)", self.runs_per_step)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::components::SpringEnd;
    use tumble_core::math::Vec3;

    /// The schedule a plan builds holds exactly the planned systems, one each.
    #[test]
    fn the_schedule_holds_exactly_the_planned_systems() {
        let mut world = World::new();
        world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
        let pulled = world.spawn((RigidBody, ForceAccumulator::default())).id();
        world.spawn(RigidBody);
        world.spawn((RigidBody, Static, ForceAccumulator::default()));
        world.spawn(Spring {
            a: pulled,
            anchor_a: Vec3::ZERO,
            b: SpringEnd::World(Vec3::X),
            stiffness: 10.0,
            damping: 0.5,
            rest_length: 1.0,
        });
        world.spawn(ConstantTorque {
            body: pulled,
            torque: Vec3::Y,
        });
        let plan = PhysicsPlan::for_world(&mut world);
        assert!(plan.systems().len() >= 8, "{plan}");
        let mut schedule = plan.build_schedule();
        schedule.initialize(&mut world).unwrap();
        assert_eq!(schedule.systems_len(), plan.systems().len(), "{plan}");
    }
}
