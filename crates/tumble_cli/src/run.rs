//! `tumble run`: a scene stepped headless, its trajectory written safely, and a summary.

use std::io::{IsTerminal, Write};
use std::num::NonZeroU64;
use std::ops::ControlFlow;
use std::path::Path;
use std::time::{Duration, Instant};

use bevy_ecs::prelude::*;
use glam::DVec3;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressFinish, ProgressStyle};
use tumble_core::math::{Real, to_f64};
use tumble_ecs::prelude::*;
use tumble_scene::output::{OutputError, OutputFile};
use tumble_scene::text::{path_for_terminal, terminal_safe};
use tumble_scene::{BuiltScene, Recording, TrajectoryError, TrajectoryStats, csv_text_cell};

use crate::cli::RunArgs;
use crate::exit::{self, Failure};
use crate::interrupt;
use crate::overrides::Overrides;

use crate::summary::{self, Names, quarantine_line, warning_line};

/// Runs longer than this many body-steps show a progress bar (when stderr is a terminal).
pub(crate) const PROGRESS_BODY_STEPS: f64 = 1e6;

/// Steps between two updates of the progress bar: its cost stays invisible even for one body.
const PROGRESS_EVERY: u64 = 1024;

/// Bytes of one written number, bound: `Display` of an `f32` needs at most 16 characters for a
/// magnitude in [1e-6, 1e15) (a sign, 9 significant digits, the point, leading zeros), of an
/// `f64` at most 25 in [1e-6, 1e24). Rarer magnitudes print longer; the estimate is a guide, and
/// a full disk while writing is still an error that removes the temporary file.
const VALUE_BYTES: u64 = if size_of::<Real>() == 4 { 16 } else { 25 };

/// `tumble run`.
pub(crate) fn run(mut args: RunArgs) -> Result<(), Failure> {
    let every = every(args.every)?;
    let overrides = Overrides::of(&mut args)?;
    let patterns = args
        .bodies
        .map(|v| crate::utf8("--bodies", v))
        .transpose()?
        .map(|list| crate::body_patterns::body_patterns(&list))
        .transpose()?;
    let loaded = crate::load(&args.scene)?;
    let scene = overrides.apply(loaded.scene)?;
    let steps = scene.steps();
    let scene_name = terminal_safe(scene.name()).into_owned();
    let mut built = scene.into_built();
    if args.plan {
        return crate::plan::print_plan(&mut built);
    }
    let record = Recording {
        every,
        bodies: patterns
            .map(|p| crate::body_patterns::select_bodies(&p, &built.bodies))
            .transpose()?,
    };
    let to_stdout = args.out.as_deref().is_some_and(crate::is_stdout);
    // Created before the output file, dropped after it: a second signal while the temporary
    // file is being removed cannot cut that short.
    let guard = interrupt::Guard::poll();
    // The output is checked (its place, the free space there) before anything is said about
    // the run: a run that cannot be written fails with its one error line, and fast.
    let mut out_file = match args.out.as_deref() {
        Some(path) if !to_stdout => {
            let input = loaded.path.as_deref();
            Some(open_output(
                path, input, args.force, &built, steps, &record,
            )?)
        }
        _ => None,
    };
    let names = Names::new(&mut built.world, &built.bodies);
    stability_gate(&mut built, &names, args.allow_unstable)?;

    let conserved = summary::conserved(&mut built.world);
    let before = summary::totals(&mut built.world);
    let mut reported = 0;
    let start = Instant::now();
    let bar = progress_bar(steps, built.bodies.len());
    let mut checksums: Vec<(u64, WorldChecksum)> = Vec::new();
    if args.checksum {
        checksums.push((0, world_checksum(&built.world)));
    }
    let mut on_step = |step: u64, world: &World| {
        if step.is_multiple_of(PROGRESS_EVERY) {
            bar.set_position(step);
        }
        if args.checksum && step.is_multiple_of(every.get()) {
            checksums.push((step, world_checksum(world)));
        }
        reported = report_quarantines(world, &names, step, reported);
        if guard.interrupted() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    };
    let destination = match (args.out.as_deref(), out_file.take()) {
        (Some(path), Some(file)) => Destination::File(path, file),
        (Some(_), None) => Destination::Stdout,
        (None, _) => Destination::Nowhere,
    };
    let written = step_and_write(&mut built, steps, &record, destination, &mut on_step)?;
    bar.finish_and_clear();
    let wall = start.elapsed();
    let rejected = built.world.query::<&Rejected>().iter(&built.world).count();
    if args.checksum && checksums.last().is_none_or(|&(step, _)| step != steps) {
        checksums.push((steps, world_checksum(&built.world)));
    }
    let run = Summary {
        scene_name: &scene_name,
        steps,
        wall,
        before,
        conserved: &conserved,
        written,
        rejected,
        checksums: &checksums,
    };
    let lines = run.lines(&mut built);
    write_summary(&lines, to_stdout)?;
    if rejected > 0 {
        return Err(Failure::new(
            exit::REJECTED,
            format!(
                "{rejected} of {} bodies were rejected; their CSV rows stop at the step they were rejected on",
                built.bodies.len()
            ),
        ));
    }
    Ok(())
}

