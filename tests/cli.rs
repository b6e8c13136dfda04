//! The `geosens` binary: JSON shape, agreement with the library and the exact
//! solution, thread-count independence, and rejection of bad input.
use geosens::rod::{Direction, Probe, Rod, exact};
use geosens::{Estimate, Method, Quantity, RunConfig, RunResult, run};
use serde_json::Value;
use std::iter::Peekable;
use std::process::{Command, Output};
use std::sync::Arc;

/// The thick rod and probe most tests use.
const PROBE: [&str; 10] = [
    "--ks", "2.1", "--ke", "3", "--length", "2", "--x", "1.9", "--omega", "-1",
];

/// Runs the binary with `args`.
fn geosens(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_geosens"))
        .args(args)
        .output()
        .expect("the geosens binary runs")
}

/// `geosens rod --method <method> <PROBE> <extra> --json`: its stdout, which
/// must be one line.
fn json_line(method: &str, extra: &[&str]) -> String {
    let mut args = vec!["rod", "--method", method];
    args.extend(PROBE);
    args.extend(extra);
    args.push("--json");
    let out = geosens(&args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{args:?} failed: {stderr}");
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert_eq!(stdout.lines().count(), 1, "not one line: {stdout}");
    stdout.trim_end().to_owned()
}

/// The parsed JSON line.
fn json(method: &str, extra: &[&str]) -> Value {
    serde_json::from_str(&json_line(method, extra)).expect("valid JSON")
}

/// `v[key]["mean"]` and `v[key]["stderr"]`.
fn mean_err(v: &Value, key: &str) -> (f64, f64) {
    (
        v[key]["mean"].as_f64().unwrap(),
        v[key]["stderr"].as_f64().unwrap(),
    )
}

/// The exact solution at [`PROBE`].
fn exact_at_probe() -> exact::Solution {
    let rod = Rod::new(2.1, 3.0, 2.0).unwrap();
    exact::solve(&rod, 1.9, Direction::Left)
}

#[test]
fn json_has_exactly_the_documented_keys_and_nulls() {
    // (method, which of intensity / sensitivity / gradient_x it estimates)
    let cases = [
        ("exact", [true, true, true]),
        ("intensity", [true, false, false]),
        ("expectation", [true, true, false]),
        ("rendering", [true, true, false]),
        ("transport", [true, true, true]),
        ("fd", [true, true, false]),
    ];
    for (method, present) in cases {
        let v = json(method, &["--paths", "1000"]);
        let obj = v.as_object().unwrap();
        let keys: Vec<&str> = obj.keys().map(String::as_str).collect();
        let mut expected = vec![
            "method",
            "intensity",
            "sensitivity",
            "gradient_x",
            "paths",
            "seconds",
        ];
        expected.sort_unstable();
        let mut sorted = keys.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, expected, "{method}");
        assert_eq!(v["method"], method);
        for (key, present) in ["intensity", "sensitivity", "gradient_x"]
            .iter()
            .zip(present)
        {
            if present {
                let q = v[key].as_object().unwrap();
                // mean, stderr, and (issue 11) the count of non-zero
                // weights and whether the error bar can be trusted; a
                // central difference's derivative also the pairs of paths
                // that jumped.
                let jumps = method == "fd" && *key == "sensitivity";
                assert_eq!(q.len(), 4 + usize::from(jumps), "{method} {key}: {q:?}");
                assert_eq!(q.get("jumps").is_some_and(|k| k.is_u64()), jumps);
                assert!(q["mean"].is_f64() && q["stderr"].is_f64(), "{method} {key}");
                assert!(
                    q["nonzero"].is_u64() && q["reliable"].is_boolean(),
                    "{method} {key}"
                );
            } else {
                assert!(v[key].is_null(), "{method}: {key} should be null");
            }
        }
        let paths = if method == "exact" { 0 } else { 1000 };
        assert_eq!(v["paths"].as_u64(), Some(paths), "{method}");
        assert!(v["seconds"].as_f64().unwrap() >= 0.0);
    }
    // The keys come in the documented order.
    let line = json_line("transport", &["--paths", "1000"]);
    let pos: Vec<usize> = [
        "\"method\"",
        "\"intensity\"",
        "\"sensitivity\"",
        "\"gradient_x\"",
        "\"paths\"",
        "\"seconds\"",
    ]
    .iter()
    .map(|k| line.find(k).unwrap())
    .collect();
    assert!(pos.is_sorted(), "{line}");
}

