//! `tumble`: run a scene file headless, write its trajectory, list the bundled scenes.

mod compare;

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use tumble_core::math::{Vec3, Widen, to_f64};

use bevy_ecs::prelude::*;
use clap::{Parser, Subcommand};
use tumble_core::invariants::{angular_momentum, kinetic_energy};
use tumble_ecs::components::body_state;
use tumble_ecs::prelude::*;
use tumble_scene::{Scene, SceneError, read_scene_text, write_trajectory};

/// The scenes shipped in `scenes/`, embedded so `tumble scenes` works from anywhere.
const BUNDLED: &[(&str, &str)] = &[
    (
        "projectile",
        include_str!("../../../scenes/projectile.toml"),
    ),
    (
        "principal_spins",
        include_str!("../../../scenes/principal_spins.toml"),
    ),
    (
        "dzhanibekov",
        include_str!("../../../scenes/dzhanibekov.toml"),
    ),
    (
        "spinning_top",
        include_str!("../../../scenes/spinning_top.toml"),
    ),
    (
        "spring_chain",
        include_str!("../../../scenes/spring_chain.toml"),
    ),
    ("thin_rod", include_str!("../../../scenes/thin_rod.toml")),
    (
        "mass_ratio",
        include_str!("../../../scenes/mass_ratio.toml"),
    ),
    ("far_away", include_str!("../../../scenes/far_away.toml")),
    ("long_run", include_str!("../../../scenes/long_run.toml")),
];

/// tumble: rigid-body dynamics for headless game loops.
#[derive(Parser)]
#[command(version)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum GenKind {
    /// Many tumbling bodies under gravity, on a grid.
    Many {
        /// Number of bodies.
        #[arg(long, default_value_t = 100_000)]
        n: usize,
        /// Steps.
        #[arg(long, default_value_t = 600)]
        steps: u64,
        /// Output file (default: stdout).
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene file (or a bundled scene by name) and print a summary.
    Run {
        /// Scene file, or the name of a bundled scene.
        scene: String,
        /// Override the number of steps.
        #[arg(long)]
        steps: Option<u64>,
        /// Override the time step (s).
        #[arg(long)]
        dt: Option<f64>,
        /// Override the integrator.
        #[arg(long)]
        integrator: Option<String>,
        /// Write the trajectory to this CSV file.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Record every K-th step (step 0 is always recorded).
        #[arg(long, default_value_t = 1)]
        every: u64,
        /// Print the planned systems and exit.
        #[arg(long)]
        plan: bool,
    },
    /// List the bundled scenes.
    Scenes,
    /// Generate a scene.
    Gen {
        #[command(subcommand)]
        kind: GenKind,
    },
    /// Run a scene in tumble and in rapier 0.36 side by side and print the differences.
    Compare {
        /// Scene file, or the name of a bundled scene.
        scene: String,
        /// tumble's integrator (default: the scene's).
        #[arg(long)]
        integrator: Option<String>,
        /// rapier's gyroscopic term.
        #[arg(long, default_value = "on", value_parser = ["on", "off"])]
        gyroscopic: String,
    },
    /// The accuracy report: work–precision, stability matrix, plots.
    Report(tumble_report::run::ReportOptions),
    /// Throughput: ECS vs raw loop vs rapier, 1 and 2 threads, N = 1 … 10⁶, memory bandwidth.
    Bench(tumble_bench::BenchOptions),
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}

fn load(scene: &str) -> Result<(String, String), String> {
    if let Some((_, text)) = BUNDLED.iter().find(|(name, _)| *name == scene) {
        return Ok((format!("scenes/{scene}.toml"), (*text).to_owned()));
    }
    let text = read_scene_text(std::path::Path::new(scene)).map_err(|e| e.to_string())?;
    Ok((scene.to_owned(), text))
}

/// Names the command-line flag behind an error in an overridden world setting, so the message
/// does not point at a line of a file the user never wrote.
fn override_error(e: SceneError, dt: Option<f64>, steps: Option<u64>, integrator: bool) -> String {
    let flag = match e.field.as_str() {
        "world.dt" if dt.is_some() => "--dt",
        "world.steps" if steps.is_some() => "--steps",
        "world.integrator" if integrator => "--integrator",
        _ => return e.to_string(),
    };
    format!("{flag}: {}", e.message)
}

