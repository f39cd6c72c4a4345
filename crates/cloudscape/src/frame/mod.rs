//! One frame's view and light: the camera, the sun, the sky and the ground, derived from a scene or
//! given by a host renderer, and the `Frame` uniform that every pass reads (`frame.wgsl`).

use crate::optics::PhaseLobes;
use crate::scene::{Scene, SkyModel};
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, UVec2, Vec3, Vec4};

/// WGSL of the `Frame` uniform and its helpers (camera rays, sky radiance).
pub const FRAME_WGSL: &str = include_str!("frame.wgsl");

/// Unit vector toward elevation `el` and azimuth `az` (degrees; azimuth clockwise from north, with
/// x east, y up, z south): `(sin az cos el, sin el, -cos az cos el)`.
pub fn direction_from_angles_deg(elevation_deg: f32, azimuth_deg: f32) -> Vec3 {
    let (el, az) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
    Vec3::new(az.sin() * el.cos(), el.sin(), -az.cos() * el.cos())
}

/// `-ln(0.02)`: visibility is the distance at which haze leaves 2 % contrast, so the haze extinction
/// is 3.912 / visibility (Koschmieder 1924).
pub const KOSCHMIEDER_CONTRAST: f32 = 3.912;

/// The sky's radiance by direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyRadiance {
    /// Radiance straight up.
    pub zenith: Vec3,
    /// Radiance at and below the horizon.
    pub horizon: Vec3,
    /// Blend exponent: `mix(horizon, zenith, mu^exponent)` for mu = dir.y >= 0.
    pub exponent: f32,
    /// Extinction of the haze between the eye and distant objects, m^-1.
    pub haze_per_m: f32,
}

impl SkyRadiance {
    /// The sky of a scene; a constant sky has equal zenith and horizon.
    pub fn from_scene(scene: &Scene) -> SkyRadiance {
        let s = &scene.sky;
        let haze_per_m = KOSCHMIEDER_CONTRAST / s.visibility_m;
        match s.model {
            SkyModel::Constant => SkyRadiance {
                zenith: s.radiance.into(),
                horizon: s.radiance.into(),
                exponent: 1.0,
                haze_per_m,
            },
            SkyModel::Gradient => SkyRadiance {
                zenith: s.zenith_radiance.into(),
                horizon: s.horizon_radiance.into(),
                exponent: s.gradient_exponent,
                haze_per_m,
            },
        }
    }

    /// Radiance arriving from direction `dir` (unit).
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        self.horizon
            .lerp(self.zenith, dir.y.max(0.0).powf(self.exponent))
    }

    /// Mean radiance over the upper hemisphere, `(1 / 2 pi) int L dw = int_0^1 L(mu) dmu`.
    pub fn mean_radiance_up(&self) -> Vec3 {
        self.horizon.lerp(self.zenith, 1.0 / (1.0 + self.exponent))
    }

    /// Irradiance on an upward-facing surface, `2 pi int_0^1 L(mu) mu dmu`.
    pub fn irradiance_up(&self) -> Vec3 {
        std::f32::consts::PI * self.horizon.lerp(self.zenith, 2.0 / (2.0 + self.exponent))
    }
}

/// A frame's camera and lighting.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Image size in pixels.
    pub size: UVec2,
    /// Camera position, metres.
    pub camera_position_m: Vec3,
    /// World-to-view transform.
    pub view_from_world: Mat4,
    /// View-to-clip projection (wgpu conventions: NDC y up, depth 0 at the near plane, 1 at the far).
    pub clip_from_view: Mat4,
    /// Nothing beyond this distance is marched, metres.
    pub far_m: f32,
    /// Unit vector toward the sun.
    pub sun_direction: Vec3,
    /// Sun irradiance (colour times irradiance) on a surface facing it.
    pub sun_irradiance: Vec3,
    /// Angular radius of the sun disc, radians.
    pub sun_angular_radius_rad: f32,
    /// Sky radiance.
    pub sky: SkyRadiance,
    /// Lambertian ground albedo; None without a ground.
    pub ground_albedo: Option<Vec3>,
    /// Mean cosine `g` of the cloud droplets' phase function: how far diffuse light gets through
    /// clouds (their transport optical depth is `(1 - g) tau`).
    pub cloud_mean_cosine: f32,
    /// Scene time, seconds.
    pub time_s: f32,
    /// Frame counter that decorrelates the sampling jitter of successive frames.
    pub frame_index: u32,
}

