// Builds the clouds' shared light-space map (shadow/mod.rs): per texel, the coarse optical depth
// from four checkpoint heights to the top of the clouds, along the sun (layer 0, binding 0) and
// straight up (layer 1, binding 1). ShadowParams::column.

@group(3) @binding(0) var shadow_sun_out: texture_storage_2d<rgba16float, write>;
@group(3) @binding(1) var shadow_sky_out: texture_storage_2d<rgba16float, write>;

// ShadowParams::checkpoint_y.
fn shadow_checkpoint_y(k: u32) -> f32 {
    let s = environment.shadow;
    return s.bottom_y_m + (s.top_y_m - s.bottom_y_m) * f32(k) / 4.0;
}

// ShadowParams::column: the column from ground point g rising along `rise` (one metre up per unit).
fn shadow_column(g: vec2<f32>, rise: vec3<f32>) -> vec4<f32> {
    let length_per_m = length(rise);
    let dir = rise / length_per_m;
    let base = vec3<f32>(g.x, 0.0, g.y);
    var out = array<f32, 4>(0.0, 0.0, 0.0, 0.0);
    var above = 0.0;
    for (var i = 0u; i < 4u; i++) {
        let k = 3u - i;
        let y0 = shadow_checkpoint_y(k);
        let y1 = shadow_checkpoint_y(k + 1u);
        let span = vec3<f32>(y0 * length_per_m, (y1 - y0) * length_per_m, 1.0);
        above += field_optical_depth_coarse(base, dir, span, environment.shadow.steps_per_checkpoint, 0.5);
        out[k] = above;
    }
    return vec4<f32>(out[0], out[1], out[2], out[3]);
}

@compute @workgroup_size(8, 8)
fn shadow_build(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(shadow_sun_out);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let s = environment.shadow;
    let coord = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size) * 2.0 - 1.0;
    let offset = vec2<f32>(environment_shadow_offset(coord.x), environment_shadow_offset(coord.y));
    let g = s.centre_m + offset * s.half_extent_m;
    let sun = environment.sun_direction;
    let rise = vec3<f32>(sun.x / s.sun_y, 1.0, sun.z / s.sun_y);
    var sun_column = vec4<f32>(0.0);
    var sky_column = vec4<f32>(0.0);
    if s.enabled == 1u {
        sun_column = shadow_column(g, rise);
        sky_column = shadow_column(g, vec3<f32>(0.0, 1.0, 0.0));
    }
    textureStore(shadow_sun_out, id.xy, sun_column);
    textureStore(shadow_sky_out, id.xy, sky_column);
}
