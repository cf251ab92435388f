//! The benchmark's outputs: a markdown table, the project's speed targets, JSON, and the README
//! section.

use std::fmt::Write;

use crate::methods::MethodRow;
use crate::{BenchResults, Row, Target};

/// The default integrator's name (the targets are stated for it).
const DEFAULT: &str = "splitting";

fn rows_of<'a>(results: &'a BenchResults, integrator: &'a str) -> impl Iterator<Item = &'a Row> {
    results
        .rows
        .iter()
        .filter(move |r| r.integrator == integrator)
}

fn row(results: &BenchResults, integrator: &str, bodies: usize) -> Option<Row> {
    rows_of(results, integrator)
        .find(|r| r.bodies == bodies)
        .cloned()
}

fn fmt_ns(ns: f64) -> String {
    if ns >= 100.0 {
        format!("{ns:.0}")
    } else {
        format!("{ns:.1}")
    }
}

/// Appends a markdown table to `s`: the paragraph `caption`, the `header` row, the `align` row,
/// one row per item as `row` writes it, and a blank line.
fn table<T>(
    s: &mut String,
    caption: &str,
    header: &str,
    align: &str,
    items: impl IntoIterator<Item = T>,
    row: impl Fn(T) -> String,
) {
    let _ = writeln!(s, "{caption}\n");
    let _ = writeln!(s, "{header}");
    let _ = writeln!(s, "{align}");
    for item in items {
        let _ = writeln!(s, "{}", row(item));
    }
    s.push('\n');
}

/// A [`table`] of `rows` on its own, or nothing when there are none.
fn table_if_any<T>(
    caption: &str,
    header: &str,
    align: &str,
    rows: &[T],
    row: impl Fn(&T) -> String,
) -> String {
    let mut s = String::new();
    if !rows.is_empty() {
        table(&mut s, caption, header, align, rows, row);
    }
    s
}

/// Where and when the run was made, and on which kernel path (forced or the widest).
fn machine_line(results: &BenchResults) -> String {
    let path = if results.kernel_path == results.widest_kernel_path {
        format!(
            "kernel path `{}` (the widest this CPU has)",
            results.kernel_path
        )
    } else {
        format!(
            "kernel path `{}`, forced with `TUMBLE_KERNEL` (this CPU has `{}`)",
            results.kernel_path, results.widest_kernel_path
        )
    };
    format!("Measured {} on {}, {path}.", results.date, results.cpu)
}

/// The kernel's flops per body-step beside the bytes, and the rate the ECS step runs them at.
fn flops_line(results: &BenchResults) -> String {
    let f = &results.kernel_flops;
    let mut line = format!(
        "Compute: the default integrator's free rotation is {} flops per body-step ({} adds, {} \
         multiplies, {} divisions, {} square roots; counted by running its kernel on a lane \
         type that counts), {:.1} flops per byte the step moves",
        f.total,
        f.add,
        f.mul,
        f.div,
        f.sqrt,
        f.total as f64 / results.bytes_per_body_step as f64
    );
    let largest = rows_of(results, DEFAULT)
        .filter(|r| r.bodies <= 100_000)
        .max_by_key(|r| r.bodies);
    if let Some(r) = largest {
        let _ = write!(
            line,
            "; the ECS step on one thread at N = {} runs them at {:.1} GFLOP/s",
            r.bodies,
            f.total as f64 / r.ecs_1t
        );
    }
    line.push('.');
    line
}

