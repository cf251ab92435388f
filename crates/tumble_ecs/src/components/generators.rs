//! The force generator components, with the checks that keep them valid.

use bevy_ecs::lifecycle::HookContext;
use bevy_ecs::prelude::*;
use bevy_ecs::world::DeferredWorld;
use tumble_core::math::{Real, Vec3, Widen};

use super::body::ForceAccumulator;
use super::errors::{GeneratorError, GeneratorErrorKind, PhysicsErrors, RejectedGenerator};

/// A constant world-frame force on `body`, through a body-local point (or the centre of mass).
#[derive(Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[component(on_insert = generator_inserted::<ConstantForce>)]
pub struct ConstantForce {
    /// The body that receives the force.
    pub body: Entity,
    /// Force `F` (N), world frame.
    pub force: Vec3,
    /// Point of application in body coordinates; `None` = the centre of mass (no torque).
    /// Otherwise the torque `(p − x) × F` is added, with `p` the point in world coordinates.
    pub local_point: Option<Vec3>,
}

/// A constant force given in the body's own frame, so that it turns with the body (a thruster
/// fixed to a hull), through a body-local point or the centre of mass: in the world it is
/// `R f`, at `x + R p`, with `R` the body's rotation at the stage where forces are sampled.
///
/// For a body stepped by an implicit spring group (see [`crate::springs`]) the force's world
/// direction is taken once per stage, where the force stage samples it, and held over that
/// stage: first order in the body's turn over the stage, where a body-frame force is exact
/// for every explicit method.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[component(on_insert = generator_inserted::<ConstantLocalForce>)]
pub struct ConstantLocalForce {
    /// The body that receives the force.
    pub body: Entity,
    /// Force `f` (N), body frame.
    pub force: Vec3,
    /// Point of application in body coordinates; `None` = the centre of mass (no torque).
    pub local_point: Option<Vec3>,
}

/// A constant world-frame torque on `body`.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[component(on_insert = generator_inserted::<ConstantTorque>)]
pub struct ConstantTorque {
    /// The body that receives the torque.
    pub body: Entity,
    /// Torque `τ` (N·m), world frame.
    pub torque: Vec3,
}

/// The second end of a [`Spring`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum SpringEnd {
    /// A point fixed in the world (m).
    World(Vec3),
    /// A body-local point of another body.
    Body {
        /// The other body.
        body: Entity,
        /// Anchor in that body's coordinates.
        anchor: Vec3,
    },
}

impl SpringEnd {
    /// The point `anchor` (body coordinates) of `body`.
    pub const fn on_body(body: Entity, anchor: Vec3) -> Self {
        Self::Body { body, anchor }
    }
}

/// A damped linear spring between a point of body `a` and a second end.
///
/// With anchors `p_a`, `p_b` in world coordinates, `d = p_a − p_b`, `n = d/|d|` and the relative
/// anchor velocity `u = ṗ_a − ṗ_b`, the force on `a` is
/// `F_a = −(k (|d| − L₀) + c (u·n)) n` and `b` receives `−F_a`, each at its anchor (so with the
/// matching torques). At `|d| = 0` the direction is undefined and no force is applied.
///
/// The two parts are integrated differently. The elastic force `−k (|d| − L₀) n` is a force
/// generator ([`apply_springs`](crate::forces::apply_springs), sampled where the integrator samples forces). The damper
/// `−c (u·n) n` is a velocity flow of its own, exact for this spring alone
/// (`u·n ← e^{−cτ/m_eff} u·n` with the effective mass of the two anchors along `n`), applied
/// for half a step before and half a step after the step (see [`crate::springs`]): the damped
/// step stays second order with the drift–kick–drift integrators and never adds energy, for any
/// `c Δt`.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[component(on_insert = generator_inserted::<Spring>)]
pub struct Spring {
    /// First body.
    pub a: Entity,
    /// Anchor on `a`, body coordinates.
    pub anchor_a: Vec3,
    /// The other end.
    pub b: SpringEnd,
    /// Stiffness `k` (N/m), `>= 0`.
    pub stiffness: Real,
    /// Damping `c` (N·s/m), `>= 0`, along the spring's axis (see [`crate::springs`]).
    pub damping: Real,
    /// Rest length `L₀` (m), `>= 0`.
    pub rest_length: Real,
}

impl Spring {
    /// An undamped spring from `anchor_a` (body coordinates) of `a` to `b`, with stiffness `k`
    /// (N/m) and rest length `L₀` (m); [`with_damping`](Self::with_damping) adds a damper.
    pub const fn new(
        a: Entity,
        anchor_a: Vec3,
        b: SpringEnd,
        stiffness: Real,
        rest_length: Real,
    ) -> Self {
        Self {
            a,
            anchor_a,
            b,
            stiffness,
            damping: 0.0,
            rest_length,
        }
    }

