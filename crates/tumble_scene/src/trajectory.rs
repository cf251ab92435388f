//! Trajectory recording as CSV.

use std::borrow::Cow;
use std::io::Write;
use std::num::NonZeroU64;
use std::ops::ControlFlow;
use tumble_core::math::{Real, to_f64};

use bevy_ecs::prelude::*;
use thiserror::Error;
use tumble_ecs::prelude::*;

use crate::build::BuiltScene;

/// The CSV header, exactly: one row per body per recorded step, `step` and `time` (s), the body
/// name (see [`csv_text_cell`]), position `px..pz`, rotation `qx..qw` (glam order), linear
/// velocity `vx..vz` and world-frame angular velocity `wx..wz`. A body quarantined with
/// [`Rejected`] has no rows from the step it was rejected on: its state is the last valid one,
/// not that step's.
pub const CSV_HEADER: &str = "step,time,body,px,py,pz,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz";

/// Why [`write_trajectory`] did not write the whole trajectory.
#[derive(Debug, Error)]
pub enum TrajectoryError {
    /// Writing failed (disk full, closed pipe, …).
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// The per-step callback asked to stop after this step (e.g. on Ctrl-C).
    #[error("stopped after step {step}")]
    Stopped {
        /// The last step that was run.
        step: u64,
    },
    /// The world has no [`PhysicsSettings`] resource, so there is no time step to label rows
    /// with (a [`BuiltScene`] from [`Scene::build`](crate::Scene::build) always has one).
    #[error("the world has no PhysicsSettings resource (no time step)")]
    NoSettings,
    /// [`Recording::bodies`] names a body the scene does not have.
    #[error("recording body index {index}, but the scene has {bodies} bodies (0..{bodies})")]
    NoSuchBody {
        /// The index asked for.
        index: usize,
        /// How many bodies the scene has.
        bodies: usize,
    },
    /// [`Recording::bodies`] names a body twice (its rows would be written twice).
    #[error("recording body index {0} twice")]
    DuplicateBody(usize),
}

/// Which rows a trajectory holds: every `every`-th step (step 0 always), and all bodies or
/// only some.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Recording {
    /// Record step 0 and every step that is a multiple of this.
    pub every: NonZeroU64,
    /// Indices into [`BuiltScene::bodies`] of the bodies to record, in the order their rows
    /// are written; `None` records every body in file order.
    pub bodies: Option<Vec<usize>>,
}

impl Recording {
    /// Every body, every `every`-th step.
    pub fn every(every: NonZeroU64) -> Self {
        Self {
            every,
            bodies: None,
        }
    }
}

/// What [`write_trajectory`] wrote, and how fast.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrajectoryStats {
    /// Rows written, header excluded.
    pub rows: u64,
    /// Bytes written, header included.
    pub bytes: u64,
    /// Seconds spent formatting and writing rows (the steps between them excluded).
    pub write_seconds: f64,
}

impl TrajectoryStats {
    /// Writing throughput in MB/s (10⁶ bytes per second).
    pub fn megabytes_per_second(&self) -> f64 {
        self.bytes as f64 / 1e6 / self.write_seconds.max(f64::MIN_POSITIVE)
    }
}

