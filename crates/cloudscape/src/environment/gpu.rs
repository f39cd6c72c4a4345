//! The environment on the GPU: its uniform, the atmosphere's tables, the clouds' shadow map and
//! the light volume in one bind group ([`crate::shader::ENVIRONMENT_GROUP`]), as `environment.wgsl` declares them.

use super::light_volume::{
    DiffuseOptics, LightVolumeGrid, LightVolumeSettings, MAX_CASCADES, TABLE_PARTS,
};
use super::{Environment, SkyModel};
use crate::atmosphere::Air;
use crate::atmosphere::luts::{
    AERIAL_SIZE, AERIAL_SLICES, IRRADIANCE_SIZE, MULTIPLE_SCATTERING_SIZE, SKY_VIEW_SIZE,
    TRANSMITTANCE_SIZE,
};
use crate::gpu::GpuContext;
use crate::gpu::pipeline::{UNIFORM, bind_group, bind_group_layout, float_texture, uniform_buffer};
use crate::shadow::ShadowParams;
use bytemuck::{Pod, Zeroable};
use glam::{UVec3, Vec2, Vec3, Vec4};

/// Format of every table: filterable everywhere, and storage-writable.
pub const TABLE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// GPU layout of [`Air`]: the `Air` struct of `atmosphere.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct AirUniform {
    rayleigh_scattering_per_m: Vec3,
    bottom_radius_m: f32,
    ozone_absorption_per_m: Vec3,
    top_radius_m: f32,
    ground_albedo: Vec3,
    mie_scattering_per_m: f32,
    mie_extinction_per_m: f32,
    mie_g: f32,
    sun_angular_radius_rad: f32,
    flat_world: u32,
}

impl AirUniform {
    /// The uniform of `air`.
    pub fn new(air: &Air) -> AirUniform {
        AirUniform {
            rayleigh_scattering_per_m: air.rayleigh_scattering_per_m,
            bottom_radius_m: air.bottom_radius_m,
            ozone_absorption_per_m: air.ozone_absorption_per_m,
            top_radius_m: air.top_radius_m,
            ground_albedo: air.ground_albedo,
            mie_scattering_per_m: air.mie_scattering_per_m,
            mie_extinction_per_m: air.mie_extinction_per_m,
            mie_g: air.mie_g,
            sun_angular_radius_rad: air.sun_angular_radius_rad,
            flat_world: u32::from(air.flat_world),
        }
    }
}

/// GPU layout of [`ShadowParams`]: the `CloudShadow` struct of `shadow_map.wgsl`
/// ([`crate::shadow::SHADOW_MAP_WGSL`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct CloudShadowUniform {
    centre_m: Vec2,
    half_extent_m: f32,
    warp: f32,
    bottom_y_m: f32,
    top_y_m: f32,
    sun_y: f32,
    enabled: u32,
    steps_per_checkpoint: u32,
    pad0: u32,
    pad: [u32; 2],
}

/// The frame's map as a host binds it in its own shaders ([`crate::shadow::SHADOW_MAP_WGSL`]):
/// [`crate::renderer::CloudRenderer::shadow_map`].
#[derive(Clone, Copy, Debug)]
pub struct ShadowMapBinding<'a> {
    /// The map: a 2-D array of two layers (the columns along the sun, then straight up), each
    /// texel's four checkpoints' optical depths in rgba, in [`EnvironmentGpu`]'s table format.
    /// Filled by the frame's environment passes: copy or bind it after them.
    pub texture: &'a wgpu::Texture,
    /// Where the map lies: `CloudShadow` of `shadow_map.wgsl`.
    pub params: CloudShadowUniform,
    /// Unit vector toward the frame's sun, world space (`sun_direction` of the read).
    pub sun_direction: Vec3,
}

impl CloudShadowUniform {
    /// The uniform of `params`.
    pub fn new(params: &ShadowParams) -> CloudShadowUniform {
        CloudShadowUniform {
            centre_m: params.centre_m,
            half_extent_m: params.half_extent_m,
            warp: params.warp,
            bottom_y_m: params.bottom_y_m,
            top_y_m: params.top_y_m,
            sun_y: params.sun_y,
            enabled: u32::from(params.enabled),
            steps_per_checkpoint: params.steps_per_checkpoint,
            pad0: 0,
            pad: [0; 2],
        }
    }
}

