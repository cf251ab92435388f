//! The scene built in rapier.

use glam::Vec3;
use rapier3d::prelude::{
    IntegrationParameters, MassProperties as RapierMass, PhysicsWorld, Pose, RigidBodyBuilder,
    RigidBodyHandle,
};
use tumble_core::BodyState;

use crate::scene::{ComparisonScene, Load};

/// A rapier world holding the bodies of a [`ComparisonScene`].
pub struct RapierScene {
    world: PhysicsWorld,
    handles: Vec<RigidBodyHandle>,
    loads: Vec<Vec<Load>>,
    any_loads: bool,
    local_com: Vec<Vec3>,
}

impl RapierScene {
    /// Builds the scene with rapier's gyroscopic term on or off and the given number of solver
    /// iterations (= substeps for free bodies; rapier's default is 4).
    pub fn new(scene: &ComparisonScene, gyroscopic: bool, solver_iterations: usize) -> Self {
        let mut world = PhysicsWorld::new();
        world.gravity = scene.gravity.unwrap_or(Vec3::ZERO);
        world.integration_parameters = IntegrationParameters {
            dt: scene.dt,
            num_solver_iterations: solver_iterations.max(1),
            ..IntegrationParameters::default()
        };
        let mut handles = Vec::with_capacity(scene.bodies.len());
        let mut loads = Vec::with_capacity(scene.bodies.len());
        let mut local_com = Vec::with_capacity(scene.bodies.len());
        for body in &scene.bodies {
            let m = &body.mass;
            let c = m.local_center_of_mass();
            let origin = body.state.position - body.state.rotation * c;
            let props = RapierMass::with_principal_inertia_frame(
                c,
                m.mass(),
                m.principal_inertia(),
                m.principal_frame(),
            );
            let builder = RigidBodyBuilder::dynamic()
                .pose(Pose::from_parts(origin, body.state.rotation))
                .linvel(body.state.linear_velocity)
                .angvel(body.state.angular_velocity)
                .additional_mass_properties(props)
                .gravity_scale(body.gravity_scale)
                .linear_damping(body.linear_damping)
                .angular_damping(body.angular_damping)
                .gyroscopic_forces_enabled(gyroscopic)
                .can_sleep(false)
                .allow_fast_rotation(true);
            handles.push(world.insert_body(builder));
            loads.push(body.loads.clone());
            local_com.push(c);
        }
        let mut scene = Self {
            world,
            handles,
            any_loads: loads.iter().any(|l| !l.is_empty()),
            loads,
            local_com,
        };
        scene.apply_loads();
        scene
    }

    /// Resets every body's forces and re-adds its loads at the current pose. Skipped when no
    /// body has a load: touching a body through `get_mut` flags it as modified, which would make
    /// rapier's step (and so the benchmark) do work a scene of free bodies never asks for.
    fn apply_loads(&mut self) {
        if !self.any_loads {
            return;
        }
        for (handle, loads) in self.handles.iter().zip(&self.loads) {
            let Some(rb) = self.world.bodies.get_mut(*handle) else {
                continue;
            };
            rb.reset_forces(false);
            rb.reset_torques(false);
            for load in loads {
                match *load {
                    Load::Force {
                        force,
                        local_point: None,
                    } => rb.add_force(force, false),
                    Load::Force {
                        force,
                        local_point: Some(p),
                    } => {
                        let point = *rb.position() * p;
                        rb.add_force_at_point(force, point, false);
                    }
                    Load::Torque(torque) => rb.add_torque(torque, false),
                }
            }
        }
    }

    /// Advances rapier by one step.
    pub fn step(&mut self) {
        self.world.step();
        self.apply_loads();
    }

    /// The state of body `i` (position = centre of mass).
    pub fn state(&self, i: usize) -> BodyState {
        let rb = &self.world.bodies[self.handles[i]];
        let rotation = *rb.rotation();
        BodyState {
            position: rb.translation() + rotation * self.local_com[i],
            rotation,
            linear_velocity: rb.linvel(),
            angular_velocity: rb.angvel(),
        }
    }

    /// Number of bodies.
    pub fn len(&self) -> usize {
        self.handles.len()
    }

    /// True when the scene has no bodies.
    pub fn is_empty(&self) -> bool {
        self.handles.is_empty()
    }
}
