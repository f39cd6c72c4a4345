// The cloud field on the GPU: the twin of field/mod.rs and field/layer.rs, line for line.
// Everything it binds lives in bind group 0; techniques put their own resources in group 1+.

struct FieldLayer {
    bottom_m: f32,
    thickness_m: f32,
    coverage: f32,                // fraction of the sky covered, calibrated
    extinction_per_m: f32,        // where the density is 1
    wind_m_per_s: vec2<f32>,      // east, south
    weather_offset: vec2<f32>,    // this layer's offset into the weather map (uv)
    noise_offset_m: vec3<f32>,    // this layer's offset into the noise
    type_first: f32,              // type coordinate where the weather type channel is 0
    type_bounds: vec4<f32>,       // channel values where the next type begins (3 used)
    type_steps: vec4<f32>,        // type-coordinate change at each bound (3 used)
}

struct FieldVolume {
    min_m: vec3<f32>,             // box minimum corner
    extinction_per_m: f32,        // where the grid value is 1
    size_m: vec3<f32>,            // box size
    table_first: u32,             // where this grid's brick table begins in field_volume_bricks
    resolution_voxels: vec3<f32>, // voxels along x, y, z of the box
    reserved_0: f32,
    first_voxel: vec3<f32>,       // the box's first voxel in the brick lattice (each 0..8)
    reserved_1: f32,
    lattice_bricks: vec3<u32>,    // bricks along x, y, z of the lattice
    reserved_2: u32,
}

struct Field {
    planet_radius_m: f32,
    flat_planet: u32,             // 1 on a flat planet
    layer_bottom_m: f32,          // lowest layer bottom: the layer band's floor
    layer_top_m: f32,             // highest layer top: the layer band's ceiling
    base_noise_period_m: f32,
    detail_noise_period_m: f32,
    detail_erosion: f32,
    curl_displacement_m: f32,
    weather_extent_m: vec2<f32>,  // world size of one weather-map tile, x and z
    time_s: f32,                  // scene time the wind has moved the clouds to
    layer_count: u32,
    volume_count: u32,
    hiheight_level_count: u32,
    atlas_bricks_xy: vec2<u32>,   // bricks along x and y of the volume atlas
    detail_fbm: vec2<f32>,        // the detail fBm's mean and standard deviation (DetailStatistics)
    reserved: vec2<f32>,
    layers: array<FieldLayer, MAX_LAYERS>,
    volumes: array<FieldVolume, MAX_VOLUMES>,
    hiheight_levels: array<vec4<u32>, MAX_HIHEIGHT_LEVELS>, // per level: first cell, width, height
}

@group(0) @binding(0) var<uniform> field: Field;
@group(0) @binding(1) var field_base_noise: texture_3d<f32>;
@group(0) @binding(2) var field_detail_noise: texture_3d<f32>;
@group(0) @binding(3) var field_curl_noise: texture_2d<f32>;
@group(0) @binding(4) var field_weather_map: texture_2d<f32>;
@group(0) @binding(5) var field_volume_atlas: texture_3d<f32>;
@group(0) @binding(6) var field_repeat_linear: sampler;
@group(0) @binding(7) var field_clamp_linear: sampler;
// Hi-height pyramid cells, all levels back to back: per-layer highest cloud altitude (m).
@group(0) @binding(8) var<storage, read> field_hiheight: array<vec4<f32>>;
// The voxel grids' brick tables, back to back: per brick of a lattice, its index in the atlas + 1
// (0: empty). BrickGrid in field/brick.rs.
@group(0) @binding(9) var<storage, read> field_volume_bricks: array<u32>;

const FIELD_NO_HIT: f32 = 3.0e38;

// Unit "up" at p: the planet normal (or +y on a flat planet).
fn field_up(p: vec3<f32>) -> vec3<f32> {
    if field.flat_planet == 1u {
        return vec3<f32>(0.0, 1.0, 0.0);
    }
    return normalize(vec3<f32>(p.x, p.y + field.planet_radius_m, p.z));
}

// Ray parameters (t0, t1) where the ray o + t d is below altitude `h` (inside the sphere of radius
// R + h, or under the plane y = h); t0 > t1 when it never is.
fn field_below(o: vec3<f32>, d: vec3<f32>, h: f32) -> vec2<f32> {
    if field.flat_planet == 1u {
        if abs(d.y) < 1.0e-8 {
            return select(vec2<f32>(1.0, -1.0), vec2<f32>(-FIELD_NO_HIT, FIELD_NO_HIT), o.y < h);
        }
        let t = (h - o.y) / d.y;
        return select(vec2<f32>(t, FIELD_NO_HIT), vec2<f32>(-FIELD_NO_HIT, t), d.y > 0.0);
    }
    let r = field.planet_radius_m;
    let b = dot(o, d) + d.y * r;
    // |o - c|^2 - (R + h)^2 without cancellation: |o|^2 + 2 o.y R - h (2 R + h).
    let c = dot(o, o) + 2.0 * o.y * r - h * (2.0 * r + h);
    let disc = b * b - c;
    if disc < 0.0 {
        return vec2<f32>(1.0, -1.0);
    }
    let s = sqrt(disc);
    return vec2<f32>(-b - s, -b + s);
}

