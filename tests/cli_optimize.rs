//! `geosens optimize` from the command line: JSON lines with the issue's
//! keys, the table, refusals that name the field, and Ctrl-C stopping a
//! run cleanly with the last iterate printed.
mod common;
use common::cli::{ok, refused, repo};
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};

#[test]
fn json_lines_carry_the_records() {
    let scene = repo("scenes/inverse_occluder.toml");
    let out = ok(&[
        "optimize",
        "--scene",
        &scene,
        "--method",
        "rendering",
        "--iterations",
        "3",
        "--paths-per-step",
        "1024",
        "--json",
        "--threads",
        "1",
    ]);
    let lines: Vec<serde_json::Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 4);
    for (i, r) in lines.iter().enumerate() {
        assert_eq!(r["iteration"], i as u64);
        for key in [
            "parameters",
            "average",
            "loss",
            "gradient",
            "paths",
            "seconds",
        ] {
            assert!(r.get(key).is_some(), "{key} missing: {r}");
        }
        assert!(r["gradient"]["occluder_tx"]["stderr"].as_f64().unwrap() > 0.0);
        assert_eq!(r["paths"], 8 * 1024);
    }
    assert_eq!(lines[0]["parameters"]["occluder_rotate"], 0.0);
}

#[test]
fn the_table_ends_with_the_mean_iterate() {
    let scene = repo("scenes/design_reflector.toml");
    let out = ok(&[
        "optimize",
        "--scene",
        &scene,
        "--method",
        "expectation",
        "--iterations",
        "4",
        "--paths-per-step",
        "1024",
        "--optimizer",
        "sgd",
    ]);
    assert!(out.starts_with(" iter"), "{out}");
    assert!(
        out.lines()
            .last()
            .unwrap()
            .starts_with("mean of iterates 2..4: reflector_rotate = ")
    );
}

#[test]
fn bad_settings_and_scenes_are_refused_naming_them() {
    let scene = repo("scenes/inverse_occluder.toml");
    let e = refused(&[
        "optimize", "--scene", &scene, "--method", "fd", "--step", "0",
    ]);
    assert!(e.contains("--step"), "{e}");
    let e = refused(&[
        "optimize",
        "--scene",
        &scene,
        "--method",
        "fd",
        "--batches",
        "2",
    ]);
    assert!(e.contains("batches"), "{e}");
    let e = refused(&["optimize", "--scene", &scene, "--method", "intensity"]);
    assert!(e.contains("no gradient"), "{e}");
    // A scene without an objective names the missing table and the file.
    let e = refused(&[
        "optimize",
        "--scene",
        &repo("scenes/occluder.toml"),
        "--method",
        "fd",
    ]);
    assert!(
        e.contains("[objective]") && e.contains("occluder.toml"),
        "{e}"
    );
}

/// SIGINT in the middle of a long run: the run ends after the iteration
/// under way with status 0, the lines printed are whole records, and stderr
/// names the last iterate.
#[cfg(unix)]
#[test]
fn ctrl_c_stops_cleanly_with_the_last_iterate() {
    let scene = repo("scenes/inverse_occluder.toml");
    let mut child = Command::new(env!("CARGO_BIN_EXE_geosens"))
        .args([
            "optimize",
            "--scene",
            &scene,
            "--method",
            "expectation",
            "--iterations",
            "100000",
            "--paths-per-step",
            "1024",
            "--json",
            "--threads",
            "1",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    // Wait for a few records, so that the handler is installed.
    for _ in 0..3 {
        lines.next().unwrap().unwrap();
    }
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let rest: Vec<String> = lines.map(|l| l.unwrap()).collect();
    let status = child.wait().unwrap();
    let stderr = std::io::read_to_string(child.stderr.take().unwrap()).unwrap();
    assert!(status.success(), "{status:?}: {stderr}");
    assert!(rest.len() < 100_000, "the run was not stopped");
    for l in &rest {
        serde_json::from_str::<serde_json::Value>(l).expect("whole records");
    }
    assert!(
        stderr.contains("stopped by Ctrl-C after iteration") && stderr.contains("occluder_tx = "),
        "{stderr}"
    );
}
