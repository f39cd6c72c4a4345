//! The viewer's panels: the view settings and actions, what the frame costs (with a graph of the
//! last seconds of frame times), and every knob of the scene.

use std::path::PathBuf;

use cloudscape::raymarch::MarchSettings;
use cloudscape::scene::Scene;
use cloudscape::scene::knobs::DocumentedFields;
use cloudscape::technique::TechniqueStats;
use cloudscape::temporal::{self, TemporalSettings};

use super::camera::{CameraRig, MAX_SPEED_M_PER_S, MIN_SPEED_M_PER_S, Mode};
use super::knob_ui;
use super::stats::{FrameStats, HISTORY};

/// Render scales offered: the fraction of the viewport's pixels rendered.
pub const RENDER_SCALES: [(f32, &str); 3] = [(1.0, "1"), (0.5, "1/2"), (0.25, "1/4")];

/// How the view is drawn: not part of the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewSettings {
    /// Fraction of the viewport's pixels rendered: 1, 0.5 or 0.25.
    pub render_scale: f32,
    /// Temporal reuse; None renders every pixel every frame.
    pub temporal: Option<TemporalSettings>,
    /// Wait for the display's refresh.
    pub vsync: bool,
    /// Show the panels (Tab).
    pub panels: bool,
    /// Stop the scene's clock (Space): the wind stops moving the clouds.
    pub paused: bool,
}

/// What the frame measured, for the panel.
pub struct Measured<'a> {
    /// Frame times and GPU wall time.
    pub frames: &'a FrameStats,
    /// GPU time per pass from timestamp queries, a frame late; None without them.
    pub passes: Option<&'a [(String, f64)]>,
    /// Whether the adapter has timestamp queries at all.
    pub has_timestamps: bool,
    /// The technique's counters, a frame late.
    pub technique: Option<TechniqueStats>,
    /// Size of the rendered image, pixels.
    pub render_size: [u32; 2],
    /// The adapter, in words.
    pub adapter: &'a str,
}

/// What the user asked for with the panel's buttons.
#[derive(Debug, PartialEq)]
pub enum Request {
    /// Write the live scene to this file.
    Save(PathBuf),
    /// Write the rendered image as this PNG and an EXR beside it.
    Screenshot(PathBuf),
    /// Put the camera back where the scene file has it.
    ResetCamera,
    /// Start (true) or stop orbiting.
    Orbit(bool),
}

/// The panels' state between frames: the file names typed in.
pub struct Panel {
    /// Where "Save scene" writes.
    pub save_path: String,
    /// Where "Screenshot" writes (the PNG; the EXR goes beside it).
    pub screenshot_path: String,
    /// The last thing done (a file written), shown under the buttons.
    pub status: String,
}

/// Everything the panels show and change in one frame.
pub struct PanelInputs<'a> {
    /// The live scene (edited in place; the key changed is returned).
    pub scene: &'a mut Scene,
    /// The view settings (changed in place).
    pub view: &'a mut ViewSettings,
    /// The camera (its speed is changed in place).
    pub rig: &'a mut CameraRig,
    /// The measurements to show.
    pub measured: Measured<'a>,
    /// The newest error (a broken scene file, a refused edit).
    pub error: Option<&'a str>,
}

/// What one frame of the panels did.
#[derive(Default)]
pub struct PanelOutput {
    /// The dotted key of the scene knob changed (the scene holds the change).
    pub edited: Option<String>,
    /// Buttons pressed.
    pub requests: Vec<Request>,
}

impl Panel {
    /// Panels that save to `save_path` and take screenshots to `cloudscape-view.png`.
    pub fn new(save_path: PathBuf) -> Panel {
        Panel {
            save_path: save_path.display().to_string(),
            screenshot_path: "cloudscape-view.png".to_string(),
            status: String::new(),
        }
    }