#[test]
fn exact_matches_the_library() {
    let v = json("exact", &[]);
    let want = exact_at_probe();
    for (key, want) in [
        ("intensity", want.intensity),
        ("sensitivity", want.sensitivity),
        ("gradient_x", want.gradient_x),
    ] {
        let (mean, stderr) = mean_err(&v, key);
        assert_eq!(stderr, 0.0, "{key}");
        // serde_json's default float parser may be off by one unit in the
        // last place; the printed text is the shortest round-trip form.
        assert!(
            (mean - want).abs() <= 2.0 * f64::EPSILON * want.abs(),
            "{key}: {mean} vs {want}"
        );
    }
}

#[test]
fn monte_carlo_agrees_with_exact() {
    let want = exact_at_probe();
    for method in ["intensity", "expectation", "rendering", "transport"] {
        let v = json(method, &["--paths", "200000", "--seed", "3"]);
        for (key, want) in [
            ("intensity", want.intensity),
            ("sensitivity", want.sensitivity),
            ("gradient_x", want.gradient_x),
        ] {
            if v[key].is_null() {
                continue;
            }
            let (mean, stderr) = mean_err(&v, key);
            assert!(stderr > 0.0, "{method} {key}");
            let z = (mean - want).abs() / stderr;
            assert!(
                z < 5.0,
                "{method} {key}: {mean} ± {stderr} vs {want} (z = {z})"
            );
        }
    }
}

#[test]
fn thread_count_does_not_change_results() {
    for method in ["expectation", "transport"] {
        let run = |threads| {
            let line = json_line(
                method,
                &["--paths", "50000", "--seed", "11", "--threads", threads],
            );
            // Everything but the wall time must be byte-identical.
            line[..line.find(",\"seconds\"").unwrap()].to_owned()
        };
        assert_eq!(run("1"), run("2"), "{method}");
    }
}

#[test]
fn readable_table_names_the_quantities() {
    let mut args = vec!["rod", "--method", "transport", "--paths", "1000"];
    args.extend(PROBE);
    let out = geosens(&args);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    for word in [
        "I ",
        "∂I/∂length",
        "∂I/∂x",
        "stderr",
        "vov",
        "reliable",
        "exact",
    ] {
        assert!(text.contains(word), "missing {word:?} in\n{text}");
    }
}

