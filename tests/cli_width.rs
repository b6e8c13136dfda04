//! Every line the commands print by default, and every line of their help,
//! is at most 100 characters wide: a terminal or a log shows it unbroken.
//! JSON lines (`--json`, `render`'s and a rendering merge's one line) are
//! for programs and are not counted; nor are error messages. `compare`'s
//! tables are checked in `tests/cli.rs` (`compare_runs`), which runs it
//! anyway.
mod common;

use common::cli::{geosens, repo, scratch};

/// The widest line allowed.
const WIDTH: usize = 100;

/// Runs `args`, which must succeed, and asserts every line of its stdout
/// and stderr is at most [`WIDTH`] characters (JSON lines aside).
fn assert_narrow(args: &[&str]) {
    let out = geosens(args);
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(out.status.success(), "{args:?}: {stderr}");
    let stdout = String::from_utf8(out.stdout).unwrap();
    for (stream, text) in [("stdout", &stdout), ("stderr", &stderr)] {
        for line in text.lines().filter(|l| !l.starts_with('{')) {
            let n = line.chars().count();
            assert!(n <= WIDTH, "{args:?} {stream}: {n} characters: {line}");
        }
    }
}

#[test]
fn help_is_at_most_100_characters_wide() {
    assert_narrow(&["--help"]);
    assert_narrow(&["-h"]);
    for command in [
        "rod", "compare", "flat", "mesh", "render", "merge", "optimize",
    ] {
        assert_narrow(&[command, "--help"]);
        assert_narrow(&[command, "-h"]);
    }
}

#[test]
fn tables_are_at_most_100_characters_wide() {
    let probe = [
        "--ks", "2.1", "--ke", "3", "--length", "2", "--x", "1", "--omega", "-1",
    ];
    for method in [
        "exact",
        "intensity",
        "expectation",
        "rendering",
        "transport",
        "fd",
    ] {
        let mut args = vec!["rod", "--method", method, "--paths", "20000"];
        args.extend(probe);
        assert_narrow(&args);
    }
    let flat = repo("scenes/three_shapes.toml");
    let mesh = repo("scenes/mesh/triangle.toml");
    for method in ["intensity", "expectation", "rendering", "transport", "fd"] {
        assert_narrow(&[
            "flat", "--scene", &flat, "--method", method, "--paths", "20000",
        ]);
        assert_narrow(&[
            "mesh", "--scene", &mesh, "--method", method, "--paths", "20000",
        ]);
    }
    // A merge prints the single run's table.
    let dir = scratch("width");
    let states: Vec<String> = (1..=2)
        .map(|i| dir.join(format!("s{i}.json")).to_str().unwrap().to_owned())
        .collect();
    for (i, state) in states.iter().enumerate() {
        let shard = format!("{}/2", i + 1);
        assert_narrow(&[
            "flat", "--scene", &flat, "--method", "fd", "--paths", "20000", "--shard", &shard,
            "--state", state,
        ]);
    }
    assert_narrow(&["merge", &states[0], &states[1]]);
    // Three parameters, one of them a rotation.
    let camera = repo("scenes/mesh/inverse_camera.toml");
    assert_narrow(&[
        "optimize",
        "--scene",
        &camera,
        "--method",
        "rendering",
        "--iterations",
        "3",
        "--paths-per-step",
        "64",
    ]);
    let occluder = repo("scenes/inverse_occluder.toml");
    assert_narrow(&[
        "optimize",
        "--scene",
        &occluder,
        "--method",
        "fd",
        "--iterations",
        "3",
        "--paths-per-step",
        "256",
    ]);
    let line_camera = repo("scenes/camera_line.toml");
    let images = dir.join("images");
    let images = images.to_str().unwrap();
    assert_narrow(&[
        "render",
        "--scene",
        &line_camera,
        "--method",
        "fd",
        "--spp",
        "4",
        "--out",
        images,
    ]);
    let _ = std::fs::remove_dir_all(&dir);
}
