// One frame's camera and lighting: the twin of frame/mod.rs. Bound by each pass in its own group.

struct Frame {
    world_from_clip: mat4x4<f32>,
    camera_position: vec4<f32>, // xyz (m), far distance (m)
    viewport: vec4<f32>,        // width, height (px), time_s, frame index
    sun_direction: vec4<f32>,   // unit vector toward the sun, cos(angular radius)
    sun_irradiance: vec4<f32>,  // rgb irradiance facing the sun, angular radius (rad)
    sky_zenith: vec4<f32>,      // rgb radiance straight up, gradient exponent
    sky_horizon: vec4<f32>,     // rgb radiance at the horizon, haze extinction (m^-1)
    sky_mean_up: vec4<f32>,     // rgb mean radiance over the upper hemisphere
    ground_albedo: vec4<f32>,   // rgb albedo, 1 if there is a ground
    ground_radiance: vec4<f32>, // rgb radiance leaving the unshadowed ground
    cloud_optics: vec4<f32>,    // mean cosine g of the cloud droplets' phase function, 0, 0, 0
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

// Radiance `radiance` seen from `distance_m` away through the haze: it fades toward the horizon
// radiance as exp(-haze distance), weighted by `coverage` (1 - transmittance for clouds).
fn frame_haze(frame: Frame, radiance: vec3<f32>, coverage: f32, distance_m: f32) -> vec3<f32> {
    let clear = exp(-frame.sky_horizon.w * distance_m);
    return radiance * clear + frame.sky_horizon.xyz * coverage * (1.0 - clear);
}

// A per-pixel, per-frame value in [0, 1): white noise from the PCG hash (noise.wgsl), which turns
// step banding into grain without the visible pattern of structured dithers at low sample counts.
fn frame_pixel_jitter(pixel: vec2<u32>, index: u32) -> f32 {
    return noise_hash_to_unit(noise_pcg_hash(pixel.x ^ noise_pcg_hash(pixel.y ^ noise_pcg_hash(index))));
}

// Eddington (two-stream) diffuse transmittance of a conservatively scattering slab of optical depth
// tau: 1 / (1 + 3/4 (1 - g) tau) (e.g. Bohren 1987, "Multiple scattering of light and some of its
// observable consequences", Am. J. Phys. 55): diffuse light is dimmed by the transport optical
// depth (1 - g) tau, and only algebraically, not exponentially.
fn frame_diffuse_transmittance(frame: Frame, tau: f32) -> f32 {
    return 1.0 / (1.0 + 0.75 * (1.0 - frame.cloud_optics.x) * tau);
}