// Distance to the ground along the ray, or FIELD_NO_HIT without a ground.
fn field_ground_distance(o: vec3<f32>, d: vec3<f32>, has_ground: bool) -> f32 {
    if !has_ground {
        return FIELD_NO_HIT;
    }
    let g = field_below(o, d, 0.0);
    if g.x < g.y && g.y > 0.0 {
        return max(g.x, 0.0);
    }
    return FIELD_NO_HIT;
}

fn field_remap(value: f32, lo0: f32, hi0: f32, lo1: f32, hi1: f32) -> f32 {
    return lo1 + (value - lo0) * (hi1 - lo1) / (hi0 - lo0);
}

// Altitude above the ground (m); the cancellation-free sphere form of PlanetGeometry::altitude_m.
fn field_altitude_m(p: vec3<f32>) -> f32 {
    let r = field.planet_radius_m;
    if field.flat_planet == 1u {
        return p.y;
    }
    let to_centre = length(vec3<f32>(p.x, p.y + r, p.z));
    return (dot(p, p) + 2.0 * p.y * r) / (to_centre + r);
}

// The density-height gradient: profile::height_gradient over TYPE_GRADIENTS (generated from Rust).
fn field_height_gradient(type_coord: f32, f: f32) -> f32 {
    let t = clamp(type_coord, 0.0, 3.0);
    let lo = min(u32(floor(t)), 2u);
    let w = t - f32(lo);
    // One local copy, indexed twice: indexing the constant itself with a runtime index makes naga
    // materialise the whole array at each access.
    var gradients = TYPE_GRADIENTS;
    let g = gradients[lo] * (1.0 - w) + gradients[lo + 1u] * w;
    let rise = clamp(field_remap(f, g.x, g.y, 0.0, 1.0), 0.0, 1.0);
    let fall = clamp(field_remap(f, g.z, g.w, 1.0, 0.0), 0.0, 1.0);
    return rise * fall;
}

// The type coordinate of layer `layer` at weather type channel `channel`: TypeTable::type_coord.
fn field_type_coord(layer: u32, channel: f32) -> f32 {
    let e = TYPE_BLEND_HALF_WIDTH;
    var t = field.layers[layer].type_first;
    for (var i = 0u; i < 3u; i++) {
        t += field.layers[layer].type_steps[i] * smoothstep(field.layers[layer].type_bounds[i] - e, field.layers[layer].type_bounds[i] + e, channel);
    }
    return t;
}

fn field_apply_coverage(shape: f32, coverage: f32, type_coord: f32, f: f32) -> f32 {
    let anvil = clamp(type_coord - 2.0, 0.0, 1.0);
    let exponent = field_remap(clamp(f, 0.7, 0.8), 0.7, 0.8, 1.0, mix(1.0, 0.5, anvil));
    let c = pow(coverage, exponent);
    if c <= 0.0 {
        return 0.0;
    }
    return field_remap(shape, 1.0 - c, 1.0, 0.0, 1.0);
}

fn field_erode(density: f32, detail: vec4<f32>, f: f32, erosion: f32) -> f32 {
    let fbm = detail.x * 0.625 + detail.y * 0.25 + detail.z * 0.125;
    let modifier = mix(fbm, 1.0 - fbm, clamp(f * 10.0, 0.0, 1.0));
    return clamp(field_remap(density, modifier * erosion, 1.0, 0.0, 1.0), 0.0, 1.0);
}

// The eroded density's mean over the detail noise: layer::mean_erode, which derives it.
fn field_mean_erode(density: f32, f: f32, erosion: f32) -> f32 {
    let blend = clamp(f * 10.0, 0.0, 1.0);
    let mu = mix(field.detail_fbm.x, 1.0 - field.detail_fbm.x, blend) * erosion;
    let s = max(abs(1.0 - 2.0 * blend) * field.detail_fbm.y * erosion, 1e-6);
    let z = clamp((density - mu) / s, -8.0, 8.0);
    let pdf = 0.39894228 * exp(-0.5 * z * z); // the normal density, 1 / sqrt(2 pi) at 0
    let cdf = 1.0 / (1.0 + exp(-(0.07056 * z * z * z + 1.5976 * z)));
    return clamp(((density - mu) * cdf + s * pdf) / (1.0 - mu), 0.0, 1.0);
}

