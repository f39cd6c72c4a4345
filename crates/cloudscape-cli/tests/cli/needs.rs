//! What a test needs from the machine beyond Rust and a GPU adapter (a program, shared libraries,
//! the right to mount), and what a test does on a machine that lacks it: outside CI it prints one
//! line naming what is missing, what brings it and the test it did not run, and passes; with
//! `CI=true` it fails, so CI never loses a test silently. (A GPU test never goes through here: a
//! missing adapter always fails.)

use std::io::Write;
use std::path::Path;

/// Something the machine lacks: what it is and how to get it.
pub struct Missing {
    /// What is missing, e.g. `the program Xvfb`.
    pub what: String,
    /// What brings it, e.g. `Debian: apt-get install xvfb`.
    pub remedy: String,
}

/// Whether the calling test can go on: true when nothing is `missing`. Otherwise, outside CI,
/// prints `not run: <test>: needs <what> (<remedy>)` on stderr (past the test harness's capture,
/// so the line shows in `cargo test`'s output) and returns false; with `CI=true` it panics.
pub fn met(missing: Option<Missing>) -> bool {
    let Some(missing) = missing else {
        return true;
    };
    let thread = std::thread::current();
    let test = thread.name().unwrap_or("a test");
    let line = format!(
        "not run: {test}: needs {} ({})",
        missing.what, missing.remedy
    );
    assert!(!on_ci(), "{line}; with CI=true every test runs");
    let _ = writeln!(std::io::stderr(), "{line}");
    false
}

/// Whether this is a CI run (`CI` set to anything but empty, `0` or `false`).
fn on_ci() -> bool {
    std::env::var("CI").is_ok_and(|value| !matches!(value.trim(), "" | "0" | "false"))
}

/// `program` is missing when no directory on `PATH` holds it; Debian's `package` brings it.
pub fn program(program: &str, package: &str) -> Option<Missing> {
    let path = std::env::var_os("PATH").unwrap_or_default();
    let found = std::env::split_paths(&path).any(|dir| is_executable(&dir.join(program)));
    (!found).then(|| Missing {
        what: format!("the program {program}"),
        remedy: format!("Debian: apt-get install {package}"),
    })
}

/// The shared libraries of `libraries` (soname, Debian package) that cannot be loaded, if any.
#[cfg(unix)]
pub fn libraries(libraries: &[(&str, &str)]) -> Option<Missing> {
    let absent: Vec<&(&str, &str)> = libraries
        .iter()
        .filter(|(soname, _)| !loads(soname))
        .collect();
    (!absent.is_empty()).then(|| Missing {
        what: absent
            .iter()
            .map(|(soname, _)| *soname)
            .collect::<Vec<_>>()
            .join(", "),
        remedy: format!(
            "Debian: apt-get install {}",
            absent.iter().map(|(_, p)| *p).collect::<Vec<_>>().join(" ")
        ),
    })
}

/// Whether the dynamic loader finds and loads `soname`.
#[cfg(unix)]
fn loads(soname: &str) -> bool {
    let name = std::ffi::CString::new(soname).expect("a soname without NUL");
    // SAFETY: dlopen with a valid C string; a handle it returns is closed at once.
    unsafe {
        let handle = libc::dlopen(name.as_ptr(), libc::RTLD_LAZY | libc::RTLD_LOCAL);
        if handle.is_null() {
            return false;
        }
        libc::dlclose(handle);
    }
    true
}

#[cfg(unix)]
fn is_executable(path: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    path.metadata()
        .is_ok_and(|meta| meta.is_file() && meta.permissions().mode() & 0o111 != 0)
}

#[cfg(not(unix))]
fn is_executable(path: &Path) -> bool {
    path.is_file() || path.with_extension("exe").is_file()
}
