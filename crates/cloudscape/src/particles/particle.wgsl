// The reference particle and its optical-depth look-up: the GPU twins of particles/density.rs and
// particles/optical_depth.rs (see there for the sources and the parameterisation).

const PARTICLE_NOISE_OCTAVES: u32 = 4u;
const PARTICLE_NOISE_LACUNARITY: f32 = 1.7;
const PARTICLE_NOISE_GAIN: f32 = 0.7;
const PARTICLE_NOISE_PERIOD_CELLS: i32 = 64;

// Styles, as ParticleStyle::gpu_index.
const PARTICLE_SMOOTH: u32 = 0u;
const PARTICLE_THRESHOLDED: u32 = 1u;

fn particle_metaball_falloff(r: f32) -> f32 {
    if r >= 1.0 {
        return 0.0;
    }
    let r2 = r * r;
    return ((-4.0 / 9.0 * r2 + 17.0 / 9.0) * r2 - 22.0 / 9.0) * r2 + 1.0;
}

fn particle_noise(p: vec3<f32>, seed: u32, base_cells: f32) -> f32 {
    var sum = 0.0;
    var amplitude = 1.0;
    var total = 0.0;
    var cells = base_cells;
    for (var octave = 0u; octave < PARTICLE_NOISE_OCTAVES; octave++) {
        let offset = vec3<f32>(17.0 + 11.0 * f32(octave));
        sum += amplitude * noise_perlin(p * cells + offset, PARTICLE_NOISE_PERIOD_CELLS, seed ^ octave);
        total += amplitude;
        amplitude *= PARTICLE_NOISE_GAIN;
        cells *= PARTICLE_NOISE_LACUNARITY;
    }
    return sum / total;
}

// The noise the style reads at `p` (ReferenceParticle::noise_input).
fn particle_noise_input(p: vec3<f32>, style: u32, seed: u32, shape: ParticleShape) -> f32 {
    if style == PARTICLE_SMOOTH || style == PARTICLE_THRESHOLDED {
        return particle_noise(p, seed, shape.base_cells);
    }
    return particle_noise(p / max(length(p), 1e-6), seed, shape.base_cells);
}

// Density of the reference particle at `p` (particle space), 0..1, given the style's noise `n`
// there (ReferenceParticle::density_with_noise). `shape` holds the style's constants.
fn particle_density_with_noise(p: vec3<f32>, n: f32, style: u32, shape: ParticleShape) -> f32 {
    let r = length(p);
    if r >= 1.0 {
        return 0.0;
    }
    if style == PARTICLE_SMOOTH {
        return particle_metaball_falloff(r) * clamp(1.0 + shape.a * (n - 1.0) * 0.5, 0.0, 1.0);
    }
    if style == PARTICLE_THRESHOLDED {
        return smoothstep(shape.b, shape.c, particle_metaball_falloff(r) * (1.0 + shape.a * n));
    }
    return clamp((shape.a + shape.b * n - r) / shape.c, 0.0, 1.0);
}

// The optical mass of the particle's direction-averaged density along the chord from `entry` (on
// the unit sphere) along the inward `dir`, from the mean densities of ChordProfile at
// `mean_density[i]`, u = i / (nodes - 1): ChordProfile::mass. A function, not a table read, so
// the caller passes the two neighbouring nodes (particle_chord_nodes picks them).
fn particle_chord_position(entry: vec3<f32>, dir: vec3<f32>, nodes: u32) -> vec2<f32> {
    let u = clamp(-dot(entry, dir), 0.0, 1.0);
    let x = u * f32(nodes - 1u);
    let i = min(u32(x), nodes - 2u);
    return vec2<f32>(f32(i), x - f32(i));
}

