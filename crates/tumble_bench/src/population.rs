//! The benchmark scene: N free asymmetric bodies under gravity, tumbling at varied rates.
//!
//! Rates stay below 0.5 rad/s so that even the explicit textbook step stays finite for the
//! whole measurement (its predicted blow-up time `32/(Ω²Δt)` is over 7000 s at 60 Hz, and a
//! single-body timing runs at most 1700 s of simulated time): a benchmark of NaN arithmetic
//! would measure nothing. Every body has distinct principal moments, so the default integrator does
//! its full gyroscopic work (spherical bodies would take a cheaper path).

use tumble_core::math::{Quat, Real, Vec3};
use tumble_core::{BodyState, Mass, MassProperties};
use tumble_rapier::{ComparisonBody, ComparisonScene};

/// Gravity of the scene (m/s²).
pub const GRAVITY: Vec3 = Vec3::new(0.0, -9.81, 0.0);

/// Time step (s).
pub const DT: Real = 1.0 / 60.0;

/// The scene with `n` bodies, deterministic.
pub fn scene(n: usize) -> ComparisonScene {
    let bodies = (0..n)
        .map(|i| {
            let f = (i as Real + 0.5) / n as Real;
            let g = ((i as Real) * 0.618_034).fract();
            let mass = Mass::new(0.5 + f).expect("positive mass");
            let inertia = Vec3::new(1.0, 2.0 + f, 3.0 + f * g) * mass.get();
            let properties = MassProperties::new(mass, inertia).expect("valid inertia");
            let side = (n as Real).cbrt().ceil().max(1.0) as usize;
            let cell = Vec3::new(
                (i % side) as Real,
                ((i / side) % side) as Real,
                (i / (side * side)) as Real,
            );
            let state = BodyState {
                position: cell * 2.0,
                rotation: Quat::from_euler(glam::EulerRot::YXZ, 6.0 * g, 3.0 * f, g),
                linear_velocity: Vec3::new(1.0 - g, 2.0 * f, 0.5),
                angular_velocity: Vec3::new(0.3 + f, 1.0 - g, 0.2 + 0.5 * g) * 0.3,
            };
            ComparisonBody::new(format!("b{i}"), properties, state)
        })
        .collect();
    ComparisonScene::new(DT, Some(GRAVITY), bodies)
}
