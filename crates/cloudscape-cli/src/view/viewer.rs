//! The viewer: the window, the GPU, the clouds, the camera and the panels, and what happens on
//! each event.

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result};
use cloudscape::gpu::{GpuContext, PassTimer};
use cloudscape::renderer::{CloudRenderer, PASS_COUNT};
use cloudscape::technique::TechniqueStats;
use cloudscape::temporal::TemporalSettings;
use glam::Vec2;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, KeyEvent, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::ActiveEventLoop;
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::Window;

use super::app::Setup;
use super::camera::{CameraRig, Mode, distance_to_altitude_m};
use super::keys::HeldKeys;
use super::live::{LiveScene, save_scene};
use super::panel::{Panel, Request, ViewSettings};
use super::present::Presenter;
use super::script::{Script, held_motion};
use super::stats::FrameStats;

/// Scene time a frame advances in a run of `--frames` (so that runs repeat exactly), s.
pub const SCRIPTED_FRAME_S: f32 = 1.0 / 30.0;
/// The longest step of the clock and the camera in one frame (after a stall), s.
pub const MAX_FRAME_S: f32 = 0.1;
/// Pixels the wheel scrolls per notch, when it reports pixels.
const PIXELS_PER_NOTCH: f64 = 40.0;

/// Render scale on a software adapter, unless `--render-scale` says otherwise.
const SOFTWARE_SCALE: f32 = 0.25;
/// Temporal grid on a software adapter, unless `--temporal` says otherwise: one ray per 4x4 pixels.
const SOFTWARE_DIVISOR: u32 = 4;

/// On a software adapter (a CPU emulating a GPU, tens of times slower), start where it is
/// interactive: one ray per 4x4 pixels per frame and `render.quality = low`, unless the command
/// line chose them; the panel raises them.
fn software_defaults(setup: &mut Setup) {
    if !setup.temporal_given {
        setup.temporal = setup.temporal.map(|t| TemporalSettings {
            divisor: SOFTWARE_DIVISOR,
            ..t
        });
    }
    if !setup.quality_given {
        match setup.live.set("render.quality=low") {
            Ok(()) => eprintln!(
                "a software adapter: starting at render.quality=low and one ray per \
                 {SOFTWARE_DIVISOR}x{SOFTWARE_DIVISOR} pixels (--set render.quality=..., \
                 --temporal N, or the panel, to choose)"
            ),
            Err(error) => eprintln!("warning: {error}"),
        }
    }
}

/// The viewer and everything it holds.
pub struct Viewer {
    pub(super) window: Arc<Window>,
    pub(super) ctx: GpuContext,
    pub(super) presenter: Presenter,
    pub(super) egui: egui_winit::State,
    pub(super) clouds: CloudRenderer,
    pub(super) host: Option<cloudscape::renderer::EmptyHost>,
    pub(super) timer: PassTimer,
    pub(super) live: LiveScene,
    pub(super) rig: CameraRig,
    pub(super) view: ViewSettings,
    pub(super) panel: Panel,
    pub(super) keys: HeldKeys,
    /// Keys a script holds down, in place of the keyboard's.
    pub(super) script_keys: Option<super::camera::Motion>,
    /// The right mouse button is held over the view: the mouse turns the camera.
    mouse_look: bool,
    pub(super) stats: FrameStats,
    pub(super) passes: Option<Vec<(String, f64)>>,
    pub(super) technique_stats: Option<TechniqueStats>,
    /// The adapter, in words.
    pub(super) adapter_line: String,
    /// Frames presented so far.
    pub(super) frame_index: u64,
    /// Scene time, s.
    pub(super) clock_s: f32,
    /// The size the clouds render at this frame (the viewport's, at the render scale), pixels.
    pub(super) render_size: glam::UVec2,
    pub(super) last_frame: Instant,
    pub(super) frames: Option<u64>,
    pub(super) screenshot: Option<std::path::PathBuf>,
    pub(super) script: Script,
    /// Egui's texture changes not yet drawn (a frame was skipped).
    pub(super) pending_textures: egui::TexturesDelta,
    finished: bool,
}

