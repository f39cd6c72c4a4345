// Tileable 3D noise: the GPU twin of field/noise.rs (see there for sources). Only integer hashing
// and plain float arithmetic, so both produce the same 8-bit texels.

fn noise_pcg_hash(x: u32) -> u32 {
    let state = x * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

fn noise_hash_cell(cell: vec3<i32>, seed: u32) -> u32 {
    let h = noise_pcg_hash(seed ^ noise_pcg_hash(u32(cell.z)));
    return noise_pcg_hash(u32(cell.x) ^ noise_pcg_hash(u32(cell.y) ^ h));
}

fn noise_hash_to_unit(h: u32) -> f32 {
    return f32(h >> 8u) * (1.0 / 16777216.0);
}

fn noise_wrap(cell: vec3<i32>, period: i32) -> vec3<i32> {
    return ((cell % vec3<i32>(period)) + vec3<i32>(period)) % vec3<i32>(period);
}

fn noise_gradient(h: u32) -> vec3<f32> {
    switch h % 12u {
        case 0u: { return vec3<f32>(1.0, 1.0, 0.0); }
        case 1u: { return vec3<f32>(-1.0, 1.0, 0.0); }
        case 2u: { return vec3<f32>(1.0, -1.0, 0.0); }
        case 3u: { return vec3<f32>(-1.0, -1.0, 0.0); }
        case 4u: { return vec3<f32>(1.0, 0.0, 1.0); }
        case 5u: { return vec3<f32>(-1.0, 0.0, 1.0); }
        case 6u: { return vec3<f32>(1.0, 0.0, -1.0); }
        case 7u: { return vec3<f32>(-1.0, 0.0, -1.0); }
        case 8u: { return vec3<f32>(0.0, 1.0, 1.0); }
        case 9u: { return vec3<f32>(0.0, -1.0, 1.0); }
        case 10u: { return vec3<f32>(0.0, 1.0, -1.0); }
        default: { return vec3<f32>(0.0, -1.0, -1.0); }
    }
}

fn noise_perlin_corner(c: vec3<i32>, f: vec3<f32>, o: vec3<i32>, period: i32, seed: u32) -> f32 {
    return dot(noise_gradient(noise_hash_cell(noise_wrap(c + o, period), seed)), f - vec3<f32>(o));
}

fn noise_perlin(p: vec3<f32>, period: i32, seed: u32) -> f32 {
    let cell = floor(p);
    let f = p - cell;
    let c = vec3<i32>(cell);
    let u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    let x00 = mix(noise_perlin_corner(c, f, vec3<i32>(0, 0, 0), period, seed), noise_perlin_corner(c, f, vec3<i32>(1, 0, 0), period, seed), u.x);
    let x10 = mix(noise_perlin_corner(c, f, vec3<i32>(0, 1, 0), period, seed), noise_perlin_corner(c, f, vec3<i32>(1, 1, 0), period, seed), u.x);
    let x01 = mix(noise_perlin_corner(c, f, vec3<i32>(0, 0, 1), period, seed), noise_perlin_corner(c, f, vec3<i32>(1, 0, 1), period, seed), u.x);
    let x11 = mix(noise_perlin_corner(c, f, vec3<i32>(0, 1, 1), period, seed), noise_perlin_corner(c, f, vec3<i32>(1, 1, 1), period, seed), u.x);
    return mix(mix(x00, x10, u.y), mix(x01, x11, u.y), u.z);
}

fn noise_worley(p: vec3<f32>, period: i32, seed: u32) -> f32 {
    let cell = floor(p);
    let c = vec3<i32>(cell);
    var nearest_sq = 1.0e9;
    for (var dz = -1; dz <= 1; dz++) {
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                let o = vec3<i32>(dx, dy, dz);
                let h = noise_hash_cell(noise_wrap(c + o, period), seed);
                let feature = vec3<f32>(
                    noise_hash_to_unit(h),
                    noise_hash_to_unit(noise_pcg_hash(h)),
                    noise_hash_to_unit(noise_pcg_hash(h ^ 0x9e3779b9u)),
                );
                let d = cell + vec3<f32>(o) + feature - p;
                nearest_sq = min(nearest_sq, dot(d, d));
            }
        }
    }
    return 1.0 - min(sqrt(nearest_sq), 1.0);
}

