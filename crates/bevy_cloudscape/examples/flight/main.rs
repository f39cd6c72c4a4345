//! Fly over a ground with a few towers under cloudscape's clouds.
//!
//! `cargo run -p bevy_cloudscape --example flight --ignore-rust-version`
//!
//! Keys: W/S forward and back, A/D sideways, Q/E down and up, arrows turn, Shift faster;
//! C/V less and more cloud; T/G the sun up and down; 1/2/3 ray marcher, particles, sprites;
//! Space pauses the clouds' clock. The sky is `assets/sky.toml`: edit it while flying.
//!
//! `-- --screenshot OUT.png [--size WxH] [--view ALTITUDE_M,PITCH_DEG]` saves the window after 60
//! frames and exits (`--view`: start at that height, pitched up by that angle, negative down);
//! `-- --bench N [--size WxH] [--cold-lighting]` times N frames with the clouds and N without,
//! and prints both (`--cold-lighting`: the clouds' lighting rebuilt every frame, as `cloudscape
//! bench` does).

mod world;

use bevy::prelude::*;
use bevy::render::view::screenshot::Screenshot;
use bevy_cloudscape::{CloudShadowedMaterial, CloudSky, Clouds, CloudscapePlugin, Technique};

/// The line of help, in the window's title.
const HELP: &str = "cloudscape | WASD QE fly, arrows turn, Shift fast | C/V cloud -/+ | T/G sun | \
                    1/2/3 raymarch/particles/sprites | Space pause";

fn main() {
    let options = Options::from_args();
    App::new()
        .add_plugins((
            DefaultPlugins.set(WindowPlugin {
                primary_window: Some(Window {
                    title: HELP.into(),
                    resolution: options.size.into(),
                    present_mode: bevy::window::PresentMode::AutoNoVsync,
                    ..default()
                }),
                ..default()
            }),
            CloudscapePlugin,
        ))
        .insert_resource(options)
        .add_systems(Startup, setup)
        .add_systems(
            Update,
            (fly, change_sky, change_sun, change_clouds, run_options),
        )
        .run();
}

/// What the command line asked for besides flying.
#[derive(Resource, Default)]
struct Options {
    /// Window size, pixels.
    size: UVec2,
    /// Save the window here after [`SCREENSHOT_FRAME`] frames, then exit.
    screenshot: Option<String>,
    /// Time this many frames with clouds and as many without, then exit.
    bench: Option<u32>,
    /// Rebuild the clouds' lighting every frame.
    cold_lighting: bool,
    /// Start at this height (metres), pitched up by this angle (degrees; negative: down).
    view: Option<(f32, f32)>,
}

/// Frames before `--screenshot` saves the window (and before `--bench` starts timing).
const SCREENSHOT_FRAME: u32 = 60;

impl Options {
    fn from_args() -> Options {
        let mut options = Options {
            size: UVec2::new(1280, 720),
            ..default()
        };
        let mut args = std::env::args().skip(1);
        while let Some(arg) = args.next() {
            let mut value = || args.next().unwrap_or_else(|| panic!("{arg} needs a value"));
            match arg.as_str() {
                "--screenshot" => options.screenshot = Some(value()),
                "--bench" => options.bench = Some(value().parse().expect("--bench N")),
                "--cold-lighting" => options.cold_lighting = true,
                "--view" => {
                    let v = value();
                    let (altitude, pitch) = v.split_once(',').expect("--view ALTITUDE_M,PITCH_DEG");
                    options.view = Some((
                        altitude.parse().expect("altitude"),
                        pitch.parse().expect("pitch"),
                    ));
                }
                "--size" => {
                    let v = value();
                    let (w, h) = v.split_once('x').expect("--size WxH");
                    options.size =
                        UVec2::new(w.parse().expect("width"), h.parse().expect("height"));
                }
                other => panic!("unknown option {other}"),
            }
        }
        options
    }
}

/// `--screenshot` and `--bench`: counts frames, saves the window, times the frames.
fn run_options(
    mut commands: Commands,
    options: Res<Options>,
    time: Res<Time<Real>>,
    mut cameras: Query<(&mut Clouds, &mut Transform)>,
    mut exit: MessageWriter<AppExit>,
    mut frame: Local<u32>,
    mut timed: Local<Vec<f32>>,
) {
    *frame += 1;
    if *frame == 1 {
        for (mut clouds, mut transform) in &mut cameras {
            clouds.reuse_lighting = !options.cold_lighting;
            if let Some((altitude, pitch)) = options.view {
                let pitch = pitch.to_radians();
                *transform = Transform::from_xyz(0.0, altitude, 0.0)
                    .looking_to(Vec3::new(0.0, pitch.sin(), -pitch.cos()), Vec3::Y);
            }
        }
    }
    if let Some(path) = options
        .screenshot
        .as_ref()
        .filter(|_| *frame == SCREENSHOT_FRAME)
    {
        commands
            .spawn(Screenshot::primary_window())
            .observe(bevy::render::view::screenshot::save_to_disk(path.clone()));
    }
    if options.screenshot.is_some() && *frame == SCREENSHOT_FRAME + 5 {
        exit.write(AppExit::Success);
    }
    let Some(n) = options.bench else { return };
    if *frame > SCREENSHOT_FRAME {
        timed.push(time.delta_secs() * 1000.0);
    }
    if timed.len() == n as usize {
        for (mut clouds, _) in &mut cameras {
            clouds.enabled = false;
        }
    }
    if timed.len() == 2 * n as usize + SCREENSHOT_FRAME as usize / 4 {
        let mean = |s: &[f32]| s.iter().sum::<f32>() / s.len() as f32;
        let with = mean(&timed[1..n as usize]);
        let without = mean(&timed[timed.len() - n as usize + 1..]);
        println!(
            "{}x{}: frame with clouds {with:.1} ms, without {without:.1} ms, clouds {:.1} ms",
            options.size.x,
            options.size.y,
            with - without
        );
        exit.write(AppExit::Success);
    }
}

