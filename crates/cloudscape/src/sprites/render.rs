//! The sprite technique (`render.technique = "sprites"`, Wang 2003): the scene's sprite clouds
//! ([`super::cloud_set`]) drawn as textured quads, back to front with premultiplied alpha, into
//! two blended targets that a resolve pass turns into the cloud-output contract; clouds beyond
//! the impostor ring are drawn into the ring's 8 impostors ([`super::impostors`]) and the ring
//! first, behind the rest.

use std::path::Path;

use bytemuck::{Pod, Zeroable};
use glam::{UVec2, Vec3, Vec4};

use super::cloud_set::{Authored, CloudSet, GpuCloud, GpuSprite, authored_clouds};
use super::field_tiles::REFRESH_CANDIDATES_PER_FRAME;
use super::impostors::{ASPECT, SECTORS, SectorView};
use super::inside::InCloudFog;
use super::textures::{SHEET_TEXELS, sheet};
use super::views::{
    Reach, SortedView, ViewSettings, ViewUniform, layer_winds_m_per_s, sector_elevations,
    sort_view, wind_offsets_m,
};
use crate::field::FieldError;
use crate::field::read_gpu::FieldReadPass;
use crate::gpu::pipeline::{
    PREMULTIPLIED_OVER, RasterDescriptor, dispatch_2d, storage_buffer, uniform_buffer,
};
use crate::gpu::{GpuContext, PassTimer};
use crate::optics::PhaseLobes;
use crate::pass::{BindGroupCache, ComputePass, RasterPass, Shared};
use crate::shader::WgslModule;

use crate::scene::{LightingModel, Scene};
use crate::technique::{Draws, FrameInputs, Technique, TechniqueStats, TechniqueTargets};

/// The timed passes of a frame, in order (the impostor pass only in frames that render one).
pub const PASS_NAMES: &[&str] = &["sprites: impostors", "sprites: draw", "sprites: resolve"];
/// Format of both blended targets and of the impostors.
const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The `Settings` uniform of `sprite_render.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct SettingsUniform {
    wind_offset_m: [Vec4; 4],
    ambient_override: Vec3,
    ambient_overridden: u32,
    directional_override: Vec3,
    directional_overridden: u32,
    phase_lobes: Vec4,
    albedo: f32,
    lit_by_volume: u32,
    blend_optical_depth_max: f32,
    pad2: f32,
    slab_params: Vec4,
}

/// The `Resolve` uniform of `sprite_resolve.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct ResolveUniform {
    origin: UVec2,
    size: UVec2,
    fog_box_min_m: Vec3,
    fog_extinction_per_m: f32,
    fog_box_max_m: Vec3,
    fog_depth_m: f32,
    fog_ambient: f32,
    fog_directional: f32,
    fog_lit_by_volume: u32,
    albedo: f32,
    phase_lobes: Vec4,
    slab_params: Vec4,
}

/// One sector of the `Ring` uniform of `sprite_impostor.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct GpuSector {
    corners_m: [Vec4; 4],
    ready: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

/// A view's uniform and sorted list on the GPU.
struct ViewBuffers {
    uniform: wgpu::Buffer,
    order: wgpu::Buffer,
    count: u32,
}

impl ViewBuffers {
    fn new(ctx: &GpuContext, label: &str) -> ViewBuffers {
        ViewBuffers {
            uniform: uniform_buffer(ctx, label, size_of::<ViewUniform>() as u64),
            order: storage_buffer(ctx, label, 4),
            count: 0,
        }
    }

    /// Uploads `view` and `sorted`, growing the list's buffer when needed; whether it grew.
    fn write(&mut self, ctx: &GpuContext, view: &ViewUniform, sorted: &SortedView) -> bool {
        ctx.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(view));
        let bytes = (sorted.order.len().max(1) * 4) as u64;
        let grew = bytes > self.order.size();
        if grew {
            self.order = storage_buffer(ctx, "sprite order", bytes.next_power_of_two());
        }
        if !sorted.order.is_empty() {
            ctx.queue
                .write_buffer(&self.order, 0, bytemuck::cast_slice(&sorted.order));
        }
        self.count = sorted.order.len() as u32;
        grew
    }
}

/// The two blended targets at the output's size.
struct RasterTargets {
    size: UVec2,
    radiance: wgpu::TextureView,
    distance: wgpu::TextureView,
}

