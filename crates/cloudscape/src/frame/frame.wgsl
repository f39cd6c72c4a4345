// One frame's camera and lighting: the twin of frame/mod.rs. Bound by each pass in its own group.

struct Frame {
    world_from_clip: mat4x4<f32>,
    camera_position: vec4<f32>, // xyz (m), far distance (m)
    viewport: vec4<f32>,        // width, height (px), time_s, frame index
    sun_direction: vec4<f32>,   // unit vector toward the sun, cos(angular radius)
    sun_irradiance: vec4<f32>,  // rgb irradiance facing the sun, angular radius (rad)
    sky_zenith: vec4<f32>,      // rgb radiance straight up, gradient exponent
    sky_horizon: vec4<f32>,     // rgb radiance at the horizon
    sky_mean_up: vec4<f32>,     // rgb mean radiance over the upper hemisphere
    ground_albedo: vec4<f32>,   // rgb albedo, 1 if there is a ground
    ground_radiance: vec4<f32>, // rgb radiance leaving the unshadowed ground
}

// Unit direction of the ray through pixel coordinates `pixel` (y down), as Frame::camera_ray.
fn frame_ray_direction(frame: Frame, pixel: vec2<f32>) -> vec3<f32> {
    let ndc = vec2<f32>(2.0 * pixel.x / frame.viewport.x - 1.0, 1.0 - 2.0 * pixel.y / frame.viewport.y);
    let far = frame.world_from_clip * vec4<f32>(ndc, 1.0, 1.0);
    return normalize(far.xyz / far.w - frame.camera_position.xyz);
}

// Distance along the ray through `pixel` to the point a depth-buffer value `depth` (0 near, 1 far) stores.
fn frame_depth_distance(frame: Frame, pixel: vec2<f32>, depth: f32) -> f32 {
    let ndc = vec2<f32>(2.0 * pixel.x / frame.viewport.x - 1.0, 1.0 - 2.0 * pixel.y / frame.viewport.y);
    let p = frame.world_from_clip * vec4<f32>(ndc, depth, 1.0);
    return length(p.xyz / p.w - frame.camera_position.xyz);
}

// Sky radiance from direction `dir`: SkyRadiance::radiance.
fn frame_sky_radiance(frame: Frame, dir: vec3<f32>) -> vec3<f32> {
    return mix(frame.sky_horizon.xyz, frame.sky_zenith.xyz, pow(max(dir.y, 0.0), frame.sky_zenith.w));
}

// Interleaved gradient noise (Jimenez 2014, "Next Generation Post Processing in Call of Duty:
// Advanced Warfare"): a per-pixel value in [0, 1) whose neighbours differ, turning banding into
// fine noise.
fn frame_pixel_jitter(pixel: vec2<f32>, index: f32) -> f32 {
    let p = pixel + 5.588238 * index;
    return fract(52.9829189 * fract(dot(p, vec2<f32>(0.06711056, 0.00583715))));
}
