//! `geosens mesh`: the JSON line of `flat` with the gradient axes x, y, z,
//! agreement of every method with the closed form on the shipped occluder
//! scene, reproducibility whatever the thread count, clear errors, and the
//! same result from files with a byte-order mark or CRLF line ends.
use geosens::mesh::exact::{occluded_irradiance_with_gradient, sensitivity};
use geosens::mesh::file;
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
        .join("scenes/mesh")
        .join(name)
}

fn mesh_json(scene_file: &Path, method: &str, extra: &[&str]) -> Value {
    let path = scene_file.to_str().unwrap();
    let mut args = vec!["mesh", "--scene", path, "--method", method, "--json"];
    args.extend_from_slice(extra);
    let out = geosens(&args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{method} failed: {stderr}");
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert_eq!(stdout.lines().count(), 1, "not one line: {stdout}");
    serde_json::from_str(&stdout).unwrap()
}

/// Every method on scenes/mesh/occluder.toml against the closed form
/// computed from the loaded scene's own vertices (Lambert's formula with
/// the occluder's shadow clipped out of the lamp).
#[test]
fn every_method_matches_the_closed_form_on_the_shipped_occluder() {
    let path = scene("occluder.toml");
    let s = file::load(&path).unwrap();
    let poly = |k: usize| -> Vec<glam::DVec3> {
        // The squares' outlines: triangles [0,1,2],[0,2,3] in the files.
        let sh = &s.shapes()[k];
        let t = &sh.triangles;
        let mut order = vec![t[0][0], t[0][1], t[0][2]];
        let extra = t[1].iter().find(|v| !order.contains(v)).copied().unwrap();
        order.insert(3, extra);
        order.iter().map(|&i| sh.vertices[i as usize]).collect()
    };
    let (lamp, occ) = (poly(0), poly(1));
    let (e, g) =
        occluded_irradiance_with_gradient(glam::DVec3::ZERO, glam::DVec3::Z, &lamp, &occ, 1.0)
            .unwrap();
    for method in ["intensity", "rendering", "transport", "expectation", "fd"] {
        let v = mesh_json(&path, method, &["--paths", "200000", "--seed", "3"]);
        assert_eq!(v["method"], method);
        let z = |x: &Value, exact: f64| {
            (x["mean"].as_f64().unwrap() - exact) / x["stderr"].as_f64().unwrap()
        };
        assert!(z(&v["intensity"], e).abs() < 4.0, "{method}: {v}");
        let sens = v["sensitivity"].as_object().unwrap();
        if method == "intensity" {
            assert!(sens.is_empty());
            continue;
        }
        let names: Vec<&String> = sens.keys().collect();
        let declared: Vec<String> = s.parameters().iter().map(|p| p.name.clone()).collect();
        assert_eq!(
            names,
            declared.iter().collect::<Vec<_>>(),
            "declaration order"
        );
        for (p, param) in s.parameters().iter().enumerate() {
            let exact = sensitivity(&g, &occ, param.motion);
            let x = &sens[&param.name];
            assert!(
                z(x, exact).abs() < 4.0,
                "{method} {}: {x} vs {exact}",
                param.name
            );
            let _ = p;
        }
        let grad = &v["gradient"];
        if method == "transport" {
            for axis in ["x", "y", "z"] {
                assert!(grad[axis]["mean"].is_f64(), "{v}");
            }
        } else {
            assert!(grad.is_null(), "{method}: {v}");
        }
    }
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let path = scene("cube_shadow.toml");
    let run = |threads: &str| {
        let mut v = mesh_json(
            &path,
            "expectation",
            &["--paths", "20000", "--seed", "7", "--threads", threads],
        );
        v["seconds"] = Value::Null;
        v
    };
    assert_eq!(run("1"), run("3"));
}

#[test]
fn bad_input_is_a_clear_error() {
    let dir = std::env::temp_dir().join(format!("geosens-cli-mesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let missing_obj = dir.join("missing_obj.toml");
    std::fs::write(
        &missing_obj,
        "[sensor]\nkind = \"irradiance\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n\
         [[shapes]]\nname = \"occ\"\nmesh = \"nowhere.obj\"\nsurface = { kind = \"absorber\" }\n",
    )
    .unwrap();
    let no_file = dir.join("no_such_scene.toml");
    for (file, needle) in [
        (&missing_obj, "nowhere.obj"),
        (&no_file, "no_such_scene.toml"),
    ] {
        let out = geosens(&[
            "mesh",
            "--scene",
            file.to_str().unwrap(),
            "--method",
            "rendering",
        ]);
        assert_eq!(out.status.code(), Some(1));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.starts_with("error:") && err.contains(needle), "{err}");
    }
    // A phase function too peaked for the expectation method is refused
    // for it (as in flatland), not for rendering.
    let fog = std::fs::read_to_string(scene("fog_cube.toml"))
        .unwrap()
        .replace("g = 0.3", "g = 0.999");
    let peaked = dir.join("peaked.toml");
    std::fs::write(&peaked, fog).unwrap();
    let run = |method: &str| {
        geosens(&[
            "mesh",
            "--scene",
            peaked.to_str().unwrap(),
            "--method",
            method,
            "--paths",
            "1000",
        ])
    };
    let out = run("expectation");
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("too peaked"));
    assert!(run("rendering").status.success());
    // --fd-step belongs to fd.
    let out = geosens(&[
        "mesh",
        "--scene",
        scene("occluder.toml").to_str().unwrap(),
        "--method",
        "rendering",
        "--fd-step",
        "1e-4",
    ]);
    assert_eq!(out.status.code(), Some(1));
    std::fs::remove_dir_all(&dir).ok();
}

/// A UTF-8 byte-order mark (as some editors write) or Windows line ends in
/// the scene file or in its OBJ mesh change nothing: the same scene loads
/// and the run prints the same numbers. A mark before an OBJ's first `v`
/// used to hide that vertex, shifting every face index by one.
#[test]
fn a_byte_order_mark_or_crlf_line_ends_change_nothing() {
    let dir = std::env::temp_dir().join(format!("geosens-cli-mesh-bom-{}", std::process::id()));
    let toml = std::fs::read_to_string(scene("occluder.toml")).unwrap();
    let obj = std::fs::read_to_string(scene("occluder.obj")).unwrap();
    // The mesh starts with its first vertex (no comment, no object name),
    // so that a mark would stick to that `v`.
    // A fifth vertex, unused, lets a lost first one go unnoticed (the face
    // `f 1 2 3 4` then reads vertices 2 to 5, still a square's worth).
    let obj = format!("{}v -0.05 0.0 1.0\n", &obj[obj.find("\nv ").unwrap() + 1..]);
    let json = file::to_json(&file::load(&scene("occluder.toml")).unwrap()).unwrap();
    let bom = |s: &str| format!("\u{feff}{s}");
    let crlf = |s: &str| s.replace('\n', "\r\n");
    let run = |name: &str, scene_text: String, ext: &str, obj_text: String| {
        let d = dir.join(name);
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join("occluder.obj"), obj_text).unwrap();
        let path = d.join(format!("scene.{ext}"));
        std::fs::write(&path, scene_text).unwrap();
        let loaded = file::MeshFile::of(&file::load(&path).unwrap());
        let mut v = mesh_json(&path, "rendering", &["--paths", "4000", "--seed", "3"]);
        v["seconds"] = Value::Null;
        (loaded, v)
    };
    let plain = run("plain", toml.clone(), "toml", obj.clone());
    for (name, scene_text, ext, obj_text) in [
        ("obj_bom", toml.clone(), "toml", bom(&obj)),
        ("obj_crlf", toml.clone(), "toml", crlf(&obj)),
        ("obj_bom_crlf", toml.clone(), "toml", bom(&crlf(&obj))),
        ("toml_bom_crlf", bom(&crlf(&toml)), "toml", obj.clone()),
        ("json", json.clone(), "json", obj.clone()),
        ("json_bom_crlf", bom(&crlf(&json)), "json", bom(&obj)),
    ] {
        let other = run(name, scene_text, ext, obj_text);
        assert_eq!(other.0, plain.0, "{name}: a different scene");
        assert_eq!(other.1, plain.1, "{name}: a different result");
    }
    std::fs::remove_dir_all(&dir).ok();
}
