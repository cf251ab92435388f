//! The integrate systems: thin loops over queries that call `tumble_core`.
//!
//! Each body is checked before it is stepped (game code may have written bad data through a
//! `&mut` borrow) and after (the method may have left its stable region); a failing body is
//! quarantined with [`Rejected`] and keeps its last valid state, and the others step on unharmed.

use bevy_ecs::prelude::*;
use tumble_core::Wrench;

use crate::components::{
    Damping, ForceAccumulator, Gravity, GravityScale, MassProps, PhysicsSettings, RigidBody,
    Transform, Velocity, body_state, write_body_state,
};
use crate::validate::{BodyError, BodyErrorKind, Rejected, check_body, reject};

/// Steps one body under `wrench`; on failure leaves it untouched and returns the error.
#[inline]
fn step_body(
    settings: &PhysicsSettings,
    transform: &mut Transform,
    velocity: &mut Velocity,
    mass: &MassProps,
    wrench: &Wrench,
    damping: Option<&Damping>,
) -> Result<(), BodyErrorKind> {
    let dt = settings.dt();
    let mut state = body_state(transform, velocity, mass);
    settings.integrator.try_step(&mut state, mass, wrench, dt)?;
    if let Some(d) = damping {
        // Padé damping v ← v / (1 + Δt c): unconditionally stable, as in rapier and avian.
        state.linear_velocity /= 1.0 + dt * d.linear;
        state.angular_velocity /= 1.0 + dt * d.angular;
    }
    write_body_state(&state, mass, transform, velocity);
    Ok(())
}

/// Integrates bodies that have a [`ForceAccumulator`], consuming (reading and zeroing) it.
pub fn integrate_with_forces(
    settings: Res<PhysicsSettings>,
    mut commands: Commands,
    mut bodies: Query<
        (
            Entity,
            &mut Transform,
            &mut Velocity,
            &MassProps,
            &mut ForceAccumulator,
            Option<&Damping>,
        ),
        (With<RigidBody>, Without<Rejected>),
    >,
) {
    for (entity, mut transform, mut velocity, mass, mut acc, damping) in &mut bodies {
        let result = check_body(&transform, &velocity, Some(&acc)).and_then(|()| {
            let wrench = acc.take();
            step_body(
                &settings,
                &mut transform,
                &mut velocity,
                mass,
                &wrench,
                damping,
            )
        });
        if let Err(kind) = result {
            reject(&mut commands, BodyError { entity, kind });
        }
    }
}

/// Integrates bodies without a [`ForceAccumulator`]: free motion, plus gravity when a
/// [`Gravity`] resource exists (a uniform field needs no accumulator).
pub fn integrate_without_forces(
    settings: Res<PhysicsSettings>,
    gravity: Option<Res<Gravity>>,
    mut commands: Commands,
    mut bodies: Query<
        (
            Entity,
            &mut Transform,
            &mut Velocity,
            &MassProps,
            Option<&GravityScale>,
            Option<&Damping>,
        ),
        (
            With<RigidBody>,
            Without<Rejected>,
            Without<ForceAccumulator>,
        ),
    >,
) {
    let g = gravity.map(|g| g.0);
    for (entity, mut transform, mut velocity, mass, scale, damping) in &mut bodies {
        let wrench = match g {
            Some(g) => Wrench {
                force: (mass.mass() * scale.map_or(1.0, |s| s.0)) * g,
                torque: glam::Vec3::ZERO,
            },
            None => Wrench::ZERO,
        };
        let result = check_body(&transform, &velocity, None).and_then(|()| {
            step_body(
                &settings,
                &mut transform,
                &mut velocity,
                mass,
                &wrench,
                damping,
            )
        });
        if let Err(kind) = result {
            reject(&mut commands, BodyError { entity, kind });
        }
    }
}
