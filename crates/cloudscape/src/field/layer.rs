//! One cloud layer's parameters as the density function uses them, and the shaping steps of
//! Schneider 2015 ("The Real-time Volumetric Cloudscapes of Horizon Zero Dawn") and Schneider 2017
//! ("Nubis: Authoring Real-Time Volumetric Cloudscapes with the Decima Engine").

use super::noise::{hash_to_unit, lerp, pcg_hash, remap};
use super::profile::TypeTable;
use super::texture::{Texture8, unorm8};
use crate::scene::CloudLayer;
use glam::{Vec2, Vec3, Vec4};

/// A layer ready for density evaluation.
#[derive(Clone, Debug, PartialEq)]
pub struct LayerField {
    /// Altitude of the bottom, metres.
    pub bottom_m: f32,
    /// Thickness, metres.
    pub thickness_m: f32,
    /// Coverage threshold 0..1 (Schneider 2015's coverage) that gives the scene's cloud fraction.
    pub coverage: f32,
    /// Extinction of the densest cloud, m^-1.
    pub extinction_per_m: f32,
    /// The type mix as a lookup from the weather type channel.
    pub types: TypeTable,
    /// Wind, m/s, (east, south).
    pub wind_m_per_s: Vec2,
    /// Offset into the weather map (in map units) that decorrelates layers.
    pub weather_offset: Vec2,
    /// Offset into the noise (metres) that decorrelates layers.
    pub noise_offset_m: Vec3,
}

impl LayerField {
    /// The layer of a scene entry; its offsets come from hashing `noise_seed`.
    pub fn new(layer: &CloudLayer) -> LayerField {
        let unit =
            |k: u32| hash_to_unit(pcg_hash(layer.noise_seed.wrapping_mul(4).wrapping_add(k)));
        LayerField {
            bottom_m: layer.bottom_m,
            thickness_m: layer.thickness_m,
            coverage: coverage_threshold(layer.coverage),
            extinction_per_m: layer.extinction_per_m,
            types: TypeTable::from_mix(&layer.types),
            wind_m_per_s: Vec2::from_array(layer.wind_m_per_s),
            weather_offset: Vec2::new(unit(0), unit(1)),
            noise_offset_m: Vec3::new(unit(2), unit(3), unit(2) * 0.5) * 1.0e4,
        }
    }

    /// Local coverage from the weather map's coverage channel, shifted by the layer's threshold:
    /// `saturate(map + 2 threshold - 1)`, so 0 clears the layer and 1 fills it.
    pub fn local_coverage(&self, map_coverage: f32) -> f32 {
        (map_coverage + 2.0 * self.coverage - 1.0).clamp(0.0, 1.0)
    }
}

/// Measured fraction of the sky covered (columns of optical depth above 1) against the coverage
/// threshold, for cumulus with the default noise: pairs (fraction, threshold). Measured with
/// `cargo test --release -p cloudscape --test coverage -- --ignored --nocapture`; re-measure when the
/// noise or the height gradients change.
const COVERAGE_CALIBRATION: [(f32, f32); 14] = [
    (0.0, 0.0),
    (0.01, 0.05),
    (0.04, 0.1),
    (0.14, 0.15),
    (0.27, 0.2),
    (0.39, 0.25),
    (0.53, 0.3),
    (0.65, 0.35),
    (0.74, 0.4),
    (0.82, 0.45),
    (0.89, 0.5),
    (0.97, 0.6),
    (0.99, 0.7), // printed as 1.00: the whole sky is reached only at threshold 1
    (1.0, 1.0),
];

/// The coverage threshold that covers `fraction` of the sky (piecewise linear in
/// [`COVERAGE_CALIBRATION`]).
pub fn coverage_threshold(fraction: f32) -> f32 {
    let f = fraction.clamp(0.0, 1.0);
    COVERAGE_CALIBRATION
        .windows(2)
        .find(|w| f <= w[1].0)
        .map_or(1.0, |w| {
            let t = (f - w[0].0) / (w[1].0 - w[0].0);
            w[0].1 + t * (w[1].1 - w[0].1)
        })
}

