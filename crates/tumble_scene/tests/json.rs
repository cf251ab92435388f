//! JSON scene files: the TOML schema, the same checks, the same errors, located in JSON text.

use std::path::{Path, PathBuf};

use tumble_ecs::prelude::*;
use tumble_scene::{Scene, SceneError, SceneFile, SceneSyntax, load_scene};

fn bundled() -> Vec<(String, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut scenes: Vec<(String, String)> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read_to_string(&p).unwrap(),
            )
        })
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 10, "{scenes:?}");
    scenes
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn every_bundled_scene_reads_the_same_from_json() {
    let dir = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
    for (name, text) in bundled() {
        let toml = Scene::parse(&name, &text).unwrap();
        let json = serde_json::to_string_pretty(toml.file()).unwrap();
        let from_text = Scene::parse_json(&name, &json).unwrap();
        assert_eq!(from_text, toml, "{name}");
        let path = write(dir.path(), &name.replace(".toml", ".json"), &json);
        assert_eq!(SceneSyntax::of(&path), SceneSyntax::Json);
        assert_eq!(load_scene(&path).unwrap(), toml, "{name}");
        // Compact JSON too (one line).
        let compact = serde_json::to_string(toml.file()).unwrap();
        assert_eq!(Scene::parse_json(&name, &compact).unwrap(), toml, "{name}");
    }
}

/// A model edit that the checks must reject, and the field they must name.
struct Bad {
    field: &'static str,
    edit: fn(&mut SceneFile),
}

fn chain() -> SceneFile {
    let text = include_str!("../../../scenes/spring_chain.toml");
    Scene::parse("spring_chain.toml", text)
        .unwrap()
        .file()
        .clone()
}

const BAD: &[Bad] = &[
    Bad {
        field: "world.dt",
        edit: |m| m.world.dt = -0.5,
    },
    Bad {
        field: "world.steps",
        edit: |m| m.world.steps = 0,
    },
    Bad {
        field: "world.integrator",
        edit: |m| m.world.integrator = Some("leapfrog".into()),
    },
    Bad {
        field: "world.substeps",
        edit: |m| m.world.substeps = Some(5000),
    },
    Bad {
        field: "name",
        edit: |m| m.name = "bad\u{1b}[2Jname".into(),
    },
    Bad {
        field: "bodies[2].mass",
        edit: |m| m.bodies[2].mass = Some(-1.0),
    },
    Bad {
        field: "bodies[1].name",
        edit: |m| m.bodies[1].name = m.bodies[0].name.clone(),
    },
    Bad {
        field: "bodies[0].rotation",
        edit: |m| m.bodies[0].rotation = [0.0, 0.0, 0.0, 2.0],
    },
    Bad {
        field: "bodies[2].angular_damping",
        edit: |m| m.bodies[2].angular_damping = -3.0,
    },
    Bad {
        field: "forces[1].b",
        edit: |m| {
            if let tumble_scene::ForceDef::Spring { b, .. } = &mut m.forces[1] {
                *b = Some("nobody".into());
            }
        },
    },
    Bad {
        field: "forces[0].stiffness",
        edit: |m| {
            if let tumble_scene::ForceDef::Spring { stiffness, .. } = &mut m.forces[0] {
                *stiffness = -1.0;
            }
        },
    },
];

/// The key a dotted field ends in (`bodies[2].mass` → `mass`).
fn last_key(field: &str) -> &str {
    field.rsplit('.').next().unwrap()
}

