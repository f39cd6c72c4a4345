//! Optics of cloud droplets: phase functions and their sampling, and the energy-conserving
//! integration step of ray marching.
//!
//! Each CPU formula has a WGSL twin ([`PHASE_WGSL`]) that shaders include by concatenation.

pub mod phase;
pub mod step;

pub use phase::{PhaseLobes, draine, henyey_greenstein};
pub use step::MarchState;

/// WGSL source of the phase functions (`phase_hg`, `phase_draine`, `phase_eval`, `phase_scaled`):
/// functions only, to be concatenated into a shader module.
pub const PHASE_WGSL: &str = include_str!("phase.wgsl");

#[cfg(test)]
pub(crate) mod test_support;

#[cfg(test)]
mod tests {
    #[test]
    fn phase_wgsl_validates() {
        super::test_support::validate_wgsl("phase.wgsl", super::PHASE_WGSL);
    }
}
