//! The light volume's passes (`light_volume.wgsl`): the cells' inputs, the sweeps of the solve
//! (warm-started while the grid stays put), and the table the environment reads.

use super::inputs::{BEAM_GROWTH, BEAM_MIN_SUN_Y, BEAM_PATH_MAX_M, CELL_SAMPLE_OFFSET};
use super::solve::MAX_COLUMN_CELLS;
use super::{LightVolumeGrid, LightVolumeSettings, MAX_CASCADES, TABLE_PARTS};
use crate::environment::{EnvironmentGpu, EnvironmentTable};
use crate::gpu::pipeline::{storage_buffer, uniform_buffer};
use crate::gpu::{GpuContext, PassTimer};
use crate::pass::{BindGroupCache, ComputePass, Shared};
use bytemuck::{Pod, Zeroable};
use glam::{IVec4, UVec2};

/// Labels the passes are timed under: the cells' inputs, the solve's sweeps, the table.
pub const LIGHT_VOLUME_PASS_NAMES: [&str; 3] = [
    "light volume cells",
    "light volume solve",
    "light volume table",
];

const ENTRIES: [&str; 9] = [
    "light_volume_cells",
    "light_volume_cells_slice",
    "light_volume_limit",
    "light_volume_relax_red",
    "light_volume_relax_black",
    "light_volume_relax_red_uncoupled",
    "light_volume_relax_black_uncoupled",
    "light_volume_export",
    "light_volume_scroll",
];

/// Slices a cascade's rows are updated in on warm frames, one a turn: a turn recomputes the inputs
/// (the mean field's extinction, the sun's beam through it) of an eighth of the cells of the
/// cascade it solves, so that a cell's inputs are at most `CELL_SLICES` times the cascades turns
/// old (48 frames in the default scene: 0.8 s at 60 fps, in which an 8 m/s wind moves the clouds
/// 6 m through cells 333 m wide).
pub const CELL_SLICES: u32 = 8;

/// The table's pass among [`LIGHT_VOLUME_PASS_NAMES`]: its frame of a warm turn also copies the
/// table into the environment's texture.
const TABLE_PART: usize = 2;

/// Frames a warm turn is spread over, one part each, the passes of [`LIGHT_VOLUME_PASS_NAMES`]: the
/// slice of the cells' inputs, the sweeps, the table. Each frame then carries a third of the
/// volume's work, evenly, rather than all of it (a cascade still gets ten sweeps a second at 60
/// fps, against clouds that cross one of its cells in 40 s); the environment reads the last table
/// until the turn writes the next.
pub const WARM_TURN_FRAMES: u32 = LIGHT_VOLUME_PASS_NAMES.len() as u32;

/// The most cells (of any cascade) a recentred grid may have moved for its solve to start from the
/// last solution scrolled: twice [`super::RECENTRE_CELLS`] (in the default scene 2.7 km, a frame's
/// move at 160 km/s and 60 fps), more than any flight recentres it by. A grid that moved further was
/// cut to a new place (a camera cut, a teleport) and is solved cold, as a first frame there would
/// be: nothing of before leaks in.
const MAX_SCROLL_CELLS: u32 = 2 * super::RECENTRE_CELLS as u32;

/// Texels a row of the table's staging buffer is padded to: wgpu copies rows of 256 bytes
/// (`COPY_BYTES_PER_ROW_ALIGNMENT`), 32 rgba16float texels.
const ROW_TEXELS: u32 = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT / 8;

/// The solve's buffers (cells' inputs, radiance, diffusion coefficients, the table staged for its
/// copy into the environment's texture) and pipelines, with the grid whose solution the radiance
/// holds.
pub struct LightVolumePass {
    pass: ComputePass,
    buffers: Option<[wgpu::Buffer; 4]>,
    /// What the frame's passes solve ([`SolveUniform`]).
    solve: wgpu::Buffer,
    /// Warm frames solved since the last cold or scrolled one: whose turn it is.
    warm_frames: u32,
    group: BindGroupCache,
    solved: Option<LightVolumeGrid>,
}

impl LightVolumePass {
    /// Builds the pipelines against the shared groups.
    pub fn new(ctx: &GpuContext, shared: &Shared) -> LightVolumePass {
        LightVolumePass {
            pass: ComputePass::new(ctx, shared, "light volume", &LIGHT_VOLUME_WGSL, &ENTRIES),
            buffers: None,
            solve: uniform_buffer(ctx, "light volume solve", size_of::<SolveUniform>() as u64),
            warm_frames: 0,
            group: BindGroupCache::default(),
            solved: None,
        }
    }

