//! Which part of the picture each pixel shows: cloud, clear sky, ground or the sun's
//! neighbourhood, so that an error against the path tracer can be told apart by where it sits
//! (`../shared/references/realism-diagnosis.md` split the ray marcher's error this way).
//!
//! A pixel is classified by the ray through its centre, as the camera path of the path tracer
//! leaves it: within [`SUN_NEIGHBOURHOOD_DEG`] of the sun it is the sun's (the disc and its glow,
//! where a pixel's footprint decides most of the error); else cloud where the ray meets an optical
//! depth of at least [`CLOUD_OPTICAL_DEPTH`] before it reaches the ground or the far distance;
//! else ground where it reaches the ground; else clear sky.

use crate::cloud_medium::volume_box;
use crate::geometry::{Interval, band_intervals, ground_distance};
use cloudscape::field::CloudField;
use cloudscape::frame::Frame;
use glam::{UVec2, Vec2, Vec3};
use rayon::prelude::*;

/// Angular radius of the sun's neighbourhood, degrees.
pub const SUN_NEIGHBOURHOOD_DEG: f32 = 2.5;

/// Optical depth along a pixel's ray from which the pixel shows cloud: 5 % of the light behind
/// is scattered or absorbed.
pub const CLOUD_OPTICAL_DEPTH: f32 = 0.05;

/// Samples of the field along each stretch of a ray through cloud.
const STEPS_PER_STRETCH: u32 = 256;

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

/// The region of every pixel of `frame` (row by row) over `field`; `has_ground`: whether the
/// scene has a ground.
pub fn classify(field: &CloudField, frame: &Frame, has_ground: bool) -> Vec<Region> {
    let size: UVec2 = frame.size;
    let cos_sun = SUN_NEIGHBOURHOOD_DEG.to_radians().cos();
    (0..size.x * size.y)
        .into_par_iter()
        .map(|i| {
            let pixel = Vec2::new((i % size.x) as f32, (i / size.x) as f32) + 0.5;
            let (origin, dir) = frame.camera_ray(pixel);
            if dir.dot(frame.sun.direction) >= cos_sun {
                return Region::Sun;
            }
            let ground_m = if has_ground {
                ground_distance(&field.planet, origin, dir)
            } else {
                f32::INFINITY
            };
            let end_m = ground_m.min(frame.far_m);
            if optical_depth_reaches(field, frame.time_s, (origin, dir), end_m) {
                Region::Cloud
            } else if ground_m.is_finite() {
                Region::Ground
            } else {
                Region::ClearSky
            }
        })
        .collect()
}

/// Whether the optical depth along `origin + t dir`, `t` in `[0, end_m]`, reaches
/// [`CLOUD_OPTICAL_DEPTH`]: midpoint samples over the stretches within the layers' altitudes and
/// within each voxel grid's box.
fn optical_depth_reaches(
    field: &CloudField,
    time_s: f32,
    (origin, dir): (Vec3, Vec3),
    end_m: f32,
) -> bool {
    let mut stretches: Vec<Interval> = Vec::new();
    if let Some(range) = field.altitude_range_m() {
        stretches.extend(
            band_intervals(&field.planet, origin, dir, range, (0.0, end_m))
                .into_iter()
                .flatten(),
        );
    }
    stretches.extend(
        field
            .volumes
            .iter()
            .filter_map(|v| volume_box(v).ray_interval(origin, dir)?.clip(0.0, end_m)),
    );
    let mut tau = 0.0;
    for stretch in stretches {
        let step = (stretch.end - stretch.start) / STEPS_PER_STRETCH as f32;
        for k in 0..STEPS_PER_STRETCH {
            let t = stretch.start + (k as f32 + 0.5) * step;
            tau += field.extinction_per_m(origin + dir * t, time_s) * step;
            if tau >= CLOUD_OPTICAL_DEPTH {
                return true;
            }
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use cloudscape::scene::Scene;
    use std::path::Path;

    #[test]
    fn a_view_under_a_deck_toward_the_sun_has_every_region() {
        let mut scene = Scene::default();
        scene.camera.look_at_m = None;
        scene.camera.pitch_deg = 5.0;
        let field = CloudField::new(&scene, Path::new(".")).expect("the default field");
        let mut frame = Frame::from_scene(&scene, UVec2::new(64, 36));
        let (_, centre) = frame.camera_ray(Vec2::new(32.0, 18.0));
        frame.sun.direction = centre;
        let regions = classify(&field, &frame, true);
        let count = |r| regions.iter().filter(|x| **x == r).count();
        assert!(count(Region::Sun) > 0, "the sun is at the centre");
        assert!(count(Region::Cloud) > 0, "the default layer shows cloud");
        assert!(count(Region::Ground) > 0 || count(Region::ClearSky) > 0);
        let no_clouds = {
            let mut clear = scene.clone();
            clear.layers.clear();
            CloudField::new(&clear, Path::new(".")).expect("a clear sky")
        };
        let clear = classify(&no_clouds, &frame, true);
        assert!(
            clear.iter().all(|r| *r != Region::Cloud),
            "no cloud, no cloud region"
        );
        assert_eq!(
            clear.iter().filter(|r| **r == Region::Sun).count(),
            count(Region::Sun),
            "the sun's neighbourhood is geometry alone"
        );
    }
}