impl RasterTargets {
    fn textures(ctx: &GpuContext, size: UVec2, layers: u32) -> (wgpu::Texture, wgpu::Texture) {
        let make = |label| {
            ctx.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: size.x,
                    height: size.y,
                    depth_or_array_layers: layers,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: TARGET_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
        };
        (make("sprite radiance"), make("sprite distance"))
    }

    fn single(ctx: &GpuContext, size: UVec2) -> RasterTargets {
        let (r, d) = RasterTargets::textures(ctx, size, 1);
        RasterTargets {
            size,
            radiance: r.create_view(&Default::default()),
            distance: d.create_view(&Default::default()),
        }
    }
}

/// The ring's impostors: 8 layers of the two targets, each sector's view, and the ring uniform.
struct Ring {
    texels: UVec2,
    layers: Vec<(wgpu::TextureView, wgpu::TextureView)>,
    radiance_array: wgpu::TextureView,
    distance_array: wgpu::TextureView,
    sectors: [Option<SectorView>; SECTORS],
    views: Vec<ViewBuffers>,
    uniform: wgpu::Buffer,
    group: BindGroupCache,
    sector_groups: Vec<Option<wgpu::BindGroup>>,
    /// Sectors to render this frame.
    pending: Vec<usize>,
}

impl Ring {
    fn new(ctx: &GpuContext, texels: u32) -> Ring {
        let size = UVec2::new(texels, (texels as f32 * ASPECT) as u32);
        let (r, d) = RasterTargets::textures(ctx, size, SECTORS as u32);
        let layer = |t: &wgpu::Texture, k: u32| {
            t.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: k,
                array_layer_count: Some(1),
                ..Default::default()
            })
        };
        let array = |t: &wgpu::Texture| {
            t.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            })
        };
        Ring {
            texels: size,
            layers: (0..SECTORS as u32)
                .map(|k| (layer(&r, k), layer(&d, k)))
                .collect(),
            radiance_array: array(&r),
            distance_array: array(&d),
            sectors: [None; SECTORS],
            views: (0..SECTORS)
                .map(|_| ViewBuffers::new(ctx, "impostor view"))
                .collect(),
            uniform: uniform_buffer(
                ctx,
                "impostor ring",
                (SECTORS * size_of::<GpuSector>()) as u64,
            ),
            group: BindGroupCache::default(),
            sector_groups: vec![None; SECTORS],
            pending: Vec::new(),
        }
    }

    /// Forgets the bind groups (a buffer they bind was replaced).
    fn forget_groups(&mut self) {
        self.group.clear();
        self.sector_groups.iter_mut().for_each(|g| *g = None);
    }

    fn uniform(&self) -> [GpuSector; SECTORS] {
        std::array::from_fn(|k| match &self.sectors[k] {
            Some(s) => GpuSector {
                corners_m: s.corners_m.map(|c| c.extend(1.0)),
                ready: 1,
                ..GpuSector::zeroed()
            },
            None => GpuSector::zeroed(),
        })
    }
}

/// What the sprite technique counted in a frame (on the CPU, so current).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpriteStats {
    /// Clouds in the set.
    pub clouds: u32,
    /// Sprites in the set.
    pub sprites: u32,
    /// Sprites drawn in 3D this frame.
    pub drawn: u32,
    /// Impostors rendered this frame.
    pub impostors_rendered: u32,
    /// Layers of sprites per output texel drawn in 3D (their projected areas over the view's).
    pub overdraw: f64,
}

/// The sprite technique.
pub struct SpriteRenderer {
    sprite_pass: RasterPass,
    impostor_pass: RasterPass,
    resolve_pass: ComputePass,
    settings: wgpu::Buffer,
    resolve: wgpu::Buffer,
    sheet: wgpu::TextureView,
    sampler: wgpu::Sampler,
    set: CloudSet,
    /// Reads the field's density at the candidate sprites of new tiles.
    field_read: FieldReadPass,
    uploaded: Option<(u64, wgpu::Buffer, wgpu::Buffer)>,
    main: ViewBuffers,
    ring: Option<Ring>,
    ring_radius_m: f32,
    targets: Option<RasterTargets>,
    main_group: BindGroupCache,
    no_depth: wgpu::TextureView,
    resolve_groups: BindGroupCache,
    stats: SpriteStats,
    /// The fog around the eye this frame (none outside clouds).
    fog: InCloudFog,
    pixels: u32,
    /// What [`Technique::configure`] took from the scene.
    configured: Option<Configured>,
    /// The hand-made and model-file clouds, with what they were read from (the scene's
    /// `sprites.model`, `sprite_clouds` and directory): read again only when that changes.
    authored: Option<(AuthoredSource, Vec<Authored>)>,
}

