//! `tumble run`'s overrides of the scene's world settings (`--steps`, `--dt`, `--integrator`,
//! `--springs`, `--free-flow`, `--substeps`), checked like the file's own.

use tumble_scene::{MAX_STEPS, MAX_SUBSTEPS, Scene, SceneError};

use crate::cli::RunArgs;
use crate::exit::{self, Failure};

/// The world settings given on the command line.
pub(crate) struct Overrides {
    steps: Option<u64>,
    dt: Option<f64>,
    integrator: Option<String>,
    springs: Option<String>,
    free_flow: Option<String>,
    substeps: Option<u64>,
}

impl Overrides {
    /// The overrides in `args` (taken out of it), each checked for its range and encoding.
    pub(crate) fn of(args: &mut RunArgs) -> Result<Self, Failure> {
        let text = |flag: &str, value: Option<std::ffi::OsString>| {
            value.map(|v| crate::utf8(flag, v)).transpose()
        };
        Ok(Self {
            steps: count_up_to("--steps", args.steps, MAX_STEPS, "steps")?,
            dt: args.dt,
            integrator: text("--integrator", args.integrator.take())?,
            springs: text("--springs", args.springs.take())?,
            free_flow: text("--free-flow", args.free_flow.take())?,
            substeps: count_up_to("--substeps", args.substeps, MAX_SUBSTEPS.into(), "substeps")?,
        })
    }

    /// `scene` with the overrides applied to its world settings and validated like the file's.
    pub(crate) fn apply(self, scene: Scene) -> Result<Scene, Failure> {
        if self.steps.is_none()
            && self.dt.is_none()
            && self.integrator.is_none()
            && self.springs.is_none()
            && self.free_flow.is_none()
            && self.substeps.is_none()
        {
            return Ok(scene);
        }
        let mut world = scene.file().world.clone();
        world.steps = self.steps.unwrap_or(world.steps);
        world.dt = self.dt.unwrap_or(world.dt);
        let integrator = self.integrator.is_some();
        world.integrator = self.integrator.or(world.integrator);
        let springs = self.springs.is_some();
        world.springs = self.springs.or(world.springs);
        let free_flow = self.free_flow.is_some();
        world.free_flow = self.free_flow.or(world.free_flow);
        world.substeps = self.substeps.or(world.substeps);
        scene.with_world(world).map_err(|e| {
            override_error(
                e,
                self.dt,
                self.steps,
                integrator,
                springs,
                free_flow,
                self.substeps.is_some(),
            )
        })
    }
}

/// Names the command-line flag behind an error in an overridden world setting, so the message
/// does not point at a line of a file the user never wrote.
fn override_error(
    e: SceneError,
    dt: Option<f64>,
    steps: Option<u64>,
    integrator: bool,
    springs: bool,
    free_flow: bool,
    substeps: bool,
) -> Failure {
    let flag = match e.field.as_str() {
        "world.dt" if dt.is_some() => "--dt",
        "world.steps" if steps.is_some() => "--steps",
        "world.integrator" if integrator => "--integrator",
        "world.springs" if springs => "--springs",
        "world.free_flow" if free_flow => "--free-flow",
        "world.substeps" if substeps => "--substeps",
        field if field.starts_with("world.") => {
            // A setting the file gave, refused only beside a flag's value (the file's
            // substeps under a shorter `--dt`): blame the flags, and name the file's field.
            let given = [
                ("--dt", dt.is_some()),
                ("--steps", steps.is_some()),
                ("--integrator", integrator),
                ("--springs", springs),
                ("--free-flow", free_flow),
                ("--substeps", substeps),
            ];
            let flags: Vec<&str> = given
                .iter()
                .filter(|(_, on)| *on)
                .map(|(flag, _)| *flag)
                .collect();
            return Failure::new(
                exit::ERROR,
                format!(
                    "{}: with the scene file's `{field}`: {}",
                    flags.join(", "),
                    e.message
                ),
            );
        }
        _ => return e.into(),
    };
    Failure::new(exit::ERROR, format!("{flag}: {}", e.message))
}

/// The count given to `flag`, if any, checked to be in `1..=max`: an error `flag: expected 1
/// to {max} {unit}, got {n}` otherwise.
pub(crate) fn count_up_to(
    flag: &str,
    given: Option<i128>,
    max: u64,
    unit: &str,
) -> Result<Option<u64>, Failure> {
    match given {
        Some(n) if !(1..=i128::from(max)).contains(&n) => Err(Failure::new(
            exit::ERROR,
            format!("{flag}: expected 1 to {max} {unit}, got {n}"),
        )),
        other => Ok(other.map(|n| n as u64)),
    }
}
