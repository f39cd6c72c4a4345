//! One frame's inputs, as a host has them each frame: the camera and its projection, the host's
//! depth convention, the sun, the clock and the exposure ([`Frame`]), derived from a scene
//! ([`Frame::from_scene`]) or built by a host renderer from its own camera, light and time. What
//! does not change from frame to frame (the ground's albedo, the droplets' phase function) is the
//! renderer's settings ([`FrameSettings`]), read from the scene when it is built or edited.
//! [`FrameGpu`] uploads both once per frame into the one uniform every pass reads at bind group
//! [`crate::shader::FRAME_GROUP`] (`frame.wgsl`). The sky and haze around the clouds are the
//! environment's ([`crate::environment`]).

mod depth;
mod gpu;

pub use depth::DepthConvention;
pub use gpu::{FRAME_WGSL, FrameGpu, FrameUniform};

use crate::optics::PhaseLobes;
use crate::output::SampleGrid;
use crate::scene::{Camera, Scene, Sun, direction_from_angles_deg};
use glam::{Mat4, UVec2, Vec2, Vec3};

/// Step of the R2 sequence that spreads samples over a pixel: `(1/g, 1/g^2)` for the plastic
/// number `g = 1.3247...`, the real root of `x^3 = x + 1` (Roberts 2018).
pub const FOOTPRINT_STEP: [f64; 2] = [0.754_877_666_246_692_7, 0.569_840_290_998_053_3];

/// Step of the ray offsets from one frame to the next: `1/phi` for the golden ratio `phi`, the R1
/// sequence, the most even additive recurrence in one dimension (Roberts 2018).
pub const FRAME_OFFSET_STEP: f64 = 0.618_033_988_749_894_9;

/// `value` rounded to a value an IEEE half float holds, up or down with the probabilities that keep
/// its expectation, by `u` uniform in [0, 1) (stochastic rounding: Forsythe 1959; Connolly, Higham
/// & Mary 2021): a running mean stored in half floats (the temporal history) then drifts neither
/// way by the rounding of its small updates. `frame_round_to_half` in `frame.wgsl` is the same.
pub fn round_to_half(value: f32, u: f32) -> f32 {
    /// Fraction bits of a half float.
    const HALF_FRACTION_BITS: i32 = 10;
    /// Exponent of a half float's smallest normal value.
    const HALF_MIN_EXPONENT: i32 = -14;
    let exponent = ((value.abs().to_bits() >> 23) & 0xff) as i32 - 127;
    let ulp = 2f32.powi(exponent.max(HALF_MIN_EXPONENT) - HALF_FRACTION_BITS);
    value.signum() * (value.abs() / ulp + u).floor() * ulp
}

/// Normalised device depth of the point `camera_ray` and `frame_ray_direction` unproject to find a
/// pixel's ray: between the near and far planes in every [`DepthConvention`].
const RAY_NDC_DEPTH: f32 = 0.5;

/// The sun as a host lights one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameSun {
    /// Unit vector toward the centre of the sun's disc (world space: x east, y up, z south).
    pub direction: Vec3,
    /// Irradiance on a surface facing the sun, linear RGB (in the scene's radiometric unit); above
    /// the air when the sky is the atmosphere, which reddens it on the way down.
    pub irradiance: Vec3,
    /// Angular radius of the disc, radians.
    pub angular_radius_rad: f32,
}

impl FrameSun {
    /// The sun a scene's `[sun]` table describes.
    pub fn from_scene(sun: &Sun) -> FrameSun {
        FrameSun {
            direction: direction_from_angles_deg(sun.elevation_deg, sun.azimuth_deg),
            irradiance: Vec3::from_array(sun.color) * sun.irradiance,
            angular_radius_rad: sun.angular_radius_deg.to_radians(),
        }
    }
}

/// What the frame uniform holds that does not change from frame to frame: read from the scene when
/// a renderer is built or edited.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameSettings {
    /// Lambertian ground albedo; None without a ground.
    pub ground_albedo: Option<Vec3>,
    /// Mean cosine `g` of the cloud droplets' phase function: how far diffuse light gets through
    /// clouds (their transport optical depth is `(1 - g) tau`).
    pub cloud_mean_cosine: f32,
}

