//! [`GifPreview`]: an animated GIF of a frame sequence, small enough to open anywhere (cargo
//! feature `gif`).

use std::path::{Path, PathBuf};

use ::image::RgbaImage;
use ::image::imageops::{FilterType, resize};
use glam::UVec2;

use crate::fsutil::write_bytes_atomically;
use crate::image::LdrImage;

/// The smallest frame delay browsers honour, 1/100 s: shorter delays play at 1/10 s.
const MIN_DELAY_CS: u16 = 2;

/// NeuQuant sampling factor of the palette reduction, 1 (best) ..30 (fastest); 10 is the `gif`
/// crate's recommended compromise.
const QUANTIZE_SPEED: i32 = 10;

/// What went wrong building or writing a GIF preview.
#[derive(Debug, thiserror::Error)]
pub enum PreviewError {
    /// The preview would be larger than a GIF can be (65 535 pixels a side).
    #[error("a {0}x{1} pixel preview is larger than a GIF allows (65535 a side)")]
    TooLarge(u32, u32),
    /// A frame is empty, or its pixel buffer does not hold `width * height` pixels.
    #[error("a {width}x{height} frame holds {len} pixels")]
    BadFrame {
        /// Declared width.
        width: u32,
        /// Declared height.
        height: u32,
        /// Pixels in the buffer.
        len: usize,
    },
    /// The GIF encoder failed.
    #[error("GIF encoder: {0}")]
    Encode(#[from] gif::EncodingError),
    /// The file could not be written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
}

/// An animated GIF built in memory one frame at a time and written whole by [`GifPreview::finish`].
///
/// Frames are scaled (triangle filter) to the preview size and reduced to 256 colours each by
/// NeuQuant (Dekker 1994, "Kohonen neural networks for optimal colour quantization"). GIF delays
/// are whole hundredths of a second, so each frame's delay is rounded such that the total stays
/// within 1/100 s of the frame count over the rate; above 50 frames per second the preview plays
/// slower (browsers hold a frame at least 1/50 s). The GIF loops forever.
pub struct GifPreview {
    encoder: gif::Encoder<Vec<u8>>,
    size: UVec2,
    fps: f64,
    frames: u32,
}

impl GifPreview {
    /// An empty preview of frames `frame_size` pixels, scaled down to at most `max_width` pixels
    /// wide, playing at `fps` frames per second (> 0).
    pub fn new(frame_size: UVec2, max_width: u32, fps: f32) -> Result<GifPreview, PreviewError> {
        let size = preview_size(frame_size, max_width);
        let too_large = || PreviewError::TooLarge(size.x, size.y);
        let width = u16::try_from(size.x).map_err(|_| too_large())?;
        let height = u16::try_from(size.y).map_err(|_| too_large())?;
        let mut encoder = gif::Encoder::new(Vec::new(), width, height, &[])?;
        encoder.set_repeat(gif::Repeat::Infinite)?;
        Ok(GifPreview {
            encoder,
            size,
            fps: f64::from(fps),
            frames: 0,
        })
    }

    /// Appends `frame`, scaled to the preview size.
    pub fn push(&mut self, frame: &LdrImage) -> Result<(), PreviewError> {
        let bad_frame = PreviewError::BadFrame {
            width: frame.width,
            height: frame.height,
            len: frame.pixels.len(),
        };
        let pixels = frame.width as usize * frame.height as usize;
        if pixels == 0 || frame.pixels.len() != pixels {
            return Err(bad_frame);
        }
        let bytes = frame.pixels.as_flattened().to_vec();
        let image = RgbaImage::from_raw(frame.width, frame.height, bytes).ok_or(bad_frame)?;
        let mut pixels = resize(&image, self.size.x, self.size.y, FilterType::Triangle).into_raw();
        // `new` checked that the size fits in u16.
        let (width, height) = (self.size.x as u16, self.size.y as u16);
        let mut gif_frame = gif::Frame::from_rgba_speed(width, height, &mut pixels, QUANTIZE_SPEED);
        gif_frame.delay = self.next_delay_cs();
        self.encoder.write_frame(&gif_frame)?;
        self.frames += 1;
        Ok(())
    }

