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
    let dir = std::env::temp_dir().join(format!("tumble-scene-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
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
    std::fs::remove_dir_all(&dir).unwrap();
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
