//! A virtual X server (Xvfb) for the tests of `cloudscape view`: a real window, on a display of
//! its own, with no screen attached.

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};

use crate::needs;

/// The X client libraries winit loads at run time (through x11-dl and xkbcommon-dl), with the
/// Debian packages that bring them.
const X_CLIENT_LIBRARIES: [(&str, &str); 7] = [
    ("libX11.so.6", "libx11-6"),
    ("libX11-xcb.so.1", "libx11-xcb1"),
    ("libXcursor.so.1", "libxcursor1"),
    ("libXi.so.6", "libxi6"),
    ("libXrandr.so.2", "libxrandr2"),
    ("libxkbcommon.so.0", "libxkbcommon0"),
    ("libxkbcommon-x11.so.0", "libxkbcommon-x11-0"),
];

/// A running Xvfb, stopped when dropped.
pub struct Xvfb {
    child: Child,
    /// The display to name in `DISPLAY`, e.g. `:3`.
    pub display: String,
}

impl Xvfb {
    /// Starts Xvfb on a free display (it picks one and writes its number to `-displayfd`); None,
    /// reported by [`needs::met`], when the machine lacks Xvfb or the X client libraries.
    ///
    /// # Panics
    /// When Xvfb is there but cannot start, or with `CI=true` when it is missing.
    pub fn start() -> Option<Xvfb> {
        let present = needs::met(needs::program("Xvfb", "xvfb"))
            && needs::met(needs::libraries(&X_CLIENT_LIBRARIES));
        if !present {
            return None;
        }
        let mut child = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-screen",
                "0",
                "640x480x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap_or_else(|e| {
                panic!("cannot start Xvfb ({e}): install it (Debian: apt-get install xvfb)")
            });
        let stdout = child.stdout.take().expect("Xvfb's stdout is piped");
        let mut line = String::new();
        BufReader::new(stdout)
            .read_line(&mut line)
            .expect("read Xvfb's display number");
        let number = line.trim();
        assert!(
            !number.is_empty() && number.chars().all(|c| c.is_ascii_digit()),
            "Xvfb gave no display number (got {line:?})"
        );
        Some(Xvfb {
            display: format!(":{number}"),
            child,
        })
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
