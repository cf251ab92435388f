//! `tumble-report`: runs the work–precision study and the stability matrix, writes
//! `report.md`, `results.json` and SVG plots.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use indicatif::{ProgressBar, ProgressStyle};
use tumble_report::energy::{spins, traces};
use tumble_report::output::{Machine, Results, headline_table, markdown, plot_energy, plot_scene};
use tumble_report::reference::cases;
use tumble_report::stability::matrix;
use tumble_report::workprec::{Effort, Method, measure};

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
    match run(Args::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: Args) -> Result<(), Box<dyn std::error::Error>> {
    let dts: Vec<f64> = if args.quick {
        [15.0, 30.0, 60.0, 120.0, 240.0, 480.0]
            .iter()
            .map(|n| 1.0 / n)
            .collect()
    } else {
        [15.0, 30.0, 60.0, 120.0, 240.0, 480.0, 960.0, 1920.0]
            .iter()
            .map(|n| 1.0 / n)
            .collect()
    };
    let effort = if args.quick {
        Effort {
            batch: 8,
            repetitions: 1,
        }
    } else {
        Effort {
            batch: 64,
            repetitions: 3,
        }
    };
    let cases = cases();
    let methods = Method::all();
    let total = cases.len() * methods.len() * dts.len() + tumble_core::Integrator::ALL.len();
    let bar = ProgressBar::new(total as u64);
    bar.set_style(ProgressStyle::with_template(
        "{bar:40} {pos}/{len} {msg} [{elapsed}]",
    )?);
    let mut points = Vec::new();
    for case in &cases {
        for &method in &methods {
            if method == Method::Rapier && !case.rapier {
                bar.inc(dts.len() as u64);
                continue;
            }
            bar.set_message(format!("{} · {}", case.name, method.name()));
            for &dt in &dts {
                points.push(measure(case, method, dt, effort));
                bar.inc(1);
            }
        }
    }
    bar.set_message("stability matrix");
    let cells = matrix(args.quick, || bar.inc(1));
    bar.set_message("energy over time");
    let energy = traces(if args.quick { 30 } else { 120 });
    bar.finish_and_clear();

    let results = Results::new(Machine::detect(args.quick), points, cells, energy);
    std::fs::create_dir_all(&args.out)?;
    let mut plots = Vec::new();
    for case in &cases {
        plots.push(plot_scene(&args.out, case.name, &results.work_precision)?);
    }
    for (spin, _) in spins() {
        plots.push(plot_energy(&args.out, spin, &results.energy)?);
    }
    std::fs::write(
        args.out.join("results.json"),
        serde_json::to_string_pretty(&results)?,
    )?;
    std::fs::write(args.out.join("report.md"), markdown(&results, &plots))?;
    let headline = headline_table(&results.work_precision);
    println!("{headline}");
    if let Some(readme) = &args.readme {
        let text = std::fs::read_to_string(readme)?;
        let updated = tumble_report::output::replace_between_markers(&text, &headline)
            .ok_or("README has no <!-- report:begin --> … <!-- report:end --> markers")?;
        std::fs::write(readme, updated)?;
        println!("updated the headline table in {}", readme.display());
    }
    println!(
        "wrote {}/report.md, results.json and {} plots",
        args.out.display(),
        plots.len()
    );
    Ok(())
}
