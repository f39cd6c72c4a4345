// The environment interface (environment/mod.rs): sun, sky, haze and the clouds' shadows, bound at
// group 2. Techniques, the compositor and hosts light only through these functions. With
// sky_model 1 they read the atmosphere's tables (Hillaire 2020); otherwise the analytic gradient
// or constant sky. The twin of environment::Environment.

// The light volume's cascades (environment/light_volume, LightVolumeUniform).
struct LightVolume {
    cascade_min_m: array<vec4<f32>, LIGHT_VOLUME_MAX_CASCADES>,  // lowest corner (xyz) of each
    cascade_cell_m: array<vec4<f32>, LIGHT_VOLUME_MAX_CASCADES>, // cell size (xyz) of each
    cells: vec3<u32>,          // cells of each cascade along x, y (up) and z
    cascades: u32,
    optics: vec4<f32>,         // DiffuseOptics::to_gpu: scaled albedo, scaled g, thinning, g
    enabled: u32,              // 0: no clouds, the volume reads zero
    beam_steps: u32,           // samples of the coarse field toward the sun per cell
    pad0: u32,
    pad1: u32,
}

struct Environment {
    sun_direction: vec3<f32>,       // unit vector toward the sun
    sun_cos_angular_radius: f32,    // cosine of the sun disc's angular radius
    sun_irradiance: vec3<f32>,      // rgb irradiance facing the sun (above the air, atmosphere)
    haze_extinction_per_m: f32,     // analytic skies: extinction of the haze
    sky_zenith_radiance: vec3<f32>, // analytic skies: rgb radiance straight up
    sky_gradient_exponent: f32,     // analytic skies: mix(horizon, zenith, mu^exponent)
    sky_horizon_radiance: vec3<f32>,// analytic skies: rgb radiance at and below the horizon
    sky_model: u32,                 // 0: analytic, 1: atmosphere
    viewpoint_m: vec3<f32>,         // world point the sky and aerial perspective are seen from
    sun_limb_darkening: f32,        // linear limb-darkening coefficient u of the sun's disc
    air: Air,
    shadow: CloudShadow,
    light_volume: LightVolume,
}

@group(2) @binding(0) var<uniform> environment: Environment;
@group(2) @binding(1) var environment_transmittance: texture_2d<f32>;
@group(2) @binding(2) var environment_multiple_scattering: texture_2d<f32>;
@group(2) @binding(3) var environment_irradiance: texture_2d_array<f32>;
@group(2) @binding(4) var environment_sky_view: texture_2d<f32>;
// Atlases of slices: in-scattering (layer 0) and transmittance (layer 1).
@group(2) @binding(5) var environment_aerial: texture_2d_array<f32>;
@group(2) @binding(6) var environment_cloud_shadow: texture_2d_array<f32>;
// The light volume: I0 of each cascade side by side along z, then J / I0 (luminance) the same way.
@group(2) @binding(7) var environment_light_volume: texture_3d<f32>;
@group(2) @binding(8) var environment_linear: sampler;

// Unit vector toward the sun.
fn environment_sun_direction() -> vec3<f32> {
    return environment.sun_direction;
}

// Radius and unit up of world point p in atmosphere space.
fn environment_radius_up(p: vec3<f32>) -> vec4<f32> {
    let q = atmosphere_position(environment.air, p);
    let r = length(q);
    return vec4<f32>(r, q / r);
}

// Transmittance of the air from radius r toward the sun at cosine mu_s, zero once the planet
// hides the disc: SkyTables::sun_transmittance (Bruneton 2017, GetTransmittanceToSun).
fn environment_table_sun_transmittance(r: f32, mu_s: f32) -> vec3<f32> {
    let air = environment.air;
    let sin_horizon = air.bottom_radius_m / max(r, air.bottom_radius_m);
    let cos_horizon = -sqrt(max(1.0 - sin_horizon * sin_horizon, 0.0));
    let edge = sin_horizon * air.sun_angular_radius_rad;
    var visible = select(0.0, 1.0, mu_s >= cos_horizon);
    if edge > 0.0 {
        visible = smoothstep(-edge, edge, mu_s - cos_horizon);
    }
    let uv = atmosphere_transmittance_uv(air, r, mu_s);
    return textureSampleLevel(environment_transmittance, environment_linear, uv, 0.0).rgb * visible;
}

