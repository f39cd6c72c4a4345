//! Adapter and device set-up: the only code in the crate that knows wgpu's set-up API.
//!
//! [`GpuContext::new`] enumerates every adapter of the allowed backends (without a backend asked
//! for, Vulkan, Metal and DX12, and GL only when none of them has an adapter), filters them by
//! name, ranks them (discrete > integrated > virtual > CPU > other, then Vulkan / Metal / DX12 over
//! GL) and opens a device with the adapter's own limits and, when available, timestamp queries.

use std::fmt;
use std::str::FromStr;
use std::sync::{Arc, Mutex, PoisonError};

/// What to install when no adapter exists; part of every [`GpuError::NoAdapter`] message.
const INSTALL_HINT: &str = "On Debian/Ubuntu: apt-get install mesa-vulkan-drivers libvulkan1 \
     (software Vulkan) or a GPU driver; or pass --backend gl to use OpenGL (llvmpipe via EGL)";

/// A graphics API that wgpu can run on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    /// Vulkan (Linux, Windows, Android; Mesa lavapipe in software).
    Vulkan,
    /// OpenGL ES / desktop GL through EGL (Mesa llvmpipe in software).
    Gl,
    /// Metal (macOS, iOS).
    Metal,
    /// Direct3D 12 (Windows).
    Dx12,
}

impl Backend {
    /// Every backend, in the order used when listing them.
    pub const ALL: [Backend; 4] = [Backend::Vulkan, Backend::Gl, Backend::Metal, Backend::Dx12];

    /// The name used on the command line and in [`fmt::Display`].
    pub fn name(self) -> &'static str {
        match self {
            Backend::Vulkan => "vulkan",
            Backend::Gl => "gl",
            Backend::Metal => "metal",
            Backend::Dx12 => "dx12",
        }
    }

    fn to_wgpu(self) -> wgpu::Backends {
        match self {
            Backend::Vulkan => wgpu::Backends::VULKAN,
            Backend::Gl => wgpu::Backends::GL,
            Backend::Metal => wgpu::Backends::METAL,
            Backend::Dx12 => wgpu::Backends::DX12,
        }
    }
}

impl fmt::Display for Backend {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Backend {
    type Err = GpuError;

    /// Parses `vulkan`, `gl`, `metal` or `dx12` (case-insensitive).
    fn from_str(text: &str) -> Result<Backend, GpuError> {
        Backend::ALL
            .into_iter()
            .find(|backend| backend.name().eq_ignore_ascii_case(text.trim()))
            .ok_or_else(|| GpuError::UnknownBackend {
                name: text.to_string(),
            })
    }
}

/// How to choose the adapter.
#[derive(Clone, Debug, Default)]
pub struct GpuOptions {
    /// Only this backend; `None` allows Vulkan, GL, Metal and DX12.
    pub backend: Option<Backend>,
    /// Only adapters whose name contains this text (case-insensitive).
    pub adapter_substring: Option<String>,
}

/// Why no GPU context could be made.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// A backend name that is not one of ours.
    #[error("unknown GPU backend {name:?}: expected one of vulkan, gl, metal, dx12")]
    UnknownBackend {
        /// The text that was given.
        name: String,
    },
    /// No adapter passed the filters.
    #[error("no usable GPU adapter: {seen}.\n{INSTALL_HINT}")]
    NoAdapter {
        /// The adapters that were seen and why each was rejected, or that none was seen.
        seen: String,
    },
    /// The window system refused a surface to present to.
    #[error("cannot present to the window: {source}")]
    CreateSurface {
        /// wgpu's reason.
        #[source]
        source: wgpu::CreateSurfaceError,
    },
    /// The chosen adapter refused to open a device.
    #[error("the GPU adapter {adapter} could not open a device: {source}")]
    RequestDevice {
        /// [`GpuContext::summary`]-style description of the adapter.
        adapter: String,
        /// wgpu's reason.
        #[source]
        source: wgpu::RequestDeviceError,
    },
}

