//! # tumble_scene
//!
//! Scene files in TOML, or JSON with the same schema for large scenes (chosen by the file
//! extension), one world per file (format: `DESIGN.md` §5), loaded into a `bevy_ecs` `World`
//! with only the systems the scene needs, and trajectories recorded as CSV.
//!
//! Every error names the file, the line and the field and says what was expected; nothing is
//! built from a file that fails validation.

// docs.rs builds with `--cfg docsrs` on nightly: feature-gated items are marked with the
// features they need.
#![cfg_attr(docsrs, feature(doc_cfg))]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod build;
mod checks;
mod error;
mod format;
mod json;
mod json_locate;
mod json_strings;
pub mod many;
mod model;
pub mod output;
mod spawn;
pub mod text;
mod tool;
mod trajectory;
mod validate;

pub use build::{BuiltScene, Scene, SceneBody, SceneSyntax};
pub use checks::MAX_NAME_BYTES;
pub use error::{SaveError, SceneError};
pub use format::{BodyDef, ForceDef, SceneFile, ShapeDef, WorldDef};
pub use json_strings::MAX_JSON_STRING_BYTES;
pub use model::{MAX_STEPS, MAX_SUBSTEPS, SceneForce};
pub use trajectory::{
    CSV_HEADER, Recording, TrajectoryError, TrajectoryStats, csv_text_cell, write_trajectory,
};

/// Largest TOML scene file accepted (bytes); anything bigger is rejected before it is read
/// whole. TOML is parsed as a whole document (about 30 times its size in memory), so large
/// scenes are written in JSON ([`MAX_JSON_SCENE_BYTES`]).
pub const MAX_SCENE_BYTES: u64 = 64 * 1024 * 1024;

/// Largest JSON scene file accepted (bytes). JSON is read as a stream, so memory follows the
/// scene (about 300 bytes a body), not the text: room for ten million bodies.
pub const MAX_JSON_SCENE_BYTES: u64 = 4 << 30;

/// Serializes a scene model to TOML; loading the text gives the same model back, or this is an
/// error ([`SaveError::NotReadable`]): the text is read back and compared before it is
/// returned, so no text is handed out that a reader would refuse or read differently.
///
/// The model is not validated here: parse the text with [`Scene::parse`] to check it.
pub fn to_toml_string(model: &SceneFile) -> Result<String, SaveError> {
    let text = toml::to_string(model)?;
    // As any TOML reader holds it (integers are signed 64-bit), then as the model.
    let read =
        toml::from_str::<toml::Table>(&text).and_then(|_| toml::from_str::<SceneFile>(&text));
    match read {
        // Compared as text, so that a NaN (which the model may hold: it is checked only when
        // parsed) reads back as itself.
        Ok(back) if toml::to_string(&back).is_ok_and(|again| again == text) => Ok(text),
        Ok(_) => Err(SaveError::NotReadable(
            "it reads back with different values".to_owned(),
        )),
        Err(e) => Err(SaveError::NotReadable(
            text::terminal_safe(e.message()).into_owned(),
        )),
    }
}

/// Loads and validates a scene file: JSON when its name ends in `.json`, read as a stream of at
/// most [`MAX_JSON_SCENE_BYTES`]; TOML otherwise (see [`read_scene_text`]).
pub fn load_scene(path: &std::path::Path) -> Result<Scene, SceneError> {
    let file = path.display().to_string();
    match SceneSyntax::of(path) {
        SceneSyntax::Toml => Scene::parse(&file, &read_scene_text(path)?),
        SceneSyntax::Json => load_json(path, &file),
    }
}

fn load_json(path: &std::path::Path, file: &str) -> Result<Scene, SceneError> {
    use std::io::Read;

    let too_big = |size: &dyn std::fmt::Display| {
        SceneError::at(
            file,
            1,
            "file",
            format!(
                "is {size} bytes; JSON scene files are limited to {MAX_JSON_SCENE_BYTES} bytes"
            ),
        )
    };
    let opened = std::fs::File::open(path).map_err(|e| SceneError::io(file, e))?;
    let size = opened
        .metadata()
        .map_err(|e| SceneError::io(file, e))?
        .len();
    if size > MAX_JSON_SCENE_BYTES {
        return Err(too_big(&size));
    }
    // Pipes and devices have no size: stop one byte past the limit and tell it apart from the
    // end of a document.
    let capped = Capped {
        inner: opened.take(MAX_JSON_SCENE_BYTES + 1),
        over: std::rc::Rc::default(),
    };
    let over = capped.over.clone();
    // The `BufReader` is passed by value: `serde_json` reads byte by byte, which the standard
    // library makes cheap for a `BufReader`, not for a reference to one.
    let input = std::io::BufReader::with_capacity(1 << 16, capped);
    let scene = Scene::read_json(file, input, json::JsonSource::File(path));
    if over.get() {
        return Err(too_big(&format!("more than {MAX_JSON_SCENE_BYTES}")));
    }
    scene
}

/// A file read up to a byte limit, which says whether the limit was reached.
struct Capped {
    inner: std::io::Take<std::fs::File>,
    over: std::rc::Rc<std::cell::Cell<bool>>,
}

impl std::io::Read for Capped {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        if self.inner.limit() == 0 {
            self.over.set(true);
        }
        Ok(n)
    }
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
