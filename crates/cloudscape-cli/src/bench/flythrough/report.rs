//! The fly-through's report: means over the frames, the project's targets met or missed, printed
//! as a table or written as JSON.

use super::measure::{Clock, FrameRecord, HiHeight, Marched, ReferenceSteps};
use crate::bench::Stat;
use anyhow::Result;
use serde::Serialize;

/// Targets of the project's briefs (issues 4 and 32), by the temporal grid's divisor: the temporal
/// march takes at least this many times less GPU time per frame than the full-resolution march at
/// the default step count, with a mean FLIP error against the converged frame at most this many
/// times that march's (4x4: 8 and 1.25; 2x2: 3 and 1.1), and flickers no more than it...
fn time_and_flip_targets(divisor: u32) -> (f64, f64) {
    match divisor {
        4 => (8.0, 1.25),
        2 => (3.0, 1.1),
        _ => (1.0, 1.0),
    }
}
/// ...and empty-space skipping takes at least 3 times fewer density samples per pixel with the
/// camera above the layer...
const MIN_SAMPLE_RATIO: f64 = 3.0;
/// ...at an identical image: mean FLIP below 0.01 on every such frame.
const MAX_SKIPPING_FLIP: f64 = 0.01;

/// What was measured, and how.
#[derive(Serialize)]
pub struct Setup {
    /// The adapter.
    pub adapter: String,
    /// The scene file.
    pub scene: String,
    /// Frame width, pixels.
    pub width: u32,
    /// Frame height, pixels.
    pub height: u32,
    /// Scene time of the first and last frames, seconds.
    pub time_range_s: (f32, f32),
    /// Frames per second of scene time (none: spread over the path).
    pub fps: Option<f32>,
    /// Frames between the starts of two runs with references.
    pub reference_every: u32,
    /// What times the marches.
    pub clock: Clock,
    /// Primary steps of the full and temporal marches (the scene's).
    pub primary_steps: u32,
    /// The temporal march's grid divisor: one ray per divisor x divisor pixels per frame.
    pub temporal_divisor: u32,
    /// How the converged frames are rendered.
    pub reference: ReferenceSteps,
}

/// One march over the sequence: its time over every frame it rendered, its errors over the frames
/// with references.
#[derive(Serialize)]
struct MethodSummary {
    /// GPU time per frame.
    time: Stat,
    /// Mean over frames of the mean FLIP error against the converged frame.
    flip_mean: f64,
    /// Mean over frame pairs of the frame change.
    change_mean: f64,
    /// Mean over frame pairs of the flicker.
    flicker_mean: f64,
}

impl MethodSummary {
    fn new(
        name: &str,
        records: &[FrameRecord],
        march: fn(&FrameRecord) -> Option<&Marched>,
    ) -> Self {
        let marches = || records.iter().filter_map(march);
        MethodSummary {
            time: Stat::new(name, marches().map(|m| m.ms).collect()),
            flip_mean: mean(marches().filter_map(|m| m.flip_mean.map(f64::from))),
            change_mean: mean(marches().filter_map(|m| m.change)),
            flicker_mean: mean(marches().filter_map(|m| m.flicker)),
        }
    }
}

/// Empty-space skipping over the frames with the camera above the layers.
#[derive(Serialize)]
struct SkippingSummary {
    frames: usize,
    samples_off: f64,
    samples_on: f64,
    ms_off: f64,
    ms_on: f64,
    /// Mean over the frames of the mean FLIP error, skipping on against off.
    flip_mean: f64,
    /// The largest of the frames' mean FLIP errors.
    flip_worst: f64,
}

