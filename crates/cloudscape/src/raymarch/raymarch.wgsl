// Ray-marched clouds: per pixel, in-scattered radiance and transmittance of the cloud field along
// the view ray, up to the host's depth buffer. Needs field.wgsl, frame.wgsl and optics/phase.wgsl.

struct March {
    counts: vec4<u32>,  // primary steps, light steps, samples per pixel, octaves
    octaves: vec4<f32>, // attenuation a, contribution b, eccentricity c, single-scattering albedo
    phase: vec4<f32>,   // phase lobes (optics::PhaseLobes::to_gpu)
    ambient: vec4<f32>, // ambient scale, 0, 0, 0
    tile: vec4<u32>,    // origin x, y of the pixel tile this dispatch covers, its width
    flags: vec4<u32>,   // 1 to skip empty space with the hi-height pyramid
    grid: vec4<u32>,    // divisor of the march grid, sub-pixel x, y updated this frame, 1 if temporal
    ray_offset: vec4<f32>, // this frame's Halton offset along the rays (temporal)
}

struct MarchResult {
    radiance: vec3<f32>,
    transmittance: f32,
    density_samples: u32, // view-ray extinction evaluations
    depth_m: f32,         // transmittance-weighted mean distance of the cloud, 0 without cloud
}

@group(1) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(1) var<uniform> march: March;
// The host's depth buffer, bound as unfilterable float (GLSL cannot load from depth samplers).
@group(1) @binding(2) var host_depth: texture_2d<f32>;
@group(1) @binding(3) var cloud_out: texture_storage_2d<rgba16float, write>;
// Counters over the dispatch: [0] view-ray density samples, [1] pixels marched.
@group(1) @binding(4) var<storage, read_write> march_stats: array<atomic<u32>, 2>;
@group(1) @binding(5) var cloud_depth_out: texture_storage_2d<r32float, write>;
// Per-pixel sums over the samples of a multi-sample pass (MarchSum, declared with march_clouds).
@group(1) @binding(6) var<storage, read_write> march_sums: array<MarchSum>;

// Rays stop once this little light gets through (VolumeCloud's threshold, peers.md).
const MARCH_MIN_TRANSMITTANCE: f32 = 0.005;
// Longest path toward the sun (m): past 4 km of cumulus (optical depth ~ 200 at 0.05 m^-1) a shadow
// is complete, and longer single-sample segments only add noise.
const MARCH_SUN_PATH_MAX_M: f32 = 4000.0;

// Optical depth toward the sun from p, through the coarse (uneroded) density as Schneider 2015's
// cheap light samples: `light_steps` segments whose lengths double, covering the way to the top of
// the layers (at most MARCH_SUN_PATH_MAX_M) (VolumeCloud samples the sun path at 0.5, 1.5, 3, 6, 12
// units with weights 1, 1, 2, 4, 8; peers.md).
fn march_sun_optical_depth(p: vec3<f32>, jitter: f32) -> f32 {
    let sun = frame.sun_direction.xyz;
    var length_m = MARCH_SUN_PATH_MAX_M;
    if field.counts.x > 0u {
        length_m = clamp(field_below(p, sun, field.planet.w).y, 50.0, MARCH_SUN_PATH_MAX_M);
    }
    return field_optical_depth_coarse(p, sun, vec3<f32>(0.0, length_m, 2.0), march.counts.y, jitter);
}

// Light scattered from the sky above and the ground below, per unit sigma_s: each hemisphere
// contributes half its mean radiance (isotropic estimate), dimmed by the diffuse transmittance of
// the cloud between the point and the top (bottom) of the layer, its optical depth estimated from
// one sample halfway.
fn march_ambient(p: vec3<f32>, h: f32) -> vec3<f32> {
    let up = field_up(p);
    var above = 500.0;
    var below = 500.0;
    if field.counts.x > 0u && h >= field.planet.z && h <= field.planet.w {
        above = field.planet.w - h;
        below = h - field.planet.z;
    }
    let tau_up = field_extinction_coarse(p + up * (0.5 * above)) * above;
    let tau_down = field_extinction_coarse(p - up * (0.5 * below)) * below;
    var ground = frame.ground_radiance.xyz;
    if frame.ground_albedo.w < 0.5 {
        ground = frame.sky_horizon.xyz;
    }
    let sky = frame.sky_mean_up.xyz;
    return march.ambient.x * 0.5 * (sky * frame_diffuse_transmittance(frame, tau_up) + ground * frame_diffuse_transmittance(frame, tau_down));
}

