// Temporal reconstruction of undersampled clouds (volumecloud-implementation-detail): the current
// coarse output upsampled with depth awareness, the history reprojected with the previous frame's
// view-projection at the estimated cloud distance, clipped to the current neighbourhood and
// blended. Reads only the cloud-output contract, so it serves every technique.

struct Temporal {
    prev_clip_from_world: mat4x4<f32>,
    prev_camera_position_m: vec3<f32>,
    history_valid: u32,         // 0 on the first frame and after a cut
    wind_shift_m: vec2<f32>,    // how far the wind moved the clouds since the previous frame: x, z
    fresh_weight: f32,          // weight of a fresh sample at its own pixel
    clip_gamma: f32,            // half-width of the clip box, in standard deviations
    distance_tolerance: f32,    // history dropped where its cloud lies farther off than this fraction
    reserved_0: u32,            // padding to the 16-byte size of a uniform
    reserved_1: vec2<u32>,
}

@group(3) @binding(0) var<uniform> temporal: Temporal;
// The coarse output that upsample.wgsl reads.
@group(3) @binding(1) var coarse_clouds: texture_2d<f32>;
@group(3) @binding(2) var coarse_distance: texture_2d<f32>;
@group(3) @binding(3) var history_in: texture_2d<f32>;
@group(3) @binding(4) var history_linear: sampler;
@group(3) @binding(5) var temporal_host_depth: texture_2d<f32>;
@group(3) @binding(6) var history_out: texture_storage_2d<rgba16float, write>;
// Distance from its frame's camera to the cloud each history pixel shows (0: none).
@group(3) @binding(7) var history_distance_in: texture_2d<f32>;
@group(3) @binding(8) var history_distance_out: texture_storage_2d<r32float, write>;

// Moves q toward the centre of the box [lo, hi] until it lies inside (Pedersen 2016, "Temporal
// Reprojection Anti-Aliasing in INSIDE", clipping rather than clamping).
fn temporal_clip(q: vec4<f32>, lo: vec4<f32>, hi: vec4<f32>) -> vec4<f32> {
    let centre = 0.5 * (hi + lo);
    let extent = 0.5 * (hi - lo) + 1.0e-5;
    let v = q - centre;
    let a = abs(v / extent);
    let m = max(max(a.x, a.y), max(a.z, a.w));
    return select(q, centre + v / m, m > 1.0);
}

// The history at uv through a Catmull-Rom bicubic filter, nine bilinear taps (Jimenez 2016,
// "Filmic SMAA", SIGGRAPH course; weights of Catmull & Rom 1974). A moving camera resamples the
// history every frame: bilinear resampling blurs it a little more each time, the bicubic does not.
// Not clamped at zero: the filter keeps an image's mean, its ringing at an edge averages out over
// frames, and a clamp would not: a cloud base's transmittance (near 0) took only the upward half
// of its ringing every frame while the camera climbed toward it, and the base's lower edge
// brightened (LDR luma +0.0065 over the rows of the edge at frame 237 of the fly-through, +0.0021
// unclamped; the full march's -0.0020). The compositor clamps what it shows.
fn temporal_history_bicubic(uv: vec2<f32>) -> vec4<f32> {
    let size = vec2<f32>(textureDimensions(history_in));
    let pos = uv * size - 0.5;
    let p1 = floor(pos) + 0.5;
    let f = pos - floor(pos);
    let w0 = f * (-0.5 + f * (1.0 - 0.5 * f));
    let w1 = 1.0 + f * f * (-2.5 + 1.5 * f);
    let w2 = f * (0.5 + f * (2.0 - 1.5 * f));
    let w3 = f * f * (-0.5 + 0.5 * f);
    let w12 = w1 + w2;
    let t0 = (p1 - 1.0) / size;
    let t3 = (p1 + 2.0) / size;
    let t12 = (p1 + w2 / w12) / size;
    var sum = vec4<f32>(0.0);
    for (var j = 0; j < 3; j++) {
        let y = select(select(t3.y, t12.y, j == 1), t0.y, j == 0);
        let wy = select(select(w3.y, w12.y, j == 1), w0.y, j == 0);
        sum += textureSampleLevel(history_in, history_linear, vec2<f32>(t0.x, y), 0.0) * (w0.x * wy);
        sum += textureSampleLevel(history_in, history_linear, vec2<f32>(t12.x, y), 0.0) * (w12.x * wy);
        sum += textureSampleLevel(history_in, history_linear, vec2<f32>(t3.x, y), 0.0) * (w3.x * wy);
    }
    return sum;
}