impl Frame {
    /// The frame a scene describes, at `size` pixels.
    pub fn from_scene(scene: &Scene, size: UVec2) -> Frame {
        let c = &scene.camera;
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
        let s = &scene.sun;
        Frame {
            size,
            camera_position_m: eye,
            view_from_world: glam::camera::rh::view::look_to_mat4(eye, forward, up),
            clip_from_view: glam::camera::rh::proj::directx::perspective(
                c.fov_y_deg.to_radians(),
                aspect,
                c.near_m,
                c.far_m,
            ),
            far_m: c.far_m,
            sun_direction: direction_from_angles_deg(s.elevation_deg, s.azimuth_deg),
            sun_irradiance: Vec3::from_array(s.color) * s.irradiance,
            sun_angular_radius_rad: s.angular_radius_deg.to_radians(),
            sky: SkyRadiance::from_scene(scene),
            ground_albedo: scene
                .ground
                .enabled
                .then(|| Vec3::from_array(scene.ground.albedo)),
            cloud_mean_cosine: PhaseLobes::from_scene(&scene.phase).mean_cosine(),
            time_s: scene.render.time_s,
            frame_index: 0,
        }
    }

    /// Radiance leaving the Lambertian ground, lit by the unshadowed sun and the sky (zero without
    /// a ground): `albedo / pi * (E_sun max(0, sun.y) + E_sky)`.
    pub fn ground_radiance(&self) -> Vec3 {
        let albedo = self.ground_albedo.unwrap_or(Vec3::ZERO);
        let irradiance =
            self.sun_irradiance * self.sun_direction.y.max(0.0) + self.sky.irradiance_up();
        albedo * irradiance / std::f32::consts::PI
    }

    /// World-space ray (origin, unit direction) through pixel coordinates `pixel` (0..width, 0..height,
    /// y down), the same rays `frame.wgsl` makes.
    pub fn camera_ray(&self, pixel: glam::Vec2) -> (Vec3, Vec3) {
        let ndc = glam::Vec2::new(
            2.0 * pixel.x / self.size.x as f32 - 1.0,
            1.0 - 2.0 * pixel.y / self.size.y as f32,
        );
        let world_from_clip = (self.clip_from_view * self.view_from_world).inverse();
        let far = world_from_clip.project_point3(ndc.extend(1.0));
        (
            self.camera_position_m,
            (far - self.camera_position_m).normalize(),
        )
    }

    /// The `Frame` uniform of `frame.wgsl`.
    pub fn uniform(&self) -> FrameUniform {
        let ground = self.ground_albedo.map_or(Vec4::ZERO, |a| a.extend(1.0));
        FrameUniform {
            world_from_clip: (self.clip_from_view * self.view_from_world).inverse(),
            camera_position: self.camera_position_m.extend(self.far_m),
            viewport: Vec4::new(
                self.size.x as f32,
                self.size.y as f32,
                self.time_s,
                self.frame_index as f32,
            ),
            sun_direction: self.sun_direction.extend(self.sun_angular_radius_rad.cos()),
            sun_irradiance: self.sun_irradiance.extend(self.sun_angular_radius_rad),
            sky_zenith: self.sky.zenith.extend(self.sky.exponent),
            sky_horizon: self.sky.horizon.extend(self.sky.haze_per_m),
            sky_mean_up: self.sky.mean_radiance_up().extend(0.0),
            ground_albedo: ground,
            ground_radiance: self.ground_radiance().extend(0.0),
            cloud_optics: Vec4::new(self.cloud_mean_cosine, 0.0, 0.0, 0.0),
        }
    }
}

/// GPU layout of a [`Frame`] (see `frame.wgsl` for the meaning of each lane).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameUniform {
    world_from_clip: Mat4,
    camera_position: Vec4,
    viewport: Vec4,
    sun_direction: Vec4,
    sun_irradiance: Vec4,
    sky_zenith: Vec4,
    sky_horizon: Vec4,
    sky_mean_up: Vec4,
    ground_albedo: Vec4,
    ground_radiance: Vec4,
    cloud_optics: Vec4,
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn sky_moments_match_quadrature() {
        let sky = SkyRadiance {
            zenith: Vec3::new(0.1, 0.2, 0.5),
            horizon: Vec3::new(0.4, 0.5, 0.6),
            exponent: 0.45,
            haze_per_m: 0.0,
        };
        let n = 20_000;
        let (mut mean, mut irr) = (Vec3::ZERO, Vec3::ZERO);
        for i in 0..n {
            let mu = (i as f32 + 0.5) / n as f32;
            let l = sky.radiance(Vec3::new((1.0 - mu * mu).sqrt(), mu, 0.0));
            mean += l / n as f32;
            irr += l * mu * 2.0 * std::f32::consts::PI / n as f32;
        }
        assert!(mean.abs_diff_eq(sky.mean_radiance_up(), 1e-3));
        assert!(irr.abs_diff_eq(sky.irradiance_up(), 1e-3));
    }

    #[test]
    fn centre_ray_looks_where_the_camera_looks() {
        let scene = Scene::default();
        let f = Frame::from_scene(&scene, UVec2::new(64, 36));
        let (_, d) = f.camera_ray(glam::Vec2::new(32.0, 18.0));
        let expect = direction_from_angles_deg(scene.camera.pitch_deg, scene.camera.yaw_deg);
        assert!(d.abs_diff_eq(expect, 1e-4), "{d} vs {expect}");
    }
}