/// Asserts `args` fail with `code` and a message on stderr containing every
/// one of `words`.
fn assert_rejected(args: &[&str], code: i32, words: &[&str]) {
    let out = geosens(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {stderr}");
    assert!(out.stdout.is_empty(), "{args:?} printed to stdout");
    for w in words {
        assert!(stderr.contains(w), "{args:?}: {w:?} not in {stderr:?}");
    }
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
}

/// A rod command with `--flag value` replacing (or added to) the thick-rod
/// probe and `--paths 1000`.
fn rod_with(flag: &str, value: &str) -> Vec<String> {
    let mut pairs: Vec<[&str; 2]> = PROBE.chunks(2).map(|p| [p[0], p[1]]).collect();
    pairs.push(["--paths", "1000"]);
    match pairs.iter_mut().find(|p| p[0] == flag) {
        Some(p) => p[1] = value,
        None => pairs.push([flag, value]),
    }
    let mut args = vec!["rod", "--method", "expectation"];
    args.extend(pairs.concat());
    args.into_iter().map(String::from).collect()
}

#[test]
fn invalid_values_are_rejected_with_their_name() {
    let cases = [
        ("--ks", "-1", "ks = -1"),
        ("--ke", "1", "ke = 1"), // below ks = 2.1
        ("--length", "0", "length = 0"),
        ("--length", "-2", "length = -2"),
        ("--x", "-0.5", "x = -0.5"),
        ("--x", "2.5", "x = 2.5"),
        ("--omega", "0", "omega = 0"),
        ("--omega", "2", "omega = 2"),
        ("--paths", "1", "paths = 1"),
        ("--paths", "0", "paths = 0"),
        ("--ks", "NaN", "ks = NaN"),
        ("--length", "inf", "length = inf"),
        ("--x", "-inf", "x = -inf"),
        ("--threads", "1000000000", "threads = 1000000000"),
    ];
    for (flag, value, message) in cases {
        let args = rod_with(flag, value);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        assert_rejected(&args, 1, &["error: ", message]);
    }
}

#[test]
fn exact_rejects_bad_paths_too() {
    let mut args = vec!["rod", "--method", "exact", "--paths", "1"];
    args.extend(PROBE);
    assert_rejected(&args, 1, &["paths = 1"]);
}

#[test]
fn extreme_inputs_give_numbers_or_an_error_never_null() {
    // At κe = π̃ = 1e308 the exact solution may overflow; serde_json would
    // print a NaN as null, so the binary must refuse rather than print it.
    let args = [
        "rod", "--method", "exact", "--ks", "1e308", "--ke", "1e308", "--length", "1e308", "--x",
        "5e307", "--omega", "1", "--json",
    ];
    let out = geosens(&args);
    if out.status.success() {
        let v: Value = serde_json::from_slice(&out.stdout).unwrap();
        for key in ["intensity", "sensitivity", "gradient_x"] {
            assert!(v[key]["mean"].is_f64(), "{key} is not a number: {v}");
        }
    } else {
        assert_rejected(&args, 1, &["error: "]);
    }
}

#[test]
fn malformed_arguments_are_rejected_by_the_parser() {
    let mut unknown = vec!["rod", "--method", "magic"];
    unknown.extend(PROBE);
    assert_rejected(&unknown, 2, &["magic", "--method"]);
    assert_rejected(
        &[
            "rod", "--method", "exact", "--ks", "1", "--ke", "2", "--length", "2", "--x", "1",
        ],
        2,
        &["--omega"],
    );
    let mut negative = vec!["rod", "--method", "exact", "--threads", "-1"];
    negative.extend(PROBE);
    assert_rejected(&negative, 2, &["-1", "--threads"]);
    let mut word = vec!["rod", "--method", "exact", "--x", "one"];
    word.extend(&PROBE[..6]);
    word.extend(&PROBE[8..]);
    assert_rejected(&word, 2, &["one", "--x"]);
}

#[test]
fn compare_runs() {
    let out = geosens(&[
        "compare",
        "--paths",
        "2000",
        "--threads",
        "2",
        "--no-figures",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let text = String::from_utf8(out.stdout).unwrap();
    for word in ["thin rod", "thick rod", "exact", "transport", "reliable"] {
        assert!(text.contains(word), "missing {word:?}");
    }
    // A terminal or a log shows every line unbroken (`tests/cli_width.rs`).
    for line in text.lines().chain(stderr.lines()) {
        assert!(
            line.chars().count() <= 100,
            "{} characters: {line}",
            line.chars().count()
        );
    }
    // Every number of the table against the library: the same scenes, the
    // same seed and path count (on one thread: results do not depend on it).
    let cfg = RunConfig::new(2000, 1).unwrap().threads(1);
    let mut lines = text.lines().filter(|l| !l.trim().is_empty()).peekable();
    let totals = assert_rod_tables(&mut lines, &cfg);
    assert!(title(&mut lines).starts_with("per method over the 16 probes"));
    lines.next(); // column titles
    for (m, (z, bad)) in Method::UNBIASED.iter().zip(totals) {
        let line = lines.next().unwrap();
        let t: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(t[0], m.name(), "{line}");
        assert_printed(t[2], z, &format!("{} max z", m.name()));
        assert_eq!(t[3].parse::<usize>().ok(), Some(bad), "{line}");
    }
    assert_mesh_tables(&mut lines, &cfg);
    // The short comparison by time to the answer: a row per method.
    let optimisation = title(&mut lines);
    assert!(optimisation.starts_with("optimisation: "), "{optimisation}");
    assert!(
        optimisation.contains("(inverse_occluder.toml)"),
        "{optimisation}"
    );
    assert!(lines.next().unwrap().starts_with("method"));
    for m in ["expectation", "rendering", "transport", "fd"] {
        let line = lines.next().unwrap();
        let t: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(t[0], m, "{line}");
        assert!(line.contains("/3"), "{line}");
    }
    assert!(lines.next().unwrap().starts_with("total wall time"));
    assert_eq!(lines.next(), None);
    assert_rejected(&["compare", "--paths", "1"], 1, &["paths = 1"]);
    assert_rejected(&["compare", "--effort", "0"], 1, &["effort = 0"]);
    assert_rejected(&["compare", "--effort", "nan"], 1, &["effort = NaN"]);
}

/// The next title or note of `lines`, its wrapped lines (indented by two
/// spaces) joined by spaces.
fn title<'a>(lines: &mut Peekable<impl Iterator<Item = &'a str>>) -> String {
    let mut text = lines.next().expect("a title").to_owned();
    while let Some(more) = lines.next_if(|l| l.starts_with("  ") && !l.starts_with("   ")) {
        text.push(' ');
        text.push_str(more.trim_start());
    }
    text
}

/// Asserts one row of `geosens compare`'s tables after its leading columns
/// (`tokens`): the method, its estimate `e` (`mean ± stderr z score`, the
/// score `z`), whether it is reliable, the time.
fn assert_row<'a>(
    tokens: &mut impl Iterator<Item = &'a str>,
    method: &str,
    e: &Estimate,
    z: f64,
    what: &str,
) {
    let t: Vec<&str> = tokens.collect();
    assert_eq!(t.len(), 8, "{what}: {t:?}");
    assert_eq!((t[0], t[2], t[4]), (method, "±", "z"), "{what}: {t:?}");
    assert_printed(t[1], e.mean, &format!("{what}: mean"));
    assert_printed(t[3], e.stderr, &format!("{what}: stderr"));
    if z.is_finite() {
        assert_printed(t[5], z, &format!("{what}: z"));
    } else {
        assert_eq!(t[5], "-", "{what}: z of {e:?}");
    }
    let reliable = if e.is_reliable() { "yes" } else { "no" };
    assert_eq!(t[6], reliable, "{what}: {e:?}");
    assert!(t[7].parse::<f64>().is_ok(), "{what}: time {}", t[7]);
}

/// Asserts the rod tables of `geosens compare` (the next of `lines`) print
/// the exact solution and the library's runs with `cfg` on the thin and
/// thick rods; returns each method's largest z-score and number of
/// unreliable estimates, for the summary.
fn assert_rod_tables<'a>(
    lines: &mut Peekable<impl Iterator<Item = &'a str>>,
    cfg: &RunConfig,
) -> [(f64, usize); 4] {
    let quantities = geosens::report::rod_quantities();
    let mut totals = [(0.0f64, 0usize); 4];
    for (name, ks, ke) in [("thin", 0.07, 0.1), ("thick", 2.1, 3.0)] {
        let header = title(lines);
        assert!(header.starts_with(&format!("{name} rod: ")), "{header}");
        assert_eq!(runs_of(&header), (cfg.paths, cfg.seed), "{header}");
        lines.next(); // column titles
        let rod = Rod::new(ks, ke, 2.0).unwrap();
        for x in [0.0, 1.0, 1.9, 2.0] {
            for omega in [Direction::Right, Direction::Left] {
                let exact = exact::solve(&rod, x, omega);
                let exact = [exact.intensity, exact.sensitivity, exact.gradient_x];
                let label = format!("{x}, {:+}", omega.sign());
                let probe = Probe::new(&rod, x, omega).unwrap();
                let runs: Vec<RunResult> = Method::UNBIASED
                    .iter()
                    .map(|m| run(m.estimator((rod, probe)).unwrap().as_ref(), cfg).unwrap())
                    .collect();
                let mut first_of_probe = true;
                for (q, exact) in quantities.iter().zip(exact) {
                    let mut first = true;
                    for r in &runs {
                        let Some(e) = r.get(q) else { continue };
                        let what = format!("{name} rod at {label}, {q} by {}", r.method);
                        let line = lines.next().unwrap();
                        let mut tokens = line.split_whitespace();
                        if first_of_probe {
                            let probe: Vec<&str> = tokens.by_ref().take(2).collect();
                            assert_eq!(probe.join(" "), label, "{what}: {line}");
                            first_of_probe = false;
                        }
                        if first {
                            assert_eq!(tokens.next(), Some(q.to_string().as_str()), "{line}");
                            let printed = tokens.next().unwrap();
                            assert_printed(printed, exact, &format!("{what}: exact"));
                            first = false;
                        }
                        let z = e.z_score(exact);
                        assert_row(&mut tokens, r.method, &e, z, &what);
                    }
                }
                for (r, total) in runs.iter().zip(&mut totals) {
                    assert_eq!(r.paths, cfg.paths);
                    for (q, e) in &r.estimates {
                        let k = quantities.iter().position(|p| p == q).unwrap();
                        total.0 = total.0.max(e.z_score(exact[k]));
                        total.1 += usize::from(!e.is_reliable());
                    }
                }
            }
        }
    }
    totals
}

