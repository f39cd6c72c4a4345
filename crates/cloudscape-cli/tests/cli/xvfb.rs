//! A virtual X server (Xvfb) for the tests of `cloudscape view`: a real window, on a display of
//! its own, with no screen attached.

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};

/// A running Xvfb, stopped when dropped.
pub struct Xvfb {
    child: Child,
    /// The display to name in `DISPLAY`, e.g. `:3`.
    pub display: String,
}

impl Xvfb {
    /// Starts Xvfb on a free display (it picks one and writes its number to `-displayfd`).
    ///
    /// # Panics
    /// When Xvfb cannot start: the viewer's tests never skip.
    pub fn start() -> Xvfb {
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
        Xvfb {
            display: format!(":{number}"),
            child,
        }
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
