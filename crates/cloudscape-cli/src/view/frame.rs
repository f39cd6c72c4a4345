//! One frame of the viewer: the scene file and the script, the camera, the panels, the clouds and
//! the window, in that order. Nothing here waits for the GPU: the technique's counters and the
//! pass times of an earlier frame are read when they are ready.

use std::path::Path;
use std::time::Instant;

use anyhow::Result;
use cloudscape::frame::{Frame, FrameSun};
use cloudscape::image::LdrImage;
use cloudscape::renderer::{EmptyHost, Reuse};
use cloudscape::scene::Scene;
use cloudscape::shadow::LightingReuse;
use glam::UVec2;

use super::panel::{Measured, PanelInputs, PanelOutput, Request};
use super::present::{PanelPaint, ViewImage};
use super::viewer::{MAX_FRAME_S, SCRIPTED_FRAME_S, Viewer};

/// The panels' output of one frame, ready to draw.
pub(super) struct Ui {
    output: PanelOutput,
    /// The scene as the panels left it: it holds the edit `output.edited` names.
    draft: Scene,
    primitives: Vec<egui::ClippedPrimitive>,
    screen: egui_wgpu::ScreenDescriptor,
    /// The viewport, the window's rectangle outside the panels: origin and size, pixels.
    viewport: ([u32; 2], [u32; 2]),
}

impl Viewer {
    /// Draws one frame.
    pub(super) fn frame(&mut self) -> Result<()> {
        self.stats.start_frame();
        let dt_s = self.frame_step_s();
        if let Some(reload) = self.live.poll_file() {
            self.reloaded(reload.camera_changed);
        }
        self.script_before_frame()?;
        let motion = self.script_keys.unwrap_or_else(|| self.keys.motion());
        self.rig.advance(&motion, dt_s);
        if !self.view.paused {
            self.clock_s += dt_s;
        }
        let vsync = self.view.vsync;
        let mut ui = self.run_panels();
        if let Some(key) = ui.output.edited.take() {
            let draft = unviewed(std::mem::take(&mut ui.draft), &self.live.scene);
            // A refused edit is shown in the panel; the scene stays as it was.
            let _ = self.change_scene(|live| live.edit(draft, &key));
        }
        if vsync != self.view.vsync {
            self.presenter.set_vsync(&self.ctx, self.view.vsync);
        }
        let Some(surface) = self.presenter.acquire(&self.ctx) else {
            return Ok(());
        };
        self.render_size = render_size(ui.viewport.1, self.view.render_scale);
        self.draw(&surface, &ui);
        if let Some(path) = self.window_shot_path() {
            self.capture_window(&ui, &path)?;
        }
        self.window.pre_present_notify();
        self.ctx.queue.present(surface);
        self.read_late_results();
        for request in std::mem::take(&mut ui.output.requests) {
            self.handle(request);
        }
        self.script_after_frame()?;
        self.frame_index += 1;
        self.end_of_run()
    }

    /// How far the clock and the camera move this frame: a fixed step in a run of `--frames`, the
    /// time since the last frame otherwise.
    fn frame_step_s(&mut self) -> f32 {
        let now = Instant::now();
        let measured_s = (now - self.last_frame).as_secs_f32();
        self.last_frame = now;
        if self.frames.is_some() {
            SCRIPTED_FRAME_S
        } else {
            measured_s.min(MAX_FRAME_S)
        }
    }

    /// After the last frame of a run of `--frames`: its screenshot, and the end.
    fn end_of_run(&mut self) -> Result<()> {
        if self.frames.is_some_and(|n| self.frame_index >= n) {
            eprintln!("{}", self.stats.summary());
            if let Some(passes) = &self.passes {
                let times: Vec<String> = passes
                    .iter()
                    .map(|(n, ms)| format!("{n} {ms:.1}"))
                    .collect();
                eprintln!("GPU ms per pass (timestamps): {}", times.join(", "));
            }
            if let Some(path) = self.screenshot.clone() {
                eprintln!("{}", self.write_screenshot(&path)?);
            }
            self.finish();
        }
        Ok(())
    }

    /// The scene file changed on disk and loaded: rebuild the field from it, and cut to its
    /// camera when the file moved it.
    fn reloaded(&mut self, camera_changed: bool) {
        let base_dir = self.live.base_dir();
        if let Err(error) = self
            .clouds
            .update_scene(&self.ctx, &self.live.scene, &base_dir)
        {
            self.live.error = Some(format!("{:#}", self.live.field_error(error)));
        }
        if camera_changed {
            self.handle(Request::ResetCamera);
        }
        self.panel.status = format!("reloaded {}", self.live.origin());
    }

