// The optical-depth table as the GPU reads it (optical_depth.rs, baked by
// particle_bake.wgsl). The importing pass declares it in its own group (a library module binds
// nothing in a pass's group): `optical_depth_lut` (texture_3d, linear; repeating across entry
// azimuth, clamped elsewhere: OpticalDepthLut::sampler) with `optical_depth_sampler`, and
// `chord_mean_density` (ChordProfile::mean_density, a storage array of f32).

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
