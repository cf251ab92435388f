//! Components and resources: the whole public data model of a tumble world.

use crate::stiff::SpringSolver;
use bevy_ecs::prelude::*;
use tumble_core::math::{Quat, Real, Vec3, Widen, quat_rotate};

use std::num::NonZeroU32;
use tumble_core::integrate::{FreeFlow, Stages};
use tumble_core::{BodyState, Integrator, InvalidInput, MassProperties};

use crate::validate::revalidate_body_hook;

/// Marks an entity as a rigid body. Only entities with this marker are touched by the physics
/// systems, so resources and other entities never are.
///
/// Requires [`Pose`] and [`Velocity`] (inserted with their defaults when missing: identity
/// pose, at rest). [`MassProps`] is the game's to give: a dynamic body without one is never
/// stepped silently with a made-up mass — before its first step it gets 1 kg with unit
/// principal moments, the [`AssumedMass`] marker and a warning naming it, once (see
/// [`assume_missing_masses`]). [`Static`] and [`Kinematic`] bodies, whose mass no step uses
/// for their own motion, get the default quietly.
#[derive(Component, Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[require(Pose, Velocity)]
#[component(on_remove = crate::generator_check::body_removed)]
pub struct RigidBody;

/// Marks a rigid body that never moves: it is never integrated (forces on it are discarded), but
/// springs may anchor to it and its mass properties still count where they are read.
#[derive(Component, Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[require(MassProps)]
pub struct Static;

/// Marks a rigid body that game code moves (by writing its [`Pose`] and [`Velocity`]): tumble
/// never integrates it and discards forces on it; springs attached to it see its pose and
/// velocity as the game sets them.
#[derive(Component, Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[require(MassProps)]
pub struct Kinematic;

/// Marks a dynamic body that was given no [`MassProps`] and is stepped with the default (1 kg,
/// unit principal moments); a warning named it when the marker was set. Inserting the body's
/// own `MassProps` does not remove the marker: remove it too, or better, give the mass when
/// spawning.
#[derive(Component, Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AssumedMass;

/// True when some rigid body has no [`MassProps`]: one pass over the archetypes, allocation-free
/// (the runner asks before every step).
pub fn bodies_without_mass(world: &World) -> bool {
    let Some(body) = world.component_id::<RigidBody>() else {
        return false;
    };
    let mass = world.component_id::<MassProps>();
    world
        .archetypes()
        .iter()
        .any(|a| !a.is_empty() && a.contains(body) && mass.is_none_or(|m| !a.contains(m)))
}

/// Gives every rigid body without [`MassProps`] the default (1 kg, unit principal moments) and
/// the [`AssumedMass`] marker, with a warning naming it: run by
/// [`PhysicsPlan::for_world`](crate::schedule::PhysicsPlan::for_world) and by the runner before
/// each step, so no body is stepped on a mass it was never given without a word.
pub fn assume_missing_masses(world: &mut World) {
    if !bodies_without_mass(world) {
        return;
    }
    let mut missing = world.query_filtered::<Entity, (With<RigidBody>, Without<MassProps>)>();
    let bodies: Vec<Entity> = missing.iter(world).collect();
    for body in bodies {
        tracing::warn!(
            entity = %body,
            "rigid body {body} has no MassProps: stepped as 1 kg with unit principal moments \
             (marked AssumedMass); give it MassProps(MassProperties::…) when spawning"
        );
        world
            .entity_mut(body)
            .insert((MassProps::default(), AssumedMass));
    }
}

/// Pose of the body origin in world coordinates: where the physics keeps a body.
///
/// The centre of mass sits at `translation + rotation * c`, with `c` the local centre of mass of
/// the body's [`MassProps`].
///
/// Named `Pose`, not `Transform`, so that it lives beside Bevy's `Transform` (which every Bevy
/// game has in scope) without ambiguity. It maps onto Bevy's `Transform` field for field —
/// `translation` and `rotation` are the same, and a rigid body has scale 1 — so rendering code
/// copies them (interpolated between fixed steps with
/// [`interpolate`](crate::stepper::interpolate)) into the entity's `Transform`.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[component(on_insert = revalidate_body_hook)]
pub struct Pose {
    /// World position of the body origin (m).
    pub translation: Vec3,
    /// Orientation, body → world; must stay a unit quaternion.
    pub rotation: Quat,
}

