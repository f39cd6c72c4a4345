// The air over a spherical planet (atmosphere/medium.rs) and the parameterisations of Hillaire
// 2020's look-up tables (atmosphere/luts.rs): pure functions of the `Air` uniform, each the twin
// of the Rust function named beside it. The tables themselves are bound by environment.wgsl.

struct Air {
    rayleigh_scattering_per_m: vec3<f32>, // at the ground, RGB
    bottom_radius_m: f32,
    ozone_absorption_per_m: vec3<f32>,    // at the peak of the ozone layer, RGB
    top_radius_m: f32,
    ground_albedo: vec3<f32>,
    mie_scattering_per_m: f32,            // at the ground
    mie_extinction_per_m: f32,            // at the ground
    mie_g: f32,                           // mean cosine of the Cornette-Shanks phase function
    sun_angular_radius_rad: f32,
    flat_world: u32,                      // 1: world points sit above the pole at their height
}

struct AirSample {
    rayleigh_scattering: vec3<f32>,
    mie_scattering: f32,
    extinction: vec3<f32>,
}

// World point p in atmosphere space: Air::position_of.
fn atmosphere_position(air: Air, p: vec3<f32>) -> vec3<f32> {
    let y = p.y + air.bottom_radius_m;
    if air.flat_world == 1u {
        return vec3<f32>(0.0, y, 0.0);
    }
    return vec3<f32>(p.x, y, p.z);
}

// The medium at radius r: Air::at (Bruneton 2017's profiles).
fn atmosphere_at(air: Air, r: f32) -> AirSample {
    let h = max(r - air.bottom_radius_m, 0.0);
    let rayleigh = exp(-h / ATMOSPHERE_RAYLEIGH_SCALE_HEIGHT_M);
    let mie = exp(-h / ATMOSPHERE_MIE_SCALE_HEIGHT_M);
    let ozone = max(1.0 - abs(h - ATMOSPHERE_OZONE_PEAK_ALTITUDE_M) / ATMOSPHERE_OZONE_HALF_WIDTH_M, 0.0);
    var s: AirSample;
    s.rayleigh_scattering = air.rayleigh_scattering_per_m * rayleigh;
    s.mie_scattering = air.mie_scattering_per_m * mie;
    s.extinction = s.rayleigh_scattering + vec3<f32>(air.mie_extinction_per_m * mie) + air.ozone_absorption_per_m * ozone;
    return s;
}

// Air::rayleigh_phase.
fn atmosphere_rayleigh_phase(cos_theta: f32) -> f32 {
    return 3.0 / (16.0 * PI) * (1.0 + cos_theta * cos_theta);
}

// Air::distance_to_top.
fn atmosphere_distance_to_top(air: Air, r: f32, mu: f32) -> f32 {
    let discriminant = r * r * (mu * mu - 1.0) + air.top_radius_m * air.top_radius_m;
    return max(-r * mu + sqrt(max(discriminant, 0.0)), 0.0);
}

// Air::distance_to_ground.
fn atmosphere_distance_to_ground(air: Air, r: f32, mu: f32) -> f32 {
    let discriminant = r * r * (mu * mu - 1.0) + air.bottom_radius_m * air.bottom_radius_m;
    return max(-r * mu - sqrt(max(discriminant, 0.0)), 0.0);
}

// Air::hits_ground.
fn atmosphere_hits_ground(air: Air, r: f32, mu: f32) -> bool {
    return mu < 0.0 && r * r * (mu * mu - 1.0) + air.bottom_radius_m * air.bottom_radius_m >= 0.0;
}

// Air::distance_to_boundary.
fn atmosphere_distance_to_boundary(air: Air, r: f32, mu: f32) -> f32 {
    if atmosphere_hits_ground(air, r, mu) {
        return atmosphere_distance_to_ground(air, r, mu);
    }
    return atmosphere_distance_to_top(air, r, mu);
}

// table::texture_coord.
fn atmosphere_texture_coord(x: f32, n: f32) -> f32 {
    return 0.5 / n + x * (1.0 - 1.0 / n);
}

// table::unit_range.
fn atmosphere_unit_range(u: f32, n: f32) -> f32 {
    return (u - 0.5 / n) / (1.0 - 1.0 / n);
}

// luts::transmittance_uv (Bruneton 2017).
fn atmosphere_transmittance_uv(air: Air, r: f32, mu: f32) -> vec2<f32> {
    let horizon = sqrt(air.top_radius_m * air.top_radius_m - air.bottom_radius_m * air.bottom_radius_m);
    let rho = sqrt(max(r * r - air.bottom_radius_m * air.bottom_radius_m, 0.0));
    let d = atmosphere_distance_to_top(air, r, mu);
    let d_min = air.top_radius_m - r;
    let d_max = rho + horizon;
    var x_mu = 0.0;
    if d_max > d_min {
        x_mu = (d - d_min) / (d_max - d_min);
    }
    let size = vec2<f32>(ATMOSPHERE_TRANSMITTANCE_SIZE);
    return vec2<f32>(atmosphere_texture_coord(x_mu, size.x), atmosphere_texture_coord(rho / horizon, size.y));
}

