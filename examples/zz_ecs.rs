use tumble::bevy_ecs::prelude::*;
use tumble::glam::{Quat, Vec3};
use tumble::prelude::*;
fn main() {
    let n: usize = std::env::args().nth(1).unwrap().parse().unwrap();
    let grav: bool = std::env::args().nth(2).unwrap() == "g";
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(1.0 / 60.0, Integrator::Splitting).unwrap());
    world.insert_resource(tumble::ecs::parallel::Parallelism::SINGLE_THREAD);
    if grav {
        world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
    }
    for i in 0..n {
        let f = i as f32 / n as f32;
        world.spawn((
            RigidBody,
            Transform::from_rotation(Quat::from_rotation_y(f)),
            Velocity {
                linear: Vec3::X,
                angular: Vec3::new(0.3, 0.2, 0.1 + f),
            },
            MassProps(
                MassProperties::new(Mass::new(1.0).unwrap(), Vec3::new(1.0, 2.0 + f, 3.0)).unwrap(),
            ),
        ));
    }
    let mut schedule = PhysicsPlan::for_world(&mut world).build_schedule();
    let steps = 1_000_000 / n;
    let t = std::time::Instant::now();
    for _ in 0..steps {
        schedule.run(&mut world);
        world.clear_trackers();
    }
    println!(
        "{:.1} ns/body-step",
        t.elapsed().as_nanos() as f64 / (steps * n) as f64
    );
}
