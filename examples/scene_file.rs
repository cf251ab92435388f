//! A scene file loaded from code: the bundled spinning top (`scenes/spinning_top.toml`) read,
//! validated and built into a world, stepped to its end, and its bodies' poses read back by
//! name. A second scene is parsed from a string, with an error that names its line and field.
//! Run: `cargo run --release --features scene --example scene_file`.

use std::path::Path;

use tumble::prelude::*;
use tumble::scene::{Scene, load_scene};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/spinning_top.toml");
    let scene = load_scene(&path)?;
    println!(
        "{}: {} steps of {} s with `{}`",
        scene.name(),
        scene.steps(),
        scene.dt(),
        scene.integrator()
    );
    let steps = scene.steps();
    let mut built = scene.build();
    for _ in 0..steps {
        built.step();
    }
    for (name, entity) in &built.bodies {
        let pose = built
            .world
            .get::<Pose>(*entity)
            .ok_or("a body without a pose")?;
        println!(
            "{name}: at {:.3}, rotation {:.4}",
            pose.translation, pose.rotation
        );
    }
    let errors = built.world.resource::<PhysicsErrors>();
    if !errors.is_empty() {
        return Err(format!("physics errors: {errors:?}").into());
    }

    // A scene from a string; a bad value is an error naming the line and the field.
    let bad = "name = \"bad\"\n[world]\ndt = -0.01\nsteps = 10\n";
    match Scene::parse("inline.toml", bad) {
        Ok(_) => return Err("a negative time step was accepted".into()),
        Err(e) => println!("as expected: {e}"),
    }
    Ok(())
}
