//! HDR-FLIP (Andersson, Nilsson, Shirley & Akenine-Möller 2021, "Visualizing Errors in Rendered
//! High Dynamic Range Images", Eurographics short papers): LDR-FLIP of the two images tone-mapped
//! at a range of exposures chosen from the reference, the per-pixel maximum over exposures.
//!
//! The exposure range follows the paper: the start exposure maps the reference's largest
//! luminance, the stop exposure its median luminance, to the input `x` where the tone mapper
//! reaches `t = 0.85`; `max(2, ceil(stop - start))` exposures are spaced evenly between. One
//! deviation: the tone mapper is this crate's ACES (Hill's fit, the one the renderer shows)
//! instead of FLIP's Narkowicz fit; `x` is found for it numerically.

use super::compare::check_same_size;
use super::flip::{flip_error_map, summarise};
use super::{FlipStats, HdrImage, ImageError};
use crate::post::tonemap::tonemap_aces;
use crate::scene::Tonemap;
use glam::Vec3;

/// Tone-mapped value that the start and stop exposures aim at (Andersson et al. 2021).
const TARGET_DISPLAY_VALUE: f32 = 0.85;
/// Rec. 709 luminance weights of linear sRGB (ITU-R BT.709).
const LUMINANCE: Vec3 = Vec3::new(0.2126, 0.7152, 0.0722);
/// The median luminance is taken no lower than the largest times this (2^-20), so that a mostly
/// black reference still gets a finite exposure range.
const MIN_MEDIAN_FRACTION: f32 = 9.5e-7;

/// The exposures HDR-FLIP compares at, in stops (EV).
#[derive(Clone, Debug, PartialEq)]
pub struct ExposureRange {
    /// Shortest exposure: the brightest reference pixel reaches the target display value.
    pub start_ev: f32,
    /// Longest exposure: the median reference pixel reaches it.
    pub stop_ev: f32,
    /// Number of exposures, at least 2.
    pub count: u32,
}

impl ExposureRange {
    /// The range of the reference image (Andersson et al. 2021, section 3).
    pub fn of_reference(reference: &HdrImage) -> ExposureRange {
        let mut luminance: Vec<f32> = reference
            .pixels
            .iter()
            .map(|p| Vec3::new(p[0], p[1], p[2]).max(Vec3::ZERO).dot(LUMINANCE))
            .collect();
        luminance.sort_by(f32::total_cmp);
        let brightest = luminance.last().copied().unwrap_or(0.0);
        if brightest <= 0.0 {
            return ExposureRange {
                start_ev: 0.0,
                stop_ev: 0.0,
                count: 2,
            };
        }
        let median = luminance[luminance.len() / 2].max(brightest * MIN_MEDIAN_FRACTION);
        let x = aces_input_for(TARGET_DISPLAY_VALUE);
        let (start_ev, stop_ev) = ((x / brightest).log2(), (x / median).log2());
        ExposureRange {
            start_ev,
            stop_ev,
            count: ((stop_ev - start_ev).ceil() as u32).max(2),
        }
    }

    /// The exposures, evenly spaced from start to stop.
    pub fn exposures_ev(&self) -> impl Iterator<Item = f32> + '_ {
        let step = (self.stop_ev - self.start_ev) / (self.count - 1) as f32;
        (0..self.count).map(move |i| self.start_ev + step * i as f32)
    }
}

