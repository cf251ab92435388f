//! The implicit spring step against its promises: exact energy at any `ωΔt`, momentum, the
//! implicit midpoint phase on a linear spring, reversibility and second order.

use glam::DVec3;

use super::*;
use crate::mass::Mass;
use crate::math::{DOUBLE_PRECISION, Quat, Widen};
use crate::state::{BodyState, Wrench};

fn body(mass: Real, inertia: Vec3, position: Vec3, rotation: Quat, v: Vec3, w: Vec3) -> GroupBody {
    GroupBody {
        state: BodyState {
            position,
            rotation,
            linear_velocity: v,
            angular_velocity: w,
        },
        mass: MassProperties::new(Mass::new(mass).unwrap(), inertia).unwrap(),
        load: Wrench::default(),
    }
}

fn anchor_world(b: &GroupBody, local: Vec3) -> DVec3 {
    b.state.position.widen()
        + b.state.rotation.widen() * (local - b.mass.local_center_of_mass()).widen()
}

/// Kinetic + elastic energy (J), in f64.
fn energy(bodies: &[GroupBody], springs: &[GroupSpring]) -> f64 {
    let kinetic: f64 = bodies
        .iter()
        .map(|b| {
            let v = b.state.linear_velocity.widen();
            let w = b.state.angular_velocity;
            let iw = b.mass.world_inertia_mul(b.state.rotation, w).widen();
            0.5 * b.mass.mass().widen() * v.length_squared() + 0.5 * w.widen().dot(iw)
        })
        .sum();
    let elastic: f64 = springs
        .iter()
        .map(|s| {
            let pa = anchor_world(&bodies[s.a], s.anchor_a);
            let pb = match s.b {
                LinkEnd::Body { index, anchor } => anchor_world(&bodies[index], anchor),
                LinkEnd::Fixed(p) => p.widen(),
            };
            let stretch = (pa - pb).length() - s.rest_length.widen();
            0.5 * s.stiffness.widen() * stretch * stretch
        })
        .sum();
    kinetic + elastic
}

/// A chain of asymmetric bodies joined at off-centre anchors, the first held by a world spring;
/// stiffness set so `√(k/m) Δt = omega_dt` for the body mass `m = 1`.
fn chain(n: usize, omega_dt: Real, dt: Real) -> (Vec<GroupBody>, Vec<GroupSpring>) {
    let k = (omega_dt / dt).powi(2);
    let inertia = Vec3::new(0.02, 0.03, 0.04);
    let bodies: Vec<GroupBody> = (0..n)
        .map(|i| {
            let t = i as Real;
            body(
                1.0,
                inertia,
                Vec3::new(0.5 * t + 0.05, 0.03 * t, 0.0),
                Quat::from_rotation_z(0.3 * t).mul_quat(Quat::from_rotation_x(0.2)),
                Vec3::new(0.0, 0.1 * t, 0.2),
                Vec3::new(1.0, -0.5 * t, 0.7),
            )
        })
        .collect();
    let mut springs = vec![GroupSpring {
        a: 0,
        anchor_a: Vec3::new(-0.2, 0.05, 0.0),
        b: LinkEnd::Fixed(Vec3::new(-0.3, 0.0, 0.0)),
        stiffness: k,
        rest_length: 0.05,
    }];
    for i in 1..n {
        springs.push(GroupSpring {
            a: i - 1,
            anchor_a: Vec3::new(0.2, 0.05, 0.02),
            b: LinkEnd::Body {
                index: i,
                anchor: Vec3::new(-0.2, -0.04, 0.0),
            },
            stiffness: k,
            rest_length: 0.08,
        });
    }
    (bodies, springs)
}

/// The precision floor of one step's energy, relative: the state is rounded to `Real` after
/// every step, and the elastic energy's sensitivity to a rounded anchor is `k |stretch| ε |x|`.
fn per_step_rounding() -> f64 {
    if DOUBLE_PRECISION { 1e-13 } else { 2e-6 }
}

#[test]
fn a_stiff_asymmetric_chain_keeps_its_energy_at_every_omega_dt() {
    let dt = 1.0 / 60.0;
    for omega_dt in [0.5, 2.0, 10.0, 100.0] {
        let (mut bodies, springs) = chain(5, omega_dt, dt);
        let e0 = energy(&bodies, &springs);
        let mut solver = ImplicitSpringSolver::default();
        let mut worst: f64 = 0.0;
        // The violent cases (the bodies turn by radians per step, so the step is split) are
        // slow in a debug build: fewer steps there.
        let steps = if omega_dt > 2.0 { 100 } else { 1000 };
        let mut newton = 0;
        let mut splits = 0;
        for _ in 0..steps {
            let stats = solver
                .step(&mut bodies, &springs, dt)
                .unwrap_or_else(|e| panic!("ωΔt {omega_dt}: {e}"));
            newton += stats.newton_iterations;
            splits += stats.splits;
            let e = energy(&bodies, &springs);
            worst = worst.max((e - e0).abs() / e0);
        }
        // Exact energy up to the solver tolerance (1e-10 per step) and the rounding of the
        // state to `Real` each step, a random walk of `steps` such errors (√steps), with a
        // factor 10 of headroom.
        let bound = 10.0 * (steps as f64).sqrt() * (per_step_rounding() + solver.tolerance);
        eprintln!(
            "ωΔt {omega_dt}: worst relative energy error {worst:.3e} (bound {bound:.1e}), mean Newton {:.1}, splits {splits}",
            newton as f64 / steps as f64
        );
        assert!(worst <= bound, "ωΔt {omega_dt}: {worst:e} > {bound:e}");
        for b in &bodies {
            assert!(b.state.is_valid());
        }
    }
}