/// The full markdown report: machine, per-size table per integrator, targets.
pub fn markdown(results: &BenchResults) -> String {
    let mut s = String::new();
    let [bw1, bwn] = results.bandwidth_gb_s;
    let floor = results.bytes_per_body_step as f64 / bw1;
    let _ = writeln!(
        s,
        "{}\n\nMemory: {bw1:.1} GB/s copy on one thread, {bwn:.1} GB/s on {} threads; an ECS \
         body-step moves {} bytes, so one thread cannot go below {floor:.1} ns per body-step.\n\n\
         Threads: two independent one-thread loops, run together, do {:.2}× the work of one \
         alone: the most any two threads gain on this machine (below 2 when the two virtual \
         CPUs share a core or a neighbour is busy).\n\n{}\n",
        machine_line(results),
        results.pool_threads,
        results.bytes_per_body_step,
        results.two_copy_ceiling,
        flops_line(results)
    );
    for integrator in crate::INTEGRATORS.map(|i| i.name()) {
        table(
            &mut s,
            &format!("**{integrator}** — ns per body-step (median)"),
            "| bodies | raw 1t | ECS 1t | ECS/raw | raw 2t | ECS 2t | ECS/raw | 1t/2t | rapier | rapier/ECS 1t | ECS 1t / memory floor |",
            "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
            rows_of(results, integrator),
            |r| {
                let rapier = r.rapier.map_or("–".into(), fmt_ns);
                let vs = r
                    .rapier
                    .map_or("–".into(), |x| format!("{:.1}×", x / r.ecs_1t));
                format!(
                    "| {} | {} | {} | {:.2} | {} | {} | {:.2} | {:.2} | {} | {} | {:.1} |",
                    r.bodies,
                    fmt_ns(r.raw_1t),
                    fmt_ns(r.ecs_1t),
                    r.ecs_1t / r.raw_1t,
                    fmt_ns(r.raw_2t),
                    fmt_ns(r.ecs_2t),
                    r.ecs_2t / r.raw_2t,
                    r.ecs_1t / r.ecs_2t,
                    rapier,
                    vs,
                    r.ecs_1t / floor,
                )
            },
        );
    }
    let u = &results.unused_feature;
    let _ = writeln!(
        s,
        "Unused feature ({}): no `Gravity` {} ns vs `Gravity(0)` {} ns per body-step.\n",
        u.what,
        fmt_ns(u.without),
        fmt_ns(u.with_zero)
    );
    if let Some(c) = &results.runner_check {
        let _ = writeln!(
            s,
            "The runner's check of the world before each step ({}): {} of {} ns per body-step \
             ({:.2} %).\n",
            c.what,
            fmt_ns(c.check),
            fmt_ns(c.step),
            100.0 * c.check / c.step
        );
    }
    let _ = writeln!(s, "{}\n", flops_line(results));
    s.push_str(&springs_markdown(results));
    s.push_str(&methods_markdown(&results.methods));
    s.push_str(&rollback_markdown(&results.rollback));
    s.push_str(&csv_markdown(&results.csv));
    s.push_str(&targets_table(&results.targets));
    s
}

/// Trajectory CSV writing throughput.
pub fn csv_markdown(rows: &[crate::csv::CsvRow]) -> String {
    table_if_any(
        "**trajectory CSV** (`tumble run --out`: `write_trajectory` into a file, every body at \
         every step; formatting and writing timed, the steps between not), median of 3",
        "| bodies | recorded steps | rows | MB | bytes / row | MB/s |",
        "|---:|---:|---:|---:|---:|---:|",
        rows,
        |r| {
            format!(
                "| {} | {} | {} | {:.1} | {:.0} | {:.0} |",
                r.bodies,
                r.recorded_steps,
                r.rows,
                r.bytes as f64 / 1e6,
                r.bytes_per_row,
                r.megabytes_per_second
            )
        },
    )
}

/// Rollback snapshots: size and time next to a step and rapier's snapshot size.
pub fn rollback_markdown(rows: &[crate::rollback::RollbackRow]) -> String {
    table_if_any(
        "**rollback** snapshot of a loaded spring world (chains, gravity, a force at a point and \
         damping on every body), `RollbackSnapshot::capture_into` and `restore`, medians",
        "| bodies | bytes / body | rapier bytes / body | capture | restore | one step | restore + 8 steps |",
        "|---:|---:|---:|---:|---:|---:|---:|",
        rows,
        |r| {
            format!(
                "| {} | {:.0} | ≈ {:.0} (its #991) | {:.0} µs | {:.0} µs | {:.0} µs | {:.1} ms |",
                r.bodies,
                r.bytes_per_body,
                crate::rollback::RAPIER_BYTES_PER_BODY,
                r.capture_us,
                r.restore_us,
                r.step_us,
                (r.restore_us + 8.0 * r.step_us) / 1000.0
            )
        },
    )
}

