//! Scene files: bundled scenes load and round-trip; bad input is rejected with file, line and
//! field named.

use tumble_scene::{Scene, SceneError, load_scene};

fn scenes_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

#[test]
fn bundled_scenes_load_build_and_round_trip() {
    let mut count = 0;
    for entry in std::fs::read_dir(scenes_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let scene = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
        let again = Scene::parse("saved", &scene.to_toml().unwrap()).unwrap();
        assert_eq!(again, scene, "{} does not round-trip", path.display());
        let built = scene.build();
        assert_eq!(built.bodies.len(), scene.file().bodies.len());
        count += 1;
    }
    assert!(count >= 11, "bundled scenes: {count}");
}

/// Every file in `tests/bad/` is rejected with the line, field and message listed in
/// `tests/bad/expected.txt`, and the error names the file.
#[test]
fn bad_scene_files_name_file_line_and_field() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad");
    let manifest = std::fs::read_to_string(dir.join("expected.txt")).unwrap();
    let mut checked = 0;
    let mut failures = Vec::new();
    for entry in manifest
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
    {
        let parts: Vec<&str> = entry.splitn(4, '|').collect();
        let (file, line, field, message) = (parts[0], parts[1], parts[2], parts[3]);
        let path = dir.join(file);
        if message.contains("f32") && tumble_core::math::DOUBLE_PRECISION {
            // Out of range for f32 only: an `f64` build holds these numbers and loads the file.
            load_scene(&path).unwrap_or_else(|e| panic!("{file} in an f64 build: {e}"));
            checked += 1;
            continue;
        }
        let e: SceneError = load_scene(&path).expect_err(file);
        let ok = e.file.ends_with(file)
            && e.line.to_string() == line
            && e.field.contains(field)
            && e.message.contains(message)
            // One line of prose: no run of spaces left by a broken string continuation.
            && !e.message.contains("  ")
            && e.to_string().contains(&format!("{file}:{line}: "));
        if !ok {
            failures.push(format!(
                "{file}: expected line {line}, field ~`{field}`, message ~`{message}`; got {e}"
            ));
        }
        checked += 1;
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    let files = std::fs::read_dir(&dir).unwrap().filter(|e| {
        e.as_ref()
            .unwrap()
            .path()
            .extension()
            .is_some_and(|x| x == "toml")
    });
    assert_eq!(
        files.count(),
        checked,
        "every bad file is listed in expected.txt"
    );
    assert!(checked >= 50, "{checked} bad files");
}

#[test]
fn oversized_and_missing_files_are_rejected_before_reading() {
    let scratch = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
    let dir = scratch.path();
    let big = dir.join("big.toml");
    let f = std::fs::File::create(&big).unwrap();
    f.set_len(100 * 1024 * 1024).unwrap(); // a sparse 100 MB file
    let e = load_scene(&big).unwrap_err();
    assert!(e.message.contains("limited to"), "{e}");
    let missing = dir.join("missing.toml");
    let e = load_scene(&missing).unwrap_err();
    assert!(e.message.contains("cannot be read"), "{e}");
    // A whole-file error names no line (there is none to name).
    assert!(
        e.to_string()
            .starts_with(&format!("{}: file: cannot be read", missing.display())),
        "{e}"
    );
}

#[test]
fn random_garbage_never_panics() {
    // A fixed-seed xorshift mutator over a valid file: 100 000 inputs, each must parse or be
    // rejected with an error, never panic.
    let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    let base = std::fs::read_to_string(scenes_dir().join("spring_chain.toml")).unwrap();
    let alphabet = b"[]{}=\".,-+0123456789eEnaif \n#abcdefghijklmnopqrstuvwxyz_";
    for _ in 0..100_000 {
        let mut bytes = base.clone().into_bytes();
        for _ in 0..(next() % 8 + 1) {
            let i = (next() as usize) % bytes.len();
            match next() % 3 {
                0 => bytes[i] = alphabet[(next() as usize) % alphabet.len()],
                1 => {
                    bytes.remove(i);
                }
                _ => bytes.insert(i, alphabet[(next() as usize) % alphabet.len()]),
            }
        }
        if let Ok(text) = String::from_utf8(bytes) {
            let _ = Scene::parse("fuzz.toml", &text);
        }
    }
}

