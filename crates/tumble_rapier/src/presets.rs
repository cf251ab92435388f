//! Scenes built by code, written once for the report, the benchmark and the tests.

use tumble_core::math::{Quat, Real, Vec3, Widen};
use tumble_core::{BodyState, Mass, MassProperties};

use crate::scene::{ComparisonBody, ComparisonScene, ComparisonSpring, ComparisonSpringEnd};

/// The step of [`spring_chain`] (s).
pub const CHAIN_DT: Real = 1.0 / 60.0;

/// How a [`spring_chain`] starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChainStart {
    /// Every spring stretched by 10 % or more: the elastic energy, and with it the speed of
    /// the motion, grows with the stiffness (`E ∝ k`).
    Stretched,
    /// Every spring at its rest length: the energy is the bodies' motion alone, the same at
    /// every stiffness, so a stiffer chain only vibrates faster, with a smaller amplitude.
    Relaxed,
}

/// `chains` copies, 2 m apart along z, of a chain of ten asymmetric bodies (m = 1 kg,
/// I = (0.02, 0.03, 0.04)), one metre apart along x and each turned 0.1 rad more about z, joined
/// by springs between off-centre anchors, the first tied to a world point one metre before it;
/// every body moves at `(0, 0.05, 0)` m/s and turns at `(0.2, −0.1, 0.3)` rad/s. No gravity, no
/// damping, `Δt = 1/60` ([`CHAIN_DT`]). Stiffness `k = μ (ωΔt/Δt)²` with `μ = ½` (two unit
/// masses): nominal `√(k/μ)Δt = omega_dt`.
///
/// The chain of the stiff-springs measurements: the report's stability matrix and its run
/// against rapier take it stretched, `tumble bench` times it both ways, and
/// `scenes/stiff_chain.toml` is one stretched chain at `omega_dt = 10`.
pub fn spring_chain(omega_dt: Real, start: ChainStart, chains: usize) -> ComparisonScene {
    let k = 0.5 * (omega_dt / CHAIN_DT).powi(2);
    let mass = MassProperties::new(Mass::new(1.0).expect("valid"), Vec3::new(0.02, 0.03, 0.04))
        .expect("valid");
    let (left, right) = (Vec3::new(-0.1, -0.05, 0.02), Vec3::new(0.1, 0.05, 0.0));
    let first = Vec3::new(-0.1, 0.05, 0.0);
    let mut scene = ComparisonScene::new(CHAIN_DT, None, Vec::new());
    for c in 0..chains {
        let origin = Vec3::new(0.0, 0.0, 2.0 * c as Real);
        let base = scene.bodies.len();
        for i in 0..10 {
            let x = i as Real;
            let state = BodyState {
                position: origin + Vec3::new(x, 0.02 * x, 0.0),
                rotation: Quat::from_rotation_z(0.1 * x),
                linear_velocity: Vec3::new(0.0, 0.05, 0.0),
                angular_velocity: Vec3::new(0.2, -0.1, 0.3),
            };
            let name = if chains == 1 {
                format!("b{i}")
            } else {
                format!("c{c}b{i}")
            };
            scene.bodies.push(ComparisonBody::new(name, mass, state));
        }
        let at = |scene: &ComparisonScene, i: usize, anchor: Vec3| {
            let state = scene.bodies[i].state;
            scene.anchor_point(i, &state, anchor)
        };
        let rest = |stretched: Real, length: f64| match start {
            ChainStart::Stretched => stretched,
            ChainStart::Relaxed => length as Real,
        };
        let world_point = origin - Vec3::X;
        let length = (at(&scene, base, first) - world_point.widen()).length();
        scene.springs.push(ComparisonSpring {
            a: base,
            anchor_a: first,
            b: ComparisonSpringEnd::World(world_point),
            stiffness: k,
            damping: 0.0,
            rest_length: rest(0.8, length),
        });
        for i in base..base + 9 {
            let length = (at(&scene, i, right) - at(&scene, i + 1, left)).length();
            scene.springs.push(ComparisonSpring {
                a: i,
                anchor_a: right,
                b: ComparisonSpringEnd::Body {
                    body: i + 1,
                    anchor: left,
                },
                stiffness: k,
                damping: 0.0,
                rest_length: rest(0.72, length),
            });
        }
    }
    scene
}

#[cfg(test)]
mod tests {
    use super::*;
    use tumble_core::math::to_f64;

    fn elastic_energy(scene: &ComparisonScene) -> f64 {
        let states: Vec<BodyState> = scene
            .bodies
            .iter()
            .map(|b| BodyState {
                linear_velocity: Vec3::ZERO,
                angular_velocity: Vec3::ZERO,
                ..b.state
            })
            .collect();
        scene.total_energy(&states)
    }

    #[test]
    fn a_relaxed_chain_starts_at_rest_length_and_a_stretched_one_does_not() {
        let relaxed = spring_chain(10.0, ChainStart::Relaxed, 3);
        let stretched = spring_chain(10.0, ChainStart::Stretched, 1);
        let k = to_f64(stretched.springs[0].stiffness);
        assert_eq!((relaxed.bodies.len(), relaxed.springs.len()), (30, 30));
        assert_eq!((stretched.bodies.len(), stretched.springs.len()), (10, 10));
        // A rest length rounded to `Real` leaves a stretch of an ulp or so of a metre per spring.
        let ulp = to_f64(Real::EPSILON);
        assert!(elastic_energy(&relaxed) <= 30.0 * 0.5 * k * (4.0 * ulp).powi(2));
        // Every spring stretched by 0.05 m or more.
        assert!(elastic_energy(&stretched) >= 10.0 * 0.5 * k * 0.05 * 0.05);
    }
}