// Sun light scattered toward the eye per unit sigma_s, with multiple-scattering octaves
// (Wrenninge 2013): sum_i b^i p(c^i g, mu) exp(-a^i tau_sun) E_sun.
fn march_sun_scattering(cos_theta: f32, tau_sun: f32) -> vec3<f32> {
    var sum = 0.0;
    var weight = 1.0;
    var extinction = 1.0;
    var anisotropy = 1.0;
    for (var i = 0u; i < march.counts.w; i++) {
        sum += weight * phase_eval(phase_scaled(march.phase, anisotropy), cos_theta) * exp(-extinction * tau_sun);
        weight *= march.octaves.y;
        extinction *= march.octaves.x;
        anisotropy *= march.octaves.z;
    }
    return sum * frame.sun_irradiance.xyz;
}

// Ray parameter of stratum boundary u in [0, 1]: quadratic spacing, so strata start short where
// the ray enters the clouds (the surfaces the eye sees) and lengthen behind them.
fn march_stratum_t(t0: f32, t1: f32, u: f32) -> f32 {
    return t0 + (t1 - t0) * u * u;
}

// Strata for a segment of `length_m`: the preset's count over twice the layer band's thickness,
// up to four times as many for the long grazing rays that cross the layer toward the horizon or
// along it from inside.
fn march_step_count(length_m: f32) -> u32 {
    let band_m = max(field.planet.w - field.planet.z, 1.0);
    let scale = clamp(length_m / (2.0 * band_m), 1.0, 4.0);
    return u32(f32(march.counts.x) * scale);
}

// Where the leading stretch of [t0, t1] that the hi-height pyramid proves empty ends (t0 when
// skipping is off). The pyramid does not describe voxel grids, so the stretch ends at the first.
// One query per ray, before the march: queries between samples would make the lanes of a SIMD
// group wait on each other's traversals, and cost more than the empty samples they save.
fn march_empty_until(o: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32, volume: vec2<f32>) -> f32 {
    if march.flags.x != 1u || field.counts.z == 0u {
        return t0;
    }
    return min(field_empty_until(o, d, t0, t1), max(volume.x, t0));
}

// The stratum the march starts from: one before the stratum holding `empty_until` (rounding may
// misplace it by one), whose samples before `empty_until` the march skips one by one.
fn march_first_stratum(t0: f32, t1: f32, n: u32, empty_until: f32) -> u32 {
    let u = sqrt(clamp((empty_until - t0) / (t1 - t0), 0.0, 1.0)); // inverse of march_stratum_t
    return u32(max(f32(n) * u - 1.0, 0.0));
}

// Integrates [t0, t1] in `march_step_count` strata, one sample per stratum at fraction `jitter` of it,
// with Hillaire 2016's energy-conserving step: S_int = (S - S exp(-sigma_t dt)) / sigma_t;
// L += T S_int; T *= exp(-sigma_t dt).
// Samples in the leading empty stretch (march_empty_until) are skipped: they would read zero.
// `volume` is the stretch inside voxel-grid boxes.
fn march_segment(o: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32, jitter: f32, volume: vec2<f32>) -> MarchResult {
    let n = march_step_count(t1 - t0);
    let cos_theta = dot(d, frame.sun_direction.xyz);
    let albedo = march.octaves.w;
    var radiance = vec3<f32>(0.0);
    var transmittance = 1.0;
    var depth_weighted = 0.0;
    var samples = 0u;
    let empty_until = march_empty_until(o, d, t0, t1, volume);
    let first = march_first_stratum(t0, t1, n, empty_until);
    var t_start = march_stratum_t(t0, t1, f32(first) / f32(n));
    for (var i = first; i < n; i++) {
        let t_end = march_stratum_t(t0, t1, f32(i + 1u) / f32(n));
        let dt = t_end - t_start;
        let t = t_start + jitter * dt;
        let p = o + d * t;
        t_start = t_end;
        if t < empty_until {
            continue;
        }
        samples += 1u;
        let sigma_t = field_extinction(p);
        if sigma_t <= 0.0 {
            continue;
        }
        let h = field_altitude_m(p);
        let tau_sun = march_sun_optical_depth(p, jitter);
        let source = albedo * (march_sun_scattering(cos_theta, tau_sun) + march_ambient(p, h));
        let step_transmittance = exp(-sigma_t * dt);
        radiance += transmittance * source * (1.0 - step_transmittance);
        depth_weighted += transmittance * (1.0 - step_transmittance) * distance(p, o);
        transmittance *= step_transmittance;
        if transmittance < MARCH_MIN_TRANSMITTANCE {
            break;
        }
    }
    // Aerial perspective at the transmittance-weighted mean cloud depth (Hillaire 2016, 5.9.1).
    let coverage = 1.0 - transmittance;
    let depth = select(0.0, depth_weighted / coverage, coverage > 0.0);
    return MarchResult(frame_haze(frame, radiance, coverage, depth), transmittance, samples, depth);
}

// The seed's 3x3 Bayer matrix (volumecloud-implementation-detail): per-pixel ray offsets in ninths.
const MARCH_BAYER_3X3 = array<f32, 9>(0.0, 7.0, 3.0, 6.0, 5.0, 2.0, 4.0, 1.0, 8.0);

