//! `cloudscape bench --soak N`: a long session as a game runs one. At least N frames at a small
//! size with temporal reuse, a camera that keeps moving and turning, and a live edit of the scene
//! every `--soak-edit-every` frames (coverage, sun, technique, in turn), in whole cycles of the
//! [`EDITS`]: the run ends in the state it started in, so the figures compare like with like.
//! Resident memory and what wgpu reports of the GPU (allocated bytes, live objects) are taken after
//! a warm-up that makes every edit once, and again at the end of each cycle;
//! growth beyond [`MAX_GROWTH`] of any of them from the start to the end (on a CPU adapter,
//! resident memory may also grow by the device memory reserved at the start, which the driver
//! pages in as it is used, or on GL by [`GL_DRIVER_WARM_UP_BYTES`]), a non-finite pixel in the last frame or any error fails the run.

use super::BenchArgs;
use crate::common::{progress_bar, temporal_reuse};
use anyhow::{Result, anyhow, bail};
use cloudscape::frame::Frame;
use cloudscape::gpu::{GpuContext, GpuMemoryReport, PassTimer};
use cloudscape::renderer::{PASS_COUNT, SceneRenderer};
use cloudscape::scene::SceneDocument;
use glam::UVec2;
use serde::Serialize;

/// The live edits, made in turn and cycled: each is a `--set` override on top of the earlier ones.
const EDITS: [&str; 7] = [
    "layers.0.coverage=0.35",
    "sun.elevation_deg=12",
    "render.technique=particles",
    "layers.0.coverage=0.6",
    "sun.elevation_deg=40",
    "render.technique=sprites",
    "render.technique=raymarch",
];
/// Index of resident memory among [`Snapshot::figures`].
const RESIDENT: usize = 0;
/// Largest allowed growth of each figure from the start to the end, as a fraction.
const MAX_GROWTH: f64 = 0.01;
/// How much resident memory a software GL driver (llvmpipe) takes over the first cycles of edits
/// beyond the warm-up, with nothing leaking: its shader and state caches filling. Measured with
/// `bench --soak 840 --soak-edit-every 10 --width 48 --height 27 --set render.quality=low` on GL:
/// 215.3, 215.6, 216.8 MiB at the ends of the first three cycles and 216.7-216.8 MiB for the next
/// three; one-cycle soaks grew 2.2-4.8 MiB. A leak of a frame's worth of anything outgrows it in
/// a long soak.
const GL_DRIVER_WARM_UP_BYTES: u64 = 8 << 20;
/// Image size when neither `--width` nor `--height` is given, pixels.
const DEFAULT_SIZE: UVec2 = UVec2::new(160, 90);
/// How far the camera moves per frame, metres, and turns, degrees.
const STEP_M: f32 = 15.0;
const TURN_DEG: f32 = 0.05;
/// Scene seconds per frame.
const FRAME_S: f32 = 1.0 / 30.0;

/// Memory at one moment.
#[derive(Clone, Copy, Debug, Serialize)]
struct Snapshot {
    /// Resident set size of this process, bytes (`VmRSS` of /proc/self/status); `None` where that
    /// file does not exist.
    resident_bytes: Option<u64>,
    gpu: GpuMemoryReport,
}

impl Snapshot {
    fn take(ctx: &GpuContext) -> Snapshot {
        ctx.wait_idle();
        Snapshot {
            resident_bytes: resident_bytes(),
            gpu: ctx.memory_report(),
        }
    }

    /// The figures in one line, MiB.
    fn line(&self) -> String {
        let mib = |bytes: Option<u64>| {
            bytes.map_or("n/a".into(), |b| format!("{:.1}", b as f64 / 1048576.0))
        };
        format!(
            "resident {} MiB, GPU allocated {} MiB, {} live wgpu objects",
            mib(self.resident_bytes),
            mib(self.gpu.allocated_bytes),
            self.gpu
                .live_objects
                .map_or("n/a".into(), |n| n.to_string())
        )
    }