/// GPU layout of an [`Environment`] seen from one viewpoint: the `Environment` struct of
/// `environment.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct EnvironmentUniform {
    sun_direction: Vec3,
    sun_cos_angular_radius: f32,
    sun_irradiance: Vec3,
    haze_extinction_per_m: f32,
    sky_zenith_radiance: Vec3,
    sky_gradient_exponent: f32,
    sky_horizon_radiance: Vec3,
    sky_model: u32,
    viewpoint_m: Vec3,
    sun_limb_darkening: f32,
    air: AirUniform,
    shadow: CloudShadowUniform,
    light_volume: LightVolumeUniform,
}

/// GPU layout of a frame's light volume ([`LightVolumeGrid`], [`DiffuseOptics`]): the
/// `LightVolume` struct of `environment.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct LightVolumeUniform {
    cascade_min_m: [Vec4; MAX_CASCADES as usize],
    cascade_cell_m: [Vec4; MAX_CASCADES as usize],
    cells: UVec3,
    cascades: u32,
    optics: Vec4,
    enabled: u32,
    beam_steps: u32,
    pad0: u32,
    pad1: u32,
}

impl LightVolumeUniform {
    /// The volume of `grid` with `optics`, sampling the beam in `beam_steps`; zeros (read as no
    /// diffuse light) for None.
    pub fn new(volume: Option<(&LightVolumeGrid, DiffuseOptics, u32)>) -> LightVolumeUniform {
        let mut out = LightVolumeUniform::zeroed();
        let Some((grid, optics, beam_steps)) = volume else {
            out.cells = UVec3::ONE;
            out.cascades = 1;
            return out;
        };
        for (k, c) in grid.cascades.iter().enumerate() {
            out.cascade_min_m[k] = c.min_m.extend(0.0);
            out.cascade_cell_m[k] = c.cell_m.extend(0.0);
        }
        out.cells = grid.cells;
        out.cascades = grid.cascades.len() as u32;
        out.optics = Vec4::from_array(optics.to_gpu());
        out.enabled = u32::from(grid.enabled);
        out.beam_steps = beam_steps;
        out
    }
}

impl EnvironmentUniform {
    /// The uniform of `env` seen from world point `viewpoint_m`, with the clouds' shadow map
    /// `shadow`, without a light volume ([`EnvironmentUniform::with_light_volume`]).
    pub fn new(env: &Environment, viewpoint_m: Vec3, shadow: &ShadowParams) -> EnvironmentUniform {
        EnvironmentUniform {
            sun_direction: env.sun.direction,
            sun_cos_angular_radius: env.sun.cos_radius,
            sun_irradiance: env.sun.irradiance,
            haze_extinction_per_m: env.sky.haze_per_m,
            sky_zenith_radiance: env.sky.zenith,
            sky_gradient_exponent: env.sky.exponent,
            sky_horizon_radiance: env.sky.horizon,
            sky_model: u32::from(env.sky_model == SkyModel::Atmosphere),
            viewpoint_m,
            sun_limb_darkening: env.sun.limb_darkening,
            air: AirUniform::new(&env.air),
            shadow: CloudShadowUniform::new(shadow),
            light_volume: LightVolumeUniform::new(None),
        }
    }

    /// This uniform with the frame's light volume.
    pub fn with_light_volume(self, light_volume: LightVolumeUniform) -> EnvironmentUniform {
        EnvironmentUniform {
            light_volume,
            ..self
        }
    }
}

/// The environment's tables, each written by one pass; the bind group a pass binds while it
/// writes one holds a stand-in for it (a texture cannot be read and written in one pass).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvironmentTable {
    /// Transmittance to the top of the air (binding 1).
    Transmittance,
    /// Hillaire's multiple-scattering transfer (binding 2).
    MultipleScattering,
    /// Sky irradiance and mean radiance (binding 3).
    Irradiance,
    /// The sky seen from the viewpoint (binding 4).
    SkyView,
    /// Aerial-perspective in-scattering and transmittance (binding 5, layers 0 and 1).
    Aerial,
    /// The clouds' light-space optical depth (binding 6).
    CloudShadow,
    /// The light volume's diffuse radiance and current (binding 7, one above the other along z).
    LightVolume,
}

impl EnvironmentTable {
    /// Every table, in binding order.
    pub const ALL: [EnvironmentTable; 7] = [
        EnvironmentTable::Transmittance,
        EnvironmentTable::MultipleScattering,
        EnvironmentTable::Irradiance,
        EnvironmentTable::SkyView,
        EnvironmentTable::Aerial,
        EnvironmentTable::CloudShadow,
        EnvironmentTable::LightVolume,
    ];