    /// Draws the panels into `ui` (the whole window) and returns what they did; the rest of the
    /// window is the viewport.
    pub fn show(&mut self, ui: &mut egui::Ui, inputs: PanelInputs) -> PanelOutput {
        let mut output = PanelOutput::default();
        egui::Panel::right("stats")
            .resizable(false)
            .exact_size(270.0)
            .show(ui, |ui| {
                self.actions(ui, &inputs.rig.mode, &mut output);
                if let Some(error) = inputs.error {
                    ui.separator();
                    ui.colored_label(egui::Color32::from_rgb(255, 110, 90), error);
                }
                ui.separator();
                costs(ui, &inputs.measured, inputs.view);
            });
        egui::Panel::left("knobs")
            .resizable(true)
            .default_size(340.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    view_settings(ui, inputs.view, inputs.rig);
                    ui.separator();
                    output.edited = knob_ui::scene_sections(ui, inputs.scene, &preset_steps);
                });
            });
        output
    }

    /// The buttons, and the file names they write to.
    fn actions(&mut self, ui: &mut egui::Ui, mode: &Mode, output: &mut PanelOutput) {
        ui.heading("cloudscape view");
        if file_button(ui, "Save scene", &mut self.save_path) {
            output
                .requests
                .push(Request::Save(self.save_path.clone().into()));
        }
        if file_button(ui, "Screenshot (P)", &mut self.screenshot_path) {
            let path = self.screenshot_path.clone().into();
            output.requests.push(Request::Screenshot(path));
        }
        ui.horizontal(|ui| {
            if ui
                .button("Reset camera")
                .on_hover_text("R: the scene's camera")
                .clicked()
            {
                output.requests.push(Request::ResetCamera);
            }
            let orbiting = matches!(mode, Mode::Orbit { .. });
            let label = if orbiting { "Fly" } else { "Orbit" };
            if ui
                .button(label)
                .on_hover_text("O: orbit the point ahead, or fly")
                .clicked()
            {
                output.requests.push(Request::Orbit(!orbiting));
            }
        });
        if !self.status.is_empty() {
            ui.weak(&self.status);
        }
    }
}

/// A button beside the name of the file it writes; true when pressed.
fn file_button(ui: &mut egui::Ui, label: &str, path: &mut String) -> bool {
    ui.horizontal(|ui| {
        let pressed = ui.button(label).clicked();
        ui.text_edit_singleline(path);
        pressed
    })
    .inner
}

/// The step count a quality preset gives an unset step knob.
fn preset_steps(key: &str, scene: &Scene) -> Option<u32> {
    let (primary, light, samples) = MarchSettings::preset(scene.render.quality);
    match key {
        "render.primary_steps" => Some(primary),
        "render.light_steps" => Some(light),
        "render.samples_per_pixel" => Some(samples),
        _ => None,
    }
}

/// Render scale, temporal reuse, vsync, the clock and the camera's speed.
fn view_settings(ui: &mut egui::Ui, view: &mut ViewSettings, rig: &mut CameraRig) {
    egui::Grid::new("view").num_columns(2).show(ui, |ui| {
        ui.label("render scale")
            .on_hover_text("the fraction of the viewport's pixels rendered");
        ui.horizontal(|ui| {
            for (scale, name) in RENDER_SCALES {
                ui.selectable_value(&mut view.render_scale, scale, name);
            }
        });
        ui.end_row();
        temporal_grid(ui, view);
        ui.label("vsync");
        ui.checkbox(&mut view.vsync, "");
        ui.end_row();
        ui.label("clock")
            .on_hover_text("Space: stop and start the wind");
        ui.checkbox(&mut view.paused, "paused");
        ui.end_row();
        ui.label("speed")
            .on_hover_text("the mouse wheel: walking to 1 km/s; shift: x10");
        let range = MIN_SPEED_M_PER_S..=MAX_SPEED_M_PER_S;
        let slider = egui::Slider::new(&mut rig.speed_m_per_s, range)
            .logarithmic(true)
            .suffix(" m/s");
        ui.add(slider);
        ui.end_row();
    });
    if let Some(settings) = view.temporal.as_mut() {
        egui::CollapsingHeader::new("temporal reuse").show(ui, |ui| {
            egui::Grid::new("temporal").num_columns(2).show(ui, |ui| {
                for knob in temporal::KNOBS {
                    ui.label(knob.key).on_hover_text(knob.description());
                    if let cloudscape::scene::knobs::FieldMut::Float(value) = knob.get_mut(settings)
                    {
                        let (min, max) = knob.allowed.bounds();
                        let range = min.unwrap_or(0.0)..=max.unwrap_or(f32::MAX);
                        ui.add(egui::Slider::new(value, range).logarithmic(true));
                    }
                    ui.end_row();
                }
            });
        });
    }
}

/// The temporal grid: off, or one ray per 1x1, 2x2 or 4x4 pixels per frame.
fn temporal_grid(ui: &mut egui::Ui, view: &mut ViewSettings) {
    let hover = TemporalSettings::get_field_docs("divisor").unwrap_or_default();
    ui.label("temporal grid").on_hover_text(hover);
    let current = view.temporal.map(|t| t.divisor);
    ui.horizontal(|ui| {
        for (divisor, name) in [
            (None, "off"),
            (Some(1), "1"),
            (Some(2), "2"),
            (Some(4), "4"),
        ] {
            if ui.selectable_label(current == divisor, name).clicked() {
                view.temporal = divisor.map(|divisor| TemporalSettings {
                    divisor,
                    ..view.temporal.unwrap_or_default()
                });
            }
        }
    });
    ui.end_row();
}