/// The grey input that ACES maps to display value `t`, by bisection (the curve is increasing).
fn aces_input_for(t: f32) -> f32 {
    let (mut lo, mut hi) = (0.0f32, 1.0e3f32);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if tonemap_aces(Vec3::splat(mid)).dot(LUMINANCE) < t {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// HDR-FLIP of `test` against `reference` (linear radiance): the statistics of the per-pixel
/// error map ([`hdr_flip_errors`]) and that map coloured with magma.
pub fn hdr_flip(
    reference: &HdrImage,
    test: &HdrImage,
) -> Result<(FlipStats, super::LdrImage), ImageError> {
    let errors = hdr_flip_errors(reference, test)?;
    let map = nv_flip::FlipImageFloat::with_data(reference.width, reference.height, &errors);
    Ok(summarise(&map))
}

/// The per-pixel HDR-FLIP error of `test` against `reference`, row by row: each pixel the largest
/// LDR-FLIP error over the exposures of [`ExposureRange::of_reference`] (Andersson et al. 2021).
pub fn hdr_flip_errors(reference: &HdrImage, test: &HdrImage) -> Result<Vec<f32>, ImageError> {
    let size = |i: &HdrImage| (i.width, i.height, i.pixels.len());
    check_same_size(size(reference), size(test))?;
    let range = ExposureRange::of_reference(reference);
    let mut worst = vec![0.0f32; reference.pixels.len()];
    for ev in range.exposures_ev() {
        let errors = flip_error_map(
            &reference.to_ldr(ev, Tonemap::Aces),
            &test.to_ldr(ev, Tonemap::Aces),
        )?
        .to_vec();
        worst
            .iter_mut()
            .zip(errors)
            .for_each(|(w, e)| *w = w.max(e));
    }
    Ok(worst)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 48x32 HDR image: a gradient over four decades with a bright disc.
    fn scene(gain: f32) -> HdrImage {
        let pixels = (0..48 * 32)
            .map(|i| {
                let (x, y) = ((i % 48) as f32, (i / 48) as f32);
                let mut v = 10f32.powf(x / 12.0 - 2.0);
                if (x - 30.0).powi(2) + (y - 16.0).powi(2) < 36.0 {
                    v = 500.0;
                }
                [v * gain, v * gain * 0.8, v * gain * 0.6, 1.0]
            })
            .collect();
        HdrImage {
            width: 48,
            height: 32,
            pixels,
        }
    }

    #[test]
    fn exposure_range_spans_brightest_to_median() {
        let x = aces_input_for(TARGET_DISPLAY_VALUE);
        let t = tonemap_aces(Vec3::splat(x)).dot(LUMINANCE);
        assert!((t - TARGET_DISPLAY_VALUE).abs() < 1e-5, "{t}");
        let range = ExposureRange::of_reference(&scene(1.0));
        assert!(range.start_ev < range.stop_ev, "{range:?}");
        assert_eq!(range.count, (range.stop_ev - range.start_ev).ceil() as u32);
        // Doubling the radiance shifts the range by one stop.
        let brighter = ExposureRange::of_reference(&scene(2.0));
        assert!((brighter.start_ev - range.start_ev + 1.0).abs() < 1e-4);
        let ev: Vec<f32> = range.exposures_ev().collect();
        assert_eq!(ev.first(), Some(&range.start_ev));
        assert!((ev[ev.len() - 1] - range.stop_ev).abs() < 1e-4);
    }

    #[test]
    fn identical_images_score_zero_and_differences_score_more_with_size() {
        let reference = scene(1.0);
        let (same, _) = hdr_flip(&reference, &reference).unwrap();
        assert_eq!(same.mean, 0.0);
        let (slight, _) = hdr_flip(&reference, &scene(1.1)).unwrap();
        let (large, map) = hdr_flip(&reference, &scene(2.0)).unwrap();
        assert!(
            slight.mean > 0.0 && large.mean > slight.mean,
            "{slight:?} {large:?}"
        );
        assert!(large.p99 >= large.p95 && large.p95 <= 1.0);
        assert_eq!((map.width, map.height), (48, 32));
        // A dark-region error invisible at the start exposure shows at the later ones.
        let mut dark = reference.clone();
        dark.pixels[48 * 5] = [0.02, 0.0, 0.0, 1.0];
        let (dark_stats, _) = hdr_flip(&reference, &dark).unwrap();
        assert!(dark_stats.mean > 0.0, "{dark_stats:?}");
        let black = HdrImage::new(48, 32);
        assert_eq!(ExposureRange::of_reference(&black).count, 2);
        assert!(matches!(
            hdr_flip(&reference, &HdrImage::new(2, 2)),
            Err(ImageError::SizeMismatch { .. })
        ));
    }
}
