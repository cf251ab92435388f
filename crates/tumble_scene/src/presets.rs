//! Scenes built by code, shared by the report, the benchmark and the tests so that each is
//! written once.

use bevy_ecs::prelude::*;
use tumble_core::MassProperties;
use tumble_core::mass::Mass;
use tumble_core::math::{Quat, Real, Vec3};
use tumble_ecs::prelude::*;

/// How a [`SpringChain`] starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChainStart {
    /// Every spring stretched by about 10 % of its length: the elastic energy, and with it the
    /// speed of the motion, grows with the stiffness (`E ∝ k`).
    Stretched,
    /// Every spring at its rest length, the bodies moving and turning: the energy is the same
    /// at every stiffness, so a stiffer chain only vibrates faster, with a smaller amplitude.
    Relaxed,
}

/// Ten (or [`SpringChain::bodies`]) asymmetric bodies, `m = 1`, `I = (0.02, 0.03, 0.04)`, one
/// metre apart along x and turned 0.1 rad more each about z, joined by springs between
/// off-centre anchors, the first tied to a world point; all move at `(0, 0.05, 0)` m/s and
/// turn at `(0.2, −0.1, 0.3)` rad/s. The stiffness is set by the nominal
/// `ωΔt = √(k/μ) Δt` with `μ = ½` (two unit masses), so `k = ½ (ωΔt/Δt)²`.
///
/// The scene of the stiff-springs issue (#15): the stability matrix runs it stretched at ωΔt
/// from 0.5 to 100, `tumble bench` times it both ways, `scenes/stiff_chain.toml` is the stretched
/// chain at ωΔt = 10.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpringChain {
    /// Number of bodies (and of springs).
    pub bodies: usize,
    /// Nominal `√(k/μ) Δt`.
    pub omega_dt: Real,
    /// The step the stiffness is chosen for (s).
    pub dt: Real,
    /// How the springs start.
    pub start: ChainStart,
    /// Where the chain's first body sits (chains side by side need different origins).
    pub origin: Vec3,
}

impl SpringChain {
    /// The chain of ten bodies at `omega_dt` for `dt`, at the world origin.
    pub fn new(omega_dt: Real, dt: Real, start: ChainStart) -> Self {
        Self {
            bodies: 10,
            omega_dt,
            dt,
            start,
            origin: Vec3::ZERO,
        }
    }

    /// The springs' stiffness `k = ½ (ωΔt/Δt)²` (N/m).
    pub fn stiffness(&self) -> Real {
        0.5 * (self.omega_dt / self.dt).powi(2)
    }

    /// The mass properties of every body.
    pub fn mass() -> MassProperties {
        MassProperties::new(
            Mass::new(1.0).expect("a positive mass"),
            Vec3::new(0.02, 0.03, 0.04),
        )
        .expect("valid principal moments")
    }

    /// Spawns the bodies and springs into `world`; returns the bodies in chain order.
    pub fn spawn(&self, world: &mut World) -> Vec<Entity> {
        let poses: Vec<(Vec3, Quat)> = (0..self.bodies)
            .map(|i| {
                let x = i as Real;
                (
                    self.origin + Vec3::new(x, 0.02 * x, 0.0),
                    Quat::from_rotation_z(0.1 * x),
                )
            })
            .collect();
        let bodies: Vec<Entity> = poses
            .iter()
            .map(|&(translation, rotation)| {
                world
                    .spawn((
                        RigidBody,
                        MassProps(Self::mass()),
                        Transform {
                            translation,
                            rotation,
                        },
                        Velocity {
                            linear: Vec3::new(0.0, 0.05, 0.0),
                            angular: Vec3::new(0.2, -0.1, 0.3),
                        },
                    ))
                    .id()
            })
            .collect();
        let k = self.stiffness();
        let at = |i: usize, anchor: Vec3| poses[i].0 + poses[i].1 * anchor;
        let rest = |stretched: Real, length: Real| match self.start {
            ChainStart::Stretched => stretched,
            ChainStart::Relaxed => length,
        };
        let (left, right) = (Vec3::new(-0.1, -0.05, 0.02), Vec3::new(0.1, 0.05, 0.0));
        if let Some(&first) = bodies.first() {
            let (anchor, world_point) = (Vec3::new(-0.1, 0.05, 0.0), self.origin - Vec3::X);
            world.spawn(Spring {
                a: first,
                anchor_a: anchor,
                b: SpringEnd::World(world_point),
                stiffness: k,
                damping: 0.0,
                rest_length: rest(0.8, (at(0, anchor) - world_point).length()),
            });
        }
        for (i, pair) in bodies.windows(2).enumerate() {
            world.spawn(Spring {
                a: pair[0],
                anchor_a: right,
                b: SpringEnd::Body {
                    body: pair[1],
                    anchor: left,
                },
                stiffness: k,
                damping: 0.0,
                rest_length: rest(0.72, (at(i, right) - at(i + 1, left)).length()),
            });
        }
        bodies
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn elastic_energy(world: &mut World) -> Real {
        let springs: Vec<Spring> = world.query::<&Spring>().iter(world).copied().collect();
        let point = |e: Entity, anchor: Vec3| {
            let t = world.get::<Transform>(e).expect("a body");
            t.translation + t.rotation * anchor
        };
        springs
            .iter()
            .map(|s| {
                let a = point(s.a, s.anchor_a);
                let b = match s.b {
                    SpringEnd::World(p) => p,
                    SpringEnd::Body { body, anchor } => point(body, anchor),
                };
                let stretch = (a - b).length() - s.rest_length;
                0.5 * s.stiffness * stretch * stretch
            })
            .sum()
    }

    #[test]
    fn a_relaxed_chain_starts_at_rest_length_and_a_stretched_one_does_not() {
        let dt = 1.0 / 60.0;
        let mut world = World::new();
        SpringChain::new(10.0, dt, ChainStart::Relaxed).spawn(&mut world);
        let k = SpringChain::new(10.0, dt, ChainStart::Relaxed).stiffness();
        // Anchors are within a few metres of the origin: rounding to `Real` leaves a stretch of
        // a few ulps of a metre per spring.
        let ulp = Real::EPSILON * 4.0;
        assert!(elastic_energy(&mut world) <= 10.0 * 0.5 * k * (4.0 * ulp).powi(2));
        let mut world = World::new();
        SpringChain::new(10.0, dt, ChainStart::Stretched).spawn(&mut world);
        // Every spring stretched by 0.05 m or more.
        assert!(elastic_energy(&mut world) >= 10.0 * 0.5 * k * 0.05 * 0.05);
        assert_eq!(world.query::<&Spring>().iter(&world).count(), 10);
        assert_eq!(world.query::<&RigidBody>().iter(&world).count(), 10);
    }
}
