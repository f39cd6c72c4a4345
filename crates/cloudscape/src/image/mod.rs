//! Images: linear HDR frames and sRGB display frames, their files (OpenEXR, PNG) and their
//! comparison (FLIP, HDR-FLIP, relative MSE).
//!
//! Pixels are stored row by row from the top-left corner. The images, tone mapping and relative
//! MSE need no cargo feature; files need `png` or `exr`, FLIP and HDR-FLIP need `flip`.

mod compare;
#[cfg(feature = "exr")]
mod exr;
#[cfg(feature = "flip")]
mod flip;
#[cfg(feature = "flip")]
mod hdr_flip;
#[cfg(any(feature = "png", feature = "exr"))]
mod io;
#[cfg(feature = "png")]
mod png;

pub use compare::relative_mse;
#[cfg(feature = "flip")]
pub use flip::{FlipStats, flip};
#[cfg(feature = "flip")]
pub use hdr_flip::{ExposureRange, hdr_flip, hdr_flip_errors};
#[cfg(any(feature = "png", feature = "exr"))]
pub use io::write_image;

use std::path::PathBuf;

use glam::Vec3;
use rayon::prelude::*;

use crate::post::tonemap::{display_rgb8, quantize_u8, srgb_to_linear};
use crate::scene::Tonemap;

/// A linear HDR image: radiance RGB (scene radiometric units) and alpha (coverage, 0..1).
#[derive(Clone, Debug, PartialEq)]
pub struct HdrImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` pixels, `[r, g, b, a]`, row by row from the top left.
    pub pixels: Vec<[f32; 4]>,
}

/// A display image: sRGB-encoded 8-bit RGB and linear 8-bit alpha.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LdrImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` pixels, `[r, g, b, a]`, row by row from the top left.
    pub pixels: Vec<[u8; 4]>,
}

/// What went wrong reading, writing or comparing images; file errors name the file.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// The file name ends in neither `.png` nor `.exr`.
    #[error("{}: unsupported image file type (use a .png or .exr file name)", path.display())]
    UnsupportedFormat {
        /// The file.
        path: PathBuf,
    },
    /// The file type is known, but this build of cloudscape lacks the cargo feature that reads and
    /// writes it.
    #[error(
        "{}: this build of cloudscape cannot read or write .{feature} files; enable the `{feature}` cargo feature of cloudscape",
        path.display()
    )]
    MissingFeature {
        /// The file.
        path: PathBuf,
        /// The cargo feature (`png` or `exr`), also the file name extension.
        feature: &'static str,
    },
    /// The operating system refused to create, write, rename or read the file.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The PNG encoder or decoder failed.
    #[cfg(feature = "png")]
    #[error("{}: PNG: {source}", path.display())]
    Png {
        /// The file.
        path: PathBuf,
        /// The `image` crate's error.
        source: ::image::ImageError,
    },
    /// The OpenEXR encoder or decoder failed.
    #[cfg(feature = "exr")]
    #[error("{}: OpenEXR: {source}", path.display())]
    Exr {
        /// The file.
        path: PathBuf,
        /// The `exr` crate's error.
        source: ::exr::error::Error,
    },
    /// The pixel buffer does not hold `width * height` pixels, or the image is empty.
    #[error("image of {width}x{height} pixels holds {len} pixels (expected width * height > 0)")]
    BadSize {
        /// Declared width.
        width: u32,
        /// Declared height.
        height: u32,
        /// Pixels in the buffer.
        len: usize,
    },
    /// Two compared images differ in size.
    #[error("image sizes differ: reference {reference:?}, test {test:?} (width, height)")]
    SizeMismatch {
        /// Reference `(width, height)`.
        reference: (u32, u32),
        /// Test `(width, height)`.
        test: (u32, u32),
    },
}

/// Checks that a `width x height` image with `len` pixels is non-empty and consistent.
fn check_size(width: u32, height: u32, len: usize) -> Result<(), ImageError> {
    let expected = width as usize * height as usize;
    if expected == 0 || len != expected {
        return Err(ImageError::BadSize { width, height, len });
    }
    Ok(())
}

/// Rec. 709 luminance weights of linear sRGB (ITU-R BT.709).
const LUMINANCE_WEIGHTS: [f64; 3] = [0.2126, 0.7152, 0.0722];

impl HdrImage {
    /// A black, transparent image.
    pub fn new(width: u32, height: u32) -> Self {
        HdrImage {
            width,
            height,
            pixels: vec![[0.0; 4]; width as usize * height as usize],
        }
    }

    /// The same radiance with alpha 1: what a display should show of an image whose colour is
    /// already composited over its background and whose alpha is a mask (the path tracer's cloud
    /// coverage), which a viewer would otherwise blend over white.
    pub fn opaque(mut self) -> HdrImage {
        self.pixels.iter_mut().for_each(|p| p[3] = 1.0);
        self
    }

    /// Adds `weight` times `other` (the same size) to this image, pixel by pixel and channel by
    /// channel: a running mean of frames, each weighted by one over their count.
    pub fn add_scaled(&mut self, other: &HdrImage, weight: f32) {
        debug_assert_eq!(self.pixels.len(), other.pixels.len());
        for (total, pixel) in self.pixels.iter_mut().zip(&other.pixels) {
            for (t, p) in total.iter_mut().zip(pixel) {
                *t += p * weight;
            }
        }
    }

    /// The display image: exposure by `exposure_ev` stops, tone mapping by `op`, sRGB encoding;
    /// alpha is quantised linearly.
    pub fn to_ldr(&self, exposure_ev: f32, op: Tonemap) -> LdrImage {
        let pixels = self
            .pixels
            .par_iter()
            .map(|&[r, g, b, a]| {
                let [r8, g8, b8] = display_rgb8(Vec3::new(r, g, b), exposure_ev, op);
                [r8, g8, b8, quantize_u8(a)]
            })
            .collect();
        LdrImage {
            width: self.width,
            height: self.height,
            pixels,
        }
    }