#[test]
fn checks_give_the_same_error_in_both_syntaxes_at_the_line_of_the_field() {
    assert!(chain().forces.len() >= 2 && chain().bodies.len() >= 3);
    for bad in BAD {
        let mut model = chain();
        (bad.edit)(&mut model);
        let toml = tumble_scene::to_toml_string(&model).unwrap();
        let json = serde_json::to_string_pretty(&model).unwrap();
        let from_toml = Scene::parse("s.toml", &toml).unwrap_err();
        let from_json = Scene::parse_json("s.json", &json).unwrap_err();
        assert_eq!(from_toml.field, bad.field, "{from_toml}");
        assert_eq!(from_json.field, bad.field, "{from_json}");
        assert_eq!(from_json.message, from_toml.message, "{}", bad.field);
        let line = json.lines().nth(from_json.line - 1).unwrap_or_default();
        assert!(
            line.contains(&format!("\"{}\"", last_key(bad.field))),
            "{from_json}: line {} is `{line}`",
            from_json.line
        );
    }
}

fn json_error(text: &str) -> SceneError {
    Scene::parse_json("s.json", text).unwrap_err()
}

#[test]
fn parse_errors_name_the_line_and_the_field() {
    let body = r#"{"name": "a", "mass": 1.0, "inertia": [1, 2, 3]}"#;
    let cases: &[(String, usize, &str, &str)] = &[
        (
            format!(
                "{{\"name\": \"s\",\n\"world\": {{\"dt\": 0.1, \"steps\": 3}},\n\"bodies\": [{body},\n{{\"name\": \"b\", \"mass\": \"heavy\"}}]}}"
            ),
            4,
            "bodies[1].mass",
            "invalid type: string \"heavy\", expected f64",
        ),
        (
            "{\"name\": \"s\",\n\"world\": {\"dt\": 0.1,\n \"steps\": 3, \"gravity\": [0, 1]}}"
                .to_owned(),
            3,
            "world.gravity",
            "expected 3 numbers, got 2",
        ),
        (
            format!(
                "{{\"name\": \"s\", \"world\": {{\"dt\": 0.1, \"steps\": 3}},\n\"bodies\": [{body}],\n\"forces\": [{{\"type\": \"torque\", \"body\": \"a\",\n\"torque\": [1, 2, 3],\n\"extra\": 1}}]}}"
            ),
            5,
            "forces[0]",
            "unknown field `extra`, expected `body` or `torque`",
        ),
        (
            format!(
                "{{\"name\": \"s\", \"world\": {{\"dt\": 0.1, \"steps\": 3}},\n\"bodies\": [{body}],\n\"forces\": [{{\"type\": \"spring\", \"a\": \"a\",\n\"anchor_b\": [1, 2, 3, 4],\n\"stiffness\": 1}}]}}"
            ),
            4,
            "forces[0].anchor_b",
            "expected 3 numbers, got 4",
        ),
        (
            "{\"name\": \"s\", \"world\": {\"dt\": 0.1, \"steps\": 3}}\n\n{}".to_owned(),
            3,
            "json",
            "trailing characters",
        ),
        (
            "{\"name\": \"s\",\n \"world\": {\"dt\": 0.1, \"steps\": 3}".to_owned(),
            2,
            "json",
            "EOF while parsing an object",
        ),
        ("\0\0\0".to_owned(), 1, "json", "expected value"),
        // A byte order mark is skipped, and the lines still count from the first.
        (
            "\u{feff}{\"name\": \"s\",\n\"world\": {\"dt\": 0.1, \"steps\": 3, \"x\": 1}}"
                .to_owned(),
            2,
            "world.x",
            "unknown field `x`, expected one of `dt`, `steps`, `integrator`, `springs`, `free_flow`, `substeps`, `gravity`",
        ),
    ];
    for (text, line, field, message) in cases {
        let e = json_error(text);
        assert_eq!(
            (e.line, e.field.as_str(), e.message.as_str()),
            (*line, *field, *message),
            "{text}"
        );
    }
}

