// Particle generation on the GPU: the twin of particles/grid.rs and particles/generate.rs, line for
// line (see there for the sources). Three entry points, dispatched in order each frame:
// `list_cells` (one invocation per grid column: the seed's append buffer of non-empty cells),
// `size_dispatches` (one invocation: the indirect dispatch sizes), then `generate_particles`
// (indirect, one invocation per listed cell).

// The camera is the frame's (frame.wgsl), the sun the environment's (environment.wgsl).
struct Generation {
    sigma_max_per_m: f32,          // extinction of density 1
    particle_mean_density: f32,    // RadialProfile::volume_mean
    reserved0: vec2<u32>,
    rings: u32,
    ring_cells: u32,
    cell_layers: u32,
    inner_cell_m: f32,
    column_count: u32,
    max_particles: u32,            // capacity of `particles`
    occlusion_early_exit: u32,     // 1: stop the march toward the sun at OCCLUSION_MAX_DEPTH
    occlusion_march: u32,          // 1: march the field toward the sun; 0: the light tiles will
}

struct ListedCell {
    column: u32,
    layers: u32,       // bit l: layer l holds a particle
    span_m: vec2<f32>, // column_span: the altitudes the column's particles spread over
}

// Span: a column's particle layers over its span (ceil(fill) layers, the last one weighted by
// its fraction).
struct Span {
    bottom_m: f32,
    top_m: f32,
    fill: f32,
    spacing_m: f32,
}

// [0] listed cells, [1] particles, [2] occlusion segments marched, [3] particles beyond capacity.
const COUNT_CELLS: u32 = 0u;
const COUNT_PARTICLES: u32 = 1u;
const COUNT_OCCLUSION_STEPS: u32 = 2u;
const COUNT_DROPPED: u32 = 3u;

@group(3) @binding(0) var<uniform> generation: Generation;
@group(3) @binding(1) var<storage, read_write> listed_cells: array<ListedCell>;
@group(3) @binding(2) var<storage, read_write> counts: array<atomic<u32>, 4>;
// Workgroup counts: [0..3] generate_particles over the cells, [3..6] any pass over the particles.
@group(3) @binding(3) var<storage, read_write> dispatches: array<u32, 6>;
@group(3) @binding(4) var<storage, read_write> particles: array<Particle>;

// CELL_JITTER, RADIUS_PER_CELL, FULL_SIZE_DENSITY, MIN_DENSITY, OCCLUSION_STEPS, OCCLUSION_PATH_M,
// OCCLUSION_MAX_DEPTH, SPAN_SAMPLES and GENERATE_WORKGROUP come from generate.rs, grid.rs and generate_gpu.rs.

struct Column {
    ring: u32,
    lattice: vec2<i32>,
    centre_m: vec2<f32>,
    cell_m: f32,
    valid: bool,
}

fn grid_cell_m(ring: u32) -> f32 {
    return generation.inner_cell_m * f32(1u << ring);
}

fn grid_hole_half_cells() -> f32 {
    return (f32(generation.ring_cells) / 2.0 - 4.0) / 2.0;
}

fn grid_fade_band_cells() -> vec2<f32> {
    return vec2<f32>(2.0 * (grid_hole_half_cells() + CELL_JITTER), f32(generation.ring_cells) / 2.0 - 1.0 - CELL_JITTER);
}

// RingGrid::column.
fn grid_column(index: u32) -> Column {
    let n = generation.ring_cells;
    let ring = index / (n * n);
    let half = i32(n / 2u);
    let offset = vec2<i32>(i32(index % n) - half, i32((index / n) % n) - half);
    var column: Column;
    column.valid = true;
    if ring > 0u {
        let hole = i32(grid_hole_half_cells());
        if offset.x >= -hole && offset.x < hole && offset.y >= -hole && offset.y < hole {
            column.valid = false;
        }
    }
    let cell_m = grid_cell_m(ring);
    let snapped = vec2<i32>(floor(frame.camera_position_m.xz / cell_m + 0.5));
    column.ring = ring;
    column.lattice = snapped + offset;
    column.centre_m = (vec2<f32>(column.lattice) + 0.5) * cell_m;
    column.cell_m = cell_m;
    return column;
}

// RingGrid::weight.
fn grid_weight(ring: u32, position_m: vec2<f32>) -> f32 {
    let band = grid_fade_band_cells();
    let offset = abs(position_m - frame.camera_position_m.xz);
    let d = max(offset.x, offset.y) / grid_cell_m(ring);
    var weight = 1.0;
    if ring > 0u {
        weight *= smoothstep(band.x / 2.0, band.y / 2.0, d);
    }
    if ring + 1u < generation.rings {
        weight *= 1.0 - smoothstep(band.x, band.y, d);
    } else {
        weight *= 1.0 - smoothstep(0.8 * band.y, band.y, d);
    }
    return weight;
}

