//! `tumble run`: a scene stepped headless, its trajectory written safely, and a summary.

use std::io::{IsTerminal, Write};
use std::num::NonZeroU64;
use std::ops::ControlFlow;
use std::path::Path;
use std::time::Instant;

use bevy_ecs::prelude::*;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressFinish, ProgressStyle};
use tumble_core::math::{Real, to_f64};
use tumble_ecs::prelude::*;
use tumble_scene::output::{OutputError, OutputFile};
use tumble_scene::text::{path_for_terminal, terminal_safe};
use tumble_scene::{
    BuiltScene, MAX_STEPS, MAX_SUBSTEPS, Recording, SceneError, TrajectoryError, csv_text_cell,
};

use crate::cli::RunArgs;
use crate::exit::{self, Failure};
use crate::interrupt;
use globset::{GlobBuilder, GlobSet, GlobSetBuilder};

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
        _ => return e.into(),
    };
    Failure::new(exit::ERROR, format!("{flag}: {}", e.message))
}

/// The stages of a step of several (substeps, a composition), as `--plan` prints them: each
/// stage's span as a multiple of `Δt`, and which substep it belongs to.
fn stages_line(world: &World) -> Option<String> {
    let settings = world.get_resource::<PhysicsSettings>()?;
    let stages = settings.stages();
    if stages.count() == 1 {
        return None;
    }
    let dt = settings.dt();
    let spans: Vec<String> = stages
        .spans(dt)
        .map(|s| format!("{:.6}", to_f64(s.h) / to_f64(dt)))
        .collect();
    Some(format!(
        "stages per step: {} ({} substep(s) × {} of `{}`), h/Δt = {}",
        stages.count(),
        settings.substeps,
        settings.integrator.composition().len(),
        settings.integrator,
        spans.join(", ")
    ))
}

/// Which method steps which bodies, as `--plan` prints it: the integrator, and the bodies the
/// planner gives another step now (the exact free flow of a split method under
/// `free_flow = auto`, the implicit spring solve for stiff spring groups), with the first of
/// each by name.
fn methods_line(world: &mut World, names: &Names) -> String {
    let Some(settings) = world.get_resource::<PhysicsSettings>().copied() else {
        return String::new();
    };
    let mut out = format!(
        "method: `{}` (free flow `{}`)",
        settings.integrator, settings.free_flow
    );
    for warning in tumble_ecs::stability::check_stability(world) {
        match warning {
            StabilityWarning::ExactFreeFlow { body, bodies, .. } => out.push_str(&format!(
                "; {bodies} {} the exact free flow (`{}`) now, first {}",
                if bodies == 1 {
                    "body takes"
                } else {
                    "bodies take"
                },
                settings
                    .integrator
                    .exact_counterpart()
                    .map_or("exact", |m| m.name()),
                names.of(body)
            )),
            StabilityWarning::ImplicitGroups { body, bodies, .. } => out.push_str(&format!(
                "; {bodies} {} in stiff spring groups, stepped by the implicit spring solve, \
                 first {}",
                if bodies == 1 { "body" } else { "bodies" },
                names.of(body)
            )),
            _ => {}
        }
    }
    out.push('\n');
    out
}

/// The count given to `flag`, if any, checked to be in `1..=max`: an error `flag: expected 1
/// to {max} {unit}, got {n}` otherwise.
fn count_up_to(
    flag: &str,
    given: Option<i64>,
    max: u64,
    unit: &str,
) -> Result<Option<u64>, Failure> {
    match given {
        Some(n) if !(1..=max as i64).contains(&n) => Err(Failure::new(
            exit::ERROR,
            format!("{flag}: expected 1 to {max} {unit}, got {n}"),
        )),
        other => Ok(other.map(|n| n as u64)),
    }
}

