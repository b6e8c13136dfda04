//! Smoke tests of the figure functions at a tiny effort: they run, and write
//! non-empty files. The numbers are checked by the estimator tests; the
//! figures themselves are looked at, not asserted.
use geosens::rod::figures::{FigureOptions, convergence, efficiency};
use std::path::PathBuf;

/// Options for a quick run into a fresh temporary folder.
fn tiny(name: &str) -> FigureOptions {
    let dir = std::env::temp_dir().join(format!("geosens-smoke-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    FigureOptions {
        effort: 1e-4,
        progress: false,
        ..FigureOptions::new(dir)
    }
}

/// Every path exists, is non-empty, and the expected names are among them.
fn assert_written(paths: &[PathBuf], names: &[&str]) {
    for name in names {
        assert!(
            paths
                .iter()
                .any(|p| p.file_name().is_some_and(|f| f == *name)),
            "{name} not in {paths:?}"
        );
    }
    for p in paths {
        let len = std::fs::metadata(p).map(|m| m.len()).unwrap_or(0);
        assert!(len > 0, "{} is missing or empty", p.display());
    }
}

#[test]
fn convergence_writes_its_files() {
    let opts = tiny("convergence");
    let paths = convergence::convergence(&opts).unwrap();
    assert_written(
        &paths,
        &["convergence.png", "convergence.svg", "convergence.json"],
    );
    std::fs::remove_dir_all(&opts.out).unwrap();
}

#[test]
fn efficiency_writes_its_files() {
    let opts = tiny("efficiency");
    let paths = efficiency::efficiency(&opts).unwrap();
    assert_written(
        &paths,
        &["efficiency.png", "efficiency.svg", "efficiency.json"],
    );
    std::fs::remove_dir_all(&opts.out).unwrap();
}
