//! Particle generation on the GPU (`particle_generate.wgsl`): the twin of [`super::generate`].
//! Each frame: one invocation per grid column lists the non-empty cells into an append buffer,
//! one more sizes the indirect dispatches, and an indirect dispatch makes the particles of the
//! listed cells (Yusov 2014's DispatchIndirect).

use bytemuck::{Pod, Zeroable};

use super::generate::{Generation, ListedCell, Particle};
use crate::gpu::GpuContext;
use crate::gpu::pipeline::{storage_buffer, uniform_buffer};
use crate::pass::{ComputePass, Shared};
use crate::scene::ParticleOcclusion;

/// Most particles the GPU holds: the render pass packs a particle's index into 20 bits.
pub const MAX_PARTICLES: u32 = 1 << 20;

/// Invocations per workgroup of the generation passes.
const WORKGROUP: u32 = 64;

/// The `Generation` uniform of `particle_generate.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GenerationUniform {
    sigma_max_per_m: f32,
    particle_mean_density: f32,
    reserved0: [u32; 2],
    rings: u32,
    ring_cells: u32,
    cell_layers: u32,
    inner_cell_m: f32,
    column_count: u32,
    max_particles: u32,
    occlusion_early_exit: u32,
    occlusion_march: u32,
}

impl GenerationUniform {
    fn new(g: &Generation) -> GenerationUniform {
        GenerationUniform {
            sigma_max_per_m: g.sigma_max_per_m,
            particle_mean_density: g.particle_mean_density,
            reserved0: [0; 2],
            rings: g.grid.rings,
            ring_cells: g.grid.ring_cells,
            cell_layers: g.grid.cell_layers,
            inner_cell_m: g.grid.inner_cell_m,
            column_count: g.grid.column_count(),
            max_particles: capacity(g),
            occlusion_early_exit: u32::from(g.occlusion_early_exit),
            occlusion_march: u32::from(g.occlusion == ParticleOcclusion::March),
        }
    }
}

/// Particles the buffers hold for `g`.
fn capacity(g: &Generation) -> u32 {
    g.grid.max_particles().min(MAX_PARTICLES)
}

/// What a frame's generation counted (`counts` in `particle_generate.wgsl`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GenerationCounts {
    /// Non-empty cells listed.
    pub cells: u32,
    /// Particles made (at most the capacity).
    pub particles: u32,
    /// Segments of the marches toward the sun.
    pub occlusion_steps: u32,
    /// Particles beyond the capacity, dropped.
    pub dropped: u32,
}

impl GenerationCounts {
    /// From the four raw counters.
    pub fn from_words(words: &[u32]) -> GenerationCounts {
        GenerationCounts {
            cells: words[0],
            particles: words[1].min(MAX_PARTICLES),
            occlusion_steps: words[2],
            dropped: words[3],
        }
    }
}

/// The generation passes and their buffers, sized for one grid.
pub struct ParticleGenerator {
    pass: ComputePass,
    uniform: wgpu::Buffer,
    /// The passes' bind group: binding the dispatch sizes, and binding a stand-in for them.
    groups: [wgpu::BindGroup; 2],
    /// The four counters (see [`GenerationCounts`]).
    pub counts: wgpu::Buffer,
    /// Indirect dispatch sizes: `[0..3]` over the listed cells, `[3..6]` over the particles.
    pub dispatches: wgpu::Buffer,
    /// The particles, `Particle` each.
    pub particles: wgpu::Buffer,
    capacity: u32,
    column_count: u32,
}