impl FrameSettings {
    /// The settings a scene gives.
    pub fn from_scene(scene: &Scene) -> FrameSettings {
        FrameSettings {
            ground_albedo: scene
                .ground
                .enabled
                .then(|| Vec3::from_array(scene.ground.albedo)),
            cloud_mean_cosine: PhaseLobes::from_scene(&scene.phase).mean_cosine(),
        }
    }
}

/// One frame's inputs: what a host has each frame (camera, depth convention, sun, clock, exposure).
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Image size in pixels.
    pub size: UVec2,
    /// Camera position, metres.
    pub camera_position_m: Vec3,
    /// World-to-view transform.
    pub view_from_world: Mat4,
    /// View-to-clip projection (wgpu conventions: NDC y up, depth in 0..1 as `depth` says).
    pub clip_from_view: Mat4,
    /// What the host's depth buffer stores (standard, reversed-Z, reversed-Z with infinite far).
    pub depth: DepthConvention,
    /// Nothing beyond this distance is marched, metres.
    pub far_m: f32,
    /// The sun.
    pub sun: FrameSun,
    /// Scene time, seconds: the wind has carried the clouds `time_s` times its speed.
    pub time_s: f32,
    /// Exposure compensation of the tone-mapped image, stops.
    pub exposure_ev: f32,
    /// Frame counter that decorrelates the sampling jitter of successive frames.
    pub frame_index: u32,
}

impl Frame {
    /// The frame a scene describes (its camera, sun, time and exposure), at `size` pixels, with a
    /// standard depth buffer.
    pub fn from_scene(scene: &Scene, size: UVec2) -> Frame {
        Frame {
            time_s: scene.render.time_s,
            exposure_ev: scene.render.exposure_ev,
            ..Frame::of_camera(&scene.camera, size, FrameSun::from_scene(&scene.sun))
        }
    }

    /// The view through `camera` (its place, direction, field of view and planes) at `size`
    /// pixels, with a standard depth buffer, lit by `sun`; at time 0, exposure 0, frame 0.
    pub fn of_camera(camera: &Camera, size: UVec2, sun: FrameSun) -> Frame {
        let c = camera;
        let eye = Vec3::from_array(c.position_m);
        let forward = match c.look_at_m {
            Some(target) => (Vec3::from_array(target) - eye).normalize_or(Vec3::NEG_Z),
            None => direction_from_angles_deg(c.pitch_deg, c.yaw_deg),
        };
        let up = if forward.y.abs() > 0.999 {
            Vec3::NEG_Z
        } else {
            Vec3::Y
        };
        let aspect = size.x as f32 / size.y as f32;
        let depth = DepthConvention::Standard;
        Frame {
            size,
            camera_position_m: eye,
            view_from_world: glam::camera::rh::view::look_to_mat4(eye, forward, up),
            clip_from_view: depth.perspective(c.fov_y_deg.to_radians(), aspect, c.near_m, c.far_m),
            depth,
            far_m: c.far_m,
            sun,
            time_s: 0.0,
            exposure_ev: 0.0,
            frame_index: 0,
        }
    }

    /// Term `index` of the R2 sequence from the pixel's centre (Roberts 2018, "The unreasonable
    /// effectiveness of quasirandom sequences": the additive recurrence by [`FOOTPRINT_STEP`]), in
    /// pixel units from its corner. Any run of it covers the pixel evenly; the path tracer rotates
    /// it per pixel.
    pub fn r2_point(index: u32) -> Vec2 {
        let step = glam::DVec2::from_array(FOOTPRINT_STEP);
        (glam::DVec2::splat(0.5) + step * f64::from(index))
            .fract()
            .as_vec2()
    }

    /// Where sample `index` of `samples` crosses its pixel, in pixel units from its corner: the
    /// centre for one sample, else R2 points ([`Frame::r2_point`]) each beside its reflection
    /// through the centre (antithetic pairs; an odd count adds the centre itself), so that the
    /// samples' centroid is the pixel's centre for every count, as the path tracer's rotated
    /// points are on average (the first 8 R2 points alone lie 0.11 px left of it).
    /// `frame_footprint_point` in `frame.wgsl` is the same.
    pub fn footprint_point(index: u32, samples: u32) -> Vec2 {
        if samples <= 1 {
            return Vec2::splat(0.5);
        }
        let slot = index + 2 - samples % 2;
        let point = Self::r2_point(slot / 2);
        if slot % 2 == 1 {
            Vec2::ONE - point
        } else {
            point
        }
    }

