//! The "Springs against rapier" section of `report.md` and its plot, `spring_energy.svg`.

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;

use crate::springs::{OMEGA_DTS, SpringRun, Variant};

/// File name of the plot.
pub const SPRING_PLOT: &str = "spring_energy.svg";

/// Lowest and highest `E/E₀` drawn; values outside are clipped to the frame.
const RANGE: (f64, f64) = (1e-3, 1e3);

/// How a run ended, for the table: `E/E₀` after the last step, or the step it failed at.
fn final_cell(run: &SpringRun) -> String {
    match run.failed_at {
        Some(step) => format!("**quarantined / non-finite at step {step}**"),
        None => {
            let r = run.final_ratio();
            if (1e-3..1e3).contains(&r) {
                format!("{r:.6}")
            } else {
                format!("{r:.3e}")
            }
        }
    }
}

/// The markdown section: what was run, the plot, and the table variant × `ωΔt`.
pub fn spring_section(runs: &[SpringRun]) -> String {
    let mut out = String::new();
    let steps = runs
        .first()
        .map_or(0, |r| r.energy_ratio.len().saturating_sub(1));
    let _ = writeln!(
        out,
        "## Springs against rapier\n\nThe stiff chain (ten asymmetric bodies, I = (0.02, 0.03, \
         0.04), off-centre anchors, the first tied to the world, springs stretched 10 %, no \
         damping) for {steps} steps of 1/60 s at nominal √(k/μ)Δt ∈ {{{}}}: tumble with the \
         explicit and the implicit spring step, rapier 0.36 (4 substeps) with its `SpringJoint` \
         (default force-based model) and with the spring force added by hand \
         (`add_force_at_point`, reset every step). Energy = kinetic + rotational + elastic, \
         computed the same way (f64) from each engine's states. A run that an engine quarantined \
         (tumble's divergence check; rapier's non-finite quarantine) stops there: its energy is \
         not a number after that step. E/E₀ over time: [{SPRING_PLOT}]({SPRING_PLOT}).\n",
        OMEGA_DTS.map(|w| w.to_string()).join(", ")
    );
    out.push_str(
        "| variant | √(k/μ)Δt | final E/E₀ | max \\|E − E₀\\|/E₀ while valid | µs/step |\n|---|---|---|---|---|\n",
    );
    for run in runs {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.2e} | {:.1} |",
            run.variant,
            run.omega_dt,
            final_cell(run),
            run.max_deviation(),
            run.us_per_step
        );
    }
    out
}

/// Draws `E/E₀` against time (log scale), one panel per `ωΔt`, one colour per variant; a failed
/// run's line ends where it failed (marked with a cross). Returns the file name.
pub fn plot_spring_energy(
    dir: &Path,
    runs: &[SpringRun],
) -> Result<String, Box<dyn std::error::Error>> {
    crate::plots::svg(dir, SPRING_PLOT.to_owned(), (1200, 460), |root| {
        let panels = root.split_evenly((1, OMEGA_DTS.len()));
        let dt = 1.0 / 60.0;
        for (panel, omega_dt) in panels.iter().zip(OMEGA_DTS) {
            let omega_dt = tumble_core::math::to_f64(omega_dt);
            let here: Vec<&SpringRun> = runs.iter().filter(|r| r.omega_dt == omega_dt).collect();
            let seconds = here
                .iter()
                .map(|r| r.energy_ratio.len().saturating_sub(1))
                .max()
                .unwrap_or(1) as f64
                * dt;
            let mut chart = ChartBuilder::on(panel)
                .caption(format!("√(k/μ)Δt = {omega_dt}: E/E₀"), ("sans-serif", 16))
                .margin(10)
                .x_label_area_size(36)
                .y_label_area_size(56)
                .build_cartesian_2d(0.0..seconds.max(dt), (RANGE.0..RANGE.1).log_scale())?;
            chart
                .configure_mesh()
                .x_desc("time (s)")
                .y_label_formatter(&|y| format!("{y:.0e}"))
                .draw()?;
            for (k, variant) in Variant::ALL.iter().enumerate() {
                let Some(run) = here.iter().find(|r| r.variant == variant.name()) else {
                    continue;
                };
                let color = Palette99::pick(k).to_rgba();
                let series: Vec<(f64, f64)> = run
                    .energy_ratio
                    .iter()
                    .take_while(|e| e.is_finite())
                    .enumerate()
                    .map(|(i, e)| (i as f64 * dt, e.clamp(RANGE.0, RANGE.1)))
                    .collect();
                let label = match run.failed_at {
                    Some(step) => format!("{} (fails at step {step})", run.variant),
                    None => run.variant.clone(),
                };
                if let (Some(_), Some(&last)) = (run.failed_at, series.last()) {
                    chart.draw_series(std::iter::once(Cross::new(
                        last,
                        6,
                        color.stroke_width(2),
                    )))?;
                }
                crate::plots::legend_line(&mut chart, series, color, label)?;
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::LowerLeft)
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .label_font(("sans-serif", 11))
                .draw()?;
        }
        Ok(())
    })
}
