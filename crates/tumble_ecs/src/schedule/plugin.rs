//! `TumblePlugin` (feature `bevy_app`).

use bevy_app::{App, FixedFirst, FixedLast, FixedPostUpdate, FixedPreUpdate, FixedUpdate, Plugin};
use bevy_ecs::intern::Interned;
use bevy_ecs::prelude::*;
use bevy_ecs::schedule::ScheduleLabel;
use bevy_time::{Fixed, Time};
use tumble_core::math::Real;

use crate::components::PhysicsSettings;
use crate::schedule::PhysicsRunner;
use crate::schedule::PhysicsSet;

/// Adds the physics step to a schedule (`FixedUpdate` unless [`new`](Self::new) names another,
/// as avian's `PhysicsPlugins::new(schedule)` does), planned from the world and re-planned when
/// it changes (see [`PhysicsRunner`]).
///
/// **The time step.** In one of Bevy's fixed schedules (`FixedUpdate`, `FixedPreUpdate`,
/// `FixedPostUpdate`, `FixedFirst`, `FixedLast`) the step is Bevy's fixed clock: before each
/// step the plugin sets [`PhysicsSettings::dt`] to `Time<Fixed>`'s timestep (a `dt` that game
/// code set to something else is overridden with a warning, since physics time must follow
/// game time). Set the rate with `Time::<Fixed>::from_hz(60.0)`, as for any Bevy game. In any
/// other schedule the step is [`PhysicsSettings::dt`], one per run.
///
/// **Where game forces go.** Game systems that add forces run in the plugin's schedule before
/// the step: order them `.before(TumbleStep)` or put them in [`PhysicsSet::Forces`] (which the
/// plugin orders before [`TumbleStep`] in its schedule). Their loads are held over the whole
/// step, substeps and compositions included (see
/// [`ForceAccumulator`](crate::components::ForceAccumulator)). A force system that must see
/// the state of every stage of a step (with substeps or `yoshida4`) goes in the
/// [`ForceSystems`](crate::schedule::ForceSystems) resource instead. For avian users:
///
/// | avian | tumble |
/// |---|---|
/// | `PhysicsPlugins::new(FixedPostUpdate)` | `TumblePlugin::new(FixedPostUpdate)` |
/// | `PhysicsSet::StepSimulation` | [`TumbleStep`] |
/// | a system before `PhysicsSet::StepSimulation` | a system in [`PhysicsSet::Forces`] or `.before(TumbleStep)` |
/// | `Time<Fixed>` sets the step | `Time<Fixed>` sets the step |
///
/// The plugin keeps no state outside the world: the [`PhysicsRunner`] is a resource of the
/// world it steps, and its plan and schedule are derived from the world, so a world put back by
/// a [`RollbackSnapshot`](crate::state::RollbackSnapshot) steps on exactly as it did.
///
/// ```
/// use bevy_app::{App, FixedUpdate};
/// use bevy_ecs::prelude::*;
/// use tumble_core::math::Vec3;
/// use tumble_ecs::schedule::TumblePlugin;
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
///     .add_systems(FixedUpdate, push.in_set(PhysicsSet::Forces));
/// let body = app.world_mut().spawn((RigidBody, ForceAccumulator::default())).id();
/// for _ in 0..64 {
///     app.world_mut().run_schedule(FixedUpdate);
/// }
/// let x = app.world().get::<Pose>(body).unwrap().translation.x;
/// assert!((x - 0.5).abs() < 1e-3); // ½ a t² after one second at 1 m/s² (x ≈ 0.5)
/// ```
#[derive(Debug, Clone, Copy)]
pub struct TumblePlugin {
    /// Time step and integrator, inserted unless the app already has settings. On Bevy's fixed
    /// clock the time step is `Time<Fixed>`'s.
    pub settings: PhysicsSettings,
    /// The schedule that runs one physics step per run.
    pub schedule: Interned<dyn ScheduleLabel>,
}

impl TumblePlugin {
    /// One physics step per run of `schedule`, with the default integrator (change it with
    /// [`with_settings`](Self::with_settings)); the step is Bevy's fixed clock in a fixed
    /// schedule, 1/64 s (Bevy's default fixed rate) in any other.
    pub fn new(schedule: impl ScheduleLabel) -> Self {
        Self {
            settings: PhysicsSettings::new(DEFAULT_DT, tumble_core::Integrator::default())
                .expect("1/64 s is a valid time step"),
            schedule: schedule.intern(),
        }
    }