/// A string longer than any the schema holds (an unknown key, a tag, a name) is refused as soon
/// as it runs past the limit, naming the line it starts on, from text and from a file: it was
/// read whole, copied into the error and read again to locate it (a 50 MB key took 447 MB).
#[test]
fn a_string_longer_than_the_schema_holds_is_refused_at_its_line() {
    let long = "k".repeat(tumble_scene::MAX_JSON_STRING_BYTES + 1);
    let texts = [
        format!("{{\"name\": \"s\",\n\n\"{long}\": 1}}"),
        format!(
            "{{\"name\": \"s\",\n\"world\": {{\"dt\": 0.1, \"steps\": 3}},\n\"bodies\": [{{\"name\": \"{long}\"}}]}}"
        ),
    ];
    let dir = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
    for (text, line) in texts.iter().zip([3, 3]) {
        let path = write(dir.path(), "long.json", text);
        for e in [json_error(text), load_scene(&path).unwrap_err()] {
            assert_eq!((e.line, e.field.as_str()), (line, "json"), "{e}");
            assert!(e.message.contains("longer than 65536 bytes"), "{e}");
            assert!(e.message.len() < 200, "the string is not echoed");
        }
    }
    // A name at the schema's limit, escaped, is far below it.
    let name = "\\u00e9".repeat(tumble_scene::MAX_NAME_BYTES / 2);
    let text = format!("{{\"name\": \"{name}\", \"world\": {{\"dt\": 0.1, \"steps\": 3}}}}");
    assert!(Scene::parse_json("s.json", &text).is_ok());
}

#[test]
fn a_json_file_is_read_as_a_stream_and_errors_are_located_in_it() {
    let dir = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
    let mut model = chain();
    model.bodies[2].mass = Some(0.0);
    let json = serde_json::to_string_pretty(&model).unwrap();
    let path = write(dir.path(), "chain.JSON", &json);
    let e = load_scene(&path).unwrap_err();
    assert_eq!(e.field, "bodies[2].mass");
    assert!(json.lines().nth(e.line - 1).unwrap().contains("\"mass\""));
    assert!(e.file.ends_with("chain.JSON"), "{e}");
    // A TOML name with JSON inside is read as TOML, and says so in TOML's terms.
    let path = write(dir.path(), "chain.toml", &json);
    assert!(load_scene(&path).is_err());
}

#[test]
fn world_overrides_are_checked_like_the_file() {
    let scene = Scene::parse("c.toml", include_str!("../../../scenes/spring_chain.toml")).unwrap();
    let mut world = scene.file().world.clone();
    world.steps = 7;
    world.integrator = Some("rk4".into());
    let changed = scene.clone().with_world(world.clone()).unwrap();
    assert_eq!(changed.steps(), 7);
    assert_eq!(changed.integrator().to_string(), "rk4");
    assert_eq!(changed.file().bodies, scene.file().bodies);
    // The same as parsing the changed file.
    let mut model = scene.file().clone();
    model.world = world.clone();
    let text = tumble_scene::to_toml_string(&model).unwrap();
    assert_eq!(Scene::parse("c.toml", &text).unwrap(), changed);
    world.dt = f64::NAN;
    let e = scene.with_world(world).unwrap_err();
    assert_eq!((e.line, e.field.as_str()), (0, "world.dt"), "{e}");
}

#[test]
fn a_consumed_build_is_the_same_world_as_a_borrowed_one() {
    for (name, text) in bundled() {
        let scene = Scene::parse(&name, &text).unwrap();
        let mut borrowed = scene.build();
        let mut consumed = scene.clone().into_built();
        assert_eq!(borrowed.bodies, consumed.bodies, "{name}");
        for _ in 0..3 {
            borrowed.step();
            consumed.step();
        }
        assert_eq!(
            world_checksum(&borrowed.world),
            world_checksum(&consumed.world),
            "{name}"
        );
    }
}

/// A number below the smallest `f64` reads as 0; the error says so, quoting the file.
#[test]
fn a_number_that_underflows_is_named_as_written() {
    let e = json_error("{\"name\": \"x\",\n \"world\": {\"dt\": 1e-400, \"steps\": 10}}");
    assert_eq!((e.line, e.field.as_str()), (2, "world.dt"), "{e}");
    assert!(
        e.message
            .contains("got 0 (the file's `1e-400` is below the smallest f64"),
        "{e}"
    );
}
