// HDR radiance to display: exposure, tone mapping (tonemap.wgsl) and sRGB encoding.

struct Display {
    exposure_scale: f32, // 2^EV
    tonemap_operator: u32, // 0 ACES, 1 AgX
}

@group(3) @binding(0) var<uniform> display: Display;
@group(3) @binding(1) var display_hdr: texture_2d<f32>;
@group(3) @binding(2) var display_out: texture_storage_2d<rgba8unorm, write>;

@compute @workgroup_size(8, 8)
fn display_hdr_image(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(display_hdr);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let radiance = textureLoad(display_hdr, vec2<i32>(id.xy), 0).rgb * display.exposure_scale;
    var mapped: vec3<f32>;
    if display.tonemap_operator == 0u {
        mapped = tonemap_aces(radiance);
    } else {
        mapped = tonemap_agx(radiance);
    }
    textureStore(display_out, vec2<i32>(id.xy), vec4<f32>(linear_to_srgb(clamp(mapped, vec3<f32>(0.0), vec3<f32>(1.0))), 1.0));
}
