//! # tumble_bench
//!
//! `tumble bench`: ns per body-step of tumble through its ECS schedule, of a raw loop over plain
//! arrays calling the same `tumble_core` entry point, and of rapier 0.36 on the same bodies, for
//! N = 1 … 10⁶, on one and two threads, with the machine's memory bandwidth measured in the same
//! run. Results as a table, JSON and a README section; ratios, because the machines are shared
//! and noisy.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod bandwidth;
pub mod budget;
pub mod csv;
pub mod engines;
pub mod machines;
pub mod measure;
pub mod methods;
pub mod output;
pub mod population;
pub mod rollback;
pub mod scaling;
pub mod springs;
pub mod targets;

use std::path::PathBuf;
use tumble_core::math::Vec3;

use serde::{Deserialize, Serialize};
use tumble_core::{Integrator, KernelPath};
use tumble_ecs::parallel::{Parallelism, pool_threads};
use tumble_scene::output::{OutputSet, print_to_stdout, with_sections};

use crate::engines::{Ecs, Engine, Rapier, RawLoop, RunnerCheck};
use crate::machines::RunSummary;
use crate::measure::{Effort, compare};

/// What to measure and where to write it (the arguments of `tumble bench` and `tumble-bench`).
#[derive(Debug, Clone, clap::Args)]
pub struct BenchOptions {
    /// Smaller worlds (up to 10⁴ bodies) and shorter timings: a smoke run of a few seconds.
    #[arg(long)]
    pub quick: bool,
    /// Largest world for tumble (default 10⁶, 10⁴ with --quick; at least 1).
    #[arg(long, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..))]
    pub max_bodies: Option<usize>,
    /// Largest world for rapier (default 10⁵: a million rapier bodies take gigabytes and
    /// minutes).
    #[arg(long, default_value_t = 100_000)]
    pub rapier_max_bodies: usize,
    /// Write this run's `<name>.json` and `<name>.md` into this directory, and
    /// `bench-targets.md`, the targets of every run kept there (`<name>` is `bench-<widest>`
    /// on the CPU's widest kernel path, `bench-<widest>-forced-<path>` when `TUMBLE_KERNEL`
    /// forced another).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Also replace the frame budget in this markdown file (between
    /// `<!-- frame-budget:begin -->` and `<!-- frame-budget:end -->`): bodies per 60 Hz frame
    /// from this run, e.g. `README.md`.
    #[arg(long)]
    pub readme: Option<PathBuf>,
}

/// One world size and integrator: median ns per body-step of each engine.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// Integrator name.
    pub integrator: String,
    /// Number of bodies.
    pub bodies: usize,
    /// Steps per timing.
    pub steps: usize,
    /// Raw loop over plain arrays, one thread.
    pub raw_1t: f64,
    /// Raw loop, split over the pool as the ECS splits (same threading policy).
    pub raw_2t: f64,
    /// tumble's ECS schedule, one thread.
    pub ecs_1t: f64,
    /// tumble's ECS schedule with the default threading policy.
    pub ecs_2t: f64,
    /// rapier 0.36 (single-threaded build), if measured at this size.
    pub rapier: Option<f64>,
}

/// The cost of a feature a scene does not use.
#[derive(Debug, Clone, Serialize)]
pub struct UnusedFeature {
    /// What is compared.
    pub what: String,
    /// ns per body-step without the feature (no `Gravity` resource).
    pub without: f64,
    /// ns per body-step with the feature present but doing nothing (`Gravity(0)`).
    pub with_zero: f64,
}

/// What the runner's check of the world before each step costs against the whole step (the
/// check that keeps a stale plan from ever running).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RunnerCheckCost {
    /// What is compared.
    pub what: String,
    /// Bodies in the world.
    pub bodies: usize,
    /// ns per body-step of the check alone.
    pub check: f64,
    /// ns per body-step of the whole step (check included).
    pub step: f64,
}

/// A speed target of the project and whether this run met it.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Target {
    /// What is measured.
    pub name: String,
    /// The measured value.
    pub value: f64,
    /// The bound.
    pub bound: f64,
    /// `"<="` or `">="`.
    pub relation: String,
    /// Whether the value meets the bound.
    pub met: bool,
}

