//! ECS-free math: a body's state and mass properties, the integrators and their batch
//! interface, the invariants and the exact references' special functions.
//!
//! Everything here runs on plain data: step bodies kept in your own arrays with a
//! [`BodyBatch`] and [`Integrator::stage_batch`], or one body with [`Integrator::try_step`].
//! The ECS layer ([`ecs`](crate::ecs)) drives the same entry points.

pub use tumble_core::error::{InvalidInput, UNIT_QUATERNION_TOLERANCE};
pub use tumble_core::integrate::{
    BodyBatch, FreeFlow, Integrator, KernelPath, StepError, StepPhase, UnknownIntegrator,
    kernel_path,
};
pub use tumble_core::mass::{Density, Mass, MassProperties};
pub use tumble_core::state::{BodyState, Wrench};

/// Mass properties of parry shapes (feature `parry`).
#[cfg(any(feature = "parry", feature = "parry-f64"))]
pub mod shapes {
    pub use tumble_core::shapes::{
        HULL_MIN_RELATIVE_VOLUME, HullError, MAX_HULL_POINTS, convex_hull_mass_properties,
        from_parry, mass_properties_of,
    };
}

/// The integrators, their stages and the SIMD kernel path they run on.
pub mod integrate {
    pub use tumble_core::integrate::{
        BodyBatch, COMPOSED_SPLIT_ERROR_LIMIT, ExactSwitch, FreeFlow, Integrator, KERNEL_ENV,
        KernelError, KernelPath, OpCounts, SPLIT_DRIFT_TOLERANCE, SPLIT_ERROR_LIMIT, StageSpan,
        Stages, StepError, StepPhase, UnknownIntegrator, kernel_path, rotate, rotate_inv,
        split_orbit_error, split_rotation_drift, split_rotation_error, symmetric_rotation_flops,
    };
}

/// The implicit spring step on plain data: a group of bodies joined by stiff springs, stepped
/// with energy kept exactly (the ECS layer runs it on the stiff groups it finds).
pub mod springs {
    pub use tumble_core::springs::implicit::{DEFAULT_TOLERANCE, MAX_SPLITS, SolveStats};
    pub use tumble_core::springs::{
        AUTO_REFERENCE_DT, GroupBody, GroupRotation, GroupSpring, IMPLICIT_OMEGA_DT,
        ImplicitSpringError, ImplicitSpringSolver, LinkEnd, METHOD_TURN_RATE,
        inverse_effective_mass_bound, omega_dt_bound, turning_compliance,
    };
}

/// Mass, density and mass properties, with the ranges they accept.
pub use tumble_core::mass;
pub use tumble_core::{damping, elliptic, invariants, rotation};