/// Runs `steps` steps of a built scene and writes its trajectory as CSV to `out`: the
/// [`CSV_HEADER`] line, then one row per recorded body for step 0 and for every
/// `record.every`-th step.
///
/// - `px..pz` is `Pose::translation`, `q*` the rotation (glam order), `v*` the linear and
///   `w*` the world-frame angular velocity; `time` is `step × dt`, with `dt` read from the
///   world's [`PhysicsSettings`] when the call starts (so it cannot disagree with the step the
///   schedule takes, nor be NaN).
/// - A body that carries [`Rejected`] when a step is recorded gets no row for that step: its
///   state is the last valid one, not the state of that step. Its rows stop from the first
///   recorded step at or after the step it was rejected on (and resume if game code lifts the
///   quarantine by inserting valid data).
/// - Body names are written so that a spreadsheet reads them as text (OWASP's rule for CSV
///   injection): a name beginning with `=`, `+`, `-`, `@`, a tab or a carriage return gets a
///   leading `'`; a name holding `,`, `"`, a line feed or a carriage return is quoted as in
///   RFC 4180. Scene files reject such names anyway; library users may name bodies freely.
///
/// `on_step(step, world)` is called after each step (1 ..= `steps`) has been run and its rows
/// written: report progress or read the world there (e.g. new
/// [`PhysicsErrors`](tumble_ecs::components::PhysicsErrors)), and return [`ControlFlow::Break`] to stop (the result is then
/// [`TrajectoryError::Stopped`]). `out` is buffered here; pass it unbuffered. Rows already
/// written stay in `out` on error: write to a temporary file and rename it only on success
/// (see [`crate::output::OutputFile`]).
pub fn write_trajectory(
    scene: &mut BuiltScene,
    steps: u64,
    record: &Recording,
    out: impl Write,
    mut on_step: impl FnMut(u64, &World) -> ControlFlow<()>,
) -> Result<TrajectoryStats, TrajectoryError> {
    let dt = scene
        .world
        .get_resource::<PhysicsSettings>()
        .ok_or(TrajectoryError::NoSettings)?
        .dt();
    let every = record.every.get();
    // The recorded bodies with their name cells, computed once: a run writes them millions
    // of times.
    let recorded: Vec<(Entity, String)> = match &record.bodies {
        None => scene
            .bodies
            .iter()
            .map(|(name, e)| (*e, csv_text_cell(name).into_owned()))
            .collect(),
        Some(indices) => {
            let mut seen = vec![false; scene.bodies.len()];
            let mut recorded = Vec::with_capacity(indices.len());
            for &index in indices {
                let Some((name, e)) = scene.bodies.get(index) else {
                    return Err(TrajectoryError::NoSuchBody {
                        index,
                        bodies: scene.bodies.len(),
                    });
                };
                if std::mem::replace(&mut seen[index], true) {
                    return Err(TrajectoryError::DuplicateBody(index));
                }
                recorded.push((*e, csv_text_cell(name).into_owned()));
            }
            recorded
        }
    };
    let mut stats = TrajectoryStats {
        rows: 0,
        bytes: 0,
        write_seconds: 0.0,
    };
    let mut w = Counted {
        inner: std::io::BufWriter::with_capacity(1 << 16, out),
        bytes: 0,
    };
    let mut write = |w: &mut Counted<_>, scene: &BuiltScene, step: u64| {
        let start = std::time::Instant::now();
        stats.rows += write_rows(w, &scene.world, &recorded, step, dt)?;
        stats.write_seconds += start.elapsed().as_secs_f64();
        std::io::Result::Ok(())
    };
    writeln!(w, "{CSV_HEADER}")?;
    write(&mut w, scene, 0)?;
    for step in 1..=steps {
        scene.step();
        if step.is_multiple_of(every) {
            write(&mut w, scene, step)?;
        }
        if on_step(step, &scene.world).is_break() {
            w.flush()?;
            return Err(TrajectoryError::Stopped { step });
        }
    }
    let start = std::time::Instant::now();
    w.flush()?;
    stats.write_seconds += start.elapsed().as_secs_f64();
    stats.bytes = w.bytes;
    Ok(stats)
}

/// A writer that counts the bytes it passes on.
struct Counted<W> {
    inner: W,
    bytes: u64,
}

impl<W: Write> Write for Counted<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.bytes += n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

/// `text` as a CSV cell that a spreadsheet shows as text: a leading `'` before a formula
/// trigger (`=`, `+`, `-`, `@`, tab, carriage return), and RFC 4180 quotes around a cell that
/// holds a separator, a quote or a line break.
pub fn csv_text_cell(text: &str) -> Cow<'_, str> {
    let formula = text.starts_with(['=', '+', '-', '@', '\t', '\r']);
    let quoted = text.contains([',', '"', '\n', '\r']);
    if !formula && !quoted {
        return Cow::Borrowed(text);
    }
    let mut cell = String::with_capacity(text.len() + 3);
    if quoted {
        cell.push('"');
    }
    if formula {
        cell.push('\'');
    }
    if quoted {
        cell.push_str(&text.replace('"', "\"\""));
        cell.push('"');
    } else {
        cell.push_str(text);
    }
    Cow::Owned(cell)
}

