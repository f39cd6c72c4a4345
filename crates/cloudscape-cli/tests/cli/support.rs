//! What every end-to-end test needs: a scratch directory and a way to run the binary in it.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicU32, Ordering};

use cloudscape::gpu::TEST_BACKEND_ENV;

/// Arguments that keep a render small and fast, for tests of the commands rather than of the
/// lighting: a 64x36 image at low quality, a 64-texel shadow map and a 16x16x8-cell light volume.
/// The defaults (256 texels, 48x48x24 cells) cost a software GPU about 2 s of every still, at any
/// image size: `cloudscape bench --width 64 --height 36 --set render.quality=low` spends 2.4 s a
/// frame with them and 0.06 s with these.
pub const TINY: [&str; 12] = [
    "--width",
    "64",
    "--height",
    "36",
    "--set",
    "render.quality=low",
    "--set",
    "shadow.resolution=64",
    "--set",
    "lighting.volume_cells_horizontal=16",
    "--set",
    "lighting.volume_cells_vertical=8",
];

/// A scratch directory unique to one test, removed when dropped.
pub struct Scratch(PathBuf);

impl Scratch {
    /// An empty directory `cloudscape-cli-{test}-{process id}-{n}` in the system's temporary
    /// directory.
    pub fn new(test: &str) -> Scratch {
        static COUNT: AtomicU32 = AtomicU32::new(0);
        let n = COUNT.fetch_add(1, Ordering::Relaxed);
        let name = format!("cloudscape-cli-{test}-{}-{n}", std::process::id());
        let dir = std::env::temp_dir().join(name);
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create scratch dir");
        Scratch(dir)
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.0
    }

    /// The path of `name` inside the directory.
    pub fn join(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }

    /// The names of the files and directories in the directory.
    pub fn file_names(&self) -> BTreeSet<String> {
        let entries = std::fs::read_dir(&self.0).expect("list scratch dir");
        entries
            .map(|entry| entry.expect("read scratch dir entry").file_name())
            .map(|name| name.to_string_lossy().into_owned())
            .collect()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// What one run of the binary did.
pub struct Run {
    pub success: bool,
    pub stdout: String,
    pub stderr: String,
}

/// Runs `cloudscape args...` in `dir`, with `--backend` from `CLOUDSCAPE_TEST_BACKEND` when set
/// and `gpu` is true (only the commands that render take it).
pub fn cloudscape(dir: &Path, args: &[&str], gpu: bool) -> Run {
    run(command(dir, args, gpu))
}

/// What `command` did, once it has exited.
pub fn run(mut command: Command) -> Run {
    let output = command.output().expect("start the cloudscape binary");
    Run {
        success: output.status.success(),
        stdout: String::from_utf8_lossy(&output.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&output.stderr).into_owned(),
    }
}

/// The command `cloudscape args...` in `dir`, with `--backend` as [`cloudscape`] adds it.
pub fn command(dir: &Path, args: &[&str], gpu: bool) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_cloudscape"));
    command.current_dir(dir).args(args);
    if let Some(backend) = std::env::var_os(TEST_BACKEND_ENV).filter(|_| gpu) {
        command.arg("--backend").arg(backend);
    }
    command
}
