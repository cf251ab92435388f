//! Stepping worlds through the ECS layer: analytic formulas (projectile, spin, springs),
//! conservation, forces, schedule planning, the fixed stepper, precision, bad input and
//! determinism across threads.

mod stepping {
    pub(crate) mod bad_input;
    pub(crate) mod determinism;
    pub(crate) mod forces;
    pub(crate) mod momentum;
    pub(crate) mod precision;
    pub(crate) mod projectile;
    pub(crate) mod schedule;
    pub(crate) mod spin;
    pub(crate) mod springs;
    pub(crate) mod stepper;
    pub(crate) mod util;
}
