// The aerial-perspective volume (Hillaire 2020): for each of 32 x 32 directions across the view
// and each of 32 slices of 4 km, the light the air scatters toward the eye over the first
// (slice + 1) x 4 km and the transmittance over them, with the sun's single scattering dimmed by
// the clouds' shadow map (light shafts through the gaps). SkyTables::aerial_perspective with the
// shadows, one column of slices per invocation. The volume is stored as an atlas of its slices
// side by side in a 2D texture (slice k at x in [32 k, 32 k + 32)): wgpu's GL backend writes only
// the first slice of a 3D storage texture.

@group(3) @binding(0) var aerial_inscatter_out: texture_storage_2d<rgba16float, write>;
@group(3) @binding(1) var aerial_transmittance_out: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8)
fn atmosphere_build_aerial(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec3<u32>(ATMOSPHERE_AERIAL_SIZE, ATMOSPHERE_AERIAL_SLICES);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size.xy);
    let dir = frame_ray_direction(uv * frame.viewport_px);
    let origin = environment.viewpoint_m;
    let ru = environment_radius_up(origin);
    let angles = atmosphere_local_angles(ru.yzw, dir, environment.sun_direction);
    let ray = atmosphere_local_ray(ru.x, dot(ru.yzw, environment.sun_direction), angles.x, angles.y);
    let world = WorldRay(origin, 1u, dir);
    var light = vec3<f32>(0.0);
    var through = vec3<f32>(1.0);
    for (var k = 0u; k < size.z; k++) {
        let span = vec2<f32>(f32(k), f32(k + 1u)) * ATMOSPHERE_AERIAL_SLICE_M;
        let slice = atmosphere_scattered_along(ray, span, ATMOSPHERE_AERIAL_STEPS_PER_SLICE, false, world);
        light += through * slice.radiance;
        through *= slice.transmittance;
        let texel = vec2<u32>(id.x + k * size.x, id.y);
        textureStore(aerial_inscatter_out, texel, vec4<f32>(light, 1.0));
        textureStore(aerial_transmittance_out, texel, vec4<f32>(through, 1.0));
    }
}
