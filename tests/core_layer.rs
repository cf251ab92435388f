//! Cross-crate tests of the core layer: analytic formulas, conservation, mass properties,
//! schedule planning, bad input and determinism.

mod core_layer {
    pub mod bad_input;
    pub mod checksum;
    pub mod determinism;
    pub mod forces;
    // Shapes are built with parry's own vectors, which are tumble's except in an `f64` build
    // that keeps parry3d's `f32` shapes (`f64` without `parry-f64`): that case is tested in
    // `tumble_core::shapes`.
    #[cfg(any(not(feature = "f64"), feature = "parry-f64"))]
    pub mod mass_properties;
    pub mod momentum;
    pub mod precision;
    pub mod projectile;
    pub mod rollback;
    // Scene files through the reader: the reader is the feature `scene`.
    #[cfg(feature = "scene")]
    pub mod scene_bits;
    pub mod schedule;
    pub mod spin;
    pub mod springs;
    pub mod stepper;
    pub mod util;
}
