// Bakes the optical-depth table of the reference particle (particles/gpu.rs): the particle's
// noise into a voxel buffer, then the optical-mass ratio of every chord through it, packed two 16-bit
// floats per word in rows padded for copy_buffer_to_texture. A buffer rather than a storage
// texture keeps the GL backend working. A third entry samples the baked texture at given chords,
// so tests can check the look-up against its CPU twin.

struct ParticleBake {
    // (start zeniths, start azimuths, direction zeniths, direction azimuths).
    table_dims: vec4<u32>,
    shape: ParticleShape,
    style: u32,
    seed: u32,
    volume_size: u32,
    row_pitch_words: u32,
    steps_per_diameter: u32,
    query_count: u32,
    reserved: vec2<u32>,
}

@group(3) @binding(0) var<uniform> bake: ParticleBake;
@group(3) @binding(1) var<storage, read_write> noise_voxels: array<f32>;
@group(3) @binding(2) var<storage, read_write> optical_depth_words: array<u32>;
// The optical-depth table that particle_lookup.wgsl reads.
@group(3) @binding(3) var optical_depth_lut: texture_3d<f32>;
@group(3) @binding(4) var optical_depth_sampler: sampler;
@group(3) @binding(5) var<storage, read> chord_mean_density: array<f32>;

@compute @workgroup_size(4, 4, 4)
fn bake_particle_noise(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = bake.volume_size;
    if any(id >= vec3<u32>(n)) {
        return;
    }
    let p = (vec3<f32>(id) + 0.5) * (2.0 / f32(n)) - 1.0;
    noise_voxels[id.x + n * (id.y + n * id.z)] = particle_noise_input(p, bake.style, bake.seed, bake.shape);
}

fn voxel(c: vec3<i32>) -> f32 {
    let n = i32(bake.volume_size);
    return noise_voxels[u32(c.x + n * (c.y + n * c.z))];
}

// Trilinear noise, clamped to the edge voxels: NoiseVolume::sample.
fn volume_noise(p: vec3<f32>) -> f32 {
    let n = i32(bake.volume_size);
    let x = clamp((p + 1.0) * 0.5 * f32(n) - 0.5, vec3<f32>(0.0), vec3<f32>(f32(n - 1)));
    let base = min(vec3<i32>(floor(x)), vec3<i32>(max(n - 2, 0)));
    let f = x - vec3<f32>(base);
    let x00 = mix(voxel(base), voxel(base + vec3<i32>(1, 0, 0)), f.x);
    let x10 = mix(voxel(base + vec3<i32>(0, 1, 0)), voxel(base + vec3<i32>(1, 1, 0)), f.x);
    let x01 = mix(voxel(base + vec3<i32>(0, 0, 1)), voxel(base + vec3<i32>(1, 0, 1)), f.x);
    let x11 = mix(voxel(base + vec3<i32>(0, 1, 1)), voxel(base + vec3<i32>(1, 1, 1)), f.x);
    return mix(mix(x00, x10, f.y), mix(x01, x11, f.y), f.z);
}

