//! `tumble gen`: generated scenes, within the limits `tumble run` accepts.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

use tumble_scene::many::{many_body, many_world};
use tumble_scene::output::{OutputError, OutputFile};
use tumble_scene::text::path_for_terminal;
use tumble_scene::{MAX_JSON_SCENE_BYTES, MAX_SCENE_BYTES, MAX_STEPS, SceneSyntax};

use crate::exit::{self, Failure};
use crate::interrupt;

/// Most bodies `gen many` writes in TOML: [`RECORD_BYTES_BOUND`] × this, plus the header,
/// stays under [`MAX_SCENE_BYTES`], so the file loads.
pub(crate) const MAX_BODIES: i128 = 200_000;

/// Most bodies `gen many` writes in JSON: [`JSON_RECORD_BYTES_BOUND`] × this, plus the
/// header, stays under [`MAX_JSON_SCENE_BYTES`].
pub(crate) const MAX_JSON_BODIES: i128 = 10_000_000;

/// A bound on the bytes of one body's record in TOML: 128 bytes of fixed text, the name (`b`
/// and up to 8 digits), three grid coordinates of at most 4 digits (the grid side is ≤ 216 at
/// [`MAX_JSON_BODIES`]), and 7 numbers of at most 25 characters each (`f64` `Display` of a
/// value in (0, 6) is at most 17 significant digits, the point, and a few leading zeros).
const RECORD_BYTES_BOUND: u64 = 128 + 9 + 3 * 4 + 7 * 25;

/// The same bound for a JSON record (one line, [`many_body`] serialized with its default fields
/// left out): 99 bytes of keys, brackets, commas and the line break, the name, six numbers of
/// at most 24 characters (`ryu`'s shortest `f64`, exponent included: the mass, two moments, a
/// velocity and two rates) and seven of at most 5 (the grid coordinates, at most `430.0` at
/// [`MAX_JSON_BODIES`], and the constants `1.0`, `0.0`, `0.3`). A test checks it on records
/// across the whole range.
const JSON_RECORD_BYTES_BOUND: u64 = 99 + 9 + 6 * 24 + 7 * 5;

const _: () = assert!(MAX_BODIES as u64 * RECORD_BYTES_BOUND + 256 <= MAX_SCENE_BYTES);
const _: () =
    assert!(MAX_JSON_BODIES as u64 * JSON_RECORD_BYTES_BOUND + 256 <= MAX_JSON_SCENE_BYTES);

/// `n` and `steps` as `gen many` accepts them for a file in `syntax`.
pub(crate) fn check_many(n: i128, steps: i128, syntax: SceneSyntax) -> Result<(u64, u64), Failure> {
    let (most, limit) = match syntax {
        SceneSyntax::Toml => (MAX_BODIES, MAX_SCENE_BYTES),
        SceneSyntax::Json => (MAX_JSON_BODIES, MAX_JSON_SCENE_BYTES),
    };
    if !(1..=most).contains(&n) {
        let why = match syntax {
            _ if n <= most => String::new(),
            SceneSyntax::Toml => format!(
                " (more would not fit in a TOML scene file of {} MiB; write JSON, e.g. --out \
                 many.json, for up to {MAX_JSON_BODIES})",
                limit >> 20
            ),
            SceneSyntax::Json => format!(
                " (more would not fit in a JSON scene file of {} GiB)",
                limit >> 30
            ),
        };
        return Err(Failure::new(
            exit::ERROR,
            format!("--n: expected 1 to {most} bodies, got {n}{why}"),
        ));
    }
    if !(1..=i128::from(MAX_STEPS)).contains(&steps) {
        return Err(Failure::new(
            exit::ERROR,
            format!("--steps: expected 1 to {MAX_STEPS} steps, got {steps}"),
        ));
    }
    Ok((n as u64, steps as u64))
}

/// A scene of `n` bodies ([`many_body`]) in TOML; `None` when interrupted.
pub(crate) fn many_bodies(n: u64, steps: u64, guard: &interrupt::Guard) -> Option<String> {
    let w = many_world(steps);
    let [gx, gy, gz] = w.gravity.unwrap_or_default();
    let mut text = format!(
        "name = \"many-{n}\"\n[world]\ndt = {}\nsteps = {steps}\ngravity = [{gx:?}, {gy:?}, {gz:?}]\n",
        w.dt
    );
    for i in 0..n {
        if i.is_multiple_of(4096) && guard.interrupted() {
            return None;
        }
        let b = many_body(i, n);
        let (Some(mass), Some(inertia)) = (b.mass, b.inertia) else {
            unreachable!("generated bodies have a mass and an inertia")
        };
        let [px, py, pz] = b.position;
        let [wx, wy, wz] = b.angular_velocity;
        let _ = write!(
            text,
            "[[bodies]]\nname = \"{}\"\nmass = {mass}\ninertia = [{:?}, {}, {}]\nposition = [{px}, {py}, {pz}]\nlinear_velocity = [0.0, {}, 0.0]\nangular_velocity = [{wx}, {wy}, {wz}]\n",
            b.name, inertia[0], inertia[1], inertia[2], b.linear_velocity[1]
        );
    }
    Some(text)
}