impl SkippingSummary {
    fn new(records: &[FrameRecord]) -> Option<SkippingSummary> {
        let runs: Vec<&HiHeight> = records.iter().filter_map(|r| r.hiheight.as_ref()).collect();
        let of = |f: fn(&HiHeight) -> f64| mean(runs.iter().map(|h| f(h)));
        (!runs.is_empty()).then(|| SkippingSummary {
            frames: runs.len(),
            samples_off: of(|h| h.samples_off),
            samples_on: of(|h| h.samples_on),
            ms_off: of(|h| h.ms_off),
            ms_on: of(|h| h.ms_on),
            flip_mean: of(|h| f64::from(h.flip_mean)),
            flip_worst: runs
                .iter()
                .map(|h| f64::from(h.flip_mean))
                .fold(0.0, f64::max),
        })
    }
}

/// A target: the measured value, the bound and whether it was met.
#[derive(Serialize)]
struct Target {
    name: &'static str,
    value: f64,
    bound: String,
    met: bool,
}

impl Target {
    fn at_least(name: &'static str, value: f64, bound: f64) -> Target {
        let met = value >= bound;
        let bound = format!(">= {bound}");
        Target {
            name,
            value,
            bound,
            met,
        }
    }

    fn below(name: &'static str, value: f64, bound: f64, inclusive: bool) -> Target {
        let met = value < bound || (inclusive && value == bound);
        let bound = format!("{} {bound}", if inclusive { "<=" } else { "<" });
        Target {
            name,
            value,
            bound,
            met,
        }
    }
}

/// Everything the fly-through measured.
#[derive(Serialize)]
pub struct Report {
    #[serde(flatten)]
    setup: Setup,
    full: MethodSummary,
    temporal: MethodSummary,
    converged_wall: Stat,
    converged_change_mean: f64,
    /// Full-march GPU time over temporal-march GPU time, means per frame.
    time_ratio_full_over_temporal: f64,
    /// Temporal-march mean FLIP over full-march mean FLIP.
    flip_ratio_temporal_over_full: f64,
    /// The temporal march's mean frame change minus the converged sequence's.
    temporal_change_excess: f64,
    empty_space_skipping: Option<SkippingSummary>,
    targets: Vec<Target>,
    per_frame: Vec<FrameRecord>,
}

impl Report {
    /// Summarises `records`, measured as `setup` says.
    pub fn new(setup: Setup, records: Vec<FrameRecord>) -> Report {
        let full = MethodSummary::new("full", &records, |r| r.full.as_ref());
        let temporal = MethodSummary::new("temporal", &records, |r| Some(&r.temporal));
        let converged = records.iter().filter_map(|r| r.converged.as_ref());
        let converged_change_mean = mean(converged.clone().filter_map(|c| c.change));
        let skipping = SkippingSummary::new(&records);
        let time_ratio = full.time.mean_ms / temporal.time.mean_ms;
        let flip_ratio = temporal.flip_mean / full.flip_mean;
        let (min_time_ratio, max_flip_ratio) = time_and_flip_targets(setup.temporal_divisor);
        let mut targets = vec![
            Target::at_least("GPU time, full / temporal", time_ratio, min_time_ratio),
            Target::below("FLIP, temporal / full", flip_ratio, max_flip_ratio, true),
            Target::below(
                "flicker, temporal / full",
                temporal.flicker_mean / full.flicker_mean,
                1.0,
                true,
            ),
        ];
        if let Some(s) = &skipping {
            let ratio = s.samples_off / s.samples_on;
            targets.push(Target::at_least(
                "samples, skipping off / on",
                ratio,
                MIN_SAMPLE_RATIO,
            ));
            let flip = s.flip_worst;
            targets.push(Target::below(
                "FLIP, skipping on vs off",
                flip,
                MAX_SKIPPING_FLIP,
                false,
            ));
        }
        Report {
            setup,
            converged_wall: Stat::new("converged", converged.map(|c| c.wall_ms).collect()),
            converged_change_mean,
            time_ratio_full_over_temporal: time_ratio,
            flip_ratio_temporal_over_full: flip_ratio,
            temporal_change_excess: temporal.change_mean - converged_change_mean,
            full,
            temporal,
            empty_space_skipping: skipping,
            targets,
            per_frame: records,
        }
    }