/// The world of `world.rs` under the sky of `assets/sky.toml`.
fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut standard: ResMut<Assets<StandardMaterial>>,
    mut shadowed: ResMut<Assets<CloudShadowedMaterial>>,
    assets: Res<AssetServer>,
) {
    let sky = assets.load::<CloudSky>("sky.toml");
    let materials = world::Materials {
        standard: &mut standard,
        shadowed: &mut shadowed,
    };
    world::spawn_world(&mut commands, &mut meshes, materials, sky);
}

/// WASD QE moves the camera along its own axes, the arrows turn it.
fn fly(
    keys: Res<ButtonInput<KeyCode>>,
    time: Res<Time<Real>>,
    mut camera: Single<&mut Transform, With<Camera3d>>,
) {
    let dt = time.delta_secs();
    let speed_m_per_s = if keys.pressed(KeyCode::ShiftLeft) {
        600.0
    } else {
        80.0
    };
    let axis = |plus: KeyCode, minus: KeyCode| {
        f32::from(u8::from(keys.pressed(plus))) - f32::from(u8::from(keys.pressed(minus)))
    };
    let (forward, right) = (camera.forward().as_vec3(), camera.right().as_vec3());
    let motion = forward * axis(KeyCode::KeyW, KeyCode::KeyS)
        + right * axis(KeyCode::KeyD, KeyCode::KeyA)
        + Vec3::Y * axis(KeyCode::KeyE, KeyCode::KeyQ);
    camera.translation += motion * speed_m_per_s * dt;
    camera.translation.y = camera.translation.y.max(2.0);
    let turn_rad_per_s = 0.8;
    camera.rotate_y(axis(KeyCode::ArrowLeft, KeyCode::ArrowRight) * turn_rad_per_s * dt);
    let pitch = axis(KeyCode::ArrowUp, KeyCode::ArrowDown) * turn_rad_per_s * dt;
    camera.rotate_local_x(pitch);
}

/// C/V change the first layer's coverage: an edit of the sky asset, which the clouds pick up.
fn change_sky(
    keys: Res<ButtonInput<KeyCode>>,
    cameras: Query<&Clouds>,
    mut skies: ResMut<Assets<CloudSky>>,
) {
    let step = match (
        keys.just_pressed(KeyCode::KeyC),
        keys.just_pressed(KeyCode::KeyV),
    ) {
        (true, false) => -0.1,
        (false, true) => 0.1,
        _ => return,
    };
    for handle in cameras.iter().filter_map(|c| c.sky.as_ref()) {
        if let Some(mut sky) = skies.get_mut(handle) {
            for layer in &mut sky.scene_mut().layers {
                layer.coverage = (layer.coverage + step).clamp(0.0, 1.0);
            }
        }
    }
}

/// T/G raise and lower the sun; the clouds, the sky and the ground follow it.
fn change_sun(
    keys: Res<ButtonInput<KeyCode>>,
    time: Res<Time<Real>>,
    mut sun: Single<&mut Transform, With<DirectionalLight>>,
    mut elevation_deg: Local<Option<f32>>,
) {
    let rate = 10.0 * time.delta_secs();
    let elevation = elevation_deg.get_or_insert(35.0);
    let before = *elevation;
    if keys.pressed(KeyCode::KeyT) {
        *elevation = (*elevation + rate).min(89.0);
    }
    if keys.pressed(KeyCode::KeyG) {
        *elevation = (*elevation - rate).max(-5.0);
    }
    if *elevation != before {
        **sun = world::sun_transform(*elevation, 200.0);
    }
}

/// 1/2/3 pick the technique; Space pauses the clouds' clock (Bevy's virtual time).
fn change_clouds(
    keys: Res<ButtonInput<KeyCode>>,
    mut clouds: Query<&mut Clouds>,
    mut time: ResMut<Time<Virtual>>,
) {
    let technique = [
        (KeyCode::Digit1, Technique::Raymarch),
        (KeyCode::Digit2, Technique::Particles),
        (KeyCode::Digit3, Technique::Sprites),
    ]
    .into_iter()
    .find(|(key, _)| keys.just_pressed(*key));
    if let Some((_, technique)) = technique {
        for mut c in &mut clouds {
            c.technique = Some(technique);
        }
    }
    if keys.just_pressed(KeyCode::Space) {
        if time.is_paused() {
            time.unpause();
        } else {
            time.pause();
        }
    }
}