/// The trajectory's output file at `path` (never the scene file `input`), with room for the
/// run's rows unless `force`.
fn open_output(
    path: &Path,
    input: Option<&Path>,
    force: bool,
    built: &BuiltScene,
    steps: u64,
    record: &Recording,
) -> Result<OutputFile, Failure> {
    let inputs: Vec<&Path> = input.into_iter().collect();
    let file = OutputFile::create(path, &inputs)?;
    if !force {
        check_free_space(&file, built, steps, record)?;
    }
    Ok(file)
}

/// `--every`: a step count of at least 1.
fn every(given: i128) -> Result<NonZeroU64, Failure> {
    u64::try_from(given)
        .ok()
        .and_then(NonZeroU64::new)
        .ok_or_else(|| {
            Failure::new(
                exit::ERROR,
                format!("--every: expected a value >= 1, got {given}"),
            )
        })
}

/// Writes the summary's `lines`: to stdout, or to stderr when the trajectory went to stdout.
fn write_summary(lines: &[String], to_stdout: bool) -> Result<(), Failure> {
    // With the trajectory on stdout, the summary goes to stderr so that the CSV stays clean.
    let mut summary: Box<dyn Write> = if to_stdout {
        Box::new(std::io::stderr().lock())
    } else {
        crate::stdout::open()?
    };
    // A closed or full stdout is an error, not a success with the summary (and the checksums
    // a script reads) lost.
    let text: String = lines.iter().map(|line| format!("{line}\n")).collect();
    if let Err(e) = crate::stdout::write_all(&mut summary, &text) {
        let place = if to_stdout {
            "standard error"
        } else {
            "standard output"
        };
        return Err(Failure::new(
            exit::ERROR,
            format!("writing the summary to {place} failed: {e}"),
        ));
    }
    Ok(())
}

/// Where a run's trajectory goes.
enum Destination<'a> {
    /// To standard output.
    Stdout,
    /// To a file, written through a temporary one and committed at the end.
    File(&'a Path, OutputFile),
    /// Nowhere: the run only steps.
    Nowhere,
}

/// Steps `built` through `steps` steps, writing the trajectory to `destination` as `record`
/// says and calling `on_step` after each step (a break stops the run as interrupted). Returns
/// what was written.
fn step_and_write(
    built: &mut BuiltScene,
    steps: u64,
    record: &Recording,
    destination: Destination<'_>,
    on_step: &mut impl FnMut(u64, &World) -> ControlFlow<()>,
) -> Result<Option<TrajectoryStats>, Failure> {
    let interrupted = |step: u64, path: Option<&Path>| {
        let unchanged = match path {
            Some(path) => format!("; {} was not written", path_for_terminal(path)),
            None => String::new(),
        };
        Failure::new(
            exit::INTERRUPTED,
            format!("interrupted after step {step}{unchanged}"),
        )
    };
    match destination {
        Destination::Stdout => {
            let stdout = crate::stdout::open()?;
            let written = tumble_scene::write_trajectory(built, steps, record, stdout, on_step)
                .map_err(|e| match e {
                    TrajectoryError::Stopped { step } => interrupted(step, None),
                    e => Failure::new(exit::ERROR, format!("standard output: {e}")),
                })?;
            Ok(Some(written))
        }
        Destination::File(path, mut file) => {
            let written = tumble_scene::write_trajectory(built, steps, record, &mut file, on_step)
                .map_err(|e| match e {
                    TrajectoryError::Stopped { step } => interrupted(step, Some(path)),
                    TrajectoryError::Io(e) => OutputError::io(path, e).into(),
                    e => Failure::from(e),
                })?;
            file.commit()?;
            Ok(Some(written))
        }
        Destination::Nowhere => {
            for step in 1..=steps {
                built.step();
                if on_step(step, &built.world).is_break() {
                    return Err(interrupted(step, None));
                }
            }
            Ok(None)
        }
    }
}

