//! The report's plots: work–precision per scene, energy over time, the stability matrix.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::energy::EnergyTrace;
use crate::stability::Cell;
use crate::workprec::{Point, headline_error, work_us};

/// Draws the SVG file `file` in `dir`, `size` pixels on a white background, with `draw`, and
/// returns `file`.
pub(crate) fn svg(
    dir: &Path,
    file: String,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), Box<dyn std::error::Error>>,
) -> Result<String, Box<dyn std::error::Error>> {
    let path = dir.join(&file);
    let root = SVGBackend::new(&path, size).into_drawing_area();
    root.fill(&WHITE)?;
    draw(&root)?;
    root.present()?;
    Ok(file)
}

/// Draws `series` as a line of `color`, two pixels wide, named `label` in the legend.
pub(crate) fn legend_line<CT: CoordTranslate<From = (f64, f64)>>(
    chart: &mut ChartContext<'_, SVGBackend<'_>, CT>,
    series: Vec<(f64, f64)>,
    color: RGBAColor,
    label: impl Into<String>,
) -> Result<(), Box<dyn std::error::Error>> {
    chart
        .draw_series(LineSeries::new(series, color.stroke_width(2)))?
        .label(label)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2)));
    Ok(())
}

/// Draws error against the run time to the horizon (log–log) for one scene; returns the file
/// name.
pub fn plot_scene(
    dir: &Path,
    scene: &str,
    points: &[Point],
) -> Result<String, Box<dyn std::error::Error>> {
    let file = format!("workprec-{scene}.svg");
    let pts: Vec<&Point> = points
        .iter()
        .filter(|p| p.scene == scene && p.finite && headline_error(p) > 0.0)
        .collect();
    if pts.is_empty() {
        return Ok(file);
    }
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in &pts {
        x0 = x0.min(work_us(p));
        x1 = x1.max(work_us(p));
        y0 = y0.min(headline_error(p));
        y1 = y1.max(headline_error(p));
    }
    svg(dir, file, (800, 560), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(
                format!("{scene}: error at the horizon vs run time"),
                ("sans-serif", 18),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(
                (x0 * 0.8..x1 * 1.25).log_scale(),
                (y0 * 0.5..y1 * 2.0).log_scale(),
            )?;
        chart
            .configure_mesh()
            .x_desc("run time to the horizon per body (µs)")
            .y_desc("error (rad or m)")
            .y_label_formatter(&|y| format!("{y:.0e}"))
            .draw()?;
        let mut methods: Vec<&str> = pts.iter().map(|p| p.method.as_str()).collect();
        methods.sort_unstable();
        methods.dedup();
        for (k, method) in methods.iter().enumerate() {
            let color = Palette99::pick(k).to_rgba();
            let series: Vec<(f64, f64)> = pts
                .iter()
                .filter(|p| p.method == *method)
                .map(|p| (work_us(p), headline_error(p)))
                .collect();
            legend_line(&mut chart, series.clone(), color, *method)?;
            chart.draw_series(
                series
                    .into_iter()
                    .map(|(x, y)| Circle::new((x, y), 3, color.filled())),
            )?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()?;
        Ok(())
    })
}

/// Draws `|E(t)/E(0) − 1|` over time (log scale) for one long spin; returns the file name.
pub fn plot_energy(
    dir: &Path,
    spin: &str,
    traces: &[EnergyTrace],
) -> Result<String, Box<dyn std::error::Error>> {
    svg(dir, format!("energy-{spin}.svg"), (800, 560), |root| {
        let seconds = traces
            .iter()
            .map(|t| t.relative_energy.len())
            .max()
            .unwrap_or(1) as f64;
        let mut chart = ChartBuilder::on(root)
            .caption(
                format!("{spin} spin, 10 rad/s, 60 Hz: |E(t)/E(0) − 1|"),
                ("sans-serif", 18),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..seconds, (1e-8..10.0).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("time (s)")
            .y_desc("relative energy error")
            .draw()?;
        for (k, trace) in traces.iter().filter(|t| t.spin == spin).enumerate() {
            let color = Palette99::pick(k).to_rgba();
            let series: Vec<(f64, f64)> = trace
                .relative_energy
                .iter()
                .enumerate()
                .filter(|(_, e)| e.is_finite())
                .map(|(i, e)| (i as f64, e.abs().clamp(1e-8, 10.0)))
                .collect();
            legend_line(&mut chart, series, color, trace.method.clone())?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()?;
        Ok(())
    })
}

/// Draws the stability matrix as a heatmap: one row per scene and setting, one column per
/// integrator and spring step, coloured by [`Cell::verdict`], with a `w` where tumble predicted a
/// divergence; returns the file name.
pub fn plot_stability(dir: &Path, cells: &[Cell]) -> Result<String, Box<dyn std::error::Error>> {
    let file = "stability.svg".to_owned();
    let mut rows: Vec<(String, String)> = Vec::new();
    let mut columns: Vec<(String, String)> = Vec::new();
    for c in cells {
        let row = (c.scene.clone(), c.setting.clone());
        if !rows.contains(&row) {
            rows.push(row);
        }
        let column = (c.integrator.clone(), c.springs.clone());
        if !columns.contains(&column) {
            columns.push(column);
        }
    }
    let (cell_w, cell_h, left, top) = (44_i32, 16_i32, 260_i32, 150_i32);
    let width = left + cell_w * columns.len() as i32 + 20;
    let height = top + cell_h * rows.len() as i32 + 40;
    svg(dir, file, (width as u32, height as u32), |root| {
        let text = ("sans-serif", 11).into_font();
        root.draw(&Text::new(
        "verdict on total energy: green right · yellow dissipative · blue bounded · grey refused · red unstable · w = predicted",
        (8, 8),
        text.clone(),
    ))?;
        for (j, (integrator, springs)) in columns.iter().enumerate() {
            let x = left + cell_w * j as i32 + cell_w / 2;
            let label = if springs == "—" {
                integrator.clone()
            } else {
                format!("{integrator} / {springs}")
            };
            root.draw(&Text::new(
                label,
                (x, top - 6),
                text.clone().transform(FontTransform::Rotate270),
            ))?;
        }
        for (i, (scene, setting)) in rows.iter().enumerate() {
            let y = top + cell_h * i as i32;
            root.draw(&Text::new(
                format!("{scene} · {setting}"),
                (8, y + 3),
                text.clone(),
            ))?;
            for (j, column) in columns.iter().enumerate() {
                let Some(c) = cells.iter().find(|c| {
                    c.scene == *scene
                        && c.setting == *setting
                        && c.integrator == column.0
                        && c.springs == column.1
                }) else {
                    continue;
                };
                let colour = match c.verdict() {
                    "right" => RGBColor(76, 175, 80),
                    "dissipative" => RGBColor(255, 193, 7),
                    "bounded" => RGBColor(100, 160, 230),
                    "refused" => RGBColor(150, 150, 150),
                    _ => RGBColor(220, 50, 47),
                };
                let x = left + cell_w * j as i32;
                root.draw(&Rectangle::new(
                    [(x + 1, y + 1), (x + cell_w - 1, y + cell_h - 1)],
                    colour.filled(),
                ))?;
                if c.warned {
                    root.draw(&Text::new("w", (x + cell_w / 2 - 3, y + 2), text.clone()))?;
                }
            }
        }
        Ok(())
    })
}
