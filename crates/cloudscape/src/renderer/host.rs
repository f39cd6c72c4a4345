//! [`CloudRenderer`]: one frame, any technique, on the host's device, depth buffer and scene colour.
//!
//! The scene is read when the renderer is built ([`CloudRenderer::new`]) and when it is edited
//! ([`CloudRenderer::apply_edit`]): its field, its technique and their settings. Per frame the
//! host passes only a [`Frame`] (camera, depth convention, sun, clock, exposure):
//! [`CloudRenderer::begin_frame`] uploads the frame, the environment and the field's time;
//! [`CloudRenderer::encode_clouds`] records the technique into the cloud output;
//! [`CloudRenderer::encode_finish`] records temporal reuse (when asked for), composition over the
//! host's colour (or the sky, sun and ground) and tone mapping. Nothing waits on the GPU;
//! statistics come back a frame late ([`CloudRenderer::stats`]).

use super::dispatch;
use crate::environment::light_volume::{DiffuseOptics, LightVolumeGrid, LightVolumeSettings};
use crate::environment::{
    CloudShadowUniform, Environment, EnvironmentGpu, EnvironmentPasses, EnvironmentTable,
    EnvironmentUniform, LightVolumeUniform, ShadowMapBinding, Sky, TableSizes,
};
pub use crate::field::gpu::FieldUpdate;

use crate::field::gpu::FieldGpu;
use crate::field::{CloudField, FieldError};
use crate::frame::{Frame, FrameGpu, FrameSettings};
use crate::gpu::pipeline::{STORAGE_OUTPUT, texture_2d};
use crate::gpu::{GpuContext, PassTimer};
use crate::output::{CloudOutput, SampleGrid};
use crate::pass::Shared;
use crate::post::upsample::Upsampler;
use crate::post::{Background, Compositor, DISPLAY_FORMAT, Display, HDR_FORMAT};
use crate::scene::Scene;
use crate::shadow::{BuiltShadow, LightingReuse, ShadowParams};
use crate::technique::{FrameInputs, Technique, TechniqueStats, TechniqueTargets};
use crate::temporal::{TemporalResolve, TemporalSettings};
use glam::{UVec2, Vec2};
use std::path::{Path, PathBuf};

/// Whether a frame reuses earlier frames, and how many rays it marches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reuse {
    /// Every pixel rendered afresh (at the technique's own resolution, e.g. the particles' half).
    None,
    /// Every pixel rendered afresh from one ray per `n` x `n` pixels, depth-aware upsampled to the
    /// frame's size (`post::upsample`, Yusov 2014): a render scale of `1 / n` (at most the
    /// technique's own).
    Scaled(u32),
    /// A coarse grid per frame plus reprojected history.
    Temporal(TemporalSettings),
}

/// The images of the last frame, on the GPU: the host samples or presents them.
pub struct FrameImages<'a> {
    /// Full-resolution cloud output (after temporal reuse, when on).
    pub clouds: &'a CloudOutput,
    /// Composed linear radiance, [`HDR_FORMAT`].
    pub hdr: &'a wgpu::Texture,
    /// Exposed, tone-mapped, sRGB-encoded, [`DISPLAY_FORMAT`].
    pub ldr: &'a wgpu::Texture,
}

/// The targets of one frame size.
struct Targets {
    size: UVec2,
    grid: SampleGrid,
    output: CloudOutput,
    /// The upsampled output of a coarse grid without temporal reuse.
    full: Option<CloudOutput>,
    hdr: wgpu::Texture,
    hdr_view: wgpu::TextureView,
    ldr: wgpu::Texture,
    ldr_view: wgpu::TextureView,
}

