//! The camera along its keyframed path: position, and orientation by look-at targets or by yaw
//! and pitch turning the short way round.

use glam::Vec3;

use super::spline::catmull_rom;
use crate::scene::{Camera, CameraKey};

/// Where the camera looks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Aim {
    /// At a point, metres.
    LookAt(Vec3),
    /// Along a direction by azimuth (degrees clockwise from north, 0..360) and elevation (degrees,
    /// -90..90).
    Angles {
        /// Azimuth, degrees clockwise from north, 0..360.
        yaw_deg: f32,
        /// Elevation above the horizon, degrees, -90..90.
        pitch_deg: f32,
    },
}

/// The camera's position and aim at one time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraPose {
    /// Eye position, metres.
    pub position_m: Vec3,
    /// Where it looks.
    pub aim: Aim,
}

impl CameraPose {
    /// Sets `camera`'s position and view direction to this pose (its lens is left as it is).
    pub fn apply_to(&self, camera: &mut Camera) {
        camera.position_m = self.position_m.to_array();
        match self.aim {
            Aim::LookAt(target) => camera.look_at_m = Some(target.to_array()),
            Aim::Angles { yaw_deg, pitch_deg } => {
                camera.look_at_m = None;
                camera.yaw_deg = yaw_deg;
                camera.pitch_deg = pitch_deg;
            }
        }
    }
}

/// The pose at `time_s` on `path` (keyframe times strictly increasing); `None` for an empty path.
///
/// Positions follow a [`catmull_rom`] spline. When every keyframe has `look_at_m`, the targets
/// follow their own spline; otherwise yaw and pitch do, yaw unwrapped by [`unwrap_yaw_deg`] so that
/// the camera turns the short way round, and pitch clamped to -90..90 where the spline overshoots.
pub fn camera_at(path: &[CameraKey], time_s: f32) -> Option<CameraPose> {
    let keys = |value: fn(&CameraKey) -> Vec3| -> Vec<(f32, Vec3)> {
        path.iter().map(|k| (k.time_s, value(k))).collect()
    };
    let position_m = catmull_rom(&keys(|k| Vec3::from_array(k.position_m)), time_s)?;
    let targets: Option<Vec<(f32, Vec3)>> = path
        .iter()
        .map(|k| k.look_at_m.map(|t| (k.time_s, Vec3::from_array(t))))
        .collect();
    let aim = match targets {
        Some(targets) => Aim::LookAt(catmull_rom(&targets, time_s)?),
        None => angles_at(path, time_s)?,
    };
    Some(CameraPose { position_m, aim })
}

/// Yaw and pitch at `time_s`, yaw turning the short way between keyframes.
fn angles_at(path: &[CameraKey], time_s: f32) -> Option<Aim> {
    let yaws = unwrap_yaw_deg(&path.iter().map(|k| k.yaw_deg).collect::<Vec<_>>());
    let times = path.iter().map(|k| k.time_s);
    let yaw_keys: Vec<(f32, f32)> = times.clone().zip(yaws).collect();
    let pitch_keys: Vec<(f32, f32)> = times.zip(path.iter().map(|k| k.pitch_deg)).collect();
    Some(Aim::Angles {
        yaw_deg: catmull_rom(&yaw_keys, time_s)?.rem_euclid(360.0),
        pitch_deg: catmull_rom(&pitch_keys, time_s)?.clamp(-90.0, 90.0),
    })
}

