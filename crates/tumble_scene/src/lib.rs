//! # tumble_scene
//!
//! Scene files in TOML, one world per file (format: `DESIGN.md` §5), loaded into a `bevy_ecs`
//! `World` with only the systems the scene needs, and trajectories recorded as CSV.
//!
//! Every error names the file, the line and the field and says what was expected; nothing is
//! built from a file that fails validation.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod build;
mod error;
mod format;
pub mod output;
pub mod text;
mod trajectory;
mod validate;

pub use build::{BuiltScene, MAX_NAME_BYTES, MAX_STEPS, MAX_SUBSTEPS, Scene, SceneBody};
pub use error::{SaveError, SceneError};
pub use format::{BodyDef, ForceDef, SceneFile, ShapeDef, WorldDef};
pub use trajectory::{CSV_HEADER, TrajectoryError, csv_text_cell, write_trajectory};

/// Largest scene file accepted (bytes); anything bigger is rejected before it is read whole.
/// Room for `tumble gen many --n 100000` (about 20 MB), far below the 100 MB of the bad-input
/// test.
pub const MAX_SCENE_BYTES: u64 = 64 * 1024 * 1024;

/// Serializes a scene model to TOML (loading the text gives the same model back).
///
/// The model is not validated here: parse the text with [`Scene::parse`] to check it.
pub fn to_toml_string(model: &SceneFile) -> Result<String, SaveError> {
    Ok(toml::to_string(model)?)
}

/// Loads and validates a scene file (see [`read_scene_text`]).
pub fn load_scene(path: &std::path::Path) -> Result<Scene, SceneError> {
    let text = read_scene_text(path)?;
    Scene::parse(&path.display().to_string(), &text)
}

/// Reads a scene file as UTF-8 text.
///
/// Files over [`MAX_SCENE_BYTES`] are rejected without being read whole: by their size when
/// the file system knows it, and otherwise (pipes, devices such as `/dev/zero`) by reading at
/// most one byte more than the limit.
pub fn read_scene_text(path: &std::path::Path) -> Result<String, SceneError> {
    use std::io::Read;

    let file = path.display().to_string();
    let too_big = |size: &dyn std::fmt::Display| {
        SceneError::at(
            &file,
            1,
            "file",
            format!("is {size} bytes; scene files are limited to {MAX_SCENE_BYTES} bytes"),
        )
    };
    let size = std::fs::metadata(path)
        .map_err(|e| SceneError::io(&file, e))?
        .len();
    if size > MAX_SCENE_BYTES {
        return Err(too_big(&size));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_SCENE_BYTES + 1).read_to_end(&mut bytes))
        .map_err(|e| SceneError::io(&file, e))?;
    if bytes.len() as u64 > MAX_SCENE_BYTES {
        return Err(too_big(&format!("more than {MAX_SCENE_BYTES}")));
    }
    String::from_utf8(bytes)
        .map_err(|e| SceneError::at(&file, 1, "file", format!("is not UTF-8 text ({e})")))
}
