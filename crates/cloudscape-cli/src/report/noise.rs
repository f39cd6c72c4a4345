//! How noisy a path-traced reference is, and what converging it would take.
//!
//! A reference is the sample-weighted mean `R = (n0 h0 + n1 h1) / N` of two halves traced with
//! independent seeds (`N = n0 + n1` samples per pixel). Their difference `D = h0 - h1` has mean 0
//! and variance `s2 (1 / n0 + 1 / n1)` per pixel (`s2` the variance of one path), and it is
//! uncorrelated with `R`. Scaled by `sqrt(n0 n1) / N` it has variance `s2 / N`: exactly that of
//! `R`'s own error. So `R + D sqrt(n0 n1) / N` is an image exactly as far from `R`, in
//! distribution, as `R` is from the converged image, and comparing the two estimates the
//! reference's own error without knowing the converged image. The halves against each other
//! (the figure the report used to call the floor) hold the noise of two images of half the
//! samples: four times the variance of the reference's.
//!
//! Noise of half the amplitude (`D` scaled by half as much) is what four times the samples would
//! leave; the ratio of the two comparisons gives how HDR-FLIP falls with the noise here (it is not
//! proportional: FLIP's perceptual response flattens small differences), and from it the samples
//! a target asks for.

use super::references::Reference;
use crate::compare::Comparison;
use anyhow::Result;
use cloudscape::image::HdrImage;

/// A reference's noise, measured three ways.
pub struct ReferenceNoise {
    /// The two halves against each other.
    pub halves: Comparison,
    /// The reference against itself plus noise of its own size: its estimated error.
    pub own: Comparison,
    /// The reference against itself plus noise of half its size: the error four times the samples
    /// would leave.
    pub with_four_times_the_samples: Comparison,
}

impl ReferenceNoise {
    /// Measures `reference`'s noise; `image` is the reference itself ([`Reference::image`]).
    pub fn of(reference: &Reference, image: &HdrImage) -> Result<ReferenceNoise> {
        Ok(ReferenceNoise {
            halves: Comparison::of(&reference.halves[0], &reference.halves[1], None)?,
            own: against_own_noise(reference, image, 1.0)?,
            with_four_times_the_samples: against_own_noise(reference, image, 0.5)?,
        })
    }

    /// How HDR-FLIP of the reference's error scales with the noise amplitude here: `FLIP ~
    /// amplitude^k`, from halving the amplitude; 1 where that did not lower it.
    pub fn flip_exponent(&self) -> f64 {
        flip_exponent(
            self.own.flip_mean,
            self.with_four_times_the_samples.flip_mean,
        )
    }

    /// Samples per pixel that would bring the reference's estimated HDR-FLIP error, now measured
    /// at `spp`, to `target`: the amplitude falls as `1 / sqrt(spp)`, FLIP as its
    /// [`Self::flip_exponent`] power.
    pub fn spp_for(&self, spp: u32, target: f32) -> f64 {
        spp_for(spp, self.own.flip_mean, target, self.flip_exponent())
    }
}

/// The reference's estimated error alone ([`ReferenceNoise::own`]), where the other two figures are
/// not wanted; `image` is the reference itself.
pub fn own_error(reference: &Reference, image: &HdrImage) -> Result<Comparison> {
    against_own_noise(reference, image, 1.0)
}

/// The reference plus noise of its own size: as far from the reference, in distribution, as the
/// reference is from the converged image.
pub fn own_noise_image(reference: &Reference) -> HdrImage {
    with_own_noise(reference, 1.0)
}

/// `image`, the reference, against itself plus `amplitude` times noise of its own size.
fn against_own_noise(
    reference: &Reference,
    image: &HdrImage,
    amplitude: f32,
) -> Result<Comparison> {
    Comparison::of(image, &with_own_noise(reference, amplitude), None)
}

/// The reference plus `amplitude` times noise of its own size: `R + amplitude D sqrt(n0 n1) / N`.
fn with_own_noise(reference: &Reference, amplitude: f32) -> HdrImage {
    let [n0, n1] = reference.record.halves.map(|h| h.spp as f32);
    let total = (n0 + n1).max(1.0);
    let scale = amplitude * (n0 * n1).sqrt() / total;
    reference.combination(n0 / total + scale, n1 / total - scale)
}

