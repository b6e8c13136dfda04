//! Scene files: every scene in `scenes/` loads and survives a round trip, and
//! every bad file is a clear error naming the file, the place and the field.
use geosens::Error;
use geosens::flat::Scene;
use geosens::flat::file::{SceneFile, from_json, from_toml, load, to_toml};
use std::path::{Path, PathBuf};

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

/// The TOML scenes shipped in `scenes/`.
fn scene_files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(scenes_dir())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}

fn same(a: &Scene, b: &Scene) {
    assert_eq!(a.shapes(), b.shapes());
    assert_eq!(a.parameters(), b.parameters());
    assert_eq!(a.sensor(), b.sensor());
}

fn message(e: Error) -> String {
    match e {
        Error::Scene(m) => m,
        other => panic!("expected Error::Scene, got {other:?}"),
    }
}

#[test]
fn every_scene_file_loads_round_trips_and_stays_valid_when_moved() {
    let files = scene_files();
    let names: Vec<_> = files
        .iter()
        .map(|p| p.file_stem().unwrap().to_str().unwrap())
        .collect();
    for expected in [
        "absorbing_slab",
        "fog",
        "occluder",
        "polygon_occluder",
        "radiance",
        "reflector",
        "three_shapes",
    ] {
        assert!(names.contains(&expected), "scenes/{expected}.toml missing");
    }
    let readme = std::fs::read_to_string(scenes_dir().join("README.md")).unwrap();
    for path in &files {
        let name = path.file_name().unwrap().to_str().unwrap();
        assert!(readme.contains(name), "scenes/README.md omits {name}");
        let text = std::fs::read_to_string(path).unwrap();
        assert!(text.starts_with("# "), "{name} has no comment header");
        assert!(text.contains("Reference"), "{name} names no reference");

        let scene = load(path).unwrap_or_else(|e| panic!("{e}"));
        assert!(!scene.parameters().is_empty(), "{name} has no parameters");
        // TOML round trip.
        let again = from_toml(&to_toml(&scene)).unwrap_or_else(|e| panic!("{name}: {e}"));
        same(&scene, &again);
        // JSON round trip.
        let json = serde_json::to_string_pretty(&SceneFile::of(&scene)).unwrap();
        let again = from_json(&json).unwrap_or_else(|e| panic!("{name}: {e}"));
        same(&scene, &again);
        // Shapes stay disjoint (and the sensor clear) under the small moves
        // finite differences make.
        for j in 0..scene.parameters().len() {
            for delta in [-0.02, 0.02] {
                scene
                    .displaced(j, delta)
                    .unwrap_or_else(|e| panic!("{name}: parameter {j} moved by {delta}: {e}"));
            }
        }
    }
}

#[test]
fn json_files_load_too() {
    let scene = load(&scenes_dir().join("fog.toml")).unwrap();
    let dir = tempdir("json");
    let path = dir.join("fog.JSON");
    std::fs::write(
        &path,
        serde_json::to_string(&SceneFile::of(&scene)).unwrap(),
    )
    .unwrap();
    same(&scene, &load(&path).unwrap());
    std::fs::remove_dir_all(dir).unwrap();
}

const BASE: &str = r#"
[sensor]
kind = "irradiance"
point = [0.0, 0.0]
normal = [0.0, 1.0]

[[shapes]]
name = "lamp"
vertices = [[-1.0, 2.0], [1.0, 2.0]]
surface = { kind = "emitter", radiance = 1.0 }

[[shapes]]
name = "occluder"
vertices = [[-0.6, 1.0], [0.2, 1.0]]
surface = { kind = "absorber" }

[[shapes]]
name = "slab"
closed = true
vertices = [[-0.5, 1.3], [0.5, 1.3], [0.5, 1.6], [-0.5, 1.6]]
surface = { kind = "transparent" }
medium = { ks = 0.5, ke = 1.0 }

[[parameters]]
name = "occluder_tx"
shape = "occluder"
motion = { kind = "translate_x" }
"#;