/// Asserts the 3D tables of `geosens compare` (the next of `lines`) print
/// the closed forms and the library's runs with `cfg` of every method.
fn assert_mesh_tables<'a>(lines: &mut Peekable<impl Iterator<Item = &'a str>>, cfg: &RunConfig) {
    for (what, scene, e, s) in mesh_scenes() {
        let header = title(lines);
        assert!(header.starts_with(&format!("3D: {what}")), "{header}");
        assert_eq!(runs_of(&header), (cfg.paths, cfg.seed), "{header}");
        assert!(lines.next().unwrap().contains("reliable"));
        let scene = Arc::new(scene);
        let runs: Vec<RunResult> = Method::ALL
            .iter()
            .map(|m| run(m.estimator(Arc::clone(&scene)).unwrap().as_ref(), cfg).unwrap())
            .collect();
        let mut quantities = vec![(Quantity::Intensity, "E".to_owned(), e)];
        for (p, &x) in scene.parameters().iter().zip(&s) {
            quantities.push((Quantity::sensitivity(&p.name), format!("∂E/∂{}", p.name), x));
        }
        for (q, label, exact) in &quantities {
            let mut first = true;
            for r in &runs {
                let Some(est) = r.get(q) else { continue };
                assert_eq!(r.paths, cfg.paths);
                let what = format!("3D {what}: {label} by {}", r.method);
                let line = lines.next().unwrap();
                let mut tokens = line.split_whitespace();
                if first {
                    assert_eq!(tokens.next(), Some(label.as_str()), "{what}: {line}");
                    let closed = tokens.next().unwrap();
                    assert_printed(closed, *exact, &format!("{what}: closed form"));
                    first = false;
                }
                // Signed, and 0 where the estimate is the closed form.
                let z = if est.mean == *exact {
                    0.0
                } else {
                    (est.mean - exact) / est.stderr
                };
                assert_row(&mut tokens, r.method, &est, z, &what);
            }
        }
    }
}

