//! The frame budget: how many bodies fit in a 60 Hz frame, the question a game asks of the
//! benchmark, from the rows the same run measured.
//!
//! Bodies per frame = `(1/60 s) / (ns per body-step)` at the largest world measured of each
//! kind: the physics step alone, on one core and (where the run measured it) on two, so a game
//! reads its share of the frame off it. Spring chains have one spring per body, so their ns per
//! spring-step is per body-step too.

use std::fmt::Write;

use crate::springs::RAPIER_JOINT;
use crate::{BenchResults, Row};

/// One 60 Hz frame (ns).
const FRAME_NS: f64 = 1e9 / 60.0;

/// The README section's name (its markers: `<!-- frame-budget:begin -->` …).
pub const SECTION: &str = "frame-budget";

/// Bodies per frame at `ns` per body-step, rounded to three significant digits (the run-to-run
/// noise is larger).
fn per_frame(ns: f64) -> String {
    if !(ns.is_finite() && ns > 0.0) {
        return "–".to_owned();
    }
    let bodies = FRAME_NS / ns;
    let digits = bodies.log10().floor() as i32 - 2;
    let unit = 10f64.powi(digits.max(0));
    let rounded = (bodies / unit).round() * unit;
    let text = format!("{rounded:.0}");
    // Thousands separated by a thin space, as in the rest of the report.
    let mut out = String::new();
    for (i, c) in text.chars().enumerate() {
        if i > 0 && (text.len() - i) % 3 == 0 {
            out.push('\u{2009}');
        }
        out.push(c);
    }
    out
}

/// The free-body row of the default integrator with the most bodies.
fn largest_free(results: &BenchResults) -> Option<&Row> {
    results
        .rows
        .iter()
        .filter(|r| r.integrator == "splitting")
        .max_by_key(|r| r.bodies)
}

/// The spring throughput of `mode` at `omega_dt` with the most springs: (springs, one thread,
/// all pool threads).
fn largest_chains(
    results: &BenchResults,
    mode: &str,
    omega_dt: f64,
) -> Option<(usize, f64, Option<f64>)> {
    let rows = &results.springs.throughput;
    let n = rows
        .iter()
        .filter(|r| r.mode == mode && r.omega_dt == omega_dt)
        .map(|r| r.springs)
        .max()?;
    let at = |threads_one: bool| {
        rows.iter()
            .find(|r| {
                r.mode == mode && r.omega_dt == omega_dt && r.springs == n && {
                    (r.threads == 1) == threads_one
                }
            })
            .map(|r| r.ns_per_spring_step)
    };
    Some((n, at(true)?, at(false)))
}

/// The README's frame-budget section: bodies per 60 Hz frame for free bodies, explicit and
/// implicit spring chains, tumble on one and two threads and rapier on one, with the machine
/// and kernel path of the run.
pub fn frame_budget(results: &BenchResults) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Bodies per 60 Hz frame, the physics step alone ({} on {}, kernel path `{}`; \
         `cargo run --release -p tumble_bench -- --readme README.md` rewrites this table). \
         tumble's default integrator, rapier 0.36 with default settings; the largest world \
         of each kind the run measured:\n",
        results.date.get(..10).unwrap_or(&results.date),
        results.cpu,
        results.kernel_path
    );
    s.push_str(
        "| world | bodies measured | tumble, 1 thread | tumble, 2 threads | rapier, 1 thread |\n\
         |---|---:|---:|---:|---:|\n",
    );
    if let Some(r) = largest_free(results) {
        let _ = writeln!(
            s,
            "| free bodies under gravity | {} | {} | {} | {} |",
            r.bodies,
            per_frame(r.ecs_1t),
            per_frame(r.ecs_2t),
            r.rapier.map_or("–".to_owned(), per_frame)
        );
    }
    let rapier_joint = largest_chains(results, RAPIER_JOINT, 0.5).map(|(_, ns, _)| ns);
    for (mode, omega_dt, label) in [
        ("explicit", 0.5, "spring chains, explicit (ωΔt 0.5)"),
        ("implicit", 0.5, "spring chains, implicit (ωΔt 0.5)"),
        ("implicit", 10.0, "spring chains, implicit (ωΔt 10)"),
    ] {
        if let Some((n, one, two)) = largest_chains(results, mode, omega_dt) {
            let rapier = if mode == "explicit" {
                rapier_joint.map_or("–".to_owned(), per_frame)
            } else {
                "–".to_owned()
            };
            let _ = writeln!(
                s,
                "| {label} | {n} | {} | {} | {rapier} |",
                per_frame(one),
                two.map_or("–".to_owned(), per_frame)
            );
        }
    }
    s.push_str(
        "\nSpring chains carry gravity, a force at a body point and damping on every body; \
         rapier's chains are `SpringJoint`s. Full tables: [docs/performance.md](docs/performance.md).\n",
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bodies_per_frame_are_rounded_to_three_digits() {
        assert_eq!(per_frame(1e9 / 60.0 / 123_456.0), "123\u{2009}000");
        assert_eq!(per_frame(1e9 / 60.0 / 987.6), "988");
        assert_eq!(per_frame(f64::NAN), "–");
        assert_eq!(per_frame(0.0), "–");
    }
}