// The random orientation of particle `id` as a unit quaternion (x, y, z, w): particle_rotation in
// optical_depth.rs (Shoemake 1992, uniform over all rotations).
fn particle_rotation(id: u32) -> vec4<f32> {
    let h1 = noise_pcg_hash(id ^ 0x2c1b3c6du);
    let h2 = noise_pcg_hash(h1);
    let h3 = noise_pcg_hash(h2);
    let u1 = noise_hash_to_unit(h1);
    let a = sqrt(1.0 - u1);
    let b = sqrt(u1);
    let t2 = 2.0 * PI * noise_hash_to_unit(h2);
    let t3 = 2.0 * PI * noise_hash_to_unit(h3);
    return normalize(vec4<f32>(a * sin(t2), a * cos(t2), b * sin(t3), b * cos(t3)));
}

// `v` rotated by the unit quaternion `q`.
fn particle_rotate(q: vec4<f32>, v: vec3<f32>) -> vec3<f32> {
    let t = 2.0 * cross(q.xyz, v);
    return v + q.w * t + cross(q.xyz, t);
}

// One particle of the technique (generate.rs Particle): an ellipsoid of the reference particle,
// written by particle_generate.wgsl and read by particle_render.wgsl.
struct Particle {
    centre_m: vec3<f32>,
    radius_m: f32,          // horizontal radius
    height_m: f32,          // vertical radius
    density: f32,           // peak density relative to the reference particle's, fade included
    sun_optical_depth: f32, // light occlusion
    id: u32,                // stable: seeds jitter, size and rotation
    optical_depth_up: f32,  // the field's, up to the band's top
    optical_depth_down: f32,// the field's, down to the band's floor
    ring: u32,
    reserved: u32,
}

// A style's constants: the noise's first-octave cells per radius and three style parameters.
struct ParticleShape {
    base_cells: f32,
    a: f32,
    b: f32,
    c: f32,
}

// The two normalised texture coordinates of an optical-depth look-up (one per direction-azimuth
// slice) and the weight of the second: OpticalDepthTable::lookup samples both and blends.
struct ParticleOpticalDepthTaps {
    uvw0: vec3<f32>,
    uvw1: vec3<f32>,
    weight: f32,
}

// `table_dims` = (start zeniths, start azimuths, direction zeniths, direction azimuths).
fn particle_optical_depth_taps(entry: vec3<f32>, dir_in: vec3<f32>, table_dims: vec4<u32>) -> ParticleOpticalDepthTaps {
    let n = normalize(entry);
    let dir = normalize(dir_in);
    let start_zenith = acos(clamp(n.z, -1.0, 1.0));
    let start_azimuth = atan2(n.y, n.x);
    let sz = sin(start_zenith);
    let cz = cos(start_zenith);
    let sa = sin(start_azimuth);
    let ca = cos(start_azimuth);
    let tangent_zenith = vec3<f32>(cz * ca, cz * sa, -sz);
    let tangent_azimuth = vec3<f32>(-sa, ca, 0.0);
    let dir_zenith = acos(clamp(-dot(dir, n), 0.0, 1.0));
    let dir_azimuth = atan2(dot(dir, tangent_azimuth), dot(dir, tangent_zenith));
    let f = vec4<f32>(table_dims);
    let depth = f.z * f.w;
    let x = start_azimuth / (2.0 * PI);
    let y = start_zenith / PI;
    let zenith_texel = clamp(dir_zenith / (0.5 * PI) * f.z, 0.5, f.z - 0.5);
    let turns = dir_azimuth / (2.0 * PI);
    let slice = (turns - floor(turns)) * f.w - 0.5;
    let first = floor(slice);
    let k0 = f32((i32(first) % i32(table_dims.w) + i32(table_dims.w)) % i32(table_dims.w));
    let k1 = (k0 + 1.0) % f.w;
    var taps: ParticleOpticalDepthTaps;
    taps.uvw0 = vec3<f32>(x, y, (k0 * f.z + zenith_texel) / depth);
    taps.uvw1 = vec3<f32>(x, y, (k1 * f.z + zenith_texel) / depth);
    taps.weight = slice - first;
    return taps;
}
