// Ray-marched clouds: per output texel, in-scattered radiance, transmittance and distance of the
// cloud field along the view ray, up to the host's depth buffer (the cloud-output contract,
// output/mod.rs). No haze: the compositor applies aerial perspective at the cloud distance.

struct March {
    primary_steps: u32,
    light_steps: u32,           // samples toward the sun from each view sample
    samples_per_pixel: u32,
    octaves: u32,               // multiple-scattering octaves (Wrenninge 2013)
    octave_attenuation: f32,    // a: extinction factor per octave
    octave_contribution: f32,   // b: scattering factor per octave
    octave_eccentricity: f32,   // c: phase asymmetry factor per octave
    albedo: f32,                // single-scattering albedo
    phase_lobes: vec4<f32>,     // optics::PhaseLobes::to_gpu (g_hg, g_draine, alpha, w_draine)
    ambient_scale: f32,         // scale of sky and ground light
    empty_space_skipping: u32,  // 1 to skip empty space with the hi-height pyramid
    tile_width: u32,            // width of the texel band this dispatch covers
    lighting_model: u32,        // 0: slab (optics/slab.rs), 1: octaves, 2: the light volume
    tile_origin: vec2<u32>,     // first texel of the band
    back_steps: u32,            // samples away from the sun from each view sample (slab)
    view_peak_weight: f32,      // MarchSettings::view_peak_weight: scattering that keeps light on the ray
    slab_params: vec4<f32>,     // SunSlab::params_to_gpu
}

struct MarchResult {
    radiance: vec3<f32>,
    transmittance: f32,
    density_samples: u32, // view-ray extinction evaluations
    distance_m: f32,      // transmittance-weighted mean distance of the cloud, 0 without cloud
}

// Running sums of one pixel's samples while the pass is dispatched once per sample.
struct MarchSum {
    radiance_transmittance: vec4<f32>,
    distance_m: f32,
    samples: u32, // samples summed so far
    reserved: vec2<u32>,
}

@group(3) @binding(0) var<uniform> march: March;
// The host's depth buffer, bound as unfilterable float (GLSL cannot load from depth samplers).
@group(3) @binding(1) var host_depth: texture_2d<f32>;
@group(3) @binding(2) var cloud_out: texture_storage_2d<rgba16float, write>;
// Counters over the frame: [0] view-ray density samples, [1] texels marched.
@group(3) @binding(3) var<storage, read_write> march_stats: array<atomic<u32>, 2>;
@group(3) @binding(4) var cloud_distance_out: texture_storage_2d<r32float, write>;
@group(3) @binding(5) var<storage, read_write> march_sums: array<MarchSum>;
// The ray offsets' blue-noise tile (raymarch/blue_noise.rs), repeated over the image.
@group(3) @binding(6) var march_blue_noise: texture_2d<f32>;

// Rays stop once this little light gets through (VolumeCloud's threshold, peers.md).
const MARCH_MIN_TRANSMITTANCE: f32 = 0.005;
// The sun's light scattered at p toward the eye along d, per unit sigma_s and unit irradiance, by
// the scene's model of multiple scattering, with tau_sun the optical depth toward the sun. With the
// light volume (`reads_volume`, constant per entry point) only single scattering and the forward
// peak's beam: the volume holds the rest.
fn march_sun_scattering(p: vec3<f32>, d: vec3<f32>, tau_sun: f32, light_offset: f32, reads_volume: bool) -> f32 {
    let cos_theta = dot(d, environment_sun_direction());
    let slab = SlabModel(march.phase_lobes, march.slab_params);
    if reads_volume {
        return slab_beam_scattering(slab, cos_theta, tau_sun);
    }
    // Both models, chosen by select: lavapipe recompiles (and leaks) a shader that branches on a
    // uniform alone at every upload. Only the slab marches back samples (back_steps = 0 else).
    let by_slab = slab_scattering(slab, cos_theta, tau_sun, march_back_optical_depth(p, march.back_steps, light_offset));
    let factors = vec3<f32>(march.octave_attenuation, march.octave_contribution, march.octave_eccentricity);
    let by_octaves = phase_octaves(march.phase_lobes, factors, march.octaves, cos_theta, tau_sun);
    return select(by_octaves, by_slab, march.lighting_model == 0u);
}