    /// Finishes the GIF and writes it to `path` (complete or not at all).
    pub fn finish(self, path: &Path) -> Result<(), PreviewError> {
        let bytes = self.encoder.into_inner()?;
        write_bytes_atomically(path, &bytes).map_err(|source| PreviewError::Io {
            path: path.to_path_buf(),
            source,
        })
    }

    /// Delay of the next frame, 1/100 s: the rounded end time of the frame minus the rounded
    /// start time, so that rounding errors do not add up.
    fn next_delay_cs(&self) -> u16 {
        let end_cs = |frame: u32| (f64::from(frame) * 100.0 / self.fps).round();
        let delay = end_cs(self.frames + 1) - end_cs(self.frames);
        (delay.clamp(0.0, f64::from(u16::MAX)) as u16).max(MIN_DELAY_CS)
    }
}

/// `frame_size` scaled to at most `max_width` pixels wide (never up), keeping its aspect ratio;
/// at least 1 pixel a side; the height is rounded to the nearest pixel.
pub fn preview_size(frame_size: UVec2, max_width: u32) -> UVec2 {
    let width = frame_size.x.min(max_width).max(1);
    let frame_width = u64::from(frame_size.x.max(1));
    let height = (u64::from(frame_size.y) * u64::from(width) + frame_width / 2) / frame_width;
    UVec2::new(width, u32::try_from(height).unwrap_or(u32::MAX).max(1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fsutil::ScratchDir;

    fn flat(width: u32, height: u32, value: u8) -> LdrImage {
        LdrImage {
            width,
            height,
            pixels: vec![[value, value / 2, 255 - value, 255]; (width * height) as usize],
        }
    }

    #[test]
    fn preview_size_keeps_the_aspect_and_never_scales_up() {
        assert_eq!(
            preview_size(UVec2::new(1280, 720), 480),
            UVec2::new(480, 270)
        );
        assert_eq!(preview_size(UVec2::new(64, 36), 480), UVec2::new(64, 36));
        assert_eq!(preview_size(UVec2::new(1000, 1), 10), UVec2::new(10, 1));
    }

    #[test]
    fn delays_add_up_to_the_frame_rate() {
        let mut preview = GifPreview::new(UVec2::new(4, 4), 4, 24.0).unwrap();
        let mut total_cs = 0;
        for _ in 0..24 {
            total_cs += u32::from(preview.next_delay_cs());
            preview.frames += 1;
        }
        assert_eq!(total_cs, 100);
        let fast = GifPreview::new(UVec2::new(4, 4), 4, 120.0).unwrap();
        assert_eq!(fast.next_delay_cs(), MIN_DELAY_CS);
    }

    #[test]
    fn writes_a_gif_that_decodes_to_the_frames_at_the_preview_size() {
        let dir = ScratchDir::new("gif-preview");
        let path = dir.join("preview.gif");
        let mut preview = GifPreview::new(UVec2::new(40, 20), 20, 10.0).unwrap();
        for value in [0, 100, 200] {
            preview.push(&flat(40, 20, value)).unwrap();
        }
        preview.finish(&path).unwrap();
        let mut options = gif::DecodeOptions::new();
        options.set_color_output(gif::ColorOutput::RGBA);
        let file = std::fs::File::open(&path).unwrap();
        let mut decoder = options.read_info(file).unwrap();
        let mut frames = Vec::new();
        while let Some(frame) = decoder.read_next_frame().unwrap() {
            assert_eq!((frame.width, frame.height, frame.delay), (20, 10, 10));
            frames.push(frame.buffer[..4].to_vec());
        }
        assert_eq!(
            frames,
            [[0, 0, 255, 255], [100, 50, 155, 255], [200, 100, 55, 255]]
        );
    }

    #[test]
    fn a_frame_with_the_wrong_pixel_count_is_an_error() {
        let mut preview = GifPreview::new(UVec2::new(4, 4), 4, 10.0).unwrap();
        let mut frame = flat(4, 4, 10);
        frame.pixels.pop();
        assert!(matches!(
            preview.push(&frame),
            Err(PreviewError::BadFrame { len: 15, .. })
        ));
    }
}
