//! The plugin in a real window: a Bevy app on a virtual X server (Xvfb) and the test adapter,
//! driven by a script of frames, screenshots and file edits, its screenshots returned as images.

use bevy::asset::AssetEvent;
use bevy::camera::{CameraProjection, PerspectiveProjection};
use bevy::math::Vec4Swizzles;
use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::window::WindowResolution;
use bevy::winit::WinitPlugin;
use bevy_cloudscape::{CloudShadowedMaterial, CloudSky, Clouds, CloudscapePlugin};
use cloudscape::image::LdrImage;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use xvfb::Xvfb;

/// What a test needs from the machine (the CLI's tests' module: Xvfb's program and libraries).
#[path = "../../../cloudscape-cli/tests/cli/needs.rs"]
pub mod needs;
/// The flight example's world, which the tests render.
#[path = "../../examples/flight/world.rs"]
#[allow(
    dead_code,
    reason = "the example's world, of which the tests use a part"
)]
pub mod world;
/// A virtual X server (the CLI's tests' module; it reaches `needs` as `crate::needs`, which each
/// test file's root re-exports).
#[path = "../../../cloudscape-cli/tests/cli/xvfb.rs"]
mod xvfb;

/// Window size: small, for a 2-core software GPU.
pub const SIZE: UVec2 = UVec2::new(256, 144);
/// Frames after which a script that has not finished fails the test.
const MAX_FRAMES: u32 = 2000;

/// One step of a script.
#[derive(Clone, Debug)]
pub enum Step {
    /// Render this many frames.
    Frames(u32),
    /// Capture the window and wait for the image.
    Screenshot,
    /// Write a file (a scene the app is watching).
    Write(PathBuf, String),
    /// Wait until the sky asset has been reloaded.
    AwaitSkyReload,
    /// Set the cameras' `Clouds::render_scale`.
    RenderScale(f32),
    /// Turn the cameras' clouds off.
    CloudsOff,
    /// Set the cameras' `Clouds::sky_ambient`.
    SkyAmbient(bool),
}

/// Runs the flight world under the sky file `sky` (a name in `asset_dir`) through `script` in a
/// window on Xvfb; returns the screenshots, or None when the machine lacks Xvfb (outside CI).
pub fn run(asset_dir: &Path, sky: &str, script: Vec<Step>) -> Option<Vec<LdrImage>> {
    let xvfb = Xvfb::start()?;
    // SAFETY: each test binary starts one app, before any other thread reads the environment.
    unsafe { std::env::set_var("DISPLAY", &xvfb.display) };
    let shots = Arc::new(Mutex::new(Vec::new()));
    let mut app = App::new();
    app.add_plugins((
        DefaultPlugins
            .set(WindowPlugin {
                primary_window: Some(Window {
                    resolution: WindowResolution::new(SIZE.x, SIZE.y),
                    ..default()
                }),
                ..default()
            })
            .set(WinitPlugin {
                run_on_any_thread: true,
            })
            .set(AssetPlugin {
                file_path: asset_dir.display().to_string(),
                watch_for_changes_override: Some(true),
                ..default()
            }),
        CloudscapePlugin,
    ))
    .insert_resource(Script {
        steps: script,
        next: 0,
        frames_left: 0,
        frame: 0,
        shots_wanted: 0,
        shots: shots.clone(),
        waiting_for_reload: false,
    })
    .insert_resource(SkyFile(sky.to_string()))
    .add_systems(Startup, setup)
    .add_systems(Update, run_script);
    app.run();
    drop(xvfb);
    let shots = std::mem::take(&mut *shots.lock().expect("screenshots"));
    Some(shots)
}

#[derive(Resource)]
struct SkyFile(String);

/// The script and where it stands.
#[derive(Resource)]
struct Script {
    steps: Vec<Step>,
    next: usize,
    frames_left: u32,
    frame: u32,
    shots_wanted: usize,
    shots: Arc<Mutex<Vec<LdrImage>>>,
    waiting_for_reload: bool,
}

/// The flight example's world, its clouds marching every pixel every frame (no temporal reuse:
/// the screenshots do not depend on how many frames came before).
fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut standard: ResMut<Assets<StandardMaterial>>,
    mut shadowed: ResMut<Assets<CloudShadowedMaterial>>,
    assets: Res<AssetServer>,
    sky: Res<SkyFile>,
) {
    let sky = assets.load::<CloudSky>(sky.0.clone());
    let materials = world::Materials {
        standard: &mut standard,
        shadowed: &mut shadowed,
    };
    world::spawn_world(&mut commands, &mut meshes, materials, sky);
}

