//! Trajectory recording as CSV.

use std::io::Write;
use std::path::Path;
use tumble_core::math::{Real, to_f64};

use bevy_ecs::prelude::*;
use tumble_ecs::prelude::*;

use crate::build::BuiltScene;

/// The CSV header, exactly.
pub const CSV_HEADER: &str = "step,time,body,px,py,pz,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz";

/// Runs `steps` steps of a built scene, writing step 0 and then every `every`-th step to `out`
/// (`px..pz` is `Transform::translation`, `w*` the world-frame angular velocity). The file is
/// written to a temporary name and renamed only when complete.
pub fn write_trajectory(
    scene: &mut BuiltScene,
    dt: Real,
    steps: u64,
    every: u64,
    out: &Path,
) -> std::io::Result<()> {
    let tmp = out.with_extension("csv.partial");
    let result = (|| {
        let mut w = std::io::BufWriter::new(std::fs::File::create(&tmp)?);
        writeln!(w, "{CSV_HEADER}")?;
        write_rows(&mut w, scene, 0, dt)?;
        for step in 1..=steps {
            scene.schedule.run(&mut scene.world);
            scene.world.clear_trackers();
            if step % every.max(1) == 0 {
                write_rows(&mut w, scene, step, dt)?;
            }
        }
        w.flush()
    })();
    match result {
        Ok(()) => std::fs::rename(&tmp, out),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

fn write_rows(w: &mut impl Write, scene: &BuiltScene, step: u64, dt: Real) -> std::io::Result<()> {
    let time = to_f64(dt) * step as f64;
    for (name, e) in &scene.bodies {
        let world: &World = &scene.world;
        let (Some(t), Some(v)) = (world.get::<Transform>(*e), world.get::<Velocity>(*e)) else {
            continue;
        };
        let q = t.rotation;
        writeln!(
            w,
            "{step},{time},{name},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            t.translation.x,
            t.translation.y,
            t.translation.z,
            q.x,
            q.y,
            q.z,
            q.w,
            v.linear.x,
            v.linear.y,
            v.linear.z,
            v.angular.x,
            v.angular.y,
            v.angular.z
        )?;
    }
    Ok(())
}