impl ParticleGenerator {
    /// Builds the passes and buffers for the grid of `g`.
    pub fn new(ctx: &GpuContext, shared: &Shared, g: &Generation) -> ParticleGenerator {
        let pass = ComputePass::new(
            ctx,
            shared,
            "particle generation",
            &PARTICLE_GENERATE_WGSL,
            &[
                "list_cells",
                "size_dispatches",
                "generate_particles",
                "size_particle_dispatch",
            ],
        );
        let capacity = capacity(g);
        let uniform = uniform_buffer(
            ctx,
            "particle generation",
            size_of::<GenerationUniform>() as u64,
        );
        let cells = storage_buffer(
            ctx,
            "particle cells",
            u64::from(g.grid.column_count()) * size_of::<ListedCell>() as u64,
        );
        let counts = storage_buffer(ctx, "particle counts", 16);
        let dispatches = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("particle dispatches"),
            size: 24,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::INDIRECT
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let particles = storage_buffer(
            ctx,
            "particles",
            u64::from(capacity) * size_of::<Particle>() as u64,
        );
        // An indirect dispatch may not bind its own arguments as writable storage: the
        // generation pass binds a stand-in instead.
        let stand_in = storage_buffer(ctx, "particle dispatches stand-in", 24);
        let group_with = |args: &wgpu::Buffer| {
            pass.group.bind(
                ctx,
                &[
                    ("generation", uniform.as_entire_binding()),
                    ("listed_cells", cells.as_entire_binding()),
                    ("counts", counts.as_entire_binding()),
                    ("dispatches", args.as_entire_binding()),
                    ("particles", particles.as_entire_binding()),
                ],
            )
        };
        let groups = [group_with(&dispatches), group_with(&stand_in)];
        ParticleGenerator {
            pass,
            uniform,
            groups,
            counts,
            dispatches,
            particles,
            capacity,
            column_count: g.grid.column_count(),
        }
    }

    /// Whether these buffers were sized for the grid of `g`.
    pub fn fits(&self, g: &Generation) -> bool {
        self.capacity == capacity(g) && self.column_count == g.grid.column_count()
    }

    /// Uploads the grid and the particle constants of `g` (the camera and sun are the frame's
    /// and the environment's).
    pub fn set(&self, ctx: &GpuContext, g: &Generation) {
        let uniform = GenerationUniform::new(g);
        ctx.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Records the generation passes; `timestamps` time them as one pass.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        shared: &Shared,
        timestamps: Option<wgpu::ComputePassTimestampWrites>,
    ) {
        encoder.clear_buffer(&self.counts, 0, None);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("particle generation"),
            timestamp_writes: timestamps,
        });
        let [sizing, generating] = &self.groups;
        let (slots, entry) = (self.pass.slots, |name| self.pass.pipeline(name));
        set_groups(&mut pass, &shared.bind_groups(slots, sizing));
        pass.set_pipeline(entry("list_cells"));
        pass.dispatch_workgroups(self.column_count.div_ceil(WORKGROUP), 1, 1);
        pass.set_pipeline(entry("size_dispatches"));
        pass.dispatch_workgroups(1, 1, 1);
        set_groups(&mut pass, &shared.bind_groups(slots, generating));
        pass.set_pipeline(entry("generate_particles"));
        pass.dispatch_workgroups_indirect(&self.dispatches, 0);
        set_groups(&mut pass, &shared.bind_groups(slots, sizing));
        pass.set_pipeline(entry("size_particle_dispatch"));
        pass.dispatch_workgroups(1, 1, 1);
    }

    /// Puts `particles` in the buffers as though generation had made them (at most the capacity).
    pub fn upload(&self, ctx: &GpuContext, particles: &[Particle]) {
        let n = particles.len().min(self.capacity as usize);
        ctx.queue
            .write_buffer(&self.particles, 0, bytemuck::cast_slice(&particles[..n]));
        let n = n as u32;
        let counts = [0, n, 0, 0];
        ctx.queue
            .write_buffer(&self.counts, 0, bytemuck::cast_slice(&counts));
        let dispatches = [0, 1, 1, n.div_ceil(WORKGROUP), 1, 1];
        ctx.queue
            .write_buffer(&self.dispatches, 0, bytemuck::cast_slice(&dispatches));
    }

    /// The particles and counts of the last generation (waits for the GPU): for tests and tools.
    pub fn read(&self, ctx: &GpuContext) -> (Vec<Particle>, GenerationCounts) {
        let words: Vec<u32> = crate::gpu::readback::read_buffer(ctx, &self.counts);
        let counts = GenerationCounts::from_words(&words);
        let mut particles: Vec<Particle> = crate::gpu::readback::read_buffer(ctx, &self.particles);
        particles.truncate(counts.particles as usize);
        (particles, counts)
    }
}