impl Default for Pose {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Pose {
    /// At the origin, unrotated.
    pub const IDENTITY: Self = Self {
        translation: Vec3::ZERO,
        rotation: Quat::IDENTITY,
    };

    /// A pose at `translation` with `rotation` (unit quaternion).
    pub const fn new(translation: Vec3, rotation: Quat) -> Self {
        Self {
            translation,
            rotation,
        }
    }

    /// A pose at `translation`, unrotated.
    pub fn from_translation(translation: Vec3) -> Self {
        Self {
            translation,
            ..Self::IDENTITY
        }
    }

    /// A pose with `rotation` (unit quaternion), at the origin.
    pub fn from_rotation(rotation: Quat) -> Self {
        Self {
            rotation,
            ..Self::IDENTITY
        }
    }

    /// Returns this pose with its translation replaced.
    pub fn with_translation(self, translation: Vec3) -> Self {
        Self {
            translation,
            ..self
        }
    }

    /// World position of the centre of mass: `x = t + R c` (`t` itself when `c = 0`, as in
    /// [`body_state`]: the rotation of a zero vector adds only a signed zero).
    #[inline]
    pub fn center_of_mass(&self, mass: &MassProps) -> Vec3 {
        match com_offset(self.rotation, mass) {
            Some(offset) => self.translation + offset,
            None => self.translation,
        }
    }

    /// Maps a body-local point to world coordinates: `t + R p`.
    #[inline]
    pub fn transform_point(&self, local: Vec3) -> Vec3 {
        self.translation + quat_rotate(self.rotation, local)
    }
}

/// Velocity of the centre of mass and angular velocity, both in world coordinates.
#[derive(Component, Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[component(on_insert = revalidate_body_hook)]
pub struct Velocity {
    /// Linear velocity of the centre of mass `v` (m/s).
    pub linear: Vec3,
    /// Angular velocity `ω`, world frame (rad/s).
    pub angular: Vec3,
}

impl Velocity {
    /// At rest.
    pub const ZERO: Self = Self {
        linear: Vec3::ZERO,
        angular: Vec3::ZERO,
    };

    /// A linear and an angular (world frame) velocity.
    pub const fn new(linear: Vec3, angular: Vec3) -> Self {
        Self { linear, angular }
    }

    /// A linear velocity only.
    pub fn linear(linear: Vec3) -> Self {
        Self {
            linear,
            angular: Vec3::ZERO,
        }
    }

    /// An angular velocity (world frame) only.
    pub fn angular(angular: Vec3) -> Self {
        Self {
            linear: Vec3::ZERO,
            angular,
        }
    }
}

/// Mass properties of a body. Valid by construction: a [`MassProperties`] can only be built
/// through its checked constructors, so mass ≤ 0, NaN or negative inertia never reach the world.
///
/// Immutable: to change the mass, insert a new `MassProps`.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[component(immutable)]
pub struct MassProps(pub MassProperties);

impl Default for MassProps {
    /// 1 kg with unit principal moments (1 kg·m²) and the centre of mass at the origin.
    fn default() -> Self {
        let one = tumble_core::Mass::new(1.0).expect("1 kg is a valid mass");
        Self(MassProperties::new(one, Vec3::ONE).expect("unit inertia is valid"))
    }
}

impl std::ops::Deref for MassProps {
    type Target = MassProperties;
    fn deref(&self) -> &MassProperties {
        &self.0
    }
}

impl From<MassProperties> for MassProps {
    fn from(value: MassProperties) -> Self {
        Self(value)
    }
}

/// Net force and torque (about the centre of mass, world frame) to apply in the next step.
///
/// **Opt-in:** a body takes loads from game code only with an accumulator (a body without one
/// takes the cheaper force-free path). Spawn it with `ForceAccumulator::default()`, or apply
/// loads through [`ApplyForces`](crate::body_forces::ApplyForces) on the entity
/// (`world.entity_mut(body).apply_force(..)`), which inserts it when missing; force generators
/// insert it on their bodies. [`BodyForces`](crate::body_forces::BodyForces) adds loads in
/// world or body coordinates and at points, with the centre of mass taken from the body.
///
/// **Clearing rule:** the integrator *consumes* the accumulator: it reads it and resets it to zero
/// in the same pass. So a force that game code adds between two steps is applied in the next
/// step exactly once, and nothing needs to clear it at the start of a step.
///
/// **Stages** (substeps, `yoshida4`'s composition: see [`PhysicsSettings::substeps`]): the force
/// stage — gravity, the force generators and game systems in
/// [`PhysicsSet::Forces`](crate::schedule::PhysicsSet::Forces) — runs in every stage, on the
/// state of that stage, and its forces act for that stage. What game code added *before* the
/// step is held constant over the whole step (in [`HeldLoad`]) and applied in every stage for
/// that stage's span, so it is applied exactly once in total: its impulse is `F Δt`, whatever the
/// number of stages.
#[derive(Component, Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[component(on_insert = revalidate_body_hook)]
#[require(HeldLoad)]
pub struct ForceAccumulator {
    /// Accumulated force `ΣF` (N), world frame.
    pub force: Vec3,
    /// Accumulated torque `Στ` about the centre of mass (N·m), world frame.
    pub torque: Vec3,
}

impl ForceAccumulator {
    /// Adds a force through the centre of mass (no torque).
    #[inline]
    pub fn add_force(&mut self, force: Vec3) {
        self.force += force;
    }

