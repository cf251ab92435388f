//! The components of a rigid body, and the checks that keep bad data out of them.

use bevy_ecs::lifecycle::HookContext;
use bevy_ecs::prelude::*;
use bevy_ecs::world::DeferredWorld;
use tumble_core::error::is_clearly_unit;
use tumble_core::math::{Quat, Real, Vec3, Widen, quat_rotate};
use tumble_core::{BodyState, InvalidInput, MassProperties};

use bevy_ecs::system::SystemParam;

use super::errors::{BodyError, BodyErrorKind, PhysicsErrors, Rejected, StepRefusals};

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
#[component(on_remove = body_removed)]
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
/// [`interpolate`](crate::schedule::interpolate)) into the entity's `Transform`.
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
/// loads through [`ApplyForces`](crate::forces::ApplyForces) on the entity
/// (`world.entity_mut(body).apply_force(..)`), which inserts it when missing; force generators
/// insert it on their bodies. [`BodyForces`](crate::forces::BodyForces) adds loads in
/// world or body coordinates and at points, with the centre of mass taken from the body.
///
/// **Clearing rule:** the integrator *consumes* the accumulator: it reads it and resets it to zero
/// in the same pass. So a force that game code adds between two steps is applied in the next
/// step exactly once, and nothing needs to clear it at the start of a step.
///
/// **Stages** (substeps, `yoshida4`'s composition: see [`PhysicsSettings::substeps`](super::PhysicsSettings::substeps)): the force
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
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct HeldLoad {
    /// Held force (N), world frame.
    pub force: Vec3,
    /// Held torque about the centre of mass (N·m), world frame.
    pub torque: Vec3,
}

/// Multiplies the world [`Gravity`](super::Gravity) for one body (1 = normal, 0 = none, −1 = reversed).
#[derive(Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct GravityScale(pub Real);

impl Default for GravityScale {
    fn default() -> Self {
        Self(1.0)
    }
}