// Which density field_layer_extinction returns: eroded by the detail noise, its mean over the
// noise (the light paths'), or uneroded (the coarse shapes').
const FIELD_ERODED: u32 = 0u;
const FIELD_MEAN: u32 = 1u;
const FIELD_COARSE: u32 = 2u;

// Extinction of layer `layer` (an index: its members are read from the uniform where used rather
// than copied, which the march feels) at p, altitude h, of the density `density` (FIELD_ERODED,
// FIELD_MEAN or FIELD_COARSE): CloudField::layer_extinction.
fn field_layer_extinction(layer: u32, p: vec3<f32>, h: f32, density: u32) -> f32 {
    let f = (h - field.layers[layer].bottom_m) / field.layers[layer].thickness_m;
    if f < 0.0 || f > 1.0 {
        return 0.0;
    }
    let wind = field.layers[layer].wind_m_per_s * field.time_s;
    let xz = p.xz - wind;
    let w = textureSampleLevel(field_weather_map, field_repeat_linear, xz / field.weather_extent_m + field.layers[layer].weather_offset, 0.0);
    let coverage = clamp(w.x + 2.0 * field.layers[layer].coverage - 1.0, 0.0, 1.0);
    if coverage <= 0.0 {
        return 0.0;
    }
    let type_coord = field_type_coord(layer, w.y);
    let gradient = field_height_gradient(type_coord, f);
    if gradient <= 0.0 {
        return 0.0;
    }
    let q = p - vec3<f32>(wind.x, 0.0, wind.y) + field.layers[layer].noise_offset_m;
    let base = textureSampleLevel(field_base_noise, field_repeat_linear, q / field.base_noise_period_m, 0.0);
    let fbm = base.y * 0.625 + base.z * 0.25 + base.w * 0.125;
    let shaped = field_remap(base.x, fbm - 1.0, 1.0, 0.0, 1.0) * gradient;
    let covered = field_apply_coverage(shaped, coverage, type_coord, f);
    if covered <= 0.0 {
        return 0.0;
    }
    if density == FIELD_COARSE {
        return min(covered, 1.0) * w.z * field.layers[layer].extinction_per_m;
    }
    if density == FIELD_MEAN {
        return field_mean_erode(min(covered, 1.0), f, field.detail_erosion) * w.z * field.layers[layer].extinction_per_m;
    }
    let curl = textureSampleLevel(field_curl_noise, field_repeat_linear, q.xz / field.base_noise_period_m, 0.0);
    let swirl = (curl.xy * 2.0 - 1.0) * field.curl_displacement_m * (1.0 - f);
    let detail = textureSampleLevel(field_detail_noise, field_repeat_linear, (q + vec3<f32>(swirl.x, 0.0, swirl.y)) / field.detail_noise_period_m, 0.0);
    return field_erode(covered, detail, f, field.detail_erosion) * w.z * field.layers[layer].extinction_per_m;
}

// BrickGrid::sample: the brick holding the sample, then trilinear filtering inside its 9^3 texels
// (its voxels and the first of its neighbours') in the atlas.
fn field_volume_extinction(v: FieldVolume, p: vec3<f32>) -> f32 {
    let uvw = (p - v.min_m) / v.size_m;
    if any(uvw < vec3<f32>(0.0)) || any(uvw > vec3<f32>(1.0)) {
        return 0.0;
    }
    let texel = clamp(uvw * v.resolution_voxels - 0.5, vec3<f32>(0.0), v.resolution_voxels - 1.0) + v.first_voxel;
    let brick = min(vec3<u32>(floor(texel / BRICK_VOXELS)), v.lattice_bricks - 1u);
    let entry = (brick.z * v.lattice_bricks.y + brick.y) * v.lattice_bricks.x + brick.x;
    let slot = field_volume_bricks[v.table_first + entry];
    if slot == 0u {
        return 0.0;
    }
    let row = field.atlas_bricks_xy;
    let index = slot - 1u;
    let atlas_brick = vec3<u32>(index % row.x, index / row.x % row.y, index / (row.x * row.y));
    let local = texel - vec3<f32>(brick) * BRICK_VOXELS;
    let atlas_texel = vec3<f32>(atlas_brick) * BRICK_TEXELS + local + 0.5;
    let atlas_uvw = atlas_texel / vec3<f32>(textureDimensions(field_volume_atlas));
    return textureSampleLevel(field_volume_atlas, field_clamp_linear, atlas_uvw, 0.0).x * v.extinction_per_m;
}

