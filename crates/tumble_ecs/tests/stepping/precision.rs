//! The engine's precision (`tumble_core::math::Real`): the feature `f64` switches every component,
//! resource and state to double precision, and far from the origin that is what keeps a body
//! moving at all.

use tumble_core::math::{DOUBLE_PRECISION, Quat, Real, Vec3, to_f64};
use tumble_ecs::prelude::*;

use super::util::{mass_props, run, world_with};

#[test]
fn real_follows_the_feature() {
    let bytes = if DOUBLE_PRECISION { 8 } else { 4 };
    assert_eq!(size_of::<Real>(), bytes);
    assert_eq!(size_of::<Vec3>(), 3 * bytes);
    assert_eq!(size_of::<Quat>(), 4 * bytes);
    // The components carry the engine's types.
    let t = Pose::from_translation(Vec3::ONE);
    let _: Vec3 = t.translation;
    let _: Quat = t.rotation;
}

/// A body 10⁷ m from the origin at 1 m/s. Each drift `x += v Δt` rounds to half an ulp of `x`,
/// so after `n` steps the position is within `n · ½ ulp(x)` of `x₀ + v t`: 357 m in f32 (where
/// 1/60 m is below half an ulp, 0.5 m, and the body does not move at all), 7e-7 m in f64.
#[test]
fn far_from_the_origin_the_error_is_the_precision_s_half_ulp_per_step() {
    let (x0, v, dt, n) = (1.0e7 as Real, 1.0 as Real, 1.0 / 60.0 as Real, 600);
    let mut world = world_with(dt, Integrator::default());
    let id = world
        .spawn((
            RigidBody,
            mass_props(1.0, [1.0, 1.0, 1.0]),
            Pose::from_translation(Vec3::new(x0, 0.0, 0.0)),
            Velocity::linear(Vec3::new(v, 0.0, 0.0)),
        ))
        .id();
    run(&mut world, n);
    let x = to_f64(world.get::<Pose>(id).unwrap().translation.x);
    let exact = to_f64(x0) + to_f64(v) * to_f64(dt) * n as f64;
    let half_ulp = 0.5 * to_f64(Real::EPSILON) * to_f64(x0);
    let tolerance = n as f64 * half_ulp;
    assert!((x - exact).abs() <= tolerance, "x = {x}, exact {exact}");
    if DOUBLE_PRECISION {
        assert!((x - exact).abs() < 1e-6, "x = {x}, exact {exact}");
    }
}
