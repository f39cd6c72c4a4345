//! The GPU context of tests: one device per test process, shared by every test thread, and taken
//! in turns on OpenGL.
//!
//! wgpu's GL backend guards its one EGL context with a lock it waits on for at most 6 s
//! (`CONTEXT_LOCK_TIMEOUT_SECS` in wgpu-hal's `gles/egl.rs`) before it panics ("Could not lock
//! adapter context"). On a software rasteriser a single submission holds that lock longer, so test
//! threads sharing the device must not wait on it: on GL each test holds the process's turn on the
//! device for as long as it uses it. Vulkan, Metal and DX12 devices are used by every test thread
//! at once.

use std::cell::Cell;
use std::ops::Deref;
use std::sync::{Mutex, MutexGuard, OnceLock, PoisonError};

use super::context::{Backend, GpuContext, GpuOptions};

/// Environment variable that picks the backend of [`GpuContext::for_tests`] (`vulkan` or `gl`).
pub const TEST_BACKEND_ENV: &str = "CLOUDSCAPE_TEST_BACKEND";

/// The turn on a GL device; whoever holds it is the only thread using the device.
static DEVICE_TURN: Mutex<()> = Mutex::new(());

thread_local! {
    /// How many [`TestGpu`]s this thread holds: a test's helpers may ask for the context again.
    static CONTEXTS_HELD: Cell<usize> = const { Cell::new(0) };
}

/// The shared GPU context of one test, with its turn on the device when the device is GL's.
/// Dereferences to [`GpuContext`]; the turn ends when it is dropped.
///
/// A test must not hand the device to another thread while it holds the turn and wait for it:
/// on GL that thread's own [`GpuContext::for_tests`] waits for the turn.
pub struct TestGpu {
    context: GpuContext,
    /// The turn, when this thread took it (GL, and no other `TestGpu` held on this thread).
    _turn: Option<MutexGuard<'static, ()>>,
}

impl Deref for TestGpu {
    type Target = GpuContext;

    fn deref(&self) -> &GpuContext {
        &self.context
    }
}

impl Drop for TestGpu {
    fn drop(&mut self) {
        CONTEXTS_HELD.with(|held| held.set(held.get() - 1));
    }
}

impl GpuContext {
    /// The shared context of GPU tests.
    ///
    /// Honours the environment variable [`TEST_BACKEND_ENV`] (`vulkan` or `gl`); without it any
    /// backend is allowed, chosen as [`GpuContext::new`] chooses. All callers in one process share
    /// one device, and the adapter used is printed once to stderr. On GL the caller waits for its
    /// turn on the device (see the module documentation).
    ///
    /// # Panics
    /// When the variable holds an unknown backend or no adapter exists: GPU tests never skip silently.
    pub fn for_tests() -> TestGpu {
        static SHARED: OnceLock<GpuContext> = OnceLock::new();
        let context = SHARED
            .get_or_init(|| {
                let context = Self::new(&test_options()).unwrap_or_else(|error| panic!("{error}"));
                eprintln!("cloudscape GPU tests run on {}", context.summary());
                context
            })
            .clone();
        let first_on_thread = CONTEXTS_HELD.with(|held| held.replace(held.get() + 1)) == 0;
        let is_gl = context.adapter_info().backend == wgpu::Backend::Gl;
        let turn = (first_on_thread && is_gl)
            .then(|| DEVICE_TURN.lock().unwrap_or_else(PoisonError::into_inner));
        TestGpu {
            context,
            _turn: turn,
        }
    }
}

fn test_options() -> GpuOptions {
    let backend = std::env::var(TEST_BACKEND_ENV)
        .ok()
        .filter(|text| !text.trim().is_empty());
    let backend = backend.map(|text| {
        text.parse::<Backend>()
            .unwrap_or_else(|error| panic!("{TEST_BACKEND_ENV}: {error}"))
    });
    GpuOptions {
        backend,
        adapter_substring: None,
    }
}