impl Targets {
    fn new(ctx: &GpuContext, size: UVec2, grid: SampleGrid) -> Targets {
        let hdr = texture_2d(ctx, "hdr", size, HDR_FORMAT, STORAGE_OUTPUT);
        let ldr = texture_2d(ctx, "ldr", size, DISPLAY_FORMAT, STORAGE_OUTPUT);
        Targets {
            size,
            grid,
            output: CloudOutput::new(ctx, "cloud output", grid.size(size)),
            full: (grid.divisor > 1).then(|| CloudOutput::new(ctx, "upsampled clouds", size)),
            hdr_view: hdr.create_view(&Default::default()),
            ldr_view: ldr.create_view(&Default::default()),
            hdr,
            ldr,
        }
    }
}

/// Whether going from scene `previous` to `next` needs [`CloudRenderer::update_scene`]: a change of
/// the cloud field (layers, weather, noise, volumes, planet) or of the technique. Everything else
/// is the technique's settings ([`crate::technique::Technique::configure`]) or the frame's.
pub fn needs_update(previous: &Scene, next: &Scene) -> bool {
    fn rebuilt(s: &Scene) -> impl PartialEq + '_ {
        (
            (&s.layers, &s.weather, &s.noise, &s.volumes, &s.planet),
            s.render.technique,
        )
    }
    rebuilt(previous) != rebuilt(next)
}

/// `scene` without what a [`Frame`] carries (camera, sun, time, exposure, image size, animation):
/// what a renderer is configured from.
fn settings_of(scene: &Scene) -> Scene {
    let defaults = Scene::default();
    let mut settings = scene.clone();
    settings.camera = defaults.camera;
    settings.sun = defaults.sun;
    settings.animation = defaults.animation;
    let render = &mut settings.render;
    (render.time_s, render.exposure_ev) = (defaults.render.time_s, defaults.render.exposure_ev);
    (render.width, render.height) = (defaults.render.width, defaults.render.height);
    settings
}

/// Clouds for a host renderer: the field, the shared frame state, the scene's technique and the
/// shared passes, made once.
pub struct CloudRenderer {
    /// The scene drawn, without its frame inputs ([`settings_of`]); files resolve against `base_dir`.
    settings: Scene,
    base_dir: PathBuf,
    sky: Sky,
    frame_settings: FrameSettings,
    field: CloudField,
    field_gpu: FieldGpu,
    frame_gpu: FrameGpu,
    environment_gpu: EnvironmentGpu,
    environment_passes: EnvironmentPasses,
    /// The environment of the last frame begun, and whether its passes still need recording.
    environment: (Environment, bool),
    /// Whether the technique's once-a-frame passes still need recording this frame.
    technique_setup_pending: bool,
    /// CPU time the technique took to take the last frame begun ([`Technique::prepare`]).
    prepare_time: std::time::Duration,
    technique: Box<dyn Technique>,
    temporal: Option<TemporalResolve>,
    upsampler: Upsampler,
    compositor: Compositor,
    display: Display,
    targets: Option<Targets>,
    frame: Option<Frame>,
    reuse: Reuse,
    /// Whether the shadow map may be kept across frames, what the current one was built for, and
    /// whether this frame builds it.
    lighting_reuse: Option<LightingReuse>,
    shadow_built: Option<BuiltShadow>,
    shadow_rebuild: bool,
    /// The light volume of the frame begun, when the technique reads one, and whether it may start
    /// from the last frame's solution (with temporal or lighting reuse: a frame without either is
    /// a still, the same whatever was drawn before), and whether this frame solves it (a shifted
    /// frame reads the one solved before).
    light_volume: Option<(LightVolumeGrid, LightVolumeSettings, bool)>,
    light_volume_solve: bool,
}