/// Everything one run measured.
#[derive(Debug, Clone, Serialize)]
pub struct BenchResults {
    /// JSON schema version.
    pub schema: u32,
    /// Threads of the compute pool.
    pub pool_threads: usize,
    /// The SIMD kernel path that ran (`avx512`, `avx2`, `portable`; `TUMBLE_KERNEL` forces one).
    pub kernel_path: String,
    /// The widest kernel path this CPU runs: a run on another one was forced.
    pub widest_kernel_path: String,
    /// The CPU, as the operating system names it (`model name` of `/proc/cpuinfo`).
    pub cpu: String,
    /// When the run started (UTC, RFC 3339, to the second).
    pub date: String,
    /// Copy bandwidth (read + write), GB/s, one thread and all pool threads.
    pub bandwidth_gb_s: [f64; 2],
    /// What two independent one-thread raw loops, each over half of the 2-thread target's
    /// bodies, run together gain over one alone: `2 t_alone / t_together`, the most any two
    /// threads can gain on this machine ([`scaling`]).
    pub two_copy_ceiling: f64,
    /// Floating-point operations of the default integrator's free rotation per body-step.
    pub kernel_flops: KernelFlops,
    /// Bytes a body-step must move through memory in the ECS (read + write), for the floor.
    pub bytes_per_body_step: usize,
    /// All rows.
    pub rows: Vec<Row>,
    /// The cost of an unused feature.
    pub unused_feature: UnusedFeature,
    /// The runner's check of the world against the whole step (absent in runs from before it
    /// was measured).
    #[serde(default)]
    pub runner_check: Option<RunnerCheckCost>,
    /// Spring chains: the cost of stiffness and spring throughput.
    pub springs: springs::SpringResults,
    /// Every integrator against the default, ECS, one thread.
    pub methods: Vec<methods::MethodRow>,
    /// Rollback snapshots: bytes per body, capture and restore time.
    pub rollback: Vec<rollback::RollbackRow>,
    /// Trajectory CSV writing throughput.
    pub csv: Vec<csv::CsvRow>,
    /// Whether this was a `--quick` run.
    pub quick: bool,
    /// The run's wall-clock time (s), the measurements alone.
    pub seconds: f64,
    /// The speed issue's targets ([`targets::TARGETS`]) as this run measured them.
    pub targets: Vec<Target>,
}

/// The floating-point operations of one body's free rotation under the default integrator,
/// counted by running its lane kernel on a lane type that counts
/// ([`tumble_core::integrate::symmetric_rotation_flops`]); the SIMD paths run them four or
/// eight bodies per instruction.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct KernelFlops {
    /// Additions and subtractions.
    pub add: u64,
    /// Multiplications.
    pub mul: u64,
    /// Divisions.
    pub div: u64,
    /// Square roots.
    pub sqrt: u64,
    /// All of them.
    pub total: u64,
}

impl KernelFlops {
    /// The count of the torque-free step's free rotation (what the free-body rows run).
    pub fn counted() -> Self {
        let c = tumble_core::integrate::symmetric_rotation_flops(false);
        Self {
            add: c.add,
            mul: c.mul,
            div: c.div,
            sqrt: c.sqrt,
            total: c.total(),
        }
    }
}

/// The two integrators measured: the default and the textbook step.
pub const INTEGRATORS: [Integrator; 2] = [Integrator::Splitting, Integrator::SymplecticEuler];

/// Bytes moved per ECS body-step: `Pose` and `Velocity` read and written, `MassProps`
/// read, one changed-tick written per mutated component.
pub fn bytes_per_body_step() -> usize {
    use tumble_ecs::components::{MassProps, Pose, Velocity};
    let state = size_of::<Pose>() + size_of::<Velocity>();
    2 * state + size_of::<MassProps>() + 2 * size_of::<u32>()
}

