// Building Hillaire 2020's tables, one texel per invocation into the pass's output (group 3,
// binding 0). Each entry point is the twin of the SkyTables function named beside it. The tables
// are read through environment.wgsl, whose group binds a stand-in for the table being written.

@group(3) @binding(0) var atmosphere_out: texture_storage_2d<rgba16float, write>;
// The irradiance pass's second output: the mean radiance (layer 1 of the irradiance table).
@group(3) @binding(1) var atmosphere_out_mean: texture_storage_2d<rgba16float, write>;

// Centre of texel id in texture coordinates of the output, or a negative u outside it.
fn atmosphere_texel_uv(id: vec2<u32>) -> vec2<f32> {
    let size = textureDimensions(atmosphere_out);
    if id.x >= size.x || id.y >= size.y {
        return vec2<f32>(-1.0);
    }
    return (vec2<f32>(id) + 0.5) / vec2<f32>(size);
}

// luts::transmittance_table.
@compute @workgroup_size(8, 8)
fn atmosphere_build_transmittance(@builtin(global_invocation_id) id: vec3<u32>) {
    let uv = atmosphere_texel_uv(id.xy);
    if uv.x < 0.0 {
        return;
    }
    let air = environment.air;
    let r_mu = atmosphere_transmittance_r_mu(air, uv);
    let d = atmosphere_distance_to_top(air, r_mu.x, r_mu.y);
    let dt = d / f32(ATMOSPHERE_TRANSMITTANCE_STEPS);
    var depth = vec3<f32>(0.0);
    for (var i = 0u; i < ATMOSPHERE_TRANSMITTANCE_STEPS; i++) {
        let t = (f32(i) + 0.5) * dt;
        let r_t = sqrt(max(t * t + 2.0 * r_mu.x * r_mu.y * t + r_mu.x * r_mu.x, 0.0));
        depth += atmosphere_at(air, r_t).extinction * dt;
    }
    textureStore(atmosphere_out, id.xy, vec4<f32>(exp(-depth), 1.0));
}

// SkyTables::isotropic_transfer: the second-order light and the transfer f_ms along one ray.
fn atmosphere_isotropic_transfer(ray: LocalRay) -> array<vec3<f32>, 2> {
    let air = environment.air;
    let mu = ray.dir.y;
    let t_max = atmosphere_distance_to_boundary(air, ray.r, mu);
    let dt = t_max / f32(ATMOSPHERE_MULTIPLE_SCATTERING_STEPS);
    var light = vec3<f32>(0.0);
    var transfer = vec3<f32>(0.0);
    var through = vec3<f32>(1.0);
    let isotropic = 1.0 / (4.0 * PI);
    for (var i = 0u; i < ATMOSPHERE_MULTIPLE_SCATTERING_STEPS; i++) {
        let p = vec3<f32>(0.0, ray.r, 0.0) + ray.dir * ((f32(i) + 0.5) * dt);
        let r = length(p);
        let sample = atmosphere_at(air, r);
        let sun = environment_table_sun_transmittance(r, dot(p / r, ray.sun));
        let step = exp(-sample.extinction * dt);
        let integral = (vec3<f32>(1.0) - step) / max(sample.extinction, vec3<f32>(1e-12));
        let scattering = sample.rayleigh_scattering + vec3<f32>(sample.mie_scattering);
        light += through * scattering * sun * isotropic * integral;
        transfer += through * scattering * integral;
        through *= step;
    }
    if atmosphere_hits_ground(air, ray.r, mu) {
        let ground = vec3<f32>(0.0, ray.r, 0.0) + ray.dir * t_max;
        let mu_s = dot(normalize(ground), ray.sun);
        let sun = environment_table_sun_transmittance(air.bottom_radius_m, mu_s);
        light += through * sun * max(mu_s, 0.0) * air.ground_albedo / PI;
    }
    return array<vec3<f32>, 2>(light, transfer);
}