/// The `(paths, seed)` of a table's title: `…; 2000 paths per run, seed 1`.
fn runs_of(header: &str) -> (u64, u64) {
    let (_, tail) = header.rsplit_once("; ").unwrap();
    let t: Vec<&str> = tail.split_whitespace().collect();
    assert_eq!(t[1..5], ["paths", "per", "run,", "seed"], "{header}");
    (t[0].parse().unwrap(), t[5].parse().unwrap())
}

/// Asserts the printed `token` is `value` to the digits printed: within half
/// a unit of its last digit (`0.0e0`, printed only for 0, exactly 0).
fn assert_printed(token: &str, value: f64, what: &str) {
    let printed: f64 = token
        .parse()
        .unwrap_or_else(|_| panic!("{what}: {token:?} is not a number"));
    let (digits, exponent) = token
        .split_once('e')
        .map_or((token, 0), |(m, e)| (m, e.parse::<i32>().unwrap()));
    let decimals = digits.split_once('.').map_or(0, |(_, d)| d.len()) as i32;
    let half_unit = 0.5 * 10f64.powi(exponent - decimals);
    let exact_zero = token.contains('e') && printed == 0.0;
    assert!(
        if exact_zero {
            value == 0.0
        } else {
            (printed - value).abs() <= half_unit * (1.0 + 1e-9)
        },
        "{what}: printed {token}, library {value}"
    );
}

