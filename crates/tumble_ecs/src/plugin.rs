//! `TumblePlugin` (feature `bevy_app`): tumble inside a Bevy app, one physics step per
//! `FixedUpdate`.

use bevy_app::{App, FixedUpdate, Plugin};
use bevy_ecs::prelude::*;

use crate::components::PhysicsSettings;
use crate::runner::PhysicsRunner;

/// Adds the physics step to `FixedUpdate`, planned from the world and re-planned when it changes
/// (see [`PhysicsRunner`]).
///
/// The step size is [`PhysicsSettings::dt`]; keep it equal to the app's fixed time step (Bevy's
/// default is 64 Hz, the default here). Game systems that add forces run in `FixedUpdate` before
/// [`TumbleStep`]; their loads are held over the whole step (see
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
}

impl Default for TumblePlugin {
    /// 64 Hz (Bevy's default fixed step) with the default integrator.
    fn default() -> Self {
        Self {
            settings: PhysicsSettings::new(1.0 / 64.0, tumble_core::Integrator::default())
                .expect("1/64 s is a valid time step"),
        }
    }
}

/// The system set of the physics step in `FixedUpdate`.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct TumbleStep;

impl Plugin for TumblePlugin {
    fn build(&self, app: &mut App) {
        if !app.world().contains_resource::<PhysicsSettings>() {
            app.insert_resource(self.settings);
        }
        // A multi-threaded executor (feature `parallel`) needs the compute pool.
        crate::parallel::pool_threads();
        app.add_systems(FixedUpdate, physics_step.in_set(TumbleStep));
    }
}

/// One physics step, planned on first use and re-planned when the world changes.
pub fn physics_step(world: &mut World, mut runner: Local<Option<PhysicsRunner>>) {
    match runner.as_mut() {
        Some(r) => r.step(world),
        None => {
            let mut r = PhysicsRunner::new(world);
            r.step(world);
            *runner = Some(r);
        }
    }
}
