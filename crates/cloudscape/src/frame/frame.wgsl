// One frame's camera, ground and sampling grid: the twin of frame/mod.rs (FrameUniform member for
// member). Bound once, at group 1, in every program that uses it.

struct Frame {
    clip_from_world: mat4x4<f32>,   // for raster passes
    view_from_clip: mat4x4<f32>,    // inverse projection: rays relative to the camera
    world_from_view: mat4x4<f32>,   // inverse view transform
    camera_position_m: vec3<f32>,
    far_m: f32,                     // nothing beyond this distance is marched
    ground_albedo: vec3<f32>,       // Lambertian albedo (0 without a ground)
    has_ground: u32,                // 1 when there is a ground
    viewport_px: vec2<f32>,         // full-resolution width, height
    time_s: f32,                    // scene time
    frame_index: u32,               // decorrelates the jitter of successive frames
    grid_subpixel: vec2<u32>,       // the pixel of each divisor x divisor block the output samples
    grid_divisor: u32,              // 1, 2 or 4: output resolution is 1/divisor of the viewport
    depth_far_value: f32,           // the host depth-buffer value where there is no geometry
    depth_reversed: u32,            // 1 when nearer geometry stores larger depth values
    cloud_mean_cosine: f32,         // mean cosine g of the cloud droplets' phase function
    reserved: vec2<u32>,
}

@group(1) @binding(0) var<uniform> frame: Frame;

// Where sample `index` of `samples` crosses its pixel, in pixel units from its corner: the centre
// for one sample, else R2 points (Roberts 2018, "The unreasonable effectiveness of quasirandom
// sequences") each beside its reflection through the centre, so their centroid is the centre.
// Frame::footprint_point is the same.
fn frame_footprint_point(index: u32, samples: u32) -> vec2<f32> {
    if samples <= 1u {
        return vec2<f32>(0.5);
    }
    let slot = index + 2u - samples % 2u;
    let step = vec2<f32>(FRAME_FOOTPRINT_STEP_X, FRAME_FOOTPRINT_STEP_Y);
    let point = fract(vec2<f32>(0.5) + f32(slot / 2u) * step);
    return select(point, vec2<f32>(1.0) - point, slot % 2u == 1u);
}

// Normalised device xy of pixel coordinates `pixel` (y down).
fn frame_ndc(pixel: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(2.0 * pixel.x / frame.viewport_px.x - 1.0, 1.0 - 2.0 * pixel.y / frame.viewport_px.y);
}

// The view-space point (relative to the camera: no cancellation against its world position) that
// normalised depth `depth` stores at pixel coordinates `pixel`.
fn frame_view_point(pixel: vec2<f32>, depth: f32) -> vec3<f32> {
    let p = frame.view_from_clip * vec4<f32>(frame_ndc(pixel), depth, 1.0);
    return p.xyz / p.w;
}

// Unit direction of the ray through pixel coordinates `pixel` (y down), as Frame::camera_ray: the
// point at normalised depth 0.5 lies between the planes in every depth convention.
fn frame_ray_direction(pixel: vec2<f32>) -> vec3<f32> {
    return normalize((frame.world_from_view * vec4<f32>(frame_view_point(pixel, 0.5), 0.0)).xyz);
}

// Whether a host depth-buffer value holds geometry (not the cleared value).
fn frame_has_geometry(depth: f32) -> bool {
    return select((depth < 1.0), (depth > 0.0), frame.depth_reversed == 1u);
}

// The farther of two depth-buffer values.
fn frame_farther_depth(a: f32, b: f32) -> f32 {
    return select(max(a, b), min(a, b), frame.depth_reversed == 1u);
}

// The farthest depth over a block of `size` x `size` texels of a full-resolution host depth buffer
// (clamped to the viewport): a low-resolution ray must not stop short of geometry that only part
// of its block has (Yusov 2014).
fn frame_block_depth(host_depth: texture_2d<f32>, block: vec2<u32>, size: u32) -> f32 {
    var depth = 1.0 - frame.depth_far_value; // the nearest value: any geometry is farther
    let full = vec2<u32>(frame.viewport_px);
    for (var y = 0u; y < size; y++) {
        for (var x = 0u; x < size; x++) {
            let texel = min(block * size + vec2<u32>(x, y), full - 1u);
            depth = frame_farther_depth(depth, textureLoad(host_depth, vec2<i32>(texel), 0).x);
        }
    }
    return depth;
}

// Distance along the ray through `pixel` to what depth-buffer value `depth` stores; FIELD-style
// 3e38 where it holds no geometry: Frame::depth_distance_m.
fn frame_depth_distance(pixel: vec2<f32>, depth: f32) -> f32 {
    if !frame_has_geometry(depth) {
        return 3.0e38;
    }
    return length(frame_view_point(pixel, depth));
}

// v rounded to a value a half float holds: up or down at random, with the probabilities that keep
// its expectation (stochastic rounding: Forsythe 1959, "Reprint of a note on rounding-off errors",
// SIAM Review 1; Connolly, Higham & Mary 2021, "Stochastic rounding and its probabilistic backward
// error analysis", SIAM J. Sci. Comput. 43). For running means stored in half floats: rounded to
// the nearest half (or toward zero, as a store may), every update smaller than half a unit in the
// last place is lost, and a mean that began low stays low. `u` is uniform in [0, 1).
// frame::round_to_half is the same.
fn frame_round_to_half(v: vec4<f32>, u: f32) -> vec4<f32> {
    let bits = bitcast<vec4<u32>>(abs(v));
    // Each value's binary exponent, and a half float's unit in the last place there: 10 fraction
    // bits, and below the normal range (2^-14) the subnormals' fixed unit 2^-24.
    let exponent = max(vec4<i32>((bits >> vec4<u32>(23u)) & vec4<u32>(0xffu)) - 127, vec4<i32>(-14));
    let ulp = exp2(vec4<f32>(exponent - 10));
    return sign(v) * floor(abs(v) / ulp + u) * ulp;
}

// Eddington (two-stream) diffuse transmittance of a conservatively scattering slab of optical depth
// tau: 1 / (1 + 3/4 (1 - g) tau) (e.g. Bohren 1987, "Multiple scattering of light and some of its
// observable consequences", Am. J. Phys. 55): diffuse light is dimmed by the transport optical
// depth (1 - g) tau, and only algebraically, not exponentially. optics::diffuse_transmittance.
fn frame_diffuse_transmittance(tau: f32) -> f32 {
    return 1.0 / (1.0 + 0.75 * (1.0 - frame.cloud_mean_cosine) * tau);
}

// The share of the light from below in the mean diffuse radiance inside a conservatively
// scattering slab lit from above and below, tau_above under its top and tau_below over its bottom:
// (k tau_above + 1/2) / (1 + k (tau_above + tau_below)), k = 3/4 (1 - g), the two-stream
// solution. optics::two_stream_share_from_below.
fn frame_two_stream_share_from_below(tau_above: f32, tau_below: f32) -> f32 {
    let k = 0.75 * (1.0 - frame.cloud_mean_cosine);
    return (k * tau_above + 0.5) / (1.0 + k * (tau_above + tau_below));
}
