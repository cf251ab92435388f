//! Energy over time for long torque-free spins: where each method's energy error goes in
//! 120 s at 60 Hz (I = diag(1, 2, 3), |ω| = 10 rad/s).

use serde::Serialize;
use tumble_core::invariants::kinetic_energy;
use tumble_core::math::{Vec3, to_f64};
use tumble_core::{BodyState, Mass, MassProperties, Wrench};
use tumble_rapier::{ComparisonBody, ComparisonScene, RapierScene};

use crate::workprec::Method;

/// Relative energy `E(t)/E(0) − 1`, sampled once per second, for one spin and one method.
#[derive(Debug, Clone, Serialize)]
pub struct EnergyTrace {
    /// Spin name.
    pub spin: String,
    /// Method name.
    pub method: String,
    /// `E(t)/E(0) − 1` at t = 0, 1, 2, … s (NaN after a divergence).
    pub relative_energy: Vec<f64>,
}

/// The long spins: about the largest, the smallest and the middle axis (a Dzhanibekov tumble).
pub fn spins() -> [(&'static str, Vec3); 3] {
    [
        ("largest-axis", Vec3::new(0.01, 0.01, 10.0)),
        ("smallest-axis", Vec3::new(10.0, 0.01, 0.01)),
        ("middle-axis", Vec3::new(0.01, 10.0, 0.01)),
    ]
}

/// Energy traces of every method for every long spin, `seconds` long.
pub fn traces(seconds: usize) -> Vec<EnergyTrace> {
    let dt = 1.0 / 60.0;
    let mass = MassProperties::new(Mass::new(1.0).expect("valid"), Vec3::new(1.0, 2.0, 3.0))
        .expect("valid");
    let mut out = Vec::new();
    for (spin, omega0) in spins() {
        let initial = BodyState {
            angular_velocity: omega0,
            ..Default::default()
        };
        let e0 = to_f64(kinetic_energy(&initial, &mass));
        for method in Method::all() {
            let mut values = vec![0.0];
            match method {
                Method::Tumble(integrator) => {
                    let mut state = initial;
                    for _ in 0..seconds {
                        for _ in 0..60 {
                            if integrator
                                .try_step(&mut state, &mass, &Wrench::ZERO, dt)
                                .is_err()
                            {
                                state.angular_velocity = Vec3::NAN;
                            }
                        }
                        values.push(to_f64(kinetic_energy(&state, &mass)) / e0 - 1.0);
                    }
                }
                Method::Rapier => {
                    let scene = ComparisonScene::new(
                        dt,
                        None,
                        vec![ComparisonBody::new(spin, mass, initial)],
                    );
                    let mut world = RapierScene::new(&scene, true, 4);
                    for _ in 0..seconds {
                        for _ in 0..60 {
                            world.step();
                        }
                        let s = world.state(0);
                        values.push(to_f64(kinetic_energy(&s, &mass)) / e0 - 1.0);
                    }
                }
            }
            out.push(EnergyTrace {
                spin: spin.to_owned(),
                method: method.name(),
                relative_energy: values,
            });
        }
    }
    out
}
