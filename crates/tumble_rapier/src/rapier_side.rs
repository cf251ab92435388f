//! The scene built in rapier.

use rapier3d::prelude::{
    IntegrationParameters, MassProperties as RapierMass, PhysicsWorld, Pose, RigidBodyBuilder,
    RigidBodyHandle, SpringJointBuilder,
};
use tumble_core::BodyState;
use tumble_core::math::{Narrow, Quat, Real, Vec3, Widen};

use crate::rapier_springs::{RapierSprings, spring_force};
use crate::scene::{ComparisonScene, ComparisonSpringEnd, Load};

/// rapier links `parry3d` in `f32`: tumble's numbers are rounded to `f32` on the way in (exact in
/// the default build, one rounding in an `f64` build) and widened exactly on the way out.
fn vec_in(v: Vec3) -> glam::Vec3 {
    v.widen().as_vec3()
}

/// A rotation into rapier's `f32`.
fn quat_in(q: Quat) -> glam::Quat {
    q.widen().as_quat()
}

/// A scalar into rapier's `f32`.
fn real_in(x: Real) -> f32 {
    x.widen() as f32
}

/// A vector out of rapier, in tumble's precision.
fn vec_out(v: glam::Vec3) -> Vec3 {
    v.as_dvec3().narrow()
}

/// A rotation out of rapier, in tumble's precision.
fn quat_out(q: glam::Quat) -> Quat {
    q.as_dquat().narrow()
}

/// A rapier world holding the bodies (and springs) of a [`ComparisonScene`].
pub struct RapierScene {
    world: PhysicsWorld,
    handles: Vec<RigidBodyHandle>,
    loads: Vec<Vec<Load>>,
    any_loads: bool,
    local_com: Vec<Vec3>,
    /// The scene, kept when its springs are forces added by hand every step.
    spring_forces: Option<ComparisonScene>,
}

impl RapierScene {
    /// Builds the scene with rapier's gyroscopic term on or off and the given number of solver
    /// iterations (= substeps for free bodies; rapier's default is 4); springs, if any, as
    /// [`RapierSprings::Joint`].
    pub fn new(scene: &ComparisonScene, gyroscopic: bool, solver_iterations: usize) -> Self {
        Self::with_springs(scene, gyroscopic, solver_iterations, RapierSprings::Joint)
    }