/// What the sprite clouds of a scene were read from.
type AuthoredSource = (
    Option<String>,
    Vec<crate::scene::SpriteCloudSpec>,
    std::path::PathBuf,
);

/// The scene's settings as the frames read them.
#[derive(Clone, Copy)]
struct Configured {
    views: ViewSettings,
    winds_m_per_s: [glam::Vec2; 4],
    /// The settings uniform but for the frame's wind offsets.
    uniform: SettingsUniform,
}

impl SpriteRenderer {
    /// Builds the passes against the shared groups' layouts and bakes the puff sheet; the clouds
    /// come with [`Technique::configure`].
    pub fn new(ctx: &GpuContext, shared: &Shared) -> SpriteRenderer {
        let blended = Some(wgpu::ColorTargetState {
            format: TARGET_FORMAT,
            blend: Some(PREMULTIPLIED_OVER),
            write_mask: wgpu::ColorWrites::ALL,
        });
        let raster = |root: &'static WgslModule, entries| {
            let descriptor = RasterDescriptor {
                label: root.name,
                entries,
                targets: &[blended.clone(), blended.clone()],
                depth: None,
                topology: wgpu::PrimitiveTopology::TriangleStrip,
            };
            RasterPass::new(ctx, shared, root, &descriptor)
        };
        SpriteRenderer {
            sprite_pass: raster(&SPRITE_RENDER_WGSL, ("vs_sprite", "fs_sprite")),
            impostor_pass: raster(&SPRITE_IMPOSTOR_WGSL, ("vs_impostor", "fs_impostor")),
            resolve_pass: ComputePass::new(
                ctx,
                shared,
                "sprite resolve",
                &SPRITE_RESOLVE_WGSL,
                &["resolve_sprites"],
            ),
            settings: uniform_buffer(ctx, "sprite settings", size_of::<SettingsUniform>() as u64),
            resolve: uniform_buffer(ctx, "sprite resolve", size_of::<ResolveUniform>() as u64),
            sheet: upload_sheet(ctx),
            sampler: ctx.device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("sprites"),
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                ..Default::default()
            }),
            set: CloudSet::default(),
            field_read: FieldReadPass::new(ctx, shared),
            uploaded: None,
            main: ViewBuffers::new(ctx, "sprite view"),
            ring: None,
            ring_radius_m: 0.0,
            targets: None,
            main_group: BindGroupCache::default(),
            no_depth: crate::gpu::pipeline::texture_2d(
                ctx,
                "no host depth",
                UVec2::ONE,
                wgpu::TextureFormat::R32Float,
                wgpu::TextureUsages::TEXTURE_BINDING,
            )
            .create_view(&Default::default()),
            resolve_groups: BindGroupCache::default(),
            stats: SpriteStats::default(),
            fog: InCloudFog::default(),
            pixels: 0,
            configured: None,
            authored: None,
        }
    }

    /// The counts of the newest frame.
    pub fn sprite_stats(&self) -> SpriteStats {
        self.stats
    }

    /// The clouds drawn in the newest frame, as a model file would hold them.
    pub fn clouds(&self) -> Vec<super::SpriteCloud> {
        self.set.sprite_clouds()
    }

    /// Uploads the set's records when they changed.
    fn upload_set(&mut self, ctx: &GpuContext) {
        if self
            .uploaded
            .as_ref()
            .is_some_and(|u| u.0 == self.set.generation)
        {
            return;
        }
        let sprites: &[GpuSprite] = if self.set.sprites.is_empty() {
            &[GpuSprite::zeroed()]
        } else {
            &self.set.sprites
        };
        let clouds: &[GpuCloud] = if self.set.clouds.is_empty() {
            &[GpuCloud::zeroed()]
        } else {
            &self.set.clouds
        };
        let buffer = |label, bytes: &[u8]| {
            let b = storage_buffer(ctx, label, bytes.len() as u64);
            ctx.queue.write_buffer(&b, 0, bytes);
            b
        };
        self.uploaded = Some((
            self.set.generation,
            buffer("sprites", bytemuck::cast_slice(sprites)),
            buffer("sprite clouds", bytemuck::cast_slice(clouds)),
        ));
        self.main_group.clear();
        if let Some(ring) = self.ring.as_mut() {
            ring.forget_groups();
        }
    }

    /// Decides which sectors to render this frame and sorts their lists.
    fn prepare_ring(
        &mut self,
        ctx: &GpuContext,
        views: &ViewSettings,
        eye: Vec3,
        time_s: f32,
        offsets: &[Vec4; 4],
    ) {
        let (radius, texels) = (views.ring_radius_m, views.impostor_texels);
        if radius <= 0.0 {
            self.ring = None;
            return;
        }
        if self
            .ring
            .as_ref()
            .is_none_or(|r| r.texels.x != texels || self.ring_radius_m != radius)
        {
            self.ring = Some(Ring::new(ctx, texels));
            self.ring_radius_m = radius;
        }
        let set = &self.set;
        let ring = self.ring.as_mut().expect("made above");
        let stale: Vec<usize> = (0..SECTORS)
            .filter(|&k| ring.sectors[k].is_none_or(|s| s.stale(eye, time_s, radius)))
            .collect();
        // All at once when none is ready (the first frame, a still); else one per frame, the
        // oldest first, so the work spreads over frames.
        ring.pending = if ring.sectors.iter().all(Option::is_none) {
            stale
        } else {
            stale
                .into_iter()
                .min_by(|&a, &b| {
                    let age = |k: usize| ring.sectors[k].map_or(f32::MIN, |s| s.time_s);
                    age(a).total_cmp(&age(b))
                })
                .into_iter()
                .collect()
        };
        for &k in &ring.pending {
            let tans = sector_elevations(set, offsets, eye, k, radius);
            let sector = SectorView::new(k, eye, time_s, radius, tans);
            let sorted = sort_view(
                set,
                offsets,
                (eye, sector.clip_from_world),
                Reach::Beyond(radius),
            );
            if ring.views[k].write(ctx, &ViewUniform::of_sector(&sector, views), &sorted) {
                ring.sector_groups[k] = None;
            }
            ring.sectors[k] = Some(sector);
        }
        ctx.queue
            .write_buffer(&ring.uniform, 0, bytemuck::cast_slice(&ring.uniform()));
    }

    /// The bind group of the sprite pass for `view` (host depth `depth`).
    fn sprite_group(
        &self,
        ctx: &GpuContext,
        view: &ViewBuffers,
        depth: &wgpu::TextureView,
    ) -> wgpu::BindGroup {
        let (_, sprites, clouds) = self.uploaded.as_ref().expect("uploaded in prepare");
        use wgpu::BindingResource::{Sampler, TextureView};
        self.sprite_pass.group.bind(
            ctx,
            &[
                ("view", view.uniform.as_entire_binding()),
                ("settings", self.settings.as_entire_binding()),
                ("sprites", sprites.as_entire_binding()),
                ("clouds", clouds.as_entire_binding()),
                ("order", view.order.as_entire_binding()),
                ("puffs", TextureView(&self.sheet)),
                ("puff_sampler", Sampler(&self.sampler)),
                ("host_depth", TextureView(depth)),
            ],
        )
    }

    /// Records the render of this frame's pending impostors.
    fn encode_impostors(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        shared: &Shared,
        timer: &mut Option<&mut PassTimer>,
    ) {
        let Some(mut ring) = self.ring.take() else {
            return;
        };
        for &k in &ring.pending {
            if ring.sector_groups[k].is_none() {
                ring.sector_groups[k] =
                    Some(self.sprite_group(ctx, &ring.views[k], &self.no_depth));
            }
        }
        for (n, &k) in ring.pending.iter().enumerate() {
            let group = ring.sector_groups[k].as_ref().expect("made above");
            let writes = if n == 0 {
                timer
                    .as_deref_mut()
                    .and_then(|t| t.render_pass_writes(PASS_NAMES[0]))
            } else {
                None
            };
            let (radiance, distance) = &ring.layers[k];
            let mut pass = begin_targets(encoder, "sprite impostor", (radiance, distance), writes);
            let sprites = &self.sprite_pass;
            draw_sprites(
                &mut pass,
                &sprites.pipeline,
                &shared.bind_groups(sprites.slots, group),
                ring.views[k].count,
            );
        }
        self.stats.impostors_rendered = ring.pending.len() as u32;
        ring.pending.clear();
        self.ring = Some(ring);
    }
}

