//! A shard's state carries a checksum of its data (`State::data_checksum`):
//! a state changed after its shard wrote it is refused by name, an
//! untouched one, however laid out, merges to the single run bit for bit.
mod common;
use common::cli::{ok, refused, repo, scratch, without_seconds};
use serde_json::Value;
use std::path::Path;

/// Runs `base` as `n` shards through the CLI (last shard first) and returns
/// the state files.
fn shards(base: &[&str], n: u64, dir: &Path) -> Vec<String> {
    (1..=n)
        .rev()
        .map(|i| {
            let file = dir.join(format!("s{i}.json")).to_str().unwrap().to_owned();
            let shard = format!("{i}/{n}");
            let mut args = base.to_vec();
            args.extend(["--shard", &shard, "--state", &file]);
            ok(&args);
            file
        })
        .collect()
}

/// The state file `from` with `edit` applied, written to `to` (checksum
/// untouched); returns `to`.
fn edited_state(from: &str, to: &Path, edit: &dyn Fn(&mut Value)) -> String {
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(from).unwrap()).unwrap();
    edit(&mut v);
    std::fs::write(to, v.to_string()).unwrap();
    to.to_str().unwrap().to_owned()
}

/// A state changed after its shard wrote it is refused by name, where it
/// used to merge into another result marked reliable: one bit of one
/// block's mean, a pixel's, or the seed of every state. The same state
/// written out again with another layout still merges bit for bit.
#[test]
fn a_changed_bit_or_field_in_a_state_is_refused() {
    let occluder = repo("scenes/occluder.toml");
    let dir = scratch("checksum");
    let base = [
        "flat",
        "--scene",
        &occluder,
        "--method",
        "expectation",
        "--paths",
        "200000",
        "--seed",
        "1",
    ];
    let files = shards(&base, 3, &dir);
    let (s3, s2, s1) = (files[0].as_str(), files[1].as_str(), files[2].as_str());
    let mut single = base.to_vec();
    single.push("--json");
    let want = without_seconds(&ok(&single));
    let merged = |states: &[&str]| {
        let mut args = vec!["merge", "--json"];
        args.extend(states);
        without_seconds(&ok(&args))
    };
    assert_eq!(merged(&[s1, s2, s3]), want, "untouched states");
    // The same data laid out otherwise (pretty-printed, CRLF line ends, a
    // letter escaped) carry the same sum: it is over the data, not the text.
    let v: Value = serde_json::from_str(&std::fs::read_to_string(s2).unwrap()).unwrap();
    let text = serde_json::to_string_pretty(&v)
        .unwrap()
        .replace("\"expectation\"", "\"\\u0065xpectation\"")
        .replace('\n', "\r\n");
    assert!(text.contains("\\u0065xpectation"));
    let relaid = dir.join("relaid.json");
    std::fs::write(&relaid, text).unwrap();
    assert_eq!(merged(&[s1, relaid.to_str().unwrap(), s3]), want, "relaid");

    // One bit of the first block's mean of I (the bits of an f64).
    for bit in [0, 30, 52, 62] {
        let flipped = edited_state(s2, &dir.join(format!("bit{bit}.json")), &|v| {
            let mean = &mut v["payload"]["moments"][0][0][2];
            *mean = Value::from(mean.as_u64().unwrap() ^ (1 << bit));
        });
        let err = refused(&["merge", s1, &flipped, s3]);
        assert!(
            err.contains(&format!("bit{bit}.json: a damaged state"))
                && err.contains("do not match its checksum"),
            "bit {bit}: {err}"
        );
    }
    // A field edited in every state alike (no other state to disagree).
    let seeds: Vec<String> = [s1, s2, s3]
        .iter()
        .enumerate()
        .map(|(i, s)| {
            edited_state(s, &dir.join(format!("seed{i}.json")), &|v| {
                v["run"]["seed"] = Value::from(2)
            })
        })
        .collect();
    let err = refused(&["merge", &seeds[0], &seeds[1], &seeds[2]]);
    assert!(
        err.contains("seed0.json: a damaged state") && err.contains("checksum"),
        "{err}"
    );
    // A state of the format before the checksum, and one without it.
    let old = edited_state(s2, &dir.join("old.json"), &|v| {
        v["format"] = Value::from("geosens-state/1");
        v.as_object_mut().unwrap().remove("checksum");
    });
    let err = refused(&["merge", s1, &old, s3]);
    assert!(
        err.contains("old.json") && err.contains("without a checksum"),
        "{err}"
    );
    let bare = edited_state(s2, &dir.join("bare.json"), &|v| {
        v.as_object_mut().unwrap().remove("checksum");
    });
    let err = refused(&["merge", s1, &bare, s3]);
    assert!(
        err.contains("bare.json") && err.contains("checksum"),
        "{err}"
    );

    // A rendering's pixel.
    let line = repo("scenes/camera_line.toml");
    let render = [
        "render",
        "--scene",
        &line,
        "--method",
        "expectation",
        "--spp",
        "8",
        "--seed",
        "2",
    ];
    let rdir = dir.join("render");
    std::fs::create_dir_all(&rdir).unwrap();
    let rfiles = shards(&render, 2, &rdir);
    let out = rdir.join("out");
    ok(&[
        "merge",
        &rfiles[0],
        &rfiles[1],
        "--out",
        out.to_str().unwrap(),
    ]);
    let flipped = edited_state(&rfiles[0], &rdir.join("pixel.json"), &|v| {
        let mean = &mut v["payload"]["pixels"][0][0][9];
        *mean = Value::from(mean.as_u64().unwrap() ^ 1);
    });
    let err = refused(&[
        "merge",
        &flipped,
        &rfiles[1],
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(err.contains("pixel.json: a damaged state"), "{err}");
}