#[test]
fn bad_scenes_are_clear_errors() {
    from_toml(BASE).unwrap();
    let box_around_sensor = r#"name = "wall"
closed = true
vertices = [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]]
surface = { kind = "absorber" }

[[shapes]]
name = "occluder""#;
    // (what, text replaced, replacement, substrings the error must contain)
    let cases: &[(&str, &str, &str, &[&str])] = &[
        (
            "unknown field",
            "name = \"occluder\"\n",
            "name = \"occluder\"\ncolour = \"red\"\n",
            &["line 14", "unknown field `colour`"],
        ),
        (
            "unknown field on a variant without fields",
            "kind = \"absorber\"",
            "kind = \"absorber\", albedo = 0.5",
            &["line 15", "unknown field `albedo`"],
        ),
        (
            "unknown field of the file",
            "[sensor]",
            "title = \"x\"\n[sensor]",
            &["line 2", "unknown field `title`"],
        ),
        (
            "missing field",
            ", radiance = 1.0",
            "",
            &["line 10", "surface", "missing field `radiance`"],
        ),
        (
            "missing sensor",
            "[sensor]\nkind = \"irradiance\"\npoint = [0.0, 0.0]\nnormal = [0.0, 1.0]\n",
            "",
            &["missing field `sensor`"],
        ),
        (
            "wrong type",
            "radiance = 1.0",
            "radiance = \"bright\"",
            &[
                "line 10",
                "field `radiance`",
                "invalid type: string \"bright\"",
            ],
        ),
        (
            "wrong type of a vertex",
            "[0.2, 1.0]]",
            "[0.2]]",
            &[
                "line 14",
                "vertices",
                "vertex 1 has 1 coordinates, expected 2",
            ],
        ),
        (
            "wrong type in the sensor",
            "point = [0.0, 0.0]",
            "point = \"origin\"",
            &["field `point`", "invalid type: string \"origin\""],
        ),
        (
            "unknown variant",
            "kind = \"translate_x\"",
            "kind = \"translate_z\"",
            &["line 27", "unknown variant `translate_z`", "translate_x"],
        ),
        (
            "self-intersecting polygon",
            "[[-0.5, 1.3], [0.5, 1.3], [0.5, 1.6], [-0.5, 1.6]]",
            "[[-0.5, 1.3], [0.5, 1.7], [0.5, 1.3], [-0.5, 1.8]]",
            &["\"slab\"", "intersects itself"],
        ),
        (
            "zero-length segment",
            "[[-0.6, 1.0], [0.2, 1.0]]",
            "[[0.2, 1.0], [0.2, 1.0]]",
            &["\"occluder\"", "segment 0 has zero length"],
        ),
        (
            "negative κs",
            "ks = 0.5",
            "ks = -0.1",
            &["\"slab\"", "κs = -0.1"],
        ),
        (
            "κe < κs",
            "ks = 0.5, ke = 1.0",
            "ks = 1.0, ke = 0.5",
            &["\"slab\"", "κe = 0.5", "≥ κs = 1"],
        ),
        (
            "Henyey–Greenstein g out of range",
            "ke = 1.0 }",
            "ke = 1.0, phase = { kind = \"henyey_greenstein\", g = 1.0 } }",
            &["\"slab\"", "g = 1"],
        ),
        (
            "parameter naming a missing shape",
            "shape = \"occluder\"",
            "shape = \"occludr\"",
            &["\"occluder_tx\"", "\"occludr\"", "does not exist"],
        ),
        (
            "sensor inside a wall",
            "name = \"occluder\"",
            box_around_sensor,
            &["sensor", "inside the opaque shape \"wall\""],
        ),
        (
            "sensor on a segment",
            "point = [0.0, 0.0]",
            "point = [0.0, 1.0]",
            &["sensor at [0, 1]", "lies on shape \"occluder\""],
        ),
        (
            "two shapes crossing",
            "[[-0.6, 1.0], [0.2, 1.0]]",
            "[[-0.6, 1.0], [0.2, 2.5]]",
            &["\"lamp\"", "\"occluder\"", "touch or cross"],
        ),
        (
            "two shapes touching",
            "[[-0.6, 1.0], [0.2, 1.0]]",
            "[[-0.6, 1.0], [0.0, 1.3]]",
            &["\"occluder\"", "\"slab\"", "touch or cross"],
        ),
        (
            "medium on an open shape",
            "surface = { kind = \"absorber\" }",
            "surface = { kind = \"transparent\" }\nmedium = { ks = 0.0, ke = 1.0 }",
            &["\"occluder\"", "not closed"],
        ),
        (
            "a TOML syntax error",
            "[[shapes]]\nname = \"slab\"",
            "[[shapes]\nname = \"slab\"",
            &["line 17", "[[shapes]"],
        ),
    ];
    for (what, from, to, wanted) in cases {
        assert!(
            BASE.contains(from),
            "{what}: {from:?} not in the base scene"
        );
        let text = BASE.replacen(from, to, 1);
        let err = message(from_toml(&text).expect_err(what));
        for w in *wanted {
            assert!(err.contains(w), "{what}: {w:?} not in the error:\n{err}");
        }
    }
}

