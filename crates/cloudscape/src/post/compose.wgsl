// Composes the cloud output over what lies behind it: the host's geometry where its depth buffer
// holds some, else the sky, the sun's disc (its mean over the pixel: anti-aliased) and the ground in the clouds' shadows. Aerial
// perspective is applied here, once: to the background at its distance and to the clouds at their
// distance. final = background * transmittance + hazed cloud radiance.

@group(3) @binding(0) var compose_clouds: texture_2d<f32>;
@group(3) @binding(1) var compose_cloud_distance: texture_2d<f32>;
@group(3) @binding(2) var compose_host_color: texture_2d<f32>;
@group(3) @binding(3) var compose_host_depth: texture_2d<f32>;
@group(3) @binding(4) var compose_out: texture_storage_2d<rgba16float, write>;

// Radiance leaving the Lambertian ground at g. With a light volume, the δ-Eddington split the
// clouds are lit by: the scaled sun beam through the clouds (the direct sun and the light they
// scatter forward, exp(-tau') along its slant path in the shared shadow map) and the volume's
// diffuse light from the sky and the clouds' bases (environment_light_volume_ground_irradiance).
// Without one, the sun's and the sky's share of environment_ground_radiance, each dimmed by the
// clouds' diffuse transmittance between the ground and the light, read from the shadow map.
fn compose_ground(g: vec3<f32>) -> vec3<f32> {
    let sun = environment_sun_direction();
    let sun_irradiance = environment_sun_irradiance(g) * max(sun.y, 0.0);
    var tau_sun = 0.0;
    if sun.y > 0.0 {
        tau_sun = environment_cloud_sun_optical_depth(g);
    }
    if environment_has_light_volume() {
        let beam = sun_irradiance * exp(-environment.light_volume.optics.z * tau_sun);
        return frame.ground_albedo / PI * (beam + environment_light_volume_ground_irradiance(g));
    }
    let sun_t = select(0.0, frame_diffuse_transmittance(tau_sun), sun.y > 0.0);
    let sky_t = frame_diffuse_transmittance(environment_cloud_sky_optical_depth(g));
    let sky = environment_sky_irradiance_up(g);
    return frame.ground_albedo / PI * (sun_irradiance * sun_t + sky * sky_t);
}

// What lies behind the clouds along the ray through pixel `px`, as the eye sees it through the haze.
fn compose_background(px: vec2<u32>) -> vec3<f32> {
    let pixel = vec2<f32>(px) + 0.5;
    let uv = pixel / frame.viewport_px;
    let o = frame.camera_position_m;
    let d = frame_ray_direction(pixel);
    let host_depth = textureLoad(compose_host_depth, vec2<i32>(px), 0).x;
    if frame_has_geometry(host_depth) {
        let host = textureLoad(compose_host_color, vec2<i32>(px), 0).rgb;
        return environment_aerial_perspective(host, 1.0, uv, frame_depth_distance(pixel, host_depth));
    }
    let ground_m = field_ground_distance(o, d, frame.has_ground == 1u);
    if ground_m < frame.far_m {
        return environment_aerial_perspective(compose_ground(o + d * ground_m), 1.0, uv, ground_m);
    }
    let step_x = frame_ray_direction(pixel + vec2<f32>(1.0, 0.0)) - d;
    let step_y = frame_ray_direction(pixel + vec2<f32>(0.0, 1.0)) - d;
    return environment_sky_radiance(d) + environment_sun_disc_pixel_radiance(d, step_x, step_y);
}

@compute @workgroup_size(8, 8)
fn compose_clouds_over_background(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= u32(frame.viewport_px.x) || id.y >= u32(frame.viewport_px.y) {
        return;
    }
    // A temporal history keeps its resampling's ringing (temporal_history_bicubic): clamped here,
    // where nothing feeds back.
    let stored = textureLoad(compose_clouds, vec2<i32>(id.xy), 0);
    let clouds = vec4<f32>(max(stored.rgb, vec3<f32>(0.0)), clamp(stored.a, 0.0, 1.0));
    let distance_m = textureLoad(compose_cloud_distance, vec2<i32>(id.xy), 0).x;
    let uv = (vec2<f32>(id.xy) + 0.5) / frame.viewport_px;
    let hazed = environment_aerial_perspective(clouds.rgb, 1.0 - clouds.a, uv, distance_m);
    textureStore(compose_out, vec2<i32>(id.xy), vec4<f32>(compose_background(id.xy) * clouds.a + hazed, 1.0));
}
