//! The path-traced references of the realism report, kept in the repository
//! (`docs/realism/references/`) so that a fresh clone regenerates the report without hours of
//! tracing.
//!
//! Per canonical scene and medium (the cloud field, or the particle technique's particles) a
//! reference is two halves traced with two seeds, whose disagreement measures its noise. Each half
//! is stored as the mean radiance over its samples (`NAME-0.exr`, `NAME-1.exr`, 32-bit float) and
//! described in `NAME.json`: the key of everything the path tracer read, the samples per pixel,
//! the seeds and the tracing time. A stored reference whose key differs is stale and traced anew;
//! one with fewer samples than asked for is extended by continuing each half's sample sequence
//! ([`ProgressiveRender::starting_at`]), so references converge further run after run.

use anyhow::{Context, Result};
use cloudscape::image::HdrImage;
use cloudscape_reference::medium::Medium;
use cloudscape_reference::{PathTracer, ProgressiveRender};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Samples per pixel of one progressive pass: a pass is never cut short, so every pixel of a
/// stored half has the same count.
const PASS_SPP: u32 = 4;

/// One stored half: its seed, samples per pixel and tracing time.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct HalfRecord {
    /// Seed of the half's random numbers.
    pub seed: u64,
    /// Samples (paths) per pixel.
    pub spp: u32,
    /// Seconds spent tracing them, over every run that added to them.
    pub seconds: f64,
}

/// What `NAME.json` says of a stored reference.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// Stable hash (hex) of everything the path tracer read: scene, field, medium, size and
    /// [`cloudscape_reference::TRACER_REVISION`].
    pub key: String,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// The two halves.
    pub halves: [HalfRecord; 2],
}

impl Record {
    /// Samples per pixel of both halves together.
    pub fn spp(&self) -> u32 {
        self.halves.iter().map(|h| h.spp).sum()
    }

    /// Paths traced per second of tracing.
    pub fn samples_per_second(&self) -> f64 {
        let seconds: f64 = self.halves.iter().map(|h| h.seconds).sum();
        f64::from(self.spp()) * f64::from(self.width * self.height) / seconds.max(1e-9)
    }
}

/// A reference: the two half-sample images and their record.
pub struct Reference {
    /// The halves' mean radiances.
    pub halves: [HdrImage; 2],
    /// Their record.
    pub record: Record,
}

impl Reference {
    /// The mean of both halves: the reference itself.
    pub fn image(&self) -> HdrImage {
        let [wa, wb] = self
            .record
            .halves
            .map(|h| h.spp as f32 / self.record.spp().max(1) as f32);
        self.combination(wa, wb)
    }

    /// The pixel-wise sum `wa * first half + wb * second half`.
    pub fn combination(&self, wa: f32, wb: f32) -> HdrImage {
        let [a, b] = &self.halves;
        linear_combination((a, wa), (b, wb))
    }
}

/// Samples per pixel of a reference traced for the first time when no count is asked for.
pub const DEFAULT_SPP: u32 = 256;

/// How much tracing a reference may take.
#[derive(Clone, Copy, Debug)]
pub struct Budget {
    /// Samples per pixel wanted in all (half in each half): a stored reference with fewer is
    /// extended, one with more is kept. None takes what is stored, and traces [`DEFAULT_SPP`]
    /// where nothing is.
    pub spp: Option<u32>,
    /// Most seconds of tracing for one reference in this run; the samples traced by then are
    /// stored.
    pub seconds: f64,
    /// Seed of the first half; the second half uses the next one.
    pub seed: u64,
}

/// The directory of stored references.
pub struct ReferenceStore {
    dir: PathBuf,
}

impl ReferenceStore {
    /// The store in `dir` (created when a reference is first written).
    pub fn new(dir: &Path) -> ReferenceStore {
        ReferenceStore {
            dir: dir.to_path_buf(),
        }
    }

    fn record_path(&self, name: &str) -> PathBuf {
        self.dir.join(format!("{name}.json"))
    }

    fn half_path(&self, name: &str, half: usize) -> PathBuf {
        self.dir.join(format!("{name}-{half}.exr"))
    }

    /// The stored reference `name` when its key is `key` and its size `size`; None (saying why)
    /// when it is missing or stale.
    pub fn load(&self, name: &str, key: &str, size: (u32, u32)) -> Option<Reference> {
        let text = std::fs::read_to_string(self.record_path(name)).ok()?;
        let record: Record = match serde_json::from_str(&text) {
            Ok(record) => record,
            Err(e) => {
                eprintln!("{name}: unreadable record ({e}): tracing anew");
                return None;
            }
        };
        if record.key != key || (record.width, record.height) != size {
            eprintln!("{name}: the stored reference is stale (its scene or tracer changed)");
            return None;
        }
        let read = |h| HdrImage::read(&self.half_path(name, h)).ok();
        let halves = [read(0)?, read(1)?];
        Some(Reference { halves, record })
    }

