// The sun's light inside a cloud by the delta-Eddington solution of a slab along the sun: the GPU
// twin of optics/slab.rs (SunSlab), which derives and cites every formula. Functions only.

// SunSlab as the march's uniform holds it: the phase lobes, and
// (peak fraction f, albedo, diffuse scale, back scale) in `params`.
struct SlabModel {
    lobes: vec4<f32>,
    params: vec4<f32>,
}

// The lobes with each asymmetry raised to `power`, keeping its sign (forward_lobes).
fn slab_forward_lobes(lobes: vec4<f32>, power: f32) -> vec4<f32> {
    return vec4<f32>(sign(lobes.xy) * pow(abs(lobes.xy), vec2<f32>(power)), lobes.zw);
}

// Mean cosine of the phase lobes (PhaseLobes::mean_cosine).
fn slab_mean_cosine(lobes: vec4<f32>) -> f32 {
    let g = lobes.y;
    let a = lobes.z;
    let draine = g * (1.0 + a * (3.0 + 2.0 * g * g) / 5.0) / (1.0 + a * (1.0 + 2.0 * g * g) / 3.0);
    return (1.0 - lobes.w) * lobes.x + lobes.w * draine;
}

// Moments (I0, I1) of the diffuse radiance at scaled depth t of a slab of scaled thickness
// `thickness`, scaled albedo `omega` and asymmetry `g`, per unit irradiance of the beam entering at
// `mu0` to the normal (diffuse_moments).
fn slab_diffuse_moments(omega: f32, g: f32, t: f32, thickness: f32, mu0: f32) -> vec2<f32> {
    let lambda_sq = 3.0 * (1.0 - omega) * (1.0 - omega * g);
    let lambda = sqrt(lambda_sq);
    var resonance = lambda_sq * mu0 * mu0 - 1.0;
    resonance = select(resonance, 1e-3, abs(resonance) < 1e-3);
    let source = 3.0 * omega / (4.0 * PI);
    let p0 = mu0 * mu0 * source * (1.0 + g - omega * g) / resonance;
    let p1 = mu0 * (3.0 * (1.0 - omega) * p0 - source);
    let l = lambda / (1.0 - omega * g);
    let plus = 0.5 + l / 3.0;
    let minus = 0.5 - l / 3.0;
    let across = exp(-lambda * thickness);
    let beam_out = exp(-thickness / mu0);
    let r_top = -(p0 / 2.0 + p1 / 3.0);
    let r_bottom = -(p0 / 2.0 - p1 / 3.0) * beam_out;
    let det = minus * minus * across * across - plus * plus;
    let a = (r_top * minus * across - plus * r_bottom) / det;
    let b = (minus * across * r_bottom - plus * r_top) / det;
    let from_bottom = exp(-lambda * max(thickness - t, 0.0));
    let from_top = exp(-lambda * t);
    let beam = exp(-t / mu0);
    let i0 = a * from_bottom + b * from_top + p0 * beam;
    let i1 = -l * a * from_bottom + l * b * from_top + p1 * beam;
    return vec2<f32>(i0, i1);
}

// The diffuse light of the scaled slab along the sun of a point `depth` under its lit face and
// `back` over the far one, scattered toward the eye at cos_theta (SunSlab::scattering's diffuse).
fn slab_diffuse(model: SlabModel, depth: f32, back: f32, cos_theta: f32) -> f32 {
    let f = model.params.x;
    let albedo = model.params.y;
    let g = slab_mean_cosine(model.lobes);
    let thinning = 1.0 - albedo * f;
    let omega = min((1.0 - f) * albedo / thinning, SLAB_MAX_TWO_STREAM_ALBEDO);
    let scaled_g = (g - f) / (1.0 - f);
    let thickness = thinning * (depth + model.params.w * back);
    let moments = slab_diffuse_moments(omega, scaled_g, thinning * depth, thickness, 1.0);
    return max(moments.x + g * cos_theta * moments.y, 0.0);
}

// The light the forward peak scattered that the beam still carries at tau_sun, scattered toward the
// eye once more with its spread after a mean n peak scatterings (SunSlab::peak_beam).
fn slab_peak_beam(model: SlabModel, cos_theta: f32, tau_sun: f32) -> f32 {
    let in_peak = model.params.x * model.params.y * tau_sun;
    let scattered = exp(-(tau_sun - in_peak)) - exp(-tau_sun);
    let scatterings = in_peak / max(1.0 - exp(-in_peak), 1e-20);
    let lobes = slab_forward_lobes(model.lobes, scatterings + 1.0);
    return select(0.0, phase_eval(lobes, cos_theta) * scattered, scattered > 0.0);
}

// The sun's light scattered toward the eye per unit scattering coefficient and unit irradiance,
// tau_sun under the sunlit side and tau_back over the far one, cos_theta between the view ray and
// the direction to the sun (SunSlab::scattering).
fn slab_scattering(model: SlabModel, cos_theta: f32, tau_sun: f32, tau_back: f32) -> f32 {
    let diffuse = slab_diffuse(model, tau_sun, tau_back, cos_theta);
    return slab_beam_scattering(model, cos_theta, tau_sun) + model.params.z * diffuse;
}

// Single scattering and the forward peak's beam: the part the march adds per sample when the
// light volume holds the diffuse light (SunSlab::beam_scattering).
fn slab_beam_scattering(model: SlabModel, cos_theta: f32, tau_sun: f32) -> f32 {
    return phase_eval(model.lobes, cos_theta) * exp(-tau_sun) + slab_peak_beam(model, cos_theta, tau_sun);
}
