//! `report.md`, `results.json` and SVG plots.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use serde::Serialize;

use crate::energy::EnergyTrace;
use crate::springs::SpringRun;
use crate::stability::Cell;
use crate::workprec::Point;

/// Where and on what the report was measured.
#[derive(Debug, Clone, Serialize)]
pub struct Machine {
    /// CPU model from /proc/cpuinfo, when readable.
    pub cpu: String,
    /// Logical cores.
    pub cores: usize,
    /// Operating system.
    pub os: String,
    /// tumble version.
    pub tumble_version: String,
    /// Quick mode (fewer, shorter runs).
    pub quick: bool,
}

impl Machine {
    /// Reads the machine description.
    pub fn detect(quick: bool) -> Self {
        let cpu = std::fs::read_to_string("/proc/cpuinfo")
            .ok()
            .and_then(|s| {
                s.lines()
                    .find(|l| l.starts_with("model name"))
                    .and_then(|l| l.split(':').nth(1))
                    .map(|m| m.trim().to_owned())
            })
            .unwrap_or_else(|| "unknown".to_owned());
        Self {
            cpu,
            cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
            os: std::env::consts::OS.to_owned(),
            tumble_version: env!("CARGO_PKG_VERSION").to_owned(),
            quick,
        }
    }
}

/// Everything the report measured, as written to `results.json`.
#[derive(Debug, Clone, Serialize)]
pub struct Results {
    /// Schema version of this file.
    pub schema: u32,
    /// Units of every field.
    pub units: BTreeMap<&'static str, &'static str>,
    /// The machine.
    pub machine: Machine,
    /// Work–precision points.
    pub work_precision: Vec<Point>,
    /// Stability matrix.
    pub stability: Vec<Cell>,
    /// Energy over time of the long spins.
    pub energy: Vec<EnergyTrace>,
    /// The stiff chain in tumble and rapier, each spring step (see [`crate::springs`]).
    pub springs: Vec<SpringRun>,
    /// The thin asymmetric plate at every spin rate (see [`crate::thin`]).
    pub thin_plate: Vec<crate::thin::ThinRow>,
}

impl Results {
    /// Bundles the measurements with their units.
    pub fn new(
        machine: Machine,
        work_precision: Vec<Point>,
        stability: Vec<Cell>,
        energy: Vec<EnergyTrace>,
        springs: Vec<SpringRun>,
        thin_plate: Vec<crate::thin::ThinRow>,
    ) -> Self {
        let units = BTreeMap::from([
            ("dt_s", "s"),
            ("orientation_error_rad", "rad"),
            ("position_error_m", "m"),
            ("energy_drift", "1 (relative)"),
            ("momentum_drift", "1 (relative)"),
            ("ns_per_body_step", "ns"),
            ("max_quaternion_error", "1"),
            ("energy_ratio", "1"),
            (
                "relative_energy",
                "1 (E(t)/E(0) − 1, one sample per second)",
            ),
            ("omega_dt", "1 (nominal √(k/μ)Δt)"),
            (
                "energy_ratio (springs)",
                "1 (E/E₀ after every step, null once quarantined or non-finite)",
            ),
            ("us_per_step", "µs"),
        ]);
        Self {
            schema: 1,
            units,
            machine,
            work_precision,
            stability,
            energy,
            springs,
            thin_plate,
        }
    }
}

/// The error that matters for a scene: orientation for rotating scenes, position otherwise.
pub fn headline_error(p: &Point) -> f64 {
    if p.scene.starts_with("top") || p.scene == "dzhanibekov" {
        p.orientation_error_rad
    } else {
        p.position_error_m.max(p.orientation_error_rad)
    }
}

fn sci(x: f64) -> String {
    if x.is_nan() {
        // Not measured (the linkage's energy is not conserved: its force and torque work).
        "—".to_owned()
    } else if x.is_finite() {
        format!("{x:.1e}")
    } else {
        "∞".to_owned()
    }
}

/// The scenes and the methods of `points`, each in order of first appearance.
fn scenes_and_methods(points: &[Point]) -> (Vec<&str>, Vec<&str>) {
    let mut scenes: Vec<&str> = Vec::new();
    let mut methods: Vec<&str> = Vec::new();
    for p in points {
        if !scenes.contains(&p.scene.as_str()) {
            scenes.push(&p.scene);
        }
        if !methods.contains(&p.method.as_str()) {
            methods.push(&p.method);
        }
    }
    (scenes, methods)
}

/// The header rows of a table with a method column, one column per scene and optionally a
/// last column.
fn table_head(scenes: &[&str], last: Option<&str>) -> String {
    let mut out = String::from("| method |");
    for s in scenes {
        let _ = write!(out, " {s} |");
    }
    if let Some(last) = last {
        let _ = write!(out, " {last} |");
    }
    out.push_str("\n|---|");
    out.push_str(&"---|".repeat(scenes.len() + usize::from(last.is_some())));
    out.push('\n');
    out
}