/// Low-frequency cloud shape from the base texel: the Perlin-Worley channel remapped by the Worley
/// fBm of the other three, `remap(R, fbm - 1, 1, 0, 1)` with fbm = 0.625 G + 0.25 B + 0.125 A
/// (Schneider 2015).
pub fn base_shape(base: Vec4) -> f32 {
    let fbm = base.y * 0.625 + base.z * 0.25 + base.w * 0.125;
    remap(base.x, fbm - 1.0, 1.0, 0.0, 1.0)
}

/// Coverage applied to the shaped base, `remap(shape, 1 - c, 1, 0, 1)` (Schneider 2015 also multiplies
/// by `c`, thinning sparse clouds; we leave density to the weather map's density channel, so that a
/// layer's `extinction_per_m` is the extinction of its cloud cores), with the
/// cumulonimbus anvil bias that widens coverage near the top, `c^remap(f, 0.7, 0.8, 1, lerp(1, 0.5,
/// anvil))` (Schneider 2017), `anvil` growing from type 2 (cumulus) to 3 (cumulonimbus).
pub fn apply_coverage(shape: f32, coverage: f32, type_coord: f32, f: f32) -> f32 {
    let anvil = (type_coord - 2.0).clamp(0.0, 1.0);
    let exponent = remap(f.clamp(0.7, 0.8), 0.7, 0.8, 1.0, lerp(1.0, 0.5, anvil));
    let c = coverage.powf(exponent);
    if c <= 0.0 {
        return 0.0;
    }
    remap(shape, 1.0 - c, 1.0, 0.0, 1.0)
}

/// Detail erosion (Schneider 2015): the detail fBm, inverted from wispy at the base to billowy
/// above 10 % of the layer, is subtracted through `remap(density, detail * erosion, 1, 0, 1)`.
pub fn erode(density: f32, detail: Vec4, f: f32, erosion: f32) -> f32 {
    let fbm = detail.x * 0.625 + detail.y * 0.25 + detail.z * 0.125;
    remap(density, erosion_modifier(fbm, f) * erosion, 1.0, 0.0, 1.0).clamp(0.0, 1.0)
}

/// The detail fBm as [`erode`] subtracts it at height fraction `f`: wispy (the fBm) at the base,
/// billowy (its complement) above 10 % of the layer.
fn erosion_modifier(fbm: f32, f: f32) -> f32 {
    lerp(fbm, 1.0 - fbm, billow_blend(f))
}

/// How far [`erosion_modifier`] has turned from the fBm to its complement at height fraction `f`.
fn billow_blend(f: f32) -> f32 {
    (f * 10.0).clamp(0.0, 1.0)
}

/// The detail fBm's mean and standard deviation over a baked detail texture: what
/// [`mean_erode`] needs of the noise (about 0.48 and 0.075 for every seed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DetailStatistics {
    /// Mean of the fBm [`erode`] reads.
    pub fbm_mean: f32,
    /// Its standard deviation.
    pub fbm_sd: f32,
}

impl DetailStatistics {
    /// The statistics of every texel of `detail`, the baked detail noise.
    pub fn of(detail: &Texture8) -> DetailStatistics {
        let fbm = |&t: &[u8; 4]| {
            let v = unorm8(t);
            (v.x * 0.625 + v.y * 0.25 + v.z * 0.125) as f64
        };
        let n = detail.texels.len() as f64;
        let mean = detail.texels.iter().map(fbm).sum::<f64>() / n;
        let variance = detail
            .texels
            .iter()
            .map(|t| (fbm(t) - mean).powi(2))
            .sum::<f64>()
            / n;
        DetailStatistics {
            fbm_mean: mean as f32,
            fbm_sd: variance.sqrt() as f32,
        }
    }
}

/// The expectation of [`erode`] over the detail noise: the density light paths read. The noise
/// varies over tens of metres (its correlation falls to a half in about 90 m at the default
/// 700 m period), finer than a light path's segments, so a path sees the eroded density's mean
/// rather than the coarse density, its upper bound (Schneider 2015's cheap light samples). With
/// the subtracted `x = modifier * erosion` taken as normal, `N(mu, s)` (the modifier is the fBm
/// or its complement, or a blend `t` of the two whose spread is `|1 - 2t|` the fBm's), the mean of
/// the ramp `(d - x)+` is `(d - mu) Phi(z) + s phi(z)`, `z = (d - mu) / s` (the normal partial
/// expectation), divided by `1 - mu` as [`erode`]'s remap divides by `1 - x`: within 0.002 of
/// the average over the baked noise at erosion 0.4 (the default), 0.01 at 0.8.
pub fn mean_erode(density: f32, f: f32, erosion: f32, noise: DetailStatistics) -> f32 {
    let blend = billow_blend(f);
    let mu = erosion_modifier(noise.fbm_mean, f) * erosion;
    let s = ((1.0 - 2.0 * blend).abs() * noise.fbm_sd * erosion).max(1e-6);
    let z = ((density - mu) / s).clamp(-8.0, 8.0);
    let pdf = (-0.5 * z * z).exp() / (2.0 * std::f32::consts::PI).sqrt();
    (((density - mu) * normal_cdf(z) + s * pdf) / (1.0 - mu)).clamp(0.0, 1.0)
}

