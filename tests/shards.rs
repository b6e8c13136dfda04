//! Runs split into shards (`--shard I/N --state FILE`) and merged (`geosens
//! merge`) print exactly what the single run prints, for every estimation
//! command, whatever the number of shards and threads; states that are not
//! one whole run are refused with a message naming the fault.
mod common;
use common::cli::{geosens, ok, refused, repo, scratch, without_seconds};
use geosens::job::{Job, SceneSource, Target};
use geosens::shard::{Merged, Shard, State, merge};
use geosens::{Method, RunConfig};
use serde_json::Value;
use std::path::Path;

/// A table without its timing line's seconds.
fn without_time(table: &str) -> String {
    table
        .lines()
        .map(|l| match l.find(" s") {
            Some(_) if l.starts_with("method ") => l.rsplit_once(", ").unwrap().0.to_owned(),
            _ => l.to_owned(),
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Runs `base` as `n` shards through the CLI (shard order shuffled, one
/// thread each) and returns the state files.
fn shards(base: &[&str], n: u64, dir: &Path) -> Vec<String> {
    let mut files = Vec::new();
    for i in (1..=n).rev() {
        let file = dir.join(format!("s{i}.json")).to_str().unwrap().to_owned();
        let shard = format!("{i}/{n}");
        let mut args = base.to_vec();
        args.extend(["--shard", &shard, "--state", &file, "--threads", "1"]);
        let out = geosens(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(
            out.stdout.is_empty(),
            "a shard prints its state, not a result"
        );
        files.push(file);
    }
    files
}

#[test]
fn four_shards_merge_to_the_single_run_bit_for_bit() {
    let occluder = repo("scenes/occluder.toml");
    let cube = repo("scenes/mesh/fog_cube.toml");
    // 300 000 paths: five blocks of 65 536 and a partial one, so shards
    // hold one or two blocks each, the last one partial.
    let runs: [Vec<&str>; 4] = [
        vec![
            "rod",
            "--method",
            "rendering",
            "--ks",
            "2.1",
            "--ke",
            "3",
            "--length",
            "2",
            "--x",
            "1",
            "--omega",
            "-1",
            "--paths",
            "300000",
            "--seed",
            "9",
        ],
        vec![
            "flat",
            "--scene",
            &occluder,
            "--method",
            "expectation",
            "--paths",
            "300000",
            "--seed",
            "4",
        ],
        vec![
            "flat",
            "--scene",
            &occluder,
            "--method",
            "fd",
            "--fd-step",
            "0.01",
            "--paths",
            "300000",
            "--seed",
            "4",
        ],
        vec![
            "mesh",
            "--scene",
            &cube,
            "--method",
            "transport",
            "--paths",
            "150000",
            "--seed",
            "2",
        ],
    ];
    for (k, base) in runs.iter().enumerate() {
        let dir = scratch(&format!("four-{k}"));
        let files = shards(base, 4, &dir);
        let mut merge_args = vec!["merge"];
        merge_args.extend(files.iter().map(String::as_str));
        let mut single = base.clone();
        single.push("--json");
        let mut merged_json = merge_args.clone();
        merged_json.push("--json");
        let a = ok(&single);
        let b = ok(&merged_json);
        assert_eq!(without_seconds(&a), without_seconds(&b), "{base:?}");
        // The table too, but for its wall time.
        assert_eq!(
            without_time(&ok(base)),
            without_time(&ok(&merge_args)),
            "{base:?}"
        );
    }
}

#[test]
fn more_shards_than_blocks_and_one_shard_merge_too() {
    let occluder = repo("scenes/occluder.toml");
    let base = [
        "flat",
        "--scene",
        &occluder,
        "--method",
        "rendering",
        "--paths",
        "100000",
        "--seed",
        "3",
    ];
    let mut single = base.to_vec();
    single.push("--json");
    let want = without_seconds(&ok(&single));
    // Two blocks among five shards: three shards are empty.
    for n in [5, 1] {
        let dir = scratch(&format!("many-{n}"));
        let files = shards(&base, n, &dir);
        let mut args = vec!["merge", "--json"];
        args.extend(files.iter().map(String::as_str));
        assert_eq!(without_seconds(&ok(&args)), want, "{n} shards");
    }
}

#[test]
fn a_rendering_merges_to_the_same_images() {
    let scene = repo("scenes/mesh/camera_shadow.toml");
    let dir = scratch("render");
    let single_dir = dir.join("single");
    let merged_dir = dir.join("merged");
    let base = [
        "render",
        "--scene",
        &scene,
        "--method",
        "expectation",
        "--spp",
        "16",
        "--seed",
        "6",
    ];
    let mut single = base.to_vec();
    single.extend(["--out", single_dir.to_str().unwrap()]);
    let a = ok(&single);
    let files = shards(&base, 3, &dir);
    let mut args = vec!["merge", "--out", merged_dir.to_str().unwrap()];
    args.extend(files.iter().map(String::as_str));
    let b = ok(&args);
    assert_eq!(without_seconds(&a), without_seconds(&b));
    let mut npy = 0;
    for entry in std::fs::read_dir(&single_dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "npy") {
            let name = path.file_name().unwrap();
            assert_eq!(
                std::fs::read(&path).unwrap(),
                std::fs::read(merged_dir.join(name)).unwrap(),
                "{name:?}"
            );
            npy += 1;
        }
    }
    // I and three sensitivities, each with its error image.
    assert_eq!(npy, 8);
}

#[test]
fn the_library_merges_as_the_cli_does() {
    let job = Job {
        target: Target::Flat(SceneSource::File(repo("scenes/fog.toml").into())),
        method: Some(Method::Transport),
        fd_step: None,
    };
    let cfg = RunConfig::new(200_000, 11).unwrap().threads(2);
    let single = job.run(&cfg, &geosens::runner::quiet).unwrap();
    let states: Vec<(String, State)> = (1..=3)
        .map(|i| {
            let s = job
                .run_shard(&cfg, Shard::new(i, 3).unwrap(), &geosens::runner::quiet)
                .unwrap();
            // Through the file format and back.
            let s = State::from_json(&s.to_json().unwrap()).unwrap();
            (format!("shard {i}"), s)
        })
        .collect();
    let Merged::Probe(merged) = merge(&states).unwrap() else {
        panic!("a probe's states merge to a report")
    };
    assert_eq!(merged.result.estimates, single.result.estimates);
    assert_eq!(merged.result.paths, single.result.paths);
    assert_eq!(merged.header, single.header);
}

#[test]
fn states_that_are_not_one_whole_run_are_refused() {
    let occluder = repo("scenes/occluder.toml");
    let fog = repo("scenes/fog.toml");
    let dir = scratch("refused");
    let base = [
        "flat",
        "--scene",
        &occluder,
        "--method",
        "intensity",
        "--paths",
        "200000",
        "--seed",
        "1",
    ];
    let files = shards(&base, 3, &dir);
    let (s3, s2, s1) = (&files[0], &files[1], &files[2]);
    let err = refused(&["merge", s1, s3]);
    assert!(err.contains("shard 2/3 missing"), "{err}");
    let err = refused(&["merge", s1, s2, s2, s3]);
    assert!(err.contains("shard 2/3 given twice"), "{err}");
    // Another seed, another path count, another scene, another method.
    let other = |args: &[&str], name: &str| -> String {
        let file = dir.join(name).to_str().unwrap().to_owned();
        let mut a = args.to_vec();
        a.extend(["--shard", "2/3", "--state", &file]);
        ok(&a);
        file
    };
    let mut seed = base.to_vec();
    seed[8] = "2";
    let f = other(&seed, "seed.json");
    let err = refused(&["merge", s1, &f, s3]);
    assert!(
        err.contains("not of one run") && err.contains("seed 2 against 1"),
        "{err}"
    );
    let mut paths = base.to_vec();
    paths[6] = "200001";
    let f = other(&paths, "paths.json");
    let err = refused(&["merge", s1, &f, s3]);
    assert!(err.contains("200001 paths against 200000"), "{err}");
    let mut scene = base.to_vec();
    scene[2] = &fog;
    let f = other(&scene, "scene.json");
    let err = refused(&["merge", s1, &f, s3]);
    assert!(err.contains("hashes differ"), "{err}");
    let mut method = base.to_vec();
    method[4] = "expectation";
    let f = other(&method, "method.json");
    let err = refused(&["merge", s1, &f, s3]);
    assert!(
        err.contains("method expectation against intensity"),
        "{err}"
    );
    // The state file `from` with `edit` applied and its checksum made
    // right again (a writer's own slip, which the checksum cannot see),
    // written as `name`.
    let edited = |from: &str, name: &str, edit: &dyn Fn(&mut Value)| {
        let path = edited_state(from, &dir.join(name), edit);
        let mut state: State =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        state.checksum = state.data_checksum().unwrap();
        std::fs::write(&path, state.to_json().unwrap()).unwrap();
        path
    };
    // A damaged state: a block dropped.
    let damaged = edited(s2, "damaged.json", &|v| {
        v["payload"]["moments"].as_array_mut().unwrap().pop();
    });
    let err = refused(&["merge", s1, &damaged, s3]);
    assert!(
        err.contains("should hold blocks") && err.contains("damaged"),
        "{err}"
    );
    // Cut short, and edited into contradictions (all were merged, or
    // misreported as having no format).
    let text = std::fs::read_to_string(s2).unwrap();
    let cut = dir.join("cut.json");
    std::fs::write(&cut, &text[..text.len() / 2]).unwrap();
    let err = refused(&["merge", s1, cut.to_str().unwrap(), s3]);
    assert!(
        err.contains("cut.json") && err.contains("cut short"),
        "{err}"
    );
    let slow = edited(s2, "slow.json", &|v| v["seconds"] = Value::from(-1.0));
    let err = refused(&["merge", s1, &slow, s3]);
    assert!(
        err.contains("damaged") && err.contains("time is -1"),
        "{err}"
    );
    let many = edited(s2, "many.json", &|v| {
        let n = v["payload"]["moments"][0][0][0].as_u64().unwrap();
        v["payload"]["moments"][0][0][1] = Value::from(n + 5);
    });
    let err = refused(&["merge", s1, &many, s3]);
    assert!(
        err.contains("damaged") && err.contains("non-zero weights among"),
        "{err}"
    );
    // A shard count no run has (it would allocate a slot per shard).
    let huge = edited(s1, "huge.json", &|v| {
        v["run"]["shards"] = Value::from(u64::MAX)
    });
    let err = refused(&["merge", &huge]);
    assert!(err.contains("huge.json") && err.contains("I/N"), "{err}");
    // Not a state at all, and no file.
    let err = refused(&["merge", &occluder]);
    assert!(
        err.contains("not a geosens state") || err.contains("not"),
        "{err}"
    );
    let err = refused(&["merge", dir.join("absent.json").to_str().unwrap()]);
    assert!(err.contains("cannot read"), "{err}");
}

/// The state file `from` with `edit` applied, written to `to` (checksum
/// untouched); returns `to`.
fn edited_state(from: &str, to: &Path, edit: &dyn Fn(&mut Value)) -> String {
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(from).unwrap()).unwrap();
    edit(&mut v);
    std::fs::write(to, v.to_string()).unwrap();
    to.to_str().unwrap().to_owned()
}

#[test]
fn shard_arguments_are_checked() {
    let occluder = repo("scenes/occluder.toml");
    let dir = scratch("args");
    let state = dir.join("s.json");
    let state = state.to_str().unwrap();
    let base = [
        "flat",
        "--scene",
        &occluder,
        "--method",
        "intensity",
        "--paths",
        "1000",
    ];
    for bad in ["0/4", "5/4", "2", "a/b", "1/0"] {
        let mut args = base.to_vec();
        args.extend(["--shard", bad, "--state", state]);
        let out = geosens(&args);
        assert!(!out.status.success(), "--shard {bad} accepted");
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(err.contains("I/N") || err.contains(bad), "{bad}: {err}");
    }
    let mut args = base.to_vec();
    args.extend(["--shard", "1/2"]);
    assert!(refused(&args).contains("needs --state"));
    let mut args = base.to_vec();
    args.extend(["--state", state, "--json"]);
    assert!(refused(&args).contains("geosens merge --json"));
    let exact = [
        "rod", "--method", "exact", "--ks", "1", "--ke", "2", "--length", "1", "--x", "0.5",
        "--omega", "1", "--state", state,
    ];
    assert!(refused(&exact).contains("samples nothing"));
    assert!(!Path::new(state).exists(), "a refused run wrote a state");
}

#[test]
fn a_line_camera_spreads_over_every_shard() {
    // One row of 40 pixels over 7 shards: split by rows, six shards held
    // nothing and one did all the work; split by pixels each holds 5 or 6.
    let scene = repo("scenes/camera_line.toml");
    let dir = scratch("line");
    let base = [
        "render",
        "--scene",
        &scene,
        "--method",
        "expectation",
        "--spp",
        "32",
        "--seed",
        "9",
    ];
    let files = shards(&base, 7, &dir);
    let mut pixels = 0;
    for f in &files {
        let state = State::read(Path::new(f)).unwrap();
        let held = state.paths / 32;
        assert!((5..=6).contains(&held), "{f}: {held} pixels");
        pixels += held;
    }
    assert_eq!(pixels, 40);
    let (single_dir, merged_dir) = (dir.join("single"), dir.join("merged"));
    let mut single = base.to_vec();
    single.extend(["--out", single_dir.to_str().unwrap()]);
    let a = ok(&single);
    let mut args = vec!["merge", "--out", merged_dir.to_str().unwrap()];
    args.extend(files.iter().map(String::as_str));
    assert_eq!(without_seconds(&a), without_seconds(&ok(&args)));
    for name in ["I.npy", "I_stderr.npy", "d_tx.npy", "d_rot_stderr.npy"] {
        assert_eq!(
            std::fs::read(single_dir.join(name)).unwrap(),
            std::fs::read(merged_dir.join(name)).unwrap(),
            "{name}"
        );
    }
    // The help says what a rendering's shard is.
    let help = ok(&["render", "--help"]);
    assert!(help.contains("pixels") && !help.contains("65536"), "{help}");
}
