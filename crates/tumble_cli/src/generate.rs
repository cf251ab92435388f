//! `tumble gen`: generated scenes, within the limits `tumble run` accepts.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

use tumble_scene::output::{OutputError, OutputFile};
use tumble_scene::text::path_for_terminal;
use tumble_scene::{MAX_SCENE_BYTES, MAX_STEPS};

use crate::exit::{self, Failure};
use crate::interrupt;

/// Most bodies `gen many` writes: [`RECORD_BYTES_BOUND`] × this, plus the header, stays under
/// [`MAX_SCENE_BYTES`], so the file loads.
pub const MAX_BODIES: i64 = 200_000;

/// A bound on the bytes of one body's record in [`many_bodies`]: 128 bytes of fixed text,
/// the name (`b` and 6 digits), three grid coordinates of at most 3 digits (the grid side is
/// ≤ 59 at [`MAX_BODIES`]), and 7 numbers of at most 25 characters each (`f64` `Display` of a
/// value in (0, 6) is at most 17 significant digits, the point, and a few leading zeros).
const RECORD_BYTES_BOUND: u64 = 128 + 7 + 3 * 3 + 7 * 25;

const _: () = assert!(MAX_BODIES as u64 * RECORD_BYTES_BOUND + 256 <= MAX_SCENE_BYTES);

/// `n` and `steps` as `gen many` accepts them.
pub fn check_many(n: i64, steps: i64) -> Result<(u64, u64), Failure> {
    if !(1..=MAX_BODIES).contains(&n) {
        let why = if n > MAX_BODIES {
            format!(
                " (more would not fit in a scene file of {} MiB)",
                MAX_SCENE_BYTES >> 20
            )
        } else {
            String::new()
        };
        return Err(Failure::new(
            exit::ERROR,
            format!("--n: expected 1 to {MAX_BODIES} bodies, got {n}{why}"),
        ));
    }
    if !(1..=MAX_STEPS as i64).contains(&steps) {
        return Err(Failure::new(
            exit::ERROR,
            format!("--steps: expected 1 to {MAX_STEPS} steps, got {steps}"),
        ));
    }
    Ok((n as u64, steps as u64))
}

/// A scene of `n` asymmetric bodies on a cubic grid, each with its own spin, under gravity;
/// `None` when interrupted.
pub fn many_bodies(n: u64, steps: u64, guard: &interrupt::Guard) -> Option<String> {
    let side = (n as f64).cbrt().ceil().max(1.0) as u64;
    let mut text = format!(
        "name = \"many-{n}\"\n[world]\ndt = 0.016666668\nsteps = {steps}\ngravity = [0.0, -9.81, 0.0]\n"
    );
    for i in 0..n {
        if i.is_multiple_of(4096) && guard.interrupted() {
            return None;
        }
        let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
        let f = i as f64 / n.max(1) as f64;
        let _ = write!(
            text,
            "[[bodies]]\nname = \"b{i}\"\nmass = {}\ninertia = [1.0, {}, {}]\nposition = [{}, {}, {}]\nlinear_velocity = [0.0, {}, 0.0]\nangular_velocity = [{}, {}, 0.3]\n",
            1.0 + f,
            2.0 + f,
            3.0 + f,
            2 * x,
            2 * y,
            2 * z,
            5.0 * f,
            0.3 + f,
            1.0 - f
        );
    }
    Some(text)
}

/// `tumble gen many`: the scene to `out` (a file, or stdout for `None` and `-`).
pub fn run(n: i64, steps: i64, out: Option<&Path>) -> Result<(), Failure> {
    let (n, steps) = check_many(n, steps)?;
    // Polling starts first so that it ends last, after the temporary file is removed.
    let guard = interrupt::Guard::poll();
    // The output is checked (and its temporary file made) before the work.
    let file = match out {
        Some(path) if !crate::is_stdout(path) => Some(OutputFile::create(path, &[])?),
        _ => None,
    };
    let text = many_bodies(n, steps, &guard).ok_or_else(|| {
        let unchanged = out
            .filter(|p| !crate::is_stdout(p))
            .map(|p| format!("; {} was not written", path_for_terminal(p)))
            .unwrap_or_default();
        Failure::new(exit::INTERRUPTED, format!("interrupted{unchanged}"))
    })?;
    // Cannot happen below the caps; checked so that a change of the generator cannot slip by.
    if text.len() as u64 > MAX_SCENE_BYTES {
        return Err(Failure::new(
            exit::ERROR,
            format!(
                "the generated scene is {} bytes, over the {MAX_SCENE_BYTES} bytes `run` reads",
                text.len()
            ),
        ));
    }
    match file {
        Some(mut file) => {
            file.write_all(text.as_bytes())
                .map_err(|e| OutputError::io(file.path(), e))?;
            file.commit()?;
        }
        None => {
            let mut stdout = std::io::stdout().lock();
            stdout
                .write_all(text.as_bytes())
                .and_then(|()| stdout.flush())
                .map_err(|e| format!("standard output: {e}"))?;
        }
    }
    Ok(())
}