// The stored value of texel `t`: OpticalDepthLayout::texel_ray, chord_optical_mass, ChordProfile::ratio.
fn texel_optical_mass(t: vec3<u32>) -> f32 {
    let f = vec4<f32>(bake.table_dims);
    let start_zenith = (f32(t.y) + 0.5) / f.x * PI;
    let start_azimuth = (f32(t.x) + 0.5) / f.y * 2.0 * PI;
    let slice = t.z / bake.table_dims.z;
    let j = t.z % bake.table_dims.z;
    let dir_zenith = (f32(j) + 0.5) / f.z * 0.5 * PI;
    let dir_azimuth = (f32(slice) + 0.5) / f.w * 2.0 * PI;
    let sz = sin(start_zenith);
    let cz = cos(start_zenith);
    let sa = sin(start_azimuth);
    let ca = cos(start_azimuth);
    let normal = vec3<f32>(sz * ca, sz * sa, cz);
    let tangent_zenith = vec3<f32>(cz * ca, cz * sa, -sz);
    let tangent_azimuth = vec3<f32>(-sa, ca, 0.0);
    let dir = -cos(dir_zenith) * normal
        + sin(dir_zenith) * (cos(dir_azimuth) * tangent_zenith + sin(dir_azimuth) * tangent_azimuth);
    // The chord from a point on the sphere: t_out = -2 (entry . dir).
    let b = dot(normal, dir);
    let c = dot(normal, normal) - 1.0;
    let disc = b * b - c;
    if disc <= 0.0 {
        return 0.0;
    }
    let length = max(-b + sqrt(disc), 0.0);
    let steps = max(u32(ceil(length * 0.5 * f32(bake.steps_per_diameter))), 2u);
    let dt = length / f32(steps);
    var sum = 0.0;
    for (var i = 0u; i < steps; i++) {
        let p = normal + dir * ((f32(i) + 0.5) * dt);
        sum += particle_density_with_noise(p, volume_noise(p), bake.style, bake.shape);
    }
    // Stored as the ratio to the direction-averaged density's mass (ChordProfile::ratio).
    return sum * dt / max(chord_mass(normal, dir), 1e-7);
}

// The IEEE binary16 bits of `x`, rounded to nearest even as the CPU's half::f16::from_f32 rounds:
// by hand, since pack2x16float needs a capability some backends lack.
fn f16_bits(x: f32) -> u32 {
    let bits = bitcast<u32>(x);
    let sign = (bits >> 16u) & 0x8000u;
    let exponent = i32((bits >> 23u) & 0xffu) - 112;
    var mantissa = bits & 0x7fffffu;
    if exponent >= 31 {
        return sign | 0x7c00u;
    }
    var shift = 13u;
    var base = sign | (u32(max(exponent, 0)) << 10u);
    if exponent <= 0 {
        // Subnormal: the implicit one joins the mantissa, shifted down further.
        if exponent < -10 {
            return sign;
        }
        mantissa |= 0x800000u;
        shift = u32(14 - exponent);
        base = sign;
    }
    let half = base | (mantissa >> shift);
    let rest = mantissa & ((1u << shift) - 1u);
    let midpoint = 1u << (shift - 1u);
    if rest > midpoint || (rest == midpoint && (half & 1u) == 1u) {
        return half + 1u;
    }
    return half;
}

@compute @workgroup_size(8, 8, 1)
fn bake_optical_depth(@builtin(global_invocation_id) id: vec3<u32>) {
    let dims = vec3<u32>(bake.table_dims.y, bake.table_dims.x, bake.table_dims.z * bake.table_dims.w);
    let x = id.x * 2u;
    if x >= dims.x || id.y >= dims.y || id.z >= dims.z {
        return;
    }
    let first = texel_optical_mass(vec3<u32>(x, id.y, id.z));
    var second = 0.0;
    if x + 1u < dims.x {
        second = texel_optical_mass(vec3<u32>(x + 1u, id.y, id.z));
    }
    let row = id.z * dims.y + id.y;
    optical_depth_words[row * bake.row_pitch_words + id.x] = f16_bits(first) | (f16_bits(second) << 16u);
}

// Look-up probe: chord `i` is (entry, direction) at noise_voxels[6 i .. 6 i + 6], looked up as
// particle `i` sees it (turned by particle_rotation(i)); the optical mass goes to
// noise_voxels[6 * query_count + i].

@compute @workgroup_size(64)
fn probe_optical_depth(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= bake.query_count {
        return;
    }
    let entry = vec3<f32>(noise_voxels[6u * i], noise_voxels[6u * i + 1u], noise_voxels[6u * i + 2u]);
    let dir = vec3<f32>(noise_voxels[6u * i + 3u], noise_voxels[6u * i + 4u], noise_voxels[6u * i + 5u]);
    let turn = particle_rotation(i);
    let local_entry = particle_rotate(turn, entry);
    let local_dir = particle_rotate(turn, dir);
    noise_voxels[6u * bake.query_count + i] = particle_optical_mass(local_entry, local_dir, bake.table_dims);
}
