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
mod trajectory;
mod validate;

pub use build::{BuiltScene, Scene};
pub use error::SceneError;
pub use format::{BodyDef, ForceDef, SceneFile, ShapeDef, WorldDef};
pub use trajectory::{CSV_HEADER, write_trajectory};

/// Largest scene file accepted (bytes); anything bigger is rejected before it is read whole.
pub const MAX_SCENE_BYTES: u64 = 16 * 1024 * 1024;

/// Serializes a scene model to TOML (loading the text gives the same model back).
pub fn to_toml_string(model: &SceneFile) -> String {
    toml::to_string(model).unwrap_or_default()
}

/// Loads and validates a scene file.
pub fn load_scene(path: &std::path::Path) -> Result<Scene, SceneError> {
    let file = path.display().to_string();
    let size = std::fs::metadata(path)
        .map_err(|e| SceneError::io(&file, e))?
        .len();
    if size > MAX_SCENE_BYTES {
        return Err(SceneError::at(
            &file,
            1,
            "file",
            format!("is {size} bytes; scene files are limited to {MAX_SCENE_BYTES} bytes"),
        ));
    }
    let bytes = std::fs::read(path).map_err(|e| SceneError::io(&file, e))?;
    let text = String::from_utf8(bytes)
        .map_err(|e| SceneError::at(&file, 1, "file", format!("is not UTF-8 text ({e})")))?;
    Scene::parse(&file, &text)
}