/// What `tumble run` says at the end of a run.
struct Summary<'a> {
    scene_name: &'a str,
    steps: u64,
    wall: Duration,
    /// Energy and angular momentum before the run.
    before: (f64, DVec3),
    conserved: &'a summary::Conserved,
    written: Option<TrajectoryStats>,
    rejected: usize,
    /// `(step, checksum)` pairs, the last step's included; empty without `--checksum`.
    checksums: &'a [(u64, WorldChecksum)],
}

impl Summary<'_> {
    /// The summary's lines, with the world after the run in `built`.
    fn lines(&self, built: &mut BuiltScene) -> Vec<String> {
        let (steps, wall) = (self.steps, self.wall);
        let after = summary::totals(&mut built.world);
        let body_steps = (steps as f64) * built.bodies.len().max(1) as f64;
        let (dt, integrator) = {
            let settings = built.world.resource::<PhysicsSettings>();
            let integrator = match settings.substeps().get() {
                1 => settings.integrator.to_string(),
                n => format!("{}, {n} substeps", settings.integrator),
            };
            (settings.dt(), integrator)
        };
        let mut lines = vec![
            format!("scene      {}", self.scene_name),
            format!("bodies     {}", built.bodies.len()),
            format!(
                "steps      {steps} × {} s ({integrator})",
                tumble_core::error::compact(dt)
            ),
            format!(
                "wall time  {:.3} s, {:.1} ns per body-step",
                wall.as_secs_f64(),
                wall.as_nanos() as f64 / body_steps
            ),
        ];
        // Totals over every body, quarantined ones at their last valid state.
        let energy = summary::drift(self.before.0, after.0, "J");
        lines.push(match self.conserved.energy {
            None => format!("energy     {energy} (kinetic + spring + gravity)"),
            Some(why) => {
                format!("energy     {energy} (kinetic + spring + gravity; not conserved: {why})")
            }
        });
        let momentum = summary::drift(self.before.1.length(), after.1.length(), "kg·m²/s");
        lines.push(match self.conserved.momentum {
            None => format!("|L|        {momentum} (about the origin)"),
            Some(why) => format!("|L|        {momentum} (about the origin; not conserved: {why})"),
        });
        if let Some(written) = &self.written {
            lines.push(format!(
                "trajectory {} rows, {:.1} MB, written at {:.0} MB/s",
                written.rows,
                written.bytes as f64 / 1e6,
                written.megabytes_per_second()
            ));
        }
        if self.rejected > 0 {
            lines.push(format!(
                "rejected   {} bodies (named above, on stderr)",
                self.rejected
            ));
        }
        for (step, checksum) in self.checksums {
            lines.push(format!("checksum   step {step}: {checksum}"));
        }
        lines
    }
}

/// A progress bar on stderr for long runs when stderr is a terminal, hidden otherwise.
fn progress_bar(steps: u64, bodies: usize) -> ProgressBar {
    let long = steps as f64 * bodies as f64 > PROGRESS_BODY_STEPS;
    if !long || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    // Cleared when dropped on an error, so the error line starts on a line of its own.
    let bar = ProgressBar::with_draw_target(Some(steps), ProgressDrawTarget::stderr())
        .with_finish(ProgressFinish::AndClear);
    if let Ok(style) =
        ProgressStyle::with_template("{bar:40} {human_pos}/{human_len} steps [{elapsed} < {eta}]")
    {
        bar.set_style(style);
    }
    bar
}

/// The estimated CSV size: `(rows, bytes per row)`, the row size a bound for the usual
/// magnitudes (see [`VALUE_BYTES`]).
pub(crate) fn csv_estimate(built: &BuiltScene, steps: u64, record: &Recording) -> (u64, u64) {
    let recorded = steps / record.every.get() + 1;
    let bodies: Vec<&String> = match &record.bodies {
        None => built.bodies.iter().map(|(n, _)| n).collect(),
        Some(indices) => indices.iter().map(|&i| &built.bodies[i].0).collect(),
    };
    let rows = recorded.saturating_mul(bodies.len() as u64);
    let name = bodies
        .iter()
        .map(|n| csv_text_cell(n).len() as u64)
        .max()
        .unwrap_or(0);
    let dt = built
        .world
        .get_resource::<PhysicsSettings>()
        .map_or(0.0, |s| to_f64(s.dt()));
    // `time` is an f64 of up to 17 significant digits: 25 characters cover it from 1e-6 s on.
    let time = (format!("{}", dt * steps as f64).len() as u64).max(25);
    let step = steps.to_string().len() as u64;
    let row = step + time + name + 13 * VALUE_BYTES + 15 + 1;
    (rows, row)
}

