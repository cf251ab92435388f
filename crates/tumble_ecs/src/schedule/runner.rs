//! `PhysicsRunner`: a step that re-plans when the world changes.

use std::fmt;

use bevy_ecs::prelude::*;
use bevy_ecs::schedule::{IntoScheduleConfigs, Schedule};
use bevy_ecs::system::ScheduleSystem;

use super::generator_watch::GeneratorWatch;
use super::plan::{PhysicsPlan, PhysicsSet, SpringQuery};
use crate::components::PhysicsSettings;
use tumble_core::math::same_bits;

/// Game systems that compute forces inside the step: added to [`PhysicsSet::Forces`] of every
/// schedule a [`PhysicsRunner`] builds (and builds again after a re-plan), so they run in every
/// stage of a step (see [`crate::integrate`]), on the state of that stage, like the built-in force
/// generators. Insert this resource before the first step; a change to it rebuilds the schedule.
///
/// ```
/// use bevy_ecs::prelude::*;
/// use tumble_core::math::Vec3;
/// use tumble_ecs::prelude::*;
/// use tumble_ecs::schedule::ForceSystems;
///
/// // A thruster that pushes harder the faster the body goes: it must see each stage's state.
/// fn drag(mut bodies: Query<(&Velocity, &mut ForceAccumulator)>) {
///     for (v, mut acc) in &mut bodies {
///         acc.add_force(-0.5 * v.linear);
///     }
/// }
///
/// let mut world = World::new();
/// let mut forces = ForceSystems::default();
/// forces.add(drag);
/// world.insert_resource(forces);
/// world.spawn((RigidBody, Velocity::linear(Vec3::X), ForceAccumulator::default()));
/// let mut physics = PhysicsRunner::new(&mut world);
/// physics.step(&mut world);
/// ```
#[derive(Resource, Default)]
pub struct ForceSystems(Vec<Box<dyn Fn(&mut Schedule) + Send + Sync>>);

impl ForceSystems {
    /// Adds `systems` (a system, or a tuple of them) to [`PhysicsSet::Forces`] of every schedule
    /// built from now on.
    pub fn add<M>(
        &mut self,
        systems: impl IntoScheduleConfigs<ScheduleSystem, M> + Clone + Send + Sync + 'static,
    ) -> &mut Self {
        self.0.push(Box::new(move |schedule: &mut Schedule| {
            schedule.add_systems(systems.clone().in_set(PhysicsSet::Forces));
        }));
        self
    }

    /// Adds the systems to `schedule`.
    fn apply(&self, schedule: &mut Schedule) {
        for add in &self.0 {
            add(schedule);
        }
    }
}

impl std::fmt::Debug for ForceSystems {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "ForceSystems({} entries)", self.0.len())
    }
}

/// When the world's [`ForceSystems`] last changed (`None` without them).
fn force_systems_changed(world: &World) -> Option<bevy_ecs::change_detection::Tick> {
    world
        .get_resource_ref::<ForceSystems>()
        .map(|r| r.last_changed())
}

/// The schedule of `plan`, with the world's [`ForceSystems`].
fn build(plan: &PhysicsPlan, world: &World) -> Schedule {
    let mut schedule = plan.build_schedule();
    if let Some(systems) = world.get_resource::<ForceSystems>() {
        systems.apply(&mut schedule);
    }
    schedule
}

