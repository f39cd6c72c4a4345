//! The energy-conserving integration step of ray marching through a participating medium.
//!
//! Within one step of length `dt` the medium is taken as homogeneous: extinction `sigma_t` and
//! source `S` are constant. The radiance the step adds towards the eye is then integrated exactly,
//! `S_int = int_0^dt S exp(-sigma_t x) dx = (S - S exp(-sigma_t dt)) / sigma_t`, so the result
//! does not depend on how finely a homogeneous region is cut, and a thick step never adds more
//! light than it occludes (Hillaire 2016, "Physically Based Sky, Atmosphere and Cloud Rendering
//! in Frostbite", section 5.6.3).

use glam::Vec3;

/// Radiance gathered and transmittance left along a view ray, marched from the eye outwards.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MarchState {
    /// In-scattered radiance that reaches the eye so far (scene radiometric units).
    pub radiance: Vec3,
    /// Transmittance from the eye to the current point, 0..1.
    pub transmittance: f32,
}

impl Default for MarchState {
    fn default() -> Self {
        Self::new()
    }
}

impl MarchState {
    /// At the eye: no radiance gathered, transmittance 1.
    pub const fn new() -> Self {
        MarchState {
            radiance: Vec3::ZERO,
            transmittance: 1.0,
        }
    }

    /// Advances the ray by one step of length `dt_m` metres through a medium of extinction
    /// `sigma_t_per_m` (m^-1, >= 0) and source `source`.
    ///
    /// `source` is `S`, the radiance scattered towards the eye per unit length of the ray
    /// (radiance per metre): `S = sigma_s * L_in`, where `sigma_s` is the scattering coefficient in
    /// m^-1 and `L_in` the in-scattered radiance, e.g. `sum over lights of p(theta) L_light
    /// T_light` plus ambient. Then (Hillaire 2016, section 5.6.3)
    /// `S_int = S (1 - exp(-sigma_t dt)) / sigma_t`, `L += T S_int`, `T *= exp(-sigma_t dt)`,
    /// where `(1 - exp(-sigma_t dt)) / sigma_t` tends to `dt` as `sigma_t -> 0`.
    pub fn step(&mut self, source: Vec3, sigma_t_per_m: f32, dt_m: f32) {
        debug_assert!(
            sigma_t_per_m >= 0.0 && dt_m >= 0.0,
            "negative extinction or step"
        );
        let step_transmittance = (-sigma_t_per_m * dt_m).exp();
        self.radiance += self.transmittance * source * attenuated_length_m(sigma_t_per_m, dt_m);
        self.transmittance *= step_transmittance;
    }
}

/// `int_0^dt exp(-sigma_t x) dx = (1 - exp(-sigma_t dt)) / sigma_t` in metres, computed with
/// `exp_m1` so that it stays accurate for small optical depths and equals `dt` at `sigma_t = 0`.
fn attenuated_length_m(sigma_t_per_m: f32, dt_m: f32) -> f32 {
    if sigma_t_per_m > 0.0 {
        -(-sigma_t_per_m * dt_m).exp_m1() / sigma_t_per_m
    } else {
        dt_m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SOURCE: Vec3 = Vec3::new(0.02, 0.03, 0.05);
    const SIGMA_T_PER_M: f32 = 0.05;
    const LENGTH_M: f32 = 60.0;

    /// Marches a homogeneous slab of `LENGTH_M` in `steps` equal steps of `dt_m` with `step`.
    fn march(steps: u32, step: impl Fn(&mut MarchState, f32)) -> MarchState {
        let dt_m = LENGTH_M / steps as f32;
        let mut state = MarchState::new();
        for _ in 0..steps {
            step(&mut state, dt_m);
        }
        state
    }

    fn energy_conserving(steps: u32, sigma_t_per_m: f32) -> MarchState {
        march(steps, |s, dt_m| s.step(SOURCE, sigma_t_per_m, dt_m))
    }

    /// The naive Riemann sum `L += T S dt; T *= exp(-sigma_t dt)`, for contrast.
    fn riemann(steps: u32) -> MarchState {
        march(steps, |s, dt_m| {
            s.radiance += s.transmittance * SOURCE * dt_m;
            s.transmittance *= (-SIGMA_T_PER_M * dt_m).exp();
        })
    }

    #[test]
    fn result_is_independent_of_step_count() {
        let (one, many) = (
            energy_conserving(1, SIGMA_T_PER_M),
            energy_conserving(1000, SIGMA_T_PER_M),
        );
        assert!(
            (one.radiance - many.radiance).abs().max_element() < 1e-5,
            "{one:?} vs {many:?}"
        );
        assert!((one.transmittance - many.transmittance).abs() < 1e-5);
        // And both equal the exact integral S (1 - exp(-sigma_t L)) / sigma_t.
        let exact = SOURCE * (1.0 - (-SIGMA_T_PER_M * LENGTH_M).exp()) / SIGMA_T_PER_M;
        assert!((one.radiance - exact).abs().max_element() < 1e-6);
    }

    #[test]
    fn transmittance_follows_beer_lambert() {
        let state = energy_conserving(37, SIGMA_T_PER_M);
        let beer_lambert = (-SIGMA_T_PER_M * LENGTH_M).exp();
        assert!((state.transmittance - beer_lambert).abs() < 1e-6);
    }

    #[test]
    fn vacuum_limit_is_source_times_length() {
        let state = energy_conserving(10, 0.0);
        assert!((state.radiance - SOURCE * LENGTH_M).abs().max_element() < 1e-5);
        assert_eq!(state.transmittance, 1.0);
        // A tiny extinction agrees with the limit instead of dividing 0 by 0.
        let thin = energy_conserving(1, 1e-30);
        assert!((thin.radiance - SOURCE * LENGTH_M).abs().max_element() < 1e-5);
    }

    #[test]
    fn riemann_sum_depends_on_step_count() {
        // One coarse naive step adds S * 60 m of light through an optical depth of 3, far more
        // than the medium can emit (S / sigma_t at most); only fine steps approach the exact value.
        let (coarse, fine) = (riemann(1), riemann(1000));
        let exact = energy_conserving(1, SIGMA_T_PER_M);
        assert!((coarse.radiance - fine.radiance).abs().max_element() > 0.5);
        assert!(coarse.radiance.x > 2.0 * exact.radiance.x);
        assert!((fine.radiance - exact.radiance).abs().max_element() < 0.01);
    }
}
