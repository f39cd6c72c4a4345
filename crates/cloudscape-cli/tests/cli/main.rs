//! End-to-end tests of the `cloudscape` binary: each runs the real executable in a fresh scratch
//! directory and checks its exit status, its messages and the files it writes (or must not write).
//!
//! GPU work stays tiny (64x36 pixels, low quality). Like the library's GPU tests, these honour
//! `CLOUDSCAPE_TEST_BACKEND` (`vulkan` or `gl`) and fail, never skip, when no adapter exists.
//! One test binary holds every command's tests, so they share [`support`].

mod animate;
mod bake;
mod commands;
#[cfg(unix)]
mod faults;
mod needs;
mod reference;
mod support;
mod vdb;
#[cfg(unix)]
mod view;
#[cfg(unix)]
mod xvfb;

/// Sparse test clouds, shared with the library's GPU field tests.
#[path = "../../../cloudscape/tests/support/puffs.rs"]
mod puffs;

/// FLIP against goldens in `tests/golden/`, shared with the library's golden tests.
#[path = "../../../cloudscape/tests/support/mod.rs"]
mod golden;
