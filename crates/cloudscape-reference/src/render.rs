//! Progressive rendering: passes of samples per pixel over all cores, accumulated per pixel with
//! the statistics to tell how converged each pixel is; stoppable between rows.

use crate::integrator::{CameraSample, PathTracer};
use crate::medium::Medium;
use crate::rng::Rng;
use cloudscape::frame::Frame;
use cloudscape::image::HdrImage;
use glam::{DVec3, Vec2};
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// Rec. 709 luminance weights of linear sRGB (ITU-R BT.709).
const LUMINANCE: DVec3 = DVec3::new(0.2126, 0.7152, 0.0722);

/// The stream of random numbers that rotates a pixel's sample points (never a sample's index).
const PIXEL_ROTATION_STREAM: u64 = u64::MAX;

/// One pixel's running sums.
#[derive(Clone, Copy, Debug, Default)]
struct PixelSums {
    samples: u32,
    /// Sum of the RGB estimates.
    sum: DVec3,
    /// Sum of the squared luminance of the estimates.
    sum_sq_luminance: f64,
    /// Estimates dropped for not being finite (a bug if ever non-zero; counted, never hidden).
    non_finite: u32,
    /// Samples whose path met cloud.
    met_cloud: u32,
}

/// A pixel's estimate and its uncertainty.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelEstimate {
    /// Mean radiance over the samples.
    pub mean: DVec3,
    /// Samples taken.
    pub samples: u32,
    /// Estimated variance of the mean luminance (sample variance over the sample count).
    pub luminance_variance_of_mean: f64,
}

/// Totals of a render so far.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderStats {
    /// Camera samples taken (paths traced).
    pub samples: u64,
    /// Time spent tracing.
    pub elapsed: Duration,
    /// Samples whose estimate was not finite (and was dropped).
    pub non_finite: u64,
}

impl RenderStats {
    /// Camera samples (paths) per second of wall time.
    pub fn samples_per_second(&self) -> f64 {
        self.samples as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }
}

/// A progressive render of one path tracer and seed.
pub struct ProgressiveRender<'a, M> {
    tracer: &'a PathTracer<M>,
    seed: u64,
    width: usize,
    pixels: Vec<PixelSums>,
    next_sample: u32,
    elapsed: Duration,
}

impl<'a, M: Medium> ProgressiveRender<'a, M> {
    /// An empty render of `tracer`'s frame; `seed` picks the random numbers (the same seed gives
    /// the same image, whatever the passes and the thread count).
    pub fn new(tracer: &'a PathTracer<M>, seed: u64) -> Self {
        Self::starting_at(tracer, seed, 0)
    }

    /// An empty render whose samples continue `seed`'s sequence from sample `first_sample`: the
    /// samples a render of `seed` that took `first_sample` per pixel did not take, so the two
    /// renders' means, weighted by their sample counts, are one render of `seed` (how a stored
    /// reference is extended).
    pub fn starting_at(tracer: &'a PathTracer<M>, seed: u64, first_sample: u32) -> Self {
        let size = tracer.frame.size;
        ProgressiveRender {
            tracer,
            seed,
            width: size.x as usize,
            pixels: vec![PixelSums::default(); size.x as usize * size.y as usize],
            next_sample: first_sample,
            elapsed: Duration::ZERO,
        }
    }

    /// Adds `spp` samples to every pixel, rows in parallel. `stop` is asked before each row: once
    /// it says yes, the remaining rows of the pass are skipped (their pixels keep fewer samples).
    /// `row_done` is told how many samples each finished row added. Returns whether the pass
    /// completed.
    ///
    /// Sample `s` of a pixel crosses it at the R2 point `s` ([`Frame::r2_point`]) shifted
    /// by a random offset per pixel and seed (a Cranley-Patterson rotation, 1976): each sample is
    /// uniform over the pixel, so the estimate stays unbiased, while together they cover it
    /// evenly (a sun disc smaller than a pixel no longer flickers from seed to seed).
    pub fn run_pass(
        &mut self,
        spp: u32,
        stop: &(dyn Fn() -> bool + Sync),
        row_done: &(dyn Fn(u64) + Sync),
    ) -> bool {
        let start = Instant::now();
        let (first, width, seed, tracer) = (self.next_sample, self.width, self.seed, self.tracer);
        let complete = self
            .pixels
            .par_chunks_mut(width)
            .enumerate()
            .map(|(y, row)| {
                if stop() {
                    return false;
                }
                for (x, pixel) in row.iter_mut().enumerate() {
                    let index = (y * width + x) as u64;
                    let rotation = Rng::for_sample(seed, index, PIXEL_ROTATION_STREAM).next_vec2();
                    for s in first..first + spp {
                        let mut rng = Rng::for_sample(seed, index, u64::from(s));
                        let within = (Frame::r2_point(s) + rotation).fract();
                        let point = Vec2::new(x as f32, y as f32) + within;
                        pixel.add(tracer.camera_sample(point, &mut rng));
                    }
                }
                row_done(u64::from(spp) * width as u64);
                true
            })
            .reduce(|| true, |a, b| a && b);
        self.next_sample += spp;
        self.elapsed += start.elapsed();
        complete
    }

    /// The image so far: each pixel's mean (black where no sample was taken), and in alpha the
    /// share of its paths that met cloud ([`CameraSample::met_cloud`]).
    pub fn image(&self) -> HdrImage {
        let size = self.tracer.frame.size;
        let pixels = self
            .pixels
            .iter()
            .map(|p| {
                let n = f64::from(p.samples.max(1));
                let m = p.sum / n;
                let cloud = f64::from(p.met_cloud) / n;
                [m.x as f32, m.y as f32, m.z as f32, cloud as f32]
            })
            .collect();
        HdrImage {
            width: size.x,
            height: size.y,
            pixels,
        }
    }

    /// The estimate of pixel `(x, y)`.
    pub fn pixel(&self, x: u32, y: u32) -> PixelEstimate {
        self.pixels[y as usize * self.width + x as usize].estimate()
    }

    /// Totals so far.
    pub fn stats(&self) -> RenderStats {
        RenderStats {
            samples: self.pixels.iter().map(|p| u64::from(p.samples)).sum(),
            elapsed: self.elapsed,
            non_finite: self.pixels.iter().map(|p| u64::from(p.non_finite)).sum(),
        }
    }
}

impl PixelSums {
    fn add(&mut self, sample: CameraSample) {
        let radiance = sample.radiance.as_dvec3();
        if !radiance.is_finite() {
            self.non_finite += 1;
            return;
        }
        self.samples += 1;
        self.met_cloud += u32::from(sample.met_cloud);
        self.sum += radiance;
        self.sum_sq_luminance += radiance.dot(LUMINANCE).powi(2);
    }

    fn estimate(&self) -> PixelEstimate {
        let n = f64::from(self.samples.max(1));
        let mean = self.sum / n;
        let mean_luminance = mean.dot(LUMINANCE);
        let variance = (self.sum_sq_luminance / n - mean_luminance * mean_luminance).max(0.0);
        PixelEstimate {
            mean,
            samples: self.samples,
            luminance_variance_of_mean: variance * n / (n - 1.0).max(1.0) / n,
        }
    }
}
