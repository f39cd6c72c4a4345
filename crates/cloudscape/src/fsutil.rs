//! File-system helpers shared by every module that writes files: every file appears whole or not
//! at all, also when the process is interrupted ([`abandon_writes`]).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

/// The temporary files being written now, and whether they were abandoned ([`abandon_writes`]).
struct Pending {
    files: Vec<PathBuf>,
    abandoned: bool,
}

static PENDING: Mutex<Pending> = Mutex::new(Pending {
    files: Vec::new(),
    abandoned: false,
});

fn pending() -> std::sync::MutexGuard<'static, Pending> {
    // A writer that panicked leaves the list as it was: still the files to remove.
    PENDING
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Removes the temporary file of every write in progress and refuses new ones, so that the
/// process can then end at once (a host's Ctrl-C handler) with no file left partial: the files
/// being written are left as they were. Writes that try to complete afterwards fail with
/// [`std::io::ErrorKind::Interrupted`].
pub fn abandon_writes() {
    let mut pending = pending();
    pending.abandoned = true;
    for file in pending.files.drain(..) {
        let _ = std::fs::remove_file(file);
    }
}

/// A temporary file being written: listed, so that [`abandon_writes`] removes it, until
/// dropped. Writers that hand a temporary file to another process (an encoder) list it too.
pub struct PendingFile(PathBuf);

impl PendingFile {
    /// Lists `path`, a temporary file that another process creates and writes. Fails with
    /// [`std::io::ErrorKind::Interrupted`] once writes were abandoned.
    pub fn list(path: &Path) -> std::io::Result<PendingFile> {
        Self::list_with(path, |_| Ok(())).map(|(pending, ())| pending)
    }

    /// Creates and lists `path`, at once, so that an exit never misses it.
    fn create(path: &Path) -> std::io::Result<(PendingFile, File)> {
        Self::list_with(path, |p| File::create(p))
    }

    fn list_with<T>(
        path: &Path,
        make: impl FnOnce(&Path) -> std::io::Result<T>,
    ) -> std::io::Result<(PendingFile, T)> {
        let mut pending = pending();
        if pending.abandoned {
            return Err(std::io::Error::new(
                std::io::ErrorKind::Interrupted,
                "writes were abandoned: the process is exiting",
            ));
        }
        let made = make(path)?;
        pending.files.push(path.to_path_buf());
        Ok((PendingFile(path.to_path_buf()), made))
    }

    /// Renames the file to `target`, unless an exit has removed it first.
    pub fn rename_to(&self, target: &Path) -> std::io::Result<()> {
        let _pending = pending();
        std::fs::rename(&self.0, target)
    }
}

impl Drop for PendingFile {
    fn drop(&mut self) {
        pending().files.retain(|f| *f != self.0);
    }
}

/// The user's cache directory, where derived files that take long to make are kept (the
/// particles' tables, the field's noise): `$CLOUDSCAPE_CACHE_DIR`, else `$XDG_CACHE_HOME/cloudscape`, else
/// `~/.cache/cloudscape`, else `cloudscape-cache` in the system's temporary directory.
pub fn cache_dir() -> PathBuf {
    let var = |name: &str| {
        std::env::var_os(name)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    var("CLOUDSCAPE_CACHE_DIR")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("cloudscape")))
        .or_else(|| var("HOME").map(|d| d.join(".cache").join("cloudscape")))
        .unwrap_or_else(|| std::env::temp_dir().join("cloudscape-cache"))
}

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
    let (pending, file) = PendingFile::create(&temporary).map_err(&io_error)?;
    let result = write_and_close(file, &io_error, write)
        .and_then(|()| pending.rename_to(path).map_err(&io_error));
    if result.is_err() {
        // The temporary file is ours and incomplete; a failure to remove it cannot make the
        // outcome worse.
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

/// Runs `write` on `file`, and flushes, syncs and closes it (a file must be closed before it is
/// renamed on some systems).
fn write_and_close<E>(
    file: File,
    io_error: impl Fn(std::io::Error) -> E,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), E>,
) -> Result<(), E> {
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

    /// The directory.
    pub(crate) fn path(&self) -> &Path {
        &self.0
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

    /// A writer that takes `capacity` bytes and then fails as a full disk does.
    struct FullDisk<'a> {
        inner: &'a mut dyn Write,
        capacity: usize,
    }

    impl Write for FullDisk<'_> {
        fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
            if self.capacity == 0 {
                return Err(std::io::Error::from_raw_os_error(28)); // ENOSPC
            }
            let n = bytes.len().min(self.capacity);
            self.capacity -= n;
            self.inner.write(&bytes[..n])
        }

        fn flush(&mut self) -> std::io::Result<()> {
            self.inner.flush()
        }
    }

    #[test]
    fn a_full_disk_part_way_keeps_the_old_file_and_says_so() {
        let (dir, path) = with_old_file("fsutil-full");
        let error = write_atomically(
            &path,
            |error| error,
            |file| {
                let mut disk = FullDisk {
                    inner: file,
                    capacity: 1000,
                };
                disk.write_all(&[7; 5000])
            },
        )
        .expect_err("the disk is full");
        assert_eq!(error.raw_os_error(), Some(28));
        assert!(
            error.to_string().contains("No space left on device"),
            "{error}"
        );
        assert_eq!(std::fs::read(&path).expect("read"), b"old");
        assert_eq!(dir.entries(), ["out.bin"]);
        assert!(!pending().files.iter().any(|f| f.starts_with(&dir.0)));
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
