//! The stage cursor: which stage of the step a run of the schedule is.

use bevy_ecs::prelude::*;
use tumble_core::integrate::StageSpan;

use crate::components::{ForceAccumulator, HeldLoad, PhysicsSettings, RigidBody};

/// Which stage of the step the physics schedule is running: 0 at the start of every step,
/// moved on by [`next_stage`] at the end of each run of a plan of several stages.
#[derive(Resource, Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct StageCursor(u32);

impl StageCursor {
    /// The index of the running stage in its step.
    pub fn index(self) -> usize {
        self.0 as usize
    }

    /// The running stage of a step under `settings`. (An index left over from settings with
    /// more stages wraps around.)
    #[inline]
    pub fn span(self, settings: &PhysicsSettings) -> StageSpan {
        let stages = settings.stages();
        stages.span(settings.dt(), self.index() % stages.count())
    }
}

/// First system of a plan of several stages (with dynamic bodies that have accumulators): in
/// the first stage, holds what game code put in each accumulator before the step (its
/// [`HeldLoad`]); in every later stage, puts it back into the accumulator the previous stage
/// consumed, so that it acts in every stage for the stage's span and once in total.
pub fn hold_game_loads(
    settings: Res<PhysicsSettings>,
    cursor: Res<StageCursor>,
    mut bodies: Query<(&mut ForceAccumulator, &mut HeldLoad), With<RigidBody>>,
) {
    if cursor.span(&settings).opens_step {
        for (acc, mut held) in &mut bodies {
            let load = HeldLoad {
                force: acc.force,
                torque: acc.torque,
            };
            if *held != load {
                *held = load;
            }
        }
    } else {
        for (mut acc, held) in &mut bodies {
            if held.force != tumble_core::math::Vec3::ZERO
                || held.torque != tumble_core::math::Vec3::ZERO
            {
                acc.force += held.force;
                acc.torque += held.torque;
            }
        }
    }
}

/// Last system of a plan of several stages: moves the [`StageCursor`] to the next stage, back
/// to 0 after the last.
pub fn next_stage(settings: Res<PhysicsSettings>, mut cursor: ResMut<StageCursor>) {
    let count = settings.stages().count() as u32;
    cursor.0 = (cursor.0 + 1) % count;
}