// A cloud distance as the disocclusion test compares it: the far distance where there is none (0).
fn temporal_distance_or_far(distance_m: f32) -> f32 {
    return select(frame.far_m, distance_m, distance_m > 0.0);
}

// Whether the history at uv shows a cloud this pixel's neighbourhood sees. Either the cloud it
// recorded can hardly have moved against what lies behind it (the camera's step, seen from that
// cloud, spans under half a pixel: nothing it hid can have come out), or the distance it recorded
// lies within the range [lo_m, hi_m] of the distances of this frame's nearby rays, widened by the
// distance tolerance and by the camera's step. A range, not one interpolated distance: the rays
// move from sub-pixel to sub-pixel every frame, and at the edges of clouds at different distances
// the interpolated distance jumps with them; and a cloud thinner than the rays' spacing is missed
// by all of them in most frames. Either would drop good history and leave the interpolated
// estimate (a blur, or a cloud seen only at this frame's rays: the grid) in its place.
fn temporal_same_cloud(uv: vec2<f32>, pixel: vec2<f32>, lo_m: f32, hi_m: f32) -> bool {
    let size = vec2<f32>(textureDimensions(history_distance_in));
    let texel = clamp(vec2<i32>(uv * size), vec2<i32>(0), vec2<i32>(size) - 1);
    let recorded_m = temporal_distance_or_far(textureLoad(history_distance_in, texel, 0).x);
    let moved_m = distance(frame.camera_position_m, temporal.prev_camera_position_m);
    let tolerance = temporal.distance_tolerance;
    let in_range = recorded_m >= lo_m * (1.0 - tolerance) - moved_m && recorded_m <= hi_m * (1.0 + tolerance) + moved_m;
    return temporal_parallax_px(pixel, recorded_m) < 0.5 || in_range;
}

// How far, in pixels, the camera's step since the previous frame moved a cloud `distance_m` away
// against the far background: the part of the history's motion its reprojection can get wrong
// (turning the camera moves everything alike, and reprojects exactly).
fn temporal_parallax_px(pixel: vec2<f32>, distance_m: f32) -> f32 {
    let moved_m = distance(frame.camera_position_m, temporal.prev_camera_position_m);
    let pixel_rad = distance(frame_ray_direction(pixel), frame_ray_direction(pixel + vec2<f32>(0.0, 1.0)));
    return moved_m / (distance_m * pixel_rad);
}

// Squared distance in pixels from pixel `px` to the nearest ray of this frame's grid (one through
// pixel c * divisor + grid_subpixel of every block c).
fn temporal_ray_distance2(px: vec2<u32>) -> f32 {
    let n = vec2<i32>(i32(frame.grid_divisor));
    let along = ((vec2<i32>(px) - vec2<i32>(frame.grid_subpixel)) % n + n) % n;
    let nearest = vec2<f32>(select(along, along - n, 2 * along > n));
    return dot(nearest, nearest);
}

// How much of this frame's estimate a pixel takes: the fresh weight at a ray's own pixel, falling
// off as a Gaussian of TEMPORAL_RAY_SIGMA_PX with the distance to the nearest ray, to the
// unmarched weight far from every ray. Every pixel meets every offset from the rays once per
// divisor^2 frames, so all pixels take in new samples at one rate and no grid shows; a ray's
// sample spreads over the pixels around it as a soft bump, not a dot (Yang et al. 2009,
// "Amortized supersampling": weights by the distance to the new sample). Where the camera's step
// moves the history, the bump widens and its peak rises to 1 (a ray replaces the history there):
// the view changes under a moving camera from frame to frame, and a history that lags it shows
// as a haze over the clouds the camera flies toward.
fn temporal_new_weight(px: vec2<u32>, moving: f32) -> f32 {
    let sigma = mix(TEMPORAL_RAY_SIGMA_PX, TEMPORAL_MOVING_RAY_SIGMA_PX, moving);
    let fresh = mix(temporal.fresh_weight, 1.0, moving);
    return fresh * exp(-temporal_ray_distance2(px) / (2.0 * sigma * sigma));
}

