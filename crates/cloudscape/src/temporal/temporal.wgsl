// Temporal reconstruction of undersampled clouds (volumecloud-implementation-detail): the current
// coarse output upsampled with depth awareness, the history reprojected with the previous frame's
// view-projection at the estimated cloud distance, clipped to the current neighbourhood and
// blended. Reads only the cloud-output contract, so it serves every technique.

struct Temporal {
    prev_clip_from_world: mat4x4<f32>,
    prev_camera_position_m: vec3<f32>,
    history_valid: u32,         // 0 on the first frame and after a cut
    wind_shift_m: vec2<f32>,    // how far the wind moved the clouds since the previous frame: x, z
    fresh_weight: f32,          // weight of a pixel's own fresh sample
    clip_gamma: f32,            // half-width of the clip box, in standard deviations
    unmarched_weight: f32,      // weight toward the upsampled estimate of a pixel without a ray
    distance_tolerance: f32,    // history dropped where its cloud lies farther off than this fraction
    reserved: vec2<u32>,
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
    return max(sum, vec4<f32>(0.0));
}

// Whether the history at uv shows the cloud this pixel sees at `world` (`distance_m` from the
// camera; the far distance where there is none): the previous camera saw it at the distance the
// history recorded, within the distance tolerance.
fn temporal_same_cloud(uv: vec2<f32>, world: vec3<f32>, distance_m: f32) -> bool {
    let size = vec2<f32>(textureDimensions(history_distance_in));
    let texel = clamp(vec2<i32>(uv * size), vec2<i32>(0), vec2<i32>(size) - 1);
    let recorded = textureLoad(history_distance_in, texel, 0).x;
    let far = frame.far_m;
    let expected_m = select(far, distance(world, temporal.prev_camera_position_m), distance_m < far);
    let recorded_m = select(far, recorded, recorded > 0.0);
    return abs(recorded_m - expected_m) <= temporal.distance_tolerance * max(recorded_m, expected_m);
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
    let estimate = upsample_cloud(id.xy, host_m);
    var current = estimate.radiance_transmittance;
    var cloud_m = estimate.distance_m;
    // The pixel this frame's ray went through has a sample of its own.
    let own = vec2<i32>(id.xy / divisor);
    let fresh = all(id.xy % divisor == frame.grid_subpixel);
    if fresh {
        current = textureLoad(coarse_clouds, own, 0);
        cloud_m = textureLoad(coarse_distance, own, 0).x;
    }
    // Neighbourhood statistics of the current grid: the spread sigma of the seed's ClipAABB.
    var m1 = vec4<f32>(0.0);
    var m2 = vec4<f32>(0.0);
    for (var y = -1; y <= 1; y++) {
        for (var x = -1; x <= 1; x++) {
            let v = textureLoad(coarse_clouds, upsample_grid_texel(own + vec2<i32>(x, y)), 0);
            m1 += v;
            m2 += v * v;
        }
    }
    let mean = m1 / 9.0;
    let sigma = sqrt(abs(m2 / 9.0 - mean * mean));
    // The box is centred on this pixel's own estimate, which varies smoothly from pixel to pixel,
    // rather than on the block's mean, which would print the grid's blocks into the history.
    let centre = current;
    // Reproject: where the cloud this pixel sees was in the previous frame, at its estimated
    // distance (the far distance where there is none), moved back against the wind.
    let d = frame_ray_direction(pixel);
    let distance_m = select(frame.far_m, cloud_m, cloud_m > 0.0);
    let world = frame.camera_position_m + d * distance_m - vec3<f32>(temporal.wind_shift_m.x, 0.0, temporal.wind_shift_m.y);
    let clip = temporal.prev_clip_from_world * vec4<f32>(world, 1.0);
    let ndc = clip.xy / clip.w;
    let uv = vec2<f32>(0.5 + 0.5 * ndc.x, 0.5 - 0.5 * ndc.y);
    let on_screen = clip.w > 0.0 && all(uv >= vec2<f32>(0.0)) && all(uv <= vec2<f32>(1.0));
    var result = current;
    if temporal.history_valid == 1u && on_screen && temporal_same_cloud(uv, world, distance_m) {
        let gamma = temporal.clip_gamma;
        let history = temporal_clip(temporal_history_bicubic(uv), centre - gamma * sigma, centre + gamma * sigma);
        // lerp(history, current, w): w is the pixel's own-sample weight when it has one; otherwise
        // the seed's per-frame blend toward the upsampled estimate, which bleeds out what clipping
        // let through.
        result = mix(history, current, select(temporal.unmarched_weight, temporal.fresh_weight, fresh));
    }
    textureStore(history_out, vec2<i32>(id.xy), result);
    textureStore(history_distance_out, vec2<i32>(id.xy), vec4<f32>(cloud_m, 0.0, 0.0, 0.0));
}