/// Uploads the baked puff sheet.
fn upload_sheet(ctx: &GpuContext) -> wgpu::TextureView {
    let size = UVec2::splat(SHEET_TEXELS);
    let texture = crate::gpu::pipeline::texture_2d(
        ctx,
        "puff sheet",
        size,
        wgpu::TextureFormat::R8Unorm,
        wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
    );
    ctx.queue.write_texture(
        texture.as_image_copy(),
        sheet(),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(SHEET_TEXELS),
            rows_per_image: None,
        },
        wgpu::Extent3d {
            width: size.x,
            height: size.y,
            depth_or_array_layers: 1,
        },
    );
    texture.create_view(&Default::default())
}

/// A render pass into the two blended targets, cleared to nothing (no light, full transmittance).
fn begin_targets<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    (radiance, distance): (&wgpu::TextureView, &wgpu::TextureView),
    timestamps: Option<wgpu::RenderPassTimestampWrites>,
) -> wgpu::RenderPass<'e> {
    let attachment = |view| {
        Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                store: wgpu::StoreOp::Store,
            },
        })
    };
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[attachment(radiance), attachment(distance)],
        depth_stencil_attachment: None,
        timestamp_writes: timestamps,
        ..Default::default()
    })
}

/// Draws `count` sprites of the bound list (4 vertices each, a triangle strip).
fn draw_sprites(
    pass: &mut wgpu::RenderPass,
    pipeline: &wgpu::RenderPipeline,
    groups: &[Option<&wgpu::BindGroup>],
    count: u32,
) {
    pass.set_pipeline(pipeline);
    for (slot, group) in groups.iter().enumerate() {
        if let Some(group) = group {
            pass.set_bind_group(slot as u32, *group, &[]);
        }
    }
    if count > 0 {
        pass.draw(0..4, 0..count);
    }
}

