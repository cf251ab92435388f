//! Cost of one body-step of each integrator over an array of bodies (plain data, no ECS):
//! torque-free asymmetric bodies with varied rates, as in a scene of many tumbling objects.
//! Rates stay below 1.5 rad/s so that even the explicit textbook step stays finite for the
//! whole measurement (its blow-up time is over 1000 s here): a benchmark of NaN arithmetic
//! would measure nothing.

mod common;

use criterion::{BenchmarkId, Criterion, Throughput};
use tumble::core::integrate::{ExactSwitch, FreeFlow};
use tumble::math::{Quat, Real, Vec3};

use tumble::prelude::*;

fn bodies(n: usize) -> (Vec<BodyState>, Vec<MassProperties>) {
    let mut states = Vec::with_capacity(n);
    let mut masses = Vec::with_capacity(n);
    for i in 0..n {
        let f = i as Real / n as Real;
        states.push(BodyState {
            position: Vec3::new(f, 2.0 * f, 0.0),
            rotation: Quat::from_rotation_y(f * 3.0),
            linear_velocity: Vec3::new(1.0, 0.0, f),
            angular_velocity: Vec3::new(0.3 + f, 1.0 - f, 0.3),
        });
        let inertia = Vec3::new(1.0, 2.0 + f, 3.0 + f);
        masses.push(MassProperties::new(Mass::new(1.0 + f).unwrap(), inertia).unwrap());
    }
    (states, masses)
}

fn step_all(c: &mut Criterion) {
    let n = 10_000;
    let mut group = c.benchmark_group("body_step");
    group.throughput(Throughput::Elements(n as u64));
    let (states0, masses) = bodies(n);
    for &integrator in Integrator::ALL {
        group.bench_with_input(
            BenchmarkId::from_parameter(integrator),
            &integrator,
            |b, &it| {
                let mut states = states0.clone();
                b.iter(|| {
                    for (state, mass) in states.iter_mut().zip(&masses) {
                        it.step(state, mass, &Wrench::ZERO, 1.0 / 60.0);
                    }
                });
            },
        );
    }
    for &integrator in &[Integrator::Splitting, Integrator::SymplecticEuler] {
        group.bench_with_input(
            BenchmarkId::new("try", integrator),
            &integrator,
            |b, &it| {
                let mut states = states0.clone();
                b.iter(|| {
                    for (state, mass) in states.iter_mut().zip(&masses) {
                        let _ = it.try_step(state, mass, &Wrench::ZERO, 1.0 / 60.0);
                    }
                });
            },
        );
        group.bench_with_input(
            BenchmarkId::new("many", integrator),
            &integrator,
            |b, &it| {
                let mut states = states0.clone();
                let wrenches = vec![Wrench::ZERO; n];
                b.iter(|| it.try_step_many(&mut states, &masses, &wrenches, 1.0 / 60.0));
            },
        );
    }
    // What the default free-flow check (`FreeFlow::Auto`) costs a body that keeps the split:
    // the same batch with and without the switch, on bodies turning slowly enough that none
    // switches (a third of the rates above).
    let slow: Vec<BodyState> = states0
        .iter()
        .map(|s| BodyState {
            angular_velocity: s.angular_velocity / 3.0,
            ..*s
        })
        .collect();
    let switch = ExactSwitch::new(Integrator::Splitting, FreeFlow::Auto, 1.0 / 60.0);
    assert!(
        slow.iter()
            .zip(&masses)
            .all(|(s, m)| !switch.unwrap().applies(s, m)),
        "a body of the slow set would switch"
    );
    for (name, switch) in [("split", None), ("auto", switch)] {
        group.bench_with_input(BenchmarkId::new("free_flow", name), &switch, |b, &sw| {
            let mut states = slow.clone();
            let wrenches = vec![Wrench::ZERO; n];
            b.iter(|| {
                Integrator::Splitting.try_step_many_switched(
                    &mut states,
                    &masses,
                    &wrenches,
                    1.0 / 60.0,
                    sw,
                )
            });
        });
    }
    // What the switch costs where it applies: bodies spun ten times faster, which it hands to
    // the exact flow (`exact`, or `exact4` for `yoshida4`), two at a time in the batch.
    for (integrator, factor) in [(Integrator::Splitting, 10.0), (Integrator::Yoshida4, 40.0)] {
        let spun: Vec<BodyState> = states0
            .iter()
            .map(|s| BodyState {
                angular_velocity: s.angular_velocity * factor,
                ..*s
            })
            .collect();
        let switch = ExactSwitch::new(integrator, FreeFlow::Auto, 1.0 / 60.0);
        let switched = spun
            .iter()
            .zip(&masses)
            .filter(|(s, m)| switch.is_some_and(|sw| sw.applies(s, m)))
            .count();
        assert!(
            switched > n / 2,
            "{integrator}: only {switched} of {n} spun bodies switch"
        );
        let id = BenchmarkId::new("free_flow_spun", integrator);
        group.bench_with_input(id, &switch, |b, &sw| {
            let mut states = spun.clone();
            let wrenches = vec![Wrench::ZERO; n];
            b.iter(|| {
                integrator.try_step_many_switched(&mut states, &masses, &wrenches, 1.0 / 60.0, sw)
            });
        });
    }
    group.finish();
}

fn main() {
    common::run(step_all, 2);
}