/// Devices and pipes report no size: they are cut off at the limit instead of read forever.
#[cfg(unix)]
#[test]
fn endless_files_are_cut_off_at_the_limit() {
    let e = load_scene(std::path::Path::new("/dev/zero")).unwrap_err();
    assert_eq!((e.line, e.field.as_str()), (1, "file"), "{e}");
    assert!(e.message.contains("limited to"), "{e}");
}

/// A huge key or value is not echoed whole: the message stays one short line.
#[test]
fn errors_stay_one_short_line() {
    let key = "k".repeat(1_000_000);
    let e = Scene::parse("long.toml", &format!("name = \"x\"\n{key} = 1\n")).unwrap_err();
    let shown = e.to_string();
    assert!(shown.starts_with("long.toml:2: "), "{}", &shown[..80]);
    assert!(
        shown.len() < 1_000 && !shown.contains('\n'),
        "{} bytes",
        shown.len()
    );
}

const WORLD: &str = "name = \"x\"\n[world]\ndt = 0.01\nsteps = 1\n";

/// A million-element array where three numbers are expected is an error naming the count, not
/// silently cut to three (and it is counted, not parsed: this stays fast).
#[test]
fn a_million_element_position_is_rejected_with_its_length() {
    let numbers = vec!["1"; 1_000_000].join(", ");
    let text = format!(
        "{WORLD}[[bodies]]\nname = \"a\"\nmass = 1.0\ninertia = [1.0, 2.0, 3.0]\nposition = [{numbers}]\n"
    );
    let e = Scene::parse("big.toml", &text).unwrap_err();
    assert_eq!((e.line, e.field.as_str()), (9, "bodies[0].position"), "{e}");
    assert!(e.message.contains("expected 3 numbers, got 1000000"), "{e}");
}

/// Exact-length arrays in every place they occur, including convex hull points.
#[test]
fn extra_elements_are_rejected_everywhere() {
    for (table, line, field) in [
        (
            "[world]\ndt = 0.01\nsteps = 1\ngravity = [0, -9.8, 0, 1]\n",
            5,
            "world.gravity",
        ),
        (
            "[world]\ndt = 0.01\nsteps = 1\n[[bodies]]\nname = \"a\"\ndensity = 1.0\nshape = { cuboid = [1, 1, 1, 1] }\n",
            8,
            "bodies[0].shape",
        ),
        (
            "[world]\ndt = 0.01\nsteps = 1\n[[bodies]]\nname = \"a\"\ndensity = 1.0\nshape = { convex_hull = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1, 5]] }\n",
            8,
            "bodies[0].shape",
        ),
        (
            "[world]\ndt = 0.01\nsteps = 1\n[[bodies]]\nname = \"a\"\nmass = 1.0\ninertia = [1, 1, 1]\nrotation = [0, 0, 0, 1, 0]\n",
            9,
            "bodies[0].rotation",
        ),
    ] {
        let e = Scene::parse("x.toml", &format!("name = \"x\"\n{table}")).unwrap_err();
        assert_eq!(e.line, line, "{e}");
        assert!(e.field.contains(field), "{e}");
        assert!(e.message.contains("numbers, got"), "{e}");
    }
}

/// Tiny and huge numbers are shown in exponent form, never as hundreds of digits.
#[test]
fn numbers_in_messages_are_compact() {
    for (dt, shown) in [
        ("1e-300", "1e-300"),
        ("-1e300", "-1e300"),
        ("1e300", "1e300"),
    ] {
        if tumble_core::math::DOUBLE_PRECISION && !dt.starts_with('-') {
            continue; // fits in f64
        }
        let text = format!("name = \"x\"\n[world]\ndt = {dt}\nsteps = 1\n");
        let e = Scene::parse("x.toml", &text).unwrap_err();
        assert!(e.message.contains(shown), "{e}");
        assert!(e.message.len() < 120, "{e}");
    }
}

