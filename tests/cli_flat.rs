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