    /// Bindings of the texture (or textures) of this table.
    fn bindings(self) -> &'static [usize] {
        match self {
            EnvironmentTable::Transmittance => &[1],
            EnvironmentTable::MultipleScattering => &[2],
            EnvironmentTable::Irradiance => &[3],
            EnvironmentTable::SkyView => &[4],
            EnvironmentTable::Aerial => &[5],
            EnvironmentTable::CloudShadow => &[6],
            EnvironmentTable::LightVolume => &[7],
        }
    }
}

/// One table texture: its size, layers and view dimension.
struct TableShape {
    label: &'static str,
    size: (u32, u32, u32),
    dimension: wgpu::TextureViewDimension,
}

/// The sizes of the tables that follow the scene's settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TableSizes {
    /// Texels per side of the cloud shadow map.
    pub shadow_texels: u32,
    /// Cells of the light volume: one cascade's, the cascades side by side along z (the table
    /// holds them [`TABLE_PARTS`] times along z).
    pub light_volume: UVec3,
}

impl TableSizes {
    /// The sizes a scene asks for: its shadow map, and its light volume when its lighting model
    /// reads one (else a single texel).
    pub fn from_scene(scene: &crate::scene::Scene) -> TableSizes {
        let light_volume = if scene.lighting.model == crate::scene::LightingModel::Volume {
            let settings = LightVolumeSettings::from_scene(scene);
            settings.cells() * UVec3::new(1, 1, settings.cascades)
        } else {
            UVec3::ONE
        };
        TableSizes {
            shadow_texels: scene.shadow.resolution,
            light_volume,
        }
    }

    /// The smallest tables (tests of passes that read none of them).
    pub const SMALLEST: TableSizes = TableSizes {
        shadow_texels: 1,
        light_volume: UVec3::ONE,
    };
}

/// The shapes of bindings 1-7 for tables of `sizes`.
fn shapes(sizes: TableSizes) -> [TableShape; 7] {
    use wgpu::TextureViewDimension::{D2, D2Array, D3};
    let volume = sizes.light_volume;
    // The aerial perspective's slices side by side (`atmosphere_aerial.wgsl`).
    let atlas = (AERIAL_SIZE.0 * AERIAL_SLICES, AERIAL_SIZE.1);
    let shape = |label, (w, h): (u32, u32), layers, dimension| TableShape {
        label,
        size: (w, h, layers),
        dimension,
    };
    [
        shape("transmittance table", TRANSMITTANCE_SIZE, 1, D2),
        shape("multiple scattering table", MULTIPLE_SCATTERING_SIZE, 1, D2),
        shape("sky irradiance table", IRRADIANCE_SIZE, 2, D2Array),
        shape("sky view table", SKY_VIEW_SIZE, 1, D2),
        shape("aerial perspective", atlas, 2, D2Array),
        shape(
            "cloud shadow map",
            (sizes.shadow_texels, sizes.shadow_texels),
            2,
            D2Array,
        ),
        shape(
            "light volume",
            (volume.x, volume.y),
            TABLE_PARTS * volume.z,
            D3,
        ),
    ]
}

fn make_texture(ctx: &GpuContext, shape: &TableShape, stand_in: bool) -> wgpu::Texture {
    let three_d = shape.dimension == wgpu::TextureViewDimension::D3;
    let (w, h, layers) = match (stand_in, three_d) {
        (true, true) => (1, 1, 1),
        (true, false) => (1, 1, shape.size.2),
        (false, _) => shape.size,
    };
    ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(shape.label),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: if three_d {
            wgpu::TextureDimension::D3
        } else {
            wgpu::TextureDimension::D2
        },
        format: TABLE_FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

fn whole_view(texture: &wgpu::Texture, dimension: wgpu::TextureViewDimension) -> wgpu::TextureView {
    texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(dimension),
        ..Default::default()
    })
}

/// The environment's uniform buffer, tables and bind groups ([`crate::shader::ENVIRONMENT_GROUP`]):
/// `EnvironmentGpu::new(ctx, 256)`, then `write(ctx, &EnvironmentUniform::new(..))` each frame;
/// [`crate::environment::EnvironmentPasses`] fills the tables.
pub struct EnvironmentGpu {
    buffer: wgpu::Buffer,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    textures: Vec<wgpu::Texture>,
    views: Vec<wgpu::TextureView>,
    stand_ins: Vec<wgpu::TextureView>,
    bind_group: Option<wgpu::BindGroup>,
    writing: Vec<wgpu::BindGroup>,
    outputs: Vec<Vec<wgpu::TextureView>>,
    sizes: Option<TableSizes>,
    generation: u64,
}

