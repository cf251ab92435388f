//! Cross-crate tests: the pinned checksums of the reference scene (and of scene files through
//! the reader), rollback of the reference scene, and mass properties from parry shapes through
//! the facade. Stepping through the ECS layer is tested beside it, in `tumble_ecs/tests`.

mod core_layer {
    pub(crate) mod checksum;
    // Shapes are built with parry's own vectors, which are tumble's except in an `f64` build
    // that keeps parry3d's `f32` shapes (`f64` without `parry-f64`): that case is tested in
    // `tumble_core::shapes`.
    #[cfg(any(not(feature = "f64"), feature = "parry-f64"))]
    pub(crate) mod mass_properties;
    pub(crate) mod rollback;
    // Scene files through the reader: the reader is the feature `scene`.
    #[cfg(feature = "scene")]
    pub(crate) mod scene_bits;
    // The helpers of the ECS crate's stepping tests (the facade's crates are this package's
    // dependencies too), one file for both test binaries.
    #[path = "../../crates/tumble_ecs/tests/stepping/util.rs"]
    #[allow(dead_code, reason = "helpers the stepping tests use and these do not")]
    pub(crate) mod util;
}
