//! The seed's tiled light occlusion on the GPU (`particle_occlusion.wgsl`): the twin of
//! [`super::occlusion`]. After generation, three passes: bin the particles into the light tiles,
//! sort each tile's list from the sun, and walk the lists to set each particle's optical depth
//! toward the sun.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use super::generate::{Generation, OCCLUSION_MAX_DEPTH};
use super::generate_gpu::{MAX_PARTICLES, ParticleGenerator};
use super::occlusion::LightTiles;
use super::tables_gpu::ParticleTables;
use crate::gpu::GpuContext;
use crate::gpu::pipeline::{storage_buffer, uniform_buffer};
use crate::pass::ComputePass;

/// The `LightGrid` uniform of `particle_occlusion.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct LightGridUniform {
    origin_m: Vec3,
    tile_m: f32,
    right: Vec3,
    depth_range_m: f32,
    up: Vec3,
    sigma_max_per_m: f32,
    sun: Vec3,
    tiles_per_side: u32,
    levels: u32,
    tile_capacity: u32,
    max_particles: u32,
    early_exit: u32,
}

impl LightGridUniform {
    fn new(tiles: &LightTiles, g: &Generation) -> LightGridUniform {
        LightGridUniform {
            origin_m: tiles.origin_m,
            tile_m: tiles.tile_m,
            right: tiles.right,
            depth_range_m: tiles.depth_range_m,
            up: tiles.up,
            sigma_max_per_m: g.sigma_max_per_m,
            sun: tiles.sun,
            tiles_per_side: tiles.tiles_per_side,
            levels: tiles.levels,
            tile_capacity: tiles.tile_capacity(),
            max_particles: MAX_PARTICLES,
            early_exit: u32::from(g.occlusion_early_exit),
        }
    }
}

/// What the light tiles counted in a frame (`light_stats`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LightTileCounts {
    /// Particles beyond a full tile's capacity, left out of its list.
    pub dropped: u32,
    /// Particles whose centre lies outside their level's tiles (unoccluded by the walk).
    pub outside: u32,
}

/// The light-tile passes and their lists, sized for one light grid.
pub struct LightOcclusion {
    pass: ComputePass,
    uniform: wgpu::Buffer,
    tile_counts: wgpu::Buffer,
    tile_entries: wgpu::Buffer,
    /// How many tiles list a particle, then their indices.
    listed_tiles: wgpu::Buffer,
    stats: wgpu::Buffer,
    /// The grid's shape the lists were sized for: (tiles per side, levels, capacity).
    shape: (u32, u32, u32),
    group: Option<wgpu::BindGroup>,
}

/// Workgroups of the sort, each taking every this-many-th tile that lists a particle: enough
/// invocations (256 each) to fill a large GPU, few enough that starting them costs little where
/// that is slow (llvmpipe's OpenGL).
const LIGHT_SORT_WORKGROUPS: u32 = 1024;

/// Bytes of the light-tile counters.
const STATS_BYTES: u64 = 8;

impl LightOcclusion {
    /// The passes and lists for `tiles`.
    pub fn new(ctx: &GpuContext, tiles: &LightTiles) -> LightOcclusion {
        let count = u64::from(tiles.tile_count());
        LightOcclusion {
            pass: ComputePass::standalone(
                ctx,
                "particle light occlusion",
                &PARTICLE_OCCLUSION_WGSL,
                &["bin_light_tiles", "sort_light_tiles", "walk_light_tiles"],
            ),
            uniform: uniform_buffer(ctx, "light grid", size_of::<LightGridUniform>() as u64),
            tile_counts: storage_buffer(ctx, "light tile counts", count * 4),
            tile_entries: storage_buffer(
                ctx,
                "light tile entries",
                count * u64::from(tiles.tile_capacity()) * 4,
            ),
            listed_tiles: storage_buffer(ctx, "listed light tiles", (count + 1) * 4),
            stats: storage_buffer(ctx, "light tile stats", STATS_BYTES),
            shape: Self::shape_of(tiles),
            group: None,
        }
    }

