//! `TumblePlugin` (feature `bevy_app`): tumble inside a Bevy app, one physics step per run of a
//! schedule of the app's choosing (`FixedUpdate` by default).

use bevy_app::{App, FixedUpdate, Plugin};
use bevy_ecs::intern::Interned;
use bevy_ecs::prelude::*;
use bevy_ecs::schedule::ScheduleLabel;

use crate::components::PhysicsSettings;
use crate::runner::PhysicsRunner;

/// Adds the physics step to a schedule (`FixedUpdate` unless [`new`](Self::new) names another,
/// as avian's `PhysicsPlugins::new(schedule)` does), planned from the world and re-planned when
/// it changes (see [`PhysicsRunner`]).
///
/// The plugin keeps no state outside the world: the [`PhysicsRunner`] is a resource of the
/// world it steps, and its plan and schedule are derived from the world, so a world put back by
/// a [`RollbackSnapshot`](crate::rollback::RollbackSnapshot) steps on exactly as it did.
///
/// The step size is [`PhysicsSettings::dt`]; keep it equal to the schedule's period (Bevy's
/// `FixedUpdate` runs at 64 Hz by default, the default here). Game systems that add forces run
/// in the same schedule before [`TumbleStep`]; their loads are held over the whole step (see
/// [`ForceAccumulator`](crate::components::ForceAccumulator)). A force system that must see
/// the state of every stage of a step (with substeps or `yoshida4`) goes in the
/// [`ForceSystems`](crate::runner::ForceSystems) resource instead:
///
/// ```
/// use bevy_app::{App, FixedUpdate};
/// use bevy_ecs::prelude::*;
/// use tumble_ecs::plugin::{TumblePlugin, TumbleStep};
/// use tumble_ecs::prelude::*;
///
/// fn push(mut bodies: Query<&mut ForceAccumulator>) {
///     for mut acc in &mut bodies {
///         acc.add_force(Vec3::X);
///     }
/// }
///
/// let mut app = App::new();
/// app.add_plugins(TumblePlugin::default())
///     .add_systems(FixedUpdate, push.before(TumbleStep));
/// let body = app.world_mut().spawn((RigidBody, ForceAccumulator::default())).id();
/// for _ in 0..64 {
///     app.world_mut().run_schedule(FixedUpdate);
/// }
/// let x = app.world().get::<Transform>(body).unwrap().translation.x;
/// assert!((x - 0.5).abs() < 1e-3); // ½ a t² after one second at 1 m/s² (x ≈ 0.5)
/// ```
#[derive(Debug, Clone, Copy)]
pub struct TumblePlugin {
    /// Time step and integrator, inserted unless the app already has settings.
    pub settings: PhysicsSettings,
    /// The schedule that runs one physics step per run.
    pub schedule: Interned<dyn ScheduleLabel>,
}

impl TumblePlugin {
    /// One physics step per run of `schedule`, at 64 Hz with the default integrator (change
    /// them with [`with_settings`](Self::with_settings)).
    pub fn new(schedule: impl ScheduleLabel) -> Self {
        Self {
            settings: PhysicsSettings::new(1.0 / 64.0, tumble_core::Integrator::default())
                .expect("1/64 s is a valid time step"),
            schedule: schedule.intern(),
        }
    }

    /// The same plugin with `settings` (time step, integrator, substeps, spring solver).
    pub fn with_settings(mut self, settings: PhysicsSettings) -> Self {
        self.settings = settings;
        self
    }
}

impl Default for TumblePlugin {
    /// `FixedUpdate` at 64 Hz (Bevy's default fixed step) with the default integrator.
    fn default() -> Self {
        Self::new(FixedUpdate)
    }
}

/// The system set of the physics step in the plugin's schedule.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct TumbleStep;

impl Plugin for TumblePlugin {
    fn build(&self, app: &mut App) {
        if !app.world().contains_resource::<PhysicsSettings>() {
            app.insert_resource(self.settings);
        }
        // A multi-threaded executor (feature `parallel`) needs the compute pool.
        crate::parallel::pool_threads();
        app.add_systems(self.schedule, physics_step.in_set(TumbleStep));
    }
}

/// One physics step with the world's [`PhysicsRunner`] resource, planned (and inserted) on
/// first use and re-planned when the world changes.
pub fn physics_step(world: &mut World) {
    if !world.contains_resource::<PhysicsRunner>() {
        let runner = PhysicsRunner::new(world);
        world.insert_resource(runner);
    }
    world.resource_scope(|world, mut runner: Mut<PhysicsRunner>| runner.step(world));
}