/// What the sprites draw: clouds made from the field's layers, and hand-made and model-file
/// sprite clouds (not voxel grids).
pub const DRAWS: Draws = Draws {
    layers: true,
    voxel_grids: false,
    sprite_clouds: true,
};

impl Technique for SpriteRenderer {
    fn name(&self) -> &'static str {
        "sprites"
    }

    fn draws(&self) -> Draws {
        DRAWS
    }

    fn pass_names(&self) -> &'static [&'static str] {
        PASS_NAMES
    }

    fn configure(
        &mut self,
        _ctx: &GpuContext,
        scene: &Scene,
        base_dir: &Path,
    ) -> Result<(), FieldError> {
        let source: AuthoredSource = (
            scene.sprites.model.clone(),
            scene.sprite_clouds.clone(),
            base_dir.to_path_buf(),
        );
        if self
            .authored
            .as_ref()
            .is_none_or(|(read, _)| *read != source)
        {
            self.authored = Some((source, authored_clouds(scene, base_dir)?));
        }
        let authored = &self.authored.as_ref().expect("read above").1;
        self.set.configure(scene, authored);
        self.configured = Some(Configured {
            views: ViewSettings::of(&scene.sprites),
            winds_m_per_s: layer_winds_m_per_s(scene),
            uniform: SettingsUniform {
                ambient_override: Vec3::from_array(scene.sprites.ambient_color.unwrap_or_default()),
                ambient_overridden: scene.sprites.ambient_color.is_some() as u32,
                directional_override: Vec3::from_array(
                    scene.sprites.directional_color.unwrap_or_default(),
                ),
                directional_overridden: scene.sprites.directional_color.is_some() as u32,
                phase_lobes: Vec4::from_array(PhaseLobes::from_scene(&scene.phase).to_gpu()),
                albedo: scene.lighting.albedo,
                lit_by_volume: u32::from(scene.lighting.model == LightingModel::Volume),
                blend_optical_depth_max: super::shading::MAX_SPRITE_OPTICAL_DEPTH,
                slab_params: Vec4::from_array(scene.sun_slab().params_to_gpu()),
                ..SettingsUniform::zeroed()
            },
        });
        Ok(())
    }

    fn prepare(&mut self, ctx: &GpuContext, inputs: &FrameInputs) {
        let configured = self.configured.expect("configure comes before prepare");
        let frame = inputs.frame;
        let eye = frame.camera_position_m;
        let reader = self.field_read.reader(ctx, inputs.shared);
        self.set.update(
            inputs.field,
            &reader,
            (eye, frame.sun.direction),
            frame.time_s,
            inputs.real_time.then_some(REFRESH_CANDIDATES_PER_FRAME),
        );
        self.upload_set(ctx);
        let offsets = wind_offsets_m(&configured.winds_m_per_s, frame.time_s);
        let settings = SettingsUniform {
            wind_offset_m: offsets,
            ..configured.uniform
        };
        ctx.queue
            .write_buffer(&self.settings, 0, bytemuck::bytes_of(&settings));
        let views = configured.views;
        self.fog = self
            .set
            .fog_at(inputs.field, eye, frame.time_s, views.lock_distance_m);
        let view = ViewUniform::of_frame(frame, inputs.grid, &views);
        let reach = match views.ring_radius_m {
            r if r > 0.0 => Reach::Within(r),
            _ => Reach::All,
        };
        let sorted = sort_view(&self.set, &offsets, (eye, frame.clip_from_world()), reach);
        if self.main.write(ctx, &view, &sorted) {
            self.main_group.clear();
        }
        self.prepare_ring(ctx, &views, eye, frame.time_s, &offsets);
        self.stats = SpriteStats {
            clouds: self.set.clouds.len() as u32,
            sprites: self.set.sprites.len() as u32,
            drawn: sorted.order.len() as u32,
            impostors_rendered: 0,
            overdraw: sorted.overdraw,
        };
    }

    fn encode_frame_setup(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        shared: &Shared,
        _: &TechniqueTargets,
        mut timer: Option<&mut PassTimer>,
    ) {
        self.encode_impostors(ctx, encoder, shared, &mut timer);
    }

    fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        shared: &Shared,
        targets: &TechniqueTargets,
        (origin, size): (UVec2, UVec2),
        timer: Option<(&mut PassTimer, &str)>,
    ) {
        let mut timer = timer.map(|(t, _)| t);
        let output = targets.output;
        if self.targets.as_ref().is_none_or(|t| t.size != output.size) {
            self.targets = Some(RasterTargets::single(ctx, output.size));
            self.resolve_groups.clear();
        }
        let mut main_group = std::mem::take(&mut self.main_group);
        let group = main_group
            .get(&[targets.host_depth], || {
                self.sprite_group(ctx, &self.main, targets.host_depth)
            })
            .clone();
        self.main_group = main_group;
        let raster = self.targets.as_ref().expect("made above");
        {
            let writes = timer
                .as_deref_mut()
                .and_then(|t| t.render_pass_writes(PASS_NAMES[1]));
            let mut pass = begin_targets(
                encoder,
                "sprites",
                (&raster.radiance, &raster.distance),
                writes,
            );
            pass.set_scissor_rect(origin.x, origin.y, size.x, size.y);
            let (impostors, sprites) = (&self.impostor_pass, &self.sprite_pass);
            if let Some(ring) = self.ring.as_mut() {
                let ring_group = ring.group.get(&[targets.host_depth], || {
                    use wgpu::BindingResource::{Sampler, TextureView};
                    impostors.group.bind(
                        ctx,
                        &[
                            ("view", self.main.uniform.as_entire_binding()),
                            ("ring", ring.uniform.as_entire_binding()),
                            ("impostor_radiance", TextureView(&ring.radiance_array)),
                            ("impostor_distance", TextureView(&ring.distance_array)),
                            ("impostor_sampler", Sampler(&self.sampler)),
                            ("host_depth", TextureView(targets.host_depth)),
                        ],
                    )
                });
                draw_sprites(
                    &mut pass,
                    &impostors.pipeline,
                    &shared.bind_groups(impostors.slots, ring_group),
                    SECTORS as u32,
                );
            }
            draw_sprites(
                &mut pass,
                &sprites.pipeline,
                &shared.bind_groups(sprites.slots, &group),
                self.main.count,
            );
        }
        let settings = self
            .configured
            .expect("configure comes before encode")
            .uniform;
        let fog = self.fog;
        let uniform = ResolveUniform {
            origin,
            size,
            fog_box_min_m: fog.box_m.0,
            fog_extinction_per_m: fog.extinction_per_m,
            fog_box_max_m: fog.box_m.1,
            fog_depth_m: fog.depth_m,
            fog_ambient: fog.ambient,
            fog_directional: fog.directional,
            fog_lit_by_volume: u32::from(fog.from_field) * settings.lit_by_volume,
            albedo: settings.albedo,
            phase_lobes: settings.phase_lobes,
            slab_params: settings.slab_params,
        };
        ctx.queue
            .write_buffer(&self.resolve, 0, bytemuck::bytes_of(&uniform));
        let resolve = &self.resolve_pass;
        let resolve_group = self
            .resolve_groups
            .get(&[&output.radiance, &output.distance], || {
                use wgpu::BindingResource::TextureView;
                resolve.group.bind(
                    ctx,
                    &[
                        ("resolve", self.resolve.as_entire_binding()),
                        ("accumulated", TextureView(&raster.radiance)),
                        ("accumulated_distance", TextureView(&raster.distance)),
                        ("cloud_out", TextureView(&output.radiance)),
                        ("cloud_distance_out", TextureView(&output.distance)),
                    ],
                )
            });
        let writes = timer.and_then(|t| t.compute_pass_writes(PASS_NAMES[2]));
        dispatch_2d(
            encoder,
            "sprite resolve",
            resolve.main(),
            &shared.bind_groups(resolve.slots, resolve_group),
            size,
            writes,
        );
        self.pixels = output.size.x * output.size.y;
    }

    fn finish_frame(&mut self, _encoder: &mut wgpu::CommandEncoder) {}

    fn reads_light_volume(&self) -> bool {
        self.configured
            .is_some_and(|c| c.uniform.lit_by_volume == 1)
    }

    fn stats(&mut self, _ctx: &GpuContext) -> Option<TechniqueStats> {
        Some(TechniqueStats {
            pixels: self.pixels,
            density_samples_per_pixel: self.stats.overdraw,
            primitives: Some(self.stats.drawn + self.ring.as_ref().map_or(0, |_| SECTORS as u32)),
        })
    }
}