impl CloudRenderer {
    /// Builds the field of `scene` (files resolve against `base_dir`), the technique it names and
    /// every pass, configured from the scene's settings.
    pub fn new(
        ctx: &GpuContext,
        scene: &Scene,
        base_dir: &Path,
    ) -> Result<CloudRenderer, FieldError> {
        let field = CloudField::new(scene, base_dir)?;
        let field_gpu = FieldGpu::new(ctx, &field);
        let frame_gpu = FrameGpu::new(ctx, "frame");
        let environment_gpu = EnvironmentGpu::new(ctx, TableSizes::from_scene(scene));
        let shared = Shared {
            field: &field_gpu,
            frame: &frame_gpu,
            environment: &environment_gpu,
        };
        let mut technique = dispatch::build(ctx, &shared, scene.render.technique);
        technique.configure(ctx, scene, base_dir)?;
        let environment_passes = EnvironmentPasses::new(ctx, &shared);
        let compositor = Compositor::new(ctx, &shared);
        let upsampler = Upsampler::new(ctx, &shared);
        Ok(CloudRenderer {
            settings: settings_of(scene),
            base_dir: base_dir.to_path_buf(),
            sky: Sky::from_scene(scene),
            frame_settings: FrameSettings::from_scene(scene),
            field,
            field_gpu,
            frame_gpu,
            environment_gpu,
            environment_passes,
            environment: (Environment::from_scene(scene), false),
            technique_setup_pending: false,
            prepare_time: std::time::Duration::ZERO,
            technique,
            temporal: None,
            upsampler,
            compositor,
            display: Display::new(ctx),
            targets: None,
            frame: None,
            reuse: Reuse::None,
            lighting_reuse: None,
            shadow_built: None,
            shadow_rebuild: true,
            light_volume: None,
            light_volume_solve: true,
        })
    }

    /// Takes a new `scene` (files resolve against `base_dir`) and rebuilds what it changed: a new
    /// cloud field (coverage, wind, types, weather, grids) is uploaded without regenerating the
    /// noise unless its seed changed, and a new technique is built only when `render.technique`
    /// changed; any other change of settings only reconfigures the technique. Returns what the
    /// field update did, or None when the field stayed. The scene's camera, sun, time and exposure
    /// are the frame's ([`Frame::from_scene`]), not read here.
    pub fn apply_edit(
        &mut self,
        ctx: &GpuContext,
        scene: &Scene,
        base_dir: &Path,
    ) -> Result<Option<FieldUpdate>, FieldError> {
        let settings = settings_of(scene);
        if settings == self.settings && base_dir == self.base_dir {
            return Ok(None);
        }
        if needs_update(&self.settings, scene) || base_dir != self.base_dir {
            return self.update_scene(ctx, scene, base_dir).map(Some);
        }
        self.configure(ctx, scene, base_dir)?;
        Ok(None)
    }

    /// Takes `scene` as a new cloud field (and technique, when it names another): what
    /// [`CloudRenderer::apply_edit`] does when the field changed, done unconditionally.
    pub fn update_scene(
        &mut self,
        ctx: &GpuContext,
        scene: &Scene,
        base_dir: &Path,
    ) -> Result<FieldUpdate, FieldError> {
        self.field = CloudField::new(scene, base_dir)?;
        let update = self.field_gpu.update(ctx, &self.field);
        if self.technique.name() != scene.render.technique.name() {
            self.technique = dispatch::build(ctx, &self.shared(), scene.render.technique);
        }
        self.configure(ctx, scene, base_dir)?;
        self.shadow_built = None;
        self.reset_history();
        Ok(update)
    }

    /// Reads the settings of `scene` into the technique and the shared passes.
    fn configure(
        &mut self,
        ctx: &GpuContext,
        scene: &Scene,
        base_dir: &Path,
    ) -> Result<(), FieldError> {
        self.technique.configure(ctx, scene, base_dir)?;
        self.settings = settings_of(scene);
        self.base_dir = base_dir.to_path_buf();
        self.sky = Sky::from_scene(scene);
        self.frame_settings = FrameSettings::from_scene(scene);
        Ok(())
    }

    /// The CPU field drawn (the specification the GPU follows).
    pub fn field(&self) -> &CloudField {
        &self.field
    }

    /// The environment's bind group and its layout, for a host's own shaders built with
    /// [`crate::shader::Program::host`] over [`crate::environment::ENVIRONMENT_WGSL`] (the sky, the
    /// sun, the clouds' shadow on its geometry): bind it at [`crate::shader::ENVIRONMENT_GROUP`].
    pub fn environment_group(&self) -> (&wgpu::BindGroupLayout, &wgpu::BindGroup) {
        (
            self.environment_gpu.layout(),
            self.environment_gpu.bind_group(),
        )
    }