    /// The same frame with its image shifted by `offset_px` pixels (x right, y down): every
    /// pixel then samples the point `offset_px` from its centre (a sub-pixel jitter of the
    /// projection).
    pub fn shifted_by(&self, offset_px: Vec2) -> Frame {
        let ndc = Vec2::new(-2.0, 2.0) * offset_px / self.size.as_vec2();
        Frame {
            clip_from_view: Mat4::from_translation(ndc.extend(0.0)) * self.clip_from_view,
            ..self.clone()
        }
    }

    /// Sample `index` of `samples` over each pixel's footprint: this frame shifted so that every
    /// pixel is seen through [`Frame::footprint_point`] of itself, its frame index the sample's.
    pub fn footprint_sample(&self, index: u32, samples: u32) -> Frame {
        Frame {
            frame_index: index,
            ..self.shifted_by(Frame::footprint_point(index, samples) - 0.5)
        }
    }

    /// The same frame seen through a depth buffer of convention `depth`: the projection is rebuilt
    /// for it from the scene camera's field of view and planes.
    pub fn with_depth(self, scene: &Scene, depth: DepthConvention) -> Frame {
        let c = &scene.camera;
        let aspect = self.size.x as f32 / self.size.y as f32;
        Frame {
            clip_from_view: depth.perspective(c.fov_y_deg.to_radians(), aspect, c.near_m, c.far_m),
            depth,
            ..self
        }
    }

    /// World-to-clip transform.
    pub fn clip_from_world(&self) -> Mat4 {
        self.clip_from_view * self.view_from_world
    }

    /// Normalised device coordinates of pixel coordinates `pixel` (0..width, 0..height, y down).
    fn ndc(&self, pixel: glam::Vec2) -> glam::Vec2 {
        glam::Vec2::new(
            2.0 * pixel.x / self.size.x as f32 - 1.0,
            1.0 - 2.0 * pixel.y / self.size.y as f32,
        )
    }

    /// World-space ray (origin, unit direction) through pixel coordinates `pixel` (0..width,
    /// 0..height, y down): `frame_ray_direction` in `frame.wgsl`.
    pub fn camera_ray(&self, pixel: glam::Vec2) -> (Vec3, Vec3) {
        let to_point = self.view_point(pixel, RAY_NDC_DEPTH);
        let world = self.view_from_world.inverse().transform_vector3(to_point);
        (self.camera_position_m, world.normalize())
    }

    /// The view-space point (relative to the camera, so with no cancellation against its world
    /// position) that normalised depth `depth` stores at `pixel`.
    fn view_point(&self, pixel: glam::Vec2, depth: f32) -> Vec3 {
        let p = self.clip_from_view.inverse() * self.ndc(pixel).extend(depth).extend(1.0);
        p.truncate() / p.w
    }

    /// Distance from the camera to what a depth-buffer value `depth` stores at `pixel`, infinite
    /// where it holds no geometry: `frame_depth_distance` in `frame.wgsl`.
    pub fn depth_distance_m(&self, pixel: glam::Vec2, depth: f32) -> f32 {
        if !self.depth.has_geometry(depth) {
            return f32::INFINITY;
        }
        self.view_point(pixel, depth).length()
    }

