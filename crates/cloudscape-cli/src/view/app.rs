//! The window's event loop: opens the viewer when the window system is ready, passes it the
//! window's and the mouse's events, and asks for a frame whenever the last one is done.

use std::path::PathBuf;

use anyhow::{Result, anyhow};
use cloudscape::gpu::GpuOptions;
use cloudscape::temporal::TemporalSettings;
use winit::application::ApplicationHandler;
use winit::event::{DeviceEvent, DeviceId, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::WindowId;

use super::ViewArgs;
use super::live::LiveScene;
use super::script::Script;
use super::viewer::Viewer;

/// Everything the viewer starts from, read and checked before the window opens.
pub struct Setup {
    /// The scene, loaded and checked.
    pub live: LiveScene,
    /// Which GPU.
    pub gpu: GpuOptions,
    /// The window's first inner size, pixels.
    pub window_size: [u32; 2],
    /// `--render-scale`; None picks by adapter (1/4 on a software adapter).
    pub render_scale: Option<f32>,
    /// Temporal reuse at the start; None for off. Without `--temporal`, one ray per 2x2 pixels
    /// (4x4 on a software adapter).
    pub temporal: Option<TemporalSettings>,
    /// Whether the command line chose the temporal reuse.
    pub temporal_given: bool,
    /// Vsync at the start.
    pub vsync: bool,
    /// Panels shown at the start.
    pub panels: bool,
    /// Frames to render before exiting; None to run until closed.
    pub frames: Option<u64>,
    /// Where the last frame's image goes (with `frames`).
    pub screenshot: Option<PathBuf>,
    /// Timed actions.
    pub script: Script,
    /// Whether the command line chose `render.quality` (else a software adapter starts at low).
    pub quality_given: bool,
}

impl Setup {
    /// Reads the scene and the script; every error is reported before a window opens.
    pub fn from_args(args: ViewArgs) -> Result<Setup> {
        let overrides = args.scene.all_overrides();
        let live = LiveScene::load(args.scene.scene.as_deref(), &overrides)?;
        let script = match &args.script {
            Some(path) => Script::read(path)?,
            None => Script::default(),
        };
        if let (Some(last), Some(frames)) = (script.last_frame(), args.frames)
            && last >= frames
        {
            return Err(anyhow!(
                "the script has a step at frame {last}, past the last of --frames {frames} \
                 (frames count from 0)"
            ));
        }
        let render = &live.scene.render;
        let divisor = args
            .temporal
            .map_or(Some(TemporalSettings::default().divisor), |t| t.0);
        let temporal_given = args.temporal.is_some();
        Ok(Setup {
            window_size: [render.width, render.height],
            gpu: args.gpu.options(),
            render_scale: args.render_scale,
            temporal: divisor.map(|divisor| TemporalSettings {
                divisor,
                ..TemporalSettings::default()
            }),
            temporal_given,
            vsync: !args.no_vsync,
            panels: !args.hide_panels,
            frames: args.frames,
            screenshot: args.screenshot,
            script,
            quality_given: overrides
                .iter()
                .any(|o| o.trim_start().starts_with("render.quality")),
            live,
        })
    }
}

/// Runs the event loop until the window closes or the frames are done.
pub fn run(setup: Setup) -> Result<()> {
    let event_loop = EventLoop::new().map_err(|e| {
        anyhow!(
            "cannot open a window: {e} (is there a display? set DISPLAY, or run under xvfb-run)"
        )
    })?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App {
        setup: Some(setup),
        viewer: None,
        outcome: Ok(()),
    };
    event_loop.run_app(&mut app)?;
    app.outcome
}

/// The event loop's state: the setup until the window opens, then the viewer.
struct App {
    setup: Option<Setup>,
    viewer: Option<Viewer>,
    /// The first error, which ends the loop.
    outcome: Result<()>,
}

impl App {
    /// Ends the loop with `error` (the first one is kept).
    fn fail(&mut self, event_loop: &ActiveEventLoop, error: anyhow::Error) {
        if self.outcome.is_ok() {
            self.outcome = Err(error);
        }
        event_loop.exit();
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        let Some(setup) = self.setup.take() else {
            return;
        };
        match Viewer::open(event_loop, setup) {
            Ok(viewer) => self.viewer = Some(viewer),
            Err(error) => self.fail(event_loop, error),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(viewer) = self.viewer.as_mut() else {
            return;
        };
        let result = viewer.window_event(&event);
        if let Err(error) = result {
            self.fail(event_loop, error);
        } else if viewer.finished() {
            event_loop.exit();
        }
    }

    fn device_event(&mut self, _: &ActiveEventLoop, _: DeviceId, event: DeviceEvent) {
        if let (Some(viewer), DeviceEvent::MouseMotion { delta }) = (self.viewer.as_mut(), event) {
            viewer.mouse_moved(delta);
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if let Some(viewer) = self.viewer.as_ref() {
            let drawing = viewer.request_frame();
            let flow = if drawing {
                ControlFlow::Poll
            } else {
                ControlFlow::Wait
            };
            event_loop.set_control_flow(flow);
        }
    }
}
