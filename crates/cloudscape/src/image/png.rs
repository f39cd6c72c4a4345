//! PNG files of display images (cargo feature `png`).

use std::fs::File;
use std::path::Path;

use super::io::io_error;
use super::{ImageError, LdrImage, check_size};
use crate::fsutil::write_atomically;

impl LdrImage {
    /// Writes the image as an 8-bit RGBA PNG file.
    pub fn write_png(&self, path: &Path) -> Result<(), ImageError> {
        check_size(self.width, self.height, self.pixels.len())?;
        let bytes: &[u8] = bytemuck::cast_slice(&self.pixels);
        write_atomically(
            path,
            |e| io_error(path, e),
            |file| {
                ::image::write_buffer_with_format(
                    file,
                    bytes,
                    self.width,
                    self.height,
                    ::image::ExtendedColorType::Rgba8,
                    ::image::ImageFormat::Png,
                )
                .map_err(|source| ImageError::Png {
                    path: path.to_path_buf(),
                    source,
                })
            },
        )
    }

    /// Reads a PNG file of any colour type, converted to 8-bit RGBA.
    pub fn read_png(path: &Path) -> Result<LdrImage, ImageError> {
        let png_error = |source| ImageError::Png {
            path: path.to_path_buf(),
            source,
        };
        let file = File::open(path).map_err(|source| io_error(path, source))?;
        let reader = ::image::ImageReader::with_format(
            std::io::BufReader::new(file),
            ::image::ImageFormat::Png,
        );
        let rgba = reader.decode().map_err(png_error)?.into_rgba8();
        let (width, height) = rgba.dimensions();
        let pixels = bytemuck::cast_slice(rgba.as_raw()).to_vec();
        Ok(LdrImage {
            width,
            height,
            pixels,
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::fsutil::ScratchDir;
    use crate::image::tests::ldr_sample;
    use crate::image::{HdrImage, LdrImage};
    use crate::post::tonemap::srgb_to_linear;

    #[test]
    fn png_round_trip_is_exact() {
        let dir = ScratchDir::new("image-png");
        let path = dir.join("frame.PNG");
        ldr_sample().write_png(&path).expect("write png");
        assert_eq!(LdrImage::read_png(&path).expect("read png"), ldr_sample());
        // Read as HDR, the same file decodes from sRGB to linear.
        let hdr = HdrImage::read(&path).expect("read png as hdr");
        let [r, _, _, a] = hdr.pixels[11];
        assert!((r - srgb_to_linear(187.0 / 255.0)).abs() < 1e-7);
        assert!((a - 139.0 / 255.0).abs() < 1e-7);
        assert_eq!(dir.entries(), ["frame.PNG"]);
    }
}
