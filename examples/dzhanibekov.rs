//! The intermediate-axis (Dzhanibekov) flip and stable spins, for every integrator, in f32 at
//! 60 Hz over 120 s with I = diag(1, 2, 3): counts flips (sign changes of the body rate about the
//! middle axis) and reports the relative drift of energy and |L|. The exact solution flips 67
//! times for ω₀ = (1, 5, 1) and 44 times for ω₀ = (0.01, 10, 0.01).
use tumble::core::invariants::{angular_momentum, kinetic_energy};
use tumble::math::{Real, Vec3};

use tumble::prelude::*;

fn run(integrator: Integrator, omega0: Vec3, dt: Real, seconds: Real) -> (u32, Real, Real, Vec3) {
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), Vec3::new(1.0, 2.0, 3.0)).unwrap();
    let mut state = BodyState {
        angular_velocity: omega0,
        ..Default::default()
    };
    let (e0, l0) = (
        kinetic_energy(&state, &mass),
        angular_momentum(&state, &mass).length(),
    );
    let mut flips = 0;
    let mut last_sign = (state.rotation.inverse() * state.angular_velocity)
        .y
        .signum();
    for _ in 0..(seconds / dt).round() as usize {
        if integrator
            .try_step(&mut state, &mass, &Wrench::ZERO, dt)
            .is_err()
        {
            return (flips, Real::NAN, Real::NAN, Vec3::NAN);
        }
        let sign = (state.rotation.inverse() * state.angular_velocity)
            .y
            .signum();
        if sign != last_sign {
            flips += 1;
            last_sign = sign;
        }
    }
    let e = kinetic_energy(&state, &mass);
    let l = angular_momentum(&state, &mass).length();
    (
        flips,
        e / e0 - 1.0,
        l / l0 - 1.0,
        state.rotation.inverse() * state.angular_velocity,
    )
}

fn main() {
    // (name, ω₀ in the principal frame, exact flip count or None for a stable spin)
    let cases = [
        (
            "middle axis, ω₀ = (1, 5, 1)",
            Vec3::new(1.0, 5.0, 1.0),
            Some(67),
        ),
        (
            "near separatrix, ω₀ = (0.01, 10, 0.01)",
            Vec3::new(0.01, 10.0, 0.01),
            Some(44),
        ),
        (
            "largest axis, ω₀ = (0.01, 0.01, 10)",
            Vec3::new(0.01, 0.01, 10.0),
            None,
        ),
        (
            "smallest axis, ω₀ = (10, 0.01, 0.01)",
            Vec3::new(10.0, 0.01, 0.01),
            None,
        ),
    ];
    for (name, omega0, exact_flips) in cases {
        match exact_flips {
            Some(n) => println!("{name}: exact solution flips {n} times"),
            None => println!("{name}: stable, ω stays near {omega0}"),
        }
        for &integrator in Integrator::ALL {
            let (flips, de, dl, w) = run(integrator, omega0, 1.0 / 60.0, 120.0);
            let flips = if exact_flips.is_some() {
                format!("flips {flips:>3}")
            } else {
                String::new()
            };
            println!(
                "  {:<24} {flips:<9}  ΔE/E {de:>10.3e}  Δ|L|/|L| {dl:>10.3e}  final ω_body {w:.3}",
                integrator.name()
            );
        }
    }
}