#[test]
fn json_errors_name_the_place_and_the_field() {
    let scene = from_toml(BASE).unwrap();
    let json = serde_json::to_string_pretty(&SceneFile::of(&scene)).unwrap();
    let cases: &[(&str, &str, &str, &[&str])] = &[
        (
            "unknown field",
            "\"closed\": false,",
            "\"closed\": false, \"colour\": 1,",
            &["unknown field `colour`", "line 15 column"],
        ),
        (
            "wrong type",
            "\"closed\": false,",
            "\"closed\": \"no\",",
            &["field `closed`", "expected a boolean", "line 15 column"],
        ),
        (
            "wrong type in a tagged table",
            "\"radiance\": 1.0",
            "\"radiance\": \"x\"",
            &["field `radiance`", "expected f64", "line "],
        ),
        (
            "missing field",
            "\"name\": \"lamp\",",
            "",
            &["missing field `name`", "line "],
        ),
        (
            "syntax error",
            "\"closed\": false,",
            "\"closed\": false",
            &["expected `,` or `}`", "line 16 column"],
        ),
    ];
    for (what, from, to, wanted) in cases {
        assert!(json.contains(from), "{what}: {from:?} not in the JSON");
        let err = message(from_json(&json.replacen(from, to, 1)).expect_err(what));
        for w in *wanted {
            assert!(err.contains(w), "{what}: {w:?} not in the error:\n{err}");
        }
    }
}

/// A fresh directory under the system's temporary directory.
fn tempdir(tag: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("geosens-scene-files-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn file_errors_name_the_file() {
    let dir = tempdir("errors");
    // A parse error: the file, the line and the field.
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, BASE.replace("radiance = 1.0", "radiance = true")).unwrap();
    let err = message(load(&bad).unwrap_err());
    for w in [
        "bad.toml",
        "line 10",
        "field `radiance`",
        "invalid type: boolean",
    ] {
        assert!(err.contains(w), "{w:?} not in:\n{err}");
    }
    // A validation error: the file and the shape.
    let crossing = dir.join("crossing.toml");
    std::fs::write(&crossing, BASE.replace("[0.2, 1.0]]", "[0.2, 2.5]]")).unwrap();
    let err = message(load(&crossing).unwrap_err());
    assert!(
        err.contains("crossing.toml") && err.contains("touch or cross"),
        "{err}"
    );
    // An extension that is neither TOML nor JSON, even for a valid scene.
    let yaml = dir.join("scene.yaml");
    std::fs::write(&yaml, BASE).unwrap();
    let err = message(load(&yaml).unwrap_err());
    assert!(
        err.contains("scene.yaml") && err.contains("extension"),
        "{err}"
    );
    let err = message(load(&dir.join("no_extension")).unwrap_err());
    assert!(
        err.contains("no_extension") && err.contains("extension"),
        "{err}"
    );
    // A missing file.
    let missing = dir.join("missing.toml");
    let err = message(load(&missing).unwrap_err());
    assert!(
        err.contains(&missing.display().to_string()) && err.contains("cannot read"),
        "{err}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}
