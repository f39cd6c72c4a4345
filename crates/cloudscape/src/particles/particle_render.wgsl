// Particle rendering in compute (particles/render.rs): the particles of particle_generate.wgsl
// binned into screen tiles (`bin_particles`, one invocation per particle), then one workgroup per
// tile (`render_tiles`) that sorts the tile's list by distance and blends, per pixel, the segment of
// the view ray through each particle, shaded from the tables (single scattering) and the light
// volume (multiple scattering, lighting.model = "volume"), front to back with Yusov 2014's
// volume-aware blending (particles/blend.rs is its specification). wgpu has no rasterizer-ordered
// views, so the ordering the seed gets from pixel synchronisation comes from the sort.

struct Render {
    grid_size: vec2<u32>,          // output texels
    tiles: vec2<u32>,              // tiles across and down
    tile_capacity: u32,            // entries a tile's list holds (MAX_TILE_ENTRIES are blended)
    blending: u32,                 // Blending::gpu_index: 0 volume-aware, 1 alpha
    max_particles: u32,            // capacity of the particle buffer
    flat_planet: u32,              // 1 on a flat planet
    planet_radius_m: f32,
    sigma_max_per_m: f32,          // extinction of density 1
    reference_optical_radius: f32, // sigma R of the particle the tables were baked for
    albedo: f32,                   // single-scattering albedo
    phase_lobes: vec4<f32>,        // optics::PhaseLobes::to_gpu
    table_dims: vec4<u32>,         // optical-depth table (start zen, start az, dir zen, dir az)
    ambient_scale: f32,            // scale of sky and ground light
    band_first_tile_row: u32,      // the first tile row this dispatch renders
    band_rows: vec2<u32>,          // texel rows [x, y) this dispatch writes
    diffuse_from_volume: u32,      // 1: the light volume's diffuse light, not the tables' multiple
    reserved0: u32,
    reserved1: vec2<u32>,
    slab_params: vec4<f32>,        // optics::SunSlab::params_to_gpu: the forward peak's beam
}

@group(3) @binding(0) var<uniform> render: Render;
@group(3) @binding(1) var<storage, read> particles: array<Particle>;
// particle_generate.wgsl's counts: [1] particles made.
@group(3) @binding(2) var<storage, read> counts: array<u32, 4>;
// The optical-depth table that particle_lookup.wgsl reads.
@group(3) @binding(3) var optical_depth_lut: texture_3d<f32>;
@group(3) @binding(4) var optical_depth_sampler: sampler;
@group(3) @binding(5) var<storage, read> chord_mean_density: array<f32>;
// Single (r, without the phase function) and multiple (g) scattering (ScatteringLut).
@group(3) @binding(6) var scattering_lut: texture_3d<f32>;
@group(3) @binding(7) var scattering_sampler: sampler;
@group(3) @binding(8) var<storage, read_write> tile_counts: array<atomic<u32>>;
// Per tile, `tile_capacity` sort keys: quantised log distance << 20 | particle index
// (particle_tiles.wgsl sorts them).
@group(3) @binding(9) var<storage, read_write> tile_entries: array<u32>;
@group(3) @binding(10) var host_depth: texture_2d<f32>;
@group(3) @binding(11) var cloud_out: texture_storage_2d<rgba16float, write>;
@group(3) @binding(12) var cloud_distance_out: texture_storage_2d<r32float, write>;
// [0] segments blended, [1] texels written, [2] tile entries dropped (full tiles), [3] particles binned.
@group(3) @binding(13) var<storage, read_write> render_stats: array<atomic<u32>, 4>;

const TILE: u32 = 16u;
const INDEX_BITS: u32 = 20u;
const INDEX_MASK: u32 = 0xfffffu;
const DISTANCE_LEVELS: f32 = 4095.0;
const OPAQUE_TRANSMITTANCE: f32 = 0.01;
// Occlusion of multiple scattering relative to single (Yusov's released code: exp(-0.25 tau)).
const MULTIPLE_OCCLUSION: f32 = 0.25;
const VOLUME_AWARE: u32 = 0u;

// The sort key of a particle whose nearest point is `near_m` away: log2 of the distance over
// [0.5 m, 362 km] in 12 bits (steps of 0.33 %), then the index.
fn sort_key(near_m: f32, index: u32) -> u32 {
    let level = clamp((log2(max(near_m, 0.5)) + 1.0) / 19.5, 0.0, 1.0) * DISTANCE_LEVELS;
    return (u32(level) << INDEX_BITS) | index;
}