    /// Makes the buffers hold the cells of `grid`; true when they were remade (and hold nothing).
    fn ensure_buffers(&mut self, ctx: &GpuContext, grid: &LightVolumeGrid) -> bool {
        let cascades = grid.cascades.len() as u64;
        let cells = u64::from(grid.cells.element_product()) * cascades;
        let n = grid.cells;
        let table = 8 * u64::from(table_row_texels(n.x) * n.y * TABLE_PARTS * n.z) * cascades;
        let bytes = [16 * cells, 16 * cells, 4 * cells, table];
        if self
            .buffers
            .as_ref()
            .is_some_and(|b| b.iter().zip(bytes).all(|(b, n)| b.size() == n))
        {
            return false;
        }
        let labels = [
            "light volume cells",
            "light volume radiance",
            "light volume diffusion",
            "light volume table",
        ];
        self.buffers = Some([0, 1, 2, 3].map(|i| storage_buffer(ctx, labels[i], bytes[i])));
        self.group.clear();
        true
    }

    /// Records the frame's volume for `grid` (the environment's uniform already holds it): a cold
    /// solve of `settings.sweeps` sweeps when the grid is new or the frame may not start warm;
    /// when the grid was recentred by whole cells, the last solution scrolled with it, every
    /// cell's inputs and `warm_sweeps` more sweeps than it moved cells (the solution spreads a
    /// cell a sweep into the new columns); else, amortised over frames, one part of a warm turn
    /// ([`WARM_TURN_FRAMES`]): a slice of one cascade's cells' inputs, its `warm_sweeps` from the
    /// last solution, or its table, the cascades in turn.
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        (shared, environment): (&Shared, &EnvironmentGpu),
        (grid, settings, may_start_warm): (&LightVolumeGrid, &LightVolumeSettings, bool),
        mut timer: Option<&mut PassTimer>,
    ) {
        assert!(
            grid.cells.y <= MAX_COLUMN_CELLS,
            "the light volume's columns hold at most {MAX_COLUMN_CELLS} cells"
        );
        let remade = self.ensure_buffers(ctx, grid);
        let turn_frame = (self.warm_frames % WARM_TURN_FRAMES) as usize;
        let (solve, moved_cells) = self.plan(grid, !remade && may_start_warm);
        // A cold or scrolled frame records every pass; a warm one its turn's part.
        let records = |part: usize| moved_cells != Some(0) || part == turn_frame;
        ctx.queue
            .write_buffer(&self.solve, 0, bytemuck::bytes_of(&solve));
        let buffers = self.buffers.as_ref().expect("made above");
        let passes = [
            cells_steps(grid, &solve, moved_cells),
            solve_steps(grid, &solve, moved_cells, settings),
            table_steps(grid, &solve),
        ];
        match moved_cells {
            None => encoder.clear_buffer(&buffers[1], 0, None),
            Some(1..) => {
                encoder.copy_buffer_to_buffer(&buffers[1], 0, &buffers[3], 0, buffers[1].size());
            }
            Some(0) => {}
        }
        let pass = &self.pass;
        let solve_buffer = &self.solve;
        let group = self.group.get(&[], || {
            pass.group.bind(
                ctx,
                &[
                    ("volume_cells", buffers[0].as_entire_binding()),
                    ("volume_radiance", buffers[1].as_entire_binding()),
                    ("volume_diffusion", buffers[2].as_entire_binding()),
                    ("volume_table_out", buffers[3].as_entire_binding()),
                    ("volume_solve", solve_buffer.as_entire_binding()),
                ],
            )
        });
        let writing = environment.bind_group_writing(EnvironmentTable::LightVolume);
        let groups = shared.bind_groups_with(pass.slots, writing, group);
        for (part, (label, steps)) in LIGHT_VOLUME_PASS_NAMES.iter().zip(passes).enumerate() {
            let writes = timer
                .as_deref_mut()
                .and_then(|t| t.compute_pass_writes(label));
            let mut compute = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(label),
                timestamp_writes: writes,
            });
            if !records(part) {
                continue;
            }
            for (i, g) in groups.iter().enumerate() {
                if let Some(g) = g {
                    compute.set_bind_group(i as u32, *g, &[]);
                }
            }
            for (entry, size) in steps {
                compute.set_pipeline(pass.pipeline(entry));
                compute.dispatch_workgroups(size.x.div_ceil(8), size.y.div_ceil(8), 1);
            }
        }
        if records(TABLE_PART) {
            let table = environment.texture(EnvironmentTable::LightVolume);
            copy_table(encoder, (&buffers[3], table), grid, &solve);
        }
        self.solved = Some(grid.clone());
    }

    /// What this frame solves for `grid`, and how many cells the grid moved since the last
    /// solution when the solve starts from it (None: cold; 0: a warm frame, which takes the next
    /// part of a turn, the turns going round the cascades).
    fn plan(
        &mut self,
        grid: &LightVolumeGrid,
        may_start_warm: bool,
    ) -> (SolveUniform, Option<u32>) {
        let cascades = grid.cascades.len() as u32;
        let shift = match (&self.solved, may_start_warm) {
            (Some(solved), true) => grid.shift_cells_from(solved),
            _ => None,
        };
        let moved_cells = shift
            .as_ref()
            .map(|s| s.iter().map(|c| c.abs().max_element()).max().unwrap_or(0) as u32)
            .filter(|&moved| moved <= MAX_SCROLL_CELLS);
        let mut solve = SolveUniform::zeroed();
        let scrolled = shift.iter().flatten().filter(|_| moved_cells.is_some());
        for (c, s) in solve.shift_cells.iter_mut().zip(scrolled) {
            *c = s.extend(0).extend(0);
        }
        let turn = self.warm_frames / WARM_TURN_FRAMES;
        (solve.first_swept, solve.swept) = match moved_cells {
            Some(0) => (turn % cascades, 1),
            _ => (0, cascades),
        };
        solve.cell_slice = (turn / cascades) % CELL_SLICES;
        self.warm_frames = match moved_cells {
            Some(0) => self.warm_frames.wrapping_add(1),
            _ => 0,
        };
        (solve, moved_cells)
    }
}

