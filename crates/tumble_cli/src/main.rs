//! `tumble`: run a scene file headless, write its trajectory, list the bundled scenes.
//!
//! Every error is one line on stderr (`error: …`) and a documented exit code ([`exit`]).

mod body_patterns;
mod cli;
mod compare;
mod exit;
mod generate;
mod interrupt;
mod logging;
mod memory;
mod overrides;
mod plan;
mod run;
mod stdout;
mod summary;

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::Parser;
use clap::error::ErrorKind;
use tumble_scene::text::terminal_safe;
use tumble_scene::{Scene, load_scene};

use crate::cli::{Cli, Command, GenKind};
use crate::exit::Failure;

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
        "thin_plate",
        include_str!("../../../scenes/thin_plate.toml"),
    ),
    (
        "mass_ratio",
        include_str!("../../../scenes/mass_ratio.toml"),
    ),
    ("far_away", include_str!("../../../scenes/far_away.toml")),
    ("long_run", include_str!("../../../scenes/long_run.toml")),
    (
        "stiff_chain",
        include_str!("../../../scenes/stiff_chain.toml"),
    ),
    ("cloth", include_str!("../../../scenes/cloth.toml")),
];

#[global_allocator]
static ALLOCATOR: memory::ExitWhenExhausted = memory::ExitWhenExhausted;

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return usage_error(&e),
    };
    if let Err(failure) = logging::init(cli.verbose, cli.quiet) {
        return failure.report();
    }
    // A bad TUMBLE_KERNEL is a clear error here, not a panic in the middle of a step.
    if let Err(e) = tumble_core::KernelPath::selected() {
        return Failure::new(exit::ERROR, e.to_string()).report();
    }
    interrupt::install();
    match dispatch(cli) {
        Ok(()) => ExitCode::from(exit::SUCCESS),
        Err(failure) => failure.report(),
    }
}

/// clap's error as one line (its first), with exit code [`exit::USAGE`]; help and version
/// are printed whole.
fn usage_error(e: &clap::Error) -> ExitCode {
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
            match stdout::print(&e.render().to_string()) {
                Ok(()) => ExitCode::from(exit::SUCCESS),
                Err(failure) => failure.report(),
            }
        }
        ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            let _ = e.print();
            ExitCode::from(exit::USAGE)
        }
        ErrorKind::InvalidUtf8 => {
            Failure::new(exit::USAGE, non_utf8_argument(std::env::args_os())).report()
        }
        _ => {
            // clap's first line, with the indented lines that complete it (the missing
            // arguments' names), up to the blank line before its usage.
            let text = e.to_string();
            let mut lines = text.lines();
            let first = lines.next().unwrap_or_default();
            let first = first.strip_prefix("error: ").unwrap_or(first);
            let rest: Vec<&str> = lines
                .take_while(|l| l.starts_with(' '))
                .map(str::trim)
                .collect();
            let message = if rest.is_empty() {
                first.to_owned()
            } else {
                format!("{first} {}", rest.join(", "))
            };
            Failure::new(
                exit::USAGE,
                format!("{} (see --help)", terminal_safe(&message)),
            )
            .report()
        }
    }
}

/// Which argument is not UTF-8 (clap only says that one is).
fn non_utf8_argument(args: impl Iterator<Item = OsString>) -> String {
    let args: Vec<OsString> = args.collect();
    for (i, arg) in args.iter().enumerate().skip(1) {
        if arg.to_str().is_some() {
            continue;
        }
        let lossy = arg.to_string_lossy();
        if let Some((flag, _)) = lossy.split_once('=')
            && flag.starts_with('-')
        {
            return format!("{}: the value is not valid UTF-8", terminal_safe(flag));
        }
        if let Some(flag) = args[i - 1].to_str().filter(|a| a.starts_with('-')) {
            return format!(
                "{}: the value {} is not valid UTF-8",
                terminal_safe(flag),
                terminal_safe(&lossy)
            );
        }
        return format!(
            "argument {i} ({}) is not valid UTF-8",
            terminal_safe(&lossy)
        );
    }
    "an argument is not valid UTF-8".to_owned()
}

/// The value of `flag` as UTF-8, or an error that names the flag.
fn utf8(flag: &str, value: OsString) -> Result<String, Failure> {
    value.into_string().map_err(|v| {
        Failure::new(
            exit::ERROR,
            format!(
                "{flag}: the value {} is not valid UTF-8",
                terminal_safe(&v.to_string_lossy())
            ),
        )
    })
}

/// A checked scene, and its path when it was read from a file.
pub struct Loaded {
    /// The scene.
    pub scene: Scene,
    /// The file it was read from (`None` for a bundled scene).
    pub path: Option<PathBuf>,
}

