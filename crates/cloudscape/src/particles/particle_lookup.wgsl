#import particle
// The particle tables as the GPU reads them: the optical-depth table (optical_depth.rs, baked by
// particle_bake.wgsl) and the scattering tables (scattering/mod.rs), bound at the same slots of
// group 3 in every program that imports this module.

@group(3) @binding(3) var optical_depth_lut: texture_3d<f32>;
// Linear; repeating across entry azimuth, clamped elsewhere (OpticalDepthLut::sampler).
@group(3) @binding(4) var optical_depth_sampler: sampler;
// ChordProfile::mean_density.
@group(3) @binding(5) var<storage, read> chord_mean_density: array<f32>;
// Single (r, without the phase function) and multiple (g) scattering (ScatteringLut).
@group(3) @binding(6) var scattering_lut: texture_3d<f32>;
@group(3) @binding(7) var scattering_sampler: sampler;

// ChordProfile::mass.
fn chord_mass(entry: vec3<f32>, dir: vec3<f32>) -> f32 {
    let at = particle_chord_position(entry, dir, arrayLength(&chord_mean_density));
    let i = u32(at.x);
    let mean = mix(chord_mean_density[i], chord_mean_density[i + 1u], at.y);
    return 2.0 * clamp(-dot(entry, dir), 0.0, 1.0) * mean;
}

// Optical mass (particle radii) along the chord entering the unit sphere at `entry` along `dir`,
// in the particle's own orientation: OpticalDepthTable::lookup.
fn particle_optical_mass(entry: vec3<f32>, dir: vec3<f32>, table_dims: vec4<u32>) -> f32 {
    let taps = particle_optical_depth_taps(entry, dir, table_dims);
    let a = textureSampleLevel(optical_depth_lut, optical_depth_sampler, taps.uvw0, 0.0).x;
    let b = textureSampleLevel(optical_depth_lut, optical_depth_sampler, taps.uvw1, 0.0).x;
    return mix(a, b, taps.weight) * chord_mass(normalize(entry), normalize(dir));
}

// (S, M) for light leaving the unit sphere at `point` along `out` (toward the eye), lit from
// `to_light`: ScatteringTables::lookup (texture coordinates as texture_coordinates there).
fn particle_scattering(point: vec3<f32>, out: vec3<f32>, to_light: vec3<f32>) -> vec2<f32> {
    let n = normalize(point);
    let cos_entry = clamp(dot(n, to_light), -1.0, 1.0);
    let away = n * cos_entry - to_light;
    var tangent = vec3<f32>(0.0);
    if dot(away, away) > 1e-12 {
        tangent = normalize(away);
    } else {
        tangent = particle_any_orthonormal(n);
    }
    let bitangent = cross(n, tangent);
    let zenith = acos(clamp(dot(out, n), 0.0, 1.0));
    let azimuth = atan2(abs(dot(out, bitangent)), dot(out, tangent));
    let uvw = vec3<f32>(azimuth / PI, zenith / (0.5 * PI), acos(cos_entry) / PI);
    return textureSampleLevel(scattering_lut, scattering_sampler, uvw, 0.0).xy;
}

// A unit vector orthogonal to unit `n`: glam's Vec3::any_orthonormal_vector (Duff et al. 2017).
fn particle_any_orthonormal(n: vec3<f32>) -> vec3<f32> {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return vec3<f32>(b, sign + n.y * n.y * a, -n.y);
}
