//! Ctrl-C (SIGINT): every command stops at once, says so, and leaves no partial file (files being
//! written are abandoned, `cloudscape::fsutil::abandon_writes`), exiting with 130. A
//! command that can use its work so far (`reference`) asks for a graceful stop instead: the first
//! Ctrl-C raises [`stop_requested`], a second one abandons as above.

use std::sync::atomic::{AtomicBool, Ordering};

/// The exit status of a process ended by SIGINT (128 + 2, as shells report it).
const INTERRUPTED_STATUS: i32 = 130;

static GRACEFUL: AtomicBool = AtomicBool::new(false);
static STOP: AtomicBool = AtomicBool::new(false);

/// Installs the handler; call once, first thing.
pub fn install() -> anyhow::Result<()> {
    ctrlc::set_handler(on_interrupt)?;
    Ok(())
}

/// Makes the first Ctrl-C raise [`stop_requested`] rather than end the process.
pub fn stop_gracefully() {
    GRACEFUL.store(true, Ordering::SeqCst);
}

/// Whether Ctrl-C asked a graceful command to stop.
pub fn stop_requested() -> bool {
    STOP.load(Ordering::Relaxed)
}

fn on_interrupt() {
    if GRACEFUL.load(Ordering::SeqCst) && !STOP.swap(true, Ordering::SeqCst) {
        eprintln!("\ninterrupted: stopping (Ctrl-C again to abandon without writing)");
        return;
    }
    cloudscape::fsutil::abandon_writes();
    eprintln!("\ninterrupted: stopped; no partial file was left");
    exit_now(INTERRUPTED_STATUS)
}

/// Ends the process without running the C library's exit handlers: they tear down the graphics
/// driver (Mesa's llvmpipe) while the render thread may still be inside it, which corrupted the
/// heap and ended the process by SIGABRT instead of 130.
#[cfg(unix)]
fn exit_now(code: i32) -> ! {
    // SAFETY: `_exit` ends the process at once; stderr is unbuffered, so nothing is lost.
    unsafe { libc::_exit(code) }
}

#[cfg(not(unix))]
fn exit_now(code: i32) -> ! {
    std::process::exit(code)
}