/// The file name is echoed escaped: a newline or ESC in it cannot break the one-line error or
/// reach the terminal.
#[test]
fn file_names_are_escaped_in_errors() {
    let e = Scene::parse("evil\n\u{1b}[2J\u{202e}.toml", "name = 1\n").unwrap_err();
    let shown = e.to_string();
    assert!(
        !shown.chars().any(tumble_scene::text::is_unsafe_char),
        "{shown:?}"
    );
    assert!(
        shown.starts_with("evil\\n\\u{1b}[2J\\u{202e}.toml:1: "),
        "{shown}"
    );
}

/// Unknown body names in forces are echoed escaped and cut.
#[test]
fn unknown_body_names_are_echoed_safely() {
    let ghost = format!("g\u{1b}]0;x\u{7}{}", "h".repeat(100_000));
    let text = format!(
        "{WORLD}[[bodies]]\nname = \"a\"\nmass = 1.0\ninertia = [1.0, 2.0, 3.0]\n[[forces]]\ntype = \"torque\"\nbody = \"{}\"\ntorque = [1, 0, 0]\n",
        ghost
            .replace('\u{1b}', "\\u001b")
            .replace('\u{7}', "\\u0007")
    );
    let e = Scene::parse("x.toml", &text).unwrap_err();
    let shown = e.to_string();
    assert!(
        shown.contains("unknown body `g\\u{1b}]0;x\\u{7}h"),
        "{shown}"
    );
    assert!(!shown.chars().any(tumble_scene::text::is_unsafe_char));
    assert!(shown.len() < 1_000);
}

/// A long scene name is rejected, not echoed whole.
#[test]
fn long_scene_names_are_rejected() {
    let text = format!(
        "name = \"{}\"\n[world]\ndt = 0.01\nsteps = 1\n",
        "n".repeat(1_000_000)
    );
    let e = Scene::parse("x.toml", &text).unwrap_err();
    assert_eq!((e.line, e.field.as_str()), (1, "name"), "{e}");
    assert!(e.message.contains("at most 256"), "{e}");
    assert!(e.to_string().len() < 1_000);
}

/// `Scene` keeps what its checks accepted: the step is read through an accessor and built into
/// the world as is; `body_states` names its fields.
#[test]
fn scene_accessors_and_body_states() {
    let text = format!(
        "{WORLD}[[bodies]]\nname = \"a\"\nmass = 2.0\ninertia = [1.0, 2.0, 3.0]\nlinear_damping = 0.5\n"
    );
    let scene = Scene::parse("x.toml", &text).unwrap();
    assert_eq!(scene.dt(), 0.01);
    assert_eq!(scene.steps(), 1);
    assert_eq!(scene.gravity(), None);
    let built = scene.build();
    let settings = built
        .world
        .resource::<tumble_ecs::components::PhysicsSettings>();
    assert_eq!(settings.dt(), 0.01);
    let bodies = scene.body_states();
    assert_eq!(bodies[0].name, "a");
    assert_eq!(bodies[0].mass.mass(), 2.0);
    assert_eq!(bodies[0].linear_damping, 0.5);
    assert_eq!(bodies[0].gravity_scale, 1.0);
}

/// A model TOML cannot hold (its integers are signed 64-bit) is an error, not a text no reader
/// accepts; a NaN the model holds (models are checked only when parsed) still reads back.
#[test]
fn a_model_toml_cannot_hold_is_an_error() {
    let path = scenes_dir().join("projectile.toml");
    let scene = load_scene(&path).unwrap();
    let mut model = scene.file().clone();
    model.world.steps = u64::MAX;
    let err = tumble_scene::to_toml_string(&model).unwrap_err();
    assert!(
        matches!(err, tumble_scene::SaveError::NotReadable(_)),
        "{err}"
    );
    assert!(err.to_string().contains("would not read back"), "{err}");
    model.world.steps = i64::MAX as u64;
    assert!(tumble_scene::to_toml_string(&model).is_ok());
    model.world.dt = f64::NAN;
    let text = tumble_scene::to_toml_string(&model).unwrap();
    assert!(text.contains("nan"), "{text}");
}

