//! A frame loop that changes nothing but the frame keeps the process's memory flat, with every
//! technique: each frame's passes allocate nothing that outlives it, in this library or in the
//! driver beneath.
//!
//! The regression it guards: lavapipe (Mesa 22.3) recompiles a shader whose branch depends on
//! uniform values alone each time the uniform buffer is rewritten, and leaks every compilation.
//! The aerial-perspective pass had one such branch (the shadow map's warp) and grew the process by
//! about 350 KB a frame, the sprites' shaders by about 100 KB (docs/hardening.md, "Soak"). The test
//! is alone in its binary, so no other test's allocations move the figure.

use cloudscape::frame::Frame;
use cloudscape::gpu::{GpuContext, PassTimer};
use cloudscape::renderer::{PASS_COUNT, Reuse, SceneRenderer};
use cloudscape::scene::{SceneDocument, Technique};
use cloudscape::temporal::TemporalSettings;
use glam::UVec2;

/// Frame size: small, for a 2-core software GPU (the atmosphere's tables do not scale with it).
const SIZE: UVec2 = UVec2::new(48, 27);
/// Frames before the first reading: pipelines compiled, device memory paged in, caches filled.
const WARMUP_FRAMES: u32 = 8;
/// Frames between the two readings: the sprites' leak (the smaller) grows the process 2.4 MB over
/// them, twice the bound below.
const MEASURED_FRAMES: u32 = 24;
/// Largest growth of resident memory over the measured frames, bytes: an eighth of what the
/// leaking pass lost over as many frames. Measured here with the fix over 48 frames: 0 and 60 KiB
/// in two runs; without it: 10 MB.
const MAX_GROWTH_BYTES: u64 = MEASURED_FRAMES as u64 * 350 * 1024 / 8;

#[cfg(target_os = "linux")]
#[test]
fn frames_of_an_unchanged_scene_keep_resident_memory_flat() {
    let ctx = GpuContext::for_tests();
    for technique in [
        Technique::Raymarch,
        Technique::Particles,
        Technique::Sprites,
    ] {
        steady_frames(&ctx, technique);
    }
}

/// Renders the default scene with `technique` and checks resident memory over the measured frames.
#[cfg(target_os = "linux")]
fn steady_frames(ctx: &GpuContext, technique: Technique) {
    let overrides = [
        format!("render.width={}", SIZE.x),
        format!("render.height={}", SIZE.y),
        "render.quality=low".to_string(),
        format!("render.technique={}", technique.name()),
        // The environment's passes small: what leaks does so at any size, and with the default
        // shadow map and light volume a frame costs a software GPU five times as long (`cloudscape
        // bench --width 48 --height 27 --temporal 4`: 256 ms against 52 ms).
        "shadow.resolution=64".to_string(),
        "lighting.volume_cells_horizontal=16".to_string(),
        "lighting.volume_cells_vertical=8".to_string(),
    ];
    let doc = SceneDocument::load(None, &overrides).expect("the default scene loads");
    let mut renderer =
        SceneRenderer::new(ctx, &doc.scene, &doc.resolve_path("")).expect("field builds");
    let mut timer = PassTimer::new(ctx, PASS_COUNT);
    let reuse = Reuse::Temporal(TemporalSettings {
        divisor: 4,
        ..TemporalSettings::default()
    });
    let mut render = |index: u32| {
        let frame = Frame {
            frame_index: index,
            ..Frame::from_scene(&doc.scene, SIZE)
        };
        renderer.render_frame(ctx, &frame, reuse, &mut timer);
    };
    (0..WARMUP_FRAMES).for_each(&mut render);
    let before = resident_bytes();
    (WARMUP_FRAMES..WARMUP_FRAMES + MEASURED_FRAMES).for_each(&mut render);
    let after = resident_bytes();
    let growth = after.saturating_sub(before);
    let name = technique.name();
    eprintln!("{name}: resident memory over {MEASURED_FRAMES} frames: {before} -> {after} bytes");
    assert!(
        growth <= MAX_GROWTH_BYTES,
        "{name}: resident memory grew {growth} bytes over {MEASURED_FRAMES} frames \
         ({before} -> {after}); at most {MAX_GROWTH_BYTES} allowed"
    );
}

/// This process's resident set size, bytes (`VmRSS` of /proc/self/status).
#[cfg(target_os = "linux")]
fn resident_bytes() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").expect("/proc/self/status");
    let line = status
        .lines()
        .find(|l| l.starts_with("VmRSS:"))
        .expect("VmRSS in /proc/self/status");
    let kib: u64 = line
        .split_whitespace()
        .nth(1)
        .and_then(|n| n.parse().ok())
        .expect("VmRSS in kB");
    kib * 1024
}
