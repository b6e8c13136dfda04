//! `geosens flat`: the JSON line's shape (the rod's, with `sensitivity` keyed
//! by parameter name), agreement with the analytic reference, and clear
//! errors for bad scene files.
use geosens::flat::exact::Reference;
use geosens::flat::file;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn geosens(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_geosens"))
        .args(args)
        .output()
        .expect("the geosens binary runs")
}

fn scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

fn flat_json(scene_file: &Path, method: &str, paths: &str) -> Value {
    let path = scene_file.to_str().unwrap();
    let out = geosens(&[
        "flat", "--scene", path, "--method", method, "--paths", paths, "--json",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{method} failed: {stderr}");
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert_eq!(stdout.lines().count(), 1, "not one line: {stdout}");
    serde_json::from_str(&stdout).unwrap()
}

#[test]
fn json_keys_sensitivities_by_parameter_name_in_declaration_order() {
    let path = scene("occluder.toml");
    let names: Vec<String> = file::load(&path)
        .unwrap()
        .parameters()
        .iter()
        .map(|p| p.name.clone())
        .collect();
    for method in ["intensity", "expectation", "rendering", "transport", "fd"] {
        let v = flat_json(&path, method, "20000");
        let keys: Vec<&str> = v.as_object().unwrap().keys().map(|k| k.as_str()).collect();
        assert_eq!(
            keys,
            [
                "method",
                "intensity",
                "sensitivity",
                "gradient",
                "paths",
                "seconds"
            ]
        );
        assert_eq!(v["method"], method);
        assert_eq!(v["paths"], 20000);
        let s = v["sensitivity"].as_object().unwrap();
        if method == "intensity" {
            assert!(s.is_empty());
        } else {
            let got: Vec<&String> = s.keys().collect();
            assert_eq!(got, names.iter().collect::<Vec<_>>(), "{method}");
        }
        assert_eq!(v["gradient"].is_null(), method != "transport", "{method}");
    }
}

#[test]
fn flat_estimates_agree_with_the_closed_form() {
    let path = scene("polygon_occluder.toml");
    let sc = file::load(&path).unwrap();
    let reference = Reference::for_scene(&sc).unwrap();
    let v = flat_json(&path, "rendering", "200000");
    let z = |v: &Value, exact: f64| {
        let (m, s) = (v["mean"].as_f64().unwrap(), v["stderr"].as_f64().unwrap());
        (m - exact).abs() / s
    };
    assert!(z(&v["intensity"], reference.value()) < 4.0);
    for (j, p) in sc.parameters().iter().enumerate() {
        let zj = z(&v["sensitivity"][&p.name], reference.derivative(j));
        assert!(zj < 4.0, "{}: z = {zj}", p.name);
    }
}

#[test]
fn bad_scene_files_exit_with_a_reason() {
    let dir = std::env::temp_dir().join(format!("geosens-cli-flat-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.toml");
    let text = std::fs::read_to_string(scene("occluder.toml"))
        .unwrap()
        .replace("radiance = 1", "radiance = -1");
    std::fs::write(&bad, text).unwrap();
    for (file, words) in [
        (bad.to_str().unwrap().to_owned(), vec!["radiance", "-1"]),
        ("no/such/scene.toml".to_owned(), vec!["no/such/scene.toml"]),
    ] {
        let out = geosens(&["flat", "--scene", &file, "--method", "rendering"]);
        assert_eq!(out.status.code(), Some(1), "{file}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.starts_with("error: "), "{stderr}");
        for w in words {
            assert!(stderr.contains(w), "{stderr} lacks {w}");
        }
    }
    let out = geosens(&[
        "flat",
        "--scene",
        scene("occluder.toml").to_str().unwrap(),
        "--method",
        "magic",
    ]);
    assert_eq!(out.status.code(), Some(2));
    std::fs::remove_dir_all(&dir).ok();
}

/// `geosens flat --json` with `extra` arguments: its JSON line.
fn flat_json_with(scene_file: &Path, method: &str, extra: &[&str]) -> Value {
    let mut args = vec!["flat", "--scene", scene_file.to_str().unwrap()];
    args.extend(["--method", method, "--json"]);
    args.extend(extra);
    let out = geosens(&args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{args:?} failed: {stderr}");
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The JSON line without its wall time.
fn without_seconds(mut v: Value) -> Value {
    v.as_object_mut().unwrap().remove("seconds");
    v
}

#[test]
fn fd_differentiates_twelve_parameters_and_agrees_with_expectation() {
    // 13 quantities, over the old finite-difference cap of 8. Step 10⁻²:
    // its O(h²) bias is far under these standard errors, and at 10⁻³ a
    // reflector's grazing paths give the difference heavy tails.
    let path = scene("three_shapes.toml");
    let names: Vec<String> = file::load(&path)
        .unwrap()
        .parameters()
        .iter()
        .map(|p| p.name.clone())
        .collect();
    assert_eq!(names.len(), 12);
    let fd = flat_json_with(
        &path,
        "fd",
        &["--fd-step", "0.01", "--paths", "200000", "--seed", "1"],
    );
    let other = flat_json_with(&path, "expectation", &["--paths", "200000", "--seed", "2"]);
    let s = fd["sensitivity"].as_object().unwrap();
    assert_eq!(
        s.keys().collect::<Vec<_>>(),
        names.iter().collect::<Vec<_>>()
    );
    let z = |a: &Value, b: &Value| {
        let (ma, sa) = (a["mean"].as_f64().unwrap(), a["stderr"].as_f64().unwrap());
        let (mb, sb) = (b["mean"].as_f64().unwrap(), b["stderr"].as_f64().unwrap());
        assert!(sa > 0.0 && sb > 0.0, "{a} {b}");
        (ma - mb).abs() / sa.hypot(sb)
    };
    assert!(z(&fd["intensity"], &other["intensity"]) < 4.0);
    for name in &names {
        let zj = z(&fd["sensitivity"][name], &other["sensitivity"][name]);
        assert!(
            zj < 4.0,
            "{name}: fd {} vs expectation {}, z = {zj}",
            fd["sensitivity"][name],
            other["sensitivity"][name]
        );
    }
}

#[test]
fn fd_step_sets_the_half_step() {
    let path = scene("occluder.toml");
    let run = |extra: &[&str]| {
        let mut args = vec!["--paths", "20000", "--seed", "3"];
        args.extend(extra);
        without_seconds(flat_json_with(&path, "fd", &args))
    };
    let default = run(&[]);
    // The default is 10⁻³, bit for bit.
    assert_eq!(default, run(&["--fd-step", "0.001"]));
    let wide = run(&["--fd-step", "0.01"]);
    // The nominal scene's I is the same paths; every sensitivity moves.
    assert_eq!(default["intensity"], wide["intensity"]);
    for (name, s) in default["sensitivity"].as_object().unwrap() {
        assert_ne!(s["mean"], wide["sensitivity"][name]["mean"], "{name}");
    }
}

/// Asserts `geosens flat --scene <file> <args>` fails with status 1 and
/// every one of `words` on stderr, and prints nothing.
fn assert_flat_rejected(file: &Path, args: &[&str], words: &[&str]) {
    let mut all = vec!["flat", "--scene", file.to_str().unwrap()];
    all.extend(args);
    let out = geosens(&all);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{all:?}: {stderr}");
    assert!(out.stdout.is_empty(), "{all:?} printed to stdout");
    assert!(stderr.starts_with("error: "), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for w in words {
        assert!(stderr.contains(w), "{all:?}: {w:?} not in {stderr:?}");
    }
}

#[test]
fn bad_fd_steps_are_rejected_with_their_name() {
    let path = scene("occluder.toml");
    for (value, shown) in [
        ("0", "fd-step = 0"),
        ("-0.001", "fd-step = -0.001"),
        ("1", "fd-step = 1"),
        ("nan", "fd-step = NaN"),
        ("inf", "fd-step = inf"),
        ("1e-17", "fd-step = 1e-17"),
    ] {
        assert_flat_rejected(
            &path,
            &["--method", "fd", "--paths", "1000", "--fd-step", value],
            &[shown, "from 1e-12", "up to 1"],
        );
    }
    // A step for a method without one is a mistake, not a no-op.
    assert_flat_rejected(
        &path,
        &[
            "--method",
            "rendering",
            "--paths",
            "1000",
            "--fd-step",
            "0.01",
        ],
        &["--fd-step", "--method fd", "rendering"],
    );
    let out = geosens(&[
        "flat",
        "--scene",
        path.to_str().unwrap(),
        "--method",
        "fd",
        "--fd-step",
        "small",
    ]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn an_invalid_displaced_scene_names_the_file_the_parameter_and_finite_differences() {
    // At 10⁻¹ of the scene's size (3), the block moved right by 0.3 crosses
    // the fog.
    let path = scene("three_shapes.toml");
    assert_flat_rejected(
        &path,
        &["--method", "fd", "--paths", "1000", "--fd-step", "0.1"],
        &[
            "three_shapes.toml",
            "fd step too large",
            "finite differences",
            "displace the scene by +0.3 along parameter \"block_tx\"",
            "shapes \"block\" and \"fog\" touch or cross",
            "try a smaller --fd-step",
        ],
    );
}
