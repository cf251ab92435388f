//! The command line: clap types only (the logic is in the other modules).

use std::ffi::OsString;
use std::path::PathBuf;

use clap::{ArgAction, Parser, Subcommand};

/// tumble: rigid-body dynamics for headless game loops.
///
/// Exit status: 0 success, 1 error (bad input or I/O), 2 usage, 3 a body was rejected or
/// diverged, 4 predicted unstable or a method that cannot step the scene (refused unless
/// --allow-unstable), 130 interrupted.
#[derive(Parser, Debug)]
#[command(version)]
pub(crate) struct Cli {
    /// More log output on stderr: -v info, -vv debug, -vvv trace (default: warnings).
    /// `RUST_LOG` directives take precedence.
    #[arg(short, long, action = ArgAction::Count, global = true)]
    pub verbose: u8,
    /// Only errors in the log output on stderr.
    #[arg(short, long, global = true, conflicts_with = "verbose")]
    pub quiet: bool,
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// What `tumble gen` generates.
#[derive(Subcommand, Debug)]
pub(crate) enum GenKind {
    /// Many tumbling bodies under gravity, on a grid.
    #[command(allow_negative_numbers = true)]
    Many {
        /// Number of bodies: 1 to 200000 in TOML, 1 to 10000000 in JSON (the generated file
        /// must stay loadable).
        #[arg(long, default_value_t = 100_000, allow_hyphen_values = true)]
        n: i128,
        /// Steps (1 to 1000000000, as `run` accepts).
        #[arg(long, default_value_t = 600, allow_hyphen_values = true)]
        steps: i128,
        /// Output file, `-` for stdout (default: stdout). A name ending in `.json` gets JSON,
        /// the format for large scenes (read as a stream); any other, TOML.
        #[arg(long)]
        out: Option<PathBuf>,
        /// `toml` or `json` (default: by the extension of `--out`, else `toml`).
        #[arg(long, value_parser = ["toml", "json"])]
        format: Option<String>,
    },
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub(crate) enum Command {
    /// Run a scene file (or a bundled scene by name) and print a summary.
    #[command(allow_negative_numbers = true)]
    Run(RunArgs),
    /// List the bundled scenes.
    Scenes,
    /// Generate a scene.
    Gen {
        /// The kind of scene.
        #[command(subcommand)]
        kind: GenKind,
    },
    /// Run a scene in tumble and in rapier 0.36 side by side and print the differences.
    Compare {
        /// Scene file, or the name of a bundled scene.
        scene: PathBuf,
        /// tumble's integrator (default: the scene's).
        #[arg(long)]
        integrator: Option<OsString>,
        /// rapier's gyroscopic term.
        #[arg(long, default_value = "on", value_parser = ["on", "off"])]
        gyroscopic: String,
        /// How tumble steps springs: `auto` (implicit for stiff spring groups), `explicit` or
        /// `implicit` (default: the scene's `[world] springs`, else `auto`).
        #[arg(long)]
        springs: Option<OsString>,
        /// Which free rotation tumble's split integrators give each body: `auto` (the exact
        /// flow for a body while the split errs by more than 1 % a step) or `method` (default:
        /// the scene's `[world] free_flow`, else `auto`).
        #[arg(long)]
        free_flow: Option<OsString>,
        /// How springs are built in rapier: `joint` (its `SpringJoint`, force-based model: what a
        /// rapier user picks; implicit, loses energy) or `force` (the spring force added with
        /// `add_force_at_point` every step: explicit, gains energy, diverges when stiff).
        #[arg(long, default_value = "joint")]
        rapier_springs: OsString,
        /// Compare even when tumble predicts the step unstable for this scene.
        #[arg(long)]
        allow_unstable: bool,
    },
    /// The accuracy report: work–precision, stability matrix, plots.
    #[command(allow_negative_numbers = true)]
    Report(tumble_report::run::ReportOptions),
    /// Throughput: ECS vs raw loop vs rapier, 1 and 2 threads, N = 1 … 10⁶, memory bandwidth.
    // A negative size is then clap's "invalid value '-1' for '--max-bodies'", not "unexpected
    // argument '-1'".
    #[command(allow_negative_numbers = true)]
    Bench(tumble_bench::BenchOptions),
}

/// The arguments of `tumble run`.
#[derive(clap::Args, Debug)]
pub(crate) struct RunArgs {
    /// Scene file, or the name of a bundled scene.
    pub scene: PathBuf,
    /// Override the number of steps.
    // Numbers are read wide and signed so that `--steps -5` gets tumble's own message.
    #[arg(long, allow_hyphen_values = true)]
    pub steps: Option<i128>,
    /// Override the time step (s).
    #[arg(long, allow_hyphen_values = true)]
    pub dt: Option<f64>,
    /// Override the integrator.
    #[arg(long)]
    pub integrator: Option<OsString>,
    /// Override how springs are stepped: `auto` (implicit for stiff spring groups), `explicit`
    /// or `implicit`.
    #[arg(long)]
    pub springs: Option<OsString>,
    /// Override which free rotation a split integrator (`splitting`, `splitting-xyz`,
    /// `yoshida4`) gives each body: `auto` (the exact flow for a body while the split errs by
    /// more than 1 % a step, said on stderr) or `method` (the integrator's own, for every body).
    #[arg(long)]
    pub free_flow: Option<OsString>,
    /// Override the substeps per step (1 to 1000): the forces are sampled in each.
    #[arg(long, allow_hyphen_values = true)]
    pub substeps: Option<i128>,
    /// Write the trajectory to this CSV file, `-` for stdout (the summary then goes to stderr).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Record every K-th step (step 0 is always recorded).
    #[arg(long, default_value_t = 1, allow_hyphen_values = true)]
    pub every: i128,
    /// Record only these bodies: a comma-separated list of names or shell glob patterns (`*`
    /// any run of characters, `?` one character, `[abc]` one of a class, `[!abc]` or `[^abc]`
    /// none of it, `\` escapes the next character), e.g. `--bodies 'b1,b2?,b9*'`.
    /// Rows keep the order of the scene file; a pattern that matches no body is an error.
    #[arg(long)]
    pub bodies: Option<OsString>,
    /// Print the planned systems and exit.
    #[arg(long)]
    pub plan: bool,
    /// Write the trajectory even when its estimated size exceeds the free space.
    #[arg(long)]
    pub force: bool,
    /// Run even when tumble predicts the step unstable for this scene.
    #[arg(long)]
    pub allow_unstable: bool,
    /// Print the world's checksum (`WorldChecksum`: 32 hex digits over everything the next step
    /// depends on) at step 0, at every recorded step (`--every`) and after the last, with the
    /// summary.
    #[arg(long)]
    pub checksum: bool,
}
