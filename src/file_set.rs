//! Output files written whole or not at all, as one set.
//!
//! A run's files (a rendering's images, a shard's state) were written in
//! place one after the other: a run that failed part way (a full disk) left
//! the files before the failure, the one it failed in cut short, and, for a
//! state, its temporary. A [`FileSet`] writes each file to a temporary
//! beside it (`NAME.part`) and renames them all onto their names only when
//! every one is complete. A set that fails, or is dropped before
//! [`FileSet::commit`], removes its temporaries; a rename that fails part
//! way removes the files already renamed. So a failed run leaves no file of
//! its own, and the files a previous run left under the same names stay
//! whole unless the renames themselves fail.
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::error::Error;

/// Files being written as one set; see the [module](self) docs.
#[derive(Debug, Default)]
pub struct FileSet {
    /// (temporary, name), in the order written.
    staged: Vec<(PathBuf, PathBuf)>,
}

impl FileSet {
    /// An empty set.
    pub fn new() -> FileSet {
        FileSet::default()
    }

    /// Writes the set's file `path` to its temporary: `encode` writes the
    /// contents (its errors should name `path`, as this function's do).
    /// The file is flushed and synced to its disk, so that a rename never
    /// puts a name on data still in memory. On any error the set's
    /// temporaries are removed and the set is empty. A name given twice is
    /// an error (the second file would replace the first unseen).
    pub fn write(
        &mut self,
        path: &Path,
        encode: impl FnOnce(&mut BufWriter<File>) -> Result<(), Error>,
    ) -> Result<(), Error> {
        let written = self.stage(path, encode);
        if written.is_err() {
            self.discard();
        }
        written
    }

    fn stage(
        &mut self,
        path: &Path,
        encode: impl FnOnce(&mut BufWriter<File>) -> Result<(), Error>,
    ) -> Result<(), Error> {
        if self.staged.iter().any(|(_, p)| p == path) {
            return Err(output_error(path, "two files of one run have this name"));
        }
        let mut part = path.as_os_str().to_owned();
        part.push(".part");
        let part = PathBuf::from(part);
        let file = File::create(&part).map_err(|e| io_error(path, &e))?;
        // Staged before a byte is written: a failure below removes it.
        self.staged.push((part, path.to_owned()));
        let mut out = BufWriter::new(file);
        encode(&mut out)?;
        let file = out.into_inner().map_err(|e| io_error(path, e.error()))?;
        file.sync_all().map_err(|e| io_error(path, &e))
    }

    /// Renames every file of the set onto its name, in the order written,
    /// and returns the names. If a rename fails, the files renamed so far
    /// and the temporaries left are removed and the error names the file.
    pub fn commit(mut self) -> Result<Vec<PathBuf>, Error> {
        let staged = std::mem::take(&mut self.staged);
        for (i, (part, path)) in staged.iter().enumerate() {
            if let Err(e) = std::fs::rename(part, path) {
                for (_, done) in &staged[..i] {
                    let _ = std::fs::remove_file(done);
                }
                for (rest, _) in &staged[i..] {
                    let _ = std::fs::remove_file(rest);
                }
                return Err(io_error(path, &e));
            }
        }
        Ok(staged.into_iter().map(|(_, path)| path).collect())
    }

    /// Removes the temporaries written so far.
    fn discard(&mut self) {
        for (part, _) in self.staged.drain(..) {
            let _ = std::fs::remove_file(part);
        }
    }
}

impl Drop for FileSet {
    /// A set not committed (an error, a panic) leaves no temporary.
    fn drop(&mut self) {
        self.discard();
    }
}

/// Writes `bytes` to `path` through a temporary beside it, renamed when
/// complete: the file is either the new one, whole, or what was there
/// before, and no temporary is left.
pub fn write_whole(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    let mut set = FileSet::new();
    set.write(path, |out| {
        out.write_all(bytes).map_err(|e| io_error(path, &e))
    })?;
    set.commit().map(drop)
}

/// An I/O failure on `path`, saying which directory is missing if one is.
pub(crate) fn io_error(path: &Path, e: &io::Error) -> Error {
    let dir = path.parent().filter(|dir| !dir.as_os_str().is_empty());
    match dir {
        Some(dir) if e.kind() == io::ErrorKind::NotFound && !dir.is_dir() => {
            output_error(path, format!("directory {} does not exist", dir.display()))
        }
        _ => output_error(path, e),
    }
}

/// `cannot write <path>: <cause>`.
pub(crate) fn output_error(path: &Path, cause: impl std::fmt::Display) -> Error {
    Error::Output(format!("cannot write {}: {cause}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("geosens-file_set-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        v.sort();
        v
    }

    fn text(s: &'static str) -> impl FnOnce(&mut BufWriter<File>) -> Result<(), Error> {
        move |out| {
            out.write_all(s.as_bytes())
                .map_err(|e| Error::Output(e.to_string()))
        }
    }

    #[test]
    fn a_set_appears_whole_at_its_commit() {
        let dir = scratch("commit");
        std::fs::write(dir.join("a"), "old a").unwrap();
        let mut set = FileSet::new();
        set.write(&dir.join("a"), text("new a")).unwrap();
        set.write(&dir.join("b"), text("new b")).unwrap();
        // Before the commit: the old file and the temporaries.
        assert_eq!(std::fs::read_to_string(dir.join("a")).unwrap(), "old a");
        assert_eq!(names(&dir), ["a", "a.part", "b.part"]);
        let written = set.commit().unwrap();
        assert_eq!(written, [dir.join("a"), dir.join("b")]);
        assert_eq!(names(&dir), ["a", "b"]);
        assert_eq!(std::fs::read_to_string(dir.join("a")).unwrap(), "new a");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_failed_set_leaves_nothing_of_its_own() {
        let dir = scratch("fail");
        std::fs::write(dir.join("a"), "old a").unwrap();
        // A failure while writing: the temporaries go, the old file stays.
        let mut set = FileSet::new();
        set.write(&dir.join("a"), text("new a")).unwrap();
        let failed = set.write(&dir.join("b"), |out| {
            out.write_all(b"half").unwrap();
            Err(Error::Output("cannot write b: no space".into()))
        });
        assert!(failed.is_err());
        assert_eq!(names(&dir), ["a"]);
        assert_eq!(std::fs::read_to_string(dir.join("a")).unwrap(), "old a");
        // A set dropped uncommitted (an error elsewhere) leaves nothing.
        let mut set = FileSet::new();
        set.write(&dir.join("c"), text("c")).unwrap();
        drop(set);
        assert_eq!(names(&dir), ["a"]);
        // A rename that fails part way (onto a folder): the files renamed
        // before it are removed, and the error names the file.
        std::fs::create_dir(dir.join("d")).unwrap();
        let mut set = FileSet::new();
        set.write(&dir.join("c"), text("c")).unwrap();
        set.write(&dir.join("d"), text("d")).unwrap();
        set.write(&dir.join("e"), text("e")).unwrap();
        let Err(Error::Output(m)) = set.commit() else {
            panic!("renamed onto a folder")
        };
        assert!(m.contains(&dir.join("d").display().to_string()), "{m}");
        assert_eq!(names(&dir), ["a", "d"]);
        // One name twice is refused.
        let mut set = FileSet::new();
        set.write(&dir.join("f"), text("f")).unwrap();
        let Err(Error::Output(m)) = set.write(&dir.join("f"), text("g")) else {
            panic!("one name twice")
        };
        assert!(m.contains("two files"), "{m}");
        assert_eq!(names(&dir), ["a", "d"]);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
