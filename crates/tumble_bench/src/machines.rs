//! Every machine's targets side by side.
//!
//! The machines this project is measured on change from session to session (an AVX-512 Xeon
//! one day, an AVX2-only EPYC the next), and a target met on one can be missed on the other.
//! So a run does not overwrite another machine's results: it is named after the widest kernel
//! path of its CPU and the path it ran ([`run_name`]); the bench reads every run kept in the
//! output directory ([`read_runs`], before it measures), puts its own in place of its file's
//! ([`with_run`]) and tabulates their targets, one column per run ([`targets_by_run`]).

use std::path::{Path, PathBuf};

use serde::Deserialize;
use tumble_scene::text::path_for_terminal;

use crate::{BenchResults, Target};

/// The file stem of a run: `bench-<widest>` on the CPU's widest kernel path, and
/// `bench-<widest>-forced-<path>` when `TUMBLE_KERNEL` forced a narrower one. The widest path
/// stands for the machine class, so an AVX2-only CPU and an AVX-512 CPU forced onto AVX2 keep
/// separate files.
pub fn run_name(kernel_path: &str, widest_kernel_path: &str) -> String {
    if kernel_path == widest_kernel_path {
        format!("bench-{widest_kernel_path}")
    } else {
        format!("bench-{widest_kernel_path}-forced-{kernel_path}")
    }
}

/// The file stem of the table of every run's targets (not itself a run).
pub const SUMMARY_NAME: &str = "bench-targets";

/// What the summary needs of a run's JSON (`bench-*.json`, written by
/// [`run_and_write`](crate::run_and_write)).
#[derive(Debug, Clone, Deserialize)]
pub struct RunSummary {
    /// The kernel path that ran.
    pub kernel_path: String,
    /// The widest kernel path of the CPU.
    pub widest_kernel_path: String,
    /// The CPU's name.
    pub cpu: String,
    /// When the run started (RFC 3339).
    pub date: String,
    /// The targets and what the run measured for them.
    pub targets: Vec<Target>,
}

impl From<&BenchResults> for RunSummary {
    /// The summary of a run still in memory (as its JSON would read back).
    fn from(results: &BenchResults) -> Self {
        Self {
            kernel_path: results.kernel_path.clone(),
            widest_kernel_path: results.widest_kernel_path.clone(),
            cpu: results.cpu.clone(),
            date: results.date.clone(),
            targets: results.targets.clone(),
        }
    }
}

impl RunSummary {
    /// The column heading: CPU, kernel path (and whether forced), day.
    fn label(&self) -> String {
        let path = if self.kernel_path == self.widest_kernel_path {
            format!("`{}`", self.kernel_path)
        } else {
            format!("`{}` (forced)", self.kernel_path)
        };
        let day = self.date.get(..10).unwrap_or(&self.date);
        cell_text(&format!("{}, {path}, {day}", self.cpu))
    }
}

/// A kept run that could not be read.
#[derive(Debug, thiserror::Error)]
pub enum SummaryError {
    /// The directory or a file in it could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The path, safe to print.
        path: String,
        /// The error.
        source: std::io::Error,
    },
    /// A `bench-*.json` file is not a run's JSON.
    #[error("{path}: not a bench run's JSON: {source}")]
    Json {
        /// The path, safe to print.
        path: String,
        /// The error.
        source: serde_json::Error,
    },
}

/// Every run kept in `dir` with its file stem: the files `bench-*.json` other than the summary,
/// in the order of their names (so the table's columns do not depend on the directory's order).
pub fn read_runs(dir: &Path) -> Result<Vec<(String, RunSummary)>, SummaryError> {
    let io = |path: &Path| {
        let path = path_for_terminal(path);
        move |source| SummaryError::Io { path, source }
    };
    let mut files: Vec<PathBuf> = Vec::new();
    let entries = match std::fs::read_dir(dir) {
        // A directory still to be made keeps no runs (it is made when the files go in).
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        entries => entries.map_err(io(dir))?,
    };
    for entry in entries {
        let path = entry.map_err(io(dir))?.path();
        let is_run = path.extension().is_some_and(|e| e == "json")
            && path
                .file_stem()
                .and_then(|s| s.to_str())
                .is_some_and(|s| s.starts_with("bench-") && s != SUMMARY_NAME);
        if is_run {
            files.push(path);
        }
    }
    files.sort();
    files
        .iter()
        .map(|path| {
            let text = std::fs::read_to_string(path).map_err(io(path))?;
            let run = serde_json::from_str(&text).map_err(|source| SummaryError::Json {
                path: path_for_terminal(path),
                source,
            })?;
            let stem = path.file_stem().unwrap_or_default().to_string_lossy();
            Ok((stem.into_owned(), run))
        })
        .collect()
}

/// The kept runs with `run` (whose file stem is `name`) in place of its old file's, in the
/// order of their names.
pub fn with_run(
    mut kept: Vec<(String, RunSummary)>,
    name: &str,
    run: RunSummary,
) -> Vec<RunSummary> {
    kept.retain(|(stem, _)| stem != name);
    kept.push((name.to_owned(), run));
    kept.sort_by(|a, b| a.0.cmp(&b.0));
    kept.into_iter().map(|(_, run)| run).collect()
}

/// `text` safe inside a markdown table cell: a `|` would end the cell, a line break the row.
fn cell_text(text: &str) -> String {
    tumble_scene::text::terminal_safe(text).replace('|', "\\|")
}

