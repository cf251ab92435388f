//! Trajectory CSV throughput: how fast `tumble run --out` formats and writes rows, on the path
//! it runs ([`tumble_scene::write_trajectory`] into a file).

use std::num::NonZeroU64;
use std::ops::ControlFlow;

use serde::Serialize;
use tumble_scene::many::{many_body, many_world};
use tumble_scene::{Recording, Scene, SceneFile};

/// One measurement of trajectory writing.
#[derive(Debug, Clone, Serialize)]
pub struct CsvRow {
    /// Bodies in the world (every one recorded).
    pub bodies: usize,
    /// Recorded steps (step 0 included).
    pub recorded_steps: u64,
    /// Rows written.
    pub rows: u64,
    /// Bytes written.
    pub bytes: u64,
    /// MB/s (10⁶ bytes per second) of formatting and writing, the steps between excluded.
    pub megabytes_per_second: f64,
    /// Bytes per row.
    pub bytes_per_row: f64,
}

/// The scene of `tumble gen many` with `n` bodies: asymmetric bodies on a grid, each with its
/// own spin, so the rows hold numbers of every length.
fn tumbling(n: usize) -> Scene {
    let n = n as u64;
    let model = SceneFile {
        name: format!("many-{n}"),
        world: many_world(1),
        bodies: (0..n).map(|i| many_body(i, n)).collect(),
        forces: Vec::new(),
    };
    let json = serde_json::to_string(&model).expect("a scene model serializes");
    Scene::parse_json("csv bench", &json).expect("the generated scene is valid")
}

/// Writes the trajectory of `n` bodies over `steps` steps (every step recorded) into a
/// temporary file in `dir` (the system's temporary folder if `None`: it may be a small RAM disk,
/// so the bench passes its output folder); returns the median of `repetitions` runs by
/// throughput.
pub fn measure(
    n: usize,
    steps: u64,
    repetitions: usize,
    dir: Option<&std::path::Path>,
) -> std::io::Result<CsvRow> {
    let scene = tumbling(n);
    let mut runs = Vec::new();
    for _ in 0..repetitions.max(1) {
        let mut built = scene.build();
        let file = match dir {
            // An output directory still to be made (it is made when the files go in) is on
            // the file system of the nearest directory above it that exists.
            Some(dir) => {
                let existing = dir
                    .ancestors()
                    .find(|a| a.is_dir())
                    .filter(|a| !a.as_os_str().is_empty())
                    .unwrap_or(std::path::Path::new("."));
                tempfile::tempfile_in(existing)?
            }
            None => tempfile::tempfile()?,
        };
        let stats = tumble_scene::write_trajectory(
            &mut built,
            steps,
            &Recording::every(NonZeroU64::MIN),
            file,
            |_, _| ControlFlow::Continue(()),
        )
        .map_err(|e| std::io::Error::other(e.to_string()))?;
        runs.push(stats);
    }
    runs.sort_by(|a, b| {
        a.megabytes_per_second()
            .total_cmp(&b.megabytes_per_second())
    });
    let median = runs[runs.len() / 2];
    Ok(CsvRow {
        bodies: n,
        recorded_steps: steps + 1,
        rows: median.rows,
        bytes: median.bytes,
        megabytes_per_second: median.megabytes_per_second(),
        bytes_per_row: median.bytes as f64 / median.rows.max(1) as f64,
    })
}