// SkyTables::multiple_scattering_at: Psi_ms = L_2 / (1 - f_ms) over an 8 x 8 sphere grid.
@compute @workgroup_size(8, 8)
fn atmosphere_build_multiple_scattering(@builtin(global_invocation_id) id: vec3<u32>) {
    let uv = atmosphere_texel_uv(id.xy);
    if uv.x < 0.0 {
        return;
    }
    let r_mu = atmosphere_sun_table_r_mu(environment.air, uv, vec2<f32>(ATMOSPHERE_MULTIPLE_SCATTERING_SIZE));
    let n = ATMOSPHERE_MULTIPLE_SCATTERING_DIRECTIONS;
    var second_order = vec3<f32>(0.0);
    var transfer = vec3<f32>(0.0);
    for (var i = 0u; i < n; i++) {
        for (var j = 0u; j < n; j++) {
            let cos_zenith = 1.0 - 2.0 * (f32(i) + 0.5) / f32(n);
            let azimuth = 2.0 * PI * (f32(j) + 0.5) / f32(n);
            let lf = atmosphere_isotropic_transfer(atmosphere_local_ray(r_mu.x, r_mu.y, asin(cos_zenith), azimuth));
            second_order += lf[0];
            transfer += lf[1];
        }
    }
    let count = f32(n * n);
    textureStore(atmosphere_out, id.xy, vec4<f32>((second_order / count) / (vec3<f32>(1.0) - transfer / count), 1.0));
}

// SkyTables::irradiance_at: the irradiance on an upward surface (layer 0 of the table) and the
// mean radiance over the hemisphere above it (layer 1).
@compute @workgroup_size(8, 8)
fn atmosphere_build_irradiance(@builtin(global_invocation_id) id: vec3<u32>) {
    let uv = atmosphere_texel_uv(id.xy);
    if uv.x < 0.0 {
        return;
    }
    let r_mu = atmosphere_sun_table_r_mu(environment.air, uv, vec2<f32>(ATMOSPHERE_IRRADIANCE_SIZE));
    let n = ATMOSPHERE_IRRADIANCE_DIRECTIONS;
    var irradiance = vec3<f32>(0.0);
    var radiance = vec3<f32>(0.0);
    for (var i = 0u; i < n; i++) {
        let cos_zenith = (f32(i) + 0.5) / f32(n);
        for (var j = 0u; j < n; j++) {
            let azimuth = PI * (f32(j) + 0.5) / f32(n);
            let ray = atmosphere_local_ray(r_mu.x, r_mu.y, asin(cos_zenith), azimuth);
            let span = vec2<f32>(0.0, atmosphere_distance_to_boundary(environment.air, ray.r, ray.dir.y));
            let l = atmosphere_scattered_along(ray, span, ATMOSPHERE_IRRADIANCE_STEPS, true, ATMOSPHERE_UNSHADOWED).radiance;
            irradiance += l * cos_zenith;
            radiance += l;
        }
    }
    let count = f32(n * n);
    textureStore(atmosphere_out, id.xy, vec4<f32>(irradiance * (2.0 * PI / count), 1.0));
    textureStore(atmosphere_out_mean, id.xy, vec4<f32>(radiance / count, 1.0));
}

// SkyTables::sky_view_table, seen from the environment's viewpoint.
@compute @workgroup_size(8, 8)
fn atmosphere_build_sky_view(@builtin(global_invocation_id) id: vec3<u32>) {
    let uv = atmosphere_texel_uv(id.xy);
    if uv.x < 0.0 {
        return;
    }
    let ru = environment_radius_up(environment.viewpoint_m);
    let mu_s = dot(ru.yzw, environment.sun_direction);
    let angles = atmosphere_sky_view_angles(environment.air, ru.x, uv);
    let ray = atmosphere_local_ray(ru.x, mu_s, angles.x, angles.y);
    let span = vec2<f32>(0.0, atmosphere_distance_to_boundary(environment.air, ray.r, ray.dir.y));
    let l = atmosphere_scattered_along(ray, span, ATMOSPHERE_SKY_VIEW_STEPS, true, ATMOSPHERE_UNSHADOWED).radiance;
    textureStore(atmosphere_out, id.xy, vec4<f32>(l, 1.0));
}
