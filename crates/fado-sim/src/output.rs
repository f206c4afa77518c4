//! Writing results so that a crash, a full disk or a second writer never leaves a mix.
//!
//! * [`DirLock`]: one writer per output directory. An advisory lock (`flock(2)` on Unix,
//!   `LockFileEx` on Windows, through [`std::fs::File::try_lock`]) on `DIR/.fado.lock`; a
//!   second `fado-sim run`/`sweep` (or Python call) on the same directory is refused with
//!   [`OutputError`] instead of interleaving its lines. The lock goes with the process, so a
//!   `kill -9` never leaves a stale lock behind; the empty lock file stays (removing it would
//!   race with a writer opening it).
//! * [`AtomicFile`]: every output is written to a temporary file in the target's directory
//!   (`.NAME.tmp-PID`), flushed, `fsync`ed and renamed over the target (`rename(2)` is atomic
//!   within one file system). A reader sees the previous whole file or the new whole file,
//!   never a part; an error or a kill leaves the previous file. Temporary files of killed
//!   writers are removed when the next writer takes the directory's lock.
//!
//! Errors name the path and what was being done with it; the CLI exits with code 3 for them
//! (2 is for configuration errors).

use std::fmt;
use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// Name of the lock file inside a locked directory.
pub const LOCK_FILE: &str = ".fado.lock";

/// Infix of the temporary files ([`AtomicFile`]): `.NAME.tmp-PID`.
const TMP_INFIX: &str = ".tmp-";

/// Reading or writing an output failed, or another process holds the directory.
#[derive(Debug)]
pub struct OutputError {
    /// The file or directory concerned.
    pub path: PathBuf,
    /// What was being done (`create`, `write`, `rename to`, `lock`, ...).
    pub action: &'static str,
    /// The operating system's error (for a held lock: `WouldBlock`).
    pub source: io::Error,
}

impl OutputError {
    /// An error of `action` on `path`.
    pub fn new(action: &'static str, path: impl Into<PathBuf>, source: io::Error) -> Self {
        Self {
            path: path.into(),
            action,
            source,
        }
    }

    /// True when the directory is locked by another writer.
    pub fn is_busy(&self) -> bool {
        self.source.kind() == io::ErrorKind::WouldBlock
    }
}

impl fmt::Display for OutputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_busy() {
            write!(
                f,
                "{}: another fado-sim command (run, sweep, compare or commission) is writing \
                 to this directory (it holds {}); wait for it or choose another output \
                 directory",
                self.path.display(),
                LOCK_FILE
            )
        } else {
            write!(
                f,
                "cannot {} {}: {}",
                self.action,
                self.path.display(),
                self.source
            )
        }
    }
}

impl std::error::Error for OutputError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&self.source)
    }
}

/// Exclusive hold on an output directory for as long as the value lives (see the module
/// documentation).
#[derive(Debug)]
pub struct DirLock {
    dir: PathBuf,
    // Held for its lock; released by the operating system when closed (drop or exit).
    _file: File,
}

impl DirLock {
    /// Creates `dir` if needed and locks it, or fails at once (no waiting) if another process
    /// holds it. Removes the temporary files that killed writers left there.
    pub fn acquire(dir: &Path) -> Result<Self, OutputError> {
        std::fs::create_dir_all(dir).map_err(|e| {
            if dir.exists() && !dir.is_dir() {
                // `--out` names a file: say so rather than "File exists".
                let e = io::Error::new(
                    e.kind(),
                    "it is a file, not a directory (--out names the directory to write into)",
                );
                return OutputError::new("use as the output directory", dir, e);
            }
            OutputError::new("create directory", dir, e)
        })?;
        let path = dir.join(LOCK_FILE);
        let file = OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&path)
            .map_err(|e| OutputError::new("create", &path, e))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                return Err(OutputError::new(
                    "lock",
                    dir,
                    io::Error::from(io::ErrorKind::WouldBlock),
                ));
            }
            Err(std::fs::TryLockError::Error(e)) => return Err(OutputError::new("lock", &path, e)),
        }
        remove_stale_temporaries(dir)?;
        Ok(Self {
            dir: dir.to_owned(),
            _file: file,
        })
    }

    /// The locked directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }
}

fn remove_stale_temporaries(dir: &Path) -> Result<(), OutputError> {
    let entries = std::fs::read_dir(dir).map_err(|e| OutputError::new("list", dir, e))?;
    for entry in entries.flatten() {
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if name.starts_with('.') && name.contains(TMP_INFIX) {
            let path = entry.path();
            std::fs::remove_file(&path).map_err(|e| OutputError::new("remove", &path, e))?;
        }
    }
    Ok(())
}

/// A file written under a temporary name and renamed into place by [`commit`](Self::commit)
/// (see the module documentation). Dropped uncommitted, it removes its temporary file.
#[derive(Debug)]
pub struct AtomicFile {
    target: PathBuf,
    tmp: PathBuf,
    writer: Option<BufWriter<File>>,
}

impl AtomicFile {
    /// Starts writing `target` (its directory must exist).
    pub fn create(target: &Path) -> Result<Self, OutputError> {
        let name = target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let tmp = target.with_file_name(format!(".{name}{TMP_INFIX}{}", std::process::id()));
        let file = File::create(&tmp).map_err(|e| OutputError::new("create", &tmp, e))?;
        Ok(Self {
            target: target.to_owned(),
            tmp,
            writer: Some(BufWriter::with_capacity(1 << 16, file)),
        })
    }

