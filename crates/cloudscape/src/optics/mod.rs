//! Optics of cloud droplets: phase functions and their sampling, and the energy-conserving
//! integration step of ray marching.
//!
//! Each CPU formula has a WGSL twin in `phase.wgsl` (the `phase` shader module).

pub(crate) mod phase;
pub(crate) mod slab;
pub(crate) mod step;

pub use phase::{
    DIFFRACTION_PEAK_MIN_ASYMMETRY, Lobe, Octaves, PhaseLobes, draine, henyey_greenstein,
};
pub use slab::SunSlab;
pub use step::MarchState;

/// Eddington (two-stream) diffuse transmittance of a conservatively scattering slab of optical
/// depth `tau` whose phase function has mean cosine `g`: `1 / (1 + 3/4 (1 - g) tau)` (e.g. Bohren
/// 1987, "Multiple scattering of light and some of its observable consequences", Am. J. Phys. 55):
/// diffuse light is dimmed by the transport optical depth `(1 - g) tau`, and only algebraically.
/// `frame_diffuse_transmittance` in `frame.wgsl`.
pub fn diffuse_transmittance(tau: f32, g: f32) -> f32 {
    1.0 / (1.0 + 0.75 * (1.0 - g) * tau)
}

/// The share of the light from below in the mean diffuse radiance inside a conservatively
/// scattering slab lit diffusely from above (radiance `L_top`) and below (`L_bottom`), at optical
/// depth `tau_above` under its top and `tau_below` over its bottom: the two-stream (Eddington)
/// solution `J = L_top + (L_bottom - L_top) w` with
/// `w = (k tau_above + 1/2) / (1 + k (tau_above + tau_below))`, `k = 3/4 (1 - g)`.
///
/// Derivation, in the two-stream model whose transmittance is [`diffuse_transmittance`]: without
/// absorption the net flux `F_down - F_up` is the same at every depth and `dF_down / dtau =
/// dF_up / dtau = -k (F_down - F_up)`; the boundary fluxes `pi L_top` (top, down) and
/// `pi L_bottom` (bottom, up) fix both, and `J = (F_down + F_up) / (2 pi)`. Exact in a white
/// furnace (`J = L` when both sides are `L`), the mean of the two sides at either face of a thin
/// slab, and `L_top` near the top of a thick one (which reflects the sky back to itself).
/// `frame_two_stream_share_from_below` in `frame.wgsl`.
pub fn two_stream_share_from_below(tau_above: f32, tau_below: f32, g: f32) -> f32 {
    let k = 0.75 * (1.0 - g);
    (k * tau_above + 0.5) / (1.0 + k * (tau_above + tau_below))
}

#[cfg(test)]
pub(crate) mod test_support;

#[cfg(test)]
mod tests {
    use super::*;

    /// At each face of a slab lit from above only, the mean radiance is the mean of what comes in
    /// and what goes out there: at the bottom `(T + 0) / 2`, at the top `(1 + R) / 2` with
    /// `R = 1 - T`, the two-stream transmittance and reflectance of the same model.
    #[test]
    fn the_two_stream_field_meets_the_slab_transmittance_at_both_faces() {
        for (tau, g) in [(0.0, 0.85), (1.0, 0.0), (30.0, 0.85), (200.0, 0.5)] {
            let t = diffuse_transmittance(tau, g);
            let bottom = 1.0 - two_stream_share_from_below(tau, 0.0, g);
            let top = 1.0 - two_stream_share_from_below(0.0, tau, g);
            assert!(
                (bottom - t / 2.0).abs() < 1e-6,
                "{tau} {g}: {bottom} vs {t}"
            );
            assert!(
                (top - (2.0 - t) / 2.0).abs() < 1e-6,
                "{tau} {g}: {top} vs {t}"
            );
        }
    }

    /// Between the faces the field falls linearly with depth (constant net flux).
    #[test]
    fn the_two_stream_field_is_linear_in_depth() {
        let at = |tau_above: f32| two_stream_share_from_below(tau_above, 40.0 - tau_above, 0.8);
        let (a, b, c) = (at(10.0), at(20.0), at(30.0));
        assert!(((a + c) / 2.0 - b).abs() < 1e-6);
        assert!(a < b && b < c);
    }
}