    /// [`new`](Self::new) with the springs built as `springs` says.
    ///
    /// As joints, each spring is a `SpringJointBuilder::new(L₀, k, c)` with
    /// `local_anchor1/2` = the scene's anchors (both conventions are relative to the body
    /// origin) and rapier's default spring model (`MotorModel::ForceBased`: `k` and `c` are the
    /// physical constants); a world end is a fixed body at the world point, anchor 0. As
    /// forces, every step resets each body's forces and adds its loads and, at the current
    /// anchors, `F_a = −(k (ℓ − L₀) + c (u·n)) n` to `a` and `−F_a` to `b`
    /// (`add_force_at_point`), held over rapier's substeps.
    ///
    /// # Panics
    /// If a spring names a body index outside `scene.bodies`.
    pub fn with_springs(
        scene: &ComparisonScene,
        gyroscopic: bool,
        solver_iterations: usize,
        springs: RapierSprings,
    ) -> Self {
        let mut world = PhysicsWorld::new();
        world.gravity = vec_in(scene.gravity.unwrap_or(Vec3::ZERO));
        world.integration_parameters = IntegrationParameters {
            dt: real_in(scene.dt),
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
                vec_in(c),
                real_in(m.mass()),
                vec_in(m.principal_inertia()),
                quat_in(m.principal_frame()),
            );
            let builder = RigidBodyBuilder::dynamic()
                .pose(Pose::from_parts(
                    vec_in(origin),
                    quat_in(body.state.rotation),
                ))
                .linvel(vec_in(body.state.linear_velocity))
                .angvel(vec_in(body.state.angular_velocity))
                .additional_mass_properties(props)
                .gravity_scale(real_in(body.gravity_scale))
                // Same coefficients; rapier damps with the Padé form after its velocity update
                // (first order), tumble with a flow split around the step (second order).
                .linear_damping(real_in(body.linear_damping))
                .angular_damping(real_in(body.angular_damping))
                .gyroscopic_forces_enabled(gyroscopic)
                .can_sleep(false)
                .allow_fast_rotation(true);
            handles.push(world.insert_body(builder));
            loads.push(body.loads.clone());
            local_com.push(c);
        }
        let forces = springs == RapierSprings::Force && !scene.springs.is_empty();
        if springs == RapierSprings::Joint {
            for spring in &scene.springs {
                let (b, anchor_b) = match spring.b {
                    ComparisonSpringEnd::Body { body, anchor } => (handles[body], anchor),
                    ComparisonSpringEnd::World(p) => (
                        world.insert_body(RigidBodyBuilder::fixed().translation(vec_in(p))),
                        Vec3::ZERO,
                    ),
                };
                let joint = SpringJointBuilder::new(
                    real_in(spring.rest_length),
                    real_in(spring.stiffness),
                    real_in(spring.damping),
                )
                .local_anchor1(vec_in(spring.anchor_a))
                .local_anchor2(vec_in(anchor_b));
                world.insert_impulse_joint(handles[spring.a], b, joint);
            }
        }
        let mut rapier = Self {
            world,
            handles,
            any_loads: forces || loads.iter().any(|l| !l.is_empty()),
            loads,
            local_com,
            spring_forces: forces.then(|| scene.clone()),
        };
        rapier.apply_loads();
        rapier
    }

    /// Resets every body's forces and re-adds its loads at the current pose. Skipped when no
    /// body has a load: touching a body through `get_mut` flags it as modified, which would make
    /// rapier's step (and so the benchmark) do work a scene of free bodies never asks for.
    fn apply_loads(&mut self) {
        if !self.any_loads {
            return;
        }
        let states: Vec<BodyState> = match &self.spring_forces {
            Some(_) => (0..self.len()).map(|i| self.state(i)).collect(),
            None => Vec::new(),
        };
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
                    } => rb.add_force(vec_in(force), false),
                    Load::Force {
                        force,
                        local_point: Some(p),
                    } => {
                        let point = *rb.position() * vec_in(p);
                        rb.add_force_at_point(vec_in(force), point, false);
                    }
                    Load::Torque(torque) => rb.add_torque(vec_in(torque), false),
                }
            }
        }
        if let Some(scene) = &self.spring_forces {
            for spring in &scene.springs {
                let (force, pa, pb) = spring_force(scene, &states, spring);
                let (force, pa, pb) = (force.as_vec3(), pa.as_vec3(), pb.as_vec3());
                if let Some(rb) = self.world.bodies.get_mut(self.handles[spring.a]) {
                    rb.add_force_at_point(force, pa, false);
                }
                if let ComparisonSpringEnd::Body { body, .. } = spring.b
                    && let Some(rb) = self.world.bodies.get_mut(self.handles[body])
                {
                    rb.add_force_at_point(-force, pb, false);
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
        let rotation = quat_out(*rb.rotation());
        BodyState {
            position: vec_out(rb.translation()) + rotation * self.local_com[i],
            rotation,
            linear_velocity: vec_out(rb.linvel()),
            angular_velocity: vec_out(rb.angvel()),
        }
    }

    /// True when rapier quarantined body `i`: its state went non-finite, so rapier reset it to
    /// its last valid pose, zeroed its velocity and disabled it (rapier 0.36's `Quarantine`).
    /// Its state is then frozen and no longer part of the run.
    pub fn is_quarantined(&self, i: usize) -> bool {
        !self.world.bodies[self.handles[i]].is_enabled()
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