    /// Adds a pure torque (world frame).
    #[inline]
    pub fn add_torque(&mut self, torque: Vec3) {
        self.torque += torque;
    }

    /// Adds a force applied at a world point: the force, plus the torque `(p − x) × F` about the
    /// centre of mass `x` (see [`Pose::center_of_mass`]).
    ///
    /// The lever arm is formed before the cross product, so a body far from the world origin
    /// loses no precision to cancellation.
    #[inline]
    pub fn add_force_at_point(&mut self, force: Vec3, world_point: Vec3, center_of_mass: Vec3) {
        self.force += force;
        self.torque += (world_point - center_of_mass).cross(force);
    }

    /// Returns the accumulated load and resets the accumulator to zero.
    #[inline]
    pub fn take(&mut self) -> tumble_core::Wrench {
        let wrench = tumble_core::Wrench {
            force: self.force,
            torque: self.torque,
        };
        *self = Self::default();
        wrench
    }
}

/// The load game code put in a body's [`ForceAccumulator`] before a step of several stages,
/// held over the step and applied again in every stage after the first (see the accumulator's
/// clearing rule). Written by the step itself at the start of every step of several stages, and
/// only then; it comes with every accumulator (a required component), so holding the load never
/// changes a body's archetype. A step of one stage never reads or writes it.
#[derive(Component, Debug, Clone, Copy, PartialEq, Default)]
pub struct HeldLoad {
    /// Held force (N), world frame.
    pub force: Vec3,
    /// Held torque about the centre of mass (N·m), world frame.
    pub torque: Vec3,
}

/// Multiplies the world [`Gravity`] for one body (1 = normal, 0 = none, −1 = reversed).
#[derive(Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct GravityScale(pub Real);

impl Default for GravityScale {
    fn default() -> Self {
        Self(1.0)
    }
}

/// Velocity damping `v̇ = −c_lin v`, `ω̇ = −c_ang ω`, as a flow of its own, Strang-split around
/// the step: for half a step before it and half a step after it,
///
/// ```text
/// v ← decay(c_lin Δt/2) v,   ω ← decay(c_ang Δt/2) ω,   decay(x) = 1/(1 + x + x²/2 + x³/6)
/// ```
///
/// (`decay(x) = e^{−x} + O(x⁴)`, in `(0, 1]`, no platform `exp`: see
/// [`tumble_core::damping`]). The symmetric split keeps the drift–kick–drift integrators second
/// order, and the velocities only shrink, for any `cΔt`. Coefficients in 1/s, `>= 0`.
///
/// rapier and avian apply the Padé form `v ← v / (1 + Δt c)` once after the velocity update
/// (first order); the two agree to `O(c²Δt²)` per step.
#[derive(Component, Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Damping {
    /// Linear coefficient `c_lin` (1/s).
    pub linear: Real,
    /// Angular coefficient `c_ang` (1/s).
    pub angular: Real,
}