/// What the frame costs: frame times, GPU time per pass, the technique's counters and a graph.
fn costs(ui: &mut egui::Ui, measured: &Measured, view: &ViewSettings) {
    ui.label(measured.adapter);
    let [w, h] = measured.render_size;
    let scale = RENDER_SCALES
        .iter()
        .find(|(s, _)| *s == view.render_scale)
        .map_or("?", |(_, name)| name);
    let grid = view.temporal.map_or("off".to_string(), |t| {
        format!("1/{}", t.divisor * t.divisor)
    });
    ui.label(format!(
        "render {w}x{h} (scale {scale}), rays per pixel per frame {grid}"
    ));
    if let Some(ms) = measured.frames.mean_ms() {
        ui.label(format!("CPU frame {ms:.1} ms, {:.1} fps", 1e3 / ms));
    }
    if let Some(ms) = measured.frames.gpu_wall_ms {
        ui.label(format!("GPU wall {ms:.1} ms per frame"));
    }
    frame_graph(ui, measured.frames);
    if let Some(stats) = &measured.technique {
        ui.label(format!(
            "{:.1} density samples per pixel",
            stats.density_samples_per_pixel
        ));
        if let Some(count) = stats.primitives {
            ui.label(format!("{count} particles or sprites drawn"));
        }
    }
    ui.separator();
    pass_times(ui, measured);
}

/// GPU time per pass, or why there is none.
fn pass_times(ui: &mut egui::Ui, measured: &Measured) {
    if !measured.has_timestamps {
        ui.label("This adapter has no timestamp queries: no GPU time per pass; the wall times above are all there is.");
        return;
    }
    ui.label("GPU time per pass (timestamps, a frame late)");
    let Some(passes) = measured.passes else {
        return;
    };
    egui::Grid::new("passes")
        .num_columns(2)
        .striped(true)
        .show(ui, |ui| {
            for (name, ms) in passes {
                ui.label(name);
                ui.label(format!("{ms:.2} ms"));
                ui.end_row();
            }
            ui.label("total");
            ui.label(format!(
                "{:.2} ms",
                passes.iter().map(|(_, ms)| ms).sum::<f64>()
            ));
            ui.end_row();
        });
    if measured.adapter.contains("Cpu") {
        ui.weak(
            "A software adapter's timestamps time its CPU work: compare passes with each other.",
        );
    }
}

/// Frame times of the last seconds as a line, with 60 and 30 fps marked.
fn frame_graph(ui: &mut egui::Ui, frames: &FrameStats) {
    let (rect, _) =
        ui.allocate_exact_size(egui::vec2(ui.available_width(), 70.0), egui::Sense::hover());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 2.0, egui::Color32::from_gray(20));
    let Some(newest) = frames.frames().back().map(|f| f.at) else {
        return;
    };
    let top_ms = frames
        .frames()
        .iter()
        .map(|f| f.cpu_ms)
        .fold(40.0_f64, f64::max);
    let y = |ms: f64| rect.bottom() - (ms / top_ms) as f32 * rect.height();
    let x = |age_s: f32| rect.right() - age_s / HISTORY.as_secs_f32() * rect.width();
    for (ms, label) in [(1e3 / 60.0, "60 fps"), (1e3 / 30.0, "30 fps")] {
        let stroke = egui::Stroke::new(1.0, egui::Color32::from_gray(70));
        painter.hline(rect.x_range(), y(ms), stroke);
        let at = egui::pos2(rect.left() + 2.0, y(ms));
        painter.text(
            at,
            egui::Align2::LEFT_BOTTOM,
            label,
            egui::FontId::monospace(9.0),
            egui::Color32::GRAY,
        );
    }
    let points: Vec<egui::Pos2> = frames
        .frames()
        .iter()
        .map(|f| egui::pos2(x((newest - f.at).as_secs_f32()), y(f.cpu_ms)))
        .collect();
    painter.add(egui::Shape::line(
        points,
        egui::Stroke::new(1.5, egui::Color32::LIGHT_GREEN),
    ));
    let label = format!(
        "frame time, last {} s (max {top_ms:.0} ms)",
        HISTORY.as_secs()
    );
    painter.text(
        rect.left_top() + egui::vec2(2.0, 2.0),
        egui::Align2::LEFT_TOP,
        label,
        egui::FontId::proportional(10.0),
        egui::Color32::GRAY,
    );
}