// The mean field's optical depths (up, down) from p at altitude h to the top and the bottom of the
// layer, each estimated from one sample halfway (500 m each way outside the layers).
fn march_column(p: vec3<f32>, h: f32) -> vec2<f32> {
    let up = field_up(p);
    var above = 500.0;
    var below = 500.0;
    if field.layer_count > 0u && h >= field.layer_bottom_m && h <= field.layer_top_m {
        above = field.layer_top_m - h;
        below = h - field.layer_bottom_m;
    }
    let tau_up = field_extinction_mean(p + up * (0.5 * above)) * above;
    let tau_down = field_extinction_mean(p - up * (0.5 * below)) * below;
    return vec2<f32>(tau_up, tau_down);
}

// Light scattered from the sky above and the ground below, per unit sigma_s: the mean diffuse
// radiance of the two-stream solution for a slab lit by the sky's mean radiance from above and the
// radiance from below (frame_two_stream_share_from_below), with the optical depths of `column`.
fn march_ambient(column: vec2<f32>, light: MarchLight) -> vec3<f32> {
    let share_from_below = frame_two_stream_share_from_below(column.x, column.y);
    return march.ambient_scale * mix(light.sky_above, light.from_below, share_from_below);
}

// The light around one ray's clouds, from the environment interface: the sun's irradiance, the
// sky's mean radiance from above and the radiance from below (the unshadowed ground, or the sky
// below the horizon without one).
struct MarchLight {
    sun: vec3<f32>,
    sky_above: vec3<f32>,
    from_below: vec3<f32>,
}

// The diffuse light scattered at p toward the eye along d, per unit sigma_s: the light volume's,
// or the sky's and the ground's through the two-stream column (the slab's and the octaves'
// multiple scattering is in march_sun_scattering).
fn march_diffuse(p: vec3<f32>, d: vec3<f32>, light: MarchLight, reads_volume: bool) -> vec3<f32> {
    if reads_volume {
        return environment_light_volume_diffuse(p, -d);
    }
    return march_ambient(march_column(p, field_altitude_m(p)), light);
}

// MarchLight at p. Looked up once per ray, where it enters the cloud shell (not where empty-space
// skipping finds the first cloud, so skipping cannot change the image): the environment varies
// slowly over a cloud, and per-sample look-ups cost the march more than they change it.
fn march_light(p: vec3<f32>) -> MarchLight {
    var below = environment_ground_radiance(frame.ground_albedo, p);
    if frame.has_ground == 0u {
        below = environment_sky_radiance(-field_up(p));
    }
    return MarchLight(environment_sun_irradiance(p), environment_sky_mean_radiance_up(p), below);
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
    let band_m = max(field.layer_top_m - field.layer_bottom_m, 1.0);
    let scale = clamp(length_m / (2.0 * band_m), 1.0, 4.0);
    return u32(f32(march.primary_steps) * scale);
}

