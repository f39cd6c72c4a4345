//! The particle technique (`render.technique = "particles"`, Yusov 2014): particles generated on
//! the GPU from the cloud field in a camera-centred ring grid ([`super::generate_gpu`]), binned
//! into screen tiles, sorted per tile and blended per pixel with volume-aware blending, each shaded
//! from the precomputed tables ([`super::tables_gpu`]). It writes the cloud-output contract at the
//! sample grid's resolution like every technique, so temporal reuse, upsampling and compositing
//! serve it unchanged.

use bytemuck::{Pod, Zeroable};
use glam::{UVec2, Vec4};
use std::path::Path;

use super::ParticleTableSpec;
use super::blend::Blending;
use super::generate::{Generation, Particle};
use super::generate_gpu::{GenerationCounts, MAX_PARTICLES, ParticleGenerator, set_groups};
use super::occlusion::LightTiles;
use super::occlusion_gpu::LightOcclusion;
use super::store::TableStore;
use super::tables_gpu::ParticleTables;
use crate::field::FieldError;
use crate::gpu::late_readback::LateReadback;
use crate::gpu::pipeline::{storage_buffer, uniform_buffer};
use crate::gpu::{GpuContext, PassTimer};
use crate::optics::PhaseLobes;
use crate::pass::{BindGroupCache, ComputePass, Shared};
use crate::scene::{LightingModel, ParticleOcclusion, PlanetShape, Scene};
use crate::technique::{Draws, FrameInputs, Technique, TechniqueStats, TechniqueTargets};

/// Output texels along each side of a screen tile (`TILE` in `particle_render.wgsl`).
pub const TILE_TEXELS: u32 = 16;
/// Particles a tile sorts and blends (`MAX_TILE_ENTRIES` in `particle_tiles.wgsl`): the sort
/// runs in 8 KiB of workgroup memory. A tile that lists more keeps its nearest.
pub const TILE_SORTED: u32 = 2048;
/// Most particles a tile's list holds (fewer where the lists would pass [`TILE_LIST_BYTES`]).
pub const TILE_CAPACITY: u32 = 16384;
/// Bytes of all tile lists at most.
pub const TILE_LIST_BYTES: u64 = 96 << 20;

/// The timed pass that makes the particles from the field.
const GENERATE_PASS: &str = "particles: generate";
/// The timed pass of the seed's tiled light occlusion.
const OCCLUSION_PASS: &str = "particles: occlusion";
/// The timed pass that bins the particles into screen tiles.
const BIN_PASS: &str = "particles: bin";
/// The timed pass that sorts and blends each screen tile.
const RENDER_PASS: &str = "particles: render";
/// The timed passes of a frame, in order.
pub const PASS_NAMES: &[&str] = &[GENERATE_PASS, OCCLUSION_PASS, BIN_PASS, RENDER_PASS];

/// The `Render` uniform of `particle_render.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct RenderUniform {
    grid_size: UVec2,
    tiles: UVec2,
    tile_capacity: u32,
    blending: u32,
    max_particles: u32,
    flat_planet: u32,
    planet_radius_m: f32,
    sigma_max_per_m: f32,
    reference_optical_radius: f32,
    albedo: f32,
    phase_lobes: Vec4,
    table_dims: [u32; 4],
    ambient_scale: f32,
    band_first_tile_row: u32,
    band_rows: UVec2,
    diffuse_from_volume: u32,
    reserved0: u32,
    reserved1: [u32; 2],
    slab_params: Vec4,
}

/// What the particle technique counted in a frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ParticleStats {
    /// Generation's counts.
    pub generation: GenerationCounts,
    /// Particle segments blended, over all texels.
    pub segments: u32,
    /// Texels written.
    pub texels: u32,
    /// Tile entries dropped because a tile's list was full.
    pub dropped_tile_entries: u32,
    /// Particles binned into at least one tile (in view).
    pub binned: u32,
}

/// The tile lists, sized for one output.
struct TileLists {
    tiles: UVec2,
    capacity: u32,
    counts: wgpu::Buffer,
    entries: wgpu::Buffer,
}

impl TileLists {
    fn new(ctx: &GpuContext, size: UVec2) -> TileLists {
        let tiles = tile_grid(size);
        let n = u64::from(tiles.x * tiles.y);
        let capacity =
            (TILE_LIST_BYTES / (4 * n)).clamp(u64::from(TILE_SORTED), u64::from(TILE_CAPACITY));
        TileLists {
            tiles,
            capacity: capacity as u32,
            counts: storage_buffer(ctx, "particle tile counts", n * 4),
            entries: storage_buffer(ctx, "particle tile entries", n * capacity * 4),
        }
    }
}

/// Tiles across and down an output of `size` texels.
fn tile_grid(size: UVec2) -> UVec2 {
    (size + TILE_TEXELS - 1) / TILE_TEXELS
}