/// Uniform gravitational acceleration `g` (m/s²). Absent resource ⇒ no gravity system at all.
#[derive(Resource, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Gravity(pub Vec3);

impl Gravity {
    /// Earth gravity along −y: `(0, −9.81, 0)`.
    pub const EARTH_Y_DOWN: Self = Self(Vec3::new(0.0, -9.81, 0.0));
}

/// The step size and integrator of a world. The time step is validated on construction and the
/// field is private, so a world never holds `Δt ≤ 0` or a non-finite `Δt`.
#[derive(Resource, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "PhysicsSettingsData", into = "PhysicsSettingsData")
)]
pub struct PhysicsSettings {
    dt: Real,
    /// The integration method for every body of the world.
    pub integrator: Integrator,
    /// How springs are stepped: [`SpringSolver::Auto`] (the default) steps the spring groups
    /// that are stiff for `dt` with the energy-conserving implicit step and the others with the
    /// integrator (see [`crate::stiff`]).
    pub springs: SpringSolver,
    /// Substeps per step, `N` (default 1): every step is `N` substeps of `Δt/N`, each running
    /// the force stage afresh (see [`Stages`]); `N` substeps of `Δt` are bit for bit `N` steps of
    /// `Δt/N`, except that a load game code added before the step is held over all of them
    /// (see [`ForceAccumulator`]). Costs `N` times the step; use it when a force changes
    /// faster than the step resolves (a stiff contact-like spring, a control loop), not for
    /// accuracy alone — `yoshida4` is the cheaper way to a small error.
    pub substeps: NonZeroU32,
    /// Which free rotation a split method (`splitting`, `splitting-xyz`, `yoshida4`) gives each
    /// body: under [`FreeFlow::Auto`] (the default) a body whose split free rotation would err by
    /// more than [`SPLIT_ERROR_LIMIT`](tumble_core::integrate::SPLIT_ERROR_LIMIT) in a stage
    /// (a fast spin, a thin body) takes the exact free flow of the same step for that stage
    /// (`exact`, `exact4`), and the planner says which bodies do; [`FreeFlow::Method`] keeps
    /// the method's own flow for every body (see [`tumble_core::integrate::FreeFlow`]).
    pub free_flow: FreeFlow,
}

impl PhysicsSettings {
    /// Settings with time step `dt` (s) and the given integrator; rejects `dt ≤ 0` and NaN/Inf.
    pub fn new(dt: Real, integrator: Integrator) -> Result<Self, InvalidInput> {
        tumble_core::error::check_time_step(dt)?;
        Ok(Self {
            dt,
            integrator,
            springs: SpringSolver::Auto,
            substeps: NonZeroU32::MIN,
            free_flow: FreeFlow::Auto,
        })
    }

    /// The same settings with `substeps` substeps per step.
    pub fn with_substeps(mut self, substeps: NonZeroU32) -> Self {
        self.substeps = substeps;
        self
    }

    /// The stages of one step: the substeps times the integrator's composition.
    #[inline]
    pub fn stages(&self) -> Stages {
        Stages::new(self.integrator, self.substeps)
    }

    /// The same settings with split methods' free rotation chosen as `free_flow` says.
    pub fn with_free_flow(mut self, free_flow: FreeFlow) -> Self {
        self.free_flow = free_flow;
        self
    }

    /// The same settings with springs stepped as `springs` says.
    pub fn with_springs(mut self, springs: SpringSolver) -> Self {
        self.springs = springs;
        self
    }

    /// The fixed time step `Δt` (s).
    #[inline]
    pub fn dt(&self) -> Real {
        self.dt
    }

    /// Changes the time step; rejects `dt ≤ 0` and NaN/Inf and then leaves the settings unchanged.
    pub fn set_dt(&mut self, dt: Real) -> Result<(), InvalidInput> {
        tumble_core::error::check_time_step(dt)?;
        self.dt = dt;
        Ok(())
    }
}