/// Refuses a trajectory whose estimated size exceeds the free space where it is written.
fn check_free_space(
    file: &OutputFile,
    built: &BuiltScene,
    steps: u64,
    record: &Recording,
) -> Result<(), Failure> {
    let (rows, row) = csv_estimate(built, steps, record);
    let bytes = rows.saturating_mul(row).saturating_add(CSV_HEADER_BYTES);
    let dir = match file.target().parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    };
    let free = match fs4::available_space(dir) {
        Ok(free) => free,
        Err(e) => {
            tracing::warn!(
                "{}: cannot tell the free space ({e}); writing without the size check",
                path_for_terminal(file.path())
            );
            return Ok(());
        }
    };
    if bytes > free {
        return Err(Failure::new(
            exit::ERROR,
            format!(
                "{}: the trajectory would take up to {} ({rows} rows of up to {row} bytes), more than the {} free there; record fewer steps with --every, or pass --force",
                path_for_terminal(file.path()),
                human_bytes(bytes),
                human_bytes(free)
            ),
        ));
    }
    Ok(())
}

const CSV_HEADER_BYTES: u64 = tumble_scene::CSV_HEADER.len() as u64 + 1;

/// `bytes` with a binary unit, e.g. `1.5 GiB`.
fn human_bytes(bytes: u64) -> String {
    const UNITS: [&str; 6] = ["bytes", "KiB", "MiB", "GiB", "TiB", "PiB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{bytes} bytes")
    } else {
        format!("{value:.1} {}", UNITS[unit])
    }
}

/// Prints the planning-time predictions, naming bodies and springs; refuses a world predicted to
/// diverge unless `allow` (then the run is energy-audited, so that a divergence is caught while
/// the state is still finite). Precision warnings are printed and do not refuse the run.
pub(crate) fn stability_gate(
    built: &mut BuiltScene,
    names: &Names,
    allow: bool,
) -> Result<(), Failure> {
    let warnings = check_stability(&mut built.world);
    for line in warning_lines(&warnings, names, tracing::enabled!(tracing::Level::INFO)) {
        tracing::warn!(target: "tumble", "{line}");
    }
    let unstable = warnings.iter().filter(|w| w.is_instability()).count();
    if unstable == 0 {
        return Ok(());
    }
    if !allow {
        return Err(Failure::new(
            exit::UNSTABLE,
            format!(
                "{unstable} setting(s) outside the integrator's stable region or that it \
                 cannot run (warnings above); nothing was run; follow the warnings, or pass \
                 --allow-unstable to run anyway"
            ),
        ));
    }
    // The runner re-plans with the audit on its next step.
    built.world.insert_resource(EnergyAudit::Always);
    Ok(())
}

/// Most warnings of one kind printed at the default verbosity; `-v` prints them all.
const WARNINGS_PER_KIND: usize = 5;

/// The lines for `warnings`: all of them when `all`, else the first [`WARNINGS_PER_KIND`] of
/// each kind and a count of the rest (a scene of 10⁵ bodies far from the origin would otherwise
/// print 10⁵ lines).
fn warning_lines(warnings: &[StabilityWarning], names: &Names, all: bool) -> Vec<String> {
    let mut kinds: Vec<(std::mem::Discriminant<StabilityWarning>, usize)> = Vec::new();
    let mut lines = Vec::new();
    for warning in warnings {
        let kind = std::mem::discriminant(warning);
        let seen = match kinds.iter_mut().find(|(k, _)| *k == kind) {
            Some((_, count)) => count,
            None => {
                kinds.push((kind, 0));
                &mut kinds.last_mut().expect("just pushed").1
            }
        };
        *seen += 1;
        if all || *seen <= WARNINGS_PER_KIND {
            lines.push(warning_line(warning, names));
        }
    }
    if !all {
        for (kind, count) in kinds {
            if count > WARNINGS_PER_KIND {
                let first = warnings
                    .iter()
                    .find(|w| std::mem::discriminant(*w) == kind)
                    .expect("counted");
                lines.push(format!(
                    "… and {} more with the same warning as {} (-v lists them all)",
                    count - WARNINGS_PER_KIND,
                    names.of(first.subject())
                ));
            }
        }
    }
    lines
}

/// Logs every quarantine recorded since the first `reported` errors, with the step it happened
/// on; returns the new count.
fn report_quarantines(world: &World, names: &Names, step: u64, reported: usize) -> usize {
    let Some(errors) = world.get_resource::<PhysicsErrors>() else {
        return reported;
    };
    for error in errors.bodies.iter().skip(reported) {
        tracing::error!(target: "tumble", "{}", quarantine_line(error, step, world, names));
    }
    errors.bodies.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_read_with_binary_units() {
        assert_eq!(human_bytes(512), "512 bytes");
        assert_eq!(human_bytes(3 << 29), "1.5 GiB");
    }
}