impl EnvironmentGpu {
    /// Makes the buffer (zeroed), the tables (of `sizes`) and the bind groups.
    pub fn new(ctx: &GpuContext, sizes: TableSizes) -> EnvironmentGpu {
        let buffer = uniform_buffer(ctx, "environment", size_of::<EnvironmentUniform>() as u64);
        let mut types = vec![UNIFORM];
        types.extend(
            shapes(TableSizes::SMALLEST)
                .iter()
                .map(|s| float_texture(s.dimension)),
        );
        types.push(wgpu::BindingType::Sampler(
            wgpu::SamplerBindingType::Filtering,
        ));
        let layout = bind_group_layout(&ctx.device, "environment", &types);
        let sampler = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("environment tables"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let stand_ins = shapes(TableSizes::SMALLEST)
            .iter()
            .map(|s| whole_view(&make_texture(ctx, s, true), s.dimension))
            .collect();
        let mut gpu = EnvironmentGpu {
            buffer,
            layout,
            sampler,
            textures: Vec::new(),
            views: Vec::new(),
            stand_ins,
            bind_group: None,
            writing: Vec::new(),
            outputs: Vec::new(),
            sizes: None,
            generation: 0,
        };
        gpu.resize(ctx, sizes);
        gpu
    }

    /// Remakes the tables and bind groups for tables of `sizes` (nothing when they already have
    /// them). The tables' contents are lost: fill them again.
    pub fn resize(&mut self, ctx: &GpuContext, sizes: TableSizes) {
        if self.sizes == Some(sizes) {
            return;
        }
        let shapes = shapes(sizes);
        self.textures = shapes.iter().map(|s| make_texture(ctx, s, false)).collect();
        self.views = self
            .textures
            .iter()
            .zip(&shapes)
            .map(|(t, s)| whole_view(t, s.dimension))
            .collect();
        self.bind_group = Some(self.group(ctx, None));
        self.writing = EnvironmentTable::ALL
            .iter()
            .map(|t| self.group(ctx, Some(*t)))
            .collect();
        self.outputs = EnvironmentTable::ALL
            .iter()
            .map(|t| self.storage_views(*t))
            .collect();
        self.sizes = Some(sizes);
        self.generation += 1;
    }

    /// The views a pass writes `table` through: the whole texture, or one view per layer of an
    /// array (irradiance and mean radiance; the aerial perspective's in-scattering and
    /// transmittance; the sun's and the sky's columns).
    fn storage_views(&self, table: EnvironmentTable) -> Vec<wgpu::TextureView> {
        let texture = &self.textures[table.bindings()[0] - 1];
        match table {
            EnvironmentTable::Irradiance
            | EnvironmentTable::Aerial
            | EnvironmentTable::CloudShadow => (0..2)
                .map(|layer| {
                    texture.create_view(&wgpu::TextureViewDescriptor {
                        dimension: Some(wgpu::TextureViewDimension::D2),
                        base_array_layer: layer,
                        array_layer_count: Some(1),
                        ..Default::default()
                    })
                })
                .collect(),
            _ => vec![texture.create_view(&Default::default())],
        }
    }

    /// The texture of `table`: the light volume's pass fills its table by a copy (GL binds a 3-D
    /// storage texture one slice at a time: wgpu's GL backend binds a single-layer view
    /// unlayered, so a compute pass cannot write all of it), and a host copies the clouds' shadow
    /// map out of its table.
    pub fn texture(&self, table: EnvironmentTable) -> &wgpu::Texture {
        &self.textures[table.bindings()[0] - 1]
    }

    /// The storage views of `table` ([`EnvironmentTable`]'s outputs, in binding order).
    pub fn output_views(&self, table: EnvironmentTable) -> &[wgpu::TextureView] {
        &self.outputs[Self::index(table)]
    }

    /// Counts the times the tables were remade: a pass's bind groups of
    /// [`EnvironmentGpu::output_views`] are stale when it changed.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    fn index(table: EnvironmentTable) -> usize {
        EnvironmentTable::ALL
            .iter()
            .position(|t| *t == table)
            .expect("every table is in ALL")
    }

