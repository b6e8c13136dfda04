//! The Slurm recipe (`examples/slurm/`) and `geosens merge --missing`,
//! without Slurm: the scripts run under bash as Slurm runs them (the
//! `#SBATCH` lines are comments), with `sbatch` and `sinfo` stand-ins on
//! `PATH` that record what would be submitted. `.ci/cluster` runs the same
//! recipe on a real one-node Slurm.
mod common;
use common::cli::{repo, scratch, without_seconds};
use geosens::shard::{Shard, array_spec};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const GEOSENS: &str = env!("CARGO_BIN_EXE_geosens");

fn text(out: &[u8]) -> String {
    String::from_utf8_lossy(out).into_owned()
}

/// `geosens ARGS` in `dir`.
fn geosens(dir: &Path, args: &[&str]) -> Output {
    Command::new(GEOSENS)
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

/// A folder with the run's variables, where the recipe's scripts run as
/// Slurm would run them, `sbatch` and `sinfo` being stand-ins: `sbatch`
/// appends its arguments to `sbatch.log` and answers with a job ID, `sinfo`
/// reports a node of two CPUs.
struct Recipe {
    dir: PathBuf,
    env: Vec<(String, String)>,
}

impl Recipe {
    fn new(name: &str, run: &[(&str, &str)]) -> Recipe {
        let dir = scratch(name);
        let bin = dir.join("bin");
        std::fs::create_dir_all(&bin).unwrap();
        let sbatch = format!(
            "#!/usr/bin/env bash\necho \"$*\" >> {}\nif [[ $1 == --parsable ]]; then echo 7; \
             else echo 'Submitted batch job 8'; fi\n",
            dir.join("sbatch.log").display()
        );
        for (name, body) in [
            ("sbatch", sbatch.as_str()),
            ("sinfo", "#!/usr/bin/env bash\necho 2\n"),
        ] {
            let path = bin.join(name);
            std::fs::write(&path, body).unwrap();
            Command::new("chmod").arg("+x").arg(&path).status().unwrap();
        }
        let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap());
        let mut env: Vec<(String, String)> =
            vec![("GEOSENS".into(), GEOSENS.into()), ("PATH".into(), path)];
        env.extend(run.iter().map(|(k, v)| ((*k).into(), (*v).into())));
        Recipe { dir, env }
    }

    /// Runs `examples/slurm/SCRIPT` with bash and the variables `extra`.
    fn bash(&self, script: &str, extra: &[(&str, &str)]) -> Output {
        Command::new("bash")
            .arg(repo(&format!("examples/slurm/{script}")))
            .current_dir(&self.dir)
            .env_remove("SLURM_ARRAY_TASK_ID")
            .envs(self.env.iter().map(|(k, v)| (k, v)))
            .envs(extra.iter().copied())
            .output()
            .unwrap()
    }

    fn ok(&self, script: &str, extra: &[(&str, &str)]) -> String {
        let out = self.bash(script, extra);
        assert!(out.status.success(), "{script}: {}", text(&out.stderr));
        text(&out.stdout)
    }

    fn refused(&self, script: &str, extra: &[(&str, &str)]) -> String {
        let out = self.bash(script, extra);
        assert!(!out.status.success(), "{script} {extra:?} was accepted");
        text(&out.stderr)
    }

    /// What `sbatch` was called with since the last call, one line per
    /// submission.
    fn submitted(&self) -> Vec<String> {
        let log = self.dir.join("sbatch.log");
        let lines = std::fs::read_to_string(&log).unwrap_or_default();
        let _ = std::fs::remove_file(&log);
        lines.lines().map(str::to_owned).collect()
    }

    fn states(&self) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(self.dir.join("states"))
            .map(|d| {
                d.map(|e| e.unwrap().file_name().into_string().unwrap())
                    .collect()
            })
            .unwrap_or_default();
        names.sort();
        names
    }
}

#[test]
fn the_slurm_scripts_shard_and_merge() {
    let scene = repo("scenes/reflector.toml");
    let run = [
        ("SCENE", scene.as_str()),
        ("METHOD", "rendering"),
        ("PATHS", "250000"),
        ("SEED", "8"),
        ("SHARDS", "4"),
    ];
    let r = Recipe::new("whole", &run);
    for task in ["3", "1", "4", "2"] {
        // Each task as `sbatch --array=1-4 --cpus-per-task=1` starts it.
        r.ok(
            "shards.sbatch",
            &[
                ("SLURM_ARRAY_TASK_ID", task),
                ("SLURM_ARRAY_TASK_COUNT", "4"),
                ("SLURM_CPUS_PER_TASK", "1"),
            ],
        );
    }
    let merged = r.ok("merge.sbatch", &[]);
    let single = geosens(
        &r.dir,
        &[
            "flat",
            "--scene",
            &scene,
            "--method",
            "rendering",
            "--paths",
            "250000",
            "--seed",
            "8",
            "--json",
        ],
    );
    assert_eq!(
        without_seconds(&merged),
        without_seconds(&text(&single.stdout))
    );
}

