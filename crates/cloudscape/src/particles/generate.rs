//! Particle generation from the cloud field, on the CPU: the specification the GPU passes of
//! `particle_generate.wgsl` follow line for line (Yusov 2014, "Particle generation").
//!
//! Two steps, as the seed's two compute passes:
//! 1. [`list_cells`]: every column of the [`RingGrid`] reads the coarse field at its particles'
//!    positions and is listed, with the mask of its particles that hold cloud, when any does;
//! 2. [`generate_cell`]: every listed column makes its particles: size and density from the field,
//!    the optical depth toward the sun (light occlusion) and toward the sky and ground.
//!
//! Particles are made anew every frame from the field at the frame's time, so they follow the
//! wind and the coverage path: they grow and thicken as a cloud forms and shrink and thin as it
//! dissipates (Yusov: "clouds are animated by changing particle size and transparency").

use super::grid::{CELL_JITTER, Column, RingGrid, smoothstep};
use crate::environment::Environment;
use crate::field::noise::{hash_to_unit, pcg_hash};
use crate::field::{CloudField, GOLDEN_RATIO_CONJUGATE};
use crate::frame::Frame;
use crate::scene::{ParticleOcclusion, PlanetShape, Scene};
use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3};

/// A particle's radius relative to its cell. Yusov's sample uses 2.2 (size = cell x 2.2 x
/// lerp(0.5, 1, noise) x saturate(density / 0.02), the size being the radius; peers.md); with
/// the particles stacked where the column's cloud is ([`column_span`]) that blurs every edge, and
/// 1.2 measures closer to the path-traced field on every canonical layer scene
/// (`docs/particles.md`); 1.1, tried first, left the gaps between the particles visible.
pub const RADIUS_PER_CELL: f32 = 1.2;
/// Field density (relative to the layers' peak) at which a particle reaches its full size;
/// thinner cloud makes smaller particles.
pub const FULL_SIZE_DENSITY: f32 = 0.1;
/// Field density (relative to the peak) below which a particle position holds no particle.
pub const MIN_DENSITY: f32 = 0.01;
/// Segments of the march toward the sun (lengths doubling, as Schneider 2015's light samples).
pub const OCCLUSION_STEPS: u32 = 6;
/// Longest march toward the sun, m (as the ray marcher's: past it a shadow is complete).
pub const OCCLUSION_PATH_M: f32 = 4000.0;
/// Optical depth at which the march toward the sun stops: transmittance 0.01, the seed's
/// early-exit threshold.
pub const OCCLUSION_MAX_DEPTH: f32 = 4.605_17;

/// One particle: an ellipsoid of the reference particle, in the layout `particle_generate.wgsl`
/// writes and `particle_render.wgsl` reads.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Particle {
    /// Centre, world metres.
    pub centre_m: Vec3,
    /// Horizontal radius, m.
    pub radius_m: f32,
    /// Vertical radius, m.
    pub height_m: f32,
    /// Peak density relative to the reference particle's (extinction `density x sigma_max`),
    /// including the ring's fade weight.
    pub density: f32,
    /// Optical depth of the field toward the sun from the particle's edge (light occlusion).
    pub sun_optical_depth: f32,
    /// Stable identity (grid cell and layer): seeds its jitter, size and random rotation.
    pub id: u32,
    /// Optical depth of the field above it to the layer band's top.
    pub optical_depth_up: f32,
    /// Optical depth of the field below it to the layer band's floor.
    pub optical_depth_down: f32,
    /// Its ring.
    pub ring: u32,
    /// Padding.
    pub reserved: u32,
}

/// What generation needs besides the field: the grid, the frame's camera and sun, and the
/// reference particle's constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Generation {
    /// The cell grid.
    pub grid: RingGrid,
    /// Camera position, m.
    pub camera_m: Vec3,
    /// Unit vector toward the sun.
    pub sun_direction: Vec3,
    /// Scene time, s.
    pub time_s: f32,
    /// Extinction of density 1, m^-1 (the table's; the layers' peak).
    pub sigma_max_per_m: f32,
    /// Mean density of the reference particle over its ball ([`super::density::RadialProfile::volume_mean`]).
    pub particle_mean_density: f32,
    /// How the particles' sunlight is occluded: [`ParticleOcclusion::March`] marches the field
    /// in [`generate_cell`]; [`ParticleOcclusion::Tiles`] leaves it to [`super::occlusion`].
    pub occlusion: ParticleOcclusion,
    /// Whether the march or the walk toward the sun stops at [`OCCLUSION_MAX_DEPTH`].
    pub occlusion_early_exit: bool,
    /// The altitudes the particles lie between, m (the layer band, its floor lowered by the
    /// planet's curvature over the grid's reach); (0, 0) without layers.
    pub band_m: (f32, f32),
}