/// The sprites' render pass (`sprite_render.wgsl`).
pub static SPRITE_RENDER_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "sprite_render",
    "sprite_render.wgsl",
    [
        &crate::shader::MATH_WGSL,
        &crate::frame::FRAME_WGSL,
        &crate::environment::ENVIRONMENT_WGSL,
        &crate::optics::phase::PHASE_WGSL,
        &crate::optics::slab::SLAB_WGSL,
        &crate::raymarch::light::MARCH_LIGHT_WGSL,
        &super::views::SPRITE_WGSL
    ]
);

/// The pass that renders impostors (`sprite_impostor.wgsl`).
pub static SPRITE_IMPOSTOR_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "sprite_impostor",
    "sprite_impostor.wgsl",
    [&crate::frame::FRAME_WGSL, &super::views::SPRITE_WGSL]
);

/// The pass that resolves the sprites into the cloud output (`sprite_resolve.wgsl`).
pub static SPRITE_RESOLVE_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "sprite_resolve",
    "sprite_resolve.wgsl",
    [
        &crate::shader::MATH_WGSL,
        &crate::environment::ENVIRONMENT_WGSL,
        &crate::optics::phase::PHASE_WGSL,
        &crate::optics::slab::SLAB_WGSL,
        &super::views::SPRITE_WGSL
    ]
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::layout_check::assert_wgsl_layout;

    #[test]
    fn uniforms_match_their_wgsl_layout() {
        assert_wgsl_layout!(
            &crate::sprites::render::SPRITE_RENDER_WGSL,
            "Settings",
            SettingsUniform {
                wind_offset_m,
                ambient_override,
                ambient_overridden,
                directional_override,
                directional_overridden,
                phase_lobes,
                albedo,
                lit_by_volume,
                blend_optical_depth_max,
                pad2,
                slab_params,
            }
        );
        assert_wgsl_layout!(
            &crate::sprites::render::SPRITE_RESOLVE_WGSL,
            "Resolve",
            ResolveUniform {
                origin,
                size,
                fog_box_min_m,
                fog_extinction_per_m,
                fog_box_max_m,
                fog_depth_m,
                fog_ambient,
                fog_directional,
                fog_lit_by_volume,
                albedo,
                phase_lobes,
                slab_params,
            }
        );
        assert_wgsl_layout!(
            &crate::sprites::render::SPRITE_IMPOSTOR_WGSL,
            "Sector",
            GpuSector {
                corners_m,
                ready,
                pad0,
                pad1,
                pad2,
            }
        );
    }
}
