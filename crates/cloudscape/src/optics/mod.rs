//! Optics of cloud droplets: phase functions and their sampling, and the energy-conserving
//! integration step of ray marching.
//!
//! Each CPU formula has a WGSL twin in `phase.wgsl` (the `phase` shader module).

pub mod phase;
pub mod step;

pub use phase::{PhaseLobes, draine, henyey_greenstein};
pub use step::MarchState;

/// Eddington (two-stream) diffuse transmittance of a conservatively scattering slab of optical
/// depth `tau` whose phase function has mean cosine `g`: `1 / (1 + 3/4 (1 - g) tau)` (e.g. Bohren
/// 1987, "Multiple scattering of light and some of its observable consequences", Am. J. Phys. 55):
/// diffuse light is dimmed by the transport optical depth `(1 - g) tau`, and only algebraically.
/// `frame_diffuse_transmittance` in `frame.wgsl`.
pub fn diffuse_transmittance(tau: f32, g: f32) -> f32 {
    1.0 / (1.0 + 0.75 * (1.0 - g) * tau)
}

#[cfg(test)]
pub(crate) mod test_support;