    /// Runs the panels (none when hidden) and tessellates them.
    fn run_panels(&mut self) -> Ui {
        let input = self.egui.take_egui_input(&self.window);
        let context = self.egui.egui_ctx().clone();
        let mut output = PanelOutput::default();
        let mut viewport = egui::Rect::NOTHING;
        let mut draft = self.viewed_scene();
        let render_size = self.render_size.to_array();
        let full = context.run_ui(input, |ui| {
            if self.view.panels {
                let inputs = PanelInputs {
                    scene: &mut draft,
                    view: &mut self.view,
                    rig: &mut self.rig,
                    measured: Measured {
                        frames: &self.stats,
                        passes: self.passes.as_deref(),
                        has_timestamps: self.ctx.has_timestamps(),
                        technique: self.technique_stats,
                        render_size,
                        adapter: &self.adapter_line,
                    },
                    error: self.live.error.as_deref(),
                };
                output = self.panel.show(ui, inputs);
            }
            viewport = ui.available_rect_before_wrap();
        });
        self.egui
            .handle_platform_output(&self.window, full.platform_output);
        self.pending_textures.append(full.textures_delta);
        let size = self.window.inner_size();
        let window = [size.width, size.height];
        Ui {
            primitives: context.tessellate(full.shapes, full.pixels_per_point),
            screen: egui_wgpu::ScreenDescriptor {
                size_in_pixels: window,
                pixels_per_point: full.pixels_per_point,
            },
            viewport: physical_rect(viewport, full.pixels_per_point, window),
            draft,
            output,
        }
    }

    /// The live scene as it is viewed: with what the viewer owns (the camera it flies, the size it
    /// renders at, its clock) in place of the file's, as the panels show it and a saved scene
    /// holds it.
    pub(super) fn viewed_scene(&self) -> Scene {
        let mut scene = self.live.scene.clone();
        self.rig.pose.write_to(&mut scene.camera);
        scene.render.width = self.render_size.x;
        scene.render.height = self.render_size.y;
        scene.render.time_s = self.clock_s;
        scene
    }

    /// This frame's view: the viewer's own camera (through the scene's lens), size and clock,
    /// with the scene's sun and exposure.
    fn view_frame(&self, frame_index: u32) -> Frame {
        let scene = &self.live.scene;
        let mut camera = scene.camera.clone();
        self.rig.pose.write_to(&mut camera);
        let sun = FrameSun::from_scene(&scene.sun);
        Frame {
            time_s: self.clock_s,
            exposure_ev: scene.render.exposure_ev,
            frame_index,
            ..Frame::of_camera(&camera, self.render_size, sun)
        }
    }

    /// Records and submits the clouds, then the image and the panels into `surface`.
    fn draw(&mut self, surface: &wgpu::SurfaceTexture, ui: &Ui) {
        // Without temporal reuse a frame is a still, as `cloudscape render` draws it; with it, the
        // index advances the jitter every frame, and the shadow map is kept while it serves.
        let (frame_index, lighting_reuse) = match self.view.temporal {
            Some(_) => (self.frame_index as u32, Some(LightingReuse::REAL_TIME)),
            None => (0, None),
        };
        self.clouds.set_lighting_reuse(lighting_reuse);
        let frame = self.view_frame(frame_index);
        if self.host.as_ref().is_none_or(|h| !h.fits(&frame)) {
            self.host = Some(EmptyHost::new(&self.ctx, &frame));
        }
        let host = self.host.as_ref().expect("made above");
        let reuse = self.view.temporal.map_or(Reuse::None, Reuse::Temporal);
        self.clouds.begin_frame(&self.ctx, &frame, reuse);
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        self.timer.reset();
        let timer = Some(&mut self.timer);
        self.clouds
            .encode_clouds(&self.ctx, &mut encoder, host.depth(), None, timer);
        let timer = Some(&mut self.timer);
        self.clouds
            .encode_finish(&self.ctx, &mut encoder, &host.background(), timer);
        self.timer.resolve_late(&mut encoder);
        let target = surface.texture.create_view(&Default::default());
        let mut textures = std::mem::take(&mut self.pending_textures);
        self.encode_window(&mut encoder, &target, ui, &textures);
        self.ctx.queue.submit([encoder.finish()]);
        self.stats.watch_submission(&self.ctx.queue);
        self.presenter.free_textures(&textures);
        textures.clear();
    }