// Output texel of full-resolution pixel coordinates (the frame's sample grid).
fn grid_texel(pixel: vec2<f32>) -> vec2<f32> {
    return (pixel - vec2<f32>(frame.grid_subpixel)) / f32(frame.grid_divisor);
}

// Clip-space w below which a point counts as behind the eye (w is the view depth, m).
const FOOTPRINT_MIN_W: f32 = 0.01;

// Output texel coordinates of a clip-space point in front of the eye.
fn footprint_texel(clip: vec4<f32>) -> vec2<f32> {
    let ndc = clip.xy / clip.w;
    return grid_texel(vec2<f32>(0.5 * (ndc.x + 1.0), 0.5 * (1.0 - ndc.y)) * frame.viewport_px);
}

// The output texels the particle may cover, (min.xy, max.xy); min > max when none: the screen
// bounds of its bounding cube's part in front of the eye (the cube's corners there, and where its
// edges cross the plane w = FOOTPRINT_MIN_W). A particle the eye is in covers the whole screen:
// it is clipped, not dropped.
fn particle_footprint(p: Particle) -> vec4<i32> {
    let screen = vec4<i32>(0, 0, vec2<i32>(render.grid_size) - 1);
    let r = max(p.radius_m, p.height_m);
    if all(abs(frame.camera_position_m - p.centre_m) < vec3<f32>(r)) {
        return screen;
    }
    var corners: array<vec4<f32>, 8>;
    for (var k = 0u; k < 8u; k++) {
        let unit = vec3<f32>(f32(k & 1u), f32((k >> 1u) & 1u), f32((k >> 2u) & 1u));
        corners[k] = frame.clip_from_world * vec4<f32>(p.centre_m + r * (2.0 * unit - 1.0), 1.0);
    }
    var lo = vec2<f32>(3.0e38);
    var hi = vec2<f32>(-3.0e38);
    for (var k = 0u; k < 8u; k++) {
        let a = corners[k];
        if a.w >= FOOTPRINT_MIN_W {
            lo = min(lo, footprint_texel(a));
            hi = max(hi, footprint_texel(a));
        }
        for (var axis = 0u; axis < 3u; axis++) {
            let b = corners[k ^ (1u << axis)];
            if (a.w < FOOTPRINT_MIN_W) != (b.w < FOOTPRINT_MIN_W) {
                let crossing = mix(a, b, (FOOTPRINT_MIN_W - a.w) / (b.w - a.w));
                lo = min(lo, footprint_texel(crossing));
                hi = max(hi, footprint_texel(crossing));
            }
        }
    }
    let first = max(vec2<i32>(floor(clamp(lo, vec2<f32>(-1.0e6), vec2<f32>(1.0e6)))) - 1, screen.xy);
    let last = min(vec2<i32>(ceil(clamp(hi, vec2<f32>(-1.0e6), vec2<f32>(1.0e6)))) + 1, screen.zw);
    return vec4<i32>(first, last);
}

@compute @workgroup_size(64)
fn bin_particles(@builtin(global_invocation_id) id: vec3<u32>) {
    let count = min(counts[1], render.max_particles);
    if id.x >= count {
        return;
    }
    let p = particles[id.x];
    if p.density <= 0.0 {
        return;
    }
    let footprint = particle_footprint(p);
    if any(footprint.xy > footprint.zw) {
        return;
    }
    let near_m = length(p.centre_m - frame.camera_position_m) - max(p.radius_m, p.height_m);
    let key = sort_key(near_m, id.x);
    let first = vec2<u32>(footprint.xy) / TILE;
    let last = vec2<u32>(footprint.zw) / TILE;
    for (var ty = first.y; ty <= last.y; ty++) {
        for (var tx = first.x; tx <= last.x; tx++) {
            let tile = ty * render.tiles.x + tx;
            let slot = atomicAdd(&tile_counts[tile], 1u);
            if slot < render.tile_capacity {
                tile_entries[tile * render.tile_capacity + slot] = key;
            } else {
                atomicAdd(&render_stats[2], 1u);
            }
        }
    }
    atomicAdd(&render_stats[3], 1u);
}

// blend::PixelBlend.
struct PixelBlend {
    has_record: bool,
    record: BlendSegment,
    radiance: vec3<f32>,
    transmittance: f32,
    distance_weighted_m: f32,
}

fn blend_segment(pixel: ptr<function, PixelBlend>, s: BlendSegment) {
    let opacity = 1.0 - exp(-s.optical_depth);
    (*pixel).radiance += (*pixel).transmittance * opacity * s.colour;
    (*pixel).distance_weighted_m += (*pixel).transmittance * opacity * 0.5 * (s.near_m + s.far_m);
    (*pixel).transmittance *= 1.0 - opacity;
}

