// The seed's light occlusion (particles/occlusion.rs is its specification): the particles binned
// from the sun into light-space tiles, one level per ring (`bin_light_tiles`, one invocation per
// particle, listed in the tile of its centre), each tile's list sorted nearest the sun first
// (`sort_light_tiles`, a workgroup per tile that lists any, particle_tiles.wgsl), then each particle walking
// the lists of the 3x3 tiles around its ray on its own level and the levels next to it, up to its
// own place (`walk_light_tiles`), summing the occluders' optical depth until the light left is
// below 1 %.

struct LightGrid {
    origin_m: vec3<f32>,
    tile_m: f32,           // tile side on the first level; twice as wide on each next
    right: vec3<f32>,
    depth_range_m: f32,    // distance from the light plane the keys quantise, first level
    up: vec3<f32>,
    sigma_max_per_m: f32,  // extinction of density 1
    sun: vec3<f32>,
    tiles_per_side: u32,
    levels: u32,
    tile_capacity: u32,
    max_particles: u32,
    early_exit: u32,       // 1: a walk stops past OCCLUSION_MAX_DEPTH
}

@group(3) @binding(0) var<uniform> light_grid: LightGrid;
@group(3) @binding(1) var<storage, read_write> particles: array<Particle>;
// particle_generate.wgsl's counts: [1] particles made, [2] occlusion steps (entries walked).
@group(3) @binding(2) var<storage, read_write> counts: array<atomic<u32>, 4>;
// The optical-depth table that particle_lookup.wgsl reads (chord_mass reads the profile only).
@group(3) @binding(3) var optical_depth_lut: texture_3d<f32>;
@group(3) @binding(4) var optical_depth_sampler: sampler;
@group(3) @binding(5) var<storage, read> chord_mean_density: array<f32>;
@group(3) @binding(8) var<storage, read_write> tile_counts: array<atomic<u32>>;
// Per tile, `tile_capacity` sort keys: quantised distance from the sun << 20 | particle index.
@group(3) @binding(9) var<storage, read_write> tile_entries: array<u32>;
// [0] entries beyond a full tile's capacity, [1] particles outside their level.
@group(3) @binding(10) var<storage, read_write> light_stats: array<atomic<u32>, 2>;
// The tiles that list a particle: [0] how many, then their indices (bin_light_tiles appends a
// tile when its first particle arrives), so that the sort visits those alone: most tiles of a
// level stay empty, and a workgroup per tile of the grid costs more than the sorts themselves
// where workgroups are expensive to start (llvmpipe's OpenGL: 17 s a frame for the default scene).
@group(3) @binding(11) var<storage, read_write> listed_tiles: array<atomic<u32>>;

const KEY_INDEX_BITS: u32 = 20u;
const KEY_INDEX_MASK: u32 = 0xfffffu;
const KEY_DEPTH_LEVELS: f32 = 4095.0;
const COUNT_OCCLUSION_STEPS: u32 = 2u;

fn light_scale(level: u32) -> f32 {
    return f32(1u << level);
}

// LightTiles::tile_of.
fn light_tile_of(p: vec3<f32>, level: u32) -> vec2<i32> {
    let d = p - light_grid.origin_m;
    let at = vec2<f32>(dot(d, light_grid.right), dot(d, light_grid.up)) / (light_grid.tile_m * light_scale(level));
    return vec2<i32>(floor(at + 0.5 * f32(light_grid.tiles_per_side)));
}

// LightTiles::tile_index; -1 outside the level.
fn light_tile_index(tile: vec2<i32>, level: u32) -> i32 {
    let n = i32(light_grid.tiles_per_side);
    if level >= light_grid.levels || any(tile < vec2<i32>(0)) || any(tile >= vec2<i32>(n)) {
        return -1;
    }
    return (i32(level) * n + tile.y) * n + tile.x;
}

// LightTiles::from_sun.
fn light_from_sun(p: vec3<f32>) -> f32 {
    return -dot(p - light_grid.origin_m, light_grid.sun);
}

// LightTiles::depth_level.
fn light_depth_level(p: vec3<f32>, level: u32) -> u32 {
    let range = light_grid.depth_range_m * light_scale(level);
    return u32(clamp((light_from_sun(p) / range + 1.0) * 0.5, 0.0, 1.0) * KEY_DEPTH_LEVELS);
}

// LightTiles::key.
fn light_key(p: vec3<f32>, index: u32, level: u32) -> u32 {
    return (light_depth_level(p, level) << KEY_INDEX_BITS) | index;
}

fn particles_made() -> u32 {
    return min(atomicLoad(&counts[1]), light_grid.max_particles);
}

@compute @workgroup_size(64)
fn bin_light_tiles(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= particles_made() || particles[id.x].density <= 0.0 {
        return;
    }
    let p = particles[id.x];
    let tile = light_tile_index(light_tile_of(p.centre_m, p.ring), p.ring);
    if tile < 0 {
        atomicAdd(&light_stats[1], 1u);
        return;
    }
    let slot = atomicAdd(&tile_counts[tile], 1u);
    if slot == 0u {
        let k = atomicAdd(&listed_tiles[0], 1u);
        atomicStore(&listed_tiles[k + 1u], u32(tile));
    }
    if slot < light_grid.tile_capacity {
        tile_entries[u32(tile) * light_grid.tile_capacity + slot] = light_key(p.centre_m, id.x, p.ring);
    } else {
        atomicAdd(&light_stats[0], 1u);
    }
}