#[test]
fn a_failed_shard_is_rerun_alone_and_the_merge_is_the_single_run() {
    let scene = repo("scenes/occluder.toml");
    let run = [
        ("SCENE", scene.as_str()),
        ("METHOD", "expectation"),
        ("PATHS", "300000"),
        ("SEED", "2"),
        ("N", "4"),
    ];
    let r = Recipe::new("rerun", &run);
    // The first submission: all four shards, one CPU each (none fixed in
    // the script), and a merge cancelled if a shard fails.
    r.ok("submit.sh", &[]);
    let subs = r.submitted();
    assert_eq!(subs.len(), 2, "{subs:?}");
    assert!(
        subs[0].contains("--cpus-per-task=1 --array=1-4 "),
        "{subs:?}"
    );
    assert!(
        subs[1].contains("--dependency=afterok:7 --kill-on-invalid-dep=yes"),
        "{subs:?}"
    );
    // Shard 2 fails; the others write their states.
    for task in ["1", "3", "4"] {
        r.ok(
            "shards.sbatch",
            &[("SHARDS", "4"), ("SLURM_ARRAY_TASK_ID", task)],
        );
    }
    assert!(
        r.refused("merge.sbatch", &[("SHARDS", "4")])
            .contains("shard 2/4 missing")
    );
    let out = geosens(
        &r.dir,
        &[
            "merge",
            "--missing",
            "--shards",
            "4",
            "states/shard-1-of-4.json",
            "states/shard-3-of-4.json",
            "states/shard-4-of-4.json",
        ],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(text(&out.stdout), "2\n");
    assert!(
        text(&out.stderr).contains("3 present"),
        "{}",
        text(&out.stderr)
    );
    // A submission of another shard count into this folder, or of more
    // CPUs than a node has, is refused before anything is submitted.
    assert!(r.refused("submit.sh", &[("N", "3")]).contains("not 3"));
    let err = r.refused("submit.sh", &[("CPUS", "4")]);
    assert!(
        err.contains("no node of this cluster has more than 2 CPUs"),
        "{err}"
    );
    assert!(r.submitted().is_empty());
    let before = r.states();
    let err = r.refused(
        "shards.sbatch",
        &[("SHARDS", "3"), ("SLURM_ARRAY_TASK_ID", "2")],
    );
    assert!(err.contains("another shard count"), "{err}");
    assert_eq!(r.states(), before, "a refused shard wrote a state");
    // Submitted again, unchanged: shard 2 alone. Slurm starts it as the
    // only task of its array (count 1); it is still shard 2 of 4.
    r.ok("submit.sh", &[]);
    let subs = r.submitted();
    assert!(subs[0].contains("--array=2 "), "{subs:?}");
    r.ok(
        "shards.sbatch",
        &[
            ("SHARDS", "4"),
            ("SLURM_ARRAY_TASK_ID", "2"),
            ("SLURM_ARRAY_TASK_COUNT", "1"),
        ],
    );
    assert_eq!(
        r.states(),
        ["1", "2", "3", "4"].map(|i| format!("shard-{i}-of-4.json"))
    );
    // Nothing missing: a third submission is the merge alone, at once.
    r.ok("submit.sh", &[]);
    let subs = r.submitted();
    assert_eq!(subs.len(), 1, "{subs:?}");
    assert!(!subs[0].contains("--dependency"), "{subs:?}");
    let merged = r.ok("merge.sbatch", &[("SHARDS", "4")]);
    let single = geosens(
        &r.dir,
        &[
            "flat",
            "--scene",
            &scene,
            "--method",
            "expectation",
            "--paths",
            "300000",
            "--seed",
            "2",
            "--json",
        ],
    );
    assert_eq!(
        without_seconds(&merged),
        without_seconds(&text(&single.stdout))
    );
}

#[test]
fn a_rendering_through_the_slurm_scripts_is_the_single_rendering() {
    let scene = repo("scenes/camera_line.toml");
    let run = [
        ("KIND", "render"),
        ("SCENE", scene.as_str()),
        ("METHOD", "rendering"),
        ("SPP", "32"),
        ("SEED", "4"),
        ("SHARDS", "5"),
    ];
    let r = Recipe::new("render", &run);
    for task in ["2", "5", "1", "4", "3"] {
        r.ok("shards.sbatch", &[("SLURM_ARRAY_TASK_ID", task)]);
    }
    let merged = r.ok("merge.sbatch", &[]);
    let out = geosens(
        &r.dir,
        &[
            "render",
            "--scene",
            &scene,
            "--method",
            "rendering",
            "--spp",
            "32",
            "--seed",
            "4",
            "--out",
            "single",
        ],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(
        without_seconds(&merged),
        without_seconds(&text(&out.stdout))
    );
    for name in ["I.npy", "I_stderr.npy", "d_tx.npy", "d_rot.npy"] {
        assert_eq!(
            std::fs::read(r.dir.join("single").join(name)).unwrap(),
            std::fs::read(r.dir.join("images").join(name)).unwrap(),
            "{name}"
        );
    }
}

#[test]
fn merge_missing_lists_the_absent_shards_of_one_run() {
    let dir = scratch("missing");
    let scene = repo("scenes/occluder.toml");
    let shard = |i: u64, n: u64, seed: &str| -> String {
        let file = format!("s{i}-{n}-{seed}.json");
        let spec = format!("{i}/{n}");
        let out = geosens(
            &dir,
            &[
                "flat",
                "--scene",
                &scene,
                "--method",
                "intensity",
                "--paths",
                "200000",
                "--seed",
                seed,
                "--shard",
                &spec,
                "--state",
                &file,
            ],
        );
        assert!(out.status.success(), "{}", text(&out.stderr));
        file
    };
    let files: Vec<String> = [1, 2, 5].iter().map(|&i| shard(i, 7, "1")).collect();
    let missing = |args: &[&str]| {
        let mut all = vec!["merge", "--missing"];
        all.extend(args);
        geosens(&dir, &all)
    };
    let names: Vec<&str> = files.iter().map(String::as_str).collect();
    let out = missing(&names);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(text(&out.stdout), "3-4,6-7\n");
    let err = text(&out.stderr);
    // The paths of shards 1, 2 and 5 of seven of the run.
    let sampled: u64 = [1, 2, 5]
        .map(|i| Shard::new(i, 7).unwrap().paths(200_000))
        .iter()
        .sum();
    assert!(
        err.contains(&format!("3 present, {sampled} of 200000 paths sampled")),
        "{err}"
    );
    // No state yet: every shard, if the count is given.
    let out = missing(&["--shards", "3"]);
    assert_eq!(text(&out.stdout), "1-3\n");
    let out = missing(&[]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("--shards N"),
        "{}",
        text(&out.stderr)
    );
    // Another run's states, another count, a shard twice: refused, named.
    let other = shard(3, 7, "2");
    let mut args = names.clone();
    args.push(&other);
    let err = text(&missing(&args).stderr);
    assert!(
        err.contains(&other) && err.contains("seed 2 against 1"),
        "{err}"
    );
    let mut args = names.clone();
    args.extend(["--shards", "8"]);
    let err = text(&missing(&args).stderr);
    assert!(err.contains("of a run of 7 shards, not 8"), "{err}");
    let mut args = names.clone();
    args.push(names[1]);
    let err = text(&missing(&args).stderr);
    assert!(err.contains("shard 2/7 given twice"), "{err}");
    // A plain merge with --shards refuses another count too.
    let err = text(&geosens(&dir, &["merge", "--shards", "8", names[0]]).stderr);
    assert!(err.contains("not 8"), "{err}");
    // All present: nothing on stdout.
    let all: Vec<String> = (1..=2).map(|i| shard(i, 2, "1")).collect();
    let out = missing(&[&all[0], &all[1]]);
    assert!(out.status.success() && out.stdout.is_empty());
    assert!(text(&out.stderr).contains("none missing"));
}

#[test]
fn array_specs_join_consecutive_shards() {
    assert_eq!(array_spec(&[]), "");
    assert_eq!(array_spec(&[4]), "4");
    assert_eq!(array_spec(&[1, 2, 3, 5, 7, 8]), "1-3,5,7-8");
    assert_eq!(array_spec(&[2, 9, 10, 11, 12]), "2,9-12");
}
