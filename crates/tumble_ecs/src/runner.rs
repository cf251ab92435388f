//! A physics step that keeps its schedule in step with the world.

use std::fmt;

use bevy_ecs::prelude::*;
use bevy_ecs::schedule::Schedule;

use crate::schedule::{PhysicsPlan, SpringQuery};

/// Runs one physics step per [`step`](Self::step), re-planning when the world changed: when it
/// gains or loses a [`Gravity`](crate::components::Gravity) resource, a kind of force generator,
/// its first damped spring or its last (a damping coefficient changed in place counts),
/// dynamic bodies with or without accumulators, static or kinematic bodies, or when the
/// integrator changes between a kick–drift and a drift–kick–drift method. Re-planning is one pass
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
/// assert_eq!(physics.plan().to_string(), "begin_step → integrate_with_forces");
/// world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
/// physics.step(&mut world); // re-planned: gravity is now a system of the step
/// assert_eq!(physics.plan().to_string(), "begin_step → apply_gravity → integrate_with_forces");
/// assert_eq!(physics.replans(), 1);
/// ```
pub struct PhysicsRunner {
    plan: PhysicsPlan,
    schedule: Schedule,
    replans: u64,
    /// The springs, read by every re-planning (whether any is damped): kept so that planning
    /// every step builds no query.
    springs: Option<SpringQuery>,
}

impl PhysicsRunner {
    /// Plans the step for `world` (see [`PhysicsPlan::for_world`]).
    pub fn new(world: &mut World) -> Self {
        let plan = PhysicsPlan::for_world(world);
        let schedule = plan.build_schedule();
        Self {
            plan,
            schedule,
            replans: 0,
            springs: None,
        }
    }

    /// Advances `world` by one step, re-planning first if the world changed. (In a bare `World`,
    /// call `world.clear_trackers()` once per frame as well.)
    pub fn step(&mut self, world: &mut World) {
        if PhysicsPlan::of_with(world, &mut self.springs) != self.plan
            || crate::stiff::classification_is_stale(world)
        {
            let plan = PhysicsPlan::for_world(world);
            tracing::debug!(from = %self.plan, to = %plan, "physics re-planned");
            self.schedule = plan.build_schedule();
            self.plan = plan;
            self.replans += 1;
        }
        self.schedule.run(world);
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
