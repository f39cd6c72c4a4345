// Temporal reconstruction of undersampled clouds (volumecloud-implementation-detail): the current
// march grid upsampled with depth awareness, the history reprojected with the previous frame's
// view-projection at the estimated cloud depth, clipped to the current neighbourhood and blended.

struct Temporal {
    prev_clip_from_world: mat4x4<f32>,
    prev_camera_m: vec4<f32>, // the previous frame's camera position (xyz)
    wind_shift_m: vec4<f32>, // how far the wind moved the clouds since the previous frame: x, z (m)
    blend: vec4<f32>,        // weight of a pixel's own fresh sample, clip gamma (sigmas)
    grid: vec4<u32>,         // divisor, sub-pixel x, y updated this frame, 1 if the history is valid
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> temporal: Temporal;
@group(0) @binding(2) var current_clouds: texture_2d<f32>;
@group(0) @binding(3) var current_depth: texture_2d<f32>;
@group(0) @binding(4) var history_in: texture_2d<f32>;
@group(0) @binding(5) var history_linear: sampler;
@group(0) @binding(6) var temporal_host_depth: texture_2d<f32>;
@group(0) @binding(7) var history_out: texture_storage_2d<rgba16float, write>;
// Distance from its frame's camera to the cloud each history pixel shows (0: none).
@group(0) @binding(8) var history_depth_in: texture_2d<f32>;
@group(0) @binding(9) var history_depth_out: texture_storage_2d<r32float, write>;

// The history is trusted where the cloud it shows lies within this fraction of the distance at which
// the current estimate puts it; otherwise it shows something else (a disocclusion, the inside of a
// cloud the camera has left) and is dropped.
const TEMPORAL_DEPTH_TOLERANCE: f32 = 0.25;

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
// history recorded, within TEMPORAL_DEPTH_TOLERANCE.
fn temporal_same_cloud(uv: vec2<f32>, world: vec3<f32>, distance_m: f32) -> bool {
    let size = vec2<f32>(textureDimensions(history_depth_in));
    let texel = clamp(vec2<i32>(uv * size), vec2<i32>(0), vec2<i32>(size) - 1);
    let recorded = textureLoad(history_depth_in, texel, 0).x;
    let far = frame.camera_position.w;
    let expected_m = select(far, distance(world, temporal.prev_camera_m.xyz), distance_m < far);
    let recorded_m = select(far, recorded, recorded > 0.0);
    return abs(recorded_m - expected_m) <= TEMPORAL_DEPTH_TOLERANCE * max(recorded_m, expected_m);
}

fn temporal_grid_texel(texel: vec2<i32>) -> vec2<i32> {
    return clamp(texel, vec2<i32>(0), vec2<i32>(textureDimensions(current_clouds)) - 1);
}

@compute @workgroup_size(8, 8)
fn resolve_clouds(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(frame.viewport.xy);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let divisor = temporal.grid.x;
    let pixel = vec2<f32>(id.xy) + 0.5;
    // Depth-aware upsampling (Yusov 2014): bilinear weights over the four nearest grid samples,
    // zeroed where a sample's cloud lies behind this pixel's host geometry.
    let host = textureLoad(temporal_host_depth, vec2<i32>(id.xy), 0).x;
    var host_m = 3.0e38;
    if host < 1.0 {
        host_m = frame_depth_distance(frame, pixel, host);
    }
    let pos = pixel / f32(divisor) - 0.5;
    let base = floor(pos);
    let f = pos - base;
    var current = vec4<f32>(0.0);
    var cloud_m = 0.0;
    var weight = 0.0;
    var cloud_weight = 0.0;
    for (var k = 0; k < 4; k++) {
        let offset = vec2<i32>(k & 1, k >> 1u);
        let texel = temporal_grid_texel(vec2<i32>(base) + offset);
        let w2 = select(1.0 - f, f, vec2<bool>(offset == vec2<i32>(1)));
        let depth_m = textureLoad(current_depth, texel, 0).x;
        let w = w2.x * w2.y * select(1.0, 0.0, depth_m > host_m) + 1.0e-6;
        let sample = textureLoad(current_clouds, texel, 0);
        current += sample * w;
        weight += w;
        // The cloud's distance averages over the samples that see cloud, by how much they see:
        // a clear sample (distance 0) would pull an edge's distance halfway to the camera.
        cloud_m += depth_m * w * (1.0 - sample.a);
        cloud_weight += w * (1.0 - sample.a);
    }
    current /= weight;
    cloud_m = select(0.0, cloud_m / cloud_weight, cloud_weight > 1.0e-6);
    // The pixel this frame's ray went through has a sample of its own.
    let own = vec2<i32>(id.xy / divisor);
    let fresh = all(id.xy % divisor == temporal.grid.yz);
    if fresh {
        current = textureLoad(current_clouds, own, 0);
        cloud_m = textureLoad(current_depth, own, 0).x;
    }
    // Neighbourhood statistics of the current grid: the spread sigma of the seed's ClipAABB.
    var m1 = vec4<f32>(0.0);
    var m2 = vec4<f32>(0.0);
    for (var y = -1; y <= 1; y++) {
        for (var x = -1; x <= 1; x++) {
            let v = textureLoad(current_clouds, temporal_grid_texel(own + vec2<i32>(x, y)), 0);
            m1 += v;
            m2 += v * v;
        }
    }
    let mean = m1 / 9.0;
    let sigma = sqrt(abs(m2 / 9.0 - mean * mean));
    // The box is centred on this pixel's own estimate, which varies smoothly from pixel to pixel,
    // rather than on the block's mean, which would print the march grid's blocks into the history.
    let centre = current;
    // Reproject: where the cloud this pixel sees was in the previous frame, at its estimated
    // depth (the far distance where there is none), moved back against the wind.
    let d = frame_ray_direction(frame, pixel);
    let distance_m = select(frame.camera_position.w, cloud_m, cloud_m > 0.0);
    let world = frame.camera_position.xyz + d * distance_m - vec3<f32>(temporal.wind_shift_m.x, 0.0, temporal.wind_shift_m.y);
    let clip = temporal.prev_clip_from_world * vec4<f32>(world, 1.0);
    let ndc = clip.xy / clip.w;
    let uv = vec2<f32>(0.5 + 0.5 * ndc.x, 0.5 - 0.5 * ndc.y);
    let on_screen = clip.w > 0.0 && all(uv >= vec2<f32>(0.0)) && all(uv <= vec2<f32>(1.0));
    var result = current;
    if temporal.grid.w == 1u && on_screen && temporal_same_cloud(uv, world, distance_m) {
        let gamma = temporal.blend.y;
        let history = temporal_clip(temporal_history_bicubic(uv), centre - gamma * sigma, centre + gamma * sigma);
        // lerp(history, current, w): w is the pixel's own-sample weight when it has one; otherwise
        // the seed's 0.05 toward the upsampled estimate, which bleeds out what clipping let through.
        result = mix(history, current, select(0.05, temporal.blend.x, fresh));
    }
    textureStore(history_out, vec2<i32>(id.xy), result);
    textureStore(history_depth_out, vec2<i32>(id.xy), vec4<f32>(cloud_m, 0.0, 0.0, 0.0));
}