/// Every integrator's cost against the default, and its ECS layer's cost.
pub fn methods_markdown(rows: &[MethodRow]) -> String {
    let mut s = String::new();
    let mut sizes: Vec<usize> = rows.iter().map(|r| r.bodies).collect();
    sizes.dedup();
    for n in sizes {
        s.push_str(&table_if_any(
            &format!(
                "**Every integrator**, {n} free bodies — ns per body-step through the ECS and the \
                 raw loop, on one thread and on two; `× splitting` is the ECS step on one thread \
                 against `splitting`'s, timed in the same run"
            ),
            "| integrator | raw 1t | ECS 1t | ECS/raw | raw 2t | ECS 2t | ECS/raw | × splitting |",
            "|---|---:|---:|---:|---:|---:|---:|---:|",
            &rows.iter().filter(|r| r.bodies == n).collect::<Vec<_>>(),
            |r| {
                format!(
                    "| `{}` | {} | {} | {:.2} | {} | {} | {:.2} | {:.2} |",
                    r.integrator,
                    fmt_ns(r.raw_1t),
                    fmt_ns(r.ecs_1t),
                    r.ecs_1t / r.raw_1t,
                    fmt_ns(r.raw_2t),
                    fmt_ns(r.ecs_2t),
                    r.ecs_2t / r.raw_2t,
                    r.per_splitting()
                )
            },
        ));
    }
    s
}

/// The spring tables: one chain at each stiffness, then spring throughput (next to the free
/// body's ECS step at the same `N` from `results`' rows, when measured).
pub fn springs_markdown(results: &BenchResults) -> String {
    let springs = &results.springs;
    let mut s = String::new();
    let reference = springs.explicit_reference().unwrap_or(f64::NAN);
    table(
        &mut s,
        "**Spring chain** (ten asymmetric bodies, off-centre anchors, Δt = 1/60; `relaxed`: springs \
         at rest length, the same energy at every stiffness; `stretched`: springs 10 % long, energy \
         ∝ k) — µs per step (median), and relative to the explicit step at ωΔt = 0.5 (relaxed)",
        "| start | spring step | ωΔt | µs/step | × explicit 0.5 | clean |",
        "|---|---|---:|---:|---:|:---:|",
        &springs.stiffness,
        |r| {
            format!(
                "| {} | {} | {} | {:.1} | {:.1} | {} |",
                r.start,
                r.springs,
                r.omega_dt,
                r.us_per_step,
                r.us_per_step / reference,
                if r.clean { "yes" } else { "**no**" }
            )
        },
    );
    let window = format!(
        "every size timed over the same steps of the same motion: {} timings of {} steps after \
         one warm-up step, from the scene's start",
        springs.repetitions, springs.window_steps
    );
    table(
        &mut s,
        &format!(
            "**Spring throughput** (chains of ten, relaxed, with gravity, a force at a body point \
             and damping on every body; one spring per body, so ns per spring-step = ns per \
             body-step; {window}) — median, and relative to a free body's ECS step on one thread \
             at the same N"
        ),
        "| springs | spring step | ωΔt | threads | ns/spring-step | × free body |",
        "|---:|---|---:|---:|---:|---:|",
        &springs.throughput,
        |r| {
            let free = row(results, DEFAULT, r.springs).map(|f| f.ecs_1t);
            format!(
                "| {} | {} | {} | {} | {} | {} |",
                r.springs,
                r.mode,
                r.omega_dt,
                r.threads,
                fmt_ns(r.ns_per_spring_step),
                free.map_or("–".into(), |f| format!(
                    "{:.1}×",
                    r.ns_per_spring_step / f
                ))
            )
        },
    );
    table(
        &mut s,
        &format!(
            "**Stages** (the same loaded chains, explicit springs at ωΔt = 0.5, through the ECS; \
             {window}): substeps and `yoshida4`'s fourth-order composition, ns per body-step \
             (median) and relative to `splitting` in one stage"
        ),
        "| bodies | integrator | substeps | stages | ns/body-step | × one stage |",
        "|---:|---|---:|---:|---:|---:|",
        &springs.stages,
        |r| {
            format!(
                "| {} | `{}` | {} | {} | {} | {:.2} |",
                r.bodies,
                r.integrator,
                r.substeps,
                r.stages,
                fmt_ns(r.ns_per_body_step),
                r.ratio
            )
        },
    );
    s
}

/// The targets as a markdown table.
pub fn targets_table(targets: &[Target]) -> String {
    let mut s = String::from("| target | measured | bound | met |\n|---|---:|---:|:---:|\n");
    for t in targets {
        let _ = writeln!(
            s,
            "| {} | {:.2} | {} {} | {} |",
            t.name,
            t.value,
            t.relation,
            t.bound,
            if t.met { "yes" } else { "**no**" }
        );
    }
    s
}
