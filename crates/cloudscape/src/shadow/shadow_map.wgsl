// Reading the clouds' shadow map (shadow/mod.rs), as functions of the map's placement, its texture,
// a filtering sampler and the sun: the environment (environment.wgsl) reads its own bindings
// through them, and a host's shaders (bevy_cloudscape's materials) read a copy bound in their own
// group by the same code.

// Where the map lies and what it holds: the twin of ShadowParams (CloudShadowUniform).
struct CloudShadow {
    centre_m: vec2<f32>,       // world xz of the map's centre (under the viewpoint)
    half_extent_m: f32,        // the map reaches this far from its centre on the ground plane
    warp: f32,                 // texel size at the centre over the mean texel size (1: no warp)
    bottom_y_m: f32,           // world y below which the whole cloud column lies above
    top_y_m: f32,              // world y above which no cloud lies
    sun_y: f32,                // sun direction's y, at least SHADOW_MIN_SUN_Y
    enabled: u32,              // 0: no clouds, the map reads zero
    steps_per_checkpoint: u32, // samples of the coarse field between two checkpoints
    pad0: u32,
    pad: vec2<u32>,
}

// Texel coordinate in [-1, 1] of ground-plane offset x (in half extents, -1..1) in a map of warp
// k: the inverse of x = s (k + (1 - k) |s|) (ShadowParams::coord_of).
// Branch-free on purpose: lavapipe (Mesa 22.3) recompiles a shader with a branch on uniform values
// alone whenever those values change, and leaks each compilation (docs/hardening.md, "Soak").
fn cloud_shadow_coord(x: f32, k: f32) -> f32 {
    let a = abs(x);
    let warped = (-k + sqrt(k * k + 4.0 * (1.0 - k) * a)) / (2.0 * max(1.0 - k, 1e-6));
    return sign(x) * select(a, warped, k < 1.0);
}

// Ground-plane offset (in half extents) of texel coordinate s in a map of warp k:
// x = s (k + (1 - k) |s|), fine texels near the viewpoint and coarse ones far away
// (ShadowParams::offset_of).
fn cloud_shadow_offset(s: f32, k: f32) -> f32 {
    return s * (k + (1.0 - k) * abs(s));
}

// Cloud optical depth above height y from the map's four checkpoints (rgba at bottom + 0, 1/4, 1/2
// and 3/4 of the span; zero at its top), read in `layer` of `map` at ground-plane point g: linear
// between checkpoints (ShadowParams::depth_above).
fn cloud_shadow_read(
    s: CloudShadow,
    map: texture_2d_array<f32>,
    map_sampler: sampler,
    g: vec2<f32>,
    y: f32,
    layer: i32,
) -> f32 {
    if s.enabled == 0u || y >= s.top_y_m {
        return 0.0;
    }
    let x = (g - s.centre_m) / s.half_extent_m;
    if any(abs(x) > vec2<f32>(1.0)) {
        return 0.0;
    }
    let coord = vec2<f32>(cloud_shadow_coord(x.x, s.warp), cloud_shadow_coord(x.y, s.warp));
    let checkpoints = textureSampleLevel(map, map_sampler, coord * 0.5 + 0.5, layer, 0.0);
    let f = clamp((y - s.bottom_y_m) / (s.top_y_m - s.bottom_y_m), 0.0, 1.0) * 4.0;
    var values = array<f32, 5>(checkpoints.x, checkpoints.y, checkpoints.z, checkpoints.w, 0.0);
    let i = min(u32(f), 3u);
    return mix(values[i], values[i + 1u], f - f32(i));
}

// Optical depth of the clouds between world point p and the sun (unit vector toward it), read in
// the map's sun layer at p's ground-plane projection along the sun (ShadowParams::ground_of).
fn cloud_shadow_sun_optical_depth(
    s: CloudShadow,
    map: texture_2d_array<f32>,
    map_sampler: sampler,
    sun_direction: vec3<f32>,
    p: vec3<f32>,
) -> f32 {
    let g = p.xz - sun_direction.xz * (p.y / s.sun_y);
    return cloud_shadow_read(s, map, map_sampler, g, p.y, 0);
}
