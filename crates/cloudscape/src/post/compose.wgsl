// Puts the clouds over the background this crate draws when there is no host scene: the sky, the
// sun's disc and the ground. final = background * transmittance + cloud radiance.

@group(1) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(1) var compose_clouds: texture_2d<f32>;
@group(1) @binding(2) var compose_out: texture_storage_2d<rgba16float, write>;

// Radiance of the sun's disc, a uniform disc of the sun's irradiance: E / (pi r^2) for small r.
fn compose_sun_disc(d: vec3<f32>) -> vec3<f32> {
    if dot(d, frame.sun_direction.xyz) < frame.sun_direction.w {
        return vec3<f32>(0.0);
    }
    let r = frame.sun_irradiance.w;
    return frame.sun_irradiance.xyz / (3.14159265 * r * r);
}

@compute @workgroup_size(8, 8)
fn compose_background(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= u32(frame.viewport.x) || id.y >= u32(frame.viewport.y) {
        return;
    }
    let pixel = vec2<f32>(id.xy) + 0.5;
    let o = frame.camera_position.xyz;
    let d = frame_ray_direction(frame, pixel);
    var background = frame_sky_radiance(frame, d) + compose_sun_disc(d);
    let ground_m = field_ground_distance(o, d, frame.ground_albedo.w > 0.5);
    if ground_m < frame.camera_position.w {
        background = frame_haze(frame, frame.ground_radiance.xyz, 1.0, ground_m);
    }
    let clouds = textureLoad(compose_clouds, vec2<i32>(id.xy), 0);
    textureStore(compose_out, vec2<i32>(id.xy), vec4<f32>(background * clouds.a + clouds.rgb, 1.0));
}