/// An open device and its queue, with what was learnt about the adapter.
///
/// Cloning is cheap: wgpu handles are reference counted, and clones share one device.
#[derive(Clone, Debug)]
pub struct GpuContext {
    /// The logical device.
    pub device: wgpu::Device,
    /// Its only queue.
    pub queue: wgpu::Queue,
    adapter: wgpu::Adapter,
    info: wgpu::AdapterInfo,
    /// The instance the adapter came from; None for a host's own device.
    instance: Option<wgpu::Instance>,
    /// Textures made once for the device ([`GpuContext::shared_texture`]).
    shared_textures: Arc<Mutex<Vec<(SharedTextureKey, wgpu::Texture)>>>,
}

/// What names a texture [`GpuContext::shared_texture`] shares: what it holds and the number it
/// was made from (a noise seed).
pub type SharedTextureKey = (&'static str, u64);

/// Textures [`GpuContext::shared_texture`] keeps: the last eight made (the noise of a field is
/// three; a viewer that changes seeds keeps a few of them).
const SHARED_TEXTURES_KEPT: usize = 8;

impl GpuContext {
    /// Picks an adapter as described in the module documentation and opens a device on it.
    /// Blocks until the device is ready.
    pub fn new(options: &GpuOptions) -> Result<GpuContext, GpuError> {
        pollster::block_on(Self::new_async(options))
    }

    async fn new_async(options: &GpuOptions) -> Result<GpuContext, GpuError> {
        let without_display = wgpu::InstanceDescriptor::new_without_display_handle;
        if options.backend.is_some() {
            return Self::open(
                instance(backends(options), without_display()),
                options,
                None,
            )
            .await;
        }
        // GL is probed only when no native API offers an adapter: its probe of the display
        // servers is slow and, without XDG_RUNTIME_DIR, prints a frightening libwayland error.
        match Self::open(
            instance(native_backends(), without_display()),
            options,
            None,
        )
        .await
        {
            Err(GpuError::NoAdapter { .. }) => {
                Self::open(instance(all_backends(), without_display()), options, None).await
            }
            opened => opened,
        }
    }

    /// Like [`GpuContext::new`], for a window: the instance is made with the window system's
    /// `display` (GL presents through it), a surface is made for `window`, and only adapters that
    /// can present to it are considered.
    pub fn with_surface(
        options: &GpuOptions,
        display: Box<dyn wgpu::wgt::WgpuHasDisplayHandle>,
        window: impl Into<wgpu::SurfaceTarget<'static>>,
    ) -> Result<(GpuContext, wgpu::Surface<'static>), GpuError> {
        let descriptor = wgpu::InstanceDescriptor::new_with_display_handle(display);
        let instance = instance(backends(options), descriptor);
        let surface = instance
            .create_surface(window)
            .map_err(|source| GpuError::CreateSurface { source })?;
        let context = pollster::block_on(Self::open(instance, options, Some(&surface)))?;
        Ok((context, surface))
    }

    /// A new surface for `window` on this context's instance, to replace a lost one.
    ///
    /// # Panics
    /// For a context made by [`GpuContext::from_wgpu`], which has no instance.
    pub fn create_surface(
        &self,
        window: impl Into<wgpu::SurfaceTarget<'static>>,
    ) -> Result<wgpu::Surface<'static>, GpuError> {
        let instance = self
            .instance
            .as_ref()
            .expect("a context made by GpuContext::new");
        instance
            .create_surface(window)
            .map_err(|source| GpuError::CreateSurface { source })
    }

    /// Picks the adapter (one that presents to `surface`, when given) and opens a device on it.
    async fn open(
        instance: wgpu::Instance,
        options: &GpuOptions,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<GpuContext, GpuError> {
        let adapters = instance.enumerate_adapters(backends(options)).await;
        let adapter = choose_adapter(adapters, options, surface)?;
        let info = adapter.get_info();
        let (device, queue) = adapter
            .request_device(&device_descriptor(&adapter))
            .await
            .map_err(|source| GpuError::RequestDevice {
                adapter: describe(&info),
                source,
            })?;
        Ok(GpuContext {
            device,
            queue,
            adapter,
            info,
            instance: Some(instance),
            shared_textures: Arc::default(),
        })
    }

    /// Wraps a device, queue and adapter the host renderer already owns (a game engine's): the
    /// library then renders on the host's device, into textures the host can sample or present.
    /// The device needs no feature beyond WebGPU's defaults; with
    /// [`wgpu::Features::TIMESTAMP_QUERY`] passes can be timed.
    pub fn from_wgpu(
        adapter: wgpu::Adapter,
        device: wgpu::Device,
        queue: wgpu::Queue,
    ) -> GpuContext {
        let info = adapter.get_info();
        GpuContext {
            device,
            queue,
            adapter,
            info,
            instance: None,
            shared_textures: Arc::default(),
        }
    }

    /// The texture `make` makes for `key`, made once for this device and shared by everything
    /// on it that asks for the same key: for inputs that depend on nothing but their key (a
    /// field's noise, from its kind and seed), so a second renderer on the device (another
    /// camera, another technique, the next test) makes none. The caller must not write to it.
    /// The last few keys are kept; on a software adapter the field's noise is seconds of work.
    pub fn shared_texture(
        &self,
        key: SharedTextureKey,
        make: impl FnOnce() -> wgpu::Texture,
    ) -> wgpu::Texture {
        let lock = || {
            self.shared_textures
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
        };
        if let Some((_, texture)) = lock().iter().find(|(k, _)| *k == key) {
            return texture.clone();
        }
        let texture = make();
        let mut kept = lock();
        kept.retain(|(k, _)| *k != key);
        if kept.len() >= SHARED_TEXTURES_KEPT {
            kept.remove(0);
        }
        kept.push((key, texture.clone()));
        texture
    }

    /// The chosen adapter (a window's surface asks it what it can present).
    pub fn adapter(&self) -> &wgpu::Adapter {
        &self.adapter
    }

    /// The chosen adapter's name, backend, type and driver.
    pub fn adapter_info(&self) -> &wgpu::AdapterInfo {
        &self.info
    }

    /// One line naming the adapter, e.g. `llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan, Cpu)`.
    pub fn summary(&self) -> String {
        describe(&self.info)
    }

    /// Whether passes can write timestamps ([`wgpu::Features::TIMESTAMP_QUERY`] was granted).
    pub fn has_timestamps(&self) -> bool {
        self.device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
    }

    /// Largest width or height of a 2D texture on this device, in texels.
    pub fn max_texture_dimension_2d(&self) -> u32 {
        self.device.limits().max_texture_dimension_2d
    }

    /// The features the adapter offers, whether or not the device requested them.
    pub fn adapter_features(&self) -> wgpu::Features {
        self.adapter.features()
    }

    /// The GPU memory and live objects wgpu reports now (see [`super::GpuMemoryReport`]).
    pub fn memory_report(&self) -> super::GpuMemoryReport {
        super::GpuMemoryReport::new(&self.device, self.instance.as_ref())
    }

    /// Blocks until the GPU has finished all submitted work.
    ///
    /// # Panics
    /// When the device is lost.
    pub fn wait_idle(&self) {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .unwrap_or_else(|error| panic!("the GPU device was lost: {error}"));
    }
}

/// An instance of `backends`, with wgpu's debugging flags from the environment.
fn instance(backends: wgpu::Backends, mut descriptor: wgpu::InstanceDescriptor) -> wgpu::Instance {
    descriptor.backends = backends;
    descriptor.flags = descriptor.flags.with_env();
    wgpu::Instance::new(descriptor)
}

/// The backends `options` allow.
fn backends(options: &GpuOptions) -> wgpu::Backends {
    options.backend.map_or(all_backends(), Backend::to_wgpu)
}

/// Every backend but GL.
fn native_backends() -> wgpu::Backends {
    all_backends() - Backend::Gl.to_wgpu()
}

fn all_backends() -> wgpu::Backends {
    Backend::ALL
        .into_iter()
        .fold(wgpu::Backends::empty(), |all, backend| {
            all | backend.to_wgpu()
        })
}

fn describe(info: &wgpu::AdapterInfo) -> String {
    format!("{} ({:?}, {:?})", info.name, info.backend, info.device_type)
}

/// Keeps the adapters whose name matches (and that present to `surface`, when given), then takes
/// the best by [`rank`]; the first wins a tie.
fn choose_adapter(
    adapters: Vec<wgpu::Adapter>,
    options: &GpuOptions,
    surface: Option<&wgpu::Surface<'_>>,
) -> Result<wgpu::Adapter, GpuError> {
    let (matching, rejected): (Vec<_>, Vec<_>) = adapters
        .into_iter()
        .partition(|adapter| rejection(adapter, options, surface).is_none());
    let key = |adapter: &wgpu::Adapter| {
        let info = adapter.get_info();
        rank(info.device_type, info.backend)
    };
    matching
        .into_iter()
        .min_by_key(key)
        .ok_or_else(|| GpuError::NoAdapter {
            seen: rejection_report(&rejected, options, surface),
        })
}

/// Why `adapter` is not used, or None when it may be.
fn rejection(
    adapter: &wgpu::Adapter,
    options: &GpuOptions,
    surface: Option<&wgpu::Surface<'_>>,
) -> Option<String> {
    let wanted = options.adapter_substring.as_deref().map(str::to_lowercase);
    if let Some(text) = wanted.filter(|t| !adapter.get_info().name.to_lowercase().contains(t)) {
        return Some(format!("name does not contain {text:?}"));
    }
    surface
        .filter(|surface| !adapter.is_surface_supported(surface))
        .map(|_| "it cannot present to the window".to_string())
}

/// Sort key of an adapter: device type first, then native APIs before GL. Lower is better.
fn rank(device_type: wgpu::DeviceType, backend: wgpu::Backend) -> (u8, u8) {
    let type_rank = match device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    };
    (type_rank, u8::from(backend == wgpu::Backend::Gl))
}