impl Viewer {
    /// Opens the window and the GPU on it, and builds the clouds of the scene.
    pub fn open(event_loop: &ActiveEventLoop, setup: Setup) -> Result<Viewer> {
        let [width, height] = setup.window_size;
        let attributes = Window::default_attributes()
            .with_title(format!("cloudscape view: {}", setup.live.origin()))
            .with_inner_size(PhysicalSize::new(width, height));
        let window = Arc::new(event_loop.create_window(attributes)?);
        let display = Box::new(event_loop.owned_display_handle());
        let (ctx, surface) = GpuContext::with_surface(&setup.gpu, display, window.clone())?;
        eprintln!("adapter: {}", ctx.summary());
        let presenter = Presenter::new(&ctx, window.clone(), surface, setup.vsync)?;
        let egui = egui_winit::State::new(
            egui::Context::default(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(ctx.max_texture_dimension_2d() as usize),
        );
        let software = ctx.adapter_info().device_type == wgpu::DeviceType::Cpu;
        let mut setup = setup;
        if software {
            software_defaults(&mut setup);
        }
        let live = setup.live;
        let clouds = CloudRenderer::new(&ctx, &live.scene, &live.base_dir())
            .map_err(|e| live.field_error(e))
            .context("while building the cloud field")?;
        let default_scale = if software { SOFTWARE_SCALE } else { 1.0 };
        Ok(Viewer {
            timer: PassTimer::new(&ctx, PASS_COUNT),
            rig: CameraRig::new(&live.scene.camera),
            view: ViewSettings {
                render_scale: setup.render_scale.unwrap_or(default_scale),
                temporal: setup.temporal,
                vsync: setup.vsync,
                panels: setup.panels,
                paused: false,
            },
            panel: Panel::new(live.default_save_path()),
            clock_s: live.scene.render.time_s,
            render_size: glam::UVec2::new(width, height),
            keys: HeldKeys::default(),
            script_keys: None,
            mouse_look: false,
            stats: FrameStats::new(),
            passes: None,
            technique_stats: None,
            adapter_line: ctx.summary(),
            frame_index: 0,
            last_frame: Instant::now(),
            frames: setup.frames,
            screenshot: setup.screenshot,
            script: setup.script,
            pending_textures: Default::default(),
            finished: false,
            host: None,
            live,
            clouds,
            window,
            ctx,
            presenter,
            egui,
        })
    }

    /// Whether the viewer is done (its window closed, or its frames rendered).
    pub fn finished(&self) -> bool {
        self.finished
    }

    /// Asks for the next frame, unless the window is minimised; true when one was asked for.
    pub fn request_frame(&self) -> bool {
        let drawing = self.presenter.visible() && !self.finished;
        if drawing {
            self.window.request_redraw();
        }
        drawing
    }

    /// Marks the viewer done.
    pub(super) fn finish(&mut self) {
        self.finished = true;
    }

    /// Takes one event of the window.
    pub fn window_event(&mut self, event: &WindowEvent) -> Result<()> {
        let consumed = self.egui.on_window_event(&self.window, event).consumed;
        match event {
            WindowEvent::RedrawRequested => return self.frame(),
            WindowEvent::CloseRequested => self.finished = true,
            WindowEvent::Resized(size) => self.presenter.resize(&self.ctx, size.width, size.height),
            WindowEvent::Focused(false) => self.keys.clear(),
            WindowEvent::KeyboardInput { event, .. } => self.key(event),
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Right,
                ..
            } => {
                let over_panels = self.egui.egui_ctx().egui_wants_pointer_input();
                self.mouse_look = *state == ElementState::Pressed && !over_panels;
                self.window.set_cursor_visible(!self.mouse_look);
            }
            WindowEvent::MouseWheel { delta, .. } if !consumed => {
                let notches = match delta {
                    MouseScrollDelta::LineDelta(_, y) => *y,
                    MouseScrollDelta::PixelDelta(p) => (p.y / PIXELS_PER_NOTCH) as f32,
                };
                self.rig.scroll(notches);
            }
            _ => {}
        }
        Ok(())
    }

    /// The mouse moved by `delta` (raw device units, about pixels).
    pub fn mouse_moved(&mut self, delta: (f64, f64)) {
        if self.mouse_look {
            self.rig.look(Vec2::new(delta.0 as f32, delta.1 as f32));
        }
    }

    /// A key: movement keys are held while down; the others act on their press, unless a panel's
    /// text field has the keyboard.
    fn key(&mut self, event: &KeyEvent) {
        let PhysicalKey::Code(code) = event.physical_key else {
            return;
        };
        if event.state == ElementState::Released {
            // Every release counts, so that no key stays held when typing begins.
            self.keys.update(code, false);
            return;
        }
        let typing = self.egui.egui_ctx().egui_wants_keyboard_input();
        if typing || self.keys.update(code, true) || event.repeat {
            return;
        }
        match code {
            KeyCode::Tab => self.view.panels = !self.view.panels,
            KeyCode::Space => self.view.paused = !self.view.paused,
            KeyCode::KeyR => self.handle(Request::ResetCamera),
            KeyCode::KeyO => {
                let orbiting = matches!(self.rig.mode, Mode::Orbit { .. });
                self.handle(Request::Orbit(!orbiting));
            }
            KeyCode::KeyP => {
                let path = self.panel.screenshot_path.clone().into();
                self.handle(Request::Screenshot(path));
            }
            _ => {}
        }
    }

