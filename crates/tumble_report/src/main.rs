//! `tumble-report`: runs the work–precision study and the stability matrix, writes
//! `report.md`, `results.json` and SVG plots (the same as `tumble report`).

use std::process::ExitCode;

use clap::Parser;
use tumble_report::run::{ReportOptions, run_report};

/// tumble's accuracy report: error against run time, and the stability matrix.
#[derive(Parser)]
#[command(version)]
struct Args {
    #[command(flatten)]
    options: ReportOptions,
}

fn main() -> ExitCode {
    match run_report(&Args::parse().options) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
