//! Cross-crate tests of the core layer: analytic formulas, conservation, mass properties,
//! schedule planning, bad input and determinism.

mod core_layer {
    pub mod bad_input;
    pub mod determinism;
    pub mod forces;
    pub mod mass_properties;
    pub mod momentum;
    pub mod projectile;
    pub mod schedule;
    pub mod spin;
    pub mod springs;
    pub mod stepper;
    pub mod util;
}