@compute @workgroup_size(8, 8)
fn resolve_clouds(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(frame.viewport_px);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let divisor = frame.grid_divisor;
    let pixel = vec2<f32>(id.xy) + 0.5;
    let host_m = frame_depth_distance(pixel, textureLoad(temporal_host_depth, vec2<i32>(id.xy), 0).x);
    // The estimate from this frame's rays: a ray's own sample at its pixel, interpolated between.
    let estimate = upsample_cloud(id.xy, host_m);
    let current = estimate.radiance_transmittance;
    let cloud_m = estimate.distance_m;
    // The grid texel nearest the pixel, the centre of the neighbourhood.
    let own = vec2<i32>(floor((pixel - 0.5 - vec2<f32>(frame.grid_subpixel)) / f32(divisor) + 0.5));
    // Neighbourhood statistics of the current grid: the spread sigma of the seed's ClipAABB, and
    // the range of cloud distances its rays see.
    var m1 = vec4<f32>(0.0);
    var m2 = vec4<f32>(0.0);
    var lo_m = frame.far_m;
    var hi_m = 0.0;
    for (var y = -1; y <= 1; y++) {
        for (var x = -1; x <= 1; x++) {
            let texel = upsample_grid_texel(own + vec2<i32>(x, y));
            let v = textureLoad(coarse_clouds, texel, 0);
            m1 += v;
            m2 += v * v;
            let seen_m = temporal_distance_or_far(textureLoad(coarse_distance, texel, 0).x);
            lo_m = min(lo_m, seen_m);
            hi_m = max(hi_m, seen_m);
        }
    }
    let mean = m1 / 9.0;
    let sigma = sqrt(abs(m2 / 9.0 - mean * mean));
    // Reproject: where the cloud this pixel sees was in the previous frame, at its estimated
    // distance (the far distance where there is none), moved back against the wind.
    let d = frame_ray_direction(pixel);
    let distance_m = temporal_distance_or_far(cloud_m);
    let world = frame.camera_position_m + d * distance_m - vec3<f32>(temporal.wind_shift_m.x, 0.0, temporal.wind_shift_m.y);
    let clip = temporal.prev_clip_from_world * vec4<f32>(world, 1.0);
    let ndc = clip.xy / clip.w;
    let uv = vec2<f32>(0.5 + 0.5 * ndc.x, 0.5 - 0.5 * ndc.y);
    let on_screen = clip.w > 0.0 && all(uv >= vec2<f32>(0.0)) && all(uv <= vec2<f32>(1.0));
    var result = current;
    if temporal.history_valid == 1u && on_screen && temporal_same_cloud(uv, pixel, lo_m, hi_m) {
        let gamma = temporal.clip_gamma;
        let reprojected = temporal_history_bicubic(uv);
        // The plain estimate gave the distance to reproject at; on the coarsest grid its radiance
        // is taken again with the history as the guide (select, not a branch on the uniform:
        // lavapipe recompiles shaders that branch on a uniform alone).
        let guided = select(0.0, 1.0, divisor >= TEMPORAL_GUIDED_DIVISOR);
        let guide = UpsampleGuide(reprojected, gamma * sigma + 1.0e-4, guided);
        let current = upsample_cloud_guided(id.xy, host_m, guide).radiance_transmittance;
        // The box is centred on this pixel's own estimate, which varies smoothly from pixel to
        // pixel, rather than on the block's mean, which would print the grid's blocks into it.
        let clipped = temporal_clip(reprojected, current - gamma * sigma, current + gamma * sigma);
        // The history is clipped as far as the camera's step moved it against the background:
        // where the view holds still or turns it is the better estimate (this frame's sparse rays
        // miss features thinner than their spacing, and a box from them would erase those features
        // everywhere but at this frame's rays: the grid); where it shifts by parallax, its
        // reprojection at an estimated distance may show what is no longer there.
        let moving = min(temporal_parallax_px(pixel, distance_m) / TEMPORAL_CLIP_MOTION_PX, 1.0);
        let history = mix(reprojected, clipped, moving);
        // lerp(history, estimate, w), w by the pixel's distance to this frame's nearest ray: at a
        // ray's own pixel the estimate is its sample; between rays, where the history moves and is
        // less to be trusted, the interpolated estimate is taken over a wider bump.
        result = mix(history, current, temporal_new_weight(id.xy, moving));
    }
    // Stored rounded at random (frame_round_to_half): the steady history is a mean with a weight
    // of 0.05 a frame, whose updates nearest-rounding to half floats lost (a still view settled
    // 0.1 % darker than its own march, FLIP 0.0185 against the full march's 0.0146).
    // White noise, independent of the rays' offsets (the blue noise), which set the value.
    let rounding = noise_hash_to_unit(noise_hash_cell(vec3<i32>(vec2<i32>(id.xy), i32(frame.frame_index)), TEMPORAL_ROUNDING_SEED));
    textureStore(history_out, vec2<i32>(id.xy), frame_round_to_half(result, rounding));
    textureStore(history_distance_out, vec2<i32>(id.xy), vec4<f32>(cloud_m, 0.0, 0.0, 0.0));
}