    /// Each figure by name, `None` where it is not known; resident memory first ([`RESIDENT`]).
    fn figures(&self) -> [(&'static str, Option<u64>); 4] {
        [
            ("resident memory (bytes)", self.resident_bytes),
            ("GPU allocated (bytes)", self.gpu.allocated_bytes),
            ("GPU reserved (bytes)", self.gpu.reserved_bytes),
            ("live wgpu objects", self.gpu.live_objects.map(|n| n as u64)),
        ]
    }
}

#[derive(Serialize)]
struct SoakReport {
    adapter: String,
    /// A CPU adapter, whose device memory is resident memory of this process.
    software: bool,
    width: u32,
    height: u32,
    /// Frames soaked: the frames asked for, rounded up to whole cycles of the edits.
    frames: u32,
    /// Frames between two live edits.
    edit_every: u32,
    warmup_frames: u32,
    edits: u32,
    start: Snapshot,
    end: Snapshot,
}

/// Runs the soak and prints its report; an error when a figure grew too much.
pub fn run(args: &BenchArgs, frames: u32) -> Result<()> {
    let mut size_overrides = Vec::new();
    if args.scene.width.is_none() && args.scene.height.is_none() {
        size_overrides.push(format!("render.width={}", DEFAULT_SIZE.x));
        size_overrides.push(format!("render.height={}", DEFAULT_SIZE.y));
    }
    resident_memory_follows_what_is_live();
    let doc = args.scene.load(&size_overrides)?;
    let ctx = args.gpu.open(&doc)?;
    let mut soak = Soak::new(args, &ctx, size_overrides)?;
    eprintln!("warming up: every edit once, {} frames each", args.warmup);
    soak.cycle(&ctx, args.warmup, None)?;
    let start = Snapshot::take(&ctx);
    let cycle_frames = args.soak_edit_every * EDITS.len() as u32;
    let cycles = frames.div_ceil(cycle_frames);
    let bar = progress_bar("soaking");
    bar.set_length(u64::from(cycles * cycle_frames));
    for cycle in 1..=cycles {
        soak.cycle(&ctx, args.soak_edit_every, Some(&bar))?;
        let line = format!("cycle {cycle}: {}", Snapshot::take(&ctx).line());
        bar.suspend(|| eprintln!("{line}"));
    }
    bar.finish_and_clear();
    soak.check_last_frame(&ctx)?;
    let end = Snapshot::take(&ctx);
    let report = SoakReport {
        adapter: ctx.summary(),
        software: ctx.adapter_info().device_type == wgpu::DeviceType::Cpu,
        width: soak.size.x,
        height: soak.size.y,
        frames: cycles * cycle_frames,
        edit_every: args.soak_edit_every,
        warmup_frames: args.warmup * EDITS.len() as u32,
        edits: soak.edits,
        start,
        end,
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    }
    print_and_check(&report, !args.json)
}

/// The renderer, the scene as edited so far and the moving camera.
struct Soak<'a> {
    args: &'a BenchArgs,
    base: Vec<String>,
    applied: Vec<String>,
    doc: SceneDocument,
    renderer: SceneRenderer,
    timer: PassTimer,
    size: UVec2,
    frame_index: u32,
    edits: u32,
}

impl<'a> Soak<'a> {
    fn new(args: &'a BenchArgs, ctx: &GpuContext, base: Vec<String>) -> Result<Soak<'a>> {
        let doc = args.scene.load(&base)?;
        let renderer = SceneRenderer::new(ctx, &doc.scene, &doc.resolve_path(""))
            .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))?;
        let size = UVec2::new(doc.scene.render.width, doc.scene.render.height);
        Ok(Soak {
            args,
            base,
            applied: Vec::new(),
            doc,
            renderer,
            timer: PassTimer::new(ctx, PASS_COUNT),
            size,
            frame_index: 0,
            edits: 0,
        })
    }

    /// Makes edit `index` of [`EDITS`] (cycled) live.
    fn edit(&mut self, ctx: &GpuContext, index: usize) -> Result<()> {
        self.applied.push(EDITS[index % EDITS.len()].to_string());
        let overrides: Vec<String> = self.base.iter().chain(&self.applied).cloned().collect();
        self.doc = self.args.scene.load(&overrides)?;
        let scene = &self.doc.scene;
        self.renderer
            .set_scene(ctx, scene, &self.doc.resolve_path(""))
            .map_err(|e| anyhow!(self.doc.error_at(&e.key_path, e.message)))?;
        self.edits += 1;
        Ok(())
    }

    /// Makes every edit of [`EDITS`] in turn, each followed by `frames_each` frames (counted on
    /// `bar`).
    fn cycle(
        &mut self,
        ctx: &GpuContext,
        frames_each: u32,
        bar: Option<&indicatif::ProgressBar>,
    ) -> Result<()> {
        for _ in 0..EDITS.len() {
            self.edit(ctx, self.edits as usize)?;
            self.frames(ctx, frames_each, bar);
        }
        Ok(())
    }

    /// Renders `count` frames (counted on `bar`).
    fn frames(&mut self, ctx: &GpuContext, count: u32, bar: Option<&indicatif::ProgressBar>) {
        let reuse = temporal_reuse(self.args.temporal.unwrap_or(4));
        for _ in 0..count {
            let frame = self.moving_frame();
            self.renderer
                .render_frame(ctx, &frame, reuse, &mut self.timer);
            self.frame_index += 1;
            if let Some(bar) = bar {
                bar.inc(1);
            }
        }
    }

    /// This frame's view: the scene's camera carried along x and turned a little more each frame.
    fn moving_frame(&self) -> Frame {
        let mut scene = self.doc.scene.clone();
        let n = self.frame_index as f32;
        let camera = &mut scene.camera;
        camera.position_m[0] += STEP_M * n;
        if let Some(target) = camera.look_at_m.as_mut() {
            target[0] += STEP_M * n;
        }
        camera.yaw_deg += TURN_DEG * n;
        let mut frame = Frame::from_scene(&scene, self.size);
        frame.time_s = scene.render.time_s + FRAME_S * n;
        frame.frame_index = self.frame_index;
        frame
    }

    /// The last frame's HDR image holds only finite, non-negative radiance.
    fn check_last_frame(&self, ctx: &GpuContext) -> Result<()> {
        let hdr = self.renderer.images(ctx).hdr;
        let bad = hdr
            .pixels
            .iter()
            .position(|p| p.iter().any(|c| !c.is_finite() || *c < 0.0));
        if let Some(index) = bad {
            bail!(
                "the last frame holds {:?} at pixel {index}",
                hdr.pixels[index]
            );
        }
        Ok(())
    }
}