// Psi_ms at radius r and sun cosine mu_s: SkyTables::multiple_scattering.
fn environment_table_multiple_scattering(r: f32, mu_s: f32) -> vec3<f32> {
    let uv = atmosphere_sun_table_uv(environment.air, r, mu_s, vec2<f32>(ATMOSPHERE_MULTIPLE_SCATTERING_SIZE));
    return textureSampleLevel(environment_multiple_scattering, environment_linear, uv, 0.0).rgb;
}

// Whether the sky is the atmosphere's (its tables) rather than an analytic one. The functions below
// choose between the two by `select`, never by a branch on this alone: lavapipe (Mesa 22.3)
// recompiles a shader with a branch on uniform values alone each time they are uploaded, and leaks
// every compilation (docs/hardening.md, "Soak").
fn environment_is_atmosphere() -> bool {
    return environment.sky_model == 1u;
}

// Transmittance of the air from p toward the sun (1 for the analytic skies).
fn environment_sun_transmittance(p: vec3<f32>) -> vec3<f32> {
    let ru = environment_radius_up(p);
    let air = environment_table_sun_transmittance(ru.x, dot(ru.yzw, environment.sun_direction));
    return select(vec3<f32>(1.0), air, environment_is_atmosphere());
}

// Sun irradiance reaching world point p (on a surface facing the sun): Environment::sun_irradiance.
fn environment_sun_irradiance(p: vec3<f32>) -> vec3<f32> {
    return environment.sun_irradiance * environment_sun_transmittance(p);
}

// Radiance of the sun's disc seen from the viewpoint in direction d, limb-darkened by the linear
// law I(mu) / I(1) = 1 - u (1 - mu) and normalised so the disc integrates to the irradiance:
// SunDisc::radiance.
fn environment_sun_disc_radiance(d: vec3<f32>) -> vec3<f32> {
    let one_minus_cos_radius = 1.0 - environment.sun_cos_angular_radius;
    // 1 - cos(theta) = |d - s|^2 / 2, exact for the tiny angles where 1 - dot(d, s) is not.
    let chord = d - environment.sun_direction;
    let one_minus_cos_angle = 0.5 * dot(chord, chord);
    if one_minus_cos_radius <= 0.0 || one_minus_cos_angle > one_minus_cos_radius {
        return vec3<f32>(0.0);
    }
    let u = environment.sun_limb_darkening;
    let mu = sqrt(clamp(1.0 - one_minus_cos_angle / one_minus_cos_radius, 0.0, 1.0));
    let limb = (1.0 - u * (1.0 - mu)) / (1.0 - u / 3.0);
    return environment_sun_irradiance(environment.viewpoint_m) * limb / (2.0 * PI * one_minus_cos_radius);
}

// Mean radiance of the sun's disc over the pixel around direction d whose sides are step_x and
// step_y (the steps to the neighbouring pixel centres): closed form along x, SUN_PIXEL_ROWS
// midpoint rows in phi (y = r sin phi) across: SunDisc::pixel_radiance_of.
fn environment_sun_disc_pixel_radiance(d: vec3<f32>, step_x: vec3<f32>, step_y: vec3<f32>) -> vec3<f32> {
    let radius = acos(clamp(environment.sun_cos_angular_radius, -1.0, 1.0));
    let half = vec2<f32>(length(step_x), length(step_y)) * 0.5;
    let from_sun = d - environment.sun_direction;
    if radius <= 0.0 || min(half.x, half.y) <= 0.0 {
        return vec3<f32>(0.0);
    }
    let centre = vec2<f32>(dot(from_sun, step_x) / (2.0 * half.x), dot(from_sun, step_y) / (2.0 * half.y));
    let lo = centre - half;
    let hi = centre + half;
    let phi_lo = asin(clamp(lo.y / radius, -1.0, 1.0));
    let phi_hi = asin(clamp(hi.y / radius, -1.0, 1.0));
    if phi_hi <= phi_lo || lo.x >= radius || hi.x <= -radius {
        return vec3<f32>(0.0);
    }
    let u = environment.sun_limb_darkening;
    let dphi = (phi_hi - phi_lo) / f32(SUN_PIXEL_ROWS);
    var sum = 0.0;
    for (var k = 0u; k < SUN_PIXEL_ROWS; k++) {
        let w = radius * cos(phi_lo + (f32(k) + 0.5) * dphi);
        let a = clamp(lo.x, -w, w);
        let b = clamp(hi.x, -w, w);
        let row = (1.0 - u) * (b - a) + u / radius * (environment_disc_chord(b, w) - environment_disc_chord(a, w));
        sum += row * w * dphi;
    }
    let omega = 2.0 * PI * (1.0 - environment.sun_cos_angular_radius);
    let mean = sum / (1.0 - u / 3.0) / omega / (4.0 * half.x * half.y);
    return environment_sun_irradiance(environment.viewpoint_m) * mean;
}

