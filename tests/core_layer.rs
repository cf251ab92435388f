//! Cross-crate tests of the core layer: analytic formulas, conservation, mass properties,
//! schedule planning, bad input and determinism.

mod core_layer {
    pub(crate) mod bad_input;
    pub(crate) mod checksum;
    pub(crate) mod determinism;
    pub(crate) mod forces;
    // Shapes are built with parry's own vectors, which are tumble's except in an `f64` build
    // that keeps parry3d's `f32` shapes (`f64` without `parry-f64`): that case is tested in
    // `tumble_core::shapes`.
    #[cfg(any(not(feature = "f64"), feature = "parry-f64"))]
    pub(crate) mod mass_properties;
    pub(crate) mod momentum;
    pub(crate) mod precision;
    pub(crate) mod projectile;
    pub(crate) mod rollback;
    // Scene files through the reader: the reader is the feature `scene`.
    #[cfg(feature = "scene")]
    pub(crate) mod scene_bits;
    pub(crate) mod schedule;
    pub(crate) mod spin;
    pub(crate) mod springs;
    pub(crate) mod stepper;
    pub(crate) mod util;
}
