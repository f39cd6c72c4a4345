//! `XDG_RUNTIME_DIR` for processes started without it (services, cron, `env -i`): Mesa's Vulkan
//! device-selection layer and wgpu's GL probe ask libwayland for a display, and libwayland prints
//! `error: XDG_RUNTIME_DIR is invalid or not set in the environment.` when the variable is unset
//! or not absolute. A private directory stands in for it; no display is found there either, but
//! quietly.

use std::os::unix::fs::{DirBuilderExt, PermissionsExt};
use std::path::PathBuf;

const VARIABLE: &str = "XDG_RUNTIME_DIR";

/// Sets `XDG_RUNTIME_DIR` to a private directory (mode 0700, under the system's temporary
/// directory) when it is unset or not an absolute path. Call first in `main`, while the process
/// has a single thread.
pub fn ensure() {
    let set = std::env::var_os(VARIABLE).is_some_and(|dir| PathBuf::from(dir).is_absolute());
    if set {
        return;
    }
    let dir = std::env::temp_dir().join("cloudscape-runtime");
    // A directory that cannot be made or restricted still quiets libwayland, which only checks
    // that the path is absolute; nothing is ever written there.
    let _ = std::fs::DirBuilder::new()
        .recursive(true)
        .mode(0o700)
        .create(&dir);
    let _ = std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700));
    // SAFETY: called at the start of `main`, before any other thread exists, so no thread can
    // read the environment while it changes.
    unsafe { std::env::set_var(VARIABLE, &dir) };
}