/// A rotation read from a file is normalized by the engine's own arithmetic (f64, one
/// rounding), not by glam's `Quat::normalize`, whose SIMD and scalar (`enhanced-determinism`)
/// builds round differently: the same file gives the same bits in every build. Quaternions a
/// little off unit length, as files written with a few digits hold them.
#[test]
fn file_rotations_are_normalized_by_the_engine() {
    use tumble_core::math::{Quat, Real, quat_normalize};
    use tumble_ecs::prelude::Pose;

    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let mut text = String::from("name = \"rotations\"\n[world]\ndt = 0.01\nsteps = 1\n");
    let mut given = Vec::new();
    for i in 0..500 {
        let q = [next(), next(), next(), next()];
        let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        // Within the accepted tolerance of unit length, by up to ~3e-7.
        let off = 1.0 + 3e-7 * next();
        let q = q.map(|x| x / norm * off);
        text.push_str(&format!(
            "[[bodies]]\nname = \"b{i}\"\nmass = 1.0\ninertia = [1.0, 2.0, 3.0]\n\
             rotation = [{}, {}, {}, {}]\n",
            q[0], q[1], q[2], q[3]
        ));
        given.push(Quat::from_array(q.map(|x| x as Real)));
    }
    let built = Scene::parse("rotations.toml", &text).unwrap().build();
    for ((name, entity), q) in built.bodies.iter().zip(&given) {
        let pose = built.world.get::<Pose>(*entity).unwrap();
        let expected = quat_normalize(*q);
        assert_eq!(
            pose.rotation.to_array().map(Real::to_bits),
            expected.to_array().map(Real::to_bits),
            "{name}"
        );
    }
}

/// A rate about the free axes of a body with a locked axis loads and is kept, even when the
/// rotation is written with seven digits (the locked rate is then rounding, not a spin).
#[test]
fn a_spin_about_the_free_axes_of_a_locked_body_is_kept() {
    // 30° about x: body y (locked) points along (0, cos 30°, sin 30°), body z along
    // (0, −sin 30°, cos 30°); ω is 4 rad/s about body z.
    let text = r#"
name = "locked"
[world]
dt = 0.01
steps = 10
[[bodies]]
name = "plate"
mass = 1.0
inertia = [1.0, 0.0, 1.0]
rotation = [0.258819, 0.0, 0.0, 0.9659258]
angular_velocity = [0.0, -2.0, 3.4641016]
"#;
    let scene = tumble_scene::Scene::parse("locked.toml", text).unwrap();
    let mut built = scene.build();
    built.step();
    let given = scene.body_states()[0].state.angular_velocity;
    let w = built
        .world
        .get::<tumble_ecs::components::Velocity>(built.bodies[0].1)
        .unwrap()
        .angular;
    assert!(
        (w - given).length() < 1e-5 * given.length(),
        "{w} from {given}"
    );
}

/// Names are kept composed (Unicode form C): a force naming its body decomposed finds it, and
/// the body's name is written composed.
#[test]
fn a_name_typed_decomposed_is_the_composed_name() {
    let text = "name = \"cafe\u{301}\"\n[world]\ndt = 0.01\nsteps = 10\n[[bodies]]\n\
                name = \"caf\u{e9}\"\nmass = 1.0\ninertia = [1.0, 1.0, 1.0]\n[[forces]]\n\
                type = \"torque\"\nbody = \"cafe\u{301}\"\ntorque = [0.0, 0.0, 1.0]\n";
    let scene = Scene::parse("names.toml", text).unwrap();
    assert_eq!(scene.name(), "caf\u{e9}");
    assert_eq!(scene.body_states()[0].name, "caf\u{e9}");
    assert_eq!(scene.forces().len(), 1);
    assert_eq!(tumble_scene::text::composed("cafe\u{301}"), "caf\u{e9}");
    assert!(matches!(
        tumble_scene::text::composed("plain"),
        std::borrow::Cow::Borrowed(_)
    ));
}
