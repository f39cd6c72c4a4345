// The rendered clouds, upscaled into the window's viewport: one triangle over the viewport,
// sampled bilinearly. The image holds sRGB-encoded values (the library's display pass).

@group(0) @binding(0) var image: texture_2d<f32>;
@group(0) @binding(1) var image_sampler: sampler;

struct Varyings {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

@vertex
fn blit_vertex(@builtin(vertex_index) index: u32) -> Varyings {
    // (0,0), (2,0), (0,2) in uv: a triangle that covers the viewport.
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    var out: Varyings;
    out.position = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0);
    out.uv = uv;
    return out;
}

// For a target that stores the values as given (Rgba8Unorm, Bgra8Unorm).
@fragment
fn blit_encoded(in: Varyings) -> @location(0) vec4<f32> {
    return vec4<f32>(textureSample(image, image_sampler, in.uv).rgb, 1.0);
}

// For an sRGB target, which encodes on write: decode first (IEC 61966-2-1 sRGB transfer function).
@fragment
fn blit_linear(in: Varyings) -> @location(0) vec4<f32> {
    let c = textureSample(image, image_sampler, in.uv).rgb;
    let low = c / 12.92;
    let high = pow((c + 0.055) / 1.055, vec3<f32>(2.4));
    return vec4<f32>(select(high, low, c <= vec3<f32>(0.04045)), 1.0);
}