/// Bytes of the render counters.
const STATS_BYTES: u64 = 16;

/// The particle technique.
pub struct ParticleRenderer {
    pass: ComputePass,
    uniform: wgpu::Buffer,
    settings: RenderUniform,
    stats: wgpu::Buffer,
    readback: LateReadback,
    generation_readback: LateReadback,
    store: TableStore,
    tables: Option<ParticleTables>,
    /// The generation the scene asks for, from [`Technique::configure`]; each frame's camera, sun
    /// and time make the frame's `generation`.
    configured: Option<Generation>,
    generation: Option<Generation>,
    still_divisor: u32,
    generator: Option<ParticleGenerator>,
    occlusion: Option<LightOcclusion>,
    lists: Option<TileLists>,
    group: BindGroupCache,
    supplied: Option<Vec<Particle>>,
}

impl ParticleRenderer {
    /// Builds the passes against the shared groups' layouts; the tables are loaded by
    /// [`Technique::configure`], the particle buffers made by the first [`Technique::encode`].
    pub fn new(ctx: &GpuContext, shared: &Shared) -> ParticleRenderer {
        ParticleRenderer {
            pass: ComputePass::new(
                ctx,
                shared,
                "particle render",
                &PARTICLE_RENDER_WGSL,
                &["bin_particles", "render_tiles"],
            ),
            uniform: uniform_buffer(ctx, "particle render", size_of::<RenderUniform>() as u64),
            settings: RenderUniform::zeroed(),
            stats: storage_buffer(ctx, "particle render stats", STATS_BYTES),
            readback: LateReadback::new(ctx, "particle render stats", STATS_BYTES),
            generation_readback: LateReadback::new(ctx, "particle generation counts", 16),
            store: TableStore::user_cache(),
            tables: None,
            configured: None,
            generation: None,
            still_divisor: 1,
            generator: None,
            occlusion: None,
            lists: None,
            group: BindGroupCache::default(),
            supplied: None,
        }
    }

    /// Renders `particles` instead of generating them from the field (None: generate again): a
    /// host's own particle set, and how tests place particles.
    pub fn set_particles(&mut self, particles: Option<Vec<Particle>>) {
        self.supplied = particles;
    }

    /// The particle buffers (for tests and tools: read them with [`ParticleGenerator::read`]).
    pub fn generator(&self) -> Option<&ParticleGenerator> {
        self.generator.as_ref()
    }

    /// The light tiles of the seed's occlusion (for tests and tools: [`LightOcclusion::read`]),
    /// once a frame used them.
    pub fn light_occlusion(&self) -> Option<&LightOcclusion> {
        self.occlusion.as_ref()
    }

    /// The counts of the newest frame the GPU has finished (never waits).
    pub fn particle_stats(&mut self, ctx: &GpuContext) -> Option<ParticleStats> {
        let generation = GenerationCounts::from_words(bytemuck::cast_slice(
            self.generation_readback.latest(ctx)?,
        ));
        let words: &[u32] = bytemuck::cast_slice(self.readback.latest(ctx)?);
        Some(ParticleStats {
            generation,
            segments: words[0],
            texels: words[1],
            dropped_tile_entries: words[2],
            binned: words[3],
        })
    }

    fn load_tables(&mut self, ctx: &GpuContext, scene: &Scene) -> &ParticleTables {
        let spec = ParticleTableSpec::from_scene(scene);
        if self.tables.as_ref().is_none_or(|t| t.spec != spec) {
            self.tables = Some(ParticleTables::new(ctx, &spec, &self.store, &mut |_, _| {}));
            self.group.clear();
            self.occlusion = None;
        }
        self.tables.as_ref().expect("loaded above")
    }

    fn uniform(scene: &Scene, tables: &ParticleTables) -> RenderUniform {
        let spec = &tables.spec;
        let od = spec.optical_depth;
        RenderUniform {
            blending: Blending::from_scene(scene.particles.blending).gpu_index(),
            max_particles: MAX_PARTICLES,
            flat_planet: u32::from(scene.planet.shape == PlanetShape::Flat),
            planet_radius_m: scene.planet.radius_m,
            sigma_max_per_m: spec.extinction_per_m,
            reference_optical_radius: spec.extinction_per_m * spec.radius_m,
            albedo: scene.lighting.albedo,
            phase_lobes: Vec4::from_array(PhaseLobes::from_scene(&scene.phase).to_gpu()),
            table_dims: [
                od.start_zenith,
                od.start_azimuth,
                od.dir_zenith,
                od.dir_azimuth,
            ],
            ambient_scale: scene.lighting.ambient_scale,
            diffuse_from_volume: u32::from(scene.lighting.model == LightingModel::Volume),
            slab_params: Vec4::from_array(scene.sun_slab().params_to_gpu()),
            ..RenderUniform::zeroed()
        }
    }