fn rejection_report(
    rejected: &[wgpu::Adapter],
    options: &GpuOptions,
    surface: Option<&wgpu::Surface<'_>>,
) -> String {
    let backends = options
        .backend
        .map_or("vulkan, gl, metal or dx12".to_string(), |b| b.to_string());
    if rejected.is_empty() {
        return format!("no adapter found on backend {backends}");
    }
    let lines: Vec<String> = rejected
        .iter()
        .map(|adapter| {
            let why = rejection(adapter, options, surface).unwrap_or_default();
            format!("{} rejected: {why}", describe(&adapter.get_info()))
        })
        .collect();
    format!("adapters seen on backend {backends}: {}", lines.join("; "))
}

/// Timestamp features when offered, and the adapter's own limits so that large textures work.
fn device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
    let timing = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
    wgpu::DeviceDescriptor {
        label: Some("cloudscape device"),
        required_features: adapter.features() & timing,
        required_limits: adapter.limits(),
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn backend_names_round_trip() {
        for backend in Backend::ALL {
            assert_eq!(backend.to_string().parse::<Backend>().unwrap(), backend);
        }
        assert_eq!("Vulkan".parse::<Backend>().unwrap(), Backend::Vulkan);
    }

    #[test]
    fn unknown_backend_lists_the_choices() {
        let message = "opengl".parse::<Backend>().unwrap_err().to_string();
        assert!(message.contains("\"opengl\"") && message.contains("vulkan, gl, metal, dx12"));
    }

    #[test]
    fn discrete_beats_cpu_and_vulkan_beats_gl() {
        let discrete_gl = rank(wgpu::DeviceType::DiscreteGpu, wgpu::Backend::Gl);
        let cpu_vulkan = rank(wgpu::DeviceType::Cpu, wgpu::Backend::Vulkan);
        let cpu_gl = rank(wgpu::DeviceType::Cpu, wgpu::Backend::Gl);
        let other_vulkan = rank(wgpu::DeviceType::Other, wgpu::Backend::Vulkan);
        assert!(discrete_gl < cpu_vulkan && cpu_vulkan < cpu_gl && cpu_gl < other_vulkan);
    }

    #[test]
    fn no_adapter_message_says_what_to_install() {
        let options = GpuOptions {
            backend: Some(Backend::Metal),
            adapter_substring: None,
        };
        let message = GpuError::NoAdapter {
            seen: rejection_report(&[], &options, None),
        }
        .to_string();
        assert!(message.contains("no adapter found on backend metal"));
        assert!(message.contains("apt-get install mesa-vulkan-drivers libvulkan1"));
        assert!(message.contains("--backend gl"));
    }
}
