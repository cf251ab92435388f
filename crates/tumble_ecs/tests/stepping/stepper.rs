//! Fixed step for variable frame times: accumulator, step cap, interpolation factor.

use tumble_core::math::{Quat, Real, Vec3, to_f64};
use tumble_ecs::prelude::*;

fn settings(dt: Real) -> PhysicsSettings {
    PhysicsSettings::new(dt, Integrator::Splitting).unwrap()
}

#[test]
fn accumulates_partial_frames() {
    let at = settings(0.01);
    let mut s = FixedStepper::new(8).unwrap();
    let f = s.advance(0.025, &at).unwrap();
    assert_eq!(f.steps, 2);
    assert!((f.alpha - 0.5).abs() < 1e-5);
    let f = s.advance(0.006, &at).unwrap();
    assert_eq!(f.steps, 1);
    assert!((f.alpha - 0.1).abs() < 1e-4);
    // Over many irregular frames, steps × Δt tracks wall time to within one step.
    let mut total_steps = 3u64;
    let mut time = 0.031;
    for k in 0..10_000 {
        let frame = 0.004 + 0.003 * ((k * 7919) % 13) as f64 / 13.0;
        time += frame;
        total_steps += u64::from(s.advance(frame, &at).unwrap().steps);
    }
    let simulated = total_steps as f64 * to_f64(at.dt());
    assert!((time - simulated).abs() <= to_f64(at.dt()) + 1e-9);
}

/// Frames of exactly one step (the display's rate is the physics rate) give one step each,
/// from the first frame on, though the step in the engine's precision is a hair longer than
/// the frame (`1/60` in `f32`); and frames of exactly `k` steps give `k` each.
#[test]
fn frames_of_whole_steps_give_whole_steps_at_once() {
    for (hz, steps_per_frame) in [(60.0, 1), (144.0, 1), (30.0, 2), (120.0, 3)] {
        let at = settings((1.0 / (hz * f64::from(steps_per_frame))) as Real);
        let mut s = FixedStepper::new(8).unwrap();
        for frame in 0..6000 {
            let f = s.advance(1.0 / hz, &at).unwrap();
            assert_eq!(f.steps, steps_per_frame, "{hz} Hz, frame {frame}");
        }
    }
}

/// The step is the world's: a time step changed in the settings mid-run is followed at the
/// next frame (a stepper with a step of its own kept running the old one).
#[test]
fn the_step_follows_the_settings() {
    let mut s = FixedStepper::new(16).unwrap();
    assert_eq!(s.advance(0.1, &settings(0.01)).unwrap().steps, 10);
    assert_eq!(s.advance(0.1, &settings(0.02)).unwrap().steps, 5);
}

#[test]
fn caps_steps_and_drops_the_backlog() {
    let at = settings(0.01);
    let mut s = FixedStepper::new(4).unwrap();
    let f = s.advance(1.0, &at).unwrap(); // a 1 s hitch
    assert_eq!(f.steps, 4);
    assert!(f.alpha < 1.0);
    assert!((s.dropped_time() - 0.96).abs() < 0.011);
    let f = s.advance(0.01, &at).unwrap();
    assert!(f.steps <= 2, "no spiral of death: {}", f.steps);
}

#[test]
fn rejects_bad_input() {
    assert!(FixedStepper::new(0).is_err());
    let at = settings(0.01);
    let mut s = FixedStepper::new(4).unwrap();
    assert!(s.advance(-1.0, &at).is_err());
    assert!(s.advance(f64::NAN, &at).is_err());
    assert_eq!(s.advance(0.0, &at).unwrap().steps, 0);
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
