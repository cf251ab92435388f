//! The whole report in one call, shared by `tumble-report` and `tumble report`.

use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressStyle};
use tumble_scene::output::{OutputError, OutputSet, print_to_stdout, with_sections};
use tumble_scene::text::path_for_terminal;

use crate::energy::{spins, traces};
use crate::output::{Machine, Results, headline_table, markdown};
use crate::plots::{plot_energy, plot_scene};
use crate::reference::{Case, cases};
use crate::spring_output::plot_spring_energy;
use crate::springs::spring_runs;
use crate::stability::matrix;
use crate::workprec::{Effort, Method, measure};

/// What to run and where to write it (also the command-line arguments of `tumble report` and
/// `tumble-report`).
#[derive(Debug, Clone, clap::Args)]
pub struct ReportOptions {
    /// Fewer time steps, smaller batches, shorter stability runs (< 60 s on 2 cores).
    #[arg(long)]
    pub quick: bool,
    /// Output directory.
    #[arg(long, default_value = "report")]
    pub out: PathBuf,
    /// Also replace the headline table in this markdown file (between the
    /// `<!-- report:begin -->` and `<!-- report:end -->` markers), e.g. README.md.
    #[arg(long)]
    pub readme: Option<PathBuf>,
}

/// Runs the work–precision study, the stability matrix, the energy traces and the springs
/// against rapier; writes
/// `report.md`, `results.json` and the SVG plots; prints the headline table.
///
/// Every destination is checked before minutes of work (an output directory that is a file or
/// takes no new file, a read-only `report.md` or `results.json`, a README without its markers:
/// each an error naming it). The files are written as one
/// [`OutputSet`]: all of them, the README too, are written
/// before any old one is replaced, so a failure leaves the old report whole.
pub fn run_report(options: &ReportOptions) -> Result<(), Box<dyn std::error::Error>> {
    let out: &Path = &options.out;
    for name in ["report.md", "results.json"] {
        OutputSet::check(&out.join(name))?;
    }
    if let Some(readme) = &options.readme {
        with_sections(readme, &[("report", "")])?;
        OutputSet::check(readme)?;
    }
    let cases = cases();
    let results = measure_everything(options.quick, &cases)?;
    // The plots are drawn into a private directory in `out` (plotters opens its path as it
    // is), then each joins the set by the same safe route as the other files. `out` is made
    // for it by the set, which removes it again unless it commits; the staging directory,
    // declared after the set, goes first.
    let mut files = OutputSet::new();
    files.make_directory(out)?;
    let staging = tempfile::Builder::new()
        .prefix(".tumble-plots-")
        .tempdir_in(out)
        .map_err(|e| OutputError::io(out, e))?;
    let plots = draw_plots(staging.path(), &cases, &results)?;
    for plot in &plots {
        let drawn = staging.path().join(plot);
        // A scene without finite points gets no plot file (see `plot_scene`).
        if drawn.exists() {
            let bytes = std::fs::read(&drawn).map_err(|e| OutputError::io(&drawn, e))?;
            files.add(&out.join(plot), &bytes)?;
        }
    }
    files.add(
        &out.join("results.json"),
        serde_json::to_string_pretty(&results)?.as_bytes(),
    )?;
    files.add(
        &out.join("report.md"),
        markdown(&results, &plots).as_bytes(),
    )?;
    let headline = format!(
        "{}\nAt equal run time (each method run as long as `splitting` at Δt = 1/60 s, its error \
         interpolated on its work–precision curve):\n\n{}",
        headline_table(&results.work_precision),
        crate::output::equal_time_table(&results.work_precision)
    );
    if let Some(readme) = &options.readme {
        files.add(
            readme,
            with_sections(readme, &[("report", &headline)])?.as_bytes(),
        )?;
    }
    files.commit()?;
    print_to_stdout(&format!("{headline}\n"))?;
    if let Some(readme) = &options.readme {
        print_to_stdout(&format!(
            "updated the headline table in {}\n",
            path_for_terminal(readme)
        ))?;
    }
    print_to_stdout(&format!(
        "wrote {}/report.md, results.json and {} plots\n",
        path_for_terminal(out),
        plots.len()
    ))?;
    Ok(())
}

/// Every measurement of the report (`quick`: the short version CI runs): work–precision on
/// `cases` and the linkage, the stability matrix, the thin plate, energy over time and the
/// springs against rapier, with a progress bar.
fn measure_everything(quick: bool, cases: &[Case]) -> Result<Results, Box<dyn std::error::Error>> {
    let dts: Vec<f64> = if quick {
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
    let effort = if quick {
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
    let methods = Method::all();
    let integrators = tumble_core::Integrator::ALL;
    let total = cases.len() * methods.len() * dts.len()
        + integrators.len() * dts.len()
        + tumble_core::Integrator::ALL.len()
        + 2 * crate::springs::OMEGA_DTS.len();
    let bar = ProgressBar::new(total as u64);
    bar.set_style(ProgressStyle::with_template(
        "{bar:40} {pos}/{len} {msg} [{elapsed}]",
    )?);
    let mut points = Vec::new();
    for case in cases {
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
    bar.set_message(format!("{} · reference", crate::linkage::NAME));
    let exact = crate::linkage::reference(crate::linkage::HORIZON, crate::linkage::REFERENCE_STEPS);
    for &integrator in integrators {
        bar.set_message(format!("{} · {integrator}", crate::linkage::NAME));
        for &dt in &dts {
            points.push(crate::linkage::measure(
                integrator,
                dt,
                effort.batch,
                effort.repetitions,
                &exact,
            ));
            bar.inc(1);
        }
    }
    bar.set_message("stability matrix");
    let cells = matrix(quick, || bar.inc(1));
    bar.set_message("thin plate");
    let thin_plate = crate::thin::table();
    bar.set_message("energy over time");
    let energy = traces(if quick { 30 } else { 120 });
    bar.set_message("springs against rapier");
    let springs = spring_runs(if quick { 120 } else { 600 }, || bar.inc(1));
    bar.finish_and_clear();

    let mut results = Results::new(
        Machine::detect(quick),
        points,
        cells,
        energy,
        springs,
        thin_plate,
    );
    results.f32_storage = crate::storage::storage_table(cases);
    Ok(results)
}

/// Draws every plot of `results` into `dir`; returns their file names.
fn draw_plots(
    dir: &Path,
    cases: &[Case],
    results: &Results,
) -> Result<Vec<String>, Box<dyn std::error::Error>> {
    let mut plots = Vec::new();
    for name in cases.iter().map(|c| c.name).chain([crate::linkage::NAME]) {
        plots.push(plot_scene(dir, name, &results.work_precision)?);
    }
    for (spin, _) in spins() {
        plots.push(plot_energy(dir, spin, &results.energy)?);
    }
    plots.push(crate::plots::plot_stability(dir, &results.stability)?);
    plots.push(plot_spring_energy(dir, &results.springs)?);
    Ok(plots)
}