// int sqrt(w^2 - x^2) dx at x: (x sqrt(w^2 - x^2) + w^2 asin(x / w)) / 2.
fn environment_disc_chord(x: f32, w: f32) -> f32 {
    return 0.5 * (x * sqrt(max(w * w - x * x, 0.0)) + w * w * asin(clamp(x / w, -1.0, 1.0)));
}

// Sky radiance arriving at the viewpoint from direction d (the disc excluded): the sky-view table
// (atmosphere) or SkyRadiance::radiance.
fn environment_sky_radiance(d: vec3<f32>) -> vec3<f32> {
    let ru = environment_radius_up(environment.viewpoint_m);
    let angles = atmosphere_local_angles(ru.yzw, d, environment.sun_direction);
    let uv = atmosphere_sky_view_uv(environment.air, ru.x, angles);
    let air = environment.sun_irradiance * textureSampleLevel(environment_sky_view, environment_linear, uv, 0.0).rgb;
    let mu = max(d.y, 0.0);
    let analytic = mix(environment.sky_horizon_radiance, environment.sky_zenith_radiance, pow(mu, environment.sky_gradient_exponent));
    return select(analytic, air, environment_is_atmosphere());
}

// Layer `layer` of the irradiance table at p: 0 the irradiance on an upward surface, 1 the mean
// radiance over the hemisphere above it, for the scene's sun.
fn environment_table_irradiance(p: vec3<f32>, layer: i32) -> vec3<f32> {
    let ru = environment_radius_up(p);
    let uv = atmosphere_sun_table_uv(environment.air, ru.x, dot(ru.yzw, environment.sun_direction), vec2<f32>(ATMOSPHERE_IRRADIANCE_SIZE));
    return environment.sun_irradiance * textureSampleLevel(environment_irradiance, environment_linear, uv, layer, 0.0).rgb;
}

// Mean sky radiance over the upper hemisphere at p: Environment::sky_mean_radiance_up.
fn environment_sky_mean_radiance_up(p: vec3<f32>) -> vec3<f32> {
    let analytic = mix(environment.sky_horizon_radiance, environment.sky_zenith_radiance, 1.0 / (1.0 + environment.sky_gradient_exponent));
    return select(analytic, environment_table_irradiance(p, 1), environment_is_atmosphere());
}

// Sky irradiance on an upward-facing surface at p: Environment::sky_irradiance_up.
fn environment_sky_irradiance_up(p: vec3<f32>) -> vec3<f32> {
    let analytic = PI * mix(environment.sky_horizon_radiance, environment.sky_zenith_radiance, 2.0 / (2.0 + environment.sky_gradient_exponent));
    return select(analytic, environment_table_irradiance(p, 0), environment_is_atmosphere());
}

// Radiance leaving a Lambertian ground of `albedo` at p under the unshadowed sun and sky:
// Environment::ground_radiance.
fn environment_ground_radiance(albedo: vec3<f32>, p: vec3<f32>) -> vec3<f32> {
    let sun = environment_sun_irradiance(p) * max(environment.sun_direction.y, 0.0);
    return albedo / PI * (sun + environment_sky_irradiance_up(p));
}

