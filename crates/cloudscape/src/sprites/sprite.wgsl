// What the sprite passes share (sprites/render.rs): the view a pass draws from, the host-depth
// test, and the two blended targets every sprite pass writes.

// One view: the camera of the frame (the main pass) or of an impostor of the ring.
struct View {
    clip_from_world: mat4x4<f32>,   // world to clip for this view
    eye_m: vec3<f32>,               // the view's eye, m
    host_depth_test: u32,           // 1: fade against the host's depth (main pass); 0: impostors
    forward: vec3<f32>,             // unit view direction (locked sprites face along it)
    lock_distance_m: f32,           // sprites nearer than this are locked (Wang 2003)
    target_offset_ndc: vec2<f32>,   // shift that puts the output's rays at the texel centres
    fade_start_m: f32,              // clouds fade out with horizontal distance from here...
    fade_end_m: f32,                // ...to here
}

// What a sprite pass writes per fragment, both blended "over" with premultiplied alpha (back to
// front): premultiplied radiance and opacity; and (opacity x distance in km, opacity), whose
// ratio after blending is the opacity-weighted mean distance the cloud output holds.
struct SpriteTargets {
    @location(0) radiance: vec4<f32>,
    @location(1) distance: vec4<f32>,
}

// Distance units of the distance target (km in f16 keeps 3 digits out to 65,000 km).
const SPRITE_DISTANCE_UNIT_M: f32 = 1000.0;

// The targets of a fragment of opacity `alpha`, premultiplied radiance `radiance`, `distance_m`
// from the eye.
fn sprite_targets(radiance: vec3<f32>, alpha: f32, distance_m: f32) -> SpriteTargets {
    var out: SpriteTargets;
    out.radiance = vec4<f32>(radiance, alpha);
    out.distance = vec4<f32>(alpha * distance_m / SPRITE_DISTANCE_UNIT_M, alpha, 0.0, alpha);
    return out;
}

// Clip position of world point `p` in `view`, shifted onto the output's rays.
fn sprite_clip(view: View, p: vec3<f32>) -> vec4<f32> {
    var clip = view.clip_from_world * vec4<f32>(p, 1.0);
    clip = vec4<f32>(clip.xy + view.target_offset_ndc * clip.w, clip.zw);
    return clip;
}

// The full-resolution pixel whose ray output texel `texel` holds (the frame's sample grid).
fn sprite_frame_pixel(texel: vec2<f32>) -> vec2<u32> {
    return vec2<u32>(floor(texel)) * frame.grid_divisor + frame.grid_subpixel;
}

// Soft intersection with the host's geometry: 1 well in front of the depth the host stored at the
// fragment's pixel, 0 behind it, ramping over `soft_m`.
fn sprite_host_fade(depth: f32, texel: vec2<f32>, distance_m: f32, soft_m: f32) -> f32 {
    let pixel = vec2<f32>(sprite_frame_pixel(texel)) + 0.5;
    let host_m = frame_depth_distance(pixel, depth);
    return clamp((host_m - distance_m) / soft_m, 0.0, 1.0);
}

// The colour at height fraction `h` of a cloud whose five levels have `colors` at `heights`,
// interpolated linearly between them and held at the ends (shading::level_at, its CPU twin).
fn sprite_level(colors: array<vec4<f32>, 5>, heights: array<f32, 5>, h: f32) -> vec4<f32> {
    if h <= heights[0] {
        return colors[0];
    }
    for (var i = 1u; i < 5u; i++) {
        if h <= heights[i] {
            let t = (h - heights[i - 1u]) / max(heights[i] - heights[i - 1u], 1e-6);
            return mix(colors[i - 1u], colors[i], t);
        }
    }
    return colors[4];
}