    /// The technique's bind group for `targets` (made once per set of views).
    fn bind_group(&mut self, ctx: &GpuContext, targets: &TechniqueTargets) -> wgpu::BindGroup {
        let output = targets.output;
        let (tables, generator, lists) = (
            self.tables.as_ref().expect("configure loads the tables"),
            self.generator.as_ref().expect("made by the frame's setup"),
            self.lists.as_ref().expect("made by the frame's setup"),
        );
        let (pass, uniform, stats) = (&self.pass, &self.uniform, &self.stats);
        let views = [targets.host_depth, &output.radiance, &output.distance];
        self.group
            .get(&views, || {
                let od = &tables.optical_depth;
                let od_view = od.texture.create_view(&Default::default());
                let sc_view = tables.scattering.texture.create_view(&Default::default());
                use wgpu::BindingResource::{Sampler, TextureView};
                pass.group.bind(
                    ctx,
                    &[
                        ("render", uniform.as_entire_binding()),
                        ("particles", generator.particles.as_entire_binding()),
                        ("counts", generator.counts.as_entire_binding()),
                        ("optical_depth_lut", TextureView(&od_view)),
                        ("optical_depth_sampler", Sampler(&od.sampler)),
                        ("chord_mean_density", od.chord_buffer.as_entire_binding()),
                        ("scattering_lut", TextureView(&sc_view)),
                        ("scattering_sampler", Sampler(&tables.scattering.sampler)),
                        ("tile_counts", lists.counts.as_entire_binding()),
                        ("tile_entries", lists.entries.as_entire_binding()),
                        ("host_depth", TextureView(targets.host_depth)),
                        ("cloud_out", TextureView(&output.radiance)),
                        ("cloud_distance_out", TextureView(&output.distance)),
                        ("render_stats", stats.as_entire_binding()),
                    ],
                )
            })
            .clone()
    }

    /// Makes the tile lists fit `size` output texels.
    fn ensure_lists(&mut self, ctx: &GpuContext, size: UVec2) {
        let tiles = tile_grid(size);
        if self.lists.as_ref().is_none_or(|l| l.tiles != tiles) {
            self.lists = Some(TileLists::new(ctx, size));
            self.group.clear();
        }
    }

    /// The seed's tiled occlusion of generation `g`'s particles, when the scene asks for it.
    fn encode_occlusion(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        g: &Generation,
        timer: Option<&mut PassTimer>,
    ) {
        if g.occlusion != ParticleOcclusion::Tiles {
            return;
        }
        let tiles = LightTiles::new(g);
        if self.occlusion.as_ref().is_none_or(|o| !o.fits(&tiles)) {
            self.occlusion = Some(LightOcclusion::new(ctx, &tiles));
        }
        let occlusion = self.occlusion.as_mut().expect("made above");
        let generator = self.generator.as_ref().expect("made before encoding");
        let tables = self.tables.as_ref().expect("configure loads the tables");
        let writes = timer.and_then(|t| t.compute_pass_writes(OCCLUSION_PASS));
        occlusion.encode(ctx, encoder, (g, generator, tables), writes);
    }

    /// Generates, occludes and bins this frame's particles.
    fn encode_particles(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        shared: &Shared,
        group: &wgpu::BindGroup,
        mut timer: Option<&mut PassTimer>,
    ) {
        if self.supplied.is_none() {
            let generator = self.generator.as_ref().expect("made before encoding");
            let writes = timer
                .as_deref_mut()
                .and_then(|t| t.compute_pass_writes(GENERATE_PASS));
            generator.encode(encoder, shared, writes);
            let g = self.generation.expect("prepare comes before encoding");
            self.encode_occlusion(ctx, encoder, &g, timer.as_deref_mut());
        }
        let generator = self.generator.as_ref().expect("made before encoding");
        let lists = self.lists.as_ref().expect("made before encoding");
        encoder.clear_buffer(&lists.counts, 0, None);
        let writes = timer.and_then(|t| t.compute_pass_writes(BIN_PASS));
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(BIN_PASS),
            timestamp_writes: writes,
        });
        set_groups(&mut pass, &shared.bind_groups(self.pass.slots, group));
        pass.set_pipeline(self.pass.pipeline("bin_particles"));
        pass.dispatch_workgroups_indirect(&generator.dispatches, 12);
    }
}

/// What the particles draw: the field's layers (not voxel grids, not sprite clouds).
pub const DRAWS: Draws = Draws {
    layers: true,
    voxel_grids: false,
    sprite_clouds: false,
};