/// Runs the benchmark; `progress` receives one line per measurement.
pub fn run_bench(options: &BenchOptions, mut progress: impl FnMut(&str)) -> BenchResults {
    let started = std::time::SystemTime::now();
    let max = options
        .max_bodies
        .unwrap_or(if options.quick { 10_000 } else { 1_000_000 });
    let sizes: Vec<usize> = [1, 10, 100, 1_000, 10_000, 100_000, 1_000_000]
        .into_iter()
        .filter(|&n| n <= max)
        .collect();
    let effort = if options.quick {
        Effort {
            body_steps: 100_000,
            min_steps: 2,
            max_steps: 10_000,
            repetitions: 3,
        }
    } else {
        // Nine interleaved timings: on a shared 2-vCPU machine a busy neighbour comes in
        // bursts of seconds, which spoil up to four of them without moving the median.
        Effort {
            body_steps: 1_000_000,
            min_steps: 3,
            max_steps: 20_000,
            repetitions: 9,
        }
    };
    progress("memory bandwidth");
    let bandwidth = [
        bandwidth::copy_bandwidth(1, 3),
        bandwidth::copy_bandwidth(pool_threads().max(1), 3),
    ];
    // The 2-thread target is at 1e5 bodies: each thread steps half of them.
    let half = max.min(100_000) / 2;
    progress(&format!(
        "two independent one-thread loops of {half} bodies"
    ));
    let two_copy_ceiling = scaling::two_copy_ceiling(half, effort.steps(half), effort.repetitions);
    let rows = free_body_rows(&sizes, options.rapier_max_bodies, &effort, &mut progress);
    progress("unused feature: no gravity vs zero gravity");
    let unused_feature = unused_gravity(sizes.last().copied().unwrap_or(1).min(10_000), &effort);
    let check_bodies = max.min(100_000);
    progress(&format!(
        "the runner's check of a world of {check_bodies} bodies"
    ));
    let runner_check = Some(runner_check(check_bodies, &effort));
    let springs = springs::run(options.quick, &mut progress);
    let method_sizes: Vec<usize> = if options.quick {
        vec![max.min(1_000)]
    } else {
        [1_000, 100_000].into_iter().filter(|&n| n <= max).collect()
    };
    let methods = methods::run(&method_sizes, &effort, &mut progress);
    let rollback_sizes: &[usize] = if options.quick {
        &[1_000]
    } else {
        &[10_000, 100_000]
    };
    let rollback = rollback::run(
        rollback_sizes,
        if options.quick { 3 } else { 21 },
        &mut progress,
    );
    let csv_bodies = if options.quick { 10_000 } else { 100_000 };
    progress(&format!("trajectory CSV of {csv_bodies} bodies"));
    let csv = csv::measure(csv_bodies, 10, 3, options.out.as_deref())
        .map_err(|e| eprintln!("the CSV measurement failed: {e}"))
        .into_iter()
        .collect();
    let mut results = BenchResults {
        schema: 5,
        pool_threads: pool_threads(),
        kernel_path: tumble_core::kernel_path().to_string(),
        widest_kernel_path: widest_kernel_path(),
        cpu: cpu_name(),
        date: humantime::format_rfc3339_seconds(started).to_string(),
        bandwidth_gb_s: bandwidth,
        two_copy_ceiling,
        kernel_flops: KernelFlops::counted(),
        bytes_per_body_step: bytes_per_body_step(),
        rows,
        unused_feature,
        runner_check,
        springs,
        methods,
        rollback,
        csv,
        quick: options.quick,
        seconds: started.elapsed().map_or(f64::NAN, |d| d.as_secs_f64()),
        targets: Vec::new(),
    };
    results.targets = targets::evaluate(&results);
    results
}

/// The free-body rows: every size of `sizes` and integrator of the bench, stepped by the raw
/// loop and the ECS on one and two threads, and by rapier up to `rapier_max_bodies` bodies.
fn free_body_rows(
    sizes: &[usize],
    rapier_max_bodies: usize,
    effort: &Effort,
    progress: &mut impl FnMut(&str),
) -> Vec<Row> {
    let threaded = Parallelism::default();
    let single = Parallelism::SINGLE_THREAD;
    let mut rows = Vec::new();
    for &n in sizes {
        let scene = population::scene(n);
        let mut rapier = (n <= rapier_max_bodies).then(|| Rapier::new(&scene));
        for (k, &integrator) in INTEGRATORS.iter().enumerate() {
            progress(&format!("{n} bodies · {integrator}"));
            let mut raw1 = RawLoop::new(&scene, integrator, single);
            let mut raw2 = RawLoop::new(&scene, integrator, threaded);
            let mut ecs1 = Ecs::new(&scene, integrator, single);
            let mut ecs2 = Ecs::new(&scene, integrator, threaded);
            let mut engines: Vec<&mut dyn Engine> =
                vec![&mut raw1, &mut raw2, &mut ecs1, &mut ecs2];
            // rapier does not depend on tumble's integrator: timed once per size.
            let with_rapier = k == 0 && rapier.is_some();
            if with_rapier && let Some(r) = rapier.as_mut() {
                engines.push(r);
            }
            let ns = compare(&mut engines, n, effort);
            check_moved(&raw1, &ecs1, &scene);
            rows.push(Row {
                integrator: integrator.name().to_owned(),
                bodies: n,
                steps: effort.steps(n),
                raw_1t: ns[0],
                raw_2t: ns[1],
                ecs_1t: ns[2],
                ecs_2t: ns[3],
                rapier: if with_rapier {
                    Some(ns[4])
                } else {
                    rows.iter()
                        .rev()
                        .find(|r: &&Row| r.bodies == n)
                        .and_then(|r| r.rapier)
                },
            });
        }
    }
    rows
}

/// The CPU's model name from `/proc/cpuinfo` (Linux), or `unknown CPU`.
fn cpu_name() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|info| {
            info.lines()
                .find_map(|l| l.strip_prefix("model name")?.split_once(':'))
                .map(|(_, name)| name.trim().to_owned())
        })
        .unwrap_or_else(|| "unknown CPU".to_owned())
}