    /// The bind group with the stand-ins in place of `written`'s textures.
    fn group(&self, ctx: &GpuContext, written: Option<EnvironmentTable>) -> wgpu::BindGroup {
        let replaced = written.map_or(&[][..], EnvironmentTable::bindings);
        let mut resources = vec![self.buffer.as_entire_binding()];
        for (i, view) in self.views.iter().enumerate() {
            let view = if replaced.contains(&(i + 1)) {
                &self.stand_ins[i]
            } else {
                view
            };
            resources.push(wgpu::BindingResource::TextureView(view));
        }
        resources.push(wgpu::BindingResource::Sampler(&self.sampler));
        bind_group(&ctx.device, &self.layout, &resources)
    }

    /// Uploads `value` for the next submitted work.
    pub fn write(&self, ctx: &GpuContext, value: &EnvironmentUniform) {
        ctx.queue
            .write_buffer(&self.buffer, 0, bytemuck::bytes_of(value));
    }

    /// The bind group layout, for pipeline layouts.
    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// The bind group with every table.
    pub fn bind_group(&self) -> &wgpu::BindGroup {
        self.bind_group.as_ref().expect("made by new")
    }

    /// The bind group for the pass that writes `table`: a stand-in in its place.
    pub fn bind_group_writing(&self, table: EnvironmentTable) -> &wgpu::BindGroup {
        &self.writing[Self::index(table)]
    }

    /// Texels per side of the shadow map.
    pub fn shadow_texels(&self) -> u32 {
        self.sizes().shadow_texels
    }

    /// The tables' sizes.
    pub fn sizes(&self) -> TableSizes {
        self.sizes.expect("made by new")
    }
}

/// The environment on the GPU (`environment.wgsl`, group [`crate::shader::ENVIRONMENT_GROUP`]): sun, sky, aerial perspective and the clouds' shadow, for every technique and for a host's own shaders ([`crate::shader::Program::host`]).
pub static ENVIRONMENT_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "environment",
    "environment.wgsl",
    [
        &crate::shader::MATH_WGSL,
        &crate::atmosphere::ATMOSPHERE_WGSL,
        &crate::shadow::SHADOW_MAP_WGSL
    ],
    environment_constants
);

/// The environment's constants as WGSL.
fn environment_constants() -> String {
    use crate::shader::WgslConst::{F32, U32};
    crate::shader::wgsl_consts([
        ("SUN_PIXEL_ROWS", U32(super::SUN_PIXEL_ROWS)),
        ("LIGHT_VOLUME_MAX_CASCADES", U32(MAX_CASCADES)),
        ("LIGHT_VOLUME_TABLE_PARTS", U32(TABLE_PARTS)),
        (
            "CASCADE_BLEND_CELLS",
            F32(super::light_volume::CASCADE_BLEND_CELLS),
        ),
    ])
}

impl crate::pass::SharedGroup for EnvironmentGpu {
    fn layout(&self) -> &wgpu::BindGroupLayout {
        EnvironmentGpu::layout(self)
    }

    fn bind_group(&self) -> &wgpu::BindGroup {
        EnvironmentGpu::bind_group(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::layout_check::assert_wgsl_layout;

    #[test]
    fn environment_uniform_matches_its_wgsl_layout() {
        assert_wgsl_layout!(
            &crate::probe::PROBE_WGSL,
            "Environment",
            EnvironmentUniform {
                sun_direction,
                sun_cos_angular_radius,
                sun_irradiance,
                haze_extinction_per_m,
                sky_zenith_radiance,
                sky_gradient_exponent,
                sky_horizon_radiance,
                sky_model,
                viewpoint_m,
                sun_limb_darkening,
                air,
                shadow,
                light_volume,
            }
        );
        assert_wgsl_layout!(
            &crate::probe::PROBE_WGSL,
            "LightVolume",
            LightVolumeUniform {
                cascade_min_m,
                cascade_cell_m,
                cells,
                cascades,
                optics,
                enabled,
                beam_steps,
                pad0,
                pad1,
            }
        );
        assert_wgsl_layout!(
            &crate::probe::PROBE_WGSL,
            "Air",
            AirUniform {
                rayleigh_scattering_per_m,
                bottom_radius_m,
                ozone_absorption_per_m,
                top_radius_m,
                ground_albedo,
                mie_scattering_per_m,
                mie_extinction_per_m,
                mie_g,
                sun_angular_radius_rad,
                flat_world,
            }
        );
        assert_wgsl_layout!(
            &crate::probe::PROBE_WGSL,
            "CloudShadow",
            CloudShadowUniform {
                centre_m,
                half_extent_m,
                warp,
                bottom_y_m,
                top_y_m,
                sun_y,
                enabled,
                steps_per_checkpoint,
                pad0,
                pad,
            }
        );
    }
}
