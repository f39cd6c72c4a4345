//! GPU set-up and utilities shared by every technique.
//!
//! - [`context`]: adapter choice and device creation, the only place that knows wgpu's set-up API.
//! - [`readback`]: copying textures and buffers back to the CPU.
//! - [`timing`]: per-pass GPU time from timestamp queries.
//! - [`memory`]: the memory and live objects wgpu reports, for leak checks.
//! - [`test_gpu`]: the device GPU tests share, taken in turns on OpenGL.
//! - [`pipeline`]: compute and raster pipeline builders; [`uniform`]: a uniform in its own group.

pub(crate) mod context;
pub(crate) mod memory;
pub mod readback;
pub(crate) mod test_gpu;
pub(crate) mod timing;

pub use context::{Backend, GpuContext, GpuError, GpuOptions};
pub use memory::GpuMemoryReport;
pub use readback::{read_buffer, read_texture, read_texture_rgba16f, read_texture_rgba32f};
pub use test_gpu::{TEST_BACKEND_ENV, TestGpu};
pub use timing::PassTimer;
pub(crate) mod late_readback;
#[cfg(test)]
pub(crate) mod layout_check;
pub mod pipeline;
pub(crate) mod uniform;
