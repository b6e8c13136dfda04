//! Running the command line from the integration tests: the binary, its
//! output when it must succeed or be refused, the repository's files, a
//! scratch folder per test, and a JSON result line without its wall time.
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the `geosens` binary with `args`.
pub fn geosens(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_geosens"))
        .args(args)
        .output()
        .expect("the geosens binary runs")
}

/// The standard output of a run that must succeed.
pub fn ok(args: &[&str]) -> String {
    let out = geosens(args);
    assert!(
        out.status.success(),
        "{args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// The standard error of a run that must be refused (exit 1).
pub fn refused(args: &[&str]) -> String {
    let out = geosens(args);
    assert_eq!(out.status.code(), Some(1), "{args:?} was not refused");
    String::from_utf8(out.stderr).unwrap()
}

/// The repository's file `path`, absolute.
pub fn repo(path: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(path)
        .to_str()
        .unwrap()
        .to_owned()
}

/// An empty folder for test `name`, apart from every other test binary's
/// and every other run's (named after the binary and the process).
pub fn scratch(name: &str) -> PathBuf {
    let binary = std::env::current_exe()
        .ok()
        .and_then(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .unwrap_or_default();
    let dir = std::env::temp_dir().join(format!("geosens-{binary}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The JSON line without its wall time, the one field a merge cannot
/// repeat.
pub fn without_seconds(line: &str) -> Value {
    let mut v: Value = serde_json::from_str(line).unwrap();
    v.as_object_mut().unwrap().remove("seconds");
    v
}
