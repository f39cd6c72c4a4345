//! OpenEXR files of linear HDR images (cargo feature `exr`).

use std::path::Path;

use ::exr::prelude::{Image, ReadChannels, ReadLayers, SpecificChannels, WritableImage};

use super::io::io_error;
use super::{HdrImage, ImageError, check_size};
use crate::fsutil::write_atomically;

impl HdrImage {
    /// Writes the image as a 32-bit float RGBA OpenEXR file.
    pub fn write_exr(&self, path: &Path) -> Result<(), ImageError> {
        check_size(self.width, self.height, self.pixels.len())?;
        let width = self.width as usize;
        let channels = SpecificChannels::rgba(|::exr::math::Vec2(x, y)| {
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
}

fn exr_error(path: &Path, source: ::exr::error::Error) -> ImageError {
    ImageError::Exr {
        path: path.to_path_buf(),
        source,
    }
}

/// Reads an OpenEXR file's RGBA channels (alpha 1 where the file has none).
pub(super) fn read_exr(path: &Path) -> Result<HdrImage, ImageError> {
    let image = ::exr::prelude::read()
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

#[cfg(test)]
mod tests {
    use crate::fsutil::ScratchDir;
    use crate::image::tests::hdr_sample;
    use crate::image::{HdrImage, ImageError};

    #[test]
    fn exr_round_trip_is_exact() {
        let dir = ScratchDir::new("image-exr");
        let path = dir.join("frame.exr");
        hdr_sample().write_exr(&path).expect("write exr");
        assert_eq!(HdrImage::read(&path).expect("read exr"), hdr_sample());
        assert_eq!(dir.entries(), ["frame.exr"]);
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
}