/// A bundled scene by name, or a scene file (TOML, or JSON by its `.json` extension).
pub fn load(scene: &Path) -> Result<Loaded, Failure> {
    if let Some(name) = scene.to_str()
        && let Some((_, text)) = BUNDLED.iter().find(|(bundled, _)| *bundled == name)
    {
        return Ok(Loaded {
            scene: Scene::parse(&format!("scenes/{name}.toml"), text)?,
            path: None,
        });
    }
    // A name that is neither a bundled scene nor a file: say which names exist (and how to
    // make the generated one) instead of only "no such file".
    if !scene.exists()
        && let Some(name) = scene.to_str().filter(|n| !n.contains(['/', '.']))
    {
        let bundled: Vec<&str> = BUNDLED.iter().map(|(n, _)| *n).collect();
        let hint = if name == "many" {
            "`many` is generated, not bundled: run `tumble gen many --n 100000 --out many.toml` \
             first, then `tumble run many.toml`"
                .to_owned()
        } else {
            format!(
                "it is neither a file nor a bundled scene ({}; `tumble scenes` lists them)",
                bundled.join(", ")
            )
        };
        return Err(Failure::new(
            exit::ERROR,
            format!("{}: no such scene: {hint}", terminal_safe(name)),
        ));
    }
    Ok(Loaded {
        scene: load_scene(scene)?,
        path: Some(scene.to_owned()),
    })
}

/// `path` is `-`: standard output.
pub fn is_stdout(path: &Path) -> bool {
    path.as_os_str() == "-"
}

fn dispatch(cli: Cli) -> Result<(), Failure> {
    match cli.command {
        Command::Gen {
            kind:
                GenKind::Many {
                    n,
                    steps,
                    out,
                    format,
                },
        } => {
            let format = format.map(|f| match f.as_str() {
                "json" => tumble_scene::SceneSyntax::Json,
                _ => tumble_scene::SceneSyntax::Toml,
            });
            generate::run(n, steps, out.as_deref(), format)
        }
        Command::Scenes => {
            let mut out = String::new();
            for (name, text) in BUNDLED {
                let first = text.lines().find(|l| l.starts_with("name")).unwrap_or("");
                out.push_str(&format!("{name:<16} {first}\n"));
            }
            out.push_str(&format!(
                "{:<16} generated: tumble gen many --n 100000 --out many.toml (or --n 1000000 \
                 --out many.json)\n",
                "many"
            ));
            stdout::print(&out)
        }
        Command::Compare {
            scene,
            integrator,
            gyroscopic,
            springs,
            free_flow,
            rapier_springs,
            allow_unstable,
        } => {
            let integrator = integrator.map(|v| utf8("--integrator", v)).transpose()?;
            let springs = springs.map(|v| utf8("--springs", v)).transpose()?;
            let free_flow = free_flow.map(|v| utf8("--free-flow", v)).transpose()?;
            let rapier_springs: tumble_rapier::RapierSprings =
                utf8("--rapier-springs", rapier_springs)?.parse().map_err(
                    |e: tumble_rapier::UnknownRapierSprings| format!("--rapier-springs: {e}"),
                )?;
            let scene = load(&scene)?.scene;
            let integrator = match integrator {
                Some(name) => {
                    name.parse()
                        .map_err(|e: tumble_core::integrate::UnknownIntegrator| {
                            format!("--integrator: {e}")
                        })?
                }
                None => scene.integrator(),
            };
            let springs = match springs {
                Some(name) => name
                    .parse()
                    .map_err(|e: String| format!("--springs: {}", terminal_safe(&e)))?,
                None => scene.settings().springs,
            };
            let free_flow = match free_flow {
                Some(name) => name
                    .parse()
                    .map_err(|e: String| format!("--free-flow: {}", terminal_safe(&e)))?,
                None => scene.settings().free_flow,
            };
            // The same planning-time predictions as `run`, for tumble's side of the comparison.
            let mut built = scene.build();
            {
                let mut settings = built
                    .world
                    .resource_mut::<tumble_ecs::prelude::PhysicsSettings>();
                settings.integrator = integrator;
                settings.springs = springs;
                settings.free_flow = free_flow;
            }
            let names = summary::Names::new(&mut built.world, &built.bodies);
            run::stability_gate(&mut built, &names, allow_unstable)?;
            let settings = compare::Settings {
                integrator,
                gyroscopic: gyroscopic == "on",
                springs,
                rapier_springs,
                free_flow,
            };
            compare::run(&scene, settings)
        }
        Command::Report(options) => {
            tumble_report::run::run_report(&options).map_err(|e| Failure::from(e.to_string()))
        }
        Command::Bench(options) => {
            tumble_bench::run_and_write(&options).map_err(|e| Failure::from(e.to_string()))
        }
        Command::Run(args) => run::run(args),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_non_utf8_argument_is_named() {
        #[cfg(unix)]
        {
            use std::os::unix::ffi::OsStringExt;
            let bad = || OsString::from_vec(vec![b'x', 0xff]);
            let args = |v: Vec<OsString>| v.into_iter();
            let said = non_utf8_argument(args(vec!["tumble".into(), "--steps".into(), bad()]));
            assert_eq!(said, "--steps: the value x\u{fffd} is not valid UTF-8");
            let mut flag = OsString::from("--n=");
            flag.push(bad());
            let said = non_utf8_argument(args(vec!["tumble".into(), flag]));
            assert_eq!(said, "--n: the value is not valid UTF-8");
        }
    }
}