    /// This spring with the damping `c` (N·s/m).
    pub const fn with_damping(self, damping: Real) -> Self {
        Self { damping, ..self }
    }

    /// Elastic energy `½ k (|d| − L₀)²` (J) with the anchors at the world points `pa` and `pb`,
    /// in `f64` (energy balances sum many such terms).
    pub fn elastic_energy(&self, pa: Vec3, pb: Vec3) -> f64 {
        let stretch = (pa - pb).widen().length() - self.rest_length.widen();
        0.5 * self.stiffness.widen() * stretch * stretch
    }
}

/// Inserts a zero [`ForceAccumulator`] on every one of `bodies` that has none (a valid
/// generator's bodies: see [`crate::components`]).
pub(crate) fn ensure_accumulators(commands: &mut Commands, bodies: impl Iterator<Item = Entity>) {
    for body in bodies {
        if let Ok(mut e) = commands.get_entity(body) {
            e.insert_if_new(ForceAccumulator::default());
        }
    }
}

/// A force generator's checks.
pub(crate) trait Generator: Component + Copy {
    /// The type's name, as errors print it.
    const NAME: &'static str;

    /// Checks the values (finite, non-negative where the docs say so, distinct ends).
    fn check_values(&self) -> Result<(), GeneratorErrorKind>;

    /// The bodies the generator names, with the field that names each.
    fn bodies(&self) -> impl Iterator<Item = (&'static str, Entity)>;
}

fn finite(field: &'static str, value: Real) -> Result<(), GeneratorErrorKind> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(GeneratorErrorKind::NonFinite {
            field,
            value: value.to_string(),
        })
    }
}

fn finite_vec3(field: &'static str, value: Vec3) -> Result<(), GeneratorErrorKind> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(GeneratorErrorKind::NonFinite {
            field,
            value: value.to_string(),
        })
    }
}

fn non_negative(field: &'static str, value: Real) -> Result<(), GeneratorErrorKind> {
    finite(field, value)?;
    if value >= 0.0 {
        Ok(())
    } else {
        Err(GeneratorErrorKind::Negative { field, value })
    }
}

/// The values of a force through an optional body point (world or body frame alike).
fn force_at_point(force: Vec3, local_point: Option<Vec3>) -> Result<(), GeneratorErrorKind> {
    finite_vec3("force", force)?;
    match local_point {
        Some(p) => finite_vec3("local_point", p),
        None => Ok(()),
    }
}

/// The [`Generator`] of a type that acts on one body, its field `body`, with the values
/// checked by `$check` (`$g` the generator).
macro_rules! one_body_generator {
    ($name:ident, |$g:ident| $check:expr) => {
        impl Generator for $name {
            const NAME: &'static str = stringify!($name);

            fn check_values(&self) -> Result<(), GeneratorErrorKind> {
                let $g = self;
                $check
            }

            fn bodies(&self) -> impl Iterator<Item = (&'static str, Entity)> {
                std::iter::once(("body", self.body))
            }
        }
    };
}

one_body_generator!(ConstantForce, |g| force_at_point(g.force, g.local_point));
one_body_generator!(ConstantLocalForce, |g| force_at_point(
    g.force,
    g.local_point
));
one_body_generator!(ConstantTorque, |g| finite_vec3("torque", g.torque));

impl Generator for Spring {
    const NAME: &'static str = "Spring";

    fn check_values(&self) -> Result<(), GeneratorErrorKind> {
        finite_vec3("anchor_a", self.anchor_a)?;
        match self.b {
            SpringEnd::World(p) => finite_vec3("b", p)?,
            SpringEnd::Body { body, anchor } => {
                finite_vec3("b.anchor", anchor)?;
                if body == self.a {
                    return Err(GeneratorErrorKind::SelfSpring(body));
                }
            }
        }
        non_negative("stiffness", self.stiffness)?;
        non_negative("damping", self.damping)?;
        non_negative("rest_length", self.rest_length)?;
        if (self.stiffness * self.rest_length).is_finite() {
            Ok(())
        } else {
            Err(GeneratorErrorKind::ForceOverflow {
                stiffness: self.stiffness,
                rest_length: self.rest_length,
            })
        }
    }