/// Both the raw loop and the ECS really moved the bodies, to the same place bit for bit (the
/// same core function on the same data, the same number of steps).
pub(crate) fn check_moved(raw: &RawLoop, ecs: &Ecs, scene: &tumble_rapier::ComparisonScene) {
    let last = scene.bodies.len() - 1;
    for i in [0, last / 2, last] {
        let (a, b) = (raw.state(i), ecs.state(i));
        assert!(a.position != scene.bodies[i].state.position, "bodies moved");
        assert!(a.is_finite(), "benchmark stays finite");
        assert_eq!(a, b, "raw loop and ECS agree bit for bit");
    }
}

/// ECS without a `Gravity` resource against the same world with `Gravity(0)`.
fn unused_gravity(n: usize, effort: &Effort) -> UnusedFeature {
    let mut scene = population::scene(n);
    scene.gravity = None;
    let mut without = Ecs::new(&scene, Integrator::default(), Parallelism::SINGLE_THREAD);
    scene.gravity = Some(Vec3::ZERO);
    let mut with_zero = Ecs::new(&scene, Integrator::default(), Parallelism::SINGLE_THREAD);
    let ns = compare(&mut [&mut without, &mut with_zero], n, effort);
    UnusedFeature {
        what: format!("{n} free bodies, default integrator, one thread"),
        without: ns[0],
        with_zero: ns[1],
    }
}

/// The runner's check before a step against the whole step, default integrator, one thread.
fn runner_check(n: usize, effort: &Effort) -> RunnerCheckCost {
    let scene = population::scene(n);
    let mut check = RunnerCheck::new(&scene, Integrator::default());
    let mut step = Ecs::new(&scene, Integrator::default(), Parallelism::SINGLE_THREAD);
    let ns = compare(&mut [&mut check, &mut step], n, effort);
    RunnerCheckCost {
        what: format!("{n} free bodies, default integrator, one thread"),
        bodies: n,
        check: ns[0],
        step: ns[1],
    }
}

/// Runs the benchmark, prints the table, and writes the files the options ask for.
///
/// Every destination is checked before the measurements (an output directory that is a file or
/// takes no new file, a run kept there that cannot be read, a README without this run's
/// markers: each an error naming it). The files are written as one
/// [`OutputSet`]: all of them, the README too, are written
/// before any old one is replaced.
pub fn run_and_write(options: &BenchOptions) -> Result<(), Box<dyn std::error::Error>> {
    // Each machine class and forced path keeps its own files and README section, so a run on
    // one machine never overwrites another's; the targets of all of them are tabulated after.
    let name = machines::run_name(
        &tumble_core::kernel_path().to_string(),
        &widest_kernel_path(),
    );
    let kept_runs = match &options.out {
        Some(dir) => {
            for file in [format!("{name}.md"), format!("{name}.json")] {
                OutputSet::check(&dir.join(file))?;
            }
            OutputSet::check(&dir.join(format!("{}.md", machines::SUMMARY_NAME)))?;
            machines::read_runs(dir)?
        }
        None => Vec::new(),
    };
    if let Some(readme) = &options.readme {
        with_sections(readme, &[(budget::SECTION, "")])?;
        OutputSet::check(readme)?;
    }
    let results = run_bench(options, |line| eprintln!("… {line}"));
    let table = output::markdown(&results);
    let mut files = OutputSet::new();
    if let Some(dir) = &options.out {
        files.add(&dir.join(format!("{name}.md")), table.as_bytes())?;
        files.add(
            &dir.join(format!("{name}.json")),
            (serde_json::to_string_pretty(&results)? + "\n").as_bytes(),
        )?;
        let runs = machines::with_run(kept_runs, &name, RunSummary::from(&results));
        let summary_file = dir.join(format!("{}.md", machines::SUMMARY_NAME));
        files.add(
            &summary_file,
            machines::targets_by_run(&runs, &results.targets).as_bytes(),
        )?;
    }
    if let Some(readme) = &options.readme {
        // The README gets the frame budget; the full tables and the targets stay in `--out`.
        let section = budget::frame_budget(&results);
        files.add(
            readme,
            with_sections(readme, &[(budget::SECTION, &section)])?.as_bytes(),
        )?;
    }
    files.commit()?;
    print_to_stdout(&format!("{table}\n"))?;
    Ok(())
}

/// The widest kernel path this CPU has (what a run names itself by).
fn widest_kernel_path() -> String {
    KernelPath::available()
        .last()
        .map_or("portable".to_owned(), |p| p.to_string())
}
