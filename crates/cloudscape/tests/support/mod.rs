//! Helpers the golden-image tests share: FLIP against a checked-in golden, or rewriting it.

use cloudscape::image::{LdrImage, flip};
use std::path::Path;

/// Bounds on the FLIP error against the golden: mean and 99th percentile. Measured: GL llvmpipe
/// against the Vulkan lavapipe goldens scores 0.002-0.022 (the grainiest view); small real changes
/// score more (sun 3 degrees lower 0.053, detail erosion 0.35 -> 0.30 0.036, ambient x0.85 0.088).
const MAX_MEAN: f32 = 0.03;
const MAX_P99: f32 = 0.25;

/// The `cloudscape` crate's directory.
pub fn manifest_dir() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Compares `actual` with the golden `name`, or rewrites the golden when asked to.
pub fn check(name: &str, actual: &LdrImage) {
    let golden_path = manifest_dir()
        .join("tests/golden")
        .join(format!("{name}.png"));
    if std::env::var_os("CLOUDSCAPE_UPDATE_GOLDENS").is_some() {
        actual.write_png(&golden_path).expect("write golden");
        return;
    }
    let golden = LdrImage::read_png(&golden_path).unwrap_or_else(|e| {
        panic!("{e}: run with CLOUDSCAPE_UPDATE_GOLDENS=1 to create the golden")
    });
    let (stats, difference) = flip(&golden, actual).expect("same size");
    eprintln!("{name}: FLIP mean {:.4}, p99 {:.4}", stats.mean, stats.p99);
    if stats.mean > MAX_MEAN || stats.p99 > MAX_P99 {
        let dir = manifest_dir().join("../../target/golden-failures");
        std::fs::create_dir_all(&dir).expect("failure directory");
        actual
            .write_png(&dir.join(format!("{name}-actual.png")))
            .expect("write actual");
        difference
            .write_png(&dir.join(format!("{name}-difference.png")))
            .expect("write difference");
        panic!(
            "{name}: FLIP mean {:.4} (max {MAX_MEAN}), p99 {:.4} (max {MAX_P99}); see {}",
            stats.mean,
            stats.p99,
            dir.display()
        );
    }
}