/// Binds `groups` at their slots (None: left empty).
pub fn set_groups(pass: &mut wgpu::ComputePass, groups: &[Option<&wgpu::BindGroup>]) {
    for (i, g) in groups.iter().enumerate() {
        if let Some(g) = g {
            pass.set_bind_group(i as u32, *g, &[]);
        }
    }
}

/// The pass that generates the particles from the field (`particle_generate.wgsl`).
pub static PARTICLE_GENERATE_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "particle_generate",
    "particle_generate.wgsl",
    [
        &crate::shader::MATH_WGSL,
        &crate::field::gpu::FIELD_WGSL,
        &crate::field::noise::NOISE_WGSL,
        &crate::frame::FRAME_WGSL,
        &crate::environment::ENVIRONMENT_WGSL,
        &super::gpu::PARTICLE_WGSL
    ],
    generation_constants
);

/// The generation's constants as WGSL (the CPU specification's, `generate.rs` and `grid.rs`).
fn generation_constants() -> String {
    use super::generate::{
        FULL_SIZE_DENSITY, MIN_DENSITY, OCCLUSION_MAX_DEPTH, OCCLUSION_PATH_M, OCCLUSION_STEPS,
        RADIUS_PER_CELL, SPAN_SAMPLES,
    };
    use crate::shader::WgslConst::{F32, U32};
    crate::shader::wgsl_consts([
        ("CELL_JITTER", F32(super::grid::CELL_JITTER)),
        ("RADIUS_PER_CELL", F32(RADIUS_PER_CELL)),
        ("FULL_SIZE_DENSITY", F32(FULL_SIZE_DENSITY)),
        ("MIN_DENSITY", F32(MIN_DENSITY)),
        ("OCCLUSION_STEPS", U32(OCCLUSION_STEPS)),
        ("SPAN_SAMPLES", U32(SPAN_SAMPLES)),
        ("OCCLUSION_PATH_M", F32(OCCLUSION_PATH_M)),
        ("OCCLUSION_MAX_DEPTH", F32(OCCLUSION_MAX_DEPTH)),
        ("GENERATE_WORKGROUP", U32(WORKGROUP)),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::layout_check::assert_wgsl_layout;

    #[test]
    fn generation_structs_match_their_wgsl_layouts() {
        assert_wgsl_layout!(
            &crate::particles::generate_gpu::PARTICLE_GENERATE_WGSL,
            "Generation",
            GenerationUniform {
                sigma_max_per_m,
                particle_mean_density,
                reserved0,
                rings,
                ring_cells,
                cell_layers,
                inner_cell_m,
                column_count,
                max_particles,
                occlusion_early_exit,
                occlusion_march,
            }
        );
        assert_wgsl_layout!(
            &crate::particles::generate_gpu::PARTICLE_GENERATE_WGSL,
            "Particle",
            Particle {
                centre_m,
                radius_m,
                height_m,
                density,
                sun_optical_depth,
                id,
                optical_depth_up,
                optical_depth_down,
                ring,
                reserved,
            }
        );
        assert_wgsl_layout!(
            &crate::particles::generate_gpu::PARTICLE_GENERATE_WGSL,
            "ListedCell",
            crate::particles::generate::ListedCell {
                column,
                layers,
                span_m
            }
        );
        assert_wgsl_layout!(
            &crate::particles::render::PARTICLE_RENDER_WGSL,
            "ParticleShape",
            crate::particles::density::ParticleShape {
                base_cells,
                a,
                b,
                c
            }
        );
    }
}