/// The targets of every run as one markdown table: a row per target of `current` (this
/// version's targets, in its order: a kept run's targets that this version no longer sets are
/// left out), a column per run, each cell the measured value and whether it met the bound (`–`
/// where a run did not measure that target), and a last column counting the runs that met it.
pub fn targets_by_run(runs: &[RunSummary], current: &[Target]) -> String {
    let mut names: Vec<(&str, String)> = Vec::new();
    for target in current {
        if !names.iter().any(|(name, _)| *name == target.name) {
            names.push((
                &target.name,
                format!("{} {}", target.relation, target.bound),
            ));
        }
    }
    let mut s = String::from("| target | bound |");
    for run in runs {
        s.push_str(&format!(" {} |", run.label()));
    }
    s.push_str(" met by |\n|---|---:|");
    s.push_str(&"---:|".repeat(runs.len()));
    s.push_str(":---:|\n");
    for (name, bound) in &names {
        s.push_str(&format!("| {} | {} |", cell_text(name), cell_text(bound)));
        let mut met = 0;
        let mut measured = 0;
        for run in runs {
            match run.targets.iter().find(|t| t.name == *name) {
                Some(t) => {
                    measured += 1;
                    met += usize::from(t.met);
                    let verdict = if t.met { "yes" } else { "**no**" };
                    s.push_str(&format!(" {:.2} {verdict} |", t.value));
                }
                None => s.push_str(" – |"),
            }
        }
        s.push_str(&format!(" {met} of {measured} |\n"));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn target(name: &str, value: f64, met: bool) -> Target {
        Target {
            name: name.into(),
            value,
            bound: 3.0,
            relation: "<=".into(),
            met,
        }
    }

    fn run(path: &str, widest: &str, targets: Vec<Target>) -> RunSummary {
        RunSummary {
            kernel_path: path.into(),
            widest_kernel_path: widest.into(),
            cpu: "AMD | EPYC".into(),
            date: "2026-12-03T23:40:13Z".into(),
            targets,
        }
    }

    #[test]
    fn names_keep_each_machine_and_forced_path_apart() {
        assert_eq!(run_name("avx512", "avx512"), "bench-avx512");
        assert_eq!(run_name("avx2", "avx2"), "bench-avx2");
        assert_eq!(run_name("avx2", "avx512"), "bench-avx512-forced-avx2");
        assert_ne!(run_name("avx2", "avx2"), run_name("avx2", "avx512"));
    }

    #[test]
    fn the_table_marks_each_run_and_counts_who_met_a_target() {
        let runs = [
            run(
                "avx512",
                "avx512",
                vec![target("floor", 2.5, true), target("ratio", 9.0, false)],
            ),
            run("avx2", "avx2", vec![target("floor", 4.0, false)]),
        ];
        // The current version's targets are the rows: a target only an old run has is left out.
        let current = [target("floor", 0.0, true), target("ratio", 0.0, true)];
        let mut with_old = runs.clone();
        with_old[1].targets.push(target("retired", 1.0, true));
        let table = targets_by_run(&with_old, &current);
        assert!(!table.contains("retired"), "{table}");
        let lines: Vec<&str> = table.lines().collect();
        assert_eq!(lines.len(), 4, "{table}");
        assert!(
            lines[0].contains("AMD \\| EPYC, `avx512`, 2026-12-03"),
            "{table}"
        );
        assert_eq!(
            lines[2],
            "| floor | <= 3 | 2.50 yes | 4.00 **no** | 1 of 2 |"
        );
        assert_eq!(lines[3], "| ratio | <= 3 | 9.00 **no** | – | 0 of 1 |");
        // One column per run, the same count of cells in every row.
        let cells = |l: &str| l.matches('|').count() - l.matches("\\|").count();
        assert!(lines.iter().all(|l| cells(l) == cells(lines[0])), "{table}");
    }

    #[test]
    fn runs_are_read_in_name_order_and_a_bad_file_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let json = |r: &RunSummary| {
            serde_json::json!({
                "kernel_path": r.kernel_path, "widest_kernel_path": r.widest_kernel_path,
                "cpu": r.cpu, "date": r.date, "targets": r.targets, "rows": [],
            })
            .to_string()
        };
        let write = |name: &str, text: &str| std::fs::write(dir.path().join(name), text).unwrap();
        write("bench-avx512.json", &json(&run("avx512", "avx512", vec![])));
        write(
            "bench-avx2.json",
            &json(&run("avx2", "avx2", vec![target("t", 1.0, true)])),
        );
        write("bench-targets.json", "not a run");
        write("other.json", "not a run either");
        let runs = read_runs(dir.path()).unwrap();
        let stems: Vec<&str> = runs.iter().map(|(stem, _)| stem.as_str()).collect();
        assert_eq!(stems, ["bench-avx2", "bench-avx512"]);
        let runs = with_run(runs, "bench-avx2", run("avx2", "avx2", vec![]));
        let paths: Vec<&str> = runs.iter().map(|r| r.kernel_path.as_str()).collect();
        assert_eq!(paths, ["avx2", "avx512"]);
        assert!(
            runs[0].targets.is_empty(),
            "the new run replaces the kept one"
        );
        let runs = with_run(Vec::new(), "bench-a", run("a", "a", vec![]));
        assert_eq!(runs.len(), 1);
        write("bench-broken.json", "{");
        let error = read_runs(dir.path()).unwrap_err().to_string();
        assert!(
            error.contains("bench-broken.json: not a bench run's JSON"),
            "{error}"
        );
    }
}
