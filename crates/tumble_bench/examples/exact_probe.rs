use tumble_core::math::Vec3;
use tumble_core::{BodyState, Integrator, Mass, MassProperties, Wrench};
fn main() {
    let n = 1000;
    let mut bodies: Vec<(BodyState, MassProperties)> = (0..n)
        .map(|i| {
            let f = (i as f32 + 0.5) / n as f32;
            let g = (i as f32 * 0.618_034).fract();
            let mass = MassProperties::new(Mass::new(1.0).unwrap(), Vec3::new(1.0, 2.0 + f, 3.0 + f * g)).unwrap();
            let state = BodyState { angular_velocity: Vec3::new(0.3 + f, 1.0 - g, 0.2 + 0.5 * g) * 0.3, ..Default::default() };
            (state, mass)
        })
        .collect();
    let w = Wrench { force: Vec3::new(0.0, -9.81, 0.0), torque: Vec3::ZERO };
    for _ in 0..100 {
        for (s, m) in bodies.iter_mut() {
            Integrator::Exact.begin_stage(s, m, 1.0 / 60.0);
            Integrator::Exact.finish_stage(s, m, &w, 1.0 / 60.0);
        }
    }
    println!("{:?}", bodies[7].0.rotation);
}