var<workgroup> sort_listed: u32;

// Sorts each listed tile's list in place, leaving in tile_counts the entries kept: workgroup g of
// LIGHT_SORT_WORKGROUPS sorts listed tiles g, g + LIGHT_SORT_WORKGROUPS, ...
@compute @workgroup_size(256)
fn sort_light_tiles(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    if lane == 0u {
        sort_listed = atomicLoad(&listed_tiles[0]);
    }
    let listed = workgroupUniformLoad(&sort_listed);
    for (var k = group.x; k < listed; k += LIGHT_SORT_WORKGROUPS) {
        let tile = atomicLoad(&listed_tiles[k + 1u]);
        let n = load_sorted_tile(tile, light_grid.tile_capacity, lane);
        for (var i = lane; i < n; i += TILE_LANES) {
            tile_entries[tile * light_grid.tile_capacity + i] = tile_keys[i];
        }
        if lane == 0u {
            atomicStore(&tile_counts[tile], n);
        }
        // The next tile's keys overwrite these.
        workgroupBarrier();
    }
}

// occluder_optical_depth: particle j's optical depth along the ray from `origin_m` toward the sun,
// past `start_m` (reading only the fields the walk does not write).
fn occluder_optical_depth(j: u32, origin_m: vec3<f32>, start_m: f32) -> f32 {
    let radii = vec3<f32>(particles[j].radius_m, particles[j].height_m, particles[j].radius_m);
    let lo = (origin_m - particles[j].centre_m) / radii;
    let ld = light_grid.sun / radii;
    let scale = length(ld);
    let dir = ld / scale;
    let b = dot(lo, dir);
    let disc = b * b - (dot(lo, lo) - 1.0);
    if disc <= 0.0 {
        return 0.0;
    }
    let s = sqrt(disc);
    let t0 = -b - s;
    let t1 = -b + s;
    let start = start_m * scale;
    if t1 <= start {
        return 0.0;
    }
    let entry = normalize(lo + t0 * dir);
    let kept = (t1 - max(t0, start)) / (t1 - t0);
    return light_grid.sigma_max_per_m * particles[j].density * chord_mass(entry, dir) / scale * kept;
}

// The walk so far: optical depth and entries walked.
struct LightWalk {
    tau: f32,
    walked: u32,
}

fn light_walk_done(w: LightWalk) -> bool {
    return light_grid.early_exit == 1u && w.tau > OCCLUSION_MAX_DEPTH;
}

// The walking particle: its centre, where its ray leaves it, its distance from the sun and the
// quantised level of that distance on the level walked.
struct Walker {
    centre_m: vec3<f32>,
    start_m: f32,
    from_sun_m: f32,
    depth_level: u32,
}

// occlusion::walk_list: walks one tile's sorted list up to the walker's place.
fn walk_list(w_in: LightWalk, tile: i32, me: Walker) -> LightWalk {
    var w = w_in;
    let first = u32(tile) * light_grid.tile_capacity;
    let n = atomicLoad(&tile_counts[tile]);
    for (var i = 0u; i < n; i++) {
        let key = tile_entries[first + i];
        let depth_level = key >> KEY_INDEX_BITS;
        if depth_level > me.depth_level || light_walk_done(w) {
            break;
        }
        let j = key & KEY_INDEX_MASK;
        if depth_level == me.depth_level && light_from_sun(particles[j].centre_m) >= me.from_sun_m {
            continue;
        }
        w.tau += occluder_optical_depth(j, me.centre_m, me.start_m);
        w.walked += 1u;
    }
    return w;
}

// occlusion::walk_to_sun.
@compute @workgroup_size(64)
fn walk_light_tiles(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= particles_made() {
        return;
    }
    let centre_m = particles[id.x].centre_m;
    let ring = particles[id.x].ring;
    // own_extent_toward: the walk starts at the particle's edge.
    let own_radii = vec3<f32>(particles[id.x].radius_m, particles[id.x].height_m, particles[id.x].radius_m);
    var me = Walker(centre_m, 1.0 / length(light_grid.sun / own_radii), light_from_sun(centre_m), 0u);
    var w = LightWalk(0.0, 0u);
    let last = min(ring + 1u, light_grid.levels - 1u);
    for (var level = max(ring, 1u) - 1u; level <= last; level++) {
        me.depth_level = light_depth_level(centre_m, level);
        let centre = light_tile_of(centre_m, level);
        for (var k = 0; k < 9; k++) {
            let tile = light_tile_index(centre + vec2<i32>(k % 3 - 1, k / 3 - 1), level);
            if tile >= 0 {
                w = walk_list(w, tile, me);
            }
        }
    }
    particles[id.x].sun_optical_depth = w.tau;
    atomicAdd(&counts[COUNT_OCCLUSION_STEPS], w.walked);
}
