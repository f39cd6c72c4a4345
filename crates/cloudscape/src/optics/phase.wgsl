// Phase functions of cloud droplets: the GPU twin of optics/phase.rs (same formulas, same names).
//
// Sign convention: cos_theta = dot(direction light travels before scattering, direction after),
// so forward scattering is cos_theta = 1. Values are per steradian.
// Functions only (no bindings, no entry points).


// Henyey-Greenstein (Henyey & Greenstein 1941): (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^(3/2)).
// The denominator is written as a sum of non-negative terms, (1 - g)^2 + 2 g (1 - mu) for g >= 0
// and (1 + g)^2 - 2 g (1 + mu) for g < 0, to keep f32 precision at the peak of the lobe.
fn phase_hg(g: f32, cos_theta: f32) -> f32 {
    let forward = (1.0 - g) * (1.0 - g) + 2.0 * g * (1.0 - cos_theta);
    let backward = (1.0 + g) * (1.0 + g) - 2.0 * g * (1.0 + cos_theta);
    let denom = select(backward, forward, g >= 0.0);
    return (1.0 - g * g) / (4.0 * PI * denom * sqrt(denom));
}

// Draine (Draine 2003): HG(g, mu) (1 + alpha mu^2) / (1 + alpha (1 + 2 g^2) / 3).
fn phase_draine(g: f32, alpha: f32, cos_theta: f32) -> f32 {
    let shape = 1.0 + alpha * cos_theta * cos_theta;
    let norm = 1.0 + alpha * (1.0 + 2.0 * g * g) / 3.0;
    return phase_hg(g, cos_theta) * shape / norm;
}

// Mixture (Jendersie & d'Eon 2023): (1 - w) HG(g_hg) + w Draine(g_draine, alpha).
// lobes = (g_hg, g_draine, alpha, w_draine), as PhaseLobes::to_gpu() writes it.
fn phase_eval(lobes: vec4<f32>, cos_theta: f32) -> f32 {
    let hg = phase_hg(lobes.x, cos_theta);
    let draine = phase_draine(lobes.y, lobes.z, cos_theta);
    return (1.0 - lobes.w) * hg + lobes.w * draine;
}

// The share of phase_eval(lobes, cos_theta) outside a peak of weight peak_weight in the HG lobe
// (PhaseLobes::broad_share).
fn phase_broad_share(lobes: vec4<f32>, peak_weight: f32, cos_theta: f32) -> f32 {
    let peak = peak_weight * phase_hg(lobes.x, cos_theta);
    return clamp(1.0 - peak / phase_eval(lobes, cos_theta), 0.0, 1.0);
}

// Both asymmetries times factor (multiple-scattering octaves, Wrenninge 2013).
fn phase_scaled(lobes: vec4<f32>, factor: f32) -> vec4<f32> {
    return vec4<f32>(lobes.xy * factor, lobes.zw);
}

// Sun light scattered at optical depth tau from the sun, per unit sigma_s and unit irradiance,
// with `count` multiple-scattering octaves (Wrenninge 2013, "Oz: The Great and Volumetric"):
// sum_i b^i p(c^i g, mu) exp(-a^i tau), factors = (a, b, c). Octaves::scattering.
fn phase_octaves(lobes: vec4<f32>, factors: vec3<f32>, count: u32, cos_theta: f32, tau: f32) -> f32 {
    var sum = 0.0;
    var weight = 1.0;
    var extinction = 1.0;
    var anisotropy = 1.0;
    for (var i = 0u; i < count; i++) {
        sum += weight * phase_eval(phase_scaled(lobes, anisotropy), cos_theta) * exp(-extinction * tau);
        weight *= factors.y;
        extinction *= factors.x;
        anisotropy *= factors.z;
    }
    return sum;
}
