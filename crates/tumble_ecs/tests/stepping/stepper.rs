//! Fixed step for variable frame times: accumulator, step cap, interpolation factor.

use tumble_core::math::{Quat, Real, Vec3, to_f64};
use tumble_ecs::prelude::*;

#[test]
fn accumulates_partial_frames() {
    let mut s = FixedStepper::new(0.01, 8).unwrap();
    let f = s.advance(0.025).unwrap();
    assert_eq!(f.steps, 2);
    assert!((f.alpha - 0.5).abs() < 1e-5);
    let f = s.advance(0.006).unwrap();
    assert_eq!(f.steps, 1);
    assert!((f.alpha - 0.1).abs() < 1e-4);
    // Over many irregular frames, steps × Δt tracks wall time to within one step.
    let mut total_steps = 3u64;
    let mut time = 0.031;
    for k in 0..10_000 {
        let frame = 0.004 + 0.003 * ((k * 7919) % 13) as f64 / 13.0;
        time += frame;
        total_steps += u64::from(s.advance(frame).unwrap().steps);
    }
    let simulated = total_steps as f64 * to_f64(s.dt());
    assert!((time - simulated).abs() <= to_f64(s.dt()) + 1e-9);
}

#[test]
fn caps_steps_and_drops_the_backlog() {
    let mut s = FixedStepper::new(0.01, 4).unwrap();
    let f = s.advance(1.0).unwrap(); // a 1 s hitch
    assert_eq!(f.steps, 4);
    assert!(f.alpha < 1.0);
    assert!((s.dropped_time() - 0.96).abs() < 0.011);
    let f = s.advance(0.01).unwrap();
    assert!(f.steps <= 2, "no spiral of death: {}", f.steps);
}

#[test]
fn rejects_bad_input() {
    assert!(FixedStepper::new(0.0, 4).is_err());
    assert!(FixedStepper::new(Real::NAN, 4).is_err());
    assert!(FixedStepper::new(0.01, 0).is_err());
    let mut s = FixedStepper::new(0.01, 4).unwrap();
    assert!(s.advance(-1.0).is_err());
    assert!(s.advance(f64::NAN).is_err());
    assert_eq!(s.advance(0.0).unwrap().steps, 0);
}

#[test]
fn interpolation_is_linear_and_spherical() {
    let a = Pose::IDENTITY;
    let b = Pose {
        translation: Vec3::new(2.0, 0.0, 0.0),
        rotation: Quat::from_rotation_z(1.0),
    };
    let mid = interpolate(&a, &b, 0.5);
    assert!((mid.translation - Vec3::X).length() < 1e-6);
    assert!(mid.rotation.angle_between(Quat::from_rotation_z(0.5)) < 1e-5);
    assert_eq!(interpolate(&a, &b, 0.0).translation, a.translation);
}
