//! The ECS layer: components, force generators, the step's plan and runner, the energy audit,
//! stability predictions and the world's state (checksums, rollback, snapshots).
//!
//! The systems a step runs are not here: [`PhysicsPlan`](schedule::PhysicsPlan) adds them,
//! named by [`PhysicsSystem`](schedule::PhysicsSystem), and game code orders its own around
//! [`PhysicsSet`](schedule::PhysicsSet).
//!
//! Plumbing stays out: the systems, the implicit step's scratch and the threading scopes are
//! not here.
//!
//! ```compile_fail
//! use tumble::ecs::integrate::integrate_with_forces;
//! ```
//!
//! ```compile_fail
//! use tumble::ecs::audit::audit_energy;
//! ```
//!
//! ```compile_fail
//! use tumble::ecs::parallel::scope;
//! ```

/// What a rigid body, a force generator and the world carry.
pub mod components {
    pub use tumble_ecs::components::{
        AssumedMass, BodyError, BodyErrorKind, ConstantForce, ConstantLocalForce, ConstantTorque,
        Damping, Dynamic, ForceAccumulator, GeneratorError, GeneratorErrorKind, Gravity,
        GravityScale, HeldLoad, ImplicitBody, ImplicitSpring, Kinematic, MassProps, PhysicsErrors,
        PhysicsSettings, Pose, Rejected, RejectedGenerator, RigidBody, Spring, SpringEnd,
        SpringSolver, SpringTurn, Static, Velocity, WorldError, assume_missing_masses,
        bodies_without_mass, kinetic_energy_f64,
    };
}

/// Loads from game code, and the spring forces and energies the step uses.
pub mod forces {
    pub use tumble_ecs::forces::{
        ApplyForces, BodyForces, BodyForcesItem, BodyForcesReadOnly, BodyForcesReadOnlyItem,
        kinetic_and_elastic_energy, spring_force,
    };
}

/// Which spring groups are stiff (stepped by the implicit spring step), decided from the
/// world or, for code that spawns a world it knows, from its masses and springs.
pub mod springs {
    pub use tumble_ecs::springs::{
        Classification, ClassifiedSpring, SpringClassification, classification_is_stale, classify,
        classify_springs,
    };
}

/// The energy audit: its setting, its ledger (a resource: the energy each spring group's
/// integration has made up so far) and a group's account as a snapshot saves it.
pub mod audit {
    pub use tumble_ecs::audit::{EnergyAudit, EnergyLedger, SavedAccount};
}

/// Big tables split over bevy's compute pool.
pub mod parallel {
    pub use tumble_ecs::parallel::Parallelism;
}

/// The planner's stability predictions and the bounds they use.
pub mod stability {
    pub use tumble_ecs::stability::{
        ACCURACY_HORIZON, COMPOSED_SPLIT_ERROR_LIMIT, EXPLICIT_GYROSCOPIC_HORIZON,
        FIRST_ORDER_DRIFT_LIMIT, LOCKED_RATE_LIMIT, POSITION_RESOLUTION_LIMIT, RK4_STIFFNESS_LIMIT,
        SPLIT_DRIFT_TOLERANCE, SPLIT_ERROR_LIMIT, SPRING_LIMIT, StabilityWarning, check_stability,
        first_order_drift, split_rotation_error,
    };
}

/// The world's state: checksums, rollback snapshots and serde snapshots.
pub mod state {
    #[cfg(feature = "serde")]
    pub use tumble_ecs::state::{
        BodyKind, BodySnapshot, SNAPSHOT_VERSION, Snapshot, SnapshotError,
    };
    pub use tumble_ecs::state::{
        BodyRecord, Parts, RollbackError, RollbackSnapshot, WorldChecksum, world_checksum,
    };
}

/// The step's plan, the runner that keeps it, the stage a run of the schedule is in
/// ([`StageCursor`](schedule::StageCursor): game systems read it to act once per step, or to
/// know their stage's span), fixed-step clocks and the Bevy plugin.
pub mod schedule {
    pub use tumble_ecs::integrate::StageCursor;
    pub use tumble_ecs::schedule::{
        FixedStepper, ForceSystems, FrameSteps, PhysicsPlan, PhysicsRunner, PhysicsSet,
        PhysicsSystem, StepperError, interpolate,
    };
    #[cfg(feature = "bevy_app")]
    pub use tumble_ecs::schedule::{TumblePlugin, TumbleStep, physics_step};
}
