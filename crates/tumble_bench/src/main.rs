//! `tumble-bench`: the throughput benchmark (the same as `tumble bench`).

use std::process::ExitCode;

use clap::Parser;
use tumble_bench::{BenchOptions, run_and_write};

/// tumble's throughput: ECS vs raw loop vs rapier, 1 and 2 threads, N = 1 … 10⁶.
#[derive(Parser)]
#[command(version)]
struct Args {
    #[command(flatten)]
    options: BenchOptions,
}

fn main() -> ExitCode {
    match run_and_write(&Args::parse().options) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
