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
        let again = Scene::parse("saved", &scene.to_toml()).unwrap();
        assert_eq!(again, scene, "{} does not round-trip", path.display());
        let built = scene.build();
        assert_eq!(built.bodies.len(), scene.file.bodies.len());
        count += 1;
    }
    assert!(count >= 9, "bundled scenes: {count}");
}

const VALID: &str = "name = \"ok\"\n[world]\ndt = 0.01\nsteps = 10\n[[bodies]]\nname = \"a\"\nmass = 1.0\ninertia = [1.0, 2.0, 3.0]\n";

fn error(text: &str) -> SceneError {
    Scene::parse("bad.toml", text).expect_err("must be rejected")
}

#[test]
fn bad_input_names_line_and_field() {
    let cases: &[(&str, usize, &str, &str)] = &[
        // (text, line, field fragment, message fragment)
        (
            "name = \"x\"\n[world]\ndt = 0.0\nsteps = 1\n",
            3,
            "world.dt",
            "> 0",
        ),
        (
            "name = \"x\"\n[world]\ndt = -1.0\nsteps = 1\n",
            3,
            "world.dt",
            "> 0",
        ),
        (
            "name = \"x\"\n[world]\ndt = nan\nsteps = 1\n",
            3,
            "world.dt",
            "finite",
        ),
        (
            "name = \"x\"\n[world]\ndt = inf\nsteps = 1\n",
            3,
            "world.dt",
            "finite",
        ),
        (
            "name = \"x\"\n[world]\ndt = 1e39\nsteps = 1\n",
            3,
            "world.dt",
            "overflows f32",
        ),
        (
            "name = \"x\"\n[world]\ndt = 0.01\nsteps = 0\n",
            4,
            "world.steps",
            "1 to",
        ),
        (
            "name = \"x\"\n[world]\ndt = 0.01\nsteps = 99999999999\n",
            4,
            "world.steps",
            "1 to",
        ),
        (
            "name = \"x\"\n[world]\ndt = 0.01\nsteps = 1\nintegrator = \"magic\"\n",
            5,
            "world.integrator",
            "unknown integrator",
        ),
        (
            "name = \"x\"\n[world]\ndt = 0.01\nsteps = 1\nwarp = 9\n",
            5,
            "warp",
            "unknown field",
        ),
        (
            "name = \"x\"\n[world]\ndt = \"fast\"\nsteps = 1\n",
            3,
            "dt",
            "invalid type",
        ),
        ("name = \"x\"\n[world\ndt = 0.01\n", 2, "toml", ""),
        ("", 1, "toml", "missing field"),
        ("\u{1}\u{2}garbage\u{ff}", 1, "toml", ""),
        (
            &format!("{VALID}[[bodies]]\nname = \"a\"\nmass = 1.0\ninertia = [1.0, 1.0, 1.0]\n"),
            10,
            "bodies[1].name",
            "duplicate",
        ),
        (
            &VALID.replace("mass = 1.0", "mass = 0.0"),
            7,
            "bodies[0].mass",
            "mass must be > 0",
        ),
        (
            &VALID.replace("mass = 1.0", "mass = -3.0"),
            7,
            "bodies[0].mass",
            "mass must be > 0",
        ),
        (
            &VALID.replace("mass = 1.0", "mass = nan"),
            7,
            "bodies[0].mass",
            "finite",
        ),
        (
            &VALID.replace("[1.0, 2.0, 3.0]", "[1.0, -2.0, 3.0]"),
            8,
            "bodies[0].inertia",
            ">= 0",
        ),
        (
            &VALID.replace("[1.0, 2.0, 3.0]", "[0.0, 0.0, 0.0]"),
            8,
            "bodies[0].inertia",
            "zero on every axis",
        ),
        (
            &format!("{VALID}rotation = [0.0, 0.0, 0.0, 2.0]\n"),
            9,
            "bodies[0].rotation",
            "unit quaternion",
        ),
        (
            &format!("{VALID}rotation = [0.0, 0.0, 0.0, 0.0]\n"),
            9,
            "bodies[0].rotation",
            "unit quaternion",
        ),
        (
            &format!("{VALID}angular_velocity = [1e40, 0.0, 0.0]\n"),
            9,
            "bodies[0].angular_velocity",
            "overflows f32",
        ),
        (
            &format!("{VALID}position = [1.0, 2.0]\n"),
            9,
            "position",
            "",
        ),
        (
            &format!(
                "{VALID}[[forces]]\ntype = \"torque\"\nbody = \"ghost\"\ntorque = [0.0, 0.0, 1.0]\n"
            ),
            11,
            "forces[0].body",
            "unknown body `ghost`",
        ),
        (
            &format!("{VALID}[[forces]]\ntype = \"laser\"\nbody = \"a\"\n"),
            10,
            "type",
            "unknown variant",
        ),
        (
            &format!("{VALID}[[forces]]\ntype = \"spring\"\na = \"a\"\nstiffness = -5.0\n"),
            12,
            "forces[0].stiffness",
            ">= 0",
        ),
        (
            "name = \"x\"\n[world]\ndt = 0.01\nsteps = 1\n[[bodies]]\nname = \"b\"\nmass = 1.0\n",
            7,
            "bodies[0].mass",
            "either `mass` and `inertia`",
        ),
        (
            "name = \"x\"\n[world]\ndt = 0.01\nsteps = 1\n[[bodies]]\nname = \"b\"\nshape = { ball = -1.0 }\ndensity = 5.0\n",
            7,
            "bodies[0].shape",
            "> 0",
        ),
        (
            "name = \"x\"\n[world]\ndt = 0.01\nsteps = 1\n[[bodies]]\nname = \"b\"\nshape = { ball = 1.0 }\ndensity = 0.0\n",
            8,
            "bodies[0].density",
            "density must be > 0",
        ),
        (
            "name = \"x\"\n[world]\ndt = 0.01\nsteps = 1\n[[bodies]]\nname = \"b\"\nshape = { convex_hull = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] }\ndensity = 1.0\n",
            7,
            "bodies[0].shape",
            "",
        ),
    ];
    for (text, line, field, message) in cases {
        let e = error(text);
        assert_eq!(e.file, "bad.toml");
        assert_eq!(e.line, *line, "{text:?}: {e}");
        assert!(
            e.field.contains(field),
            "{text:?}: field `{}` lacks `{field}` ({e})",
            e.field
        );
        assert!(
            e.message.contains(message),
            "{text:?}: message `{}` lacks `{message}`",
            e.message
        );
        let shown = e.to_string();
        assert!(shown.starts_with(&format!("bad.toml:{line}: ")), "{shown}");
    }
}

#[test]
fn oversized_and_missing_files_are_rejected_before_reading() {
    let dir = std::env::temp_dir().join(format!("tumble-scene-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let big = dir.join("big.toml");
    let f = std::fs::File::create(&big).unwrap();
    f.set_len(100 * 1024 * 1024).unwrap(); // a sparse 100 MB file
    let e = load_scene(&big).unwrap_err();
    assert!(e.message.contains("limited to"), "{e}");
    let e = load_scene(&dir.join("missing.toml")).unwrap_err();
    assert!(e.message.contains("cannot be read"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn random_garbage_never_panics() {
    // A fixed-seed xorshift mutator over a valid file: 20 000 inputs, each must parse or be
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
    for _ in 0..20_000 {
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