impl Generation {
    /// What `scene` asks for: its grid, camera, sun, time, early exit and the peak extinction of
    /// its particle tables, for a reference particle of mean density `particle_mean_density`
    /// (`ParticleTables::mean_density`, or [`super::density::RadialProfile::volume_mean`]).
    pub fn from_scene(scene: &Scene, particle_mean_density: f32) -> Generation {
        Generation {
            grid: RingGrid::from_scene(scene),
            camera_m: Vec3::from_array(scene.camera.position_m),
            sun_direction: Environment::from_scene(scene).sun.direction,
            time_s: scene.render.time_s,
            sigma_max_per_m: super::ParticleTableSpec::from_scene(scene).extinction_per_m,
            particle_mean_density,
            occlusion: scene.particles.occlusion,
            occlusion_early_exit: scene.particles.occlusion_early_exit,
            band_m: particle_band_m(scene),
        }
    }

    /// The same generation seen from `frame`: its camera, sun and time.
    pub fn for_frame(self, frame: &Frame) -> Generation {
        Generation {
            camera_m: frame.camera_position_m,
            sun_direction: frame.sun.direction,
            time_s: frame.time_s,
            ..self
        }
    }
}

/// The altitudes a scene's particles lie between (`Generation::band_m`).
fn particle_band_m(scene: &Scene) -> (f32, f32) {
    let layers = &scene.layers;
    let Some(bottom) = layers.iter().map(|l| l.bottom_m).reduce(f32::min) else {
        return (0.0, 0.0);
    };
    let top = layers
        .iter()
        .map(|l| l.bottom_m + l.thickness_m)
        .fold(bottom, f32::max);
    let reach_m = RingGrid::from_scene(scene).reach_m();
    let drop_m = match scene.planet.shape {
        PlanetShape::Flat => 0.0,
        PlanetShape::Spherical => reach_m * reach_m / (2.0 * scene.planet.radius_m),
    };
    (bottom - drop_m, top)
}

/// A listed column, the mask of its layers that hold cloud, and the altitudes they span.
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct ListedCell {
    /// Column index in the grid.
    pub column: u32,
    /// Bit `l` set when layer `l` holds a particle.
    pub layers: u32,
    /// Where the column's cloud lies ([`column_span`]): its bottom and top altitudes, m.
    pub span_m: [f32; 2],
}

/// Altitudes at which [`column_span`] reads the coarse field across the layer band.
pub const SPAN_SAMPLES: u32 = 16;

/// Where a column's cloud lies: the altitudes its particles are spread over, so that a deck
/// thinner than the layer band (a stratus 100 m thick at the bottom of a 400 m band) gets its
/// particles inside it rather than in the empty air around it. From [`SPAN_SAMPLES`] coarse-field
/// samples at the column's centre, the density-weighted mean altitude `mu` and deviation `s`:
/// `mu -/+ (sqrt(3) s + half a sample step)` (a uniform layer's half-thickness is `sqrt(3) s`),
/// within the band; the whole band where the centre is clear. It moves continuously with the
/// field, so particles drift with the cloud rather than jump between sample heights.
pub fn column_span(field: &CloudField, g: &Generation, column: &Column) -> (f32, f32) {
    let (bottom, top, _) = band(field, &g.grid).expect("a band where there are cells");
    let step = (top - bottom) / SPAN_SAMPLES as f32;
    let (mut weight, mut first, mut second) = (0.0, 0.0, 0.0);
    for k in 0..SPAN_SAMPLES {
        let altitude = bottom + (k as f32 + 0.5) * step;
        let d =
            field.coarse_extinction_per_m(world_point(field, column.centre_m, altitude), g.time_s);
        let x = altitude - bottom;
        weight += d;
        first += d * x;
        second += d * x * x;
    }
    if weight <= 0.0 {
        return (bottom, top);
    }
    let mean = first / weight;
    let deviation = (second / weight - mean * mean).max(0.0).sqrt();
    let half = 3f32.sqrt() * deviation + 0.5 * step;
    (
        (bottom + mean - half).max(bottom),
        (bottom + mean + half).min(top),
    )
}

/// A column's particle layers over its span: bottom and top altitudes, m; `fill`, the layers the
/// band's spacing puts in that height (1..=cell_layers, fractional), and their spacing, m. The
/// layers are `ceil(fill)`, the last one weighted by the fraction it holds, so that a column's
/// particles move and fade continuously as its span changes (no popping), and the column's mass
/// is its cloud's whatever the fraction.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Span {
    bottom_m: f32,
    top_m: f32,
    fill: f32,
    spacing_m: f32,
}

impl Span {
    fn new(field: &CloudField, g: &Generation, (bottom_m, top_m): (f32, f32)) -> Span {
        let (_, _, band_spacing) = band(field, &g.grid).expect("a band where there are cells");
        let height = top_m - bottom_m;
        let fill = (height / band_spacing).clamp(1.0, g.grid.cell_layers as f32);
        Span {
            bottom_m,
            top_m,
            fill,
            spacing_m: height / fill,
        }
    }

