//! Which part of the picture each pixel shows: cloud, clear sky, ground or the sun's
//! neighbourhood, so that an error against the path tracer can be told apart by where it sits
//! (`../shared/references/realism-diagnosis.md` split the ray marcher's error this way).
//!
//! Within [`SUN_NEIGHBOURHOOD_DEG`] of the sun a pixel is the sun's (the disc and its glow, where
//! a pixel's footprint decides most of the error). Else it is cloud where at least
//! [`CLOUD_PATH_SHARE`] of the path tracer's camera paths through it met cloud before leaving the
//! scene or reaching the ground (the mask the path tracer records in its image's alpha,
//! [`crate::integrator::CameraSample::met_cloud`]); else ground where the ray through its centre
//! reaches the ground; else clear sky.

use crate::geometry::ground_distance;
use cloudscape::field::PlanetGeometry;
use cloudscape::frame::Frame;
use glam::Vec2;

/// Angular radius of the sun's neighbourhood, degrees.
pub const SUN_NEIGHBOURHOOD_DEG: f32 = 2.5;

/// Share of a pixel's camera paths that met cloud from which the pixel shows cloud: 5 %, which a
/// ray of optical depth 0.05 through cloud gives (`1 - e^-0.05`).
pub const CLOUD_PATH_SHARE: f32 = 0.05;

/// What a pixel shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Region {
    /// The ray meets cloud.
    Cloud,
    /// The ray leaves through clear sky.
    ClearSky,
    /// The ray reaches the ground through clear air.
    Ground,
    /// Within [`SUN_NEIGHBOURHOOD_DEG`] of the sun.
    Sun,
}

impl Region {
    /// Every region, in table order.
    pub const ALL: [Region; 4] = [Region::Cloud, Region::ClearSky, Region::Ground, Region::Sun];

    /// The region's name in tables.
    pub fn name(self) -> &'static str {
        match self {
            Region::Cloud => "cloud",
            Region::ClearSky => "clear sky",
            Region::Ground => "ground",
            Region::Sun => "sun",
        }
    }
}

/// The region of every pixel of `frame` (row by row), given the share of each pixel's camera
/// paths that met cloud (`cloud_share`, the alpha of the path tracer's image) over `planet`;
/// `has_ground`: whether the scene has a ground.
pub fn classify(
    frame: &Frame,
    (planet, has_ground): (&PlanetGeometry, bool),
    cloud_share: &[f32],
) -> Vec<Region> {
    let width = frame.size.x as usize;
    let cos_sun = SUN_NEIGHBOURHOOD_DEG.to_radians().cos();
    cloud_share
        .iter()
        .enumerate()
        .map(|(i, &share)| {
            let pixel = Vec2::new((i % width) as f32, (i / width) as f32) + 0.5;
            let (origin, dir) = frame.camera_ray(pixel);
            if dir.dot(frame.sun.direction) >= cos_sun {
                Region::Sun
            } else if share >= CLOUD_PATH_SHARE {
                Region::Cloud
            } else if has_ground && ground_distance(planet, origin, dir) <= frame.far_m {
                Region::Ground
            } else {
                Region::ClearSky
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use cloudscape::scene::Scene;
    use glam::UVec2;

    #[test]
    fn regions_follow_the_sun_the_mask_and_the_ground() {
        let mut scene = Scene::default();
        scene.camera.look_at_m = None;
        scene.camera.pitch_deg = 0.0;
        scene.camera.fov_y_deg = 40.0;
        let mut frame = Frame::from_scene(&scene, UVec2::new(64, 36));
        let (_, centre) = frame.camera_ray(Vec2::new(32.0, 18.0));
        frame.sun.direction = centre;
        let planet = PlanetGeometry::from_scene(&scene.planet);
        // Cloud in the left half of the upper rows.
        let share: Vec<f32> = (0..64 * 36)
            .map(|i| if i % 64 < 32 && i / 64 < 9 { 0.5 } else { 0.01 })
            .collect();
        let regions = classify(&frame, (&planet, true), &share);
        let at = |x: usize, y: usize| regions[y * 64 + x];
        assert_eq!(at(32, 18), Region::Sun, "the sun is at the centre");
        assert_eq!(at(2, 2), Region::Cloud);
        assert_eq!(at(60, 2), Region::ClearSky, "above the horizon, no cloud");
        assert_eq!(at(60, 34), Region::Ground, "below the horizon");
        let no_ground = classify(&frame, (&planet, false), &share);
        assert_eq!(no_ground[34 * 64 + 60], Region::ClearSky);
    }
}