/// A compute step: an entry point of `light_volume.wgsl` and the size of its 2-D dispatch.
type Step = (&'static str, UVec2);

/// The cells' inputs: every cell's of a cold solve, the scroll and every cell's of a scrolled
/// one, a slice of the swept cascade's of a warm one.
fn cells_steps(grid: &LightVolumeGrid, solve: &SolveUniform, moved: Option<u32>) -> Vec<Step> {
    let n = grid.cells;
    let over_cells = UVec2::new(n.x, n.y * n.z * grid.cascades.len() as u32);
    match moved {
        None => vec![(ENTRIES[0], over_cells)],
        Some(0) => {
            let rows = (n.y * n.z * solve.swept).div_ceil(CELL_SLICES);
            vec![(ENTRIES[1], UVec2::new(n.x, rows))]
        }
        Some(_) => vec![(ENTRIES[8], over_cells), (ENTRIES[0], over_cells)],
    }
}

/// The sweeps: `settings.sweeps` of a cold solve, `warm_sweeps` and one per cell moved of a
/// scrolled one, `warm_sweeps` of a warm one; each the flux limiter, then the red columns, then
/// the black (the first of a cold solve without the horizontal coupling, which it has nothing to
/// couple to yet).
fn solve_steps(
    grid: &LightVolumeGrid,
    solve: &SolveUniform,
    moved: Option<u32>,
    settings: &LightVolumeSettings,
) -> Vec<Step> {
    let n = grid.cells;
    let over_swept_cells = UVec2::new(n.x, n.y * n.z * solve.swept);
    // A sweep relaxes the columns of one colour, then the other's: half of x each.
    let over_one_colour = UVec2::new(n.x.div_ceil(2), n.z * solve.swept);
    let sweeps = match moved {
        None => settings.sweeps.max(1),
        Some(moved) => (settings.warm_sweeps + moved).min(settings.sweeps.max(1)),
    };
    let mut steps = Vec::new();
    for s in 0..sweeps {
        let coupled = !(moved.is_none() && s == 0);
        let (red, black) = if coupled { (3, 4) } else { (5, 6) };
        steps.extend([
            (ENTRIES[2], over_swept_cells),
            (ENTRIES[red], over_one_colour),
            (ENTRIES[black], over_one_colour),
        ]);
    }
    steps
}

/// The table of the swept cascades.
fn table_steps(grid: &LightVolumeGrid, solve: &SolveUniform) -> Vec<Step> {
    let n = grid.cells;
    vec![(ENTRIES[7], UVec2::new(n.x, n.y * n.z * solve.swept))]
}

/// What a frame's passes solve: `LightVolumeSolve` of `light_volume.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct SolveUniform {
    /// Per cascade (x, y): where the frame's cells lay in the grid last solved, in whole cells
    /// along x and z ([`LightVolumeGrid::shift_cells_from`]), for a recentred grid's scroll.
    shift_cells: [IVec4; MAX_CASCADES as usize],
    /// The first cascade the frame's sweeps and table cover.
    first_swept: u32,
    /// How many cascades, from it.
    swept: u32,
    /// The slice of the swept cascades' rows whose inputs a warm turn updates.
    cell_slice: u32,
    pad0: u32,
}

