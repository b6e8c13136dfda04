//! Adversarial inputs through the binary (issue 11): scene files and CLI
//! values a hostile or careless user might pass. Each run must end (a hang
//! guard kills it after [`LIMIT`]), never abort, and either succeed or exit
//! with status 1 (2 for clap's own parse errors) and a message that names
//! what is wrong. The rod's items of issue 11 (2⁶⁴ − 1 paths, overflow,
//! extreme scales of `exact`, a strongly absorbing rod) are in
//! `tests/cli.rs`, `issue_11_inputs_end_with_an_answer_or_a_message`.
use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Longest any run here may take: far above what each needs, so only a
/// hang (or a run that would never end) reaches it.
const LIMIT: Duration = Duration::from_secs(120);

/// Runs `geosens args`; returns (exit code, stdout, stderr). Panics if the
/// run is killed by a signal (an abort) or outlives [`LIMIT`].
fn geosens(args: &[&str]) -> (i32, String, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_geosens"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the geosens binary runs");
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        if start.elapsed() > LIMIT {
            child.kill().ok();
            panic!("geosens {args:?} did not end within {LIMIT:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().unwrap();
    let code = out
        .status
        .code()
        .unwrap_or_else(|| panic!("geosens {args:?} was killed: {:?}", out.status));
    (
        code,
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Asserts the run failed with `code` and a message holding every `needle`.
fn refused(args: &[&str], code: i32, needles: &[&str]) {
    let (c, _, err) = geosens(args);
    assert_eq!(c, code, "geosens {args:?}: {err}");
    for n in needles {
        assert!(err.contains(n), "geosens {args:?}: {err:?} lacks {n:?}");
    }
    assert!(err.len() < 600, "geosens {args:?}: message too long: {err}");
}

/// A scene file in the temp dir with `text`, named uniquely for the test.
fn scene_file(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("geosens-adversarial-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::File::create(&path)
        .unwrap()
        .write_all(text.as_bytes())
        .unwrap();
    path
}

/// The occluder scene (lamp at y = 2, occluder at y = 1, sensor at the
/// origin) scaled by `s`, with `extra` TOML appended.
fn occluder(s: f64, extra: &str) -> String {
    format!(
        "[sensor]\nkind = \"irradiance\"\npoint = [0.0, 0.0]\nnormal = [0.0, 1.0]\n\
         [[shapes]]\nname = \"lamp\"\nvertices = [[{a:e}, {b:e}], [{c:e}, {b:e}]]\n\
         surface = {{ kind = \"emitter\", radiance = 1.0 }}\n\
         [[shapes]]\nname = \"occ\"\nvertices = [[{d:e}, {e:e}], [{f:e}, {e:e}]]\n\
         surface = {{ kind = \"absorber\" }}\n\
         [[parameters]]\nname = \"occ_tx\"\nshape = \"occ\"\nmotion = {{ kind = \"translate_x\" }}\n{extra}",
        a = -s,
        b = 2.0 * s,
        c = s,
        d = -0.6 * s,
        e = s,
        f = 0.2 * s,
    )
}

fn flat(path: &std::path::Path, method: &str, paths: &str) -> Vec<String> {
    vec![
        "flat".into(),
        "--scene".into(),
        path.to_str().unwrap().into(),
        "--method".into(),
        method.into(),
        "--paths".into(),
        paths.into(),
        "--json".into(),
    ]
}

/// A sensitivity's mean and standard error in a run's JSON line.
fn sensitivity_of(out: &str, name: &str) -> (f64, f64) {
    let v: serde_json::Value = serde_json::from_str(out).unwrap();
    let s = &v["sensitivity"][name];
    (s["mean"].as_f64().unwrap(), s["stderr"].as_f64().unwrap())
}

/// Asserts a reading `(m, sm)` lies within 4 combined standard errors of
/// expectation's `(e, se)`.
fn assert_agrees(label: &str, (m, sm): (f64, f64), (e, se): (f64, f64)) {
    let z = (m - e) / sm.hypot(se);
    assert!(
        z.abs() < 4.0,
        "{label}: {m} ± {sm} against expectation's {e} ± {se}"
    );
}

fn run_flat(path: &std::path::Path, method: &str, paths: &str) -> (i32, String, String) {
    let args = flat(path, method, paths);
    geosens(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

#[test]
fn scenes_at_extreme_scales_run_or_are_refused_naming_the_size() {
    // 1e-13 gave I = 0.743 (true 0.2511) and 1e154 gave 0 from every method.
    // The closed form, the same at every scale: the lamp (y = 2, x ∈ [−1, 1])
    // is seen past the occluder's corner (0.2, 1) from x = 0.4 on, and a
    // lamp seen between the directions θ₁ < θ₂ gives E = sin θ₂ − sin θ₁,
    // sin θ = x/√(x² + 4) at the lamp's point x.
    let sin = |x: f64| x / x.hypot(2.0);
    let exact = sin(1.0) - sin(0.4);
    for s in [1e-13, 1e13] {
        let path = scene_file(&format!("scaled{s:e}.toml"), &occluder(s, ""));
        for method in ["intensity", "rendering", "expectation", "transport"] {
            let (code, out, err) = run_flat(&path, method, "20000");
            assert_eq!(code, 0, "{method} at ×{s:e}: {err}");
            let v: serde_json::Value = serde_json::from_str(&out).unwrap();
            let i = &v["intensity"];
            let (mean, stderr) = (i["mean"].as_f64().unwrap(), i["stderr"].as_f64().unwrap());
            let z = (mean - exact).abs() / stderr;
            assert!(z < 5.0, "{method} at ×{s:e}: {i} vs {exact}");
            // Not toothless: the error bar resolves E to 5 %.
            assert!(
                stderr > 0.0 && stderr < 0.05 * exact,
                "{method} at ×{s:e}: {i}"
            );
        }
    }
    let path = scene_file("huge.toml", &occluder(1e154, ""));
    let args = flat(&path, "intensity", "100");
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    refused(&args, 1, &["size", "rescale"]);
}

#[test]
fn a_scene_path_to_an_endless_stream_is_not_read_forever() {
    let dir = std::env::temp_dir().join(format!("geosens-adversarial-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let link = dir.join("zero.toml");
    let _ = std::fs::remove_file(&link);
    std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
    let args = flat(&link, "intensity", "100");
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    refused(&args, 1, &["larger than", "zero.toml"]);
}

#[test]
fn a_hundred_thousand_shapes_load() {
    // The name check was quadratic: 24–37 s. Linear now (about a second).
    let mut text = String::from(
        "[sensor]\nkind = \"irradiance\"\npoint = [0.0, 0.0]\nnormal = [0.0, 1.0]\n\
         [[shapes]]\nname = \"lamp\"\nvertices = [[-1.0, 2.0], [1.0, 2.0]]\n\
         surface = { kind = \"emitter\", radiance = 1.0 }\n",
    );
    for i in 0..100_000 {
        let (x, y) = (
            -50.0 + (i % 1000) as f64 * 0.1,
            3.0 + (i / 1000) as f64 * 0.1,
        );
        text += &format!(
            "[[shapes]]\nname = \"s{i}\"\nvertices = [[{x:.4}, {y:.4}], [{:.4}, {y:.4}]]\n\
             surface = {{ kind = \"absorber\" }}\n",
            x + 0.05
        );
    }
    let path = scene_file("many.toml", &text);
    let (code, _, err) = run_flat(&path, "intensity", "1000");
    assert_eq!(code, 0, "{err}");
}

#[test]
fn media_that_would_never_let_a_path_out_are_refused() {
    let fog = "[[shapes]]\nname = \"fog\"\nclosed = true\n\
               vertices = [[-1.5, -0.5], [1.5, -0.5], [1.5, 0.5], [-1.5, 0.5]]\n\
               surface = { kind = \"transparent\" }\nmedium = { ks = 900.0, ke = 900.0 }\n";
    let path = scene_file("thick.toml", &occluder(1.0, fog));
    let args = flat(&path, "intensity", "100");
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    refused(&args, 1, &["fog", "scatter", "κs"]);
}

#[test]
fn a_peaked_phase_function_is_refused_by_the_expectation_method_only() {
    let fog = "[[shapes]]\nname = \"fog\"\nclosed = true\n\
               vertices = [[-1.5, 0.3], [1.5, 0.3], [1.5, 0.6], [-1.5, 0.6]]\n\
               surface = { kind = \"transparent\" }\n\
               medium = { ks = 1.0, ke = 1.2, phase = { kind = \"henyey_greenstein\", g = 0.99999999 } }\n";
    let path = scene_file("peaked.toml", &occluder(1.0, fog));
    let args = flat(&path, "expectation", "100");
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    refused(
        &args,
        1,
        &["fog", "g = 0.99999999", "rendering or transport"],
    );
    for method in ["rendering", "transport", "intensity"] {
        let (code, _, err) = run_flat(&path, method, "2000");
        assert_eq!(code, 0, "{method}: {err}");
    }
}

/// A named pipe as a scene, an OBJ or a state is refused at once: with
/// no writer, `open` would block forever, without a word. A state path
/// to an endless stream stops at its first byte.
#[test]
fn pipes_and_endless_states_are_refused_at_once() {
    let dir = std::env::temp_dir().join(format!("geosens-adversarial-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = |name: &str| {
        let path = dir.join(name);
        let _ = std::fs::remove_file(&path);
        let made = Command::new("mkfifo").arg(&path).status().unwrap();
        assert!(made.success());
        path
    };
    let scene = fifo("pipe.toml");
    let args = flat(&scene, "intensity", "100");
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    refused(&args, 1, &["pipe.toml", "named pipe"]);
    fifo("pipe.obj");
    let mesh = scene_file(
        "pipe_mesh.toml",
        "[sensor]\nkind = \"irradiance\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n\
         [[shapes]]\nname = \"lamp\"\nmesh = \"pipe.obj\"\n\
         surface = { kind = \"emitter\", radiance = 1.0 }\n",
    );
    let m = mesh.to_str().unwrap();
    refused(
        &[
            "mesh",
            "--scene",
            m,
            "--method",
            "intensity",
            "--paths",
            "100",
        ],
        1,
        &["pipe.obj", "named pipe"],
    );
    let state = fifo("pipe.json");
    refused(
        &["merge", state.to_str().unwrap()],
        1,
        &["pipe.json", "named pipe"],
    );
    let zero = dir.join("zero_state.json");
    let _ = std::fs::remove_file(&zero);
    std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
    refused(
        &["merge", zero.to_str().unwrap()],
        1,
        &["zero_state.json", "`{`"],
    );
}

/// A file whose dimension its points do not tell (empty, a misspelt or
/// short sensor point) gets the loader's own message, not advice to use
/// the other command; a TOML syntax error gives its line.
#[test]
fn scene_faults_are_named_by_the_loader_with_their_line() {
    let text = occluder(1.0, "");
    let cases = [
        ("empty.toml", String::new(), "missing field"),
        (
            "typo.toml",
            text.replace("point = [0.0, 0.0]", "pointt = [0.0, 0.0]"),
            "unknown field `pointt`",
        ),
        (
            "short.toml",
            text.replace("point = [0.0, 0.0]", "point = [0.0]"),
            "invalid length 1",
        ),
        (
            "syntax.toml",
            text.replace("kind = \"irradiance\"", "kind = \"irradiance"),
            "line 2",
        ),
    ];
    for (name, body, needle) in cases {
        let path = scene_file(name, &body);
        let args = flat(&path, "intensity", "100");
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        refused(&args, 1, &[needle]);
        let (_, _, err) = geosens(&args);
        assert!(!err.contains("geosens mesh"), "{name}: {err}");
    }
    // A flatland file given to `mesh` with its sensor point misspelt is
    // still told by its vertices.
    let typo = scene_file(
        "typo2.toml",
        &text.replace("point = [0.0, 0.0]", "pointt = [0.0, 0.0]"),
    );
    refused(
        &[
            "mesh",
            "--scene",
            typo.to_str().unwrap(),
            "--method",
            "intensity",
        ],
        1,
        &["flatland", "geosens flat"],
    );
}

#[test]
fn numbers_in_messages_are_short_and_flags_name_themselves() {
    refused(
        &[
            "rod",
            "--method",
            "intensity",
            "--ks",
            "1",
            "--ke",
            "2",
            "--length",
            "2",
            "--x",
            "3e300",
            "--omega",
            "1",
        ],
        1,
        &["x = 3e300"],
    );
    refused(
        &[
            "rod", "--method", "fd", "--ks", "0", "--ke", "0", "--length", "1e308", "--x", "1e308",
            "--omega", "-1",
        ],
        1,
        &["x = 1e308"],
    );
    let path = scene_file("ok.toml", &occluder(1.0, ""));
    let p = path.to_str().unwrap();
    refused(
        &[
            "flat",
            "--scene",
            p,
            "--method",
            "intensity",
            "--paths",
            "-5",
        ],
        2,
        &["--paths", "-5"],
    );
    refused(
        &[
            "flat",
            "--scene",
            p,
            "--method",
            "intensity",
            "--threads",
            "-1",
        ],
        2,
        &["--threads"],
    );
    // A normal of [1e308, 1e308] has a direction (its length overflows).
    let big = occluder(1.0, "").replace("normal = [0.0, 1.0]", "normal = [1e308, 1e308]");
    let path = scene_file("big_normal.toml", &big);
    let (code, _, err) = run_flat(&path, "intensity", "1000");
    assert_eq!(code, 0, "{err}");
}

#[test]
fn finite_differences_across_a_change_of_view_are_flagged() {
    // An occluder's corner 1e-4 above the sensor: the default step swings it
    // past the zenith; the quotient (−223.5 for an exact −10⁴) used to be
    // reported reliable. Now a warning, `reliable: false` and the caveat.
    let text =
        occluder(1.0, "").replace("[[-6e-1, 1e0], [2e-1, 1e0]]", "[[-0.6, 1e-4], [0.0, 1e-4]]");
    assert!(text.contains("1e-4"), "{text}");
    let path = scene_file("corner_over_sensor.toml", &text);
    let (code, out, err) = run_flat(&path, "fd", "20000");
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("warning") && err.contains("occ_tx"), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let s = &v["sensitivity"]["occ_tx"];
    assert_eq!(s["reliable"], false, "{s}");
    assert!(s["caveat"].as_str().unwrap().contains("--fd-step"), "{s}");
    // A step inside the corner's height: no caveat.
    let args = [
        "flat",
        "--scene",
        path.to_str().unwrap(),
        "--method",
        "fd",
        "--fd-step",
        "1e-6",
        "--paths",
        "20000",
        "--json",
    ];
    let (code, out, err) = geosens(&args);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("warning"), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(v["sensitivity"]["occ_tx"].get("caveat").is_none(), "{v}");
}

#[test]
fn a_rod_whose_paths_would_never_end_is_refused_but_solved_exactly() {
    // Conservative, κs × length = 10⁴: ~10⁸ collisions per path.
    let rod = [
        "--ks", "50", "--ke", "50", "--length", "200", "--x", "100", "--omega", "1",
    ];
    for method in ["intensity", "expectation", "rendering", "transport", "fd"] {
        let mut args = vec!["rod", "--method", method, "--paths", "100"];
        args.extend(rod);
        refused(&args, 1, &["collide", "--method exact"]);
    }
    let mut args = vec!["rod", "--method", "exact", "--json"];
    args.extend(rod);
    let (code, out, err) = geosens(&args);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("\"intensity\""), "{out}");
}

#[test]
fn a_probe_no_path_reaches_prints_no_infinite_z_and_is_unreliable() {
    // At x = 1.9999 looking back no path of 20000 contributes: 0 ± 0, which
    // the table used to call reliable with z = inf.
    let (code, out, err) = geosens(&[
        "rod",
        "--method",
        "expectation",
        "--ks",
        "2.1",
        "--ke",
        "3",
        "--length",
        "2",
        "--x",
        "1.9999",
        "--omega",
        "-1",
        "--paths",
        "20000",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(!out.contains("inf"), "{out}");
    let row = out.lines().find(|l| l.starts_with("∂I/∂length")).unwrap();
    let cells: Vec<&str> = row.split_whitespace().collect();
    // quantity, mean, stderr, nonzero, vov, max_share, reliable, exact, z
    assert_eq!((cells[3], cells[6], cells[8]), ("0", "no", "-"), "{row}");
}

/// A scene moved more than 10⁶ of its sizes from the origin keeps too few
/// digits of its geometry (a sweep found a moving fog's derivative 86σ off
/// at 5·10⁷ sizes, and a triangle "enclosing no area"): it is refused with
/// a message naming the offset, in flatland and in 3D; at 10⁵ sizes it
/// loads.
#[test]
fn a_scene_far_from_the_origin_is_refused_naming_the_offset() {
    use glam::{DVec2, DVec3};
    let base = geosens::flat::file::load(
        &PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/occluder.toml"),
    )
    .unwrap();
    let flat_at = |offset: f64| {
        let shift = DVec2::new(offset, 0.0);
        let shapes = base
            .shapes()
            .iter()
            .map(|s| geosens::flat::Shape {
                vertices: s.vertices.iter().map(|v| *v + shift).collect(),
                ..s.clone()
            })
            .collect();
        let parameters = base
            .parameters()
            .iter()
            .map(|p| geosens::flat::Parameter {
                motion: match p.motion {
                    geosens::flat::Motion::Rotate { pivot } => geosens::flat::Motion::Rotate {
                        pivot: pivot.map(|c| c + shift),
                    },
                    geosens::flat::Motion::Scale { pivot } => geosens::flat::Motion::Scale {
                        pivot: pivot.map(|c| c + shift),
                    },
                    m => m,
                },
                ..p.clone()
            })
            .collect();
        let sensor = match base.sensor() {
            geosens::flat::Sensor::Irradiance { point, normal } => {
                geosens::flat::Sensor::Irradiance {
                    point: point + shift,
                    normal,
                }
            }
            s => s,
        };
        geosens::flat::Scene::new(shapes, parameters, sensor)
    };
    let size = base.size();
    assert!(flat_at(1e5 * size).is_ok());
    let err = flat_at(1e7 * size).unwrap_err().to_string();
    assert!(
        err.contains("from the origin") && err.contains("nearer"),
        "{err}"
    );

    use geosens::mesh::cases::{lamp, up};
    let mesh_at = |offset: f64| {
        let shift = DVec3::new(0.0, offset, 0.0);
        let l = lamp();
        let lamp = geosens::mesh::Shape {
            vertices: l.vertices.iter().map(|v| *v + shift).collect(),
            ..l
        };
        geosens::mesh::Scene::new(vec![lamp], Vec::new(), up())
    };
    assert!(mesh_at(1e5).is_ok());
    let err = mesh_at(1e7).unwrap_err().to_string();
    assert!(
        err.contains("from the origin") && err.contains("nearer"),
        "{err}"
    );
}

#[test]
fn a_closed_lossless_reflector_does_not_trap_the_nested_paths() {
    // A closed convex reflector of albedo 1 (found by a random-scene
    // campaign). A path vertex on one of its faces drew that face's own
    // corner, seen exactly edge-on (lobe 0) but at a cosine of 1e-16 by
    // rounding; the nested path leaving the next face there started on its
    // far side, inside the polygon, and walked 10⁵ reflections before the
    // roulette could end it: rendering and transport took about 1000× the
    // time of the other methods (12 s for 2·10⁴ paths on one thread, so
    // these 4·10⁵ paths would outlive the hang guard).
    let path = scene_file(
        "lossless.toml",
        "[sensor]\nkind = \"irradiance\"\npoint = [0.0, 0.0]\n\
         normal = [-0.9951624132880865, -0.09824342817019219]\n\
         [[shapes]]\nname = \"lamp\"\n\
         vertices = [[-2.738066331391881, -1.740573772517029], [0.16748182229351794, -1.4856885189949409]]\n\
         surface = { kind = \"emitter\", radiance = 1.568 }\n\
         [[shapes]]\nname = \"refl0\"\nclosed = true\n\
         vertices = [[-1.7556576693911842, -0.5261664234408091], [-1.7168845862765025, -0.6904653556140443], \
         [-1.1944774626169993, -0.1640026187320392], [-1.28133815205055, 0.0693876025203457]]\n\
         surface = { kind = \"reflector\", albedo = 1.0 }\n\
         [[parameters]]\nname = \"refl0_ty\"\nshape = \"refl0\"\nmotion = { kind = \"translate_y\" }\n",
    );
    let reading = |method: &str| {
        let mut args = flat(&path, method, "400000");
        args.extend(["--threads".into(), "1".into()]);
        let (code, out, err) = geosens(&args.iter().map(String::as_str).collect::<Vec<_>>());
        assert_eq!(code, 0, "{method}: {err}");
        sensitivity_of(&out, "refl0_ty")
    };
    // The reference: expectation, whose warp draws no corner.
    let e = reading("expectation");
    for method in ["rendering", "transport"] {
        assert_agrees(method, reading(method), e);
    }
}

#[test]
fn a_sight_line_along_a_face_does_not_carry_paths_into_a_solid() {
    // A closed lossless reflector with the sensor in the plane of its top
    // face (a random-scene campaign's). The jump at the near top corner
    // sends a path along that face; it met the far face exactly at its
    // corner, from behind by rounding, and the reflection turned it inside
    // the solid, where it walked 10⁵ reflections: rendering and transport
    // took 20 s (flatland) and 45 s (3D) for 2·10⁴ paths, 10³–10⁴ times the
    // other methods, and read the wrong sign on the edge-on face's motion
    // (3D tz: −0.037 against expectation's +0.067). The back of a solid is
    // now black. Before, each rendering and transport run below outlived
    // the hang guard.
    let flat_scene = scene_file(
        "solid_flat.toml",
        "[sensor]\nkind = \"irradiance\"\npoint = [2.0, 1.0]\nnormal = [-1.0, 0.0]\n\
         [[shapes]]\nname = \"lamp\"\nvertices = [[-1.0, 3.0], [3.0, 3.0]]\n\
         surface = { kind = \"emitter\", radiance = 1.0 }\n\
         [[shapes]]\nname = \"box\"\nclosed = true\n\
         vertices = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]\n\
         surface = { kind = \"reflector\", albedo = 1.0 }\n\
         [[parameters]]\nname = \"box_ty\"\nshape = \"box\"\nmotion = { kind = \"translate_y\" }\n",
    );
    // The unit cube [0, 1]³ as the shipped cases build boxes.
    let unit_cube = geosens::mesh::cases::box_shape(
        "box",
        std::array::from_fn(|i| {
            glam::DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64)
        }),
        geosens::mesh::Surface::Absorber,
        None,
    );
    let rows = |r: Vec<String>| r.join(", ");
    let vertices = rows(
        unit_cube
            .vertices
            .iter()
            .map(|v| format!("{:?}", v.to_array()))
            .collect(),
    );
    let triangles = rows(
        unit_cube
            .triangles
            .iter()
            .map(|t| format!("{t:?}"))
            .collect(),
    );
    let mesh_scene = scene_file(
        "solid_mesh.toml",
        &format!(
            "[sensor]\nkind = \"irradiance\"\npoint = [2.0, 0.5, 1.0]\nnormal = [-1.0, 0.0, 0.0]\n\
             [[shapes]]\nname = \"lamp\"\n\
             vertices = [[-1.0, -1.0, 3.0], [3.0, -1.0, 3.0], [3.0, 2.0, 3.0], [-1.0, 2.0, 3.0]]\n\
             triangles = [[0, 1, 2], [0, 2, 3]]\n\
             surface = {{ kind = \"emitter\", radiance = 1.0 }}\n\
             [[shapes]]\nname = \"box\"\nvertices = [{}]\ntriangles = [{}]\n\
             surface = {{ kind = \"reflector\", albedo = 1.0 }}\n\
             [[parameters]]\nname = \"box_tx\"\nshape = \"box\"\nmotion = {{ kind = \"translate_x\" }}\n\
             [[parameters]]\nname = \"box_tz\"\nshape = \"box\"\nmotion = {{ kind = \"translate_z\" }}\n",
            vertices, triangles
        ),
    );
    // Each run is 2·10³–10⁴ times shorter than the guard now. The sensor
    // in a face's plane is a kink for the face's normal motion (caveated,
    // each method returns a different mix of the two sides), so the
    // methods are compared on a motion along the face: the 3D box's x.
    for (command, scene, paths, name) in [
        ("flat", &flat_scene, "200000", None),
        ("mesh", &mesh_scene, "100000", Some("box_tx")),
    ] {
        let reading = |method: &str| {
            let scene = scene.to_str().unwrap();
            let args = [
                command,
                "--scene",
                scene,
                "--method",
                method,
                "--paths",
                paths,
                "--seed",
                "3",
                "--threads",
                "1",
                "--json",
            ];
            let (code, out, err) = geosens(&args);
            assert_eq!(code, 0, "{command} {method}: {err}");
            name.map(|n| sensitivity_of(&out, n))
        };
        let e = reading("expectation");
        for method in ["rendering", "transport"] {
            if let (Some(m), Some(e)) = (reading(method), e) {
                assert_agrees(&format!("{command} {method}"), m, e);
            }
        }
    }
}

#[test]
fn a_row_with_too_many_numbers_is_refused_not_cut() {
    // The TOML reader took the first three of `[0, 1, 2, 3]` and dropped the
    // rest: a quad given as one row became one triangle, half the
    // occluder, and the run answered for that (0.2024 against 0.1738).
    let quad = "[sensor]\nkind = \"irradiance\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n\
         [[shapes]]\nname = \"lamp\"\n\
         vertices = [[-0.5, -0.5, 2.0], [0.5, -0.5, 2.0], [0.5, 0.5, 2.0], [-0.5, 0.5, 2.0]]\n\
         triangles = [[0, 1, 2], [0, 2, 3]]\nsurface = { kind = \"emitter\", radiance = 1.0 }\n\
         [[shapes]]\nname = \"occ\"\n\
         vertices = [[0.0, 0.0, 1.0], [0.3, 0.0, 1.0], [0.3, 0.3, 1.0], [0.0, 0.3, 1.0]]\n\
         triangles = [[0, 1, 2, 3]]\nsurface = { kind = \"absorber\" }\n";
    let path = scene_file("quad_row.toml", quad);
    let args = [
        "mesh",
        "--scene",
        path.to_str().unwrap(),
        "--method",
        "intensity",
    ];
    refused(
        &args,
        1,
        &["triangle 0 has 4 indices, expected 3", "line 13"],
    );
    let path = scene_file(
        "long_vertex.toml",
        &quad
            .replace("[0.3, 0.0, 1.0]", "[0.3, 0.0, 1.0, 7.0]")
            .replace("[[0, 1, 2, 3]]", "[[0, 1, 2], [0, 2, 3]]"),
    );
    let args = [
        "mesh",
        "--scene",
        path.to_str().unwrap(),
        "--method",
        "intensity",
    ];
    refused(&args, 1, &["vertex 1 has 4 coordinates, expected 3"]);
    let flat_scene = scene_file(
        "flat_z.toml",
        &occluder(1.0, "").replacen("vertices = [[", "vertices = [[0.0, ", 1),
    );
    let args = [
        "flat",
        "--scene",
        flat_scene.to_str().unwrap(),
        "--method",
        "intensity",
    ];
    refused(&args, 1, &["vertex 0 has 3 coordinates, expected 2"]);
}

#[test]
fn an_image_too_large_for_memory_is_refused_before_the_run() {
    // 8192² pixels (inside the camera's limits) of 61 images each need
    // about 10¹² bytes: the run aborted on a failed allocation ("memory
    // allocation of 896 bytes failed", a Python interpreter with it) after
    // minutes; now it is refused at once, saying what it needs.
    let mut scene = String::from(
        "[sensor]\nkind = \"camera\"\nposition = [0.1, 0.1, 0.5]\nlook_at = [0.1, 0.1, 2.0]\n\
         up = [0.0, 1.0, 0.0]\nfov_deg = 90.0\nwidth = 8192\nheight = 8192\n\
         [[shapes]]\nname = \"lamp\"\n\
         vertices = [[-0.5, -0.5, 2.0], [0.5, -0.5, 2.0], [0.5, 0.5, 2.0], [-0.5, 0.5, 2.0]]\n\
         triangles = [[0, 1, 2], [0, 2, 3]]\nsurface = { kind = \"emitter\", radiance = 1.0 }\n\
         [[shapes]]\nname = \"tri\"\nvertices = [[0.0, 0.0, 1.0], [0.3, 0.0, 1.0], [0.0, 0.3, 1.0]]\n\
         triangles = [[0, 1, 2]]\nsurface = { kind = \"absorber\" }\n",
    );
    for j in 0..60 {
        scene += &format!(
            "[[parameters]]\nname = \"p{j}\"\nshape = \"tri\"\nmotion = {{ kind = \"translate_x\" }}\n"
        );
    }
    let path = scene_file("huge_camera.toml", &scene);
    let out = path.with_extension("out");
    let args = [
        "render",
        "--scene",
        path.to_str().unwrap(),
        "--method",
        "rendering",
        "--spp",
        "2",
        "--out",
        out.to_str().unwrap(),
    ];
    refused(
        &args,
        1,
        &["67108864 pixels × 61 quantities", "GB of memory is free"],
    );
    let written = std::fs::read_dir(&out).map_or(0, |d| d.count());
    assert_eq!(written, 0, "nothing is written");
}

#[test]
fn an_output_path_that_cannot_be_written_is_refused_before_the_run() {
    // Found only once the work was done: a shard's state, a rendering's
    // images or the comparison's figures were lost after the whole run.
    // A regular file stands where a folder should be.
    let blocker = scene_file("not_a_folder", "");
    let under = |name: &str| blocker.join(name).to_str().unwrap().to_owned();
    let occluder = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/occluder.toml");
    let camera = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/mesh/camera_shadow.toml"
    );
    let state = under("x.json");
    refused(
        &[
            "flat",
            "--scene",
            occluder,
            "--method",
            "rendering",
            "--paths",
            "100000000",
            "--state",
            &state,
        ],
        1,
        &["cannot write to", "x.json"],
    );
    let images = under("images");
    refused(
        &[
            "render",
            "--scene",
            camera,
            "--method",
            "rendering",
            "--spp",
            "100000",
            "--out",
            &images,
        ],
        1,
        &["cannot write to", "images"],
    );
    let figures = under("figures");
    refused(
        &["compare", "--figures", &figures],
        1,
        &["cannot write to", "figures"],
    );
    let folder = blocker.parent().unwrap().to_str().unwrap().to_owned();
    refused(
        &[
            "flat",
            "--scene",
            occluder,
            "--method",
            "rendering",
            "--state",
            &folder,
        ],
        1,
        &["is a folder"],
    );
}

#[test]
fn a_pivot_far_from_its_shape_is_refused() {
    // A rotation about a pivot 10¹⁶⁰ away read 0 with no warning, one
    // 10¹⁰⁰ away printed NaN diagnostics: such a motion is a translation
    // of enormous speed. 10⁶ sizes away is the bound, as for the scene's
    // offset from the origin.
    for (far, refused_here) in [(1e160, true), (1e100, true), (1e5, false)] {
        let extra = format!(
            "[[parameters]]\nname = \"spin\"\nshape = \"occ\"\n\
             motion = {{ kind = \"rotate\", pivot = [{far:e}, 1.0] }}\n"
        );
        let path = scene_file("far_pivot.toml", &occluder(1.0, &extra));
        let args = flat(&path, "rendering", "2000");
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        if refused_here {
            refused(&args, 1, &["\"spin\"", "pivot lies", "at most"]);
        } else {
            let (code, _, err) = geosens(&args);
            assert_eq!(code, 0, "{err}");
        }
    }
    use geosens::mesh::cases::{lamp, square_shape, up};
    use glam::DVec3;
    let square = square_shape(
        "sq",
        DVec3::new(0.0, 0.0, 1.0),
        0.1,
        geosens::mesh::Surface::Absorber,
    );
    let spin = |far: f64| geosens::mesh::Parameter {
        name: "spin".into(),
        shape: "sq".into(),
        motion: geosens::mesh::Motion::Rotate {
            axis: DVec3::Z,
            pivot: Some(DVec3::new(far, 0.0, 1.0)),
        },
        bounds: None,
    };
    let scene =
        |far| geosens::mesh::Scene::new(vec![lamp(), square.clone()], vec![spin(far)], up());
    assert!(scene(1e5).is_ok());
    let err = scene(1e200).unwrap_err().to_string();
    assert!(err.contains("pivot lies 1e200"), "{err}");
}

#[test]
fn a_json_scene_with_a_byte_order_mark_loads() {
    // Some editors start a UTF-8 file with U+FEFF; TOML allows it, and the
    // JSON reader said "expected value at line 1 column 1".
    let json = "\u{feff}{\"sensor\": {\"kind\": \"irradiance\", \"point\": [0.0, 0.0], \
         \"normal\": [0.0, 1.0]}, \"shapes\": [{\"name\": \"lamp\", \
         \"vertices\": [[-1.0, 2.0], [1.0, 2.0]], \"surface\": {\"kind\": \"emitter\", \
         \"radiance\": 1.0}}]}";
    let path = scene_file("bom.json", json);
    let args = flat(&path, "intensity", "1000");
    let (code, out, err) = geosens(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("\"intensity\""), "{out}");
}