// particle_id.
fn particle_id(ring: u32, lattice: vec2<i32>, layer: u32) -> u32 {
    return noise_pcg_hash(ring ^ noise_pcg_hash(u32(lattice.x) ^ noise_pcg_hash(u32(lattice.y) ^ noise_pcg_hash(layer))));
}

// The k-th (from 1) of id_randoms.
fn id_random(id: u32, k: u32) -> f32 {
    var h = id;
    for (var i = 0u; i < k; i++) {
        h = noise_pcg_hash(h);
    }
    return noise_hash_to_unit(h);
}

// world_point.
fn world_point(xz: vec2<f32>, altitude_m: f32) -> vec3<f32> {
    if field.flat_planet == 1u {
        return vec3<f32>(xz.x, altitude_m, xz.y);
    }
    let r = field.planet_radius_m;
    let up = normalize(vec3<f32>(xz.x, r, xz.y));
    return vec3<f32>(0.0, -r, 0.0) + up * (r + altitude_m);
}

fn band_spacing() -> f32 {
    return (field.layer_top_m - field.layer_bottom_m) / f32(generation.cell_layers);
}

// column_span.
fn column_span(column: Column) -> vec2<f32> {
    let bottom = field.layer_bottom_m;
    let top = field.layer_top_m;
    let step = (top - bottom) / f32(SPAN_SAMPLES);
    var weight = 0.0;
    var first = 0.0;
    var second = 0.0;
    for (var k = 0u; k < SPAN_SAMPLES; k++) {
        let altitude = bottom + (f32(k) + 0.5) * step;
        let d = field_extinction_coarse(world_point(column.centre_m, altitude));
        let x = altitude - bottom;
        weight += d;
        first += d * x;
        second += d * x * x;
    }
    if weight <= 0.0 {
        return vec2<f32>(bottom, top);
    }
    let mean = first / weight;
    let deviation = sqrt(max(second / weight - mean * mean, 0.0));
    let half = sqrt(3.0) * deviation + 0.5 * step;
    return vec2<f32>(max(bottom + mean - half, bottom), min(bottom + mean + half, top));
}

// Span::new.
fn column_layers(span_m: vec2<f32>) -> Span {
    let height = span_m.y - span_m.x;
    let fill = clamp(height / band_spacing(), 1.0, f32(generation.cell_layers));
    return Span(span_m.x, span_m.y, fill, height / fill);
}

// Span::layers.
fn span_layers(span: Span) -> u32 {
    return u32(ceil(span.fill));
}

// particle_position: the point, and the id in w (as bits).
fn particle_position(column: Column, span: Span, layer: u32) -> vec4<f32> {
    let id = particle_id(column.ring, column.lattice, layer);
    let jitter = (2.0 * vec3<f32>(id_random(id, 1u), id_random(id, 2u), id_random(id, 3u)) - 1.0) * CELL_JITTER;
    let xz = column.centre_m + jitter.xy * column.cell_m;
    let altitude = clamp(span.bottom_m + (f32(layer) + 0.5 + jitter.z) * span.spacing_m, span.bottom_m, span.top_m);
    return vec4<f32>(world_point(xz, altitude), bitcast<f32>(id));
}

// weighted_density: (weight, relative density).
fn weighted_density(ring: u32, p: vec3<f32>) -> vec2<f32> {
    let weight = grid_weight(ring, p.xz);
    return vec2<f32>(weight, field_extinction_coarse(p) / generation.sigma_max_per_m);
}

@compute @workgroup_size(GENERATE_WORKGROUP)
fn list_cells(@builtin(global_invocation_id) id: vec3<u32>) {
    let index = id.x;
    if index >= generation.column_count || field.layer_count == 0u {
        return;
    }
    let column = grid_column(index);
    if !column.valid {
        return;
    }
    let span_m = column_span(column);
    let span = column_layers(span_m);
    var layers = 0u;
    for (var layer = 0u; layer < span_layers(span); layer++) {
        let p = particle_position(column, span, layer).xyz;
        let wd = weighted_density(column.ring, p);
        layers |= select(0u, 1u, wd.x > 0.0 && wd.y > MIN_DENSITY) << layer;
    }
    if layers != 0u {
        let slot = atomicAdd(&counts[COUNT_CELLS], 1u);
        listed_cells[slot] = ListedCell(index, layers, span_m);
    }
}

@compute @workgroup_size(1)
fn size_dispatches() {
    let cells = atomicLoad(&counts[COUNT_CELLS]);
    dispatches[0] = (cells + GENERATE_WORKGROUP - 1u) / GENERATE_WORKGROUP;
    dispatches[1] = 1u;
    dispatches[2] = 1u;
    dispatches[3] = 0u; // sized by size_particle_dispatch after generation
    dispatches[4] = 1u;
    dispatches[5] = 1u;
}

