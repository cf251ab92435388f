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

/// Which part of a step the integrate system performs for a body.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// The whole step (forces sampled at the start, or constant).
    Whole,
    /// The rest of a step whose first half-drift already ran in [`begin_step`].
    Finish,
}

/// Steps one body under `wrench`; on failure leaves it untouched and returns the error.
#[inline]
fn step_body(
    settings: &PhysicsSettings,
    phase: Phase,
    transform: &mut Transform,
    velocity: &mut Velocity,
    mass: &MassProps,
    wrench: &Wrench,
    damping: Option<&Damping>,
) -> Result<(), BodyErrorKind> {
    let dt = settings.dt();
    let mut state = body_state(transform, velocity, mass);
    match phase {
        Phase::Whole => settings.integrator.try_step(&mut state, mass, wrench, dt)?,
        Phase::Finish => settings
            .integrator
            .try_finish_step(&mut state, mass, wrench, dt)?,
    }
    if let Some(d) = damping {
        // Padé damping v ← v / (1 + Δt c): unconditionally stable, as in rapier and avian.
        state.linear_velocity /= 1.0 + dt * d.linear;
        state.angular_velocity /= 1.0 + dt * d.angular;
    }
    write_body_state(&state, mass, transform, velocity);
    Ok(())
}

/// Set by [`begin_step`] when it has drifted the bodies with accumulators half a step, so that
/// [`integrate_with_forces`] finishes the step instead of taking a whole one. Reset every step.
#[derive(Resource, Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct HalfDrifted(pub bool);

/// First phase of a drift–kick–drift step for bodies with a [`ForceAccumulator`]: half a drift
/// before the force systems run, so forces are sampled at the midpoint. Does nothing for methods
/// that sample forces at the start of the step. Bodies without an accumulator feel no
/// state-dependent force and take their whole step in [`integrate_without_forces`].
pub fn begin_step(
    settings: Res<PhysicsSettings>,
    mut drifted: ResMut<HalfDrifted>,
    mut commands: Commands,
    mut bodies: Query<
        (
            Entity,
            &mut Transform,
            &mut Velocity,
            &MassProps,
            &ForceAccumulator,
        ),
        (With<RigidBody>, Without<Rejected>),
    >,
) {
    if !settings.integrator.samples_forces_at_midpoint() {
        return;
    }
    drifted.0 = true;
    let dt = settings.dt();
    for (entity, mut transform, mut velocity, mass, acc) in &mut bodies {
        let result = check_body(&transform, &velocity, Some(acc)).and_then(|()| {
            let mut state = body_state(&transform, &velocity, mass);
            settings.integrator.try_begin_step(&mut state, mass, dt)?;
            write_body_state(&state, mass, &mut transform, &mut velocity);
            Ok(())
        });
        if let Err(kind) = result {
            reject(&mut commands, BodyError { entity, kind });
        }
    }
}

/// Integrates bodies that have a [`ForceAccumulator`], consuming (reading and zeroing) it.
///
/// For a drift–kick–drift method this finishes the step that [`begin_step`] began; if the
/// schedule was planned without `begin_step` (the integrator was changed afterwards) it takes the
/// whole step with the forces sampled at the start, and warns once.
pub fn integrate_with_forces(
    settings: Res<PhysicsSettings>,
    mut drifted: ResMut<HalfDrifted>,
    mut warned: Local<bool>,
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
    let phase = if drifted.0 {
        Phase::Finish
    } else {
        Phase::Whole
    };
    if settings.integrator.samples_forces_at_midpoint() && phase == Phase::Whole && !*warned {
        *warned = true;
        tracing::warn!(
            integrator = %settings.integrator,
            "schedule planned without begin_step: forces are sampled at the start of the step; \
             plan again after changing the integrator"
        );
    }
    drifted.0 = false;
    for (entity, mut transform, mut velocity, mass, mut acc, damping) in &mut bodies {
        let result = check_body(&transform, &velocity, Some(&acc)).and_then(|()| {
            let wrench = acc.take();
            step_body(
                &settings,
                phase,
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
                Phase::Whole,
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