fn blend_add(pixel: ptr<function, PixelBlend>, s: BlendSegment) {
    if !(*pixel).has_record {
        (*pixel).record = s;
        (*pixel).has_record = true;
    } else if render.blending == VOLUME_AWARE && s.near_m < (*pixel).record.far_m {
        (*pixel).record = blend_merge((*pixel).record, s);
    } else {
        blend_segment(pixel, (*pixel).record);
        (*pixel).record = s;
    }
}

fn blend_is_opaque(pixel: PixelBlend) -> bool {
    var t = pixel.transmittance;
    if pixel.has_record {
        t *= exp(-pixel.record.optical_depth);
    }
    return t < OPAQUE_TRANSMITTANCE;
}

// The light around the particles of one pixel: sun irradiance, the sky's mean radiance from above
// and the radiance from below (raymarch.wgsl's MarchLight).
struct Light {
    sun: vec3<f32>,
    sky_above: vec3<f32>,
    from_below: vec3<f32>,
    phase: f32,
}

// The ray's segment through particle `p` within [0, t_max], shaded from the tables; optical depth
// 0 where it misses. The ellipsoid maps to the unit sphere by dividing by its radii; a chord the
// camera or the host's depth clips keeps its share of the whole chord's optical depth (uniform
// density, as the blending assumes).
fn particle_segment(p: Particle, o: vec3<f32>, d: vec3<f32>, t_max: f32, light: Light) -> BlendSegment {
    var none = BlendSegment(0.0, 0.0, 0.0, vec3<f32>(0.0));
    let radii = vec3<f32>(p.radius_m, p.height_m, p.radius_m);
    let lo = (o - p.centre_m) / radii;
    let ld = d / radii;
    let a = dot(ld, ld);
    let b = dot(lo, ld);
    let c = dot(lo, lo) - 1.0;
    let disc = b * b - a * c;
    if disc <= 0.0 {
        return none;
    }
    let s = sqrt(disc);
    let t0 = (-b - s) / a;
    let t1 = (-b + s) / a;
    let near_m = max(t0, 0.0);
    let far_m = min(t1, t_max);
    if far_m <= near_m {
        return none;
    }
    let entry = normalize(lo + t0 * ld);
    let dir = normalize(ld);
    let turn = particle_rotation(p.id);
    let mass = particle_optical_mass(particle_rotate(turn, entry), particle_rotate(turn, dir), render.table_dims);
    let tau_chord = render.sigma_max_per_m * p.density * mass / sqrt(a);
    let optical_depth = tau_chord * (far_m - near_m) / (t1 - t0);
    let to_light = normalize(environment_sun_direction() / radii);
    let sm = particle_scattering(entry, -dir, to_light);
    // Per unit opacity of the reference particle along this chord: single scattering at most the
    // albedo (an unshadowed thin chord), multiple at most 1 / pi (a white Lambertian reflector);
    // the bounds hold where the tables' grazing texels outlive the vanishing chord.
    let reference_opacity = max(1.0 - exp(-render.reference_optical_radius * mass), 1e-4);
    let single = min(sm.x / reference_opacity, render.albedo);
    let multiple = min(sm.y / reference_opacity, 1.0 / PI);
    let single_sun = light.sun * light.phase * single * exp(-p.sun_optical_depth);
    if render.diffuse_from_volume == 1u && environment_has_light_volume() {
        let middle = o + d * (0.5 * (near_m + far_m));
        let diffuse = environment_light_volume_diffuse(middle, -d);
        // Half the particle's own chord toward the sun, through its centre (the unit sphere's
        // chord along to_light, scaled back to metres).
        let own_tau = 0.5 * render.sigma_max_per_m * p.density * chord_mass(-to_light, to_light) / length(environment_sun_direction() / radii);
        let slab = SlabModel(render.phase_lobes, render.slab_params);
        let peak = light.sun * slab_peak_beam(slab, dot(d, environment_sun_direction()), p.sun_optical_depth + own_tau);
        return BlendSegment(near_m, far_m, optical_depth, single_sun + peak + render.albedo * diffuse);
    }
    let multiple_sun = light.sun * multiple * exp(-MULTIPLE_OCCLUSION * p.sun_optical_depth);
    let share_from_below = frame_two_stream_share_from_below(p.optical_depth_up, p.optical_depth_down);
    let ambient = render.ambient_scale * mix(light.sky_above, light.from_below, share_from_below);
    return BlendSegment(near_m, far_m, optical_depth, single_sun + multiple_sun + render.albedo * ambient);
}