/// The way to step a world: one physics step per [`step`](Self::step) — the schedule once per
/// stage of the step ([`PhysicsPlan::runs_per_step`]) — planned from the world and checked
/// against it before every step, so it never runs a plan the world has outgrown.
///
/// Before each step the runner gives every dynamic body that has no
/// [`MassProps`](crate::components::MassProps) the default
/// with a warning (see [`assume_missing_masses`](crate::components::assume_missing_masses)),
/// leaves out every force generator whose values turned bad or whose
/// body went away (see [`crate::components`]), then compares the world with what it
/// planned from and plans again
/// when the world gained or lost a [`Gravity`](crate::components::Gravity) resource, a kind of
/// force generator, its first damped spring or its last (a damping coefficient changed in place
/// counts), dynamic bodies with or without accumulators, static or kinematic bodies; when its
/// [`ForceSystems`] changed; when its [`PhysicsSettings`] changed in any way (time step,
/// integrator, substeps, spring solver: the stiff springs are classified again and the stability
/// prediction is checked again); or when its springs need classifying again. The check is one pass
/// over the archetypes per step, plus, in a world with springs, a read of their damping
/// coefficients up to the first damped one; the schedule is rebuilt only when the plan differs.
///
/// ```
/// use bevy_ecs::prelude::World;
/// use tumble_core::math::Vec3;
/// use tumble_ecs::prelude::*;
///
/// let mut world = World::new();
/// world.spawn((RigidBody, ForceAccumulator::default()));
/// let mut physics = PhysicsRunner::new(&mut world);
/// physics.step(&mut world);
/// assert_eq!(physics.plan().to_string(), "begin_stage → integrate_with_forces");
/// world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
/// physics.step(&mut world); // re-planned: gravity is now a system of the step
/// assert_eq!(physics.plan().to_string(), "begin_stage → apply_gravity → integrate_with_forces");
/// assert_eq!(physics.replans(), 1);
/// ```
///
/// A `Resource`, so that a plugin can keep it in the world it steps (see `TumblePlugin`): it
/// holds nothing a step depends on that the world does not (the plan and the schedule are
/// derived from the world and re-derived when it changes).
#[derive(Resource)]
pub struct PhysicsRunner {
    plan: PhysicsPlan,
    schedule: Schedule,
    replans: u64,
    /// The settings the plan was made for.
    settings: PhysicsSettings,
    /// The springs, read by every re-planning (whether any is damped): kept so that planning
    /// every step builds no query.
    springs: Option<SpringQuery>,
    /// When the [`ForceSystems`] the schedule holds were last changed.
    force_systems: Option<bevy_ecs::change_detection::Tick>,
    /// The checks of the force generators before each step.
    generators: GeneratorWatch,
    /// The queries that tell whether the springs' classification saw every spring and mass.
    classified: crate::springs::ClassifiedInputs,
    /// The bad [`Gravity`](crate::components::Gravity) last recorded, so that one bad value
    /// (bit for bit: a NaN is not equal to itself) is one record.
    bad_gravity: Option<tumble_core::math::Vec3>,
}

impl PhysicsRunner {
    /// Plans the step for `world` (see [`PhysicsPlan::for_world`]). A world without
    /// [`PhysicsSettings`] gets the default ones, recorded as a
    /// [`WorldError`](crate::components::WorldError) in [`PhysicsErrors`](crate::components::PhysicsErrors).
    pub fn new(world: &mut World) -> Self {
        let missing = !world.contains_resource::<PhysicsSettings>();
        let plan = PhysicsPlan::for_world(world);
        if missing {
            let settings = *world.resource::<PhysicsSettings>();
            record_missing_settings(world, &settings, "the default settings");
        }
        let schedule = build(&plan, world);
        Self {
            plan,
            schedule,
            replans: 0,
            settings: *world.resource::<PhysicsSettings>(),
            springs: None,
            force_systems: force_systems_changed(world),
            generators: GeneratorWatch::default(),
            classified: Default::default(),
            bad_gravity: None,
        }
    }

    /// Advances `world` by one step, re-planning first if the world changed. (In a bare `World`,
    /// call `world.clear_trackers()` once per frame as well.)
    pub fn step(&mut self, world: &mut World) {
        self.prepare(world);
        self.plan.run_step(&mut self.schedule, world);
    }

