//! The sun along its keyframed path on the sky.

use glam::Vec3;

use super::spline::catmull_rom;
use crate::scene::{SunAngles, SunKey, TimeOfDay, angles_of, key_direction, solar_direction};

/// Largest step of solar time between the samples that trace the sun's course between two
/// solar-time keyframes, hours (3.75 degrees of hour angle).
const SOLAR_SAMPLE_STEP_H: f32 = 0.25;

/// The sun at `time_s` on `path` (keyframe times strictly increasing); `None` for an empty path.
/// Keyframes given by solar time are placed by [`crate::scene::solar_position`] on the latitude
/// and day of `day` (a keyframe that cannot be placed, by solar time without `day`, is skipped;
/// validation rejects it).
///
/// The keyframes' unit directions follow a [`catmull_rom`] spline, projected back onto the sphere
/// by normalising: a smooth path on the sky (C1 wherever the spline is not zero, which neighbours
/// less than 90 degrees apart ensure), taking the short way between keyframes and with no
/// singularity at the zenith, unlike splining the two angles. Between two solar-time keyframes,
/// the path runs through samples of the sun's true course at most [`SOLAR_SAMPLE_STEP_H`] apart,
/// solar time passing at a steady rate from one keyframe to the next.
pub fn sun_at(path: &[SunKey], day: Option<&TimeOfDay>, time_s: f32) -> Option<SunAngles> {
    let keys = traced_path(path, day);
    let direction = catmull_rom(&keys, time_s)?.normalize_or(keys[0].1);
    Some(angles_of(direction))
}

/// `(time_s, direction)` of every keyframe, with samples of the sun's course between consecutive
/// solar-time keyframes.
fn traced_path(path: &[SunKey], day: Option<&TimeOfDay>) -> Vec<(f32, Vec3)> {
    let mut traced = Vec::with_capacity(path.len());
    for (index, key) in path.iter().enumerate() {
        let previous = index.checked_sub(1).map(|i| &path[i]);
        let hours = previous.and_then(|p| p.solar_time_h).zip(key.solar_time_h);
        if let (Some(previous), Some((from_h, to_h)), Some(day)) = (previous, hours, day) {
            let samples = ((to_h - from_h).abs() / SOLAR_SAMPLE_STEP_H).ceil() as usize;
            for sample in 1..samples {
                let t = sample as f32 / samples as f32;
                let time = TimeOfDay {
                    solar_time_h: from_h + (to_h - from_h) * t,
                    ..day.clone()
                };
                let time_s = previous.time_s + (key.time_s - previous.time_s) * t;
                traced.push((time_s, solar_direction(&time)));
            }
        }
        if let Some(direction) = key_direction(key, day) {
            traced.push((key.time_s, direction));
        }
    }
    traced
}

#[cfg(test)]
mod tests {
    use super::super::spline::tests::one_sided_velocities;
    use super::*;
    use crate::scene::direction_from_angles_deg;

    fn key(time_s: f32, sun_elevation_deg: f32, sun_azimuth_deg: f32) -> SunKey {
        SunKey::at_angles(time_s, sun_elevation_deg, sun_azimuth_deg)
    }

    fn direction_at(path: &[SunKey], time_s: f32) -> Vec3 {
        let angles = sun_at(path, None, time_s).unwrap();
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
            let angles = sun_at(&path, None, k.time_s).unwrap();
            assert!(
                (angles.elevation_deg - k.sun_elevation_deg.unwrap()).abs() < 1e-3,
                "{angles:?}"
            );
            assert!(
                (angles.azimuth_deg - k.sun_azimuth_deg.unwrap()).abs() < 1e-3,
                "{angles:?}"
            );
        }
        assert_eq!(sun_at(&path, None, -3.0), sun_at(&path, None, 0.0));
        assert_eq!(sun_at(&path, None, 30.0), sun_at(&path, None, 10.0));
        assert_eq!(sun_at(&[], None, 1.0), None);
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
            let azimuth = sun_at(&path, None, step as f32 * 0.1).unwrap().azimuth_deg;
            assert!(
                azimuth >= 339.99 || azimuth <= 20.01,
                "step {step}: {azimuth}"
            );
        }
    }

    #[test]
    fn a_solar_time_path_follows_the_suns_true_course() {
        let day = TimeOfDay {
            solar_time_h: 12.0,
            latitude_deg: 45.0,
            day_of_year: 172,
        };
        let path = [
            SunKey::at_solar_time(0.0, 6.0),
            SunKey::at_solar_time(12.0, 18.0),
        ];
        for step in 0..=24 {
            let time_s = step as f32 * 0.5;
            let angles = sun_at(&path, Some(&day), time_s).unwrap();
            let truth = crate::scene::solar_position(&TimeOfDay {
                solar_time_h: 6.0 + time_s,
                ..day.clone()
            });
            assert!(
                (angles.elevation_deg - truth.elevation_deg).abs() < 0.3
                    && (angles.azimuth_deg - truth.azimuth_deg).abs() < 0.5,
                "{time_s} s: {angles:?} vs {truth:?}"
            );
        }
        assert_eq!(sun_at(&path, None, 3.0), None, "solar keys need the day");
    }
}
