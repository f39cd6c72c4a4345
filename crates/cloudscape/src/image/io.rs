//! Image files chosen by name: OpenEXR for linear HDR radiance (cargo feature `exr`), PNG for sRGB
//! display images (cargo feature `png`). A file type that this build lacks is an
//! [`ImageError::MissingFeature`] naming the feature.
//!
//! Writing never leaves a partial file: the image goes to a temporary file in the destination
//! directory, which is renamed over the destination only once complete.

use std::path::Path;

#[cfg(feature = "png")]
use super::LdrImage;
use super::{HdrImage, ImageError};
use crate::scene::Tonemap;

/// The image file types this build reads and writes, chosen by file-name extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FileType {
    /// Tone-mapped, sRGB-encoded 8-bit RGBA.
    #[cfg(feature = "png")]
    Png,
    /// Linear 32-bit float RGBA radiance.
    #[cfg(feature = "exr")]
    Exr,
}

/// Every image file name extension cloudscape knows; each is also the cargo feature that reads and
/// writes it.
const KNOWN_EXTENSIONS: [&str; 2] = ["png", "exr"];

impl FileType {
    fn of(path: &Path) -> Result<Self, ImageError> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match extension.as_deref() {
            #[cfg(feature = "png")]
            Some("png") => Ok(FileType::Png),
            #[cfg(feature = "exr")]
            Some("exr") => Ok(FileType::Exr),
            other => Err(not_built(path, other)),
        }
    }
}

/// The error for a file type this build does not read or write: [`ImageError::MissingFeature`] for
/// a known type, [`ImageError::UnsupportedFormat`] for any other.
fn not_built(path: &Path, extension: Option<&str>) -> ImageError {
    let path = path.to_path_buf();
    match KNOWN_EXTENSIONS.into_iter().find(|&e| Some(e) == extension) {
        Some(feature) => ImageError::MissingFeature { path, feature },
        None => ImageError::UnsupportedFormat { path },
    }
}

/// Writes `hdr` to `path` by its extension: `.exr` keeps linear radiance; `.png` stores display
/// values after exposure by `exposure_ev` stops and tone mapping by `op`.
// Without `png`, nothing is tone-mapped.
#[cfg_attr(not(feature = "png"), allow(unused_variables))]
pub fn write_image(
    path: &Path,
    hdr: &HdrImage,
    exposure_ev: f32,
    op: Tonemap,
) -> Result<(), ImageError> {
    match FileType::of(path)? {
        #[cfg(feature = "exr")]
        FileType::Exr => hdr.write_exr(path),
        #[cfg(feature = "png")]
        FileType::Png => hdr.to_ldr(exposure_ev, op).write_png(path),
    }
}

impl HdrImage {
    /// Reads an image: OpenEXR as stored (alpha 1 where the file has none), or PNG decoded from
    /// sRGB to linear.
    pub fn read(path: &Path) -> Result<HdrImage, ImageError> {
        match FileType::of(path)? {
            #[cfg(feature = "exr")]
            FileType::Exr => super::exr::read_exr(path),
            #[cfg(feature = "png")]
            FileType::Png => Ok(LdrImage::read_png(path)?.to_linear()),
        }
    }
}

/// An [`ImageError::Io`] naming `path`.
pub(super) fn io_error(path: &Path, source: std::io::Error) -> ImageError {
    ImageError::Io {
        path: path.to_path_buf(),
        source,
    }
}

#[cfg(all(test, feature = "png", feature = "exr"))]
mod tests {
    use super::*;
    use crate::fsutil::ScratchDir;
    use crate::image::tests::{hdr_sample, ldr_sample};

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
    fn a_known_type_the_build_lacks_names_its_cargo_feature() {
        let err = not_built(Path::new("out/frame.EXR"), Some("exr"));
        assert!(matches!(
            err,
            ImageError::MissingFeature { feature: "exr", .. }
        ));
        let message = err.to_string();
        assert!(message.contains("out/frame.EXR"), "{message}");
        assert!(message.contains("`exr` cargo feature"), "{message}");
        assert!(matches!(
            not_built(Path::new("a.jpg"), Some("jpg")),
            ImageError::UnsupportedFormat { .. }
        ));
        assert!(matches!(
            not_built(Path::new("a"), None),
            ImageError::UnsupportedFormat { .. }
        ));
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
