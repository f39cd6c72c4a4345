// Fills a storage buffer with one noise texture's 8-bit RGBA texels (kind 0 base, 1 detail,
// 2 curl), rows padded to `row_pitch_texels`, ready for copy_buffer_to_texture. Writing through a
// buffer rather than a 3D storage texture keeps the GL backend working (wgpu-and-crates.md).

struct NoiseGenParams {
    kind: u32,
    seed: u32,
    size: u32,
    row_pitch_texels: u32,
    depth: u32,
}

@group(3) @binding(0) var<uniform> noise_gen: NoiseGenParams;
@group(3) @binding(1) var<storage, read_write> noise_texels: array<u32>;

@compute @workgroup_size(4, 4, 4)
fn generate_noise(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id >= vec3<u32>(noise_gen.size, noise_gen.size, noise_gen.depth)) {
        return;
    }
    let texel = vec3<i32>(id);
    var value: vec4<f32>;
    switch noise_gen.kind {
        case 0u: { value = noise_base_texel(noise_gen.seed, texel); }
        case 1u: { value = noise_detail_texel(noise_gen.seed, texel); }
        default: { value = noise_curl_texel(noise_gen.seed, texel); }
    }
    let index = (id.z * noise_gen.size + id.y) * noise_gen.row_pitch_texels + id.x;
    noise_texels[index] = noise_pack_unorm8(value);
}
