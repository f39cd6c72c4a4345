//! `cloudscape compare`: HDR-FLIP, relative MSE and the mean-luminance ratio of two images.

use anyhow::Result;
use clap::Args;
use cloudscape::image::{FlipStats, HdrImage, hdr_flip, relative_mse};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Arguments of `cloudscape compare`.
#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The reference image (`.exr` linear radiance, or `.png` sRGB).
    reference: PathBuf,
    /// The image under test, the same size.
    test: PathBuf,
    /// Write the HDR-FLIP error map (magma colours) to this PNG.
    #[arg(long)]
    diff: Option<PathBuf>,
    /// Print the result as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// How far an image is from a reference.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    /// Mean HDR-FLIP error, 0 (identical) .. 1.
    pub flip_mean: f32,
    /// 95th percentile of the HDR-FLIP error.
    pub flip_p95: f32,
    /// 99th percentile of the HDR-FLIP error.
    pub flip_p99: f32,
    /// Relative mean squared error on linear radiance.
    pub relative_mse: f64,
    /// Mean luminance of the test over that of the reference.
    pub luminance_ratio: f64,
}

impl Comparison {
    /// Compares `test` with `reference`, writing the error map to `diff` when given.
    pub fn of(reference: &HdrImage, test: &HdrImage, diff: Option<&Path>) -> Result<Comparison> {
        let (FlipStats { mean, p95, p99 }, map) = hdr_flip(reference, test)?;
        if let Some(path) = diff {
            map.write_png(path)?;
        }
        Ok(Comparison {
            flip_mean: mean,
            flip_p95: p95,
            flip_p99: p99,
            relative_mse: relative_mse(reference, test)?,
            luminance_ratio: test.mean_luminance() / reference.mean_luminance().max(1e-30),
        })
    }
}

/// Reads both images, compares them, prints the numbers.
pub fn run(args: CompareArgs) -> Result<()> {
    let reference = HdrImage::read(&args.reference)?;
    let test = HdrImage::read(&args.test)?;
    let c = Comparison::of(&reference, &test, args.diff.as_deref())?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&c)?);
    } else {
        println!(
            "HDR-FLIP mean {:.4}  p95 {:.4}  p99 {:.4}",
            c.flip_mean, c.flip_p95, c.flip_p99
        );
        println!("relative MSE {:.5}", c.relative_mse);
        println!(
            "mean luminance ratio (test / reference) {:.4}",
            c.luminance_ratio
        );
    }
    if let Some(path) = &args.diff {
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