/// Writes one row per recorded body that is not quarantined; returns how many.
fn write_rows(
    w: &mut impl Write,
    world: &World,
    recorded: &[(Entity, String)],
    step: u64,
    dt: Real,
) -> std::io::Result<u64> {
    let time = to_f64(dt) * step as f64;
    let mut rows = 0;
    for (e, name) in recorded {
        let Ok(body) = world.get_entity(*e) else {
            continue;
        };
        if body.contains::<Rejected>() {
            continue;
        }
        let (Some(t), Some(v)) = (body.get::<Pose>(), body.get::<Velocity>()) else {
            continue;
        };
        let q = t.rotation;
        writeln!(
            w,
            "{step},{time},{name},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            t.translation.x,
            t.translation.y,
            t.translation.z,
            q.x,
            q.y,
            q.z,
            q.w,
            v.linear.x,
            v.linear.y,
            v.linear.z,
            v.angular.x,
            v.angular.y,
            v.angular.z
        )?;
        rows += 1;
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Scene;
    use tumble_ecs::components::{BodyError, BodyErrorKind};

    fn chain() -> BuiltScene {
        let text = include_str!("../../../scenes/spring_chain.toml");
        Scene::parse("spring_chain.toml", text).unwrap().build()
    }

    fn write(built: &mut BuiltScene, steps: u64, every: u64) -> String {
        let mut out = Vec::new();
        write_trajectory(
            built,
            steps,
            &Recording::every(NonZeroU64::new(every).unwrap()),
            &mut out,
            |_, _| ControlFlow::Continue(()),
        )
        .unwrap();
        String::from_utf8(out).unwrap()
    }

    #[test]
    fn time_comes_from_the_worlds_settings_and_rows_follow_every() {
        let mut built = chain();
        built
            .world
            .resource_mut::<PhysicsSettings>()
            // 2⁻⁶ s: exact in binary, and inside the chain's stable region (at 0.125 s its
            // springs diverge and the audit quarantines the bodies, whose rows then stop).
            .set_dt(0.015625)
            .unwrap();
        let csv = write(&mut built, 6, 3);
        let rows: Vec<Vec<&str>> = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').collect())
            .collect();
        assert_eq!(csv.lines().next(), Some(CSV_HEADER));
        assert_eq!(rows.len(), 3 * 3);
        assert_eq!((rows[8][0], rows[8][1], rows[8][2]), ("6", "0.09375", "m3"));
        built.world.remove_resource::<PhysicsSettings>();
        let all = Recording::every(NonZeroU64::MIN);
        let err = write_trajectory(&mut built, 1, &all, std::io::sink(), |_, _| {
            ControlFlow::Continue(())
        })
        .unwrap_err();
        assert!(matches!(err, TrajectoryError::NoSettings), "{err}");
    }

    /// An index past the end or named twice is an error before anything is written (it was
    /// a header-only file, or duplicate rows).
    #[test]
    fn a_selection_of_missing_or_repeated_bodies_is_refused() {
        for (bodies, expected) in [
            (
                vec![0, 3],
                TrajectoryError::NoSuchBody {
                    index: 3,
                    bodies: 3,
                },
            ),
            (vec![1, 0, 1], TrajectoryError::DuplicateBody(1)),
        ] {
            let mut built = chain();
            let mut out = Vec::new();
            let record = Recording {
                every: NonZeroU64::MIN,
                bodies: Some(bodies),
            };
            let err = write_trajectory(&mut built, 2, &record, &mut out, |_, _| {
                ControlFlow::Continue(())
            })
            .unwrap_err();
            assert_eq!(err.to_string(), expected.to_string());
            assert!(out.is_empty(), "nothing written: {out:?}");
        }
    }

    #[test]
    fn a_selection_records_only_its_bodies_and_the_stats_count_what_was_written() {
        let mut built = chain();
        let mut out = Vec::new();
        let record = Recording {
            every: NonZeroU64::new(2).unwrap(),
            bodies: Some(vec![2, 0]),
        };
        let stats = write_trajectory(&mut built, 5, &record, &mut out, |_, _| {
            ControlFlow::Continue(())
        })
        .unwrap();
        let csv = String::from_utf8(out).unwrap();
        let rows: Vec<(&str, &str)> = csv
            .lines()
            .skip(1)
            .map(|l| {
                let cells: Vec<&str> = l.split(',').collect();
                (cells[0], cells[2])
            })
            .collect();
        assert_eq!(
            rows,
            [
                ("0", "m3"),
                ("0", "m1"),
                ("2", "m3"),
                ("2", "m1"),
                ("4", "m3"),
                ("4", "m1")
            ]
        );
        assert_eq!(stats.rows, 6);
        assert_eq!(stats.bytes, csv.len() as u64);
        assert!(stats.write_seconds > 0.0 && stats.megabytes_per_second().is_finite());
    }

    #[test]
    fn the_callback_sees_every_step_and_can_stop_the_run() {
        let mut built = chain();
        let mut seen = Vec::new();
        let err = write_trajectory(
            &mut built,
            10,
            &Recording::every(NonZeroU64::MIN),
            std::io::sink(),
            |step, _| {
                seen.push(step);
                if step == 3 {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            },
        )
        .unwrap_err();
        assert!(matches!(err, TrajectoryError::Stopped { step: 3 }), "{err}");
        assert_eq!(seen, [1, 2, 3]);
    }

    #[test]
    fn rejected_bodies_get_no_rows_and_names_are_neutralised() {
        let mut built = chain();
        let m2 = built.bodies[1].1;
        built.world.entity_mut(m2).insert(Rejected(BodyError {
            entity: m2,
            kind: BodyErrorKind::Restored("test".into()),
        }));
        built.bodies[0].0 = "=HYPERLINK(\"x\")".into();
        let csv = write(&mut built, 2, 1);
        let names: Vec<&str> = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(2).unwrap())
            .collect();
        assert_eq!(names.len(), 2 * 3, "{csv}");
        assert!(!names.contains(&"m2"), "{csv}");
        assert!(csv.contains(",\"'=HYPERLINK(\"\"x\"\")\","), "{csv}");
    }

    #[test]
    fn formula_triggers_get_a_leading_quote_and_separators_are_quoted() {
        for (name, cell) in [
            ("plain", "plain"),
            ("=1+2", "'=1+2"),
            ("+x", "'+x"),
            ("-x", "'-x"),
            ("@SUM(A1)", "'@SUM(A1)"),
            ("\tx", "'\tx"),
            ("a,b", "\"a,b\""),
            ("say \"hi\"", "\"say \"\"hi\"\"\""),
            ("\ra", "\"'\ra\""),
            ("x=1", "x=1"),
        ] {
            assert_eq!(csv_text_cell(name), cell, "{name:?}");
        }
    }
}