    /// Its layers.
    fn layers(&self) -> u32 {
        self.fill.ceil() as u32
    }

    /// The weight of `layer`: 1, the last one its fraction.
    fn layer_weight(&self, layer: u32) -> f32 {
        (self.fill - layer as f32).min(1.0)
    }
}

/// The stable identity of the particle in `layer` of a ring's lattice cell.
pub fn particle_id(ring: u32, lattice: glam::IVec2, layer: u32) -> u32 {
    pcg_hash(ring ^ pcg_hash(lattice.x as u32 ^ pcg_hash(lattice.y as u32 ^ pcg_hash(layer))))
}

/// `n` uniform numbers in [0, 1) from a particle's id, each hash chained on the last.
fn id_randoms<const N: usize>(id: u32) -> [f32; N] {
    let mut h = id;
    std::array::from_fn(|_| {
        h = pcg_hash(h);
        hash_to_unit(h)
    })
}

/// The world point at altitude `altitude_m` over the tangent-plane position `xz` (x, z): on a
/// spherical planet (centre `(0, -R, 0)`) along the normal through `(x, 0, z)` projected outward.
pub fn world_point(field: &CloudField, xz: Vec2, altitude_m: f32) -> Vec3 {
    match field.planet.shape {
        PlanetShape::Flat => Vec3::new(xz.x, altitude_m, xz.y),
        PlanetShape::Spherical => {
            let r = field.planet.radius_m;
            let up = Vec3::new(xz.x, r, xz.y).normalize();
            Vec3::new(0.0, -r, 0.0) + up * (r + altitude_m)
        }
    }
}

/// The layer band (floor, height of one particle layer), or None without layers.
fn band(field: &CloudField, grid: &RingGrid) -> Option<(f32, f32, f32)> {
    let (bottom, top) = field.altitude_range_m()?;
    Some((bottom, top, (top - bottom) / grid.cell_layers as f32))
}

/// Where particle `layer` of `column` sits in its span, and its id.
fn particle_position(field: &CloudField, column: &Column, span: &Span, layer: u32) -> (Vec3, u32) {
    let id = particle_id(column.ring, column.lattice, layer);
    let [jx, jz, jy] = id_randoms::<3>(id).map(|u| (2.0 * u - 1.0) * CELL_JITTER);
    let xz = column.centre_m + Vec2::new(jx, jz) * column.cell_m;
    let altitude = span.bottom_m + (layer as f32 + 0.5 + jy) * span.spacing_m;
    (
        world_point(field, xz, altitude.clamp(span.bottom_m, span.top_m)),
        id,
    )
}

/// The ring weight and relative field density of a particle position.
fn weighted_density(field: &CloudField, g: &Generation, ring: u32, p: Vec3) -> (f32, f32) {
    let camera = Vec2::new(g.camera_m.x, g.camera_m.z);
    let weight = g.grid.weight(ring, Vec2::new(p.x, p.z), camera);
    let density = field.coarse_extinction_per_m(p, g.time_s) / g.sigma_max_per_m;
    (weight, density)
}

/// Step 1 for column `index`: the cell and its mask of layers holding cloud, or None.
pub fn list_cell(field: &CloudField, g: &Generation, index: u32) -> Option<ListedCell> {
    band(field, &g.grid)?;
    let column = g
        .grid
        .column(index, Vec2::new(g.camera_m.x, g.camera_m.z))?;
    let span_m = column_span(field, g, &column);
    let span = Span::new(field, g, span_m);
    let layers = (0..span.layers()).fold(0, |mask, layer| {
        let (p, _) = particle_position(field, &column, &span, layer);
        let (weight, density) = weighted_density(field, g, column.ring, p);
        mask | (u32::from(weight > 0.0 && density > MIN_DENSITY) << layer)
    });
    (layers != 0).then_some(ListedCell {
        column: index,
        layers,
        span_m: [span_m.0, span_m.1],
    })
}

/// Step 1 over the whole grid.
pub fn list_cells(field: &CloudField, g: &Generation) -> Vec<ListedCell> {
    use rayon::prelude::*;
    (0..g.grid.column_count())
        .into_par_iter()
        .filter_map(|i| list_cell(field, g, i))
        .collect()
}

