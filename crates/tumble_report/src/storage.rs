//! What `f32` state costs: the default step run in `f64` twice on each reference scene, once as
//! is and once with every body's pose and velocities rounded to `f32` after each step, as the
//! `f32` build stores them (its arithmetic inside a step is mostly `f64` already). The
//! difference is the error the `f32` build adds by storing the state, apart from the method's
//! own error, which the work–precision curves show in `f64`.

use bevy_ecs::prelude::*;
use serde::Serialize;
use tumble_core::Integrator;
use tumble_core::math::{DOUBLE_PRECISION, Quat, Real, Vec3, Widen, to_f64};
use tumble_core::rotation::angle_between;
use tumble_ecs::prelude::{FreeFlow, Pose, SpringSolver, Velocity};
use tumble_rapier::TumbleScene;

use crate::reference::{Case, to_quat};
use crate::workprec::comparison_scene;

/// The step the table is measured at (s): the default game step.
pub const STORAGE_DT: f64 = 1.0 / 60.0;

/// One scene's row.
#[derive(Debug, Clone, Serialize)]
pub struct StorageRow {
    /// Scene name.
    pub scene: String,
    /// Orientation error of the `f64` run against the exact solution at the horizon (rad).
    pub f64_error_rad: f64,
    /// Position error of the `f64` run against the exact solution at the horizon (m).
    pub f64_error_m: f64,
    /// Orientation difference the `f32` storage makes at the horizon (rad).
    pub f32_storage_rad: f64,
    /// Position difference the `f32` storage makes at the horizon (m).
    pub f32_storage_m: f64,
}

/// `x` rounded to the nearest `f32` (a no-op in an `f32` build).
#[allow(
    clippy::unnecessary_cast,
    reason = "the cast rounds in an f64 build and is a no-op only where `Real` is f32"
)]
fn to_f32(x: Real) -> Real {
    x as f32 as Real
}

fn vec_to_f32(v: Vec3) -> Vec3 {
    Vec3::new(to_f32(v.x), to_f32(v.y), to_f32(v.z))
}

/// Rounds every body's pose and velocities to `f32`, as the `f32` build stores them.
pub fn store_as_f32(world: &mut World) {
    let mut bodies = world.query::<(&mut Pose, &mut Velocity)>();
    for (mut pose, mut velocity) in bodies.iter_mut(world) {
        pose.translation = vec_to_f32(pose.translation);
        let q = pose.rotation;
        pose.rotation = Quat::from_xyzw(to_f32(q.x), to_f32(q.y), to_f32(q.z), to_f32(q.w));
        velocity.linear = vec_to_f32(velocity.linear);
        velocity.angular = vec_to_f32(velocity.angular);
    }
}

/// The table, one row per scene; empty in an `f32` build, where both runs are the same.
pub fn storage_table(cases: &[Case]) -> Vec<StorageRow> {
    if !DOUBLE_PRECISION {
        return Vec::new();
    }
    cases.iter().map(storage_row).collect()
}

fn storage_row(case: &Case) -> StorageRow {
    let steps = (case.horizon / STORAGE_DT).round() as usize;
    let scene = comparison_scene(case, STORAGE_DT as Real, 1, true);
    let run = |round: bool| {
        let mut world = TumbleScene::with_free_flow(
            &scene,
            Integrator::default(),
            SpringSolver::Auto,
            FreeFlow::Auto,
        );
        if round {
            store_as_f32(world.world_mut());
        }
        for _ in 0..steps {
            world.step();
            if round {
                store_as_f32(world.world_mut());
            }
        }
        world.state(0)
    };
    let (exact64, stored32) = (run(false), run(true));
    let t = steps as f64 * STORAGE_DT;
    let (x, q) = (case.exact)(t);
    StorageRow {
        scene: case.name.to_owned(),
        f64_error_rad: angle_between(exact64.rotation, to_quat(q)),
        f64_error_m: (exact64.position.widen() - x).length(),
        f32_storage_rad: angle_between(exact64.rotation, stored32.rotation),
        f32_storage_m: to_f64((exact64.position - stored32.position).length()),
    }
}

/// The table as markdown, or a note saying how to get it in an `f32` build.
pub fn storage_section(rows: &[StorageRow]) -> String {
    let mut s = String::from("## What `f32` state costs\n\n");
    if rows.is_empty() {
        s.push_str(
            "This report ran in `f32` state, so the work–precision curves above include the \
             error of storing the state in `f32`. Build it with `--features f64` for curves of \
             the methods alone and this table.\n\n",
        );
        return s;
    }
    s.push_str(&format!(
        "The default step (`{}`) at Δt = 1/60 s, run in `f64` and again with every body's pose \
         and velocities rounded to `f32` after each step, as the `f32` build stores them. The \
         difference at each scene's horizon is what `f32` state adds to the method's own \
         error.\n\n| scene | `f64` error vs exact (rad) | `f32` storage (rad) | `f64` error vs exact \
         (m) | `f32` storage (m) |\n|---|---:|---:|---:|---:|\n",
        Integrator::default()
    ));
    for r in rows {
        s.push_str(&format!(
            "| {} | {:.2e} | {:.2e} | {:.2e} | {:.2e} |\n",
            r.scene, r.f64_error_rad, r.f32_storage_rad, r.f64_error_m, r.f32_storage_m
        ));
    }
    s.push('\n');
    s
}