// What the eye sees of `radiance`, scattered by something covering fraction `coverage` of the
// pixel at screen position `uv` (0..1, y down) and `distance_m` away: through the atmosphere's
// aerial-perspective volume (32 slices of 4 km; below the first slice, a linear fade from the eye),
// or the analytic skies' haze, fading toward the horizon radiance by exp(-haze distance)
// (Koschmieder 1924). Applied once, in compositing: Environment::aerial_perspective.
fn environment_aerial_perspective(radiance: vec3<f32>, coverage: f32, uv: vec2<f32>, distance_m: f32) -> vec3<f32> {
    let clear = exp(-environment.haze_extinction_per_m * distance_m);
    let hazed = radiance * clear + environment.sky_horizon_radiance * coverage * (1.0 - clear);
    let slices = distance_m / ATMOSPHERE_AERIAL_SLICE_M;
    let w = clamp(slices - 1.0, 0.0, f32(ATMOSPHERE_AERIAL_SLICES - 1u));
    let k0 = floor(w);
    let k1 = min(k0 + 1.0, f32(ATMOSPHERE_AERIAL_SLICES - 1u));
    let a = environment_aerial_texel_uv(uv, k0);
    let b = environment_aerial_texel_uv(uv, k1);
    var inscatter = mix(textureSampleLevel(environment_aerial, environment_linear, a, 0, 0.0).rgb, textureSampleLevel(environment_aerial, environment_linear, b, 0, 0.0).rgb, w - k0);
    var transmittance = mix(textureSampleLevel(environment_aerial, environment_linear, a, 1, 0.0).rgb, textureSampleLevel(environment_aerial, environment_linear, b, 1, 0.0).rgb, w - k0);
    let near = clamp(slices, 0.0, 1.0);
    inscatter *= near;
    transmittance = mix(vec3<f32>(1.0), transmittance, near);
    let air = radiance * transmittance + environment.sun_irradiance * inscatter * coverage;
    return select(hazed, air, environment_is_atmosphere());
}

// Texture coordinates in the aerial-perspective atlas of screen position uv in slice k: the slice's
// 32 x 32 texels, clamped to their centres so no neighbouring slice bleeds in.
fn environment_aerial_texel_uv(uv: vec2<f32>, k: f32) -> vec2<f32> {
    let size = vec2<f32>(ATMOSPHERE_AERIAL_SIZE);
    let texel = clamp(uv * size, vec2<f32>(0.5), size - 0.5);
    return vec2<f32>((k * size.x + texel.x) / (size.x * f32(ATMOSPHERE_AERIAL_SLICES)), texel.y / size.y);
}

// Ground-plane offset (in half extents) of texel coordinate s of the environment's shadow map.
fn environment_shadow_offset(s: f32) -> f32 {
    return cloud_shadow_offset(s, environment.shadow.warp);
}

// Cloud optical depth above height y at ground-plane point g, from `layer` of the environment's
// shadow map (cloud_shadow_read).
fn environment_shadow_read(g: vec2<f32>, y: f32, layer: i32) -> f32 {
    let s = environment.shadow;
    return cloud_shadow_read(s, environment_cloud_shadow, environment_linear, g, y, layer);
}

// Optical depth of the clouds between world point p and the sun, from the shared light-space map
// (its ground-plane projection along the sun): for hosts' geometry, the ground and the air.
fn environment_cloud_sun_optical_depth(p: vec3<f32>) -> f32 {
    return cloud_shadow_sun_optical_depth(
        environment.shadow,
        environment_cloud_shadow,
        environment_linear,
        environment.sun_direction,
        p,
    );
}

// Optical depth of the clouds straight above world point p, from the map: what dims the sky's
// light on p.
fn environment_cloud_sky_optical_depth(p: vec3<f32>) -> f32 {
    return environment_shadow_read(p.xz, p.y, 1);
}

// Transmittance of the direct sun beam between world point p and the sun through the clouds,
// exp(-tau) (Beer-Lambert) from the shared map: the shadow a host's geometry receives.
fn environment_cloud_sun_transmittance(p: vec3<f32>) -> f32 {
    return exp(-environment_cloud_sun_optical_depth(p));
}

// Texture coordinates of world point p in cascade k of the light volume's radiance (its current
// lies a third of the texture further along z, the ground's irradiance two thirds), clamped to the
// cascade's cells' centres so that no neighbouring cascade bleeds in.
fn environment_light_volume_uvw(p: vec3<f32>, k: u32) -> vec3<f32> {
    let v = environment.light_volume;
    let n = vec3<f32>(v.cells);
    let local = clamp((p - v.cascade_min_m[k].xyz) / v.cascade_cell_m[k].xyz, vec3<f32>(0.5), n - 0.5);
    return vec3<f32>(local.x / n.x, local.y / n.y, (local.z + n.z * f32(k)) / (f32(LIGHT_VOLUME_TABLE_PARTS) * n.z * f32(v.cascades)));
}

