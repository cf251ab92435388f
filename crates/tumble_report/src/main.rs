//! `tumble-report`: runs the work–precision study and the stability matrix, writes
//! `report.md`, `results.json` and SVG plots (the same as `tumble report`).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use tumble_report::run::{ReportOptions, run_report};

/// tumble's accuracy report: error against run time, and the stability matrix.
#[derive(Parser)]
#[command(version)]
struct Args {
    /// Fewer time steps, smaller batches, shorter stability runs (< 60 s on 2 cores).
    #[arg(long)]
    quick: bool,
    /// Output directory.
    #[arg(long, default_value = "report")]
    out: PathBuf,
    /// Also replace the headline table in this markdown file (between the
    /// `<!-- report:begin -->` and `<!-- report:end -->` markers), e.g. README.md.
    #[arg(long)]
    readme: Option<PathBuf>,
}

fn main() -> ExitCode {
    let args = Args::parse();
    match run_report(&ReportOptions {
        quick: args.quick,
        out: args.out,
        readme: args.readme,
    }) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