fn run(cli: Cli) -> Result<(), String> {
    match cli.command {
        Command::Gen {
            kind: GenKind::Many { n, steps, out },
        } => {
            let text = many_bodies(n, steps);
            match out {
                Some(path) => {
                    std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))
                }
                None => {
                    print!("{text}");
                    Ok(())
                }
            }
        }
        Command::Scenes => {
            for (name, text) in BUNDLED {
                let first = text.lines().find(|l| l.starts_with("name")).unwrap_or("");
                println!("{name:<16} {first}");
            }
            println!(
                "{:<16} generated: tumble gen many --n 100000 --out many.toml",
                "many"
            );
            Ok(())
        }
        Command::Compare {
            scene,
            integrator,
            gyroscopic,
        } => {
            let (file, text) = load(&scene)?;
            let scene = Scene::parse(&file, &text).map_err(|e| e.to_string())?;
            let integrator = match integrator {
                Some(name) => name
                    .parse()
                    .map_err(|e: tumble_core::integrate::UnknownIntegrator| e.to_string())?,
                None => scene.integrator(),
            };
            compare::run(&scene, integrator, gyroscopic == "on")
        }
        Command::Report(options) => {
            tumble_report::run::run_report(&options).map_err(|e| e.to_string())
        }
        Command::Bench(options) => tumble_bench::run_and_write(&options).map_err(|e| e.to_string()),
        Command::Run {
            scene,
            steps,
            dt,
            integrator,
            out,
            every,
            plan,
        } => {
            if every == 0 {
                return Err("--every: expected a value >= 1".into());
            }
            let (file, text) = load(&scene)?;
            let mut scene = Scene::parse(&file, &text).map_err(|e| e.to_string())?;
            if steps.is_some() || dt.is_some() || integrator.is_some() {
                // Overrides are applied to the file model, then validated like the file itself.
                let mut model = scene.file().clone();
                model.world.steps = steps.unwrap_or(model.world.steps);
                model.world.dt = dt.unwrap_or(model.world.dt);
                let overridden = integrator.is_some();
                model.world.integrator = integrator.or(model.world.integrator);
                let text = tumble_scene::to_toml_string(&model).map_err(|e| e.to_string())?;
                scene = Scene::parse(&file, &text)
                    .map_err(|e| override_error(e, dt, steps, overridden))?;
            }
            let mut built = scene.build();
            if plan {
                println!("{}", PhysicsPlan::for_world(&mut built.world));
                return Ok(());
            }
            // Energy and angular momentum are invariants only of free, undamped bodies.
            let invariant = scene.gravity().is_none()
                && scene.file().forces.is_empty()
                && scene
                    .file()
                    .bodies
                    .iter()
                    .all(|b| b.linear_damping == 0.0 && b.angular_damping == 0.0);
            let before = totals(&mut built.world);
            let start = Instant::now();
            match &out {
                Some(path) => write_trajectory(&mut built, scene.dt(), scene.steps(), every, path)
                    .map_err(|e| format!("{}: {e}", path.display()))?,
                None => {
                    for _ in 0..scene.steps() {
                        built.schedule.run(&mut built.world);
                        built.world.clear_trackers();
                    }
                }
            }
            let wall = start.elapsed();
            let after = totals(&mut built.world);
            let body_steps = (scene.steps() as f64) * built.bodies.len().max(1) as f64;
            println!("scene      {}", scene.file().name);
            println!("bodies     {}", built.bodies.len());
            println!(
                "steps      {} × {} s ({})",
                scene.steps(),
                scene.dt(),
                scene.integrator()
            );
            println!(
                "wall time  {:.3} s, {:.1} ns per body-step",
                wall.as_secs_f64(),
                wall.as_nanos() as f64 / body_steps
            );
            if invariant {
                println!("energy     {}", drift(before.0, after.0));
                println!("|L|        {}", drift(before.1, after.1));
            }
            let rejected = built.world.query::<&Rejected>().iter(&built.world).count();
            if rejected > 0 {
                println!("rejected   {rejected} bodies (see warnings)");
            }
            Ok(())
        }
    }
}

/// The relative drift `after/before − 1`, or the absolute change when `before` is zero.
fn drift(before: f64, after: f64) -> String {
    if before == 0.0 {
        format!("absolute change {:.3e} (zero at the start)", after - before)
    } else {
        format!("relative drift {:.3e}", after / before - 1.0)
    }
}

/// Total kinetic energy and |ΣL| of the bodies.
fn totals(world: &mut World) -> (f64, f64) {
    let mut q = world.query_filtered::<(&Transform, &Velocity, &MassProps), With<RigidBody>>();
    let (mut e, mut l) = (0.0, Vec3::ZERO.widen());
    for (t, v, m) in q.iter(world) {
        let s = body_state(t, v, m);
        e += to_f64(kinetic_energy(&s, m));
        l += angular_momentum(&s, m).widen();
    }
    (e, l.length())
}

/// A scene of `n` asymmetric bodies on a cubic grid, each with its own spin, under gravity.
fn many_bodies(n: usize, steps: u64) -> String {
    use std::fmt::Write as _;
    let side = (n as f64).cbrt().ceil().max(1.0) as usize;
    let mut text = format!(
        "name = \"many-{n}\"\n[world]\ndt = 0.016666668\nsteps = {steps}\ngravity = [0.0, -9.81, 0.0]\n"
    );
    for i in 0..n {
        let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
        let f = i as f64 / n.max(1) as f64;
        let _ = write!(
            text,
            "[[bodies]]\nname = \"b{i}\"\nmass = {}\ninertia = [1.0, {}, {}]\nposition = [{}, {}, {}]\nlinear_velocity = [0.0, {}, 0.0]\nangular_velocity = [{}, {}, 0.3]\n",
            1.0 + f,
            2.0 + f,
            3.0 + f,
            2 * x,
            2 * y,
            2 * z,
            5.0 * f,
            0.3 + f,
            1.0 - f
        );
    }
    text
}
