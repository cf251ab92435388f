//! The stiff chain, built once for every part of the report that runs it (the stability matrix
//! in tumble, and the side-by-side run against rapier).

use tumble_core::math::{Quat, Real, Vec3};
use tumble_core::{BodyState, Mass, MassProperties};
use tumble_rapier::{ComparisonBody, ComparisonScene, ComparisonSpring, ComparisonSpringEnd};

/// Time step of the chain (s).
pub const CHAIN_DT: Real = 1.0 / 60.0;

/// Ten asymmetric bodies (m = 1 kg, I = (0.02, 0.03, 0.04)) in a chain of springs at off-centre
/// anchors, the first tied to the world point (−1, 0, 0), each spring stretched 10 %, every body
/// moving (v = (0, 0.05, 0), ω = (0.2, −0.1, 0.3)); no gravity, no damping; `Δt = 1/60`.
/// Stiffness `k = μ (ωΔt/Δt)²` with `μ = ½` (two unit masses): nominal `√(k/μ)Δt = omega_dt`.
/// The same chain as `scenes/stiff_chain.toml` (there at `omega_dt = 10`).
pub fn stiff_chain(omega_dt: Real) -> ComparisonScene {
    let k = 0.5 * (omega_dt / CHAIN_DT).powi(2);
    let mass = MassProperties::new(Mass::new(1.0).expect("valid"), Vec3::new(0.02, 0.03, 0.04))
        .expect("valid");
    let bodies = (0..10)
        .map(|i| {
            let x = i as Real;
            let state = BodyState {
                position: Vec3::new(x, 0.02 * x, 0.0),
                rotation: Quat::from_rotation_z(0.1 * x),
                linear_velocity: Vec3::new(0.0, 0.05, 0.0),
                angular_velocity: Vec3::new(0.2, -0.1, 0.3),
            };
            ComparisonBody::new(format!("b{i}"), mass, state)
        })
        .collect();
    let spring =
        |a: usize, anchor_a: Vec3, b: ComparisonSpringEnd, rest_length: Real| ComparisonSpring {
            a,
            anchor_a,
            b,
            stiffness: k,
            damping: 0.0,
            rest_length,
        };
    let mut springs = vec![spring(
        0,
        Vec3::new(-0.1, 0.05, 0.0),
        ComparisonSpringEnd::World(Vec3::new(-1.0, 0.0, 0.0)),
        0.8,
    )];
    for i in 0..9 {
        springs.push(spring(
            i,
            Vec3::new(0.1, 0.05, 0.0),
            ComparisonSpringEnd::Body {
                body: i + 1,
                anchor: Vec3::new(-0.1, -0.05, 0.02),
            },
            0.72,
        ));
    }
    ComparisonScene {
        springs,
        ..ComparisonScene::new(CHAIN_DT, None, bodies)
    }
}