impl GravityScale {
    /// Checks that the scale is finite: a NaN or infinite one would make the body's gravity
    /// (and so its state) non-finite, and the fault is the scale's, not the accumulator's or
    /// the integrator's. The step checks it while a gravity field applies (a finite
    /// [`Gravity`](super::Gravity)); without one the scale is unused and harms nothing.
    #[inline]
    pub fn check(&self) -> Result<(), BodyErrorKind> {
        if self.0.is_finite() {
            return Ok(());
        }
        Err(BodyErrorKind::Invalid {
            component: "GravityScale",
            source: InvalidInput::NonFinite {
                field: "scale",
                value: self.0.to_string(),
            },
        })
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

impl Damping {
    /// Checks that both coefficients are finite and `>= 0`: the flow treats a negative or NaN
    /// rate as no damping (never growth), so a bad one would otherwise be ignored silently.
    #[inline]
    pub fn check(&self) -> Result<(), BodyErrorKind> {
        let invalid = |source| BodyErrorKind::Invalid {
            component: "Damping",
            source,
        };
        tumble_core::error::check_non_negative("linear", self.linear).map_err(invalid)?;
        tumble_core::error::check_non_negative("angular", self.angular).map_err(invalid)
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

/// Checks the body data of a [`Pose`], [`Velocity`] and optional [`ForceAccumulator`].
///
/// Runs in the insert hooks, on the bodies tumble never steps (`check_fixed_bodies`), on each
/// body of a stiff group before its solve, and on every body whose batched step failed (to name
/// the bad field), so valid data takes an inlined fast test (finite values, unit
/// quaternion within [`UNIT_QUATERNION_TOLERANCE`](tumble_core::error::UNIT_QUATERNION_TOLERANCE));
/// only bad data goes through the detailed checks that build the error.
#[inline]
pub fn check_body(
    transform: &Pose,
    velocity: &Velocity,
    forces: Option<&ForceAccumulator>,
) -> Result<(), BodyErrorKind> {
    // Branch-free, as `BodyState::is_finite`: `0 · x` is 0 for finite x and NaN otherwise, and
    // one NaN makes the sum NaN. (The rotation's finiteness is part of the unit test below.)
    let mut zeros = transform.translation * 0.0 + velocity.linear * 0.0 + velocity.angular * 0.0;
    if let Some(acc) = forces {
        zeros += acc.force * 0.0 + acc.torque * 0.0;
    }
    let finite = zeros.x + zeros.y + zeros.z == 0.0;
    // The rare quaternion `is_clearly_unit` leaves open goes through the exact test in the
    // detailed checks.
    if finite && is_clearly_unit(transform.rotation) {
        return Ok(());
    }
    check_body_in_detail(transform, velocity, forces)
}

/// The part of [`check_body`] a batched step makes before it steps a body: the rotation is a unit
/// quaternion within [`UNIT_QUATERNION_TOLERANCE`](tumble_core::error::UNIT_QUATERNION_TOLERANCE)
/// (and finite). Every method normalizes the rotation it writes, so a step cannot be trusted to
/// show a non-unit one. The translation and velocities need no test before the step: a
/// non-finite value in them reaches the stepped state through IEEE arithmetic (every method
/// moves the position by the velocity, and the rotation by the angular velocity), the step's
/// result then fails its own check, and [`check_body`] on the untouched components names the
/// field (see the integrate systems).
#[inline]
pub(crate) fn check_rotation(transform: &Pose) -> Result<(), BodyErrorKind> {
    if is_clearly_unit(transform.rotation) {
        return Ok(());
    }
    check_body_in_detail(transform, &Velocity::ZERO, None)
}

/// The detailed checks behind [`check_body`], naming the component and field at fault.
#[cold]
fn check_body_in_detail(
    transform: &Pose,
    velocity: &Velocity,
    forces: Option<&ForceAccumulator>,
) -> Result<(), BodyErrorKind> {
    use tumble_core::error::{check_finite_vec3, check_unit_quat};
    let invalid = |component| move |source| BodyErrorKind::Invalid { component, source };
    check_finite_vec3("translation", transform.translation).map_err(invalid("Pose"))?;
    check_unit_quat("rotation", transform.rotation).map_err(invalid("Pose"))?;
    check_finite_vec3("linear velocity", velocity.linear).map_err(invalid("Velocity"))?;
    check_finite_vec3("angular velocity", velocity.angular).map_err(invalid("Velocity"))?;
    match forces {
        Some(acc) => check_accumulator_in_detail(acc),
        None => Ok(()),
    }
}

/// Checks that a [`ForceAccumulator`] holds finite values (an inlined test; only bad values go
/// through the checks that build the error).
#[inline]
pub fn check_accumulator(acc: &ForceAccumulator) -> Result<(), BodyErrorKind> {
    if acc.force.is_finite() && acc.torque.is_finite() {
        return Ok(());
    }
    check_accumulator_in_detail(acc)
}

/// The detailed checks behind [`check_accumulator`], naming the field at fault.
#[cold]
fn check_accumulator_in_detail(acc: &ForceAccumulator) -> Result<(), BodyErrorKind> {
    use tumble_core::error::check_finite_vec3;
    let invalid = |source| BodyErrorKind::Invalid {
        component: "ForceAccumulator",
        source,
    };
    check_finite_vec3("force", acc.force).map_err(invalid)?;
    check_finite_vec3("torque", acc.torque).map_err(invalid)
}

/// How a step's system refuses a body: the quarantine ([`Rejected`] and the [`PhysicsErrors`]
/// record) as a deferred command, and the entity at once in [`StepRefusals`] where the energy
/// audit keeps one, so that the audit's verdict later in the same step already knows.
#[derive(SystemParam)]
pub struct Refusals<'w, 's> {
    commands: Commands<'w, 's>,
    step: Option<ResMut<'w, StepRefusals>>,
}

impl Refusals<'_, '_> {
    /// Refuses the body `error` names. One incident is one record: a step's systems see only
    /// bodies without [`Rejected`], so a body that has one when this command applies was
    /// refused earlier in the same step (a stage's first phase, say, before the force stage
    /// added to the bad force its second phase finds), and that first record stands.
    pub(crate) fn refuse(&mut self, error: BodyError) {
        if let Some(step) = self.step.as_mut() {
            step.push(error.entity);
        }
        self.commands.queue(move |world: &mut World| {
            if world.get::<Rejected>(error.entity).is_none() {
                quarantine(world, error);
            }
        });
    }
}

/// Quarantines `entity`: logs the error, records it in [`PhysicsErrors`] and inserts
/// [`Rejected`]. Used by the hooks (the step's systems refuse through [`Refusals`]).
///
/// One incident is one record: a body already quarantined for the same reason (several hooks
/// of one insertion see the same bad data) is neither logged nor recorded again.
pub(crate) fn reject(commands: &mut Commands, error: BodyError) {
    commands.queue(move |world: &mut World| {
        let same = world
            .get::<Rejected>(error.entity)
            .is_some_and(|r| r.0 == error);
        if !same {
            quarantine(world, error);
        }
    });
}

/// Logs `error`, inserts [`Rejected`] on its body and records it in [`PhysicsErrors`]; nothing
/// for a despawned body.
fn quarantine(world: &mut World, error: BodyError) {
    let Ok(mut entity) = world.get_entity_mut(error.entity) else {
        return;
    };
    tracing::warn!(entity = %error.entity, "{error}");
    entity.insert(Rejected(error.clone()));
    world
        .get_resource_or_init::<PhysicsErrors>()
        .bodies
        .push(error);
}

/// Component hook: re-checks the whole body whenever one of its state components is inserted.
pub(crate) fn revalidate_body_hook(mut world: DeferredWorld, ctx: HookContext) {
    let entity = ctx.entity;
    if world.get::<RigidBody>(entity).is_none() {
        return;
    }
    let (Some(transform), Some(velocity)) =
        (world.get::<Pose>(entity), world.get::<Velocity>(entity))
    else {
        return; // the rest of the bundle is still being inserted; its own hook will check.
    };
    let result = check_body(transform, velocity, world.get::<ForceAccumulator>(entity));
    let was_rejected = world.get::<Rejected>(entity).is_some();
    let mut commands = world.commands();
    match result {
        Err(kind) => reject(&mut commands, BodyError { entity, kind }),
        Ok(()) if was_rejected => {
            commands.entity(entity).remove::<Rejected>();
        }
        Ok(()) => {}
    }
}

/// Bodies that lost their [`RigidBody`](crate::components::RigidBody) marker (removed or
/// despawned) since the runner last looked: their generators are left out before the next step.
#[derive(Resource, Debug, Default)]
pub(crate) struct RemovedBodies(pub(crate) Vec<Entity>);

/// Component hook of [`RigidBody`](crate::components::RigidBody): remembers the body for the
/// runner's next check.
pub(crate) fn body_removed(mut world: DeferredWorld, ctx: HookContext) {
    let entity = ctx.entity;
    world.commands().queue(move |world: &mut World| {
        world.get_resource_or_init::<RemovedBodies>().0.push(entity);
    });
}