/// The saved form of [`PhysicsSettings`], checked on load.
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct PhysicsSettingsData {
    dt: Real,
    integrator: Integrator,
    #[serde(default)]
    springs: SpringSolver,
    #[serde(default = "one_substep")]
    substeps: NonZeroU32,
    #[serde(default)]
    free_flow: FreeFlow,
}

#[cfg(feature = "serde")]
fn one_substep() -> NonZeroU32 {
    NonZeroU32::MIN
}

#[cfg(feature = "serde")]
impl TryFrom<PhysicsSettingsData> for PhysicsSettings {
    type Error = InvalidInput;
    fn try_from(d: PhysicsSettingsData) -> Result<Self, InvalidInput> {
        Ok(PhysicsSettings::new(d.dt, d.integrator)?
            .with_springs(d.springs)
            .with_substeps(d.substeps)
            .with_free_flow(d.free_flow))
    }
}

#[cfg(feature = "serde")]
impl From<PhysicsSettings> for PhysicsSettingsData {
    fn from(s: PhysicsSettings) -> Self {
        Self {
            dt: s.dt,
            integrator: s.integrator,
            springs: s.springs,
            substeps: s.substeps,
            free_flow: s.free_flow,
        }
    }
}

impl Default for PhysicsSettings {
    /// 60 Hz with the default integrator.
    fn default() -> Self {
        Self {
            dt: 1.0 / 60.0,
            integrator: Integrator::default(),
            springs: SpringSolver::Auto,
            substeps: NonZeroU32::MIN,
            free_flow: FreeFlow::Auto,
        }
    }
}

/// The world offset `R c` of the centre of mass from the body origin, or `None` when the centre
/// of mass is the origin (the common case, which then costs no arithmetic at all).
///
/// Skipping the arithmetic matters beyond the saved work: `Pose` has 4 bytes of padding
/// after its `Vec3`, and compiled vector code may add a whole 16-byte lane including whatever
/// bits sit there; when they happen to be a subnormal float pattern every such add takes a
/// microcode assist (over twenty times the cost of the add).
///
/// The test is the flag the mass properties keep ([`MassProperties::has_center_of_mass_offset`]),
/// not three float compares on every read and write of every body.
#[inline]
fn com_offset(rotation: Quat, mass: &MassProps) -> Option<Vec3> {
    mass.has_center_of_mass_offset()
        .then(|| quat_rotate(rotation, mass.local_center_of_mass()))
}

/// Kinetic energy `½ m |v|² + ½ ωᵀ I ω` (J) of a body, in `f64` (energy balances sum many
/// bodies; [`tumble_core::invariants::kinetic_energy`] is the same in the engine's precision).
pub fn kinetic_energy_f64(transform: &Pose, velocity: &Velocity, mass: &MassProps) -> f64 {
    let v = velocity.linear.widen();
    let rotational = mass.world_inertia_quadratic_f64(transform.rotation, velocity.angular);
    0.5 * mass.mass().widen() * v.length_squared() + 0.5 * rotational
}

/// Reads a body's core state (centre-of-mass position) from its components.
#[inline]
pub fn body_state(transform: &Pose, velocity: &Velocity, mass: &MassProps) -> BodyState {
    let t = transform.translation;
    let position = match com_offset(transform.rotation, mass) {
        Some(offset) => Vec3::new(t.x + offset.x, t.y + offset.y, t.z + offset.z),
        None => t,
    };
    BodyState {
        position,
        rotation: transform.rotation,
        linear_velocity: velocity.linear,
        angular_velocity: velocity.angular,
    }
}

/// Writes a core state back to a body's components (origin = `x − R c`).
#[inline]
pub fn write_body_state(
    state: &BodyState,
    mass: &MassProps,
    transform: &mut Pose,
    velocity: &mut Velocity,
) {
    transform.rotation = state.rotation;
    let x = state.position;
    transform.translation = match com_offset(state.rotation, mass) {
        Some(offset) => Vec3::new(x.x - offset.x, x.y - offset.y, x.z - offset.z),
        None => x,
    };
    velocity.linear = state.linear_velocity;
    velocity.angular = state.angular_velocity;
}
