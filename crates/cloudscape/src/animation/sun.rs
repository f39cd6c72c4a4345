//! The sun along its keyframed path on the sky.

use glam::Vec3;

use super::spline::catmull_rom;
use crate::frame::direction_from_angles_deg;
use crate::scene::{Sun, SunKey};

/// The sun's place on the sky.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunAngles {
    /// Elevation above the horizon, degrees, -90..90.
    pub elevation_deg: f32,
    /// Azimuth, degrees clockwise from north, 0..360.
    pub azimuth_deg: f32,
}

impl SunAngles {
    /// Sets `sun`'s elevation and azimuth to these (its irradiance and colour are left as they are).
    pub fn apply_to(&self, sun: &mut Sun) {
        sun.elevation_deg = self.elevation_deg;
        sun.azimuth_deg = self.azimuth_deg;
    }
}

/// The sun at `time_s` on `path` (keyframe times strictly increasing); `None` for an empty path.
///
/// The keyframes' unit directions follow a [`catmull_rom`] spline, projected back onto the sphere
/// by normalising: a smooth path on the sky (C1 wherever the spline is not zero, which neighbours
/// less than 90 degrees apart ensure), taking the short way between keyframes and with no
/// singularity at the zenith, unlike splining the two angles.
pub fn sun_at(path: &[SunKey], time_s: f32) -> Option<SunAngles> {
    let keys: Vec<(f32, Vec3)> = path
        .iter()
        .map(|k| {
            let direction = direction_from_angles_deg(k.sun_elevation_deg, k.sun_azimuth_deg);
            (k.time_s, direction)
        })
        .collect();
    let direction = catmull_rom(&keys, time_s)?.normalize_or(keys[0].1);
    Some(angles_of(direction))
}

/// Elevation and azimuth of the unit vector `direction`; the inverse of
/// [`direction_from_angles_deg`] (azimuth 0 straight up or down).
fn angles_of(direction: Vec3) -> SunAngles {
    SunAngles {
        elevation_deg: direction.y.clamp(-1.0, 1.0).asin().to_degrees(),
        azimuth_deg: direction
            .x
            .atan2(-direction.z)
            .to_degrees()
            .rem_euclid(360.0),
    }
}

#[cfg(test)]
mod tests {
    use super::super::spline::tests::one_sided_velocities;
    use super::*;

    fn key(time_s: f32, sun_elevation_deg: f32, sun_azimuth_deg: f32) -> SunKey {
        SunKey {
            time_s,
            sun_elevation_deg,
            sun_azimuth_deg,
        }
    }

    fn direction_at(path: &[SunKey], time_s: f32) -> Vec3 {
        let angles = sun_at(path, time_s).unwrap();
        direction_from_angles_deg(angles.elevation_deg, angles.azimuth_deg)
    }

    fn path() -> [SunKey; 4] {
        [
            key(0.0, 5.0, 100.0),
            key(3.0, 40.0, 150.0),
            key(4.0, 60.0, 190.0),
            key(10.0, 20.0, 250.0),
        ]
    }

    #[test]
    fn passes_through_keys_and_holds_outside_them() {
        let path = path();
        for k in &path {
            let angles = sun_at(&path, k.time_s).unwrap();
            assert!(
                (angles.elevation_deg - k.sun_elevation_deg).abs() < 1e-3,
                "{angles:?}"
            );
            assert!(
                (angles.azimuth_deg - k.sun_azimuth_deg).abs() < 1e-3,
                "{angles:?}"
            );
        }
        assert_eq!(sun_at(&path, -3.0), sun_at(&path, 0.0));
        assert_eq!(sun_at(&path, 30.0), sun_at(&path, 10.0));
        assert_eq!(sun_at(&[], 1.0), None);
    }

    #[test]
    fn the_direction_moves_smoothly_across_keys() {
        let path = path();
        for k in &path[1..3] {
            let (left, right) = one_sided_velocities(|t| direction_at(&path, t), k.time_s);
            assert!(
                left.abs_diff_eq(right, 2e-3),
                "{}: {left} vs {right}",
                k.time_s
            );
            assert!(left.length() > 0.05, "the sun stands still at {}", k.time_s);
        }
    }

    #[test]
    fn azimuth_takes_the_short_way_through_north() {
        let path = [key(0.0, 10.0, 340.0), key(2.0, 10.0, 20.0)];
        for step in 0..=20 {
            let azimuth = sun_at(&path, step as f32 * 0.1).unwrap().azimuth_deg;
            assert!(
                azimuth >= 339.99 || azimuth <= 20.01,
                "step {step}: {azimuth}"
            );
        }
    }
}