    /// The clouds' shadow map of the frame last begun, for a host's shaders that bind it in a
    /// group of their own (a game engine's materials): valid in the encoder once
    /// [`CloudRenderer::encode_environment`] (or [`CloudRenderer::encode_clouds`]) has recorded
    /// the frame's passes. None before the first frame.
    pub fn shadow_map(&self) -> Option<ShadowMapBinding<'_>> {
        let built = self.shadow_built.as_ref()?;
        Some(ShadowMapBinding {
            texture: self.environment_gpu.texture(EnvironmentTable::CloudShadow),
            params: CloudShadowUniform::new(&built.params),
            sun_direction: self.environment.0.sun.direction,
        })
    }

    /// The shared groups, for passes a host adds (probes, its own effects).
    pub fn shared(&self) -> Shared<'_> {
        Shared {
            field: &self.field_gpu,
            frame: &self.frame_gpu,
            environment: &self.environment_gpu,
        }
    }

    /// Texels of the technique's output this frame (the frame's size over the grid's divisor).
    pub fn output_size(&self) -> UVec2 {
        self.targets
            .as_ref()
            .expect("begin_frame makes the targets")
            .output
            .size
    }

    /// The sun, sky and haze of the frame last begun (before any, of the scene's own sun).
    pub fn environment(&self) -> &Environment {
        &self.environment.0
    }

    /// The technique in use.
    pub fn technique_name(&self) -> &'static str {
        self.technique.name()
    }

    /// The labels of a frame's passes as a [`PassTimer`] records them, in order: the
    /// environment's ([`EnvironmentPasses::pass_names`]: the shadow map and the sky's tables), the
    /// technique's ([`Technique::pass_names`]), "temporal resolve" (with temporal reuse),
    /// "compose", "display".
    pub fn pass_names(&self) -> Vec<&'static str> {
        let shared = [
            "temporal resolve",
            crate::post::upsample::UPSAMPLE_PASS,
            "compose",
            "display",
        ];
        EnvironmentPasses::pass_names(&self.environment.0, self.technique.reads_light_volume())
            .into_iter()
            .chain(self.technique.pass_names().iter().copied())
            .chain(shared)
            .collect()
    }

    /// Starts a frame: uploads `frame`, the environment its sun makes, the field's time and the
    /// technique's view, and picks this frame's sample grid. `frame.frame_index` must advance
    /// every frame when `reuse` is temporal.
    pub fn begin_frame(&mut self, ctx: &GpuContext, frame: &Frame, reuse: Reuse) {
        let grid = self.begin_view(ctx, frame, reuse);
        self.begin_environment(ctx, frame, reuse);
        self.prepare_technique(ctx, frame, grid);
    }

    /// Starts a frame that shows the last frame begun through another point of each pixel:
    /// `frame` differs from it only in its sub-pixel shift ([`Frame::shifted_by`]) and frame
    /// index, and has no temporal reuse. The lighting (shadow map, light volume) is the last
    /// frame's, not made again, and only the table laid over the view (the aerial perspective,
    /// and the sky's beside it) is redone: the samples of a pixel's footprint see one lighting,
    /// which an offline still of several samples per pixel then pays for once. (An aerial
    /// perspective kept from another shift puts its light shafts a fraction of a pixel off:
    /// sprites at 4 samples per pixel, FLIP 0.0039 against the tables made for every sample.)
    ///
    /// # Panics
    /// Without a frame begun before, or when `frame` moves the eye, the sun or the clock.
    pub fn begin_shifted_frame(&mut self, ctx: &GpuContext, frame: &Frame) {
        let last = self.frame.as_ref().expect("a frame was begun before");
        assert!(
            last.camera_position_m == frame.camera_position_m
                && last.sun == frame.sun
                && last.time_s == frame.time_s,
            "a shifted frame keeps the eye, the sun and the time of the frame before"
        );
        let grid = self.begin_view(ctx, frame, Reuse::None);
        let (_, pending) = &mut self.environment;
        if !*pending {
            *pending = true;
            self.shadow_rebuild = false;
            self.light_volume_solve = false;
        }
        self.prepare_technique(ctx, frame, grid);
    }

    /// Uploads `frame` and the field's time, and picks and makes the frame's sample grid (its
    /// targets, and the temporal resolve that `reuse` asks for).
    fn begin_view(&mut self, ctx: &GpuContext, frame: &Frame, reuse: Reuse) -> SampleGrid {
        if let Reuse::Temporal(settings) = reuse {
            if self
                .temporal
                .as_ref()
                .is_none_or(|t| *t.settings() != settings)
            {
                self.temporal = Some(TemporalResolve::new(ctx, &self.shared(), settings));
            }
        }
        let grid = match (reuse, &self.temporal) {
            (Reuse::Temporal(_), Some(t)) => t.grid(frame.frame_index),
            _ => {
                let scaled = match reuse {
                    Reuse::Scaled(n) => n.max(1),
                    _ => 1,
                };
                let divisor = self.technique.still_divisor().max(scaled);
                SampleGrid {
                    divisor,
                    subpixel: UVec2::splat((divisor - 1) / 2),
                }
            }
        };
        let (size, divisor) = (frame.size, grid.divisor);
        if self
            .targets
            .as_ref()
            .is_none_or(|t| t.size != size || t.grid.divisor != divisor)
        {
            self.targets = Some(Targets::new(ctx, size, grid));
        }
        self.targets.as_mut().expect("targets were just made").grid = grid;
        self.field_gpu.set_time(ctx, &self.field, frame.time_s);
        self.frame_gpu
            .write(ctx, &frame.uniform(&grid, &self.frame_settings));
        self.frame = Some(frame.clone());
        self.reuse = reuse;
        grid
    }

    /// Makes the environment of `frame`: its sun's light and sky, which shadow map it reads and
    /// which light volume (both carried over from the frame before where `reuse` or the lighting
    /// reuse allows), uploaded, and its passes pending.
    fn begin_environment(&mut self, ctx: &GpuContext, frame: &Frame, reuse: Reuse) {
        let env = Environment::new(&self.sky, &frame.sun);
        let shadow = self.frame_shadow(&env, frame);
        self.environment_gpu
            .resize(ctx, TableSizes::from_scene(&self.settings));
        let warm = matches!(reuse, Reuse::Temporal(_)) || self.lighting_reuse.is_some();
        let kept = self
            .light_volume
            .take()
            .filter(|_| warm)
            .map(|(grid, ..)| grid);
        self.light_volume = self.technique.reads_light_volume().then(|| {
            let settings = LightVolumeSettings::from_scene(&self.settings);
            let fresh = LightVolumeGrid::new(&settings, &self.field, frame.camera_position_m);
            let grid = kept.filter(|k| k.still_serves(&fresh)).unwrap_or(fresh);
            (grid, settings, warm)
        });
        let uniform = EnvironmentUniform::new(&env, frame.camera_position_m, &shadow)
            .with_light_volume(self.light_volume_uniform());
        self.environment_gpu.write(ctx, &uniform);
        self.environment = (env, true);
        self.light_volume_solve = true;
    }

    /// Lets the technique take `frame` on sample grid `grid` (its CPU work, timed), its
    /// once-a-frame passes pending.
    fn prepare_technique(&mut self, ctx: &GpuContext, frame: &Frame, grid: SampleGrid) {
        let env = self.environment.0;
        let inputs = FrameInputs {
            field: &self.field,
            frame,
            environment: &env,
            grid: &grid,
            shared: Shared {
                field: &self.field_gpu,
                frame: &self.frame_gpu,
                environment: &self.environment_gpu,
            },
            real_time: self.lighting_reuse.is_some(),
        };
        let start = std::time::Instant::now();
        self.technique.prepare(ctx, &inputs);
        self.prepare_time = start.elapsed();
        self.technique_setup_pending = true;
    }

    /// The CPU time the technique took to take the last frame begun: what it builds or sorts on
    /// the CPU (the sprites' clouds and their order), and what it waits for the GPU to read back.
    pub fn prepare_time(&self) -> std::time::Duration {
        self.prepare_time
    }

    /// The shadow map this frame reads: the one built before, when [`LightingReuse`] allows it,
    /// else a new one (and the frame's environment passes build it).
    fn frame_shadow(&mut self, env: &Environment, frame: &Frame) -> ShadowParams {
        let sun = env.sun.direction;
        let settings = &self.settings;
        let fresh = BuiltShadow {
            params: ShadowParams::new(settings, &self.field, frame.camera_position_m, sun),
            sun,
            texels: settings.shadow.resolution,
            time_s: frame.time_s,
        };
        let wind = self.wind_m_per_s();
        let kept = match (self.lighting_reuse, &self.shadow_built) {
            (Some(reuse), Some(built)) if built.serves(&fresh, wind, reuse) => Some(*built),
            _ => None,
        };
        self.shadow_rebuild = kept.is_none();
        let used = kept.unwrap_or(fresh);
        self.shadow_built = Some(used);
        used.params
    }

    /// The frame's light volume as the environment's uniform holds it.
    fn light_volume_uniform(&self) -> LightVolumeUniform {
        let s = &self.settings;
        let optics = DiffuseOptics::of(&s.sun_slab());
        let volume = self.light_volume.as_ref();
        LightVolumeUniform::new(
            volume.map(|(grid, settings, _)| (grid, optics, settings.beam_steps)),
        )
    }

    /// The wind of the first layer, which carries the clouds (zero without layers).
    fn wind_m_per_s(&self) -> Vec2 {
        self.field
            .layers
            .first()
            .map_or(Vec2::ZERO, |l| l.wind_m_per_s)
    }

    /// Lets the lighting (the clouds' shadow map, the light volume's solve) be carried across
    /// frames (see [`LightingReuse`]), or, with None, made afresh every frame (the default, as
    /// offline renders need; temporal reuse warm-starts the light volume either way).
    pub fn set_lighting_reuse(&mut self, reuse: Option<LightingReuse>) {
        self.lighting_reuse = reuse;
    }

    /// Records the technique over output texels `region` (origin, size; None for all of them),
    /// after the frame's environment passes (shadow map, sky tables) on the frame's first call.
    pub fn encode_clouds(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        host_depth: &wgpu::TextureView,
        region: Option<(UVec2, UVec2)>,
        mut timer: Option<&mut PassTimer>,
    ) {
        self.encode_environment(ctx, encoder, timer.as_deref_mut());
        let shared = Shared {
            field: &self.field_gpu,
            frame: &self.frame_gpu,
            environment: &self.environment_gpu,
        };
        let t = self
            .targets
            .as_ref()
            .expect("begin_frame makes the targets");
        let region = region.unwrap_or((UVec2::ZERO, t.output.size));
        let targets = TechniqueTargets {
            host_depth,
            output: &t.output,
        };
        if std::mem::take(&mut self.technique_setup_pending) {
            let timed = timer.as_deref_mut();
            self.technique
                .encode_frame_setup(ctx, encoder, &shared, &targets, timed);
        }
        let timer = timer.map(|t| (t, self.technique.name()));
        self.technique
            .encode(ctx, encoder, &shared, &targets, region, timer);
    }

    /// Records the frame's environment passes (the clouds' shadow map and the sky's tables) once
    /// per [`CloudRenderer::begin_frame`]; [`CloudRenderer::encode_clouds`] calls it first, and a
    /// host that reads the environment without drawing clouds calls it itself.
    pub fn encode_environment(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        timer: Option<&mut PassTimer>,
    ) {
        let (env, pending) = &mut self.environment;
        if !*pending {
            return;
        }
        let shared = Shared {
            field: &self.field_gpu,
            frame: &self.frame_gpu,
            environment: &self.environment_gpu,
        };
        let groups = (&shared, &self.environment_gpu);
        let volume = (self.light_volume.as_ref())
            .filter(|_| self.light_volume_solve)
            .map(|(g, s, warm)| (g, s, *warm));
        self.environment_passes.encode(
            ctx,
            encoder,
            groups,
            (env, self.shadow_rebuild, volume),
            timer,
        );
        *pending = false;
    }

    /// Records the rest of the frame: temporal reuse, composition over `background` with aerial
    /// perspective, and tone mapping with the frame's exposure and the scene's operator.
    pub fn encode_finish(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        background: &Background,
        mut timer: Option<&mut PassTimer>,
    ) {
        self.technique.finish_frame(encoder);
        let shared = Shared {
            field: &self.field_gpu,
            frame: &self.frame_gpu,
            environment: &self.environment_gpu,
        };
        let frame = self.frame.as_ref().expect("begin_frame stores the frame");
        let t = self
            .targets
            .as_ref()
            .expect("begin_frame makes the targets");
        let wind = self.wind_m_per_s();
        let clouds = match (self.reuse, self.temporal.as_mut()) {
            (Reuse::Temporal(_), Some(temporal)) => {
                let inputs = (&t.output, background.depth);
                let timer = timer.as_deref_mut();
                temporal.encode(ctx, encoder, &shared, (frame, wind), inputs, timer)
            }
            _ => match &t.full {
                Some(full) => {
                    let inputs = (&t.output, full, background.depth);
                    let timed = timer.as_deref_mut();
                    self.upsampler.encode(ctx, encoder, &shared, inputs, timed);
                    full
                }
                None => &t.output,
            },
        };
        let timed = timer.as_deref_mut();
        self.compositor.encode(
            ctx,
            encoder,
            &shared,
            (clouds, background),
            &t.hdr_view,
            timed,
        );
        let display = (frame.exposure_ev, self.settings.render.tonemap);
        let views = (&t.hdr_view, &t.ldr_view, t.size);
        self.display.encode(ctx, encoder, views, display, timer);
    }

    /// The images of the last frame encoded, valid once its work is submitted.
    pub fn images(&self) -> FrameImages<'_> {
        let t = self
            .targets
            .as_ref()
            .expect("begin_frame makes the targets");
        let clouds = match (self.reuse, &self.temporal) {
            (Reuse::Temporal(_), Some(temporal)) => temporal.latest().unwrap_or(&t.output),
            _ => t.full.as_ref().unwrap_or(&t.output),
        };
        FrameImages {
            clouds,
            hdr: &t.hdr,
            ldr: &t.ldr,
        }
    }

    /// What the technique counted in the newest frame the GPU has finished (never waits).
    pub fn stats(&mut self, ctx: &GpuContext) -> Option<TechniqueStats> {
        self.technique.stats(ctx)
    }

    /// Forgets the temporal history (a camera cut; new weather).
    pub fn reset_history(&mut self) {
        if let Some(t) = self.temporal.as_mut() {
            t.reset();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_field_and_the_technique_need_an_update() {
        let base = Scene::default();
        let changed = |edit: fn(&mut Scene)| {
            let mut next = base.clone();
            edit(&mut next);
            needs_update(&base, &next)
        };
        assert!(changed(|s| s.layers[0].coverage = 0.7));
        assert!(changed(|s| s.noise.seed = 9));
        assert!(changed(|s| s.planet.radius_m = 1.0e6));
        assert!(changed(
            |s| s.render.technique = crate::scene::Technique::Sprites
        ));
        assert!(!changed(|s| s.sprites.cloud_size_m = 900.0));
        assert!(!changed(|s| s.sun.elevation_deg = 5.0));
        assert!(!changed(|s| s.lighting.ambient_scale = 2.0));
        assert!(!changed(|s| s.render.quality = crate::scene::Quality::Low));
        assert!(!changed(|s| s.render.exposure_ev = 1.0));
        assert!(!changed(|s| s.camera.position_m[1] = 900.0));
        assert!(!changed(|s| s.particles.radius_m = 300.0));
    }
}
