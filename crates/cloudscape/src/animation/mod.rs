//! Animation: a scene as it is at any moment of scene time.
//!
//! A scene's [`Animation`] holds keyframed paths (the camera, the sun, a factor on cloud coverage),
//! each interpolated by a [`catmull_rom`] spline over its keyframe times. [`scene_at`] evaluates
//! them into a still scene. The wind needs no keyframes: the cloud field moves the clouds by
//! `wind_m_per_s * render.time_s`, and `scene_at` sets `render.time_s`.
//!
//! Rendering a sequence: build one [`crate::renderer::SceneRenderer`] and render each
//! `scene_at(scene, t)` with it. The renderer's cloud field is built from the layers, so a
//! sequence whose coverage changes (`coverage_scale`) needs a new renderer whenever the layers of
//! the still differ from the previous frame's (`cloudscape animate` does this); camera, sun and
//! wind need none. `GifPreview` (cargo feature `gif`) turns the frames into an animated GIF.

mod camera;
#[cfg(feature = "gif")]
mod preview;
mod spline;
mod sun;

pub use camera::{Aim, CameraPose, camera_at, unwrap_yaw_deg};
#[cfg(feature = "gif")]
pub use preview::{GifPreview, PreviewError, preview_size};
pub use spline::{SplineValue, catmull_rom, velocity_at_key};
pub use sun::sun_at;

use crate::scene::{Animation, CoverageKey, Scene};

/// The still of `scene` at scene time `time_s`: its camera, sun and layer coverage where the
/// animation's paths put them at that time, and `render.time_s = time_s` (which places the
/// wind-blown clouds). The still has no animation of its own, so evaluating it again changes only
/// `render.time_s`.
pub fn scene_at(scene: &Scene, time_s: f32) -> Scene {
    let animation = &scene.animation;
    let mut still = Scene {
        animation: Animation::default(),
        ..scene.clone()
    };
    still.render.time_s = time_s;
    if let Some(pose) = camera_at(&animation.camera_path, time_s) {
        pose.apply_to(&mut still.camera);
    }
    if let Some(sun) = sun_at(
        &animation.time_of_day,
        scene.sun.time_of_day.as_ref(),
        time_s,
    ) {
        sun.apply_to(&mut still.sun);
    }
    if let Some(scale) = coverage_scale_at(&animation.coverage_scale, time_s) {
        for layer in &mut still.layers {
            layer.coverage = (layer.coverage * scale).clamp(0.0, 1.0);
        }
    }
    still
}

/// The coverage factor at `time_s` on `path` (a [`catmull_rom`] spline of the keyframes' `scale`,
/// clamped at 0 where it overshoots); `None` for an empty path.
pub fn coverage_scale_at(path: &[CoverageKey], time_s: f32) -> Option<f32> {
    let keys: Vec<(f32, f32)> = path.iter().map(|k| (k.time_s, k.scale)).collect();
    catmull_rom(&keys, time_s).map(|scale| scale.max(0.0))
}

/// The scene time the paths span, seconds: from the earliest first keyframe to the latest last
/// keyframe of any path; `None` for a static scene.
pub fn time_range_s(animation: &Animation) -> Option<(f32, f32)> {
    let camera = animation.camera_path.iter().map(|k| k.time_s);
    let sun = animation.time_of_day.iter().map(|k| k.time_s);
    let coverage = animation.coverage_scale.iter().map(|k| k.time_s);
    camera.chain(sun).chain(coverage).fold(None, |range, t| {
        let (start, end) = range.unwrap_or((t, t));
        Some((start.min(t), end.max(t)))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{CameraKey, SunKey};

    fn animated() -> Scene {
        let camera = |time_s, x| CameraKey {
            time_s,
            position_m: [x, 500.0, 0.0],
            look_at_m: None,
            yaw_deg: 90.0,
            pitch_deg: 5.0,
        };
        let sun = |time_s, sun_elevation_deg| SunKey::at_angles(time_s, sun_elevation_deg, 180.0);
        let mut scene = Scene::default();
        scene.camera.look_at_m = Some([0.0, 2000.0, -5000.0]);
        scene.animation = Animation {
            camera_path: vec![camera(1.0, 0.0), camera(3.0, 200.0)],
            time_of_day: vec![sun(0.0, 10.0), sun(8.0, 30.0)],
            coverage_scale: vec![
                CoverageKey {
                    time_s: 2.0,
                    scale: 1.0,
                },
                CoverageKey {
                    time_s: 4.0,
                    scale: 4.0,
                },
            ],
        };
        scene
    }

    #[test]
    fn a_static_scene_changes_only_its_time() {
        let scene = Scene::default();
        let still = scene_at(&scene, 42.0);
        assert_eq!(still.render.time_s, 42.0);
        assert_eq!(
            Scene {
                render: scene.render.clone(),
                ..still
            },
            scene
        );
    }

    #[test]
    fn the_still_takes_camera_sun_and_coverage_from_the_paths() {
        let scene = animated();
        let still = scene_at(&scene, 2.0);
        let position = glam::Vec3::from_array(still.camera.position_m);
        assert!(
            position.abs_diff_eq(glam::Vec3::new(100.0, 500.0, 0.0), 1e-3),
            "{position}"
        );
        assert_eq!(
            still.camera.look_at_m, None,
            "the path aims by yaw and pitch"
        );
        assert!((still.camera.yaw_deg - 90.0).abs() < 1e-4);
        assert!(
            (still.sun.elevation_deg - 15.0).abs() < 0.5,
            "{}",
            still.sun.elevation_deg
        );
        assert_eq!(still.layers[0].coverage, scene.layers[0].coverage);
        assert_eq!(still.camera.fov_y_deg, scene.camera.fov_y_deg);
        assert_eq!(
            scene_at(&scene, 4.0).layers[0].coverage,
            1.0,
            "0.45 x 4 clamps to 1"
        );
    }

    #[test]
    fn the_still_is_static_so_evaluating_it_again_changes_nothing_else() {
        let still = scene_at(&animated(), 3.0);
        assert!(still.animation.is_static());
        assert_eq!(scene_at(&still, 3.0), still);
    }

    #[test]
    fn time_range_spans_every_path() {
        assert_eq!(time_range_s(&animated().animation), Some((0.0, 8.0)));
        assert_eq!(time_range_s(&Animation::default()), None);
    }

    #[test]
    fn coverage_scale_never_goes_negative() {
        let path = [
            CoverageKey {
                time_s: 0.0,
                scale: 1.0,
            },
            CoverageKey {
                time_s: 1.0,
                scale: 0.0,
            },
            CoverageKey {
                time_s: 1.2,
                scale: 0.0,
            },
            CoverageKey {
                time_s: 5.0,
                scale: 2.0,
            },
        ];
        let lowest = (0..50).filter_map(|i| coverage_scale_at(&path, i as f32 * 0.1));
        assert_eq!(lowest.fold(f32::MAX, f32::min), 0.0);
    }
}