    /// Prints the report as JSON on stdout, or as tables.
    pub fn print(&self, json: bool) -> Result<()> {
        if json {
            println!("{}", serde_json::to_string_pretty(self)?);
        } else {
            self.print_setup();
            self.print_marches();
            self.print_skipping();
            self.print_targets();
        }
        Ok(())
    }

    fn print_setup(&self) {
        let s = &self.setup;
        let (start, end) = s.time_range_s;
        let frames = self.per_frame.len();
        let pacing = s
            .fps
            .map_or("spread over the path".into(), |f| format!("{f} fps"));
        println!(
            "{}: {frames} frames from {start} s to {end} s ({pacing}) at {}x{} on {}",
            s.scene, s.width, s.height, s.adapter
        );
        let with = self.per_frame.iter().filter(|r| r.full.is_some()).count();
        println!(
            "every frame through the temporal march; {with} frames (runs of {} every {}) also \
             through the full march and a converged frame; both marches carry their lighting \
             across frames",
            super::RUN_FRAMES,
            s.reference_every
        );
        match s.clock {
            Clock::Timestamps => println!("time: GPU timestamps, summed over the frame's passes"),
            Clock::Wall => println!(
                "time: wall clock per frame (no usable GPU timestamps: none, or a software adapter)"
            ),
        }
        let r = &s.reference;
        println!(
            "error: mean LDR FLIP of the tone-mapped frame against the converged frame (full \
             resolution, no temporal reuse, {} primary steps, {} samples per pixel)",
            r.primary_steps, r.samples_per_pixel
        );
        println!(
            "change: mean |Y'(t) - Y'(t-1)| of Rec. 709 luma; flicker: mean |dX - dC|, the change \
             the converged sequence C does not have\n"
        );
    }

    fn print_marches(&self) {
        let s = &self.setup;
        let d = s.temporal_divisor;
        let rows = [
            (format!("full ({} steps)", s.primary_steps), &self.full),
            (format!("temporal {d}x{d} (1/{} px)", d * d), &self.temporal),
        ];
        println!(
            "{:<26} {:>10} {:>10} {:>10} {:>9} {:>9}",
            "march", "mean ms", "median ms", "FLIP mean", "change", "flicker"
        );
        for (name, m) in rows {
            println!(
                "{name:<26} {:>10.2} {:>10.2} {:>10.4} {:>9.4} {:>9.4}",
                m.time.mean_ms, m.time.median_ms, m.flip_mean, m.change_mean, m.flicker_mean
            );
        }
        let c = &self.converged_wall;
        println!(
            "{:<26} {:>10.2} {:>10.2} {:>10} {:>9.4} {:>9}",
            "converged (wall clock)", c.mean_ms, c.median_ms, "-", self.converged_change_mean, "-"
        );
        println!(
            "temporal change minus converged change: {:+.4}\n",
            self.temporal_change_excess
        );
    }

    fn print_skipping(&self) {
        let Some(s) = &self.empty_space_skipping else {
            println!("empty-space skipping: no frame has the camera above the cloud layers\n");
            return;
        };
        println!(
            "empty-space skipping, full march, {} frames with the camera above the layers:",
            s.frames
        );
        println!("{:<26} {:>10} {:>10}", "", "samples/px", "mean ms");
        println!("{:<26} {:>10.1} {:>10.2}", "off", s.samples_off, s.ms_off);
        println!("{:<26} {:>10.1} {:>10.2}", "on", s.samples_on, s.ms_on);
        println!(
            "FLIP on against off: mean {:.4}, worst frame {:.4}\n",
            s.flip_mean, s.flip_worst
        );
    }

    fn print_targets(&self) {
        println!("targets");
        for t in &self.targets {
            let verdict = if t.met { "met" } else { "MISSED" };
            println!(
                "  {:<30} {:>8.3} {:>8}  {verdict}",
                t.name, t.value, t.bound
            );
        }
    }
}

/// The mean of `values` (NaN for none: nothing to average).
fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, count) = values.fold((0.0, 0u32), |(s, n), v| (s + v, n + 1));
    sum / f64::from(count)
}