/// Writes the scene of `n` bodies ([`many_body`]) as JSON to `out`, one body per line (so that
/// an error in a hand-edited copy names a useful line), without holding the text. Fails with
/// [`std::io::ErrorKind::Interrupted`] when interrupted.
pub(crate) fn write_many_json(
    n: u64,
    steps: u64,
    guard: &interrupt::Guard,
    out: impl std::io::Write,
) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::with_capacity(1 << 16, out);
    write!(w, "{{\"name\":\"many-{n}\",\"world\":")?;
    serde_json::to_writer(&mut w, &many_world(steps))?;
    write!(w, ",\"bodies\":[")?;
    for i in 0..n {
        if i.is_multiple_of(4096) && guard.interrupted() {
            return Err(std::io::ErrorKind::Interrupted.into());
        }
        w.write_all(if i == 0 { b"\n" } else { b",\n" })?;
        serde_json::to_writer(&mut w, &many_body(i, n))?;
    }
    w.write_all(b"\n]}\n")?;
    w.flush()
}

/// `tumble gen many`: the scene to `out` (a file, or stdout for `None` and `-`), in `format`
/// (default: JSON for a file name ending in `.json`, else TOML).
pub(crate) fn run(
    n: i128,
    steps: i128,
    out: Option<&Path>,
    format: Option<SceneSyntax>,
) -> Result<(), Failure> {
    let file_out = out.filter(|p| !crate::is_stdout(p));
    let syntax = match (format, file_out) {
        (Some(format), Some(path)) if SceneSyntax::of(path) != format => {
            return Err(Failure::new(
                exit::ERROR,
                format!(
                    "--format {}: {} is read as {} (scene files are read by their extension: \
                     .json is JSON, anything else TOML)",
                    syntax_name(format),
                    path_for_terminal(path),
                    syntax_name(SceneSyntax::of(path))
                ),
            ));
        }
        (Some(format), _) => format,
        (None, Some(path)) => SceneSyntax::of(path),
        (None, None) => SceneSyntax::Toml,
    };
    let (n, steps) = check_many(n, steps, syntax)?;
    // Polling starts first so that it ends last, after the temporary file is removed.
    let guard = interrupt::Guard::poll();
    // The output is checked (and its temporary file made) before the work.
    let mut file = match file_out {
        Some(path) => Some(OutputFile::create(path, &[])?),
        None => None,
    };
    let interrupted = || {
        let unchanged = file_out
            .map(|p| format!("; {} was not written", path_for_terminal(p)))
            .unwrap_or_default();
        Failure::new(exit::INTERRUPTED, format!("interrupted{unchanged}"))
    };
    let written = match syntax {
        SceneSyntax::Json => {
            let result = match file.as_mut() {
                Some(file) => write_many_json(n, steps, &guard, file),
                None => write_many_json(n, steps, &guard, crate::stdout::open()?),
            };
            match result {
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {
                    return Err(interrupted());
                }
                other => other,
            }
        }
        SceneSyntax::Toml => {
            let text = many_bodies(n, steps, &guard).ok_or_else(interrupted)?;
            // Cannot happen below the caps; checked so that a change of the generator cannot
            // slip by.
            if text.len() as u64 > MAX_SCENE_BYTES {
                return Err(Failure::new(
                    exit::ERROR,
                    format!(
                        "the generated scene is {} bytes, over the {MAX_SCENE_BYTES} bytes `run` \
                         reads",
                        text.len()
                    ),
                ));
            }
            match file.as_mut() {
                Some(file) => file.write_all(text.as_bytes()),
                None => {
                    let mut stdout = crate::stdout::open()?;
                    stdout
                        .write_all(text.as_bytes())
                        .and_then(|()| stdout.flush())
                }
            }
        }
    };
    match file {
        Some(file) => {
            written.map_err(|e| OutputError::io(file.path(), e))?;
            file.commit()?;
        }
        None => written.map_err(|e| format!("standard output: {e}"))?,
    }
    Ok(())
}

/// `toml` or `json`, as `--format` spells it.
pub(crate) fn syntax_name(syntax: SceneSyntax) -> &'static str {
    match syntax {
        SceneSyntax::Toml => "toml",
        SceneSyntax::Json => "json",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every record `gen many` writes fits the per-record bound the body cap is derived from,
    /// at the largest scene and at small ones (whose fractions `i/n` differ).
    #[test]
    fn json_records_fit_their_bound() {
        let mut longest = 0;
        for n in [1, 2, 3, 7, 1000, 999_983, MAX_JSON_BODIES as u64] {
            let step = (n / 5000).max(1);
            for i in (0..n).step_by(step as usize).chain([n - 1]) {
                let record = serde_json::to_vec(&many_body(i, n)).unwrap();
                // `,\n` before every record but the first.
                longest = longest.max(record.len() as u64 + 2);
            }
        }
        assert!(longest <= JSON_RECORD_BYTES_BOUND, "{longest}");
        // The bound is not loose by more than the spread of the numbers' lengths.
        assert!(JSON_RECORD_BYTES_BOUND - longest < 100, "{longest}");
    }
}
