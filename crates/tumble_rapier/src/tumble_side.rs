//! The same scene in tumble, through the ECS schedule a game would run.

use bevy_ecs::prelude::*;
use tumble_core::math::Vec3;
use tumble_core::{BodyState, Integrator};
use tumble_ecs::components::{body_state, write_body_state};
use tumble_ecs::prelude::*;

use crate::scene::{ComparisonScene, ComparisonSpringEnd, Load};

/// A tumble world holding the bodies of a [`ComparisonScene`] and its planned schedule.
pub struct TumbleScene {
    world: World,
    physics: PhysicsRunner,
    entities: Vec<Entity>,
}

impl TumbleScene {
    /// Builds the scene with the given integrator; springs, if any, stepped as
    /// [`SpringSolver::Auto`] chooses.
    ///
    /// # Panics
    /// If `scene.dt` is not a valid time step (a `ComparisonScene` is built by code, not read
    /// from a user file; the scene loader validates user input).
    pub fn new(scene: &ComparisonScene, integrator: Integrator) -> Self {
        Self::with_springs(scene, integrator, SpringSolver::Auto)
    }

    /// [`new`](Self::new) with the springs stepped as `springs` says
    /// (`PhysicsSettings::springs`). Each [`ComparisonSpring`](crate::ComparisonSpring) becomes a
    /// `Spring` component with the same anchors (both relative to the body origin).
    ///
    /// # Panics
    /// As [`new`](Self::new), and if a spring names a body index outside `scene.bodies`.
    pub fn with_springs(
        scene: &ComparisonScene,
        integrator: Integrator,
        springs: SpringSolver,
    ) -> Self {
        Self::with_free_flow(scene, integrator, springs, FreeFlow::Auto)
    }

    /// [`with_springs`](Self::with_springs) with split methods' free rotation chosen as
    /// `free_flow` says (`PhysicsSettings::free_flow`): [`FreeFlow::Method`] measures the
    /// method itself, [`FreeFlow::Auto`] what a world steps by default.
    ///
    /// # Panics
    /// As [`with_springs`](Self::with_springs).
    pub fn with_free_flow(
        scene: &ComparisonScene,
        integrator: Integrator,
        springs: SpringSolver,
        free_flow: FreeFlow,
    ) -> Self {
        let mut world = World::new();
        world.insert_resource(
            PhysicsSettings::new(scene.dt, integrator)
                .expect("comparison scenes have a valid dt")
                .with_springs(springs)
                .with_free_flow(free_flow),
        );
        if let Some(g) = scene.gravity {
            world.insert_resource(Gravity(g));
        }
        let mut entities = Vec::with_capacity(scene.bodies.len());
        for body in &scene.bodies {
            let mass = MassProps(body.mass);
            let (mut transform, mut velocity) = (Pose::IDENTITY, Velocity::ZERO);
            write_body_state(&body.state, &mass, &mut transform, &mut velocity);
            let mut e = world.spawn((RigidBody, mass, transform, velocity));
            if body.gravity_scale != 1.0 {
                e.insert(GravityScale(body.gravity_scale));
            }
            if body.linear_damping != 0.0 || body.angular_damping != 0.0 {
                e.insert(Damping {
                    linear: body.linear_damping,
                    angular: body.angular_damping,
                });
            }
            let id = e.id();
            for load in &body.loads {
                match *load {
                    Load::Force { force, local_point } => {
                        world.spawn(ConstantForce {
                            body: id,
                            force,
                            local_point,
                        });
                    }
                    Load::Torque(torque) => {
                        world.spawn(ConstantTorque { body: id, torque });
                    }
                }
            }
            entities.push(id);
        }
        for spring in &scene.springs {
            let b = match spring.b {
                ComparisonSpringEnd::World(p) => SpringEnd::World(p),
                ComparisonSpringEnd::Body { body, anchor } => SpringEnd::Body {
                    body: entities[body],
                    anchor,
                },
            };
            world.spawn(Spring {
                a: entities[spring.a],
                anchor_a: spring.anchor_a,
                b,
                stiffness: spring.stiffness,
                damping: spring.damping,
                rest_length: spring.rest_length,
            });
        }
        let physics = PhysicsRunner::new(&mut world);
        Self {
            world,
            physics,
            entities,
        }
    }

    /// The world, to add resources (e.g. a threading policy) or read components.
    pub fn world_mut(&mut self) -> &mut World {
        &mut self.world
    }

    /// Only what a step does before running its plan (the runner's check of the world, see
    /// [`PhysicsRunner::prepare`]): to time the check alone.
    pub fn prepare_step(&mut self) {
        self.physics.prepare(&mut self.world);
    }

    /// Advances tumble by one step.
    pub fn step(&mut self) {
        self.physics.step(&mut self.world);
        self.world.clear_trackers();
    }

    /// The state of body `i` (position = centre of mass).
    pub fn state(&self, i: usize) -> BodyState {
        let e = self.entities[i];
        let (Some(t), Some(v), Some(m)) = (
            self.world.get::<Pose>(e),
            self.world.get::<Velocity>(e),
            self.world.get::<MassProps>(e),
        ) else {
            return BodyState {
                position: Vec3::NAN,
                ..BodyState::default()
            };
        };
        body_state(t, v, m)
    }

    /// True when body `i` was quarantined (bad data or divergence).
    pub fn is_rejected(&self, i: usize) -> bool {
        self.world.get::<Rejected>(self.entities[i]).is_some()
    }
}