fn field_extinction_of(p: vec3<f32>, density: u32) -> f32 {
    let h = field_altitude_m(p);
    var sigma_t = 0.0;
    for (var i = 0u; i < field.layer_count; i++) {
        sigma_t += field_layer_extinction(i, p, h, density);
    }
    for (var i = 0u; i < field.volume_count; i++) {
        sigma_t += field_volume_extinction(field.volumes[i], p);
    }
    return sigma_t;
}

// Extinction sigma_t (m^-1) at world point p (m) at the field's time: CloudField::extinction_per_m.
fn field_extinction(p: vec3<f32>) -> f32 {
    return field_extinction_of(p, FIELD_ERODED);
}

// The same without detail erosion: CloudField::coarse_extinction_per_m.
fn field_extinction_coarse(p: vec3<f32>) -> f32 {
    return field_extinction_of(p, FIELD_COARSE);
}

// The eroded extinction's mean over the detail noise, light paths' density:
// CloudField::mean_extinction_per_m.
fn field_extinction_mean(p: vec3<f32>) -> f32 {
    return field_extinction_of(p, FIELD_MEAN);
}

// The first stretch of the ray, within [0, t_max], inside the layers' altitude band.
fn field_layer_interval(o: vec3<f32>, d: vec3<f32>, t_max: f32) -> vec2<f32> {
    if field.layer_count == 0u {
        return vec2<f32>(1.0, -1.0);
    }
    let outer = field_below(o, d, field.layer_top_m);
    let inner = field_below(o, d, field.layer_bottom_m);
    var t0 = max(outer.x, 0.0);
    var t1 = min(outer.y, t_max);
    if inner.x < inner.y {
        if inner.x <= t0 && inner.y > t0 {
            t0 = inner.y; // starts below the layer: enter where the ray rises out of the inner ball
        } else if inner.x > t0 {
            t1 = min(t1, inner.x); // from above or inside: stop where the ray sinks below the layer
        }
    }
    return vec2<f32>(t0, t1);
}

// The hull of the ray's stretches inside the voxel-grid boxes.
fn field_volume_interval(o: vec3<f32>, d: vec3<f32>, t_max: f32) -> vec2<f32> {
    var hull = vec2<f32>(FIELD_NO_HIT, -FIELD_NO_HIT);
    for (var i = 0u; i < field.volume_count; i++) {
        let v = field.volumes[i];
        let inv = 1.0 / d;
        let a = (v.min_m - o) * inv;
        let b = (v.min_m + v.size_m - o) * inv;
        let t0 = max(max(max(min(a.x, b.x), min(a.y, b.y)), min(a.z, b.z)), 0.0);
        let t1 = min(min(min(max(a.x, b.x), max(a.y, b.y)), max(a.z, b.z)), t_max);
        if t0 < t1 {
            hull = vec2<f32>(min(hull.x, t0), max(hull.y, t1));
        }
    }
    return hull;
}

// Optical depth of the mean field (field_extinction_mean) along p + t dir over t in [span.x,
// span.x + span.y]: CloudField::mean_optical_depth.
fn field_optical_depth_mean(p: vec3<f32>, dir: vec3<f32>, span: vec3<f32>, n: u32, jitter: f32) -> f32 {
    return field_optical_depth_of(p, dir, span, n, jitter, FIELD_MEAN);
}

// The same through the coarse field: CloudField::coarse_optical_depth.
fn field_optical_depth_coarse(p: vec3<f32>, dir: vec3<f32>, span: vec3<f32>, n: u32, jitter: f32) -> f32 {
    return field_optical_depth_of(p, dir, span, n, jitter, FIELD_COARSE);
}

// Optical depth of `density` along p + t dir over t in [span.x, span.x + span.y], from n segments
// whose lengths grow by the factor span.z from one to the next (2: Schneider 2015's doubling light
// samples, fine near p; 1: uniform), each sampled at a jittered point; the segments' offsets are
// decorrelated from `jitter` and from each other by the golden ratio.
fn field_optical_depth_of(p: vec3<f32>, dir: vec3<f32>, span: vec3<f32>, n: u32, jitter: f32, density: u32) -> f32 {
    var total = f32(n);
    if span.z != 1.0 {
        total = (pow(span.z, f32(n)) - 1.0) / (span.z - 1.0);
    }
    var width = span.y / total;
    var start = span.x;
    var tau = 0.0;
    for (var k = 0u; k < n; k++) {
        let offset = fract(jitter + f32(k + 1u) * GOLDEN_RATIO_CONJUGATE);
        tau += field_extinction_of(p + dir * (start + width * offset), density) * width;
        start += width;
        width *= span.z;
    }
    return tau;
}