/// `tumble run`.
pub(crate) fn run(args: RunArgs) -> Result<(), Failure> {
    let every = u64::try_from(args.every)
        .ok()
        .and_then(NonZeroU64::new)
        .ok_or_else(|| {
            Failure::new(
                exit::ERROR,
                format!("--every: expected a value >= 1, got {}", args.every),
            )
        })?;
    let steps = count_up_to("--steps", args.steps, MAX_STEPS, "steps")?;
    let integrator = args
        .integrator
        .map(|v| crate::utf8("--integrator", v))
        .transpose()?;
    let springs = args
        .springs
        .map(|v| crate::utf8("--springs", v))
        .transpose()?;
    let free_flow = args
        .free_flow
        .map(|v| crate::utf8("--free-flow", v))
        .transpose()?;
    let substeps = count_up_to("--substeps", args.substeps, MAX_SUBSTEPS.into(), "substeps")?;
    let patterns = args
        .bodies
        .map(|v| crate::utf8("--bodies", v))
        .transpose()?
        .map(|list| body_patterns(&list))
        .transpose()?;
    let loaded = crate::load(&args.scene)?;
    let mut scene = loaded.scene;
    if steps.is_some()
        || args.dt.is_some()
        || integrator.is_some()
        || springs.is_some()
        || free_flow.is_some()
        || substeps.is_some()
    {
        // Overrides are applied to the world settings, then validated like the file's.
        let mut world = scene.file().world.clone();
        world.steps = steps.unwrap_or(world.steps);
        world.dt = args.dt.unwrap_or(world.dt);
        let overridden = integrator.is_some();
        world.integrator = integrator.or(world.integrator);
        let springs_overridden = springs.is_some();
        world.springs = springs.or(world.springs);
        let free_flow_overridden = free_flow.is_some();
        world.free_flow = free_flow.or(world.free_flow);
        world.substeps = substeps.or(world.substeps);
        scene = scene.with_world(world).map_err(|e| {
            override_error(
                e,
                args.dt,
                steps,
                overridden,
                springs_overridden,
                free_flow_overridden,
                substeps.is_some(),
            )
        })?;
    }
    let steps = scene.steps();
    let scene_name = terminal_safe(scene.name()).into_owned();
    let mut built = scene.into_built();
    if args.plan {
        let mut out = format!("{}\n", PhysicsPlan::for_world(&mut built.world));
        if let Some(line) = stages_line(&built.world) {
            out.push_str(&format!("{line}\n"));
        }
        let names = Names::new(&mut built.world, &built.bodies);
        out.push_str(&methods_line(&mut built.world, &names));
        return crate::stdout::print(&out);
    }
    let record = Recording {
        every,
        bodies: patterns
            .map(|p| select_bodies(&p, &built.bodies))
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
            let inputs: Vec<&Path> = loaded.path.as_deref().into_iter().collect();
            let file = OutputFile::create(path, &inputs)?;
            if !args.force {
                check_free_space(&file, &built, steps, &record)?;
            }
            Some(file)
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
    let mut written = None;
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
    match args.out.as_deref() {
        Some(_) if to_stdout => {
            let stdout = std::io::stdout().lock();
            written = Some(
                tumble_scene::write_trajectory(&mut built, steps, &record, stdout, &mut on_step)
                    .map_err(|e| match e {
                        TrajectoryError::Stopped { step } => interrupted(step, None),
                        e => Failure::new(exit::ERROR, format!("standard output: {e}")),
                    })?,
            );
        }
        Some(path) => {
            let mut file = out_file
                .take()
                .expect("the output file is created above for every path but stdout");
            written = Some(
                tumble_scene::write_trajectory(&mut built, steps, &record, &mut file, &mut on_step)
                    .map_err(|e| match e {
                        TrajectoryError::Stopped { step } => interrupted(step, Some(path)),
                        TrajectoryError::Io(e) => OutputError::io(path, e).into(),
                        e => Failure::from(e),
                    })?,
            );
            file.commit()?;
        }
        None => {
            for step in 1..=steps {
                built.step();
                if on_step(step, &built.world).is_break() {
                    return Err(interrupted(step, None));
                }
            }
        }
    }
    bar.finish_and_clear();
    let wall = start.elapsed();
    let after = summary::totals(&mut built.world);
    let body_steps = (steps as f64) * built.bodies.len().max(1) as f64;
    let (dt, integrator) = {
        let settings = built.world.resource::<PhysicsSettings>();
        let integrator = match settings.substeps.get() {
            1 => settings.integrator.to_string(),
            n => format!("{}, {n} substeps", settings.integrator),
        };
        (settings.dt(), integrator)
    };
    let rejected = built.world.query::<&Rejected>().iter(&built.world).count();
    // With the trajectory on stdout, the summary goes to stderr so that the CSV stays clean.
    let mut summary: Box<dyn Write> = if to_stdout {
        Box::new(std::io::stderr().lock())
    } else {
        Box::new(std::io::stdout().lock())
    };
    let mut lines = vec![
        format!("scene      {scene_name}"),
        format!("bodies     {}", built.bodies.len()),
        format!("steps      {steps} × {dt} s ({integrator})"),
        format!(
            "wall time  {:.3} s, {:.1} ns per body-step",
            wall.as_secs_f64(),
            wall.as_nanos() as f64 / body_steps
        ),
    ];
    // Totals over every body, quarantined ones at their last valid state.
    let energy = summary::drift(before.0, after.0, "J");
    lines.push(match conserved.energy {
        None => format!("energy     {energy} (kinetic + spring + gravity)"),
        Some(why) => {
            format!("energy     {energy} (kinetic + spring + gravity; not conserved: {why})")
        }
    });
    let momentum = summary::drift(before.1.length(), after.1.length(), "kg·m²/s");
    lines.push(match conserved.momentum {
        None => format!("|L|        {momentum} (about the origin)"),
        Some(why) => format!("|L|        {momentum} (about the origin; not conserved: {why})"),
    });
    if let Some(written) = written {
        lines.push(format!(
            "trajectory {} rows, {:.1} MB, written at {:.0} MB/s",
            written.rows,
            written.bytes as f64 / 1e6,
            written.megabytes_per_second()
        ));
    }
    if rejected > 0 {
        lines.push(format!(
            "rejected   {rejected} bodies (named above, on stderr)"
        ));
    }
    if args.checksum {
        if checksums.last().is_none_or(|&(step, _)| step != steps) {
            checksums.push((steps, world_checksum(&built.world)));
        }
        for (step, checksum) in &checksums {
            lines.push(format!("checksum   step {step}: {checksum}"));
        }
    }
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

/// The patterns of `--bodies`, compiled once into one matcher, with the text of each (in
/// order) for the error that names a pattern matching nothing.
struct BodyPatterns {
    items: Vec<String>,
    set: GlobSet,
}

/// The comma-separated patterns of `--bodies`, each checked: shell globs as `globset` reads
/// them (`*`, `?`, `[abc]`, `[a-z]`, `[!abc]` and `[^abc]` for "not one of", `{a,b}` is not
/// available since `,` separates patterns, `\` escapes the next character). Patterns are
/// composed (Unicode form C) as the scene's names are, so `é` typed either way finds `é`.
fn body_patterns(list: &str) -> Result<BodyPatterns, Failure> {
    let mut items = Vec::new();
    let mut set = GlobSetBuilder::new();
    let list = tumble_scene::text::composed(list);
    for item in list.split(',') {
        let item = item.trim();
        if item.is_empty() {
            return Err(Failure::new(
                exit::ERROR,
                format!(
                    "--bodies: an empty name in `{}`; expected names or patterns separated by \
                     commas",
                    terminal_safe(&list)
                ),
            ));
        }
        let glob = GlobBuilder::new(item)
            .literal_separator(false)
            .backslash_escape(true)
            .build()
            .map_err(|e| {
                Failure::new(
                    exit::ERROR,
                    format!(
                        "--bodies: `{}` is not a pattern: {}",
                        terminal_safe(item),
                        terminal_safe(&e.kind().to_string())
                    ),
                )
            })?;
        set.add(glob);
        items.push(item.to_owned());
    }
    let set = set.build().map_err(|e| {
        Failure::new(
            exit::ERROR,
            format!("--bodies: {}", terminal_safe(&e.to_string())),
        )
    })?;
    Ok(BodyPatterns { items, set })
}

/// Indices of the bodies that match any of `patterns`, in file order; a pattern that matches
/// none is an error (a typo must not give an empty trajectory). One pass of the compiled set
/// over the names: linear in the names, not in names × patterns.
fn select_bodies(
    patterns: &BodyPatterns,
    bodies: &[(String, Entity)],
) -> Result<Vec<usize>, Failure> {
    let mut used = vec![false; patterns.items.len()];
    let mut selected = Vec::new();
    let mut hits = Vec::new();
    for (i, (name, _)) in bodies.iter().enumerate() {
        patterns.set.matches_into(name.as_str(), &mut hits);
        if !hits.is_empty() {
            selected.push(i);
        }
        for &k in &hits {
            used[k] = true;
        }
    }
    if let Some(k) = used.iter().position(|used| !used) {
        return Err(Failure::new(
            exit::ERROR,
            format!(
                "--bodies: `{}` matches no body of the scene",
                terminal_safe(&patterns.items[k])
            ),
        ));
    }
    Ok(selected)
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
                "{unstable} setting(s) outside the integrator's stable region (warnings above); \
                 nothing was run; lower the time step or the stiffness, or pass \
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

    fn names(names: &[&str]) -> Vec<(String, Entity)> {
        names
            .iter()
            .enumerate()
            .map(|(i, n)| ((*n).to_owned(), Entity::from_raw_u32(i as u32).unwrap()))
            .collect()
    }

    fn selected(list: &str, bodies: &[&str]) -> Result<Vec<usize>, String> {
        let patterns = body_patterns(list).map_err(|f| f.message)?;
        select_bodies(&patterns, &names(bodies)).map_err(|f| f.message)
    }

    /// The syntax a shell user knows: `[!..]` and `[^..]` negate, `\` escapes, `*` and `?`
    /// match any run and one character, including `/` (names are not paths).
    #[test]
    fn body_patterns_are_shell_globs() {
        let bodies = ["m1", "m2", "m*", "a/b", "b12"];
        assert_eq!(selected("m[^1]", &bodies), Ok(vec![1, 2]));
        assert_eq!(selected("m[!1]", &bodies), Ok(vec![1, 2]));
        assert_eq!(selected("m\\*", &bodies), Ok(vec![2]));
        assert_eq!(selected("a*", &bodies), Ok(vec![3]));
        assert_eq!(selected("b1?,m1", &bodies), Ok(vec![0, 4]));
        let error = selected("m1,zz*", &bodies).unwrap_err();
        assert_eq!(error, "--bodies: `zz*` matches no body of the scene");
    }

    /// 5000 patterns against 2000 names: one compiled set, one pass over the names. The bound
    /// is loose for a shared machine; the pattern-by-pattern loop it replaced took 32 s.
    #[test]
    fn many_patterns_against_many_names_are_quick() {
        let bodies: Vec<String> = (0..2000).map(|i| format!("body{i}")).collect();
        let refs: Vec<&str> = bodies.iter().map(String::as_str).collect();
        let list: Vec<String> = (0..5000).map(|i| format!("body{}*", i % 2000)).collect();
        let start = std::time::Instant::now();
        let picked = selected(&list.join(","), &refs).unwrap();
        assert_eq!(picked.len(), 2000);
        let took = start.elapsed();
        assert!(took < std::time::Duration::from_secs(5), "{took:?}");
    }

    #[test]
    fn sizes_read_with_binary_units() {
        assert_eq!(human_bytes(512), "512 bytes");
        assert_eq!(human_bytes(3 << 29), "1.5 GiB");
    }
}