    /// Writes `bytes` to `target` in one go: whole or not at all.
    pub fn write(target: &Path, bytes: &[u8]) -> Result<(), OutputError> {
        let mut f = Self::create(target)?;
        f.write_all(bytes).map_err(|e| f.error(e))?;
        f.commit()
    }

    /// The path it will have once committed.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// An error of writing this file, naming its final path.
    pub fn error(&self, e: io::Error) -> OutputError {
        OutputError::new("write", &self.target, e)
    }

    /// Flushes and syncs the data to disk, without renaming yet (see `rename`):
    /// after this, only the rename is left, which needs no space.
    pub fn finish(mut self) -> Result<Finished, OutputError> {
        let w = self.writer.take().expect("written once");
        let file = w
            .into_inner()
            .map_err(|e| OutputError::new("write", &self.target, e.into_error()))?;
        file.sync_all()
            .map_err(|e| OutputError::new("write", &self.target, e))?;
        Ok(Finished {
            target: std::mem::take(&mut self.target),
            tmp: std::mem::take(&mut self.tmp),
        })
    }

    /// [`finish`](Self::finish) then [`Finished::rename`].
    pub fn commit(self) -> Result<(), OutputError> {
        self.finish()?.rename()
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.writer.as_mut().expect("not finished").write(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.writer.as_mut().expect("not finished").flush()
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        // Not finished (a write, the last flush or the sync failed: a full disk): the
        // temporary file is garbage (an error was already reported). `finish` takes `tmp`
        // when it hands the file on.
        if !self.tmp.as_os_str().is_empty() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// A complete, synced temporary file waiting to be renamed over its target.
#[derive(Debug)]
pub struct Finished {
    target: PathBuf,
    tmp: PathBuf,
}

impl Finished {
    /// Renames the file into place (atomic) and syncs the directory entry.
    pub fn rename(mut self) -> Result<(), OutputError> {
        std::fs::rename(&self.tmp, &self.target)
            .map_err(|e| OutputError::new("rename into", &self.target, e))?;
        self.tmp = PathBuf::new();
        sync_dir(&self.target);
        Ok(())
    }
}

impl Drop for Finished {
    fn drop(&mut self) {
        if !self.tmp.as_os_str().is_empty() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Makes a rename in `file`'s directory durable (POSIX: fsync the directory). Best effort:
/// a file system that cannot sync a directory still renamed atomically.
fn sync_dir(file: &Path) {
    #[cfg(unix)]
    if let Some(dir) = file.parent() {
        let dir = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
    }
}

/// Removes `path` if it exists (a missing file is not an error).
pub fn remove_if_present(path: &Path) -> Result<(), OutputError> {
    match std::fs::remove_file(path) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(OutputError::new("remove", path, e)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("fado-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn a_second_lock_on_a_directory_is_refused_until_the_first_is_dropped() {
        let dir = scratch("lock");
        let first = DirLock::acquire(&dir).unwrap();
        let second = DirLock::acquire(&dir).unwrap_err();
        assert!(second.is_busy(), "{second}");
        assert!(second.to_string().contains(&dir.display().to_string()));
        drop(first);
        DirLock::acquire(&dir).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_uncommitted_file_leaves_the_old_one_and_no_temporary() {
        let dir = scratch("atomic");
        let _lock = DirLock::acquire(&dir).unwrap();
        let target = dir.join("a.txt");
        AtomicFile::write(&target, b"old").unwrap();
        {
            let mut f = AtomicFile::create(&target).unwrap();
            f.write_all(b"new, half").unwrap();
            // dropped without commit: an error path
        }
        assert_eq!(std::fs::read(&target).unwrap(), b"old");
        let mut f = AtomicFile::create(&target).unwrap();
        f.write_all(b"new").unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"old");
        f.commit().unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        let names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names.len(), 2, "{names:?}"); // a.txt and the lock file
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_file_whose_last_flush_failed_leaves_no_temporary() {
        // `finish` takes the writer before its flush and sync; when they fail (a full disk:
        // `sweep.json` buffered whole, `ENOSPC` at the flush) the file is dropped in that state.
        let dir = scratch("flush");
        let _lock = DirLock::acquire(&dir).unwrap();
        let mut f = AtomicFile::create(&dir.join("sweep.json")).unwrap();
        f.write_all(b"{}").unwrap();
        let tmp = f.tmp.clone();
        assert!(tmp.exists());
        drop(f.writer.take());
        drop(f);
        assert!(!tmp.exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_killed_writers_temporary_is_removed_by_the_next_lock() {
        let dir = scratch("stale");
        std::fs::create_dir_all(&dir).unwrap();
        let stale = dir.join(".traces.csv.tmp-999999");
        std::fs::write(&stale, b"cut mid-li").unwrap();
        std::fs::write(dir.join("keep.csv"), b"x").unwrap();
        let _lock = DirLock::acquire(&dir).unwrap();
        assert!(!stale.exists());
        assert!(dir.join("keep.csv").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_output_directory_that_is_a_file_is_named_as_such() {
        let dir = scratch("outfile");
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("results");
        std::fs::write(&file, b"x").unwrap();
        let e = DirLock::acquire(&file).unwrap_err().to_string();
        assert!(e.contains("results") && e.contains("it is a file"), "{e}");
        assert_eq!(std::fs::read(&file).unwrap(), b"x");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn errors_name_the_path() {
        let e = AtomicFile::create(Path::new("/nonexistent-dir-fado/x.json")).unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("/nonexistent-dir-fado/.x.json.tmp-"),
            "{text}"
        );
        assert!(!e.is_busy());
    }
}
