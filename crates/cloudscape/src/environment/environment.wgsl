#import constants
// The environment interface (environment/mod.rs): sun, sky and haze, bound at group 2. Techniques
// and the compositor light only through these functions, so a physical atmosphere can replace this
// module without touching them. The twin of environment::Environment.

struct Environment {
    sun_direction: vec3<f32>,       // unit vector toward the sun
    sun_cos_angular_radius: f32,    // cosine of the sun disc's angular radius
    sun_irradiance: vec3<f32>,      // rgb irradiance on a surface facing the sun
    haze_extinction_per_m: f32,     // extinction of the haze between the eye and what it sees
    sky_zenith_radiance: vec3<f32>, // rgb radiance straight up
    sky_gradient_exponent: f32,     // mix(horizon, zenith, mu^exponent)
    sky_horizon_radiance: vec3<f32>,// rgb radiance at and below the horizon
    sky_pad: f32,
}

@group(2) @binding(0) var<uniform> environment: Environment;

// Unit vector toward the sun.
fn environment_sun_direction() -> vec3<f32> {
    return environment.sun_direction;
}

// Sun irradiance reaching world point p (on a surface facing the sun).
fn environment_sun_irradiance(p: vec3<f32>) -> vec3<f32> {
    return environment.sun_irradiance;
}

// Radiance of the sun's disc seen in direction d: SunDisc::radiance, E / (2 pi (1 - cos r)) inside.
fn environment_sun_disc_radiance(d: vec3<f32>) -> vec3<f32> {
    let solid_angle = 2.0 * PI * (1.0 - environment.sun_cos_angular_radius);
    if solid_angle <= 0.0 || dot(d, environment.sun_direction) < environment.sun_cos_angular_radius {
        return vec3<f32>(0.0);
    }
    return environment.sun_irradiance / solid_angle;
}

// Sky radiance from direction d: SkyRadiance::radiance.
fn environment_sky_radiance(d: vec3<f32>) -> vec3<f32> {
    let mu = max(d.y, 0.0);
    return mix(environment.sky_horizon_radiance, environment.sky_zenith_radiance, pow(mu, environment.sky_gradient_exponent));
}

// Mean sky radiance over the upper hemisphere at p: SkyRadiance::mean_radiance_up.
fn environment_sky_mean_radiance_up(p: vec3<f32>) -> vec3<f32> {
    return mix(environment.sky_horizon_radiance, environment.sky_zenith_radiance, 1.0 / (1.0 + environment.sky_gradient_exponent));
}

// Sky irradiance on an upward-facing surface at p: SkyRadiance::irradiance_up.
fn environment_sky_irradiance_up(p: vec3<f32>) -> vec3<f32> {
    return PI * mix(environment.sky_horizon_radiance, environment.sky_zenith_radiance, 2.0 / (2.0 + environment.sky_gradient_exponent));
}

// Radiance leaving a Lambertian ground of `albedo` at p under the unshadowed sun and sky:
// Environment::ground_radiance.
fn environment_ground_radiance(albedo: vec3<f32>, p: vec3<f32>) -> vec3<f32> {
    let sun = environment_sun_irradiance(p) * max(environment.sun_direction.y, 0.0);
    return albedo / PI * (sun + environment_sky_irradiance_up(p));
}

// What the eye sees of `radiance`, scattered by something covering fraction `coverage` of the pixel
// `distance_m` away, through the haze: it fades toward the horizon radiance by exp(-haze distance)
// (Koschmieder 1924). Environment::aerial_perspective; applied once, in compositing.
fn environment_aerial_perspective(radiance: vec3<f32>, coverage: f32, distance_m: f32) -> vec3<f32> {
    let clear = exp(-environment.haze_extinction_per_m * distance_m);
    return radiance * clear + environment.sky_horizon_radiance * coverage * (1.0 - clear);
}