    fn shape_of(tiles: &LightTiles) -> (u32, u32, u32) {
        (tiles.tiles_per_side, tiles.levels, tiles.tile_capacity())
    }

    /// Whether the lists were sized for `tiles`.
    pub fn fits(&self, tiles: &LightTiles) -> bool {
        self.shape == Self::shape_of(tiles)
    }

    /// Records the three passes for generation `g`'s particles in `generator`; `timestamps` time
    /// them as one pass.
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        (g, generator, tables): (&Generation, &ParticleGenerator, &ParticleTables),
        timestamps: Option<wgpu::ComputePassTimestampWrites>,
    ) {
        let tiles = LightTiles::new(g);
        let uniform = LightGridUniform::new(&tiles, g);
        ctx.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        let group = self
            .group
            .get_or_insert_with(|| {
                self.pass.group.bind(
                    ctx,
                    &[
                        ("light_grid", self.uniform.as_entire_binding()),
                        ("particles", generator.particles.as_entire_binding()),
                        ("counts", generator.counts.as_entire_binding()),
                        (
                            "chord_mean_density",
                            tables.optical_depth.chord_buffer.as_entire_binding(),
                        ),
                        ("tile_counts", self.tile_counts.as_entire_binding()),
                        ("tile_entries", self.tile_entries.as_entire_binding()),
                        ("light_stats", self.stats.as_entire_binding()),
                        ("listed_tiles", self.listed_tiles.as_entire_binding()),
                    ],
                )
            })
            .clone();
        encoder.clear_buffer(&self.tile_counts, 0, None);
        encoder.clear_buffer(&self.stats, 0, None);
        encoder.clear_buffer(&self.listed_tiles, 0, Some(4));
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("particle light occlusion"),
            timestamp_writes: timestamps,
        });
        pass.set_bind_group(3, &group, &[]);
        pass.set_pipeline(self.pass.pipeline("bin_light_tiles"));
        pass.dispatch_workgroups_indirect(&generator.dispatches, 12);
        pass.set_pipeline(self.pass.pipeline("sort_light_tiles"));
        pass.dispatch_workgroups(LIGHT_SORT_WORKGROUPS, 1, 1);
        pass.set_pipeline(self.pass.pipeline("walk_light_tiles"));
        pass.dispatch_workgroups_indirect(&generator.dispatches, 12);
    }

    /// The counts of the last frame (waits for the GPU): for tests and tools.
    pub fn read(&self, ctx: &GpuContext) -> LightTileCounts {
        let words: Vec<u32> = crate::gpu::readback::read_buffer(ctx, &self.stats);
        LightTileCounts {
            dropped: words[0],
            outside: words[1],
        }
    }
}

/// The light-occlusion passes (`particle_occlusion.wgsl`).
pub static PARTICLE_OCCLUSION_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "particle_occlusion",
    "particle_occlusion.wgsl",
    [
        &crate::shader::MATH_WGSL,
        &super::gpu::PARTICLE_WGSL,
        &super::gpu::PARTICLE_LOOKUP_WGSL,
        &super::gpu::PARTICLE_TILES_WGSL
    ],
    occlusion_constants
);

/// The walk's and the sort's constants as WGSL (the CPU specification's, `generate.rs`).
fn occlusion_constants() -> String {
    use crate::shader::WgslConst;
    crate::shader::wgsl_consts([
        ("OCCLUSION_MAX_DEPTH", WgslConst::F32(OCCLUSION_MAX_DEPTH)),
        (
            "LIGHT_SORT_WORKGROUPS",
            WgslConst::U32(LIGHT_SORT_WORKGROUPS),
        ),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::layout_check::assert_wgsl_layout;

    #[test]
    fn the_light_grid_uniform_matches_its_wgsl_layout() {
        assert_wgsl_layout!(
            &PARTICLE_OCCLUSION_WGSL,
            "LightGrid",
            LightGridUniform {
                origin_m,
                tile_m,
                right,
                depth_range_m,
                up,
                sigma_max_per_m,
                sun,
                tiles_per_side,
                levels,
                tile_capacity,
                max_particles,
                early_exit
            }
        );
    }
}