/// Yaws (degrees) rewritten so that each differs from the one before by the shortest turn, in
/// -180..180 (a half turn goes anticlockwise): `[350, 10, 200]` becomes `[350, 370, 200]`.
/// Splining the result turns the short way round and keeps the angles continuous.
pub fn unwrap_yaw_deg(yaws_deg: &[f32]) -> Vec<f32> {
    let mut unwrapped = Vec::with_capacity(yaws_deg.len());
    for (index, &yaw) in yaws_deg.iter().enumerate() {
        let value = match index.checked_sub(1) {
            None => yaw,
            Some(previous) => {
                let turn = (yaw - yaws_deg[previous] + 180.0).rem_euclid(360.0) - 180.0;
                unwrapped[previous] + turn
            }
        };
        unwrapped.push(value);
    }
    unwrapped
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(time_s: f32, x: f32, yaw_deg: f32, pitch_deg: f32) -> CameraKey {
        CameraKey {
            time_s,
            position_m: [x, 100.0, 0.0],
            look_at_m: None,
            yaw_deg,
            pitch_deg,
        }
    }

    fn angles(path: &[CameraKey], time_s: f32) -> (f32, f32) {
        match camera_at(path, time_s).unwrap().aim {
            Aim::Angles { yaw_deg, pitch_deg } => (yaw_deg, pitch_deg),
            aim => panic!("expected angles, got {aim:?}"),
        }
    }

    #[test]
    fn unwrapping_takes_the_short_way_round() {
        assert_eq!(unwrap_yaw_deg(&[350.0, 10.0, 200.0]), [350.0, 370.0, 200.0]);
        assert_eq!(unwrap_yaw_deg(&[10.0, -350.0, 720.0]), [10.0, 10.0, 0.0]);
        assert_eq!(unwrap_yaw_deg(&[]), Vec::<f32>::new());
    }

    #[test]
    fn yaw_turns_through_north_from_350_to_10() {
        let path = [key(0.0, 0.0, 350.0, 0.0), key(4.0, 10.0, 10.0, 0.0)];
        for step in 0..=40 {
            let (yaw, _) = angles(&path, step as f32 * 0.1);
            assert!(yaw >= 349.99 || yaw <= 10.01, "step {step}: yaw {yaw}");
        }
        let (middle, _) = angles(&path, 2.0);
        assert!(middle.min(360.0 - middle) < 1e-3, "{middle}");
    }

    #[test]
    fn passes_through_keys_and_holds_outside_them() {
        let path = [
            key(0.0, 0.0, 40.0, 10.0),
            key(2.0, 50.0, 300.0, -20.0),
            key(5.0, 80.0, 200.0, 30.0),
        ];
        for k in &path {
            let pose = camera_at(&path, k.time_s).unwrap();
            assert!(
                pose.position_m
                    .abs_diff_eq(Vec3::from_array(k.position_m), 1e-4)
            );
            let (yaw, pitch) = angles(&path, k.time_s);
            assert!((yaw - k.yaw_deg).abs() < 1e-3 && (pitch - k.pitch_deg).abs() < 1e-3);
        }
        assert_eq!(angles(&path, -1.0), (40.0, 10.0));
        assert_eq!(angles(&path, 9.0), (200.0, 30.0));
        assert_eq!(camera_at(&[], 0.0), None);
    }

    #[test]
    fn pitch_overshoot_is_clamped_to_straight_up() {
        let path = [
            key(0.0, 0.0, 0.0, 0.0),
            key(1.0, 0.0, 0.0, 89.0),
            key(1.1, 0.0, 0.0, 90.0),
            key(5.0, 0.0, 0.0, -10.0),
        ];
        let highest = (0..=50).map(|i| angles(&path, i as f32 * 0.1).1);
        assert!(highest.fold(f32::MIN, f32::max) <= 90.0);
    }

    #[test]
    fn look_at_targets_follow_their_own_spline() {
        let mut path = [key(0.0, 0.0, 0.0, 0.0), key(2.0, 100.0, 0.0, 0.0)];
        path[0].look_at_m = Some([0.0, 2000.0, -5000.0]);
        path[1].look_at_m = Some([1000.0, 2000.0, -5000.0]);
        let pose = camera_at(&path, 1.0).unwrap();
        assert!(
            pose.position_m
                .abs_diff_eq(Vec3::new(50.0, 100.0, 0.0), 1e-3)
        );
        assert_eq!(pose.aim, Aim::LookAt(Vec3::new(500.0, 2000.0, -5000.0)));
        let mut camera = Camera::default();
        pose.apply_to(&mut camera);
        assert_eq!(camera.look_at_m, Some([500.0, 2000.0, -5000.0]));
        assert_eq!(camera.position_m, [50.0, 100.0, 0.0]);
    }
}