/// `k` in `FLIP ~ amplitude^k` from the FLIP at one amplitude and at half of it; 1 where the
/// second is not lower (noise too small to measure the slope).
fn flip_exponent(flip: f32, flip_at_half: f32) -> f64 {
    if flip_at_half > 0.0 && flip_at_half < flip {
        (f64::from(flip) / f64::from(flip_at_half)).log2()
    } else {
        1.0
    }
}

/// Samples per pixel taking a FLIP of `flip` at `spp` down to `target`, with `FLIP ~ spp^(-k/2)`.
fn spp_for(spp: u32, flip: f32, target: f32, k: f64) -> f64 {
    let ratio = f64::from((flip / target).max(1.0));
    f64::from(spp) * ratio.powf(2.0 / k)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::references::{HalfRecord, Record};
    use cloudscape_reference::rng::Rng;

    /// A grey image of `n` pixels of radiance 1 plus Gaussian noise of variance `1 / spp`.
    fn noisy_half(n: usize, spp: u32, seed: u64) -> HdrImage {
        let sigma = 1.0 / (spp as f32).sqrt();
        let pixels = (0..n)
            .map(|i| {
                let u = Rng::for_sample(seed, 0, i as u64).next_vec2();
                let gauss = (-2.0 * (1.0 - u.x).ln()).sqrt() * (std::f32::consts::TAU * u.y).cos();
                [1.0 + sigma * gauss, 1.0, 1.0, 1.0]
            })
            .collect();
        HdrImage {
            width: n as u32,
            height: 1,
            pixels,
        }
    }

    /// Mean squared difference of the red channels.
    fn mean_squared(a: &HdrImage, b: impl Fn(usize) -> f32) -> f64 {
        let sum: f64 = a
            .pixels
            .iter()
            .enumerate()
            .map(|(i, p)| f64::from(p[0] - b(i)).powi(2))
            .sum();
        sum / a.pixels.len() as f64
    }

    #[test]
    fn the_scaled_difference_is_as_large_as_the_references_own_error() {
        let (n, spp) = (40_000, [300, 100]);
        let half = |i: usize| HalfRecord {
            seed: i as u64,
            spp: spp[i],
            seconds: 1.0,
        };
        let reference = Reference {
            halves: [noisy_half(n, spp[0], 7), noisy_half(n, spp[1], 8)],
            record: Record {
                key: String::new(),
                width: n as u32,
                height: 1,
                halves: [half(0), half(1)],
            },
        };
        let image = reference.image();
        let error = mean_squared(&image, |_| 1.0);
        let noisy = with_own_noise(&reference, 1.0);
        let estimate = mean_squared(&image, |i| noisy.pixels[i][0]);
        // Both near 1 / 400 (standard error of either about 0.7 %).
        assert!((error * 400.0 - 1.0).abs() < 0.03, "{error}");
        assert!(
            (estimate / error - 1.0).abs() < 0.05,
            "{estimate} vs {error}"
        );
        let halves = mean_squared(&reference.halves[0], |i| reference.halves[1].pixels[i][0]);
        assert!(halves / error > 5.0, "the halves differ by 1/300 + 1/100");
    }

    #[test]
    fn the_exponent_is_the_slope_of_flip_over_amplitude() {
        assert!((flip_exponent(0.08, 0.04) - 1.0).abs() < 1e-9);
        assert!((flip_exponent(0.08, 0.05) - (1.6f64).log2()).abs() < 1e-6);
        assert_eq!(flip_exponent(0.01, 0.012), 1.0);
    }

    #[test]
    fn samples_needed_follow_the_measured_slope() {
        // Proportional FLIP: twice the target needs four times the samples.
        assert!((spp_for(100, 0.04, 0.02, 1.0) - 400.0).abs() < 1e-6);
        // FLIP as the square root of the amplitude: 16 times.
        assert!((spp_for(100, 0.04, 0.02, 0.5) - 1600.0).abs() < 1e-6);
        // At or under the target: nothing more.
        assert_eq!(spp_for(100, 0.01, 0.02, 0.7), 100.0);
    }
}
