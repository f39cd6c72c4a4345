// The integral of the air's scattered light along a ray (Hillaire 2020 eq. 1-4), shared by the
// table passes.

// Light scattered toward the start of `ray` over `span` and the transmittance over it, from
// `steps` samples spaced evenly or quadratically: SkyTables::scattered_along. When
// `world.shadowed`, the sun's single scattering at world point `world.origin + world.dir * t` is
// dimmed by the clouds' direct-beam transmittance exp(-tau) toward the sun, from the shared map:
// light shafts. (The light the clouds scatter forward is diffuse, not in the sun's direction, so
// the sun's phase function does not apply to it; the air's multiple scattering stays unshadowed.)
struct ScatteredLight {
    radiance: vec3<f32>,
    transmittance: vec3<f32>,
}

// The world ray a local ray stands for, for the clouds' shadows; `shadowed` 0 ignores them.
struct WorldRay {
    origin: vec3<f32>,
    shadowed: u32,
    dir: vec3<f32>,
}

const ATMOSPHERE_UNSHADOWED = WorldRay(vec3<f32>(0.0), 0u, vec3<f32>(0.0, 1.0, 0.0));

fn atmosphere_scattered_along(ray: LocalRay, span: vec2<f32>, steps: u32, quadratic: bool, world: WorldRay) -> ScatteredLight {
    let air = environment.air;
    let cos_theta = dot(ray.dir, ray.sun);
    let rayleigh_phase = atmosphere_rayleigh_phase(cos_theta);
    let mie_phase = phase_draine(air.mie_g, 1.0, cos_theta);
    var light = vec3<f32>(0.0);
    var through = vec3<f32>(1.0);
    for (var i = 0u; i < steps; i++) {
        let t0 = atmosphere_spacing(span, f32(i) / f32(steps), quadratic);
        let t1 = atmosphere_spacing(span, f32(i + 1u) / f32(steps), quadratic);
        let t = 0.5 * (t0 + t1);
        let p = vec3<f32>(0.0, ray.r, 0.0) + ray.dir * t;
        let r = length(p);
        let mu_s = dot(p / r, ray.sun);
        let sample = atmosphere_at(air, r);
        var sun = environment_table_sun_transmittance(r, mu_s);
        if world.shadowed == 1u {
            sun *= environment_cloud_sun_transmittance(world.origin + world.dir * t);
        }
        let single = sample.rayleigh_scattering * rayleigh_phase + vec3<f32>(sample.mie_scattering * mie_phase);
        let scattering = sample.rayleigh_scattering + vec3<f32>(sample.mie_scattering);
        let source = single * sun + environment_table_multiple_scattering(r, mu_s) * scattering;
        let step = exp(-sample.extinction * (t1 - t0));
        light += through * source * (vec3<f32>(1.0) - step) / max(sample.extinction, vec3<f32>(1e-12));
        through *= step;
    }
    return ScatteredLight(light, through);
}