/// Texels of a row of the staged table for `width` cells: padded to [`ROW_TEXELS`].
fn table_row_texels(width: u32) -> u32 {
    width.div_ceil(ROW_TEXELS) * ROW_TEXELS
}

/// Copies the parts of the swept cascades (`solve`'s) of the staged table into the environment's
/// texture: the table holds [`TABLE_PARTS`] parts along z, each the cascades' cells side by side.
fn copy_table(
    encoder: &mut wgpu::CommandEncoder,
    (staged, texture): (&wgpu::Buffer, &wgpu::Texture),
    grid: &LightVolumeGrid,
    solve: &SolveUniform,
) {
    let n = grid.cells;
    let bytes_per_row = 8 * table_row_texels(n.x);
    for part in 0..TABLE_PARTS {
        let first_slice = n.z * (part * grid.cascades.len() as u32 + solve.first_swept);
        encoder.copy_buffer_to_texture(
            wgpu::TexelCopyBufferInfo {
                buffer: staged,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: u64::from(first_slice * n.y * bytes_per_row),
                    bytes_per_row: Some(bytes_per_row),
                    rows_per_image: Some(n.y),
                },
            },
            wgpu::TexelCopyTextureInfo {
                origin: wgpu::Origin3d {
                    z: first_slice,
                    ..wgpu::Origin3d::ZERO
                },
                ..texture.as_image_copy()
            },
            wgpu::Extent3d {
                width: n.x,
                height: n.y,
                depth_or_array_layers: n.z * solve.swept,
            },
        );
    }
}

/// The light volume's solve on the GPU (`light_volume.wgsl`).
pub static LIGHT_VOLUME_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "light_volume",
    "light_volume.wgsl",
    [
        &crate::shader::MATH_WGSL,
        &crate::field::gpu::FIELD_WGSL,
        &crate::frame::FRAME_WGSL,
        &crate::environment::ENVIRONMENT_WGSL
    ],
    light_volume_constants
);

/// The solve's constants as WGSL (inputs.rs and solve.rs).
fn light_volume_constants() -> String {
    use crate::shader::WgslConst::{F32, U32};
    crate::shader::wgsl_consts([
        ("LIGHT_VOLUME_CELL_SAMPLE_OFFSET", F32(CELL_SAMPLE_OFFSET)),
        ("LIGHT_VOLUME_BEAM_GROWTH", F32(BEAM_GROWTH)),
        ("LIGHT_VOLUME_BEAM_PATH_MAX_M", F32(BEAM_PATH_MAX_M)),
        ("LIGHT_VOLUME_BEAM_MIN_SUN_Y", F32(BEAM_MIN_SUN_Y)),
        ("LIGHT_VOLUME_MAX_COLUMN_CELLS", U32(MAX_COLUMN_CELLS)),
        ("LIGHT_VOLUME_ROW_TEXELS", U32(ROW_TEXELS)),
        ("LIGHT_VOLUME_CELL_SLICES", U32(CELL_SLICES)),
        (
            "LIGHT_VOLUME_MAX_RELATIVE_CURRENT",
            F32(super::solve::MAX_RELATIVE_CURRENT),
        ),
        (
            "LIGHT_VOLUME_MIN_WEIGHT",
            F32(super::read::MIN_INTERPOLATION_WEIGHT),
        ),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::layout_check::assert_wgsl_layout;

    #[test]
    fn the_solve_uniform_matches_its_wgsl_layout() {
        assert_wgsl_layout!(
            &LIGHT_VOLUME_WGSL,
            "LightVolumeSolve",
            SolveUniform {
                shift_cells,
                first_swept,
                swept,
                cell_slice,
                pad0
            }
        );
    }
}