    /// Carries out a request of the panels or the keys.
    pub(super) fn handle(&mut self, request: Request) {
        let outcome = match request {
            Request::Save(path) => save_scene(&self.viewed_scene(), &path)
                .map(|()| format!("saved {}", path.display())),
            Request::Screenshot(path) => self.write_screenshot(&path),
            Request::ResetCamera => {
                self.rig = CameraRig {
                    speed_m_per_s: self.rig.speed_m_per_s,
                    ..CameraRig::new(self.live.file_camera())
                };
                self.clouds.reset_history();
                Ok("camera reset to the scene's".to_string())
            }
            Request::Orbit(orbit) => {
                let scene = &self.live.scene;
                let middle_m = scene
                    .layers
                    .first()
                    .map_or(2000.0, |l| l.bottom_m + 0.5 * l.thickness_m);
                let far_m = 0.1 * scene.camera.far_m;
                self.rig.set_orbit(
                    orbit,
                    distance_to_altitude_m(&self.rig.pose, middle_m, far_m),
                );
                Ok(if orbit { "orbiting" } else { "flying" }.to_string())
            }
        };
        self.panel.status = outcome.unwrap_or_else(|e| format!("{e:#}"));
        eprintln!("{}", self.panel.status);
    }

    /// Runs the script's steps at this frame that come before drawing it.
    pub(super) fn script_before_frame(&mut self) -> Result<()> {
        let steps: Vec<_> = self.script.steps_at(self.frame_index).cloned().collect();
        for step in steps {
            for assignment in &step.set {
                let edit = assignment.clone();
                self.change_scene(|live| live.set(&edit))
                    .map_err(anyhow::Error::msg)
                    .with_context(|| format!("script, frame {}", step.frame))?;
            }
            if let Some(camera) = step.camera {
                self.rig.pose = super::camera::Pose {
                    position_m: camera.position_m.into(),
                    yaw_deg: camera.yaw_deg,
                    pitch_deg: camera.pitch_deg,
                };
                self.rig.mode = Mode::Fly;
                self.clouds.reset_history();
            }
            if let Some(names) = &step.hold {
                self.script_keys = Some(held_motion(names).map_err(anyhow::Error::msg)?);
            }
            if step.reset_camera {
                self.handle(Request::ResetCamera);
            }
            if let Some(orbit) = step.orbit {
                self.handle(Request::Orbit(orbit));
            }
            if let Some(scale) = step.render_scale {
                self.view.render_scale = scale;
            }
            if let Some([width, height]) = step.window_size {
                // The window system answers with a resize event in a later frame.
                let _ = self
                    .window
                    .request_inner_size(PhysicalSize::new(width, height));
            }
        }
        Ok(())
    }

    /// Runs the script's steps at this frame that come after drawing it: screenshots and saves.
    pub(super) fn script_after_frame(&mut self) -> Result<()> {
        let steps: Vec<_> = self.script.steps_at(self.frame_index).cloned().collect();
        for step in steps {
            if let Some(path) = &step.screenshot {
                self.write_screenshot(path)?;
            }
            if let Some(path) = &step.save {
                save_scene(&self.viewed_scene(), path)?;
                eprintln!("saved {}", path.display());
            }
        }
        Ok(())
    }

    /// Applies a change of the live scene, then rebuilds what depends on it; a change the scene
    /// or the renderer refuses leaves everything as it was, and says why.
    pub(super) fn change_scene(
        &mut self,
        change: impl FnOnce(&mut LiveScene) -> Result<(), String>,
    ) -> Result<(), String> {
        let previous = self.live.scene.clone();
        change(&mut self.live)?;
        let base_dir = self.live.base_dir();
        let applied = self
            .clouds
            .apply_edit(&self.ctx, &self.live.scene, &base_dir);
        match applied {
            Ok(update) => {
                if let Some(update) = update {
                    let noise = if update.noise_regenerated {
                        ", new noise"
                    } else {
                        ""
                    };
                    self.panel.status = format!("rebuilt the cloud field{noise}");
                }
                Ok(())
            }
            Err(error) => {
                let message = format!("{:#}", self.live.field_error(error));
                self.live.scene = previous;
                self.live.error = Some(message.clone());
                Err(message)
            }
        }
    }

    /// Writes the image of the last frame drawn as a PNG at `path` and an EXR beside it (waits
    /// for the GPU: a screenshot is not part of the frame path).
    pub(super) fn write_screenshot(&self, path: &Path) -> Result<String> {
        let rendered = cloudscape::renderer::read_back(&self.ctx, &self.clouds.images());
        let exr = path.with_extension("exr");
        rendered.ldr.write_png(path)?;
        rendered.hdr.write_exr(&exr)?;
        Ok(format!("wrote {} and {}", path.display(), exr.display()))
    }
}
