//! Where a run's output goes, checked before the run: a path that cannot
//! be written was found only when the work was done (a shard's state, a
//! rendering's images or the comparison's figures lost after minutes or
//! hours, a cluster job with them).
use geosens::Error;
use std::path::{Path, PathBuf};

/// Creates `dir` if missing and proves it writable with a file made and
/// removed in it.
pub(super) fn writable_dir(dir: &Path) -> Result<(), Error> {
    let fail = |e: std::io::Error| Error::Output(format!("cannot write to {}: {e}", dir.display()));
    std::fs::create_dir_all(dir).map_err(fail)?;
    let probe = dir.join(format!(".geosens-probe-{}", std::process::id()));
    std::fs::File::create(&probe).map_err(fail)?;
    std::fs::remove_file(&probe).map_err(fail)
}

/// The folders `create_dir_all(dir)` would make, deepest first.
pub(super) fn missing_folders(dir: &Path) -> Vec<PathBuf> {
    dir.ancestors()
        .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
        .map(Path::to_path_buf)
        .collect()
}

/// Removes `folders` (deepest first) where empty: those a failed run made.
pub(super) fn remove_empty(folders: &[PathBuf]) {
    for folder in folders {
        let _ = std::fs::remove_dir(folder);
    }
}

/// Proves `path` writable as a file: not a folder, and its folder exists and
/// takes a file.
pub(super) fn writable_file(path: &Path) -> Result<(), Error> {
    if path.is_dir() {
        return Err(Error::Output(format!(
            "cannot write to {}: it is a folder",
            path.display()
        )));
    }
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !parent.is_dir() {
        return Err(Error::Output(format!(
            "cannot write to {}: no folder {}",
            path.display(),
            parent.display()
        )));
    }
    writable_dir(parent)
}

/// A progress bar on stderr for `len` units of work (`unit`: "paths",
/// "pixels"), drawn only where stderr is a terminal (indicatif's own check):
/// a long run in a terminal shows it is alive and when it will end, and a
/// script's or a cluster job's stderr stays clean.
pub(super) fn progress_bar(len: u64, unit: &str, msg: String) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(len);
    let template = format!("{{msg}} [{{bar:40}}] {{human_pos}}/{{human_len}} {unit}, eta {{eta}}");
    if let Ok(style) = indicatif::ProgressStyle::with_template(&template) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(msg);
    bar
}

/// The progress hook that moves `bar` and never stops the run.
pub(super) fn shown(bar: &indicatif::ProgressBar) -> impl Fn(u64) -> Result<(), Error> + Sync + '_ {
    move |done| {
        bar.set_position(done);
        Ok(())
    }
}

/// The widest line the commands print: their tables, titles and notes (the
/// help, which clap wraps, too).
pub(super) const WIDTH: usize = 100;

/// `text` wrapped at spaces into lines of at most [`WIDTH`] characters, the
/// lines after the first indented by two spaces, so that a reader (and a
/// parser) tells a wrapped title or note from a table's rows; every line
/// ends with a newline. A word longer than a line keeps a line to itself.
pub(super) fn paragraph(text: &str) -> String {
    let mut out = String::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        let indent = if out.is_empty() { 0 } else { 2 };
        if !line.is_empty() && indent + line.chars().count() + 1 + word.chars().count() > WIDTH {
            out.push_str(&" ".repeat(indent));
            out.push_str(&line);
            out.push('\n');
            line.clear();
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    if !line.is_empty() {
        if !out.is_empty() {
            out.push_str("  ");
        }
        out.push_str(&line);
        out.push('\n');
    }
    out
}
