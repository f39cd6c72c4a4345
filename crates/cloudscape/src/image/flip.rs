//! FLIP on display images (cargo feature `flip`: NVIDIA's C++ implementation).

use super::compare::check_same_size;
use super::{ImageError, LdrImage};

/// Viewing condition of the FLIP comparison: pixels per degree of visual angle, 67 for a 0.7 m
/// distance to a 0.7 m wide 4K monitor (Andersson et al. 2020, FLIP's default).
pub const FLIP_PIXELS_PER_DEGREE: f32 = 67.0;

/// Summary of a FLIP error map: per-pixel errors in [0, 1] (0 = indistinguishable).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlipStats {
    /// Mean error over all pixels (the single number FLIP's authors recommend).
    pub mean: f32,
    /// 95th percentile of the per-pixel error (nearest rank).
    pub p95: f32,
    /// 99th percentile of the per-pixel error (nearest rank).
    pub p99: f32,
}

/// RGB bytes of a display image, alpha dropped (FLIP compares what is shown).
fn rgb_bytes(image: &LdrImage) -> Vec<u8> {
    image
        .pixels
        .iter()
        .flat_map(|&[r, g, b, _]| [r, g, b])
        .collect()
}

/// LDR FLIP (Andersson et al. 2020, "FLIP: A Difference Evaluator for Alternating Images"; NVIDIA's
/// implementation through the `nv-flip` crate) of `test` against `reference`, both sRGB; alpha is
/// ignored. Returns the statistics and the error map coloured with the magma colour map.
pub fn flip(reference: &LdrImage, test: &LdrImage) -> Result<(FlipStats, LdrImage), ImageError> {
    Ok(summarise(&flip_error_map(reference, test)?))
}

/// The per-pixel LDR FLIP errors of `test` against `reference`, both sRGB.
pub(super) fn flip_error_map(
    reference: &LdrImage,
    test: &LdrImage,
) -> Result<nv_flip::FlipImageFloat, ImageError> {
    let size = |i: &LdrImage| (i.width, i.height, i.pixels.len());
    check_same_size(size(reference), size(test))?;
    let (width, height) = (reference.width, reference.height);
    let flip_image = |i: &LdrImage| nv_flip::FlipImageRgb8::with_data(width, height, &rgb_bytes(i));
    Ok(nv_flip::flip(
        flip_image(reference),
        flip_image(test),
        FLIP_PIXELS_PER_DEGREE,
    ))
}

/// Statistics of a FLIP error map and the map coloured with the magma colour map.
pub(super) fn summarise(error: &nv_flip::FlipImageFloat) -> (FlipStats, LdrImage) {
    let (width, height) = (error.width(), error.height());
    let mut pool = nv_flip::FlipPool::from_image(error);
    let stats = FlipStats {
        mean: pool.mean(),
        p95: pool.get_percentile(0.95, false),
        p99: pool.get_percentile(0.99, false),
    };
    let magma = error.apply_color_lut(&nv_flip::magma_lut()).to_vec();
    let pixels = magma
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2], u8::MAX])
        .collect();
    (
        stats,
        LdrImage {
            width,
            height,
            pixels,
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 64x64 image with a colour gradient and a pattern of squares.
    fn pattern(invert: bool) -> LdrImage {
        let pixels = (0..64 * 64)
            .map(|i| {
                let (x, y) = ((i % 64) as u8, (i / 64) as u8);
                let square = if ((x / 8) + (y / 8)) % 2 == 0 {
                    200
                } else {
                    40
                };
                let v = if invert { 255 - square } else { square };
                [v, x * 4, y * 4, 255]
            })
            .collect();
        LdrImage {
            width: 64,
            height: 64,
            pixels,
        }
    }

    #[test]
    fn identical_images_have_zero_flip() {
        let (stats, map) = flip(&pattern(false), &pattern(false)).expect("same size");
        assert_eq!(
            stats,
            FlipStats {
                mean: 0.0,
                p95: 0.0,
                p99: 0.0
            }
        );
        assert_eq!((map.width, map.height, map.pixels.len()), (64, 64, 64 * 64));
        assert!(
            map.pixels.iter().all(|&p| p == map.pixels[0]),
            "error map not uniform"
        );
    }

    #[test]
    fn different_images_have_large_flip() {
        let (stats, map) = flip(&pattern(false), &pattern(true)).expect("same size");
        assert!(stats.mean > 0.05, "{stats:?}");
        assert!(
            stats.p99 >= stats.p95 && stats.p95 >= stats.mean,
            "{stats:?}"
        );
        assert!(stats.p99 <= 1.0);
        assert!(
            map.pixels.iter().any(|&p| p != map.pixels[0]),
            "error map is flat"
        );
        assert_eq!(FLIP_PIXELS_PER_DEGREE, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    }

    #[test]
    fn size_mismatch_is_an_error() {
        let small = LdrImage {
            width: 1,
            height: 1,
            pixels: vec![[0; 4]],
        };
        let err = flip(&pattern(false), &small).expect_err("sizes differ");
        assert!(matches!(
            err,
            ImageError::SizeMismatch {
                reference: (64, 64),
                test: (1, 1)
            }
        ));
    }
}