    /// The same plugin with `settings` (time step, integrator, substeps, spring solver).
    pub fn with_settings(mut self, settings: PhysicsSettings) -> Self {
        self.settings = settings;
        self
    }

    /// True when the plugin's schedule is one of Bevy's fixed schedules, whose period is
    /// `Time<Fixed>`'s timestep.
    pub fn on_fixed_clock(&self) -> bool {
        [
            FixedFirst.intern(),
            FixedPreUpdate.intern(),
            FixedUpdate.intern(),
            FixedPostUpdate.intern(),
            FixedLast.intern(),
        ]
        .contains(&self.schedule)
    }
}

impl Default for TumblePlugin {
    /// `FixedUpdate` on Bevy's fixed clock with the default integrator.
    fn default() -> Self {
        Self::new(FixedUpdate)
    }
}

/// The system set of the physics step in the plugin's schedule.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct TumbleStep;

/// The time step of [`TumblePlugin::new`]: Bevy's default fixed rate, 64 Hz.
const DEFAULT_DT: Real = 1.0 / 64.0;

/// How the plugin's step follows Bevy's fixed clock: present only when the plugin runs in a
/// fixed schedule.
#[derive(Resource, Debug, Clone, Copy, Default, PartialEq)]
struct FixedClock {
    /// The time step the plugin itself last put in the settings (its default, or the clock's):
    /// a settings `dt` other than this one was chosen by game code, and overriding it warns.
    applied: Option<Real>,
}

impl Plugin for TumblePlugin {
    fn build(&self, app: &mut App) {
        let own_default =
            !app.world().contains_resource::<PhysicsSettings>() && self.settings.dt() == DEFAULT_DT;
        if !app.world().contains_resource::<PhysicsSettings>() {
            app.insert_resource(self.settings);
        }
        if self.on_fixed_clock() {
            app.insert_resource(FixedClock {
                applied: own_default.then_some(DEFAULT_DT),
            });
        }
        // A multi-threaded executor (feature `parallel`) needs the compute pool.
        crate::parallel::pool_threads();
        app.configure_sets(
            self.schedule,
            (PhysicsSet::Prepare, PhysicsSet::Gravity, PhysicsSet::Forces)
                .chain()
                .before(TumbleStep),
        );
        app.configure_sets(self.schedule, PhysicsSet::Integrate.after(TumbleStep));
        app.add_systems(self.schedule, physics_step.in_set(TumbleStep));
    }
}

/// One physics step with the world's [`PhysicsRunner`] resource, planned (and inserted) on
/// first use and re-planned when the world changes; on Bevy's fixed clock, with the clock's
/// time step.
pub fn physics_step(world: &mut World) {
    follow_fixed_clock(world);
    if !world.contains_resource::<PhysicsRunner>() {
        let runner = PhysicsRunner::new(world);
        world.insert_resource(runner);
    }
    world.resource_scope(|world, mut runner: Mut<PhysicsRunner>| runner.step(world));
}

/// Sets [`PhysicsSettings::dt`] to `Time<Fixed>`'s timestep when the plugin runs on the fixed
/// clock, warning when it overrides a time step that game code set.
fn follow_fixed_clock(world: &mut World) {
    let Some(clock) = world.get_resource::<FixedClock>().copied() else {
        return;
    };
    let Some(timestep) = world.get_resource::<Time<Fixed>>().map(|t| t.timestep()) else {
        return;
    };
    let dt = timestep.as_secs_f64() as Real;
    let mut settings = world.get_resource_or_init::<PhysicsSettings>();
    let current = settings.dt();
    if current != dt {
        if clock.applied != Some(current) {
            tracing::warn!(
                "PhysicsSettings::dt = {current} s differs from Bevy's fixed timestep \
                 {dt} s: the physics step follows Time<Fixed> (set its rate with \
                 Time::<Fixed>::from_hz)"
            );
        }
        // A `Duration` is never negative, and `Time<Fixed>` refuses a zero timestep.
        if let Err(e) = settings.set_dt(dt) {
            tracing::error!("Bevy's fixed timestep {timestep:?} is not a valid time step: {e}");
        }
    }
    world.resource_mut::<FixedClock>().applied = Some(dt);
}