/// The headline table: error at Δt = 1/60 s and ns per body-step, per scene and method.
pub fn headline_table(points: &[Point]) -> String {
    let (scenes, methods) = scenes_and_methods(points);
    let mut out = table_head(&scenes, Some("ns/body-step"));
    for m in &methods {
        let _ = write!(out, "| `{m}` |");
        let mut ns = Vec::new();
        for s in &scenes {
            match points
                .iter()
                .find(|p| p.method == *m && p.scene == *s && (p.dt_s - 1.0 / 60.0).abs() < 1e-6)
            {
                Some(p) if p.finite => {
                    let _ = write!(out, " {} |", sci(headline_error(p)));
                    ns.push(p.ns_per_body_step);
                }
                Some(_) => out.push_str(" diverged |"),
                None => out.push_str(" — |"),
            }
        }
        ns.sort_by(f64::total_cmp);
        let median = ns.get(ns.len() / 2).copied().unwrap_or(f64::NAN);
        let _ = writeln!(out, " {median:.0} |");
    }
    out
}

/// The error each method reaches at the same run time: per scene, the time `splitting` takes to
/// the horizon at Δt = 1/60 s, and each method's error at that time, interpolated log–log
/// between the two measured Δt whose run times bracket it (`—` when none do, or when the
/// method diverged there). A cheap first-order method may then take many small steps, and an
/// expensive high-order one few large ones: this is the comparison that matters.
pub fn equal_time_table(points: &[Point]) -> String {
    let (scenes, methods) = scenes_and_methods(points);
    let budget = |scene: &str| {
        points
            .iter()
            .find(|p| {
                p.scene == scene && p.method == "splitting" && (p.dt_s - 1.0 / 60.0).abs() < 1e-6
            })
            .map(work_us)
    };
    let mut out = table_head(&scenes, None);
    for m in &methods {
        let _ = write!(out, "| `{m}` |");
        for s in &scenes {
            let mut curve: Vec<(f64, f64)> = points
                .iter()
                .filter(|p| p.method == *m && p.scene == *s)
                .map(|p| {
                    (
                        work_us(p),
                        if p.finite {
                            headline_error(p)
                        } else {
                            f64::INFINITY
                        },
                    )
                })
                .collect();
            curve.sort_by(|a, b| a.0.total_cmp(&b.0));
            let at = budget(s).and_then(|t| {
                curve.windows(2).find_map(|w| {
                    let ((t0, e0), (t1, e1)) = (w[0], w[1]);
                    (t0 <= t && t <= t1 && t0 < t1).then(|| {
                        if !(e0.is_finite() && e1.is_finite() && e0 > 0.0 && e1 > 0.0) {
                            return f64::INFINITY;
                        }
                        let f = (t / t0).ln() / (t1 / t0).ln();
                        (e0.ln() + f * (e1.ln() - e0.ln())).exp()
                    })
                })
            });
            match at {
                Some(e) if e.is_finite() => {
                    let _ = write!(out, " {} |", sci(e));
                }
                Some(_) => out.push_str(" diverged |"),
                None => out.push_str(" — |"),
            }
        }
        out.push('\n');
    }
    out
}