/// Step 2 for one listed cell: its particles.
pub fn generate_cell(field: &CloudField, g: &Generation, cell: ListedCell) -> Vec<Particle> {
    let camera = Vec2::new(g.camera_m.x, g.camera_m.z);
    let column = g.grid.column(cell.column, camera).expect("a listed column");
    let (bottom, top, _) = band(field, &g.grid).expect("a band where there are cells");
    let span = Span::new(field, g, (cell.span_m[0], cell.span_m[1]));
    let spacing = span.spacing_m;
    (0..span.layers())
        .filter(|layer| cell.layers & (1 << layer) != 0)
        .map(|layer| {
            let (p, id) = particle_position(field, &column, &span, layer);
            let (weight, density) = weighted_density(field, g, column.ring, p);
            let [_, _, _, size_noise, march_jitter] = id_randoms::<5>(id);
            let full_scale = 0.5 + 0.5 * size_noise;
            let grown = smoothstep(0.0, 1.0, density / FULL_SIZE_DENSITY).max(0.25);
            let size = |scale: f32| {
                let radius_m = column.cell_m * RADIUS_PER_CELL * scale;
                let height_m = radius_m.max(0.75 * spacing * scale);
                (radius_m, height_m.min(0.5 * (span.top_m - span.bottom_m)))
            };
            let (radius_m, height_m) = size(full_scale * grown);
            let altitude = field.planet.altitude_m(p);
            let up = field_up(field, p);
            let ambient = |length_m: f32, dir: Vec3| {
                let length_m = length_m.max(0.0);
                field.coarse_extinction_per_m(p + dir * (0.5 * length_m), g.time_s) * length_m
            };
            // Mass-conserving density: a grown particle carries its cell's share of the field's
            // mass; in thin cloud it shrinks at that density (so it forms and dissipates by size).
            let cell_volume = column.cell_m * column.cell_m * spacing;
            let (full_radius_m, full_height_m) = size(full_scale);
            let ball = 4.0 / 3.0 * std::f32::consts::PI * full_radius_m.powi(2) * full_height_m;
            let mass_scale = cell_volume / (ball * g.particle_mean_density);
            Particle {
                centre_m: p,
                radius_m,
                height_m,
                density: density * weight * span.layer_weight(layer) * mass_scale,
                sun_optical_depth: match g.occlusion {
                    ParticleOcclusion::March => {
                        sun_optical_depth(field, g, (p, radius_m), march_jitter).0
                    }
                    ParticleOcclusion::Tiles => 0.0,
                },
                id,
                optical_depth_up: ambient(top - altitude, up),
                optical_depth_down: ambient(altitude - bottom, -up),
                ring: column.ring,
                reserved: 0,
            }
        })
        .collect()
}

/// The planet normal at `p` (field_up in `field.wgsl`).
fn field_up(field: &CloudField, p: Vec3) -> Vec3 {
    match field.planet.shape {
        PlanetShape::Flat => Vec3::Y,
        PlanetShape::Spherical => Vec3::new(p.x, p.y + field.planet.radius_m, p.z).normalize(),
    }
}

/// Light occlusion: the coarse field's optical depth toward the sun from a particle at `p` of
/// radius `radius_m`, from its edge to the top of the layer band (at most [`OCCLUSION_PATH_M`]),
/// in [`OCCLUSION_STEPS`] segments whose lengths double, each sampled at a point offset by
/// `jitter` and decorrelated by the golden ratio (as `CloudField::coarse_optical_depth`); and
/// the segments marched, which the early exit shortens (Yusov's released code marches a coarse
/// density grid toward the sun the same way).
pub fn sun_optical_depth(
    field: &CloudField,
    g: &Generation,
    (p, radius_m): (Vec3, f32),
    jitter: f32,
) -> (f32, u32) {
    let Some((_, top)) = field.altitude_range_m() else {
        return (0.0, 0);
    };
    let sun = g.sun_direction;
    // `field_below(p, sun, top).y`: where the path leaves the layers' top (0 if never below it).
    let to_top = field
        .planet
        .below(p, sun, top)
        .map_or(0.0, |(_, t1)| t1 as f32);
    let length_m = (to_top.min(OCCLUSION_PATH_M) - radius_m).max(0.0);
    let total = ((1u32 << OCCLUSION_STEPS) - 1) as f32;
    let (mut width, mut start, mut tau) = (length_m / total, radius_m, 0.0);
    for k in 0..OCCLUSION_STEPS {
        if g.occlusion_early_exit && tau > OCCLUSION_MAX_DEPTH {
            return (tau, k);
        }
        let offset = (jitter + (k + 1) as f32 * GOLDEN_RATIO_CONJUGATE).fract();
        let q = p + sun * (start + width * offset);
        tau += field.coarse_extinction_per_m(q, g.time_s) * width;
        start += width;
        width *= 2.0;
    }
    (tau, OCCLUSION_STEPS)
}

/// Both steps over the whole grid: every particle around the camera, in no particular order.
pub fn generate(field: &CloudField, g: &Generation) -> Vec<Particle> {
    use rayon::prelude::*;
    list_cells(field, g)
        .into_par_iter()
        .flat_map_iter(|cell| generate_cell(field, g, cell))
        .collect()
}