    /// The `Frame` uniform of `frame.wgsl` for a technique output sampled on `grid`, with the
    /// renderer's `settings`.
    pub fn uniform(&self, grid: &SampleGrid, settings: &FrameSettings) -> FrameUniform {
        FrameUniform::new(self, grid, settings)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_float_rounding_keeps_the_mean_and_lands_on_half_floats() {
        let values = [
            0.0, 1.0e-6, -3.0e-5, 0.1, 0.7431, -1.0, 1.0, 2.0e-3, 17.29, 1000.3, 6.0e4,
        ];
        for value in values {
            let steps = 256;
            let rounded: Vec<f32> = (0..steps)
                .map(|i| round_to_half(value, (i as f32 + 0.5) / steps as f32))
                .collect();
            for r in &rounded {
                assert_eq!(half::f16::from_f32(*r).to_f32(), *r, "{value} -> {r}");
            }
            let ulp = (half::f16::from_f32(value.abs()).to_f32() - value.abs())
                .abs()
                .max(1e-8);
            let mean = rounded.iter().sum::<f32>() / steps as f32;
            // The mean of the stratified roundings is the value itself, within a small part of
            // the rounding step (nearest-rounding would be off by up to half of it).
            let spacing = (rounded.iter().cloned().fold(f32::MIN, f32::max)
                - rounded.iter().cloned().fold(f32::MAX, f32::min))
            .max(ulp);
            assert!(
                (mean - value).abs() <= spacing / steps as f32 + value.abs() * 1e-6,
                "{value}: mean {mean}"
            );
        }
        // A value below half a unit of its half-float neighbours is not lost on average.
        let small_step = 1.0 + 2f32.powi(-13);
        let up = (0..64).filter(|i| round_to_half(small_step, (*i as f32 + 0.5) / 64.0) > 1.0);
        assert_eq!(up.count(), 8, "1 + 1/8 ulp rounds up an eighth of the time");
    }

    #[test]
    fn centre_ray_looks_where_the_camera_looks() {
        let scene = Scene::default();
        let f = Frame::from_scene(&scene, UVec2::new(64, 36));
        let (_, d) = f.camera_ray(glam::Vec2::new(32.0, 18.0));
        let expect = direction_from_angles_deg(scene.camera.pitch_deg, scene.camera.yaw_deg);
        assert!(d.abs_diff_eq(expect, 1e-4), "{d} vs {expect}");
    }

    #[test]
    fn a_shifted_frame_samples_its_pixels_off_centre() {
        let f = Frame::from_scene(&Scene::default(), UVec2::new(64, 36));
        let offset = glam::Vec2::new(0.3, -0.2);
        let shifted = f.shifted_by(offset);
        let centre = glam::Vec2::new(20.5, 7.5);
        let (_, through_shifted) = shifted.camera_ray(centre);
        let (_, off_centre) = f.camera_ray(centre + offset);
        assert!(through_shifted.abs_diff_eq(off_centre, 1e-5));
        assert!(!through_shifted.abs_diff_eq(f.camera_ray(centre).1, 1e-5));
    }

    #[test]
    fn footprint_points_cover_the_pixel_evenly() {
        assert_eq!(Frame::footprint_point(0, 1), glam::Vec2::splat(0.5));
        let points: Vec<_> = (0..16).map(|i| Frame::footprint_point(i, 16)).collect();
        assert!(
            points
                .iter()
                .all(|p| p.cmpge(glam::Vec2::ZERO).all() && p.cmplt(glam::Vec2::ONE).all())
        );
        // Every quarter of the pixel holds 3 to 5 of the 16 points (4 if perfectly even).
        for quarter in 0..4 {
            let corner = glam::Vec2::new((quarter % 2) as f32, (quarter / 2) as f32) * 0.5;
            let inside = points
                .iter()
                .filter(|p| {
                    (**p - corner).cmpge(glam::Vec2::ZERO).all()
                        && (**p - corner).cmplt(glam::Vec2::splat(0.5)).all()
                })
                .count();
            assert!((3..=5).contains(&inside), "quarter {quarter}: {inside}");
        }
    }

    #[test]
    fn footprint_points_are_centred_for_every_count() {
        for samples in 1..=32 {
            let centroid = (0..samples)
                .map(|i| Frame::footprint_point(i, samples))
                .sum::<glam::Vec2>()
                / samples as f32;
            assert!(
                centroid.abs_diff_eq(glam::Vec2::splat(0.5), 1e-6),
                "{samples} samples: centroid {centroid}"
            );
        }
    }

    #[test]
    fn every_depth_convention_stores_the_same_distances() {
        let scene = Scene::default();
        let standard = Frame::from_scene(&scene, UVec2::new(64, 36));
        let centre = glam::Vec2::new(32.0, 18.0);
        for convention in DepthConvention::ALL {
            let f = standard.clone().with_depth(&scene, convention);
            assert!(
                f.camera_ray(centre)
                    .1
                    .abs_diff_eq(standard.camera_ray(centre).1, 1e-5)
            );
            // A standard f32 depth buffer resolves 20 km to about 1 % (why hosts reverse Z).
            let tolerance = if convention.is_reversed() { 2e-3 } else { 2e-2 };
            for distance_m in [10.0, 500.0, 20_000.0] {
                let depth = convention.depth_of_distance(&f.clip_from_view, distance_m);
                let back = f.depth_distance_m(centre, depth);
                assert!(
                    (back - distance_m).abs() < tolerance * distance_m,
                    "{convention:?}: {distance_m} m stored as {depth} reads back as {back} m"
                );
            }
            assert_eq!(
                f.depth_distance_m(centre, convention.far_value()),
                f32::INFINITY
            );
        }
    }
}
