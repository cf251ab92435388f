//! `report.md` and `results.json`: the tables and the results the plots are drawn from.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use serde::Serialize;

use crate::energy::EnergyTrace;
use crate::springs::SpringRun;
use crate::stability::Cell;
use crate::workprec::{Point, headline_error, work_us};
use tumble_core::math::REAL_NAME;

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
    /// The precision of the simulated state, `f32` or `f64` (the feature `f64`): every
    /// tumble number of the report is in it; rapier's are in `f32`.
    pub precision: String,
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
            precision: REAL_NAME.to_owned(),
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
    /// What `f32` state costs each scene (see [`crate::storage`]); empty in an `f32` build.
    pub f32_storage: Vec<crate::storage::StorageRow>,
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
            f32_storage: Vec::new(),
        }
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
        "Machine: {} ({} cores, {}), tumble {}{}. State in `{}`: every tumble number below is \
         in it (rapier's are in `f32`).\n",
        m.cpu,
        m.cores,
        m.os,
        m.tumble_version,
        if m.quick { ", quick mode" } else { "" },
        m.precision
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
    out.push_str(&work_precision_tables(&results.work_precision));
    out.push_str(&crate::storage::storage_section(&results.f32_storage));
    out.push_str(&thin_plate_section(&results.thin_plate));
    let _ = writeln!(
        out,
        "## Stability matrix\n\nEvery scene conserves its total energy (kinetic + spring + gravity) \
         physically. Verdict on it, checked after every step: **right** = finite, `||q| − 1| < \
         1e-5`, `E/E₀` within 1 ± 5 %; **dissipative** = never above 1.05 but more than 5 % lost; \
         **bounded** = more than 5 % gained at some step but within [0.01, 100]; **refused** = \
         not run: a first-order method cannot step a stiff spring group (the implicit step \
         needs a free rotation at constant momentum); **unstable** = anything else (bold). \
         \"warned\" = tumble's planning-time prediction of a divergence or a refusal; \
         `springs` = the spring step (`auto` takes the implicit one for stiff groups). The same \
         verdicts as a heatmap: [stability.svg](stability.svg).\n"
    );
    out.push_str(&stability_table(&results.stability));
    out.push('\n');
    out.push_str(&crate::spring_output::spring_section(&results.springs));
    out
}

/// One table per scene of every method's work–precision points.
fn work_precision_tables(points: &[Point]) -> String {
    let mut out = String::new();
    let mut scenes: Vec<&str> = points.iter().map(|p| p.scene.as_str()).collect();
    scenes.dedup();
    for scene in scenes {
        let _ = writeln!(out, "### {scene}\n");
        out.push_str("| method | Δt (s) | orientation (rad) | position (m) | energy drift | |L| drift | ns/body-step |\n|---|---|---|---|---|---|---|\n");
        for p in points.iter().filter(|p| p.scene == scene) {
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
    out
}

/// The stability matrix, one row per scene, setting and integrator.
fn stability_table(cells: &[Cell]) -> String {
    let mut out = String::new();
    out.push_str("| scene | setting | integrator | springs | finite | max \\|\\|q\\|−1\\| | E/E₀ | E/E₀ range | verdict | warned |\n|---|---|---|---|---|---|---|---|---|---|\n");
    for c in cells {
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