// Offset of the samples along the ray, in strata: for stills, white noise per pixel; for temporal
// reuse, the frame's Halton value plus the pixel's Bayer offset, fract(halton + bayer / 9), so that
// each 3x3 neighbourhood spans the stratum (the seed's fix for AABB clipping of undersampled rays).
fn march_ray_offset(px: vec2<u32>) -> f32 {
    if march.grid.w == 0u {
        return frame_pixel_jitter(px, u32(frame.viewport.w));
    }
    return fract(march.ray_offset.x + MARCH_BAYER_3X3[(px.x % 3u) * 3u + px.y % 3u] / 9.0);
}

// The farthest host depth over a block of the full-resolution depth buffer: a low-resolution ray
// must not stop short of geometry that only part of its block has (Yusov 2014).
fn march_block_depth(block: vec2<u32>, size: u32) -> f32 {
    var depth = 0.0;
    let full = vec2<u32>(frame.viewport.xy);
    for (var y = 0u; y < size; y++) {
        for (var x = 0u; x < size; x++) {
            let texel = min(block * size + vec2<u32>(x, y), full - 1u);
            depth = max(depth, textureLoad(host_depth, vec2<i32>(texel), 0).x);
        }
    }
    return depth;
}

// Running sums of one pixel's samples while the pass is dispatched once per sample.
struct MarchSum {
    radiance_transmittance: vec4<f32>,
    depth_m: f32,
    samples: u32, // samples summed so far
}

// One sample of one ray per pixel of the march grid (1/divisor of the frame's resolution), through
// the sub-pixel of its block this frame updates. With several samples per pixel the pass is
// dispatched once per sample and sums them in `march_sums`: llvmpipe caps the loop iterations of
// one invocation at 65535 in total (LP_MAX_TGSI_LOOP_ITERATIONS, Mesa gallivm), which long grazing
// rays times several samples exceed, and short invocations suit GPUs as well. The last sample writes
// radiance and transmittance, and the transmittance-weighted cloud distance (0 where there is no
// cloud).
@compute @workgroup_size(8, 8)
fn march_clouds(@builtin(global_invocation_id) id: vec3<u32>) {
    let px = id.xy + march.tile.xy;
    let divisor = march.grid.x;
    let grid = (vec2<u32>(frame.viewport.xy) + divisor - 1u) / divisor;
    if px.x >= grid.x || px.y >= grid.y {
        return;
    }
    let full_px = min(px * divisor + march.grid.yz, vec2<u32>(frame.viewport.xy) - 1u);
    let pixel = vec2<f32>(full_px) + 0.5;
    let o = frame.camera_position.xyz;
    let d = frame_ray_direction(frame, pixel);
    let depth = march_block_depth(px, divisor);
    var t_max = min(frame.camera_position.w, field_ground_distance(o, d, frame.ground_albedo.w > 0.5));
    if depth < 1.0 {
        t_max = min(t_max, frame_depth_distance(frame, pixel, depth));
    }
    let spp = march.counts.z;
    let slot = id.y * march.tile.z + id.x;
    var sample_index = 0u;
    if spp > 1u {
        sample_index = march_sums[slot].samples;
    }
    let layer = field_layer_interval(o, d, t_max);
    let volume = field_volume_interval(o, d, t_max);
    let t0 = min(select(FIELD_NO_HIT, layer.x, layer.x < layer.y), volume.x);
    let t1 = max(select(-FIELD_NO_HIT, layer.y, layer.x < layer.y), volume.y);
    var result = vec4<f32>(0.0, 0.0, 0.0, 1.0);
    var cloud_depth = 0.0;
    if t0 < t1 {
        // Samples of one pixel are stratified: offsets s / spp from the pixel's ray offset.
        let jitter = fract(march_ray_offset(px) + f32(sample_index) / f32(spp));
        let m = march_segment(o, d, t0, t1, jitter, volume);
        result = vec4<f32>(m.radiance, m.transmittance);
        cloud_depth = m.depth_m;
        atomicAdd(&march_stats[0], m.density_samples);
    }
    if spp > 1u {
        let sum = march_sums[slot];
        if sample_index + 1u < spp {
            march_sums[slot] = MarchSum(sum.radiance_transmittance + result, sum.depth_m + cloud_depth, sample_index + 1u);
            return;
        }
        march_sums[slot] = MarchSum(vec4<f32>(0.0), 0.0, 0u); // ready for the next pass
        result = (sum.radiance_transmittance + result) / f32(spp);
        cloud_depth = (sum.depth_m + cloud_depth) / f32(spp);
    }
    atomicAdd(&march_stats[1], 1u);
    textureStore(cloud_out, vec2<i32>(px), result);
    textureStore(cloud_depth_out, vec2<i32>(px), vec4<f32>(cloud_depth, 0.0, 0.0, 0.0));
}