    fn bodies(&self) -> impl Iterator<Item = (&'static str, Entity)> {
        let b = match self.b {
            SpringEnd::Body { body, .. } => Some(("b", body)),
            SpringEnd::World(_) => None,
        };
        std::iter::once(("a", self.a)).chain(b)
    }
}

/// The generator `g` of `entity` checked as on insert: values, then that its bodies exist
/// (`exists`).
pub(crate) fn check_inserted<G: Generator>(
    g: &G,
    exists: impl Fn(Entity) -> bool,
) -> Result<(), GeneratorErrorKind> {
    g.check_values()?;
    for (field, body) in g.bodies() {
        if !exists(body) {
            return Err(GeneratorErrorKind::MissingBody { field, body });
        }
    }
    Ok(())
}

/// Component hook of every generator: checks it, and either leaves it out of the step or
/// (valid) lifts an earlier rejection and gives its bodies accumulators.
pub(crate) fn generator_inserted<G: Generator>(mut world: DeferredWorld, ctx: HookContext) {
    let entity = ctx.entity;
    let Some(g) = world.get::<G>(entity).copied() else {
        return;
    };
    let result = check_inserted(&g, |body| world.get_entity(body).is_ok());
    let rejected = world.get::<RejectedGenerator>(entity).is_some();
    // Queued only where needed: a world spawned with its accumulators (a scene's, a million
    // generators at once) would otherwise queue a command per end.
    let lacks_accumulator = g.bodies().any(|(_, body)| {
        world
            .get_entity(body)
            .is_ok_and(|e| !e.contains::<ForceAccumulator>())
    });
    let mut commands = world.commands();
    match result {
        Err(kind) => {
            let error = GeneratorError {
                entity,
                generator: G::NAME,
                kind,
            };
            commands.queue(move |world: &mut World| reject_generator::<G>(world, error));
        }
        Ok(()) => {
            if rejected {
                commands.entity(entity).remove::<RejectedGenerator>();
            }
            if lacks_accumulator {
                crate::components::ensure_accumulators(&mut commands, g.bodies().map(|(_, b)| b));
            }
        }
    }
}

/// Leaves the generator `G` of `error.entity` out of the step: removes it, marks the entity,
/// logs the error and records it once.
pub(crate) fn reject_generator<G: Generator>(world: &mut World, error: GeneratorError) {
    let Ok(mut entity) = world.get_entity_mut(error.entity) else {
        return;
    };
    if entity.get::<G>().is_none() {
        return; // already left out (or replaced) since the check
    }
    entity.remove::<G>();
    entity.insert(RejectedGenerator(error.clone()));
    tracing::warn!(entity = %error.entity, "{error}");
    world
        .get_resource_or_init::<PhysicsErrors>()
        .generators
        .push(error);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spring() -> Spring {
        Spring::new(
            Entity::from_raw_u32(1).unwrap(),
            Vec3::ZERO,
            SpringEnd::World(Vec3::X),
            10.0,
            0.5,
        )
    }

    #[test]
    fn each_bad_spring_value_names_its_field() {
        let cases: [(fn(&mut Spring), &str); 6] = [
            (|s| s.stiffness = -1.0, "stiffness"),
            (|s| s.stiffness = Real::NAN, "stiffness"),
            (|s| s.damping = -0.5, "damping"),
            (|s| s.rest_length = Real::INFINITY, "rest_length"),
            (|s| s.anchor_a = Vec3::NAN, "anchor_a"),
            (|s| s.b = SpringEnd::World(Vec3::INFINITY), "b"),
        ];
        for (spoil, field) in cases {
            let mut s = spring();
            assert_eq!(s.check_values(), Ok(()));
            spoil(&mut s);
            match s.check_values() {
                Err(GeneratorErrorKind::NonFinite { field: f, .. })
                | Err(GeneratorErrorKind::Negative { field: f, .. }) => assert_eq!(f, field),
                other => panic!("{field}: {other:?}"),
            }
        }
        let mut s = spring();
        s.b = SpringEnd::on_body(s.a, Vec3::X);
        assert_eq!(s.check_values(), Err(GeneratorErrorKind::SelfSpring(s.a)));
        // Each value finite, but the force at zero length, k ℓ₀, overflows.
        let mut s = spring();
        s.stiffness = 100.0;
        s.rest_length = Real::MAX / 10.0;
        assert_eq!(
            s.check_values(),
            Err(GeneratorErrorKind::ForceOverflow {
                stiffness: 100.0,
                rest_length: Real::MAX / 10.0
            })
        );
        s.stiffness = 1.0;
        assert_eq!(s.check_values(), Ok(()), "k ℓ₀ = MAX / 10 is finite");
    }
}