    /// The reference `name` keyed `key` at `size`: as stored, extended to `budget.spp`, or
    /// traced anew by the path tracer `tracer` makes; stored again when anything was traced.
    pub fn obtain<M: Medium>(
        &self,
        name: &str,
        (key, size): (&str, (u32, u32)),
        budget: Budget,
        tracer: impl FnOnce() -> Result<PathTracer<M>>,
    ) -> Result<Reference> {
        let stored = self.load(name, key, size);
        let half_spp = match (budget.spp, &stored) {
            (Some(spp), _) => spp.div_ceil(2),
            (None, Some(_)) => 0,
            (None, None) => DEFAULT_SPP / 2,
        };
        if let Some(reference) = &stored
            && reference.record.halves.iter().all(|h| h.spp >= half_spp)
        {
            return Ok(stored.expect("checked"));
        }
        let tracer = tracer()?;
        let deadline_s = budget.seconds / 2.0;
        let mut halves = Vec::with_capacity(2);
        let mut records = Vec::with_capacity(2);
        for h in 0..2 {
            let (image, record) = match &stored {
                Some(r) => (r.halves[h].clone(), r.record.halves[h]),
                None => (
                    HdrImage::new(size.0, size.1),
                    HalfRecord {
                        seed: budget.seed + h as u64,
                        spp: 0,
                        seconds: 0.0,
                    },
                ),
            };
            let (image, record) = extend(&tracer, (image, record), half_spp, deadline_s);
            halves.push(image);
            records.push(record);
        }
        let reference = Reference {
            halves: halves.try_into().expect("two halves"),
            record: Record {
                key: key.to_string(),
                width: size.0,
                height: size.1,
                halves: records.try_into().expect("two halves"),
            },
        };
        self.store(name, &reference)?;
        eprintln!(
            "{name}: {} spp stored ({:.0} paths/s)",
            reference.record.spp(),
            reference.record.samples_per_second()
        );
        Ok(reference)
    }

    /// Writes `reference` as `name`. The old record goes first and the new one comes last, so an
    /// interrupted write leaves no record that misstates its images' samples (a missing record
    /// means no reference).
    fn store(&self, name: &str, reference: &Reference) -> Result<()> {
        std::fs::create_dir_all(&self.dir).with_context(|| self.dir.display().to_string())?;
        let path = self.record_path(name);
        if path.exists() {
            std::fs::remove_file(&path).with_context(|| path.display().to_string())?;
        }
        for (h, half) in reference.halves.iter().enumerate() {
            half.write_exr(&self.half_path(name, h))?;
        }
        let text = serde_json::to_string_pretty(&reference.record)?;
        std::fs::write(&path, text + "\n").with_context(|| path.display().to_string())?;
        Ok(())
    }
}

/// `half` (its mean image and record) with passes of [`PASS_SPP`] added, continuing its seed's
/// sample sequence, until it holds `spp` samples per pixel or `seconds` have passed.
fn extend<M: Medium>(
    tracer: &PathTracer<M>,
    (mean, record): (HdrImage, HalfRecord),
    spp: u32,
    seconds: f64,
) -> (HdrImage, HalfRecord) {
    if record.spp >= spp {
        return (mean, record);
    }
    let start = Instant::now();
    let mut render = ProgressiveRender::starting_at(tracer, record.seed, record.spp);
    let mut added = 0;
    while record.spp + added < spp && start.elapsed().as_secs_f64() < seconds {
        render.run_pass(PASS_SPP.min(spp - record.spp - added), &|| false, &|_| {});
        added += PASS_SPP.min(spp - record.spp - added);
    }
    let total = (record.spp + added).max(1) as f32;
    let image = linear_combination(
        (&mean, record.spp as f32 / total),
        (&render.image(), added as f32 / total),
    );
    let record = HalfRecord {
        spp: record.spp + added,
        seconds: record.seconds + render.stats().elapsed.as_secs_f64(),
        ..record
    };
    (image, record)
}

/// The pixel-wise sum `wa a + wb b` of two images of one size.
fn linear_combination((a, wa): (&HdrImage, f32), (b, wb): (&HdrImage, f32)) -> HdrImage {
    let pixels = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| std::array::from_fn(|c| wa * p[c] + wb * q[c]))
        .collect();
    HdrImage {
        pixels,
        ..a.clone()
    }
}