// Where the leading stretch of [t0, t1] that the hi-height pyramid proves empty ends (t0 when
// skipping is off). The pyramid does not describe voxel grids, so the stretch ends at the first.
// One query per ray, before the march: queries between samples would make the lanes of a SIMD
// group wait on each other's traversals, and cost more than the empty samples they save.
fn march_empty_until(o: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32, volume: vec2<f32>) -> f32 {
    if march.empty_space_skipping != 1u || field.hiheight_level_count == 0u {
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

// Integrates [t0, t1] in `march_step_count` strata, one sample per stratum at fraction `offsets.x`
// of it, its light paths at `offsets.y` of their segments (march_light_offset), with Hillaire 2016's
// energy-conserving step: S_int = (S - S exp(-sigma_t dt)) / sigma_t;
// L += T S_int; T *= exp(-sigma_t dt).
// The view ray's own forward scattering (δ-M, Wiscombe 1977, on the way to the eye): the droplets'
// diffraction peak, a share w_p of their scattering (march.view_peak_weight), deflects light by
// under a few pixels, so light it scatters stays on the ray. Light scattered toward the eye by the
// rest of the phase function (the diffuse field by the broad lobe, 1 - w_p; the sun's beam by
// its share outside the peak, phase_broad_share) reaches the eye through the δ-scaled transmittance
// T' of sigma_t (1 - albedo w_p). The beam's light scattered by the peak itself runs along the
// beam, whose own peak scatterings slab_beam_scattering already counts, so it keeps the whole
// extinction T. T, the pixel's transmittance, dims the background. w_p = 0 gives the plain march.
// Samples in the leading empty stretch (march_empty_until) are skipped: they would read zero.
// `volume` is the stretch inside voxel-grid boxes.
fn march_segment(o: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32, offsets: vec2<f32>, volume: vec2<f32>, reads_volume: bool) -> MarchResult {
    let n = march_step_count(t1 - t0);
    let albedo = march.albedo;
    let peak = march.view_peak_weight;
    let thinning = 1.0 - albedo * peak;
    let broad_sun = phase_broad_share(march.phase_lobes, peak, dot(d, environment_sun_direction()));
    var radiance = vec3<f32>(0.0);
    var transmittance = 1.0;
    var scaled_transmittance = 1.0;
    var distance_weighted = 0.0;
    var samples = 0u;
    let empty_until = march_empty_until(o, d, t0, t1, volume);
    let light = march_light(o + d * t0);
    let first = march_first_stratum(t0, t1, n, empty_until);
    var t_start = march_stratum_t(t0, t1, f32(first) / f32(n));
    for (var i = first; i < n; i++) {
        let t_end = march_stratum_t(t0, t1, f32(i + 1u) / f32(n));
        let dt = t_end - t_start;
        let t = t_start + offsets.x * dt;
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
        let tau_sun = march_sun_optical_depth(p, march.light_steps, offsets.y);
        let sun = albedo * march_sun_scattering(p, d, tau_sun, offsets.y, reads_volume) * light.sun;
        let diffuse = albedo * (1.0 - peak) * march_diffuse(p, d, light, reads_volume);
        let step_transmittance = exp(-sigma_t * dt);
        let scaled_step = exp(-sigma_t * thinning * dt);
        radiance += transmittance * (1.0 - broad_sun) * sun * (1.0 - step_transmittance);
        radiance += scaled_transmittance * (broad_sun * sun + diffuse) * (1.0 - scaled_step) / thinning;
        distance_weighted += transmittance * (1.0 - step_transmittance) * distance(p, o);
        transmittance *= step_transmittance;
        scaled_transmittance *= scaled_step;
        if scaled_transmittance < MARCH_MIN_TRANSMITTANCE {
            break;
        }
    }
    let coverage = 1.0 - transmittance;
    let distance_m = select(0.0, distance_weighted / coverage, coverage > 0.0);
    return MarchResult(radiance, transmittance, samples, distance_m);
}

// Offset of the samples along the ray of output texel `px`, in strata: the blue-noise tile
// (raymarch/blue_noise.rs: each 3x3 neighbourhood spans the stratum, as the seed's Bayer offsets
// serve AABB clipping of undersampled rays, without the R2 dither's lattice) plus the golden-ratio
// R1 sequence over frames (Roberts 2018), so each texel's offsets spread over the stratum from
// frame to frame (the light paths' offsets are march_light_offset's). On a grid of divisor x
// divisor blocks a full-resolution pixel has a ray of its own once a round of divisor^2 frames,
// and its history is a mean of its last few: the R1 step advances once a round (the sub-pixels of
// a round take successive steps), so that a pixel's own offsets are successive terms of R1, spread
// over the stratum. Every 16th term of R1 (4x4) steps by 16 / phi, 0.11 short of a whole: a
// pixel's last few offsets were nearly alike, and their error did not average.
fn march_ray_offset(px: vec2<u32>) -> f32 {
    let round_frames = frame.grid_divisor * frame.grid_divisor;
    let tile = textureLoad(march_blue_noise, vec2<i32>(px % textureDimensions(march_blue_noise)), 0).x;
    let round = (frame.frame_index / round_frames) % 4096u;
    return fract(tile + fract(f32(round) * FRAME_OFFSET_STEP) + f32(frame.frame_index % round_frames) * FRAME_OFFSET_STEP);
}

// Where in each of its segments a light path (toward the sun, and the slab's away from it) samples
// the mean density, for the pixel's sample `sample_index` of `spp` whose ray is at `ray_offset`.
// The path's segments double in length (Schneider 2015), so its last is half of a way that reaches
// kilometres toward a low sun, and one sample there either meets a cloud on the way or misses it.
// At the ray offsets' former R2 dither that variance printed a regular lattice over every lit cloud
// of a still (the backlit sunset, the default scene's big cumulus at 640x360; neither 4x the primary
// steps nor 4x the light steps softened it). With several samples per pixel, each takes the middle
// of its own stratum, the same for every pixel: the pixel's mean is stratified, and no pixel differs
// from its neighbour by where its light samples fell. With one, the ray's blue-noise offset stays:
// its error is grain without a lattice, which averages over the pixels and, through the temporal
// history, over frames; one offset for all (the middle) was smooth but biased (the fly-through's full march against its converged frames, FLIP 0.0155 ->
// 0.0355; the isolated cumulus against the sun's luminance 1.20 -> 1.31; docs/lighting.md).
fn march_light_offset(ray_offset: f32, sample_index: u32, spp: u32) -> f32 {
    return select(ray_offset, (f32(sample_index) + 0.5) / f32(spp), spp > 1u);
}

// One sample of one ray per texel of the output grid (1/divisor of the frame's resolution), through
// the sub-pixel of its block the frame's grid names. With several samples per pixel the pass is
// dispatched once per sample, each through its own point of the pixel (frame_footprint_point), and sums
// them in `march_sums`: llvmpipe caps the loop iterations of one invocation at 65535 in total
// (LP_MAX_TGSI_LOOP_ITERATIONS, Mesa gallivm), which long grazing rays times several samples
// exceed, and short invocations suit GPUs as well. The last sample writes radiance and
// transmittance, and the transmittance-weighted cloud distance (0 where there is no cloud).
// The lighting model is a constant of each entry point (march_clouds, march_clouds_volume), not a
// uniform: the compiler drops the model a pipeline does not use, and lavapipe recompiles (and
// leaks) a shader that branches on a uniform alone.
fn march_texel(id: vec3<u32>, reads_volume: bool) {
    let px = id.xy + march.tile_origin;
    let divisor = frame.grid_divisor;
    let viewport = vec2<u32>(frame.viewport_px);
    let grid = (viewport + divisor - 1u) / divisor;
    if px.x >= grid.x || px.y >= grid.y {
        return;
    }
    let full_px = min(px * divisor + frame.grid_subpixel, viewport - 1u);
    let spp = march.samples_per_pixel;
    let slot = id.y * march.tile_width + id.x;
    var sample_index = 0u;
    if spp > 1u {
        sample_index = march_sums[slot].samples;
    }
    let pixel = vec2<f32>(full_px) + frame_footprint_point(sample_index, spp);
    let o = frame.camera_position_m;
    let d = frame_ray_direction(pixel);
    let depth = frame_block_depth(host_depth, px, divisor);
    var t_max = min(frame.far_m, field_ground_distance(o, d, frame.has_ground == 1u));
    t_max = min(t_max, frame_depth_distance(pixel, depth));
    let layer = field_layer_interval(o, d, t_max);
    let volume = field_volume_interval(o, d, t_max);
    let t0 = min(select(FIELD_NO_HIT, layer.x, layer.x < layer.y), volume.x);
    let t1 = max(select(-FIELD_NO_HIT, layer.y, layer.x < layer.y), volume.y);
    var result = vec4<f32>(0.0, 0.0, 0.0, 1.0);
    var distance_m = 0.0;
    if t0 < t1 {
        // Samples of one pixel are stratified: offsets s / spp from the pixel's ray offset.
        let jitter = fract(march_ray_offset(px) + f32(sample_index) / f32(spp));
        let m = march_segment(o, d, t0, t1, vec2<f32>(jitter, march_light_offset(jitter, sample_index, spp)), volume, reads_volume);
        result = vec4<f32>(m.radiance, m.transmittance);
        distance_m = m.distance_m;
        atomicAdd(&march_stats[0], m.density_samples);
    }
    if spp > 1u {
        let sum = march_sums[slot];
        if sample_index + 1u < spp {
            march_sums[slot] = MarchSum(sum.radiance_transmittance + result, sum.distance_m + distance_m, sample_index + 1u, vec2<u32>(0u));
            return;
        }
        march_sums[slot] = MarchSum(vec4<f32>(0.0), 0.0, 0u, vec2<u32>(0u)); // ready for the next pass
        result = (sum.radiance_transmittance + result) / f32(spp);
        distance_m = (sum.distance_m + distance_m) / f32(spp);
    }
    atomicAdd(&march_stats[1], 1u);
    textureStore(cloud_out, vec2<i32>(px), result);
    textureStore(cloud_distance_out, vec2<i32>(px), vec4<f32>(distance_m, 0.0, 0.0, 0.0));
}

// The march with the slab's or the octaves' multiple scattering and the two-stream ambient light.
@compute @workgroup_size(8, 8)
fn march_clouds(@builtin(global_invocation_id) id: vec3<u32>) {
    march_texel(id, false);
}

// The march reading the environment's light volume for the diffuse light.
@compute @workgroup_size(8, 8)
fn march_clouds_volume(@builtin(global_invocation_id) id: vec3<u32>) {
    march_texel(id, true);
}