// How much cascade k's own value counts at p (cascade_weight): 1 from CASCADE_BLEND_CELLS inside
// its sides inward, falling linearly to 0 at its outermost cells' centres; the coarsest takes the
// rest.
fn environment_light_volume_cascade_weight(p: vec3<f32>, k: u32) -> f32 {
    let v = environment.light_volume;
    if k + 1u == v.cascades {
        return 1.0;
    }
    let n = vec3<f32>(v.cells);
    let local = (p - v.cascade_min_m[k].xyz) / v.cascade_cell_m[k].xyz;
    let inside = min(min(local.x - 0.5, local.z - 0.5), min(n.x - 0.5 - local.x, n.z - 0.5 - local.z));
    return clamp(inside / CASCADE_BLEND_CELLS, 0.0, 1.0);
}

// The light volume's I0 (rgb) and its current over it (LightVolume::sample) at world point p,
// interpolated with the cells' weights (their optical thickness: a point in a cloud's edge reads
// the cloud's cells more than the clear air beside them), the cascades blended finest first
// (LightVolume::blend_cascades).
struct LightVolumeSample {
    radiance: vec3<f32>,
    current: vec3<f32>,
}

fn environment_light_volume_sample_in(p: vec3<f32>, k: u32) -> LightVolumeSample {
    let uvw = environment_light_volume_uvw(p, k);
    let weighted = textureSampleLevel(environment_light_volume, environment_linear, uvw, 0.0);
    let weighted_current = textureSampleLevel(environment_light_volume, environment_linear, uvw + vec3<f32>(0.0, 0.0, 1.0 / f32(LIGHT_VOLUME_TABLE_PARTS)), 0.0);
    return LightVolumeSample(weighted.rgb / max(weighted.a, 1e-6), weighted_current.xyz / max(weighted_current.a, 1e-6));
}

fn environment_light_volume_sample(p: vec3<f32>) -> LightVolumeSample {
    var sum = LightVolumeSample(vec3<f32>(0.0), vec3<f32>(0.0));
    var left = 1.0;
    for (var k = 0u; k < environment.light_volume.cascades && left > 0.0; k++) {
        let w = environment_light_volume_cascade_weight(p, k);
        if w > 0.0 {
            let s = environment_light_volume_sample_in(p, k);
            sum.radiance += left * w * s.radiance;
            sum.current += left * w * s.current;
            left *= 1.0 - w;
        }
    }
    return sum;
}

// Whether the frame has a light volume (a technique reads it and there are clouds).
fn environment_has_light_volume() -> bool {
    return environment.light_volume.enabled == 1u;
}

// The diffuse light of the clouds at world point p scattered toward the eye along `toward_eye`
// (unit), per unit scattering coefficient: I0 + g w . I1 of the light volume's δ-Eddington
// solution, with I1 = 3 J (optics/slab.rs scatters its slab's diffuse field the same way)
// (LightVolume::diffuse). Zero without a volume.
fn environment_light_volume_diffuse(p: vec3<f32>, toward_eye: vec3<f32>) -> vec3<f32> {
    let s = environment_light_volume_sample(p);
    let g = environment.light_volume.optics.w;
    let diffuse = s.radiance * max(1.0 + 3.0 * g * dot(s.current, toward_eye), 0.0);
    return select(vec3<f32>(0.0), diffuse, environment_has_light_volume());
}

// The diffuse irradiance on level ground at g from the sky and the clouds above it: what leaves the
// volume's bottom face there, the table's third part, bilinear between columns
// (LightVolume::ground_irradiance). Zero without a volume.
fn environment_light_volume_ground_irradiance(g: vec3<f32>) -> vec3<f32> {
    let third = 2.0 / f32(LIGHT_VOLUME_TABLE_PARTS);
    var irradiance = vec3<f32>(0.0);
    var left = 1.0;
    for (var k = 0u; k < environment.light_volume.cascades && left > 0.0; k++) {
        let w = environment_light_volume_cascade_weight(g, k);
        if w > 0.0 {
            let bottom = environment_light_volume_uvw(vec3<f32>(g.x, -1e9, g.z), k);
            let texel = textureSampleLevel(environment_light_volume, environment_linear, bottom + vec3<f32>(0.0, 0.0, third), 0.0);
            irradiance += left * w * texel.rgb / max(texel.a, 1e-6);
            left *= 1.0 - w;
        }
    }
    // Irradiance is never negative; the diffusion solution's flux out of the bottom can be where
    // the P1 approximation fails (thin, dark clouds).
    return select(vec3<f32>(0.0), max(irradiance, vec3<f32>(0.0)), environment_has_light_volume());
}