/// The full markdown report.
pub fn markdown(results: &Results, plots: &[String]) -> String {
    let mut out = String::new();
    let m = &results.machine;
    let _ = writeln!(out, "# tumble accuracy report\n");
    let _ = writeln!(
        out,
        "Machine: {} ({} cores, {}), tumble {}{}.\n",
        m.cpu,
        m.cores,
        m.os,
        m.tumble_version,
        if m.quick { ", quick mode" } else { "" }
    );
    let _ = writeln!(
        out,
        "## Headline: error at Δt = 1/60 s\n\nOrientation error (rad) for the tops, position \
         error (m, or orientation where larger) for the others, at each scene's horizon; \
         ns/body-step is the median over scenes, each timed through the ECS (the batched \
         systems users run, 64 copies of the scene per world).\n"
    );
    out.push_str(&headline_table(&results.work_precision));
    let _ = writeln!(
        out,
        "\n## Headline: error at equal run time\n\nEach method's error when it runs as long as \
         `splitting` at Δt = 1/60 s (interpolated on its work–precision curve; — where the \
         measured Δt do not reach that run time).\n"
    );
    out.push_str(&equal_time_table(&results.work_precision));
    let _ = writeln!(out, "\n## Work–precision\n");
    for plot in plots {
        let _ = writeln!(out, "![{plot}]({plot})\n");
    }
    let mut scenes: Vec<&str> = results
        .work_precision
        .iter()
        .map(|p| p.scene.as_str())
        .collect();
    scenes.dedup();
    for scene in scenes {
        let _ = writeln!(out, "### {scene}\n");
        out.push_str("| method | Δt (s) | orientation (rad) | position (m) | energy drift | |L| drift | ns/body-step |\n|---|---|---|---|---|---|---|\n");
        for p in results.work_precision.iter().filter(|p| p.scene == scene) {
            let _ = writeln!(
                out,
                "| `{}` | 1/{:.0} | {} | {} | {} | {} | {:.0} |",
                p.method,
                1.0 / p.dt_s,
                sci(p.orientation_error_rad),
                sci(p.position_error_m),
                sci(p.energy_drift),
                p.momentum_drift.map_or("—".to_owned(), sci),
                p.ns_per_body_step
            );
        }
        out.push('\n');
    }
    out.push_str(&thin_plate_section(&results.thin_plate));
    let _ = writeln!(
        out,
        "## Stability matrix\n\nEvery scene conserves its total energy (kinetic + spring + gravity) \
         physically. Verdict on it, checked after every step: **right** = finite, `||q| − 1| < \
         1e-5`, `E/E₀` within 1 ± 5 %; **dissipative** = never above 1.05 but more than 5 % lost; \
         **bounded** = more than 5 % gained at some step but within [0.01, 100]; **unstable** = \
         anything else (bold). \"warned\" = tumble's planning-time prediction of a divergence; \
         `springs` = the spring step (`auto` takes the implicit one for stiff groups). The same \
         verdicts as a heatmap: [stability.svg](stability.svg).\n"
    );
    out.push_str("| scene | setting | integrator | springs | finite | max \\|\\|q\\|−1\\| | E/E₀ | E/E₀ range | verdict | warned |\n|---|---|---|---|---|---|---|---|---|---|\n");
    for c in &results.stability {
        let mark = |s: String| if c.stable() { s } else { format!("**{s}**") };
        let [low, high] = c.energy_range;
        let range = if low.is_finite() && high.is_finite() {
            format!("{low:.3} … {high:.3}")
        } else {
            "—".into()
        };
        let _ = writeln!(
            out,
            "| {} | {} | `{}` | {} | {} | {} | {} | {range} | {} | {} |",
            c.scene,
            c.setting,
            c.integrator,
            c.springs,
            mark(c.finite.to_string()),
            sci(c.max_quaternion_error),
            mark(if c.energy_ratio.is_finite() {
                format!("{:.4}", c.energy_ratio)
            } else {
                "—".into()
            }),
            mark(c.verdict().to_owned()),
            c.warned
        );
    }
    out.push('\n');
    out.push_str(&crate::spring_output::spring_section(&results.springs));
    out
}

/// The thin plate's table: one row per spin rate, one column pair per integrator.
pub fn thin_plate_section(rows: &[crate::thin::ThinRow]) -> String {
    let mut out = String::new();
    if rows.is_empty() {
        return out;
    }
    let p = crate::thin::PLATE;
    let _ = writeln!(
        out,
        "## Thin asymmetric plate\n\nI = ({}, {}, {}), spun about an axis tilted from every \
         principal axis, 10 s at Δt = 1/60 s against the closed-form top: the largest \
         orientation error over the run (rad) / the largest relative energy drift. (`|L|` is kept \
         to round-off by the Lie–Poisson methods and `exact`; see `results.json`.)\n",
        p.x, p.y, p.z
    );
    let mut methods: Vec<&str> = rows.iter().map(|r| r.integrator.as_str()).collect();
    methods.dedup();
    methods.sort_unstable();
    methods.dedup();
    let order: Vec<&str> = tumble_core::Integrator::ALL
        .iter()
        .map(|i| i.name())
        .filter(|n| methods.contains(n))
        .collect();
    out.push_str("| \\|ω\\|Δt |");
    for m in &order {
        let _ = write!(out, " `{m}` |");
    }
    out.push_str("\n|---|");
    out.push_str(&"---|".repeat(order.len()));
    out.push('\n');
    let mut rates: Vec<f64> = rows.iter().map(|r| r.omega_dt).collect();
    rates.dedup();
    for rate in rates {
        let _ = write!(out, "| {rate:.1} |");
        for m in &order {
            let cell = rows
                .iter()
                .find(|r| r.omega_dt == rate && r.integrator == *m)
                .map_or("—".to_owned(), |r| {
                    if r.finite {
                        format!("{} / {}", sci(r.orientation_error_rad), sci(r.energy_drift))
                    } else {
                        "**diverged**".to_owned()
                    }
                });
            let _ = write!(out, " {cell} |");
        }
        out.push('\n');
    }
    out.push('\n');
    out
}

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

/// Run time to simulate the scene's horizon for one body (µs): the work of a work–precision plot.
fn work_us(p: &Point) -> f64 {
    p.ns_per_body_step * p.steps as f64 / 1e3
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
        "verdict on total energy: green right · yellow dissipative · blue bounded · red unstable · w = predicted",
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