/// The standard normal distribution function by Bowling et al. 2009's logistic approximation
/// ("A logistic approximation to the cumulative normal distribution", J. Industrial Engineering
/// and Management 2(1)): `1 / (1 + exp(-(0.07056 z^3 + 1.5976 z)))`, within 1.4e-4.
fn normal_cdf(z: f32) -> f32 {
    1.0 / (1.0 + (-(0.07056 * z * z * z + 1.5976 * z)).exp())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coverage_zero_and_one_are_clear_and_full() {
        let l = LayerField::new(&CloudLayer {
            coverage: 0.0,
            ..CloudLayer::default()
        });
        assert_eq!(l.local_coverage(1.0), 0.0);
        let l = LayerField::new(&CloudLayer {
            coverage: 1.0,
            ..CloudLayer::default()
        });
        assert_eq!(l.local_coverage(0.0), 1.0);
        assert_eq!(apply_coverage(0.7, 0.0, 2.0, 0.5), 0.0);
        assert!((apply_coverage(0.7, 1.0, 2.0, 0.5) - 0.7).abs() < 1e-6);
        assert!(
            apply_coverage(0.7, 0.2, 2.0, 0.5) <= 0.0,
            "below the coverage threshold"
        );
    }

    #[test]
    fn coverage_threshold_is_monotone_from_clear_to_full() {
        assert_eq!(coverage_threshold(0.0), 0.0);
        assert_eq!(coverage_threshold(1.0), 1.0);
        let values: Vec<f32> = (0..=100)
            .map(|i| coverage_threshold(i as f32 / 100.0))
            .collect();
        assert!(values.windows(2).all(|w| w[1] > w[0]), "{values:?}");
    }

    #[test]
    fn anvil_widens_only_cumulonimbus_tops() {
        let (shape, c) = (0.6, 0.5);
        assert_eq!(
            apply_coverage(shape, c, 2.0, 0.9),
            apply_coverage(shape, c, 2.0, 0.5)
        );
        assert!(apply_coverage(shape, c, 3.0, 0.9) > apply_coverage(shape, c, 3.0, 0.5));
    }

    #[test]
    fn erosion_only_removes() {
        let detail = Vec4::new(0.8, 0.6, 0.4, 1.0);
        for d in [0.05, 0.3, 0.9] {
            assert!(erode(d, detail, 0.5, 0.35) <= d + 1e-6);
        }
        assert_eq!(erode(0.5, detail, 0.5, 0.0), 0.5);
    }

    #[test]
    fn mean_erosion_is_the_eroded_density_averaged_over_the_noise() {
        for seed in [3, 4000] {
            let detail = crate::field::noise::NoiseKind::Detail.bake(seed);
            let noise = DetailStatistics::of(&detail);
            assert!((noise.fbm_mean - 0.48).abs() < 0.02, "{noise:?}");
            for f in [0.0, 0.05, 0.5] {
                for erosion in [0.0, 0.4, 0.8] {
                    for i in 0..=20 {
                        let d = i as f32 / 20.0;
                        let eroded = |&t: &[u8; 4]| erode(d, unorm8(t), f, erosion);
                        let average = detail.texels.iter().map(eroded).sum::<f32>()
                            / detail.texels.len() as f32;
                        let mean = mean_erode(d, f, erosion, noise);
                        assert!(
                            (mean - average).abs() < 0.004 + 0.01 * erosion,
                            "seed {seed}, d {d}, f {f}, erosion {erosion}: {mean} against {average}"
                        );
                        assert!(mean <= d + 1e-6, "an upper bound remains one");
                    }
                }
            }
        }
    }
}