/// Prints the figures (when `print`), and fails on the first that grew beyond [`MAX_GROWTH`].
fn print_and_check(report: &SoakReport, print: bool) -> Result<()> {
    if print {
        println!(
            "soak on {}: {} frames at {}x{} after {} warm-up frames, {} live edits (one every {} frames)",
            report.adapter,
            report.frames,
            report.width,
            report.height,
            report.warmup_frames,
            report.edits,
            report.edit_every
        );
        println!("{:<26} {:>14} {:>14} {:>9}", "", "start", "end", "change");
    }
    let mut failures = Vec::new();
    let figures = report.start.figures().into_iter().zip(report.end.figures());
    for (index, ((name, start), (_, end))) in figures.enumerate() {
        let (Some(start), Some(end)) = (start, end) else {
            if print {
                println!("{name:<26} {:>14} {:>14}", "n/a", "n/a");
            }
            continue;
        };
        let growth = (end as f64 - start as f64) / (start as f64).max(1.0);
        if print {
            println!(
                "{name:<26} {start:>14} {end:>14} {:>+8.2} %",
                growth * 100.0
            );
        }
        // On a CPU adapter the device memory is this process's memory: the allocator reserves its
        // blocks at once and the driver pages them in as they are used, so resident memory may
        // grow by up to what was reserved at the start without anything leaking. Where wgpu
        // reports no reservation (GL), the driver allocates as it goes and fills its caches.
        let paged_in = match (index, report.software) {
            (RESIDENT, true) => report
                .start
                .gpu
                .reserved_bytes
                .unwrap_or(GL_DRIVER_WARM_UP_BYTES),
            _ => 0,
        };
        let allowed = MAX_GROWTH * start as f64 + paged_in as f64;
        if end as f64 - start as f64 > allowed {
            failures.push(format!(
                "{name} grew {:.2} % (allowed {:.0} %{})",
                growth * 100.0,
                MAX_GROWTH * 100.0,
                if paged_in > 0 {
                    format!(" plus {paged_in} bytes a software driver may page in")
                } else {
                    String::new()
                }
            ));
        }
    }
    if !failures.is_empty() {
        bail!("the soak leaks: {}", failures.join("; "));
    }
    Ok(())
}

/// Makes glibc return every large freed block to the system at once, so that resident memory
/// measures what is live. By default glibc raises its threshold for serving a block by `mmap`
/// each time such a block is freed (glibc `mallopt(3)`, "M_MMAP_THRESHOLD": dynamic threshold),
/// after which blocks of that size come from the heap and stay resident when freed: on GL, where
/// llvmpipe keeps textures in process memory, the technique edits then moved resident memory by
/// up to 11 % between cycles with nothing leaking (measured; flat within 0.7 % with the threshold
/// fixed at glibc's default of 128 KiB).
fn resident_memory_follows_what_is_live() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        const MMAP_THRESHOLD_BYTES: libc::c_int = 128 * 1024;
        // SAFETY: mallopt only sets an allocator parameter; it is called before the GPU starts.
        unsafe { libc::mallopt(libc::M_MMAP_THRESHOLD, MMAP_THRESHOLD_BYTES) };
    }
}

/// This process's resident set size, bytes, from `/proc/self/status` (Linux).
fn resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}
