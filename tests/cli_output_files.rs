//! What the command line leaves on disk: `render --out` and `merge --out`
//! write their images as one set, replacing a previous run's files of the
//! same names (fixed names: the PNGs' display scale is in their text, not
//! their names); a run that cannot write them (here a file-size limit, as a
//! full disk would) fails without leaving a file, a truncated one or a
//! `.part`, and keeps the previous run's set whole; a shard's state the same.
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_geosens");

fn geosens(args: &[&str]) -> Output {
    Command::new(BIN)
        .args(args)
        .output()
        .expect("the geosens binary runs")
}

/// `geosens args` with files limited to `kib` KiB: a write past it fails
/// with "File too large" (SIGXFSZ ignored, as bash passes it on), as on a
/// full disk, once some files are written.
fn limited(kib: u32, args: &[&str]) -> Output {
    Command::new("bash")
        .arg("-c")
        .arg(format!("trap '' XFSZ; ulimit -f {kib}; exec \"$0\" \"$@\""))
        .arg(BIN)
        .args(args)
        .output()
        .expect("bash runs")
}

fn camera() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/mesh/camera_shadow.toml")
        .to_str()
        .unwrap()
        .to_owned()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("geosens-files-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Every file in `dir` with its bytes.
fn contents(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            let name = e.file_name().into_string().unwrap();
            (name, std::fs::read(e.path()).unwrap())
        })
        .collect()
}

fn render_args<'a>(scene: &'a str, out: &'a str, seed: &'a str) -> Vec<&'a str> {
    vec![
        "render",
        "--scene",
        scene,
        "--method",
        "expectation",
        "--spp",
        "8",
        "--seed",
        seed,
        "--out",
        out,
    ]
}

/// The text chunks of the PNG at `path`.
fn png_text(path: &Path) -> BTreeMap<String, String> {
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let reader = png::Decoder::new(file).read_info().unwrap();
    (reader.info().uncompressed_latin1_text.iter())
        .map(|t| (t.keyword.clone(), t.text.clone()))
        .collect()
}

/// The values of a `.npy` file of f64 (its 10-byte preamble and header
/// skipped).
fn npy_values(path: &Path) -> Vec<f64> {
    let bytes = std::fs::read(path).unwrap();
    let start = 10 + usize::from(u16::from_le_bytes([bytes[8], bytes[9]]));
    (bytes[start..].chunks_exact(8))
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

#[test]
fn a_second_render_replaces_the_first() {
    let scene = camera();
    let dir = scratch("rerun");
    let out = dir.join("out");
    let o = out.to_str().unwrap();
    assert!(geosens(&render_args(&scene, o, "1")).status.success());
    let first = contents(&out);
    // Another seed: other images, other display scales.
    assert!(geosens(&render_args(&scene, o, "2")).status.success());
    let second = contents(&out);
    let names = |c: &BTreeMap<String, Vec<u8>>| c.keys().cloned().collect::<Vec<_>>();
    assert_eq!(names(&second), names(&first), "a rerun left two sets");
    // I and three sensitivities, each: EXR, .npy and PNG, and the same for
    // its standard error.
    assert_eq!(second.len(), 4 * 6, "{:?}", names(&second));
    assert_ne!(first["I.npy"], second["I.npy"], "the second run's images");
    for stem in ["I", "I_stderr", "d_tri_tx", "d_tri_tx_stderr"] {
        assert!(second.contains_key(&format!("{stem}.png")), "{stem}.png");
        // The scale, at full precision in the PNG, is the image's robust
        // scale (the 99th percentile of |x|).
        let text = png_text(&out.join(format!("{stem}.png")));
        let scale: f64 = text["Scale"].parse().unwrap();
        let values = npy_values(&out.join(format!("{stem}.npy")));
        assert_eq!(scale, geosens::image_io::robust_scale(&values), "{stem}");
        assert!(text["Description"].contains("from"), "{text:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_render_that_cannot_write_leaves_nothing() {
    let scene = camera();
    let dir = scratch("full");
    // A folder this run makes: gone again after the failure. 8 KiB takes
    // I.exr (about 4.4 kB) but not I.npy (8320 bytes): the 24 files failed
    // at the second, which was left cut at 8192 bytes.
    let fresh = dir.join("fresh").join("out");
    let o = fresh.to_str().unwrap();
    let run = limited(8, &render_args(&scene, o, "1"));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("I.npy") && stderr.contains("File too large"),
        "{stderr}"
    );
    assert!(!fresh.exists(), "left {:?}", contents(&fresh).keys());
    assert!(!dir.join("fresh").exists(), "left the folder it made");
    // A folder holding a previous run: kept whole, byte for byte.
    let out = dir.join("out");
    let o = out.to_str().unwrap();
    assert!(geosens(&render_args(&scene, o, "1")).status.success());
    let before = contents(&out);
    let run = limited(8, &render_args(&scene, o, "2"));
    assert_eq!(run.status.code(), Some(1));
    assert!(contents(&out) == before, "the previous images were touched");
    // The same for a merge's images.
    let states: Vec<String> = (1..=2)
        .map(|i| {
            let state = dir.join(format!("s{i}.json"));
            let shard = format!("{i}/2");
            let mut args = render_args(&scene, "", "1");
            args.truncate(args.len() - 2);
            args.extend(["--shard", &shard, "--state", state.to_str().unwrap()]);
            assert!(geosens(&args).status.success());
            state.to_str().unwrap().to_owned()
        })
        .collect();
    let merged = dir.join("merged");
    let m = merged.to_str().unwrap();
    let run = limited(8, &["merge", &states[0], &states[1], "--out", m]);
    assert_eq!(run.status.code(), Some(1));
    assert!(!merged.exists(), "left {:?}", contents(&merged).keys());
    let run = geosens(&["merge", &states[0], &states[1], "--out", m]);
    assert!(run.status.success());
    assert!(contents(&merged) == before, "the merge is the single run");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_state_that_cannot_be_written_leaves_nothing() {
    let scene = camera();
    let dir = scratch("state");
    let state = dir.join("s.json");
    let s = state.to_str().unwrap();
    let mut args = render_args(&scene, "", "1");
    args.truncate(args.len() - 2);
    args.extend(["--state", s]);
    // The state of 32×32 pixels and 4 quantities is about 1 MB.
    let run = limited(64, &args);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("s.json"), "{stderr}");
    assert!(
        contents(&dir).is_empty(),
        "left {:?}",
        contents(&dir).keys()
    );
    // A state there before is kept.
    assert!(geosens(&args).status.success());
    let before = std::fs::read(&state).unwrap();
    let mut again = args.clone();
    again[8] = "2";
    assert_eq!(limited(64, &again).status.code(), Some(1));
    assert_eq!(std::fs::read(&state).unwrap(), before);
    assert_eq!(contents(&dir).len(), 1);
    let parsed: Value = serde_json::from_slice(&before).unwrap();
    assert_eq!(parsed["run"]["seed"], 1);
    let _ = std::fs::remove_dir_all(&dir);
}
