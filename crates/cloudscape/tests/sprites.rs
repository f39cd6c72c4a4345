//! The sprite technique's behaviour on the GPU: the impostor ring costs little against drawing
//! every cloud in 3D, and a fly-through of a cloud shows neither a pop nor a hole.

use cloudscape::frame::Frame;
use cloudscape::gpu::{GpuContext, PassTimer};
use cloudscape::image::{HdrImage, LdrImage, flip};
use cloudscape::renderer::{PASS_COUNT, Reuse, SceneRenderer};
use cloudscape::scene::{Scene, SceneDocument};
use cloudscape::shadow::LightingReuse;
use glam::UVec2;
use std::path::Path;

/// A scene from `toml` and `overrides` at `size`.
fn scene(toml: &str, overrides: &[&str], size: UVec2) -> Scene {
    let mut all: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    all.push(format!("render.width={}", size.x));
    all.push(format!("render.height={}", size.y));
    SceneDocument::parse(toml, "sprite test", Path::new("."), &all)
        .expect("valid")
        .scene
}

/// A still of `scene`.
fn still(ctx: &GpuContext, scene: &Scene) -> LdrImage {
    let mut renderer = SceneRenderer::new(ctx, scene, Path::new(".")).expect("builds");
    renderer.render(ctx, |_| {}).ldr
}

#[test]
fn the_impostor_ring_shows_the_far_clouds_as_drawing_them_in_3d_does() {
    let ctx = GpuContext::for_tests();
    let size = UVec2::new(256, 144);
    let common = ["render.technique=sprites", "sprites.distance_m=20000"];
    let ring = still(
        &ctx,
        &scene(
            "",
            &[&common[..], &["sprites.ring_radius_m=5000"]].concat(),
            size,
        ),
    );
    let all_3d = still(
        &ctx,
        &scene(
            "",
            &[&common[..], &["sprites.ring_radius_m=0"]].concat(),
            size,
        ),
    );
    let (stats, _) = flip(&all_3d, &ring).expect("same size");
    // Resampling the impostors softens the far clouds a little; their place and light are kept.
    assert!(
        stats.mean < 0.05,
        "ring against 3D: FLIP mean {}",
        stats.mean
    );
    assert!(
        stats.mean > 0.0005,
        "the ring drew nothing of its own: FLIP {}",
        stats.mean
    );
}

/// The radiance of every frame of a straight flight through a hand-made cloud.
fn fly_through(ctx: &GpuContext, frames: u32) -> Vec<HdrImage> {
    let size = UVec2::new(96, 54);
    let toml = "layers = []\n[render]\ntechnique = \"sprites\"\n[sprites]\nfield_clouds = false\n\
        [camera]\nposition_m = [0.0, 1500.0, 0.0]\nyaw_deg = 0.0\npitch_deg = 0.0\n\
        [[sprite_clouds]]\ntype = \"cumulus_congestus\"\ncenter_m = [0.0, 1500.0, -1000.0]\nseed = 2\nsprites = 400\n\
        boxes = [{ center_m = [0.0, 0.0, 0.0], size_m = [1800.0, 900.0, 1800.0] }]\n";
    let base = scene(toml, &[], size);
    let mut renderer = SceneRenderer::new(ctx, &base, Path::new(".")).expect("builds");
    // The lighting carried across frames, as a game flying through it carries it.
    renderer
        .clouds()
        .set_lighting_reuse(Some(LightingReuse::REAL_TIME));
    let mut timer = PassTimer::new(ctx, PASS_COUNT);
    (0..frames)
        .map(|i| {
            let mut s = base.clone();
            // From 1 km before the cloud's centre to 1 km past it, 40 m a frame.
            s.camera.position_m[2] = -2000.0 * i as f32 / (frames - 1) as f32;
            let frame = Frame {
                frame_index: i,
                ..Frame::from_scene(&s, size)
            };
            renderer.render_frame(ctx, &frame, Reuse::None, &mut timer);
            renderer.images(ctx).hdr
        })
        .collect()
}

/// Fraction of the pixels of the view's central third (straight ahead, where the rays cross the
/// most cloud) that see the sky's blue rather than cloud (blue well above red).
fn sky_ahead(image: &HdrImage) -> f64 {
    let (w, h) = (image.width as usize, image.height as usize);
    let centre: Vec<&[f32; 4]> = (h / 3..2 * h / 3)
        .flat_map(|y| (w / 3..2 * w / 3).map(move |x| y * w + x))
        .map(|i| &image.pixels[i])
        .collect();
    let sky = centre.iter().filter(|p| p[2] > 1.4 * p[0]).count();
    sky as f64 / centre.len() as f64
}

#[test]
fn a_fly_through_a_cloud_shows_neither_a_pop_nor_a_hole() {
    let ctx = GpuContext::for_tests();
    let frames = fly_through(&ctx, 51);
    let changes: Vec<f64> = frames
        .windows(2)
        .map(|w| {
            let n = w[0].pixels.len() as f64;
            let d: f64 = w[0]
                .pixels
                .iter()
                .zip(&w[1].pixels)
                .map(|(a, b)| (0..3).map(|c| f64::from((a[c] - b[c]).abs())).sum::<f64>())
                .sum();
            d / n
        })
        .collect();
    // Sprites fade as the eye passes them and turn to face along the view: no frame changes much
    // more than the frames either side of it (a pop is a lone jump).
    for (i, pair) in changes.windows(3).enumerate() {
        let around = 0.5 * (pair[0] + pair[2]);
        assert!(
            pair[1] < 3.0 * around + 0.02,
            "a pop at frame {}: {changes:?}",
            i + 2
        );
    }
    // Inside the cloud (its box spans z = -1900..-100 m: frames 3..47), while 700 m or more of
    // it lies ahead, the view ahead stays filled (at most 10 % sky; measured: none, the fog that
    // stands for the sprites the eye has passed fills it, where the sprites alone left up to
    // 22 %).
    let inside: Vec<f64> = frames[3..30].iter().map(sky_ahead).collect();
    assert!(
        inside.iter().all(|&f| f < 0.10),
        "a hole: sky ahead {inside:?}"
    );
}
