//! Golden frames of a short temporal sequence: frames of `scenes/flythrough.toml`'s fast sideways
//! pass under the layer, marched with temporal reuse (one ray per 4x4 pixels per frame), against
//! checked-in goldens, compared by FLIP as `golden.rs` compares stills.
//!
//! `CLOUDSCAPE_UPDATE_GOLDENS=1 cargo test --test sequence` rewrites the goldens in `tests/golden/`.

use cloudscape::animation::scene_at;
use cloudscape::frame::Frame;
use cloudscape::gpu::{GpuContext, PassTimer};
use cloudscape::renderer::{PASS_COUNT, Reuse, SceneRenderer};
use cloudscape::scene::SceneDocument;
use cloudscape::temporal::TemporalSettings;
use glam::UVec2;
use support::{check, manifest_dir};

mod support;

/// Frame size: small, for a 2-core software GPU.
const SIZE: UVec2 = UVec2::new(128, 72);
/// Scene time of the first frame, seconds: the camera slides sideways at 1 km/s.
const START_S: f32 = 0.5;
/// Frames per second of the sequence.
const FPS: f32 = 24.0;
/// Frames rendered.
const FRAMES: u32 = 6;
/// Frames compared with goldens: the first (no history: the coarse march interpolated) and the
/// last (history reprojected through five frames of motion and clipped). Measured with the golden
/// bounds of `golden.rs`: GL llvmpipe against the Vulkan lavapipe goldens scores FLIP mean 0.0007
/// and 0.0009. The goldens were re-rendered for the resolve of `docs/temporal.md`, which no longer
/// prints the 4x4 update grid the former ones showed, and again for the blue-noise ray offsets
/// (`raymarch/blue_noise.rs`), without the weave the R2 dither printed over the near cloud (the
/// last frame FLIP 0.0302 against the former golden).
const CHECKED: [u32; 2] = [0, FRAMES - 1];

#[test]
fn temporal_frames_of_the_flythrough_match_their_goldens() {
    let path = manifest_dir().join("../../scenes/flythrough.toml");
    let size = [
        format!("render.width={}", SIZE.x),
        format!("render.height={}", SIZE.y),
    ];
    let doc = SceneDocument::load(Some(&path), &size).expect("the fly-through loads");
    let ctx = GpuContext::for_tests();
    let mut renderer =
        SceneRenderer::new(&ctx, &doc.scene, &doc.resolve_path("")).expect("field builds");
    let mut timer = PassTimer::new(&ctx, PASS_COUNT);
    let reuse = Reuse::Temporal(TemporalSettings {
        divisor: 4,
        ..TemporalSettings::default()
    });
    for index in 0..FRAMES {
        let still = scene_at(&doc.scene, START_S + index as f32 / FPS);
        let frame = Frame {
            frame_index: index,
            ..Frame::from_scene(&still, SIZE)
        };
        renderer.render_frame(&ctx, &frame, reuse, &mut timer);
        if CHECKED.contains(&index) {
            check(&format!("sequence_{index}"), &renderer.images(&ctx).ldr);
        }
    }
}