@compute @workgroup_size(1)
fn size_particle_dispatch() {
    let particles_made = min(atomicLoad(&counts[COUNT_PARTICLES]), generation.max_particles);
    dispatches[3] = (particles_made + GENERATE_WORKGROUP - 1u) / GENERATE_WORKGROUP;
}

// distance_below: along `dir` from p to altitude h.
fn distance_below(p: vec3<f32>, dir: vec3<f32>, h: f32) -> f32 {
    if field.flat_planet == 1u {
        return select(3.4e38, (h - p.y) / dir.y, dir.y > 1e-8);
    }
    return max(field_below(p, dir, h).y, 0.0);
}

// sun_optical_depth: the optical depth and the segments marched.
fn sun_optical_depth(p: vec3<f32>, radius_m: f32, jitter: f32) -> vec2<f32> {
    let sun = environment_sun_direction();
    let to_top = distance_below(p, sun, field.layer_top_m);
    let length_m = max(min(to_top, OCCLUSION_PATH_M) - radius_m, 0.0);
    let total = f32((1u << OCCLUSION_STEPS) - 1u);
    var width = length_m / total;
    var start = radius_m;
    var tau = 0.0;
    for (var k = 0u; k < OCCLUSION_STEPS; k++) {
        if generation.occlusion_early_exit == 1u && tau > OCCLUSION_MAX_DEPTH {
            return vec2<f32>(tau, f32(k));
        }
        let offset = fract(jitter + f32(k + 1u) * GOLDEN_RATIO_CONJUGATE);
        tau += field_extinction_coarse(p + sun * (start + width * offset)) * width;
        start += width;
        width *= 2.0;
    }
    return vec2<f32>(tau, f32(OCCLUSION_STEPS));
}

// The optical depth of the field over `length_m` from p along dir, from one sample halfway.
fn ambient_optical_depth(p: vec3<f32>, length_m: f32, dir: vec3<f32>) -> f32 {
    let l = max(length_m, 0.0);
    return field_extinction_coarse(p + dir * (0.5 * l)) * l;
}

// (radius, height) of a particle of `scale` (generate_cell's `size`).
fn particle_size(cell_m: f32, spacing: f32, thickness: f32, scale: f32) -> vec2<f32> {
    let radius_m = cell_m * RADIUS_PER_CELL * scale;
    return vec2<f32>(radius_m, min(max(radius_m, 0.75 * spacing * scale), 0.5 * thickness));
}

// generate_cell.
@compute @workgroup_size(GENERATE_WORKGROUP)
fn generate_particles(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= atomicLoad(&counts[COUNT_CELLS]) {
        return;
    }
    let cell = listed_cells[id.x];
    let column = grid_column(cell.column);
    let span = column_layers(cell.span_m);
    let spacing = span.spacing_m;
    let thickness = span.top_m - span.bottom_m;
    for (var layer = 0u; layer < span_layers(span); layer++) {
        if (cell.layers & (1u << layer)) == 0u {
            continue;
        }
        let at = particle_position(column, span, layer);
        let p = at.xyz;
        let pid = bitcast<u32>(at.w);
        let wd = weighted_density(column.ring, p);
        let full_scale = 0.5 + 0.5 * id_random(pid, 4u);
        let grown = max(smoothstep(0.0, 1.0, wd.y / FULL_SIZE_DENSITY), 0.25);
        let size = particle_size(column.cell_m, spacing, thickness, full_scale * grown);
        let full = particle_size(column.cell_m, spacing, thickness, full_scale);
        let radius_m = size.x;
        let height_m = size.y;
        let altitude = field_altitude_m(p);
        let up = field_up(p);
        let cell_volume = column.cell_m * column.cell_m * spacing;
        let ball = 4.0 / 3.0 * PI * full.x * full.x * full.y;
        let mass_scale = cell_volume / (ball * generation.particle_mean_density);
        var sun = vec2<f32>(0.0);
        if generation.occlusion_march == 1u {
            sun = sun_optical_depth(p, radius_m, id_random(pid, 5u));
        }
        atomicAdd(&counts[COUNT_OCCLUSION_STEPS], u32(sun.y));
        let slot = atomicAdd(&counts[COUNT_PARTICLES], 1u);
        if slot >= generation.max_particles {
            atomicAdd(&counts[COUNT_DROPPED], 1u);
            continue;
        }
        particles[slot] = Particle(
            p,
            radius_m,
            height_m,
            wd.y * wd.x * min(span.fill - f32(layer), 1.0) * mass_scale,
            sun.x,
            pid,
            ambient_optical_depth(p, field.layer_top_m - altitude, up),
            ambient_optical_depth(p, altitude - field.layer_bottom_m, -up),
            column.ring,
            0u,
        );
    }
}