// Distance to the ground along the ray (3e38 without one): field_ground_distance, for the planet
// of the Render uniform (this program binds no field).
fn ground_distance(o: vec3<f32>, d: vec3<f32>) -> f32 {
    if frame.has_ground == 0u {
        return 3.0e38;
    }
    if render.flat_planet == 1u {
        return select(3.0e38, -o.y / d.y, d.y < 0.0 && o.y > 0.0);
    }
    let r = render.planet_radius_m;
    let b = dot(o, d) + d.y * r;
    let c = dot(o, o) + 2.0 * o.y * r;
    let disc = b * b - c;
    if disc < 0.0 {
        return 3.0e38;
    }
    let t = -b - sqrt(disc);
    return select(3.0e38, max(t, 0.0), -b + sqrt(disc) > 0.0);
}

@compute @workgroup_size(16, 16)
fn render_tiles(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_id) local: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    let tile = vec2<u32>(group.x, group.y + render.band_first_tile_row);
    let tile_index = tile.y * render.tiles.x + tile.x;
    let n = load_sorted_tile(tile_index, render.tile_capacity, lane);

    let px = tile * TILE + local.xy;
    if px.x >= render.grid_size.x || px.y < render.band_rows.x || px.y >= render.band_rows.y {
        return;
    }
    let viewport = vec2<u32>(frame.viewport_px);
    let pixel = vec2<f32>(min(px * frame.grid_divisor + frame.grid_subpixel, viewport - 1u)) + 0.5;
    let o = frame.camera_position_m;
    let d = frame_ray_direction(pixel);
    var t_max = min(frame.far_m, ground_distance(o, d));
    t_max = min(t_max, frame_depth_distance(pixel, frame_block_depth(host_depth, px, frame.grid_divisor)));
    var below = environment_ground_radiance(frame.ground_albedo, o);
    if frame.has_ground == 0u {
        below = environment_sky_radiance(vec3<f32>(0.0, -1.0, 0.0));
    }
    let light = Light(
        environment_sun_irradiance(o),
        environment_sky_mean_radiance_up(o),
        below,
        phase_eval(render.phase_lobes, dot(d, environment_sun_direction())),
    );
    var blend: PixelBlend;
    blend.has_record = false;
    blend.transmittance = 1.0;
    var segments = 0u;
    for (var i = 0u; i < n; i++) {
        if blend_is_opaque(blend) {
            break;
        }
        let s = particle_segment(particles[tile_keys[i] & INDEX_MASK], o, d, t_max, light);
        if s.optical_depth > 0.0 {
            blend_add(&blend, s);
            segments += 1u;
        }
    }
    if blend.has_record {
        blend_segment(&blend, blend.record);
    }
    let coverage = 1.0 - blend.transmittance;
    let distance_m = select(0.0, blend.distance_weighted_m / coverage, coverage > 0.0);
    atomicAdd(&render_stats[0], segments);
    atomicAdd(&render_stats[1], 1u);
    textureStore(cloud_out, vec2<i32>(px), vec4<f32>(blend.radiance, blend.transmittance));
    textureStore(cloud_distance_out, vec2<i32>(px), vec4<f32>(distance_m, 0.0, 0.0, 0.0));
}

// (S, M) for light leaving the unit sphere at `point` along `out` (toward the eye), lit from
// `to_light`: ScatteringTables::lookup (texture coordinates as texture_coordinates there).
fn particle_scattering(point: vec3<f32>, out: vec3<f32>, to_light: vec3<f32>) -> vec2<f32> {
    let n = normalize(point);
    let cos_entry = clamp(dot(n, to_light), -1.0, 1.0);
    let away = n * cos_entry - to_light;
    var tangent = vec3<f32>(0.0);
    if dot(away, away) > 1e-12 {
        tangent = normalize(away);
    } else {
        tangent = particle_any_orthonormal(n);
    }
    let bitangent = cross(n, tangent);
    let zenith = acos(clamp(dot(out, n), 0.0, 1.0));
    let azimuth = atan2(abs(dot(out, bitangent)), dot(out, tangent));
    let uvw = vec3<f32>(azimuth / PI, zenith / (0.5 * PI), acos(cos_entry) / PI);
    return textureSampleLevel(scattering_lut, scattering_sampler, uvw, 0.0).xy;
}

// A unit vector orthogonal to unit `n`: glam's Vec3::any_orthonormal_vector (Duff et al. 2017).
fn particle_any_orthonormal(n: vec3<f32>) -> vec3<f32> {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return vec3<f32>(b, sign + n.y * n.y * a, -n.y);
}