fn noise_worley_fbm(uvw: vec3<f32>, cells: i32, seed: u32) -> f32 {
    return 0.625 * noise_worley(uvw * f32(cells), cells, seed)
        + 0.25 * noise_worley(uvw * f32(2 * cells), 2 * cells, seed ^ 0x51u)
        + 0.125 * noise_worley(uvw * f32(4 * cells), 4 * cells, seed ^ 0xa3u);
}

fn noise_perlin_fbm01(uvw: vec3<f32>, cells: i32, seed: u32) -> f32 {
    let sum = noise_perlin(uvw * f32(cells), cells, seed)
        + 0.5 * noise_perlin(uvw * f32(2 * cells), 2 * cells, seed ^ 0x51u)
        + 0.25 * noise_perlin(uvw * f32(4 * cells), 4 * cells, seed ^ 0xa3u);
    return 0.5 + 0.5 * tanh(2.4 * sum); // 2 PERLIN_CONTRAST
}

fn noise_remap(value: f32, lo0: f32, hi0: f32, lo1: f32, hi1: f32) -> f32 {
    return lo1 + (value - lo0) * (hi1 - lo1) / (hi0 - lo0);
}

fn noise_base_texel(seed: u32, texel: vec3<i32>) -> vec4<f32> {
    let uvw = (vec3<f32>(texel) + 0.5) / 128.0;
    let g = noise_worley_fbm(uvw, 4, seed ^ 0x1000u);
    let b = noise_worley_fbm(uvw, 8, seed ^ 0x2000u);
    let a = noise_worley_fbm(uvw, 16, seed ^ 0x3000u);
    let p = noise_perlin_fbm01(uvw, 4, seed ^ 0x4000u);
    return vec4<f32>(noise_remap(p, g - 1.0, 1.0, 0.0, 1.0), g, b, a);
}

fn noise_detail_texel(seed: u32, texel: vec3<i32>) -> vec4<f32> {
    let uvw = (vec3<f32>(texel) + 0.5) / 32.0;
    return vec4<f32>(
        noise_worley_fbm(uvw, 2, seed ^ 0x5000u),
        noise_worley_fbm(uvw, 4, seed ^ 0x6000u),
        noise_worley_fbm(uvw, 8, seed ^ 0x7000u),
        1.0,
    );
}

fn noise_curl_potential(seed: u32, texel: vec3<i32>, dx: i32, dy: i32) -> f32 {
    let uv = (vec3<f32>(texel + vec3<i32>(dx, dy, 0)) + 0.5) / 128.0;
    return noise_perlin_fbm01(vec3<f32>(uv.x, uv.y, 0.0), 4, seed ^ 0x8000u);
}

fn noise_curl_texel(seed: u32, texel: vec3<i32>) -> vec4<f32> {
    let scale = 2.0; // CURL_GAIN
    let vx = (noise_curl_potential(seed, texel, 0, 1) - noise_curl_potential(seed, texel, 0, -1)) * scale;
    let vy = -(noise_curl_potential(seed, texel, 1, 0) - noise_curl_potential(seed, texel, -1, 0)) * scale;
    return vec4<f32>(0.5 + 0.5 * vx, 0.5 + 0.5 * vy, 0.5, 1.0);
}

fn noise_pack_unorm8(v: vec4<f32>) -> u32 {
    let q = vec4<u32>(floor(clamp(v, vec4<f32>(0.0), vec4<f32>(1.0)) * 255.0 + 0.5));
    return q.x | (q.y << 8u) | (q.z << 16u) | (q.w << 24u);
}