    /// Records the rendered image into its viewport and the panels over it, into `target`.
    fn encode_window(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        ui: &Ui,
        textures: &egui::TexturesDelta,
    ) {
        let image = ViewImage {
            texture: self.clouds.images().ldr,
            viewport: ui.viewport,
        };
        let paint = PanelPaint {
            primitives: &ui.primitives,
            textures,
            screen: &ui.screen,
        };
        self.presenter
            .encode(&self.ctx, encoder, target, Some(&image), &paint);
    }

    /// Where the script wants this frame's window written, if it does.
    fn window_shot_path(&self) -> Option<std::path::PathBuf> {
        self.script
            .steps_at(self.frame_index)
            .find_map(|step| step.window_screenshot.clone())
    }

    /// Draws this frame's window once more into a texture and writes it as a PNG: the picture of
    /// the viewer with its panels (waits for the GPU).
    fn capture_window(&mut self, ui: &Ui, path: &Path) -> Result<()> {
        let [width, height] = ui.screen.size_in_pixels;
        let format = self.presenter.format();
        let texture = self.ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("window capture"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        let target = texture.create_view(&Default::default());
        self.encode_window(&mut encoder, &target, ui, &Default::default());
        self.ctx.queue.submit([encoder.finish()]);
        let bytes = cloudscape::gpu::read_texture(&self.ctx, &texture);
        let bgra = matches!(format.remove_srgb_suffix(), wgpu::TextureFormat::Bgra8Unorm);
        let pixels = bytes
            .chunks_exact(4)
            .map(|p| match bgra {
                true => [p[2], p[1], p[0], 255],
                false => [p[0], p[1], p[2], 255],
            })
            .collect();
        let image = LdrImage {
            width,
            height,
            pixels,
        };
        image.write_png(path)?;
        eprintln!("wrote {}", path.display());
        Ok(())
    }

    /// The technique's counters and the pass times of the newest frame the GPU has finished.
    fn read_late_results(&mut self) {
        if let Some(stats) = self.clouds.stats(&self.ctx) {
            self.technique_stats = Some(stats);
        }
        if let Some(passes) = self.timer.latest_ms(&self.ctx) {
            self.passes = Some(passes);
        }
    }
}

/// The size the clouds render at: the viewport's at `scale`, at least a pixel each way.
fn render_size(viewport: [u32; 2], scale: f32) -> UVec2 {
    let scaled = |v: u32| ((v as f32 * scale).round() as u32).max(1);
    UVec2::new(scaled(viewport[0]), scaled(viewport[1]))
}

/// `rect` (points) in whole physical pixels, within a window of `window` pixels: origin, size.
fn physical_rect(
    rect: egui::Rect,
    pixels_per_point: f32,
    window: [u32; 2],
) -> ([u32; 2], [u32; 2]) {
    let clamp = |v: f32, max: u32| (v * pixels_per_point).round().clamp(0.0, max as f32) as u32;
    let min = [clamp(rect.min.x, window[0]), clamp(rect.min.y, window[1])];
    let max = [clamp(rect.max.x, window[0]), clamp(rect.max.y, window[1])];
    (
        min,
        [max[0].saturating_sub(min[0]), max[1].saturating_sub(min[1])],
    )
}

/// `draft` (the viewed scene, as the panels edited it) with the live scene's own camera pose,
/// render size and time back in place of the viewer's: those stay the viewer's, out of the scene.
fn unviewed(mut draft: Scene, live: &Scene) -> Scene {
    let (camera, own) = (&mut draft.camera, &live.camera);
    camera.position_m = own.position_m;
    camera.look_at_m = own.look_at_m;
    camera.yaw_deg = own.yaw_deg;
    camera.pitch_deg = own.pitch_deg;
    let (render, own) = (&mut draft.render, &live.render);
    (render.width, render.height, render.time_s) = (own.width, own.height, own.time_s);
    draft
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_render_size_is_the_viewport_at_the_scale_and_never_empty() {
        assert_eq!(render_size([320, 180], 0.5), UVec2::new(160, 90));
        assert_eq!(render_size([1000, 601], 0.25), UVec2::new(250, 150));
        assert_eq!(render_size([0, 0], 1.0), UVec2::new(1, 1));
    }

    #[test]
    fn the_viewport_is_in_whole_pixels_inside_the_window() {
        let rect = egui::Rect::from_min_max(egui::pos2(100.0, 0.0), egui::pos2(700.0, 500.0));
        assert_eq!(
            physical_rect(rect, 1.5, [1000, 600]),
            ([150, 0], [850, 600])
        );
        assert_eq!(physical_rect(egui::Rect::NOTHING, 1.0, [10, 10]).1, [0, 0]);
    }
}