// luts::transmittance_r_mu: (radius, view cosine) at uv.
fn atmosphere_transmittance_r_mu(air: Air, uv: vec2<f32>) -> vec2<f32> {
    let size = vec2<f32>(ATMOSPHERE_TRANSMITTANCE_SIZE);
    let horizon = sqrt(air.top_radius_m * air.top_radius_m - air.bottom_radius_m * air.bottom_radius_m);
    let rho = horizon * atmosphere_unit_range(uv.y, size.y);
    let r = sqrt(rho * rho + air.bottom_radius_m * air.bottom_radius_m);
    let d_min = air.top_radius_m - r;
    let d_max = rho + horizon;
    let d = d_min + atmosphere_unit_range(uv.x, size.x) * (d_max - d_min);
    var mu = 1.0;
    if d > 0.0 {
        mu = clamp((horizon * horizon - rho * rho - d * d) / (2.0 * r * d), -1.0, 1.0);
    }
    return vec2<f32>(r, mu);
}

// luts::sun_table_uv, for a table of `size` texels.
fn atmosphere_sun_table_uv(air: Air, r: f32, mu_s: f32, size: vec2<f32>) -> vec2<f32> {
    let altitude = (r - air.bottom_radius_m) / (air.top_radius_m - air.bottom_radius_m);
    return vec2<f32>(atmosphere_texture_coord(clamp(mu_s * 0.5 + 0.5, 0.0, 1.0), size.x), atmosphere_texture_coord(clamp(altitude, 0.0, 1.0), size.y));
}

// luts::sun_table_r_mu: (radius, sun cosine) at uv.
fn atmosphere_sun_table_r_mu(air: Air, uv: vec2<f32>, size: vec2<f32>) -> vec2<f32> {
    let mu_s = atmosphere_unit_range(uv.x, size.x) * 2.0 - 1.0;
    let r = air.bottom_radius_m + atmosphere_unit_range(uv.y, size.y) * (air.top_radius_m - air.bottom_radius_m);
    return vec2<f32>(r, mu_s);
}

// luts::horizon_elevation.
fn atmosphere_horizon_elevation(air: Air, r: f32) -> f32 {
    return -acos(clamp(air.bottom_radius_m / r, 0.0, 1.0));
}

// luts::sky_view_uv: (elevation, azimuth from the sun) seen from radius r.
fn atmosphere_sky_view_uv(air: Air, r: f32, angles: vec2<f32>) -> vec2<f32> {
    let horizon = atmosphere_horizon_elevation(air, r);
    var v: f32;
    if angles.x >= horizon {
        v = 0.5 + 0.5 * sqrt(clamp((angles.x - horizon) / (0.5 * PI - horizon), 0.0, 1.0));
    } else {
        v = 0.5 - 0.5 * sqrt(clamp((horizon - angles.x) / (horizon + 0.5 * PI), 0.0, 1.0));
    }
    let size = vec2<f32>(ATMOSPHERE_SKY_VIEW_SIZE);
    return vec2<f32>(atmosphere_texture_coord(clamp(angles.y / PI, 0.0, 1.0), size.x), atmosphere_texture_coord(v, size.y));
}

// luts::sky_view_angles: (elevation, azimuth from the sun) at uv, seen from radius r.
fn atmosphere_sky_view_angles(air: Air, r: f32, uv: vec2<f32>) -> vec2<f32> {
    let horizon = atmosphere_horizon_elevation(air, r);
    let size = vec2<f32>(ATMOSPHERE_SKY_VIEW_SIZE);
    let v = atmosphere_unit_range(uv.y, size.y);
    var elevation: f32;
    if v >= 0.5 {
        let x = 2.0 * v - 1.0;
        elevation = horizon + x * x * (0.5 * PI - horizon);
    } else {
        let x = 1.0 - 2.0 * v;
        elevation = horizon - x * x * (horizon + 0.5 * PI);
    }
    return vec2<f32>(elevation, atmosphere_unit_range(uv.x, size.x) * PI);
}

// atmosphere::local_angles: elevation of dir above the horizontal of up, and its azimuth from
// the sun's, radians.
fn atmosphere_local_angles(up: vec3<f32>, dir: vec3<f32>, sun: vec3<f32>) -> vec2<f32> {
    let elevation = asin(clamp(dot(dir, up), -1.0, 1.0));
    let flat_dir = dir - up * dot(dir, up);
    let flat_sun = sun - up * dot(sun, up);
    var azimuth = 0.0;
    if dot(flat_dir, flat_dir) >= 1e-12 && dot(flat_sun, flat_sun) >= 1e-12 {
        azimuth = acos(clamp(dot(normalize(flat_dir), normalize(flat_sun)), -1.0, 1.0));
    }
    return vec2<f32>(elevation, azimuth);
}

// A ray in the local frame of the tables: from (0, r, 0) along dir, the sun at sun.
struct LocalRay {
    r: f32,
    dir: vec3<f32>,
    sun: vec3<f32>,
}

// LocalRay::from_angles.
fn atmosphere_local_ray(r: f32, mu_s: f32, elevation: f32, azimuth: f32) -> LocalRay {
    let ce = cos(elevation);
    return LocalRay(r, vec3<f32>(ce * cos(azimuth), sin(elevation), ce * sin(azimuth)), vec3<f32>(sqrt(max(1.0 - mu_s * mu_s, 0.0)), mu_s, 0.0));
}

// Spacing::at: distance at fraction x of span, evenly (quadratic == false) or as x^2.
fn atmosphere_spacing(span: vec2<f32>, x: f32, quadratic: bool) -> f32 {
    var f = x;
    if quadratic {
        f = x * x;
    }
    return span.x + (span.y - span.x) * f;
}
