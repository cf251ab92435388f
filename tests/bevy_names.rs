//! tumble's prelude lives beside the preludes of the Bevy crates a game uses with it: every name
//! of `tumble::prelude` is used here after glob-importing all of them, so a name two preludes
//! share would be an ambiguity error (E0659) and this file would not compile. Bevy's own names
//! (`Transform`, `Vec3`, `Real`, `Time`) resolve to Bevy's.

// rustc reports some glob ambiguities as this lint (a future hard error) rather than E0659.
#![deny(ambiguous_glob_imports)]

use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use bevy_math::prelude::*;
use bevy_time::prelude::*;
use bevy_transform::prelude::*;
use tumble::math::to_f64;
use tumble::prelude::*;

/// Every type of tumble's prelude, named.
#[allow(clippy::type_complexity, dead_code)]
struct TumbleTypes(
    (
        RigidBody,
        Static,
        Kinematic,
        Pose,
        Velocity,
        MassProps,
        ForceAccumulator,
        Damping,
        Gravity,
        GravityScale,
        PhysicsSettings,
        ConstantForce,
        ConstantLocalForce,
        ConstantTorque,
    ),
    (
        Spring,
        SpringEnd,
        GeneratorError,
        GeneratorErrorKind,
        RejectedGenerator,
        SpringSolver,
        EnergyAudit,
        WorldChecksum,
        Parallelism,
        RollbackError,
        RollbackSnapshot,
        ForceSystems,
        PhysicsRunner,
        PhysicsPlan,
        PhysicsSet,
        PhysicsSystem,
    ),
    (
        StabilityWarning,
        FixedStepper,
        FrameSteps,
        BodyError,
        BodyErrorKind,
        PhysicsErrors,
        Rejected,
        Density,
        Integrator,
        Mass,
        MassProperties,
        BodyState,
        StepPhase,
        Wrench,
    ),
);

/// tumble's traits, named through the prelude.
#[allow(dead_code)]
fn takes_a_batch<B: BodyBatch, F: ApplyForces>(_: &B, _: &F) {}

/// tumble's query data, named through the prelude.
#[allow(dead_code)]
fn a_force_system(_: Query<BodyForces>) {}

#[test]
fn tumble_and_bevy_preludes_live_together() {
    // tumble's functions, named.
    let _ = world_checksum;
    let _ = check_stability;
    let _ = interpolate;
    #[cfg(feature = "parry")]
    let _ = mass_properties_of;
    // Bevy's names are Bevy's.
    let bevy_pose = Transform::from_translation(Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(bevy_pose.scale, Vec3::ONE);
    let _: Option<Time<Real>> = None;
    let _: Option<GlobalTransform> = None;
    let _ = App::new();
    let _: Option<World> = None;
    // The pose maps onto Bevy's `Transform` field for field.
    let pose = Pose::IDENTITY;
    let transform = Transform {
        translation: Vec3::new(
            to_f64(pose.translation.x) as f32,
            to_f64(pose.translation.y) as f32,
            to_f64(pose.translation.z) as f32,
        ),
        ..Transform::IDENTITY
    };
    assert_eq!(transform, Transform::IDENTITY);
}
