//! The generated scene of many tumbling bodies (`tumble gen many`, and the benchmark's CSV
//! measurement): one definition of its bodies for every writer.

use crate::format::{BodyDef, WorldDef};

/// Body `i` of `n` of the generated scene: asymmetric, on a cubic grid of spacing 2 m, each with
/// its own mass, inertia, fall speed and spin.
pub fn many_body(i: u64, n: u64) -> BodyDef {
    let side = (n as f64).cbrt().ceil().max(1.0) as u64;
    let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
    let f = i as f64 / n.max(1) as f64;
    BodyDef {
        name: format!("b{i}"),
        mass: Some(1.0 + f),
        inertia: Some([1.0, 2.0 + f, 3.0 + f]),
        shape: None,
        density: None,
        position: [2.0 * x as f64, 2.0 * y as f64, 2.0 * z as f64],
        rotation: [0.0, 0.0, 0.0, 1.0],
        linear_velocity: [0.0, 5.0 * f, 0.0],
        angular_velocity: [0.3 + f, 1.0 - f, 0.3],
        gravity_scale: 1.0,
        linear_damping: 0.0,
        angular_damping: 0.0,
    }
}

/// The generated scene's world: 60 Hz steps under gravity.
pub fn many_world(steps: u64) -> WorldDef {
    WorldDef {
        dt: 0.016666668,
        steps,
        integrator: None,
        springs: None,
        free_flow: None,
        substeps: None,
        gravity: Some([0.0, -9.81, 0.0]),
    }
}
