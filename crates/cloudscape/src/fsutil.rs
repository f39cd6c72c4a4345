//! File-system helpers shared by every module that writes files.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Runs `write` on a temporary file beside `path`, then flushes, syncs and renames it over
/// `path`, so that readers never see a partial file. On any error the temporary file is removed
/// and `path` is left as it was.
///
/// `io_error` turns the operating system's errors (creating, flushing, syncing, renaming) into the
/// caller's error type, which lets `write` report its own encoder errors unchanged.
pub(crate) fn write_atomically<E>(
    path: &Path,
    io_error: impl Fn(std::io::Error) -> E,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), E>,
) -> Result<(), E> {
    let temporary = temporary_path(path);
    let result = write_and_close(&temporary, &io_error, write)
        .and_then(|()| std::fs::rename(&temporary, path).map_err(&io_error));
    if result.is_err() {
        // The temporary file is ours and incomplete (or was never created); a failure to remove
        // it cannot make the outcome worse.
        let _ = std::fs::remove_file(&temporary);
    }
    result
}

/// [`write_atomically`] of a byte buffer.
pub(crate) fn write_bytes_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_atomically(path, |error| error, |file| file.write_all(bytes))
}

/// A temporary file name beside `path`: hidden, and unique to this process and call.
fn temporary_path(path: &Path) -> PathBuf {
    static WRITES: AtomicU64 = AtomicU64::new(0);
    let unique = WRITES.fetch_add(1, Ordering::Relaxed);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.{unique}.tmp", std::process::id()))
}

/// Creates `temporary`, runs `write` on it, and flushes, syncs and closes it (a file must be
/// closed before it is renamed on some systems).
fn write_and_close<E>(
    temporary: &Path,
    io_error: impl Fn(std::io::Error) -> E,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), E>,
) -> Result<(), E> {
    let file = File::create(temporary).map_err(&io_error)?;
    let mut writer = BufWriter::new(file);
    write(&mut writer)?;
    let file = writer
        .into_inner()
        .map_err(|error| io_error(error.into_error()))?;
    file.sync_all().map_err(io_error)
}

/// A scratch directory for tests, unique to the test process and name, removed when dropped.
#[cfg(test)]
pub(crate) struct ScratchDir(PathBuf);

#[cfg(test)]
impl ScratchDir {
    /// An empty directory `cloudscape-{name}-{process id}` in the system's temporary directory.
    pub(crate) fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("cloudscape-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create scratch dir");
        ScratchDir(dir)
    }

    /// The path of `name` inside the directory.
    pub(crate) fn join(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }

    /// The names of the directory's entries, sorted.
    pub(crate) fn entries(&self) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(&self.0)
            .expect("list scratch dir")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }
}

#[cfg(test)]
impl Drop for ScratchDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scratch directory holding the file `out.bin` with the contents `old`, and that file.
    fn with_old_file(name: &str) -> (ScratchDir, PathBuf) {
        let dir = ScratchDir::new(name);
        let path = dir.join("out.bin");
        std::fs::write(&path, b"old").expect("write old");
        (dir, path)
    }

    #[test]
    fn writes_the_bytes_and_leaves_no_temporary_file() {
        let (dir, path) = with_old_file("fsutil-bytes");
        write_bytes_atomically(&path, b"new contents").expect("write");
        assert_eq!(std::fs::read(&path).expect("read"), b"new contents");
        assert_eq!(dir.entries(), ["out.bin"]);
    }

    #[test]
    fn a_failed_write_keeps_the_old_file_and_the_callers_error() {
        let (dir, path) = with_old_file("fsutil-failed");
        let result = write_atomically(
            &path,
            |error| error.to_string(),
            |file| {
                file.write_all(b"partial").map_err(|e| e.to_string())?;
                Err("encoder failed".to_string())
            },
        );
        assert_eq!(result, Err("encoder failed".to_string()));
        assert_eq!(std::fs::read(&path).expect("read"), b"old");
        assert_eq!(dir.entries(), ["out.bin"]);
    }

    #[test]
    fn a_failed_rename_removes_the_temporary_file() {
        let dir = ScratchDir::new("fsutil-rename");
        let occupied = dir.join("taken");
        std::fs::create_dir(&occupied).expect("create dir");
        let error = write_bytes_atomically(&occupied, b"data").expect_err("a directory");
        assert!(!error.to_string().is_empty());
        assert_eq!(dir.entries(), ["taken"]);
    }
}