impl Technique for ParticleRenderer {
    fn name(&self) -> &'static str {
        "particles"
    }

    fn draws(&self) -> Draws {
        DRAWS
    }

    fn pass_names(&self) -> &'static [&'static str] {
        PASS_NAMES
    }

    fn still_divisor(&self) -> u32 {
        self.still_divisor
    }

    fn reads_light_volume(&self) -> bool {
        self.settings.diffuse_from_volume == 1
    }

    fn configure(&mut self, ctx: &GpuContext, scene: &Scene, _: &Path) -> Result<(), FieldError> {
        let tables = self.load_tables(ctx, scene);
        let settings = Self::uniform(scene, tables);
        let generation = Generation::from_scene(scene, tables.mean_density);
        self.settings = settings;
        self.configured = Some(generation);
        self.still_divisor = scene.particles.resolution_divisor;
        Ok(())
    }

    fn prepare(&mut self, _ctx: &GpuContext, inputs: &FrameInputs) {
        let configured = self.configured.expect("configure comes before prepare");
        self.generation = Some(configured.for_frame(inputs.frame));
    }

    fn encode_frame_setup(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        shared: &Shared,
        targets: &TechniqueTargets,
        timer: Option<&mut PassTimer>,
    ) {
        let generation = self.generation.expect("prepare comes before encoding");
        if self.generator.as_ref().is_none_or(|g| !g.fits(&generation)) {
            self.generator = Some(ParticleGenerator::new(ctx, shared, &generation));
            self.group.clear();
            self.occlusion = None;
        }
        let generator = self.generator.as_ref().expect("made above");
        generator.set(ctx, &generation);
        if let Some(particles) = &self.supplied {
            generator.upload(ctx, particles);
        }
        self.ensure_lists(ctx, targets.output.size);
        let group = self.bind_group(ctx, targets);
        encoder.clear_buffer(&self.stats, 0, None);
        self.encode_particles(ctx, encoder, shared, &group, timer);
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
        let output = targets.output;
        let lists = self.lists.as_ref().expect("made by the frame's setup");
        let first_row = origin.y / TILE_TEXELS;
        let rows = (origin.y + size.y).div_ceil(TILE_TEXELS) - first_row;
        self.settings.grid_size = output.size;
        self.settings.tiles = lists.tiles;
        self.settings.tile_capacity = lists.capacity;
        self.settings.band_first_tile_row = first_row;
        self.settings.band_rows = UVec2::new(origin.y, origin.y + size.y);
        ctx.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&self.settings));
        let tiles_x = lists.tiles.x;
        let group = self.bind_group(ctx, targets);
        let writes = timer.and_then(|(t, _)| t.compute_pass_writes(RENDER_PASS));
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(RENDER_PASS),
            timestamp_writes: writes,
        });
        set_groups(&mut pass, &shared.bind_groups(self.pass.slots, &group));
        pass.set_pipeline(self.pass.pipeline("render_tiles"));
        pass.dispatch_workgroups(tiles_x, rows, 1);
    }

    fn finish_frame(&mut self, encoder: &mut wgpu::CommandEncoder) {
        self.readback.copy(encoder, &self.stats);
        if let Some(g) = &self.generator {
            self.generation_readback.copy(encoder, &g.counts);
        }
    }

    fn stats(&mut self, ctx: &GpuContext) -> Option<TechniqueStats> {
        let s = self.particle_stats(ctx)?;
        Some(TechniqueStats {
            pixels: s.texels,
            density_samples_per_pixel: f64::from(s.segments) / f64::from(s.texels.max(1)),
            primitives: Some(s.generation.particles),
        })
    }
}

/// The particles' render pass (`particle_render.wgsl`).
pub static PARTICLE_RENDER_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "particle_render",
    "particle_render.wgsl",
    [
        &crate::shader::MATH_WGSL,
        &crate::frame::FRAME_WGSL,
        &crate::environment::ENVIRONMENT_WGSL,
        &crate::optics::phase::PHASE_WGSL,
        &crate::optics::slab::SLAB_WGSL,
        &super::gpu::PARTICLE_WGSL,
        &super::gpu::PARTICLE_LOOKUP_WGSL,
        &super::gpu::PARTICLE_TILES_WGSL,
        &super::blend::PARTICLE_BLEND_WGSL
    ]
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::layout_check::assert_wgsl_layout;

    #[test]
    fn the_render_uniform_matches_its_wgsl_layout() {
        assert_wgsl_layout!(
            &crate::particles::render::PARTICLE_RENDER_WGSL,
            "Render",
            RenderUniform {
                grid_size,
                tiles,
                tile_capacity,
                blending,
                max_particles,
                flat_planet,
                planet_radius_m,
                sigma_max_per_m,
                reference_optical_radius,
                albedo,
                phase_lobes,
                table_dims,
                ambient_scale,
                band_first_tile_row,
                band_rows,
                diffuse_from_volume,
                reserved0,
                reserved1,
                slab_params,
            }
        );
    }
}
