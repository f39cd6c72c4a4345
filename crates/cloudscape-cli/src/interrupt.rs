//! Ctrl-C (SIGINT): every command stops at once, says so, and leaves no partial file (files being
//! written are abandoned, `cloudscape::fsutil::exit_abandoning_writes`), exiting with 130. A
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
    eprintln!("\ninterrupted: stopped; no partial file was left");
    cloudscape::fsutil::exit_abandoning_writes(INTERRUPTED_STATUS)
}
