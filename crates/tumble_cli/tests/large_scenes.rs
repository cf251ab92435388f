//! Large scenes: `gen many` in JSON, JSON scenes run like TOML ones, and trajectories cut down
//! with `--every` and `--bodies`.

mod common;

use common::{scratch_dir, stderr, tumble};
use tumble_scene::{CSV_HEADER, load_scene};

fn gen_many(dir: &std::path::Path, file: &str, n: &str, extra: &[&str]) -> std::path::PathBuf {
    let path = dir.join(file);
    let out = tumble()
        .args(["gen", "many", "--n", n, "--steps", "4"])
        .args(extra)
        .arg("--out")
        .arg(&path)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    path
}

#[test]
fn gen_many_writes_json_by_the_extension_and_it_is_the_toml_scene() {
    let dir = scratch_dir();
    let json = gen_many(dir.path(), "many.json", "2000", &[]);
    let toml = gen_many(dir.path(), "many.toml", "2000", &[]);
    let text = std::fs::read_to_string(&json).unwrap();
    assert!(
        text.starts_with("{\"name\":\"many-2000\""),
        "{}",
        &text[..80]
    );
    // One body a line, within the record bound the generator's cap is derived from.
    assert_eq!(text.lines().count(), 2000 + 2);
    assert!(text.lines().skip(1).all(|l| l.len() <= 180 + 9 + 9 * 24));
    let from_json = load_scene(&json).unwrap();
    assert_eq!(from_json.file().bodies.len(), 2000);
    let from_toml = load_scene(&toml).unwrap();
    for (a, b) in from_json.file().bodies.iter().zip(&from_toml.file().bodies) {
        assert!(a == b, "{a:?}\n{b:?}");
    }
    assert!(from_json == from_toml);
    // `--format` agrees with the name, or is refused before anything is written.
    let out = tumble()
        .args(["gen", "many", "--n", "5", "--format", "json", "--out"])
        .arg(dir.path().join("wrong.toml"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).starts_with("error: --format json: ")
            && stderr(&out).contains("wrong.toml is read as toml"),
        "{}",
        stderr(&out)
    );
    assert!(!dir.path().join("wrong.toml").exists());
    let out = tumble()
        .args(["gen", "many", "--n", "2", "--format", "json"])
        .output()
        .unwrap();
    assert!(out.status.success());
    assert!(tumble_scene::Scene::parse_json("-", &String::from_utf8(out.stdout).unwrap()).is_ok());
}

#[test]
fn body_caps_follow_the_format() {
    for (args, expected) in [
        (
            vec!["--n", "200001"],
            "error: --n: expected 1 to 200000 bodies, got 200001 (more would not fit in a TOML \
             scene file of 64 MiB; write JSON, e.g. --out many.json, for up to 10000000)",
        ),
        (
            vec!["--n", "10000001", "--format", "json"],
            "error: --n: expected 1 to 10000000 bodies, got 10000001 (more would not fit in a \
             JSON scene file of 4 GiB)",
        ),
    ] {
        let out = tumble().args(["gen", "many"]).args(&args).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        assert_eq!(stderr(&out).trim_end(), expected);
        assert!(out.stdout.is_empty());
    }
}

#[test]
fn a_json_scene_runs_with_overrides_and_records_only_the_chosen_bodies() {
    let dir = scratch_dir();
    let scene = gen_many(dir.path(), "many.json", "300", &[]);
    let csv = dir.path().join("few.csv");
    let out = tumble()
        .arg("run")
        .arg(&scene)
        .args(["--steps", "6", "--integrator", "rk4", "--every", "3"])
        .args(["--bodies", "b2, b1?", "--out"])
        .arg(&csv)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let summary = String::from_utf8_lossy(&out.stdout);
    assert!(summary.contains("bodies     300"), "{summary}");
    assert!(summary.contains("6 × 0.016666668 s (rk4)"), "{summary}");
    // b2 and b10..b19 (`?` is one character), in file order, at steps 0, 3 and 6.
    assert!(
        summary.contains("trajectory 33 rows, 0.0 MB, written at "),
        "{summary}"
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(CSV_HEADER));
    let rows: Vec<(String, String)> = lines
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            (cells[0].to_owned(), cells[2].to_owned())
        })
        .collect();
    let mut expected_names = vec!["b2".to_owned()];
    expected_names.extend((10..20).map(|i| format!("b{i}")));
    let expected: Vec<(String, String)> = ["0", "3", "6"]
        .iter()
        .flat_map(|step| {
            expected_names
                .iter()
                .map(move |name| (step.to_string(), name.clone()))
        })
        .collect();
    assert_eq!(rows, expected);
}

#[test]
fn bad_body_filters_are_refused_before_the_run() {
    let dir = scratch_dir();
    let scene = gen_many(dir.path(), "many.json", "20", &[]);
    let csv = dir.path().join("none.csv");
    for (filter, expected) in [
        (
            "b1,zz*",
            "error: --bodies: `zz*` matches no body of the scene",
        ),
        (
            "b[",
            "error: --bodies: `b[` is not a pattern: unclosed character class; missing ']'",
        ),
        (
            "b1,,b2",
            "error: --bodies: an empty name in `b1,,b2`; expected names or patterns separated \
             by commas",
        ),
        (
            "\u{1b}]0;x\u{7}",
            "error: --bodies: `\\u{1b}]0;x\\u{7}` matches no body of the scene",
        ),
    ] {
        let out = tumble()
            .arg("run")
            .arg(&scene)
            .args(["--bodies", filter, "--out"])
            .arg(&csv)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{filter}");
        assert_eq!(stderr(&out).trim_end(), expected);
        assert!(!csv.exists());
    }
}

#[test]
fn a_json_scene_error_names_the_file_line_and_field() {
    let dir = scratch_dir();
    let scene = gen_many(dir.path(), "many.json", "50", &[]);
    let text = std::fs::read_to_string(&scene).unwrap().replace(
        "{\"name\":\"b7\",\"mass\":1.14",
        "{\"name\":\"b7\",\"mass\":-1.14",
    );
    std::fs::write(&scene, text).unwrap();
    let out = tumble().arg("run").arg(&scene).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let message = stderr(&out);
    assert!(
        message.starts_with("error: ") && message.contains("many.json:9: bodies[7].mass: "),
        "{message}"
    );
}