/// The 3D scenes of `geosens compare`, with their closed forms: the title's
/// description, the scene, `E` and every `∂E/∂π`.
fn mesh_scenes() -> [(&'static str, geosens::mesh::Scene, f64, Vec<f64>); 2] {
    use geosens::mesh::cases::{TriangleOccluder, box_shape, lamp, up};
    use geosens::mesh::exact::BoxScene;
    use geosens::mesh::{Parameter, Scene, Surface};
    use glam::DVec3;
    let t = TriangleOccluder::NOMINAL;
    let (e, s) = t.exact().unwrap();
    let b = BoxScene::shipped(DVec3::new(0.2, -0.1, 1.0), 0.3);
    let parameters = ["box_tx", "box_ty", "box_tz", "box_rot", "box_scale"]
        .iter()
        .zip(b.motions())
        .map(|(n, m)| Parameter {
            name: (*n).into(),
            shape: "box".into(),
            motion: m,
            bounds: None,
        })
        .collect();
    let cube = box_shape("box", b.corners(), Surface::Absorber, None);
    [
        (
            "black triangle",
            t.scene(&[0, 1, 2]).unwrap(),
            e,
            s.to_vec(),
        ),
        (
            "black cube",
            Scene::new(vec![lamp(), cube], parameters, up()).unwrap(),
            b.irradiance().unwrap(),
            b.sensitivities().unwrap().to_vec(),
        ),
    ]
}

#[test]
#[cfg(feature = "figures")]
fn compare_writes_the_figures() {
    let dir = std::env::temp_dir().join(format!("geosens-cli-figures-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let dir_arg = dir.to_str().unwrap();
    let out = geosens(&[
        "compare",
        "--paths",
        "1000",
        "--effort",
        "0.0001",
        "--figures",
        dir_arg,
    ]);
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(out.status.success(), "{stderr}");
    // Its stderr not a terminal, compare draws no bar but writes a line per
    // picture: its path and the seconds its figure took.
    let mut pictures = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension() != Some("png".as_ref()) {
            continue;
        }
        pictures += 1;
        let head = format!("wrote {} (", path.display());
        let line = stderr.lines().find(|l| l.starts_with(&head));
        let seconds = line.and_then(|l| l[head.len()..].strip_suffix(" s)"));
        assert!(
            seconds.is_some_and(|s| s.parse::<f64>().is_ok()),
            "no line for {}: {stderr}",
            path.display()
        );
    }
    let logged = stderr.lines().filter(|l| l.starts_with("wrote ")).count();
    assert_eq!(logged, pictures, "{stderr}");
    // Figures drawn in several pictures keep their numbers in one JSON.
    for (name, pictures) in [
        (
            "stability",
            &[
                "stability_expectation",
                "stability_rendering",
                "stability_transport",
            ][..],
        ),
        ("flat_scene", &["flat_scene_opaque", "flat_scene_media"][..]),
    ] {
        for picture in pictures {
            for ext in ["png", "svg"] {
                let path = dir.join(format!("{picture}.{ext}"));
                let size = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
                assert!(size >= 1000, "{} missing or empty", path.display());
            }
        }
        let path = dir.join(format!("{name}.json"));
        assert!(path.exists(), "{} missing", path.display());
    }
    for name in [
        "intensity_along_rod",
        "sensitivity_along_rod",
        "convergence",
        "efficiency",
        "finite_difference",
        "flat_warp",
        "flat_against_pi",
        "flat_convergence",
        "flat_efficiency",
        "flat_stability",
    ] {
        // Every figure writes its picture twice and the numbers behind it.
        for (ext, least) in [("png", 1000), ("svg", 1000), ("json", 1)] {
            let path = dir.join(format!("{name}.{ext}"));
            let size = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
            assert!(size >= least, "{} missing or empty", path.display());
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
#[cfg(not(feature = "figures"))]
fn compare_without_the_figures_feature_says_so() {
    let dir = std::env::temp_dir().join(format!("geosens-cli-no-figures-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = geosens(&[
        "compare",
        "--paths",
        "1000",
        "--threads",
        "2",
        "--figures",
        dir.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(String::from_utf8_lossy(&out.stdout).contains("thick rod"));
    assert!(stderr.contains("`figures` feature"), "{stderr}");
    assert!(!dir.exists(), "{} written", dir.display());
}

/// `geosens rod --method fd` with `extra` arguments at [`PROBE`].
fn fd_args<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec!["rod", "--method", "fd"];
    args.extend(PROBE);
    args.extend(extra);
    args
}

#[test]
fn fd_estimates_intensity_and_sensitivity_with_common_random_numbers() {
    let want = exact_at_probe();
    for step in [None, Some("0.01")] {
        let mut extra = vec!["--paths", "200000", "--seed", "3"];
        extra.extend(step.map(|s| ["--fd-step", s]).into_iter().flatten());
        let v = json("fd", &extra);
        assert_eq!(v["method"], "fd");
        assert!(v["gradient_x"].is_null());
        for (key, want) in [
            ("intensity", want.intensity),
            ("sensitivity", want.sensitivity),
        ] {
            let (mean, stderr) = mean_err(&v, key);
            let z = (mean - want).abs() / stderr;
            assert!(
                stderr > 0.0 && z < 5.0,
                "{step:?} {key}: {mean} ± {stderr} vs {want}"
            );
        }
    }
    // The step moves the sensitivity, not the nominal rod's I.
    let line = |extra: &[&str]| {
        let mut e = vec!["--paths", "20000", "--seed", "5"];
        e.extend(extra);
        json("fd", &e)
    };
    let (a, b) = (line(&[]), line(&["--fd-step", "0.01"]));
    assert_eq!(a["intensity"], b["intensity"]);
    assert_ne!(a["sensitivity"], b["sensitivity"]);
}

#[test]
fn bad_fd_steps_are_rejected_with_their_name() {
    // Below 1e-12 a displaced vertex rounds back onto the nominal one.
    for value in ["0", "-1", "1", "2", "nan", "inf", "1e-17", "5e-324"] {
        let args = fd_args(&["--paths", "1000", "--fd-step", value]);
        assert_rejected(
            &args,
            1,
            &["error: ", "fd-step = ", "from 1e-12", "up to 1"],
        );
    }
    // The shortened rod (2 − 0.12) no longer contains x = 1.9.
    assert_rejected(
        &fd_args(&["--paths", "1000", "--fd-step", "0.06"]),
        1,
        &[
            "error: fd step too large: finite differences",
            "displace the rod by -0.12 along parameter \"length\"",
            "x = 1.9",
            "try a smaller --fd-step",
        ],
    );
    // At the moving end no step helps.
    let mut end = vec!["rod", "--method", "fd", "--paths", "1000"];
    end.extend([
        "--ks", "2.1", "--ke", "3", "--length", "2", "--x", "2", "--omega", "-1",
    ]);
    assert_rejected(&end, 1, &["invalid x = 2", "x < length for fd"]);
    for method in ["exact", "transport"] {
        let mut args = vec!["rod", "--method", method, "--fd-step", "0.01"];
        args.extend(PROBE);
        assert_rejected(&args, 1, &["--fd-step", "--method fd", method]);
    }
}

#[test]
fn issue_11_inputs_end_with_an_answer_or_a_message() {
    // 2⁶⁴ − 1 paths used to abort allocating per-chunk moments: refused now,
    // with the count printed exactly.
    let mut huge = vec!["rod", "--method", "expectation", "--paths"];
    huge.push("18446744073709551615");
    huge.extend(PROBE);
    assert_rejected(&huge, 1, &["paths = 18446744073709551615", "2^53"]);
    // Sensitivity weights ~1e300 whose squares overflow: an error, not a
    // reliable ± 0.
    assert_rejected(
        &[
            "rod",
            "--method",
            "expectation",
            "--ks",
            "1e300",
            "--ke",
            "1e300",
            "--length",
            "1e-300",
            "--x",
            "1e-300",
            "--omega",
            "1",
            "--paths",
            "2000",
        ],
        1,
        &["∂I/∂length", "NaN", "overflow"],
    );
    // The thick rod in units of 1e200: the exact solution is the thick rod's
    // (the library's on the unit-scale rod).
    let out = geosens(&[
        "rod", "--method", "exact", "--ks", "2.1e-200", "--ke", "3e-200", "--length", "2e200",
        "--x", "1e200", "--omega", "1", "--json",
    ]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let i = v["intensity"]["mean"].as_f64().unwrap();
    let unit = exact::solve(&Rod::new(2.1, 3.0, 2.0).unwrap(), 1.0, Direction::Right);
    assert!(
        (i - unit.intensity).abs() <= 1e-13 * unit.intensity,
        "I = {i}, thick rod's {}",
        unit.intensity
    );
    // κe π̃ = 10⁴ with albedo ½: 10⁴ paths end (they took 22 ms each).
    let out = geosens(&[
        "rod",
        "--method",
        "transport",
        "--ks",
        "5e5",
        "--ke",
        "1e6",
        "--length",
        "0.01",
        "--x",
        "0.005",
        "--omega",
        "1",
        "--paths",
        "10000",
        "--json",
    ]);
    assert!(out.status.success());
}