    /// Mean Rec. 709 luminance of the radiance over all pixels (0 for an empty image).
    pub fn mean_luminance(&self) -> f64 {
        if self.pixels.is_empty() {
            return 0.0;
        }
        let total: f64 = (0..self.pixels.len()).map(|i| self.luminance(i)).sum();
        total / self.pixels.len() as f64
    }

    /// Rec. 709 luminance of pixel `index` (row by row).
    pub fn luminance(&self, index: usize) -> f64 {
        let p = self.pixels[index];
        (0..3).map(|c| LUMINANCE_WEIGHTS[c] * f64::from(p[c])).sum()
    }
}

impl LdrImage {
    /// Rec. 709 luma of every pixel: the luminance weights applied to the sRGB-encoded values
    /// (ITU-R BT.709), in [0, 1]; alpha is ignored. What a viewer sees change between frames.
    pub fn luma(&self) -> Vec<f32> {
        self.pixels
            .iter()
            .map(|p| {
                let weighted: f64 = (0..3).map(|c| LUMINANCE_WEIGHTS[c] * f64::from(p[c])).sum();
                (weighted / 255.0) as f32
            })
            .collect()
    }

    /// The linear image: RGB decoded from sRGB (IEC 61966-2-1), alpha scaled to 0..1.
    pub fn to_linear(&self) -> HdrImage {
        let decode = |v: u8| srgb_to_linear(f32::from(v) / 255.0);
        let pixels = self
            .pixels
            .iter()
            .map(|&[r, g, b, a]| [decode(r), decode(g), decode(b), f32::from(a) / 255.0])
            .collect();
        HdrImage {
            width: self.width,
            height: self.height,
            pixels,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn adding_scaled_frames_makes_their_mean() {
        let a = hdr_sample();
        let mut mean = HdrImage::new(a.width, a.height);
        let doubled = HdrImage {
            pixels: a.pixels.iter().map(|p| p.map(|v| 2.0 * v)).collect(),
            ..a.clone()
        };
        mean.add_scaled(&a, 0.5);
        mean.add_scaled(&doubled, 0.5);
        for (m, p) in mean.pixels.iter().zip(&a.pixels) {
            for (mc, pc) in m.iter().zip(p) {
                assert!(
                    (mc - 1.5 * pc).abs() <= 1e-6 * pc.abs(),
                    "{mc} against {pc}"
                );
            }
        }
    }

    /// A 4x3 HDR image over several decades, with varying alpha (the file tests' sample).
    pub(super) fn hdr_sample() -> HdrImage {
        let pixels = (0..12u8)
            .map(|i| {
                let v = f32::from(i);
                [v * 0.37, 1e4 * v, 1.0 / (v + 1.0), v / 11.0]
            })
            .collect();
        HdrImage {
            width: 4,
            height: 3,
            pixels,
        }
    }

    /// A 5x3 display image with varying alpha (the file tests' sample).
    pub(super) fn ldr_sample() -> LdrImage {
        let pixels = (0..15u8)
            .map(|i| [i * 17, 255 - i, i * 3, 128 + i])
            .collect();
        LdrImage {
            width: 5,
            height: 3,
            pixels,
        }
    }

    #[test]
    fn to_ldr_tonemaps_every_pixel() {
        let mut hdr = HdrImage::new(2, 1);
        hdr.pixels[1] = [1e6, 1e6, 1e6, 0.5];
        let ldr = hdr.to_ldr(0.0, Tonemap::Aces);
        assert_eq!((ldr.width, ldr.height), (2, 1));
        assert_eq!(ldr.pixels, vec![[0, 0, 0, 0], [255, 255, 255, 128]]);
    }

    #[test]
    fn an_opaque_image_keeps_its_radiance_and_drops_its_mask() {
        let masked = hdr_sample();
        let opaque = masked.clone().opaque();
        for (o, m) in opaque.pixels.iter().zip(&masked.pixels) {
            assert_eq!((o[..3].to_vec(), o[3]), (m[..3].to_vec(), 1.0));
        }
        assert!(masked.pixels.iter().any(|p| p[3] < 1.0));
    }

    #[test]
    fn mean_luminance_weights_green_most() {
        let mut hdr = HdrImage::new(2, 1);
        hdr.pixels = vec![[1.0, 1.0, 1.0, 1.0], [0.0, 1.0, 0.0, 1.0]];
        assert!((hdr.mean_luminance() - (1.0 + 0.7152) / 2.0).abs() < 1e-12);
        assert_eq!(HdrImage::new(0, 0).mean_luminance(), 0.0);
    }

    #[test]
    fn luma_weights_the_encoded_channels() {
        let image = LdrImage {
            width: 3,
            height: 1,
            pixels: vec![[255, 255, 255, 0], [0, 255, 0, 255], [0, 0, 0, 255]],
        };
        let luma = image.luma();
        assert!((luma[0] - 1.0).abs() < 1e-6, "{luma:?}");
        assert!((luma[1] - 0.7152).abs() < 1e-6, "{luma:?}");
        assert_eq!(luma[2], 0.0);
    }

    #[test]
    fn size_check_rejects_inconsistent_buffers() {
        assert!(check_size(2, 2, 4).is_ok());
        assert!(matches!(
            check_size(2, 2, 3),
            Err(ImageError::BadSize { len: 3, .. })
        ));
        assert!(check_size(0, 5, 0).is_err());
    }
}