    /// What [`step`](Self::step) does before it runs the plan: gives bodies without mass
    /// properties the default (with a warning), leaves out generators that turned bad, checks
    /// the plan against the world and plans again if it no longer matches. Public so that its
    /// cost can be measured on its own (`tumble bench` reports it against a whole step).
    pub fn prepare(&mut self, world: &mut World) {
        if !world.contains_resource::<PhysicsSettings>() {
            // Removed after planning: the step keeps the settings it was planned with, and
            // says so (a default in their place would change the step silently).
            world.insert_resource(self.settings);
            record_missing_settings(world, &self.settings, "the settings it was planned with");
        }
        crate::components::assume_missing_masses(world);
        self.generators.check(world);
        self.check_gravity(world);
        if self.is_stale(world) {
            self.replan(world);
        }
    }

    /// Records a [`WorldError`](crate::components::WorldError) (and logs it) when the
    /// [`Gravity`](crate::components::Gravity) resource is not finite, once per bad value: the
    /// step leaves such a gravity out ([`Gravity::field`](crate::components::Gravity::field)).
    fn check_gravity(&mut self, world: &mut World) {
        let Some(&crate::components::Gravity(g)) = world.get_resource() else {
            self.bad_gravity = None;
            return;
        };
        let Err(source) = tumble_core::error::check_finite_vec3("acceleration", g) else {
            self.bad_gravity = None;
            return;
        };
        let same = |last: tumble_core::math::Vec3| same_bits(last.to_array(), g.to_array());
        if self.bad_gravity.is_some_and(same) {
            return;
        }
        self.bad_gravity = Some(g);
        let error = crate::components::WorldError {
            resource: "Gravity",
            kind: crate::components::WorldErrorKind::Invalid(source),
        };
        tracing::error!("{error}");
        world
            .get_resource_or_init::<crate::components::PhysicsErrors>()
            .world
            .push(error);
    }

    /// True when `world` no longer matches the plan (see the type's docs).
    fn is_stale(&mut self, world: &World) -> bool {
        world.get_resource::<PhysicsSettings>() != Some(&self.settings)
            || PhysicsPlan::of_with(world, &mut self.springs) != self.plan
            || crate::springs::classification_is_stale_with(world, &mut self.classified)
            || force_systems_changed(world) != self.force_systems
    }

    /// Plans `world` again ([`PhysicsPlan::for_world`]: classification, stability check) and
    /// rebuilds the schedule if the plan or the force systems changed.
    fn replan(&mut self, world: &mut World) {
        let plan = PhysicsPlan::for_world(world);
        self.settings = *world.resource::<PhysicsSettings>();
        let force_systems = force_systems_changed(world);
        if plan == self.plan && force_systems == self.force_systems {
            return;
        }
        tracing::debug!(from = %self.plan, to = %plan, "physics re-planned");
        self.schedule = build(&plan, world);
        self.plan = plan;
        self.replans += 1;
        self.force_systems = force_systems;
    }

    /// The current plan.
    pub fn plan(&self) -> &PhysicsPlan {
        &self.plan
    }

    /// How many times the world's changes forced a new plan.
    pub fn replans(&self) -> u64 {
        self.replans
    }
}

impl fmt::Debug for PhysicsRunner {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("PhysicsRunner")
            .field("plan", &self.plan.to_string())
            .field("replans", &self.replans)
            .finish()
    }
}

impl fmt::Display for PhysicsRunner {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.plan.fmt(f)
    }
}

/// Records (and logs) that the world had no [`PhysicsSettings`] when a step needed them, and
/// which (`which`, `settings`) it got instead.
fn record_missing_settings(world: &mut World, settings: &PhysicsSettings, which: &str) {
    let error = crate::components::WorldError {
        resource: "PhysicsSettings",
        kind: crate::components::WorldErrorKind::Missing {
            used: format!(
                "{which} (Δt = {} s, `{}`)",
                settings.dt(),
                settings.integrator
            ),
        },
    };
    tracing::error!("{error}");
    world
        .get_resource_or_init::<crate::components::PhysicsErrors>()
        .world
        .push(error);
}
