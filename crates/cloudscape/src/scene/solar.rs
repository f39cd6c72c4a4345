//! Directions on the sky: the scene's elevation and azimuth as a vector, and the sun's place from
//! local solar time, latitude and day of the year.

use std::f32::consts::TAU;

use glam::Vec3;

use super::{Sun, SunKey, TimeOfDay};

/// Unit vector toward elevation `el` and azimuth `az` (degrees; azimuth clockwise from north, with
/// x east, y up, z south): `(sin az cos el, sin el, -cos az cos el)`.
pub fn direction_from_angles_deg(elevation_deg: f32, azimuth_deg: f32) -> Vec3 {
    let (el, az) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
    Vec3::new(az.sin() * el.cos(), el.sin(), -az.cos() * el.cos())
}

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

/// Solar declination in radians on `day_of_year` (1 = 1 January), by Spencer's Fourier series
/// (J. W. Spencer 1971, "Fourier series representation of the position of the sun", Search 2(5),
/// p. 172; error below 0.0006 rad): with the day angle `g = 2 pi (n - 1) / 365`,
/// `0.006918 - 0.399912 cos g + 0.070257 sin g - 0.006758 cos 2g + 0.000907 sin 2g
/// - 0.002697 cos 3g + 0.00148 sin 3g`.
pub fn declination_rad(day_of_year: u32) -> f32 {
    let g = TAU * (day_of_year as f32 - 1.0) / 365.0;
    0.006918 - 0.399912 * g.cos() + 0.070257 * g.sin() - 0.006758 * (2.0 * g).cos()
        + 0.000907 * (2.0 * g).sin()
        - 0.002697 * (3.0 * g).cos()
        + 0.00148 * (3.0 * g).sin()
}

/// Unit vector toward the sun (x east, y up, z south) at `time`: the hour angle is 15 degrees per
/// hour from solar noon, `w = 15 (t - 12)` deg (negative in the morning), and with latitude `phi`
/// and declination `d` ([`declination_rad`]) the standard spherical-astronomy relations give
/// east `-cos d sin w`, north `sin d cos phi - cos d sin phi cos w` and up
/// `sin d sin phi + cos d cos phi cos w` (e.g. Iqbal 1983, *An Introduction to Solar Radiation*,
/// chapter 1). Local solar time is used directly, so no equation of time is needed.
pub fn solar_direction(time: &TimeOfDay) -> Vec3 {
    let w = (15.0 * (time.solar_time_h - 12.0)).to_radians();
    let phi = time.latitude_deg.to_radians();
    let d = declination_rad(time.day_of_year);
    let east = -d.cos() * w.sin();
    let north = d.sin() * phi.cos() - d.cos() * phi.sin() * w.cos();
    let up = d.sin() * phi.sin() + d.cos() * phi.cos() * w.cos();
    Vec3::new(east, up, -north).normalize()
}

/// The sun's elevation and azimuth (clockwise from north) at `time` ([`solar_direction`]).
pub fn solar_position(time: &TimeOfDay) -> SunAngles {
    angles_of(solar_direction(time))
}

/// The direction toward the sun a keyframe gives: its angles, or its solar time on the latitude
/// and day of `day`; `None` when it has neither (or solar time but no `day`).
pub fn key_direction(key: &SunKey, day: Option<&TimeOfDay>) -> Option<Vec3> {
    if let (Some(elevation_deg), Some(azimuth_deg)) = (key.sun_elevation_deg, key.sun_azimuth_deg) {
        return Some(direction_from_angles_deg(elevation_deg, azimuth_deg));
    }
    let time = TimeOfDay {
        solar_time_h: key.solar_time_h?,
        ..day?.clone()
    };
    Some(solar_direction(&time))
}

/// Elevation and azimuth of the unit vector `direction`; the inverse of
/// [`direction_from_angles_deg`] (azimuth 0 straight up or down).
pub(crate) fn angles_of(direction: Vec3) -> SunAngles {
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
    use super::*;

    /// The March equinox (declination about 0).
    const EQUINOX_DAY: u32 = 80;
    /// The June solstice (declination about 23.44 deg).
    const SOLSTICE_DAY: u32 = 172;

    fn at(solar_time_h: f32, latitude_deg: f32, day_of_year: u32) -> SunAngles {
        solar_position(&TimeOfDay {
            solar_time_h,
            latitude_deg,
            day_of_year,
        })
    }

    #[test]
    fn angles_follow_the_compass() {
        assert!(
            direction_from_angles_deg(0.0, 0.0).abs_diff_eq(Vec3::NEG_Z, 1e-6),
            "north is -z"
        );
        assert!(
            direction_from_angles_deg(0.0, 90.0).abs_diff_eq(Vec3::X, 1e-6),
            "east is +x"
        );
        assert!(direction_from_angles_deg(90.0, 0.0).abs_diff_eq(Vec3::Y, 1e-6));
    }

    #[test]
    fn declination_spans_the_tropics() {
        assert!(declination_rad(EQUINOX_DAY).to_degrees().abs() < 0.5);
        assert!((declination_rad(SOLSTICE_DAY).to_degrees() - 23.44).abs() < 0.1);
        assert!((declination_rad(355).to_degrees() + 23.44).abs() < 0.1);
    }

    #[test]
    fn equinox_noon_stands_at_90_minus_latitude_in_the_south() {
        for latitude_deg in [10.0, 35.0, 51.5, 70.0] {
            let sun = at(12.0, latitude_deg, EQUINOX_DAY);
            assert!(
                (sun.elevation_deg - (90.0 - latitude_deg)).abs() < 0.5,
                "{sun:?}"
            );
            assert!((sun.azimuth_deg - 180.0).abs() < 1e-3, "{sun:?}");
        }
        let south = at(12.0, -30.0, EQUINOX_DAY);
        assert!(
            south.azimuth_deg < 1e-3 || south.azimuth_deg > 360.0 - 1e-3,
            "{south:?}"
        );
    }

    #[test]
    fn equinox_six_rises_in_the_east_and_eighteen_sets_in_the_west() {
        let dawn = at(6.0, 45.0, EQUINOX_DAY);
        assert!(dawn.elevation_deg.abs() < 0.5, "{dawn:?}");
        assert!((dawn.azimuth_deg - 90.0).abs() < 0.5, "{dawn:?}");
        let dusk = at(18.0, 45.0, EQUINOX_DAY);
        assert!((dusk.azimuth_deg - 270.0).abs() < 0.5, "{dusk:?}");
    }

    #[test]
    fn midsummer_noon_in_london_is_about_62_degrees_up() {
        let sun = at(12.0, 51.5, SOLSTICE_DAY);
        assert!((sun.elevation_deg - 61.94).abs() < 0.2, "{sun:?}");
    }

    #[test]
    fn midnight_is_below_the_horizon() {
        assert!(at(0.0, 51.5, SOLSTICE_DAY).elevation_deg < -10.0);
        assert!(at(0.0, 0.0, EQUINOX_DAY).elevation_deg < -80.0);
    }

    #[test]
    fn azimuth_turns_steadily_east_to_west_through_the_day() {
        let mut previous = at(4.0, 51.5, SOLSTICE_DAY);
        for step in 1..=64 {
            let sun = at(4.0 + step as f32 * 0.25, 51.5, SOLSTICE_DAY);
            let turn = sun.azimuth_deg - previous.azimuth_deg;
            assert!(
                turn > 0.0 && turn < 10.0,
                "step {step}: {previous:?} -> {sun:?}"
            );
            previous = sun;
        }
    }
}
