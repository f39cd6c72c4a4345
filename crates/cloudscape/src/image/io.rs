//! Image files: OpenEXR for linear HDR radiance, PNG for sRGB display images.
//!
//! Writing never leaves a partial file: the image goes to a temporary file in the destination
//! directory, which is renamed over the destination only once complete.

use std::fs::File;
use std::path::Path;

use exr::prelude::{Image, ReadChannels, ReadLayers, SpecificChannels, WritableImage};

use super::{HdrImage, ImageError, LdrImage, check_size};
use crate::fsutil::write_atomically;
use crate::post::tonemap::srgb_to_linear;
use crate::scene::Tonemap;

/// The image file types, chosen by file-name extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FileType {
    /// Tone-mapped, sRGB-encoded 8-bit RGBA.
    Png,
    /// Linear 32-bit float RGBA radiance.
    Exr,
}

impl FileType {
    fn of(path: &Path) -> Result<Self, ImageError> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match extension.as_deref() {
            Some("png") => Ok(FileType::Png),
            Some("exr") => Ok(FileType::Exr),
            _ => Err(ImageError::UnsupportedFormat {
                path: path.to_path_buf(),
            }),
        }
    }
}

/// Writes `hdr` to `path` by its extension: `.exr` keeps linear radiance; `.png` stores display
/// values after exposure by `exposure_ev` stops and tone mapping by `op`.
pub fn write_image(
    path: &Path,
    hdr: &HdrImage,
    exposure_ev: f32,
    op: Tonemap,
) -> Result<(), ImageError> {
    match FileType::of(path)? {
        FileType::Exr => hdr.write_exr(path),
        FileType::Png => hdr.to_ldr(exposure_ev, op).write_png(path),
    }
}

impl HdrImage {
    /// Writes the image as a 32-bit float RGBA OpenEXR file.
    pub fn write_exr(&self, path: &Path) -> Result<(), ImageError> {
        check_size(self.width, self.height, self.pixels.len())?;
        let width = self.width as usize;
        let channels = SpecificChannels::rgba(|exr::math::Vec2(x, y)| {
            let [r, g, b, a] = self.pixels[y * width + x];
            (r, g, b, a)
        });
        let image = Image::from_channels((width, self.height as usize), channels);
        write_atomically(
            path,
            |e| io_error(path, e),
            |file| {
                image
                    .write()
                    .to_buffered(file)
                    .map_err(|source| exr_error(path, source))
            },
        )
    }

    /// Reads an image: OpenEXR as stored (alpha 1 where the file has none), or PNG decoded from
    /// sRGB to linear.
    pub fn read(path: &Path) -> Result<HdrImage, ImageError> {
        match FileType::of(path)? {
            FileType::Exr => read_exr(path),
            FileType::Png => Ok(LdrImage::read_png(path)?.to_linear()),
        }
    }
}

fn exr_error(path: &Path, source: exr::error::Error) -> ImageError {
    ImageError::Exr {
        path: path.to_path_buf(),
        source,
    }
}

fn read_exr(path: &Path) -> Result<HdrImage, ImageError> {
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |resolution, _| HdrImage::new(resolution.width() as u32, resolution.height() as u32),
            |hdr: &mut HdrImage, position, (r, g, b, a): (f32, f32, f32, f32)| {
                let index = position.y() * hdr.width as usize + position.x();
                hdr.pixels[index] = [r, g, b, a];
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|source| exr_error(path, source))?;
    Ok(image.layer_data.channel_data.pixels)
}

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

fn io_error(path: &Path, source: std::io::Error) -> ImageError {
    ImageError::Io {
        path: path.to_path_buf(),
        source,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fsutil::ScratchDir;

    fn hdr_sample() -> HdrImage {
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

    fn ldr_sample() -> LdrImage {
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
    fn exr_round_trip_is_exact() {
        let dir = ScratchDir::new("image-exr");
        let path = dir.join("frame.exr");
        hdr_sample().write_exr(&path).expect("write exr");
        assert_eq!(HdrImage::read(&path).expect("read exr"), hdr_sample());
        assert_eq!(dir.entries(), ["frame.exr"]);
    }

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

    #[test]
    fn write_image_picks_format_by_extension() {
        let dir = ScratchDir::new("image-by-ext");
        let hdr = hdr_sample();
        write_image(&dir.join("a.exr"), &hdr, 0.0, Tonemap::Aces).expect("exr");
        write_image(&dir.join("b.png"), &hdr, -3.0, Tonemap::Agx).expect("png");
        assert_eq!(HdrImage::read(&dir.join("a.exr")).expect("read exr"), hdr);
        let png = LdrImage::read_png(&dir.join("b.png")).expect("read png");
        assert_eq!(png, hdr.to_ldr(-3.0, Tonemap::Agx));
        let err = write_image(&dir.join("c.jpg"), &hdr, 0.0, Tonemap::Aces).expect_err("jpg");
        assert!(matches!(err, ImageError::UnsupportedFormat { .. }));
        assert!(err.to_string().contains("c.jpg"), "{err}");
        assert_eq!(dir.entries(), ["a.exr", "b.png"]);
    }

    #[test]
    fn unwritable_path_is_an_error_and_leaves_nothing() {
        let dir = ScratchDir::new("image-unwritable");
        let missing = dir.join("no-such-dir").join("out.png");
        let err = ldr_sample()
            .write_png(&missing)
            .expect_err("missing directory");
        assert!(matches!(err, ImageError::Io { .. }));
        assert!(err.to_string().contains("out.png"), "{err}");
        // The destination is a directory: the temporary file is written, the rename fails, and
        // the temporary file is removed again.
        let occupied = dir.join("taken.exr");
        std::fs::create_dir(&occupied).expect("create dir");
        let err = hdr_sample()
            .write_exr(&occupied)
            .expect_err("destination is a directory");
        assert!(err.to_string().contains("taken.exr"), "{err}");
        assert_eq!(dir.entries(), ["taken.exr"]);
    }

    #[test]
    fn inconsistent_image_is_not_written() {
        let dir = ScratchDir::new("image-bad-size");
        let bad = HdrImage {
            width: 3,
            height: 3,
            pixels: vec![[0.0; 4]; 4],
        };
        let err = bad
            .write_exr(&dir.join("bad.exr"))
            .expect_err("9 pixels declared, 4 given");
        assert!(matches!(err, ImageError::BadSize { len: 4, .. }));
        assert!(dir.entries().is_empty());
    }

    #[test]
    fn reading_garbage_names_the_file() {
        let dir = ScratchDir::new("image-garbage");
        for name in ["junk.png", "junk.exr"] {
            let path = dir.join(name);
            std::fs::write(&path, b"not an image").expect("write junk");
            let err = HdrImage::read(&path).expect_err("garbage");
            assert!(err.to_string().contains(name), "{err}");
        }
        let err = HdrImage::read(&dir.join("missing.exr")).expect_err("missing");
        assert!(err.to_string().contains("missing.exr"), "{err}");
    }
}