/// Moves the script on by at most one step a frame; exits the app at its end.
fn run_script(
    mut commands: Commands,
    mut script: ResMut<Script>,
    mut reloads: MessageReader<AssetEvent<CloudSky>>,
    mut clouds: Query<&mut Clouds>,
    mut exit: MessageWriter<AppExit>,
) {
    for mut c in &mut clouds {
        if c.temporal_grid.is_some() {
            c.temporal_grid = None;
        }
    }
    let reloaded = reloads
        .read()
        .any(|e| matches!(e, AssetEvent::Modified { .. }));
    let script = &mut *script;
    script.frame += 1;
    assert!(
        script.frame < MAX_FRAMES,
        "the script did not finish in {MAX_FRAMES} frames"
    );
    if script.frames_left > 0 {
        script.frames_left -= 1;
        return;
    }
    if script.shots.lock().expect("screenshots").len() < script.shots_wanted {
        return;
    }
    if script.waiting_for_reload && !reloaded {
        return;
    }
    script.waiting_for_reload = false;
    let Some(step) = script.steps.get(script.next).cloned() else {
        exit.write(AppExit::Success);
        return;
    };
    script.next += 1;
    match step {
        Step::Frames(n) => script.frames_left = n,
        Step::Screenshot => {
            script.shots_wanted += 1;
            let shots = script.shots.clone();
            commands.spawn(Screenshot::primary_window()).observe(
                move |captured: On<ScreenshotCaptured>| {
                    shots
                        .lock()
                        .expect("screenshots")
                        .push(ldr_of(&captured.image));
                },
            );
        }
        Step::Write(path, text) => std::fs::write(&path, text).expect("write the scene file"),
        Step::AwaitSkyReload => script.waiting_for_reload = true,
        Step::RenderScale(scale) => clouds.iter_mut().for_each(|mut c| c.render_scale = scale),
        Step::CloudsOff => clouds.iter_mut().for_each(|mut c| c.enabled = false),
        Step::SkyAmbient(on) => clouds.iter_mut().for_each(|mut c| c.sky_ambient = on),
    }
}

/// A screenshot as cloudscape's 8-bit image (the window's format is BGRA or RGBA, sRGB).
fn ldr_of(image: &Image) -> LdrImage {
    use bevy::render::render_resource::TextureFormat as F;
    let size = image.size();
    let data = image.data.as_ref().expect("a screenshot holds its pixels");
    let bgra = matches!(
        image.texture_descriptor.format,
        F::Bgra8Unorm | F::Bgra8UnormSrgb
    );
    let pixels = data
        .chunks_exact(4)
        .map(|p| {
            let [a, b, c, _] = [p[0], p[1], p[2], p[3]];
            if bgra { [c, b, a, 255] } else { [a, b, c, 255] }
        })
        .collect();
    LdrImage {
        width: size.x,
        height: size.y,
        pixels,
    }
}

/// Where `p` (world, metres) appears in the window, as fractions of its width and height from the
/// top left, seen from the world's starting camera.
pub fn on_screen(p: Vec3) -> Vec2 {
    let projection = PerspectiveProjection {
        aspect_ratio: SIZE.x as f32 / SIZE.y as f32,
        ..Default::default()
    };
    let view_from_world = world::start_transform().to_matrix().inverse();
    let clip = projection.get_clip_from_view() * view_from_world * p.extend(1.0);
    let ndc = clip.xy() / clip.w;
    Vec2::new(0.5 + 0.5 * ndc.x, 0.5 - 0.5 * ndc.y)
}

/// The mean colour in a square of `half` (fraction of the height) around `p`'s place on screen.
pub fn color_around(shot: &LdrImage, p: Vec3, half: f32) -> Vec3 {
    let centre = on_screen(p);
    let aspect = SIZE.y as f32 / SIZE.x as f32;
    let extent = Vec2::new(half * aspect, half);
    mean_color(shot, centre - extent, centre + extent)
}

/// How red a colour is: red over the brighter of green and blue (the unlit red tower, tone-mapped
/// by Bevy's TonyMcMapface, measures 2.9; the clouds' greys and whites 1.0-1.1).
pub fn redness(c: Vec3) -> f32 {
    c.x / c.y.max(c.z).max(1e-3)
}

/// The mean colour, 0..1 per channel, of `image` over the pixels of the rectangle from `min` to
/// `max` (fractions of the width and height from the top left).
fn mean_color(image: &LdrImage, min: Vec2, max: Vec2) -> Vec3 {
    let size = Vec2::new(image.width as f32, image.height as f32);
    let (lo, hi) = ((min * size).as_uvec2(), (max * size).as_uvec2());
    let mut sum = Vec3::ZERO;
    let mut n = 0.0;
    for y in lo.y..hi.y {
        for x in lo.x..hi.x {
            let [r, g, b, _] = image.pixels[(y * image.width + x) as usize];
            sum += Vec3::new(r.into(), g.into(), b.into()) / 255.0;
            n += 1.0;
        }
    }
    sum / n
}
