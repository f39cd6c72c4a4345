//! The light around the clouds: the sun, the sky, the haze between the eye and what it sees, and
//! the clouds' shadows on everything below them.
//!
//! This is the environment interface every technique, the compositor and a host light with. On
//! the GPU it is bind group [`crate::shader::ENVIRONMENT_GROUP`] ([`EnvironmentGpu`]) and the
//! functions of `environment.wgsl`:
//!
//! - `environment_sun_direction()`, `environment_sun_irradiance(p)`: the sun as it reaches `p`
//!   (through the air: red at sunset);
//! - `environment_sun_disc_radiance(dir)`: the limb-darkened disc seen by the eye;
//! - `environment_sky_radiance(dir)`, `environment_sky_mean_radiance_up(p)`,
//!   `environment_sky_irradiance_up(p)`: the sky;
//! - `environment_aerial_perspective(radiance, coverage, uv, distance_m)`: the haze, applied once,
//!   in compositing;
//! - `environment_cloud_sun_optical_depth(p)`, `environment_cloud_sky_optical_depth(p)`,
//!   `environment_cloud_sun_transmittance(p)`: the clouds'
//!   shared shadow map ([`crate::shadow`]), for the ground, the air and a host's geometry.
//!
//! `sky.model = "atmosphere"` (the default) puts Hillaire 2020's atmosphere ([`crate::atmosphere`])
//! behind these functions; `gradient` and `constant` keep the analytic skies. [`EnvironmentPasses`]
//! fills the tables each frame. [`Environment`] and [`ViewedEnvironment`] are the CPU twins: the
//! path tracer lights with them, and probe tests hold the GPU functions against them.

mod atmosphere_passes;
mod gpu;
pub mod light_volume;
mod passes;
mod shadow_pass;
mod table_pass;

pub use atmosphere_passes::{ATMOSPHERE_AERIAL_WGSL, ATMOSPHERE_LUTS_WGSL, ATMOSPHERE_MARCH_WGSL};
pub use gpu::{
    AirUniform, CloudShadowUniform, ENVIRONMENT_WGSL, EnvironmentGpu, EnvironmentTable,
    EnvironmentUniform, LightVolumeUniform, ShadowMapBinding, TABLE_FORMAT, TableSizes,
};
pub use passes::{EnvironmentPasses, FrameLightVolume};
pub use shadow_pass::CLOUD_SHADOW_WGSL;
pub use table_pass::TablePass;

use crate::atmosphere::medium::KOSCHMIEDER_CONTRAST;
use crate::atmosphere::{Air, Atmosphere, SkyView};
use crate::frame::FrameSun;
use crate::scene::Scene;
pub use crate::scene::SkyModel;
use glam::{Vec2, Vec3};
use std::f32::consts::{PI, TAU};
use std::sync::Arc;

/// Linear limb-darkening coefficient of the sun's disc in the visible: `I(mu) / I(1) = 1 - u (1 -
/// mu)`, u about 0.6 at 550 nm (Pierce & Slaughter 1977, "Solar limb darkening", Solar Physics 51).
pub const SUN_LIMB_DARKENING: f32 = 0.6;

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
            SkyModel::Gradient | SkyModel::Atmosphere => SkyRadiance {
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
        PI * self.horizon.lerp(self.zenith, 2.0 / (2.0 + self.exponent))
    }
}

/// Rows of the midpoint rule across a pixel in [`SunDisc::pixel_radiance_of`].
pub const SUN_PIXEL_ROWS: u32 = 16;

/// The sun, a limb-darkened disc.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunDisc {
    /// Unit vector toward the centre of the disc.
    pub direction: Vec3,
    /// Irradiance on a surface facing the sun (the disc's radiance integrated over it); above the
    /// air with the atmosphere.
    pub irradiance: Vec3,
    /// Cosine of the angular radius.
    pub cos_radius: f32,
    /// Linear limb-darkening coefficient `u` (0: a uniform disc).
    pub limb_darkening: f32,
}

impl SunDisc {
    /// Radiance seen in direction `dir` for a disc of irradiance `irradiance`: inside the disc of
    /// solid angle `Omega = 2 pi (1 - cos r)`, `E / Omega (1 - u (1 - mu)) / (1 - u / 3)`, where
    /// `mu = sqrt(1 - (theta / r)^2)` is the cosine on the solar surface and `1 - u / 3` the
    /// law's mean over the disc, so the disc integrates to `E`; zero outside and for a point sun.
    /// The compositor draws this disc and the path tracer sees it.
    pub fn radiance_of(&self, irradiance: Vec3, dir: Vec3) -> Vec3 {
        let one_minus_cos_radius = 1.0 - self.cos_radius;
        // 1 - cos(theta) = |d - s|^2 / 2 for unit vectors: exact where theta is tiny, where
        // 1 - dot(d, s) loses all but a few bits in f32 (the disc is 1e-5 across in cosine).
        let one_minus_cos_angle = 0.5 * (dir - self.direction).length_squared();
        if one_minus_cos_radius <= 0.0 || one_minus_cos_angle > one_minus_cos_radius {
            return Vec3::ZERO;
        }
        let u = self.limb_darkening;
        let mu = (1.0 - one_minus_cos_angle / one_minus_cos_radius)
            .clamp(0.0, 1.0)
            .sqrt();
        let limb = (1.0 - u * (1.0 - mu)) / (1.0 - u / 3.0);
        irradiance * limb / (TAU * one_minus_cos_radius)
    }

    /// Mean of [`SunDisc::radiance_of`] over a pixel: the square of the sky around the pixel's
    /// centre direction `dir` whose sides are `step_x` and `step_y`, the differences between the
    /// directions through neighbouring pixel centres. An anti-aliased sun: a pixel shows the share
    /// of the disc it covers, so the disc's flux over the image is its irradiance times the solid
    /// angle it subtends, wherever it falls between pixel centres.
    ///
    /// In the plane tangent to the sky at the sun (angles of a few pixels), with `x`, `y` along the
    /// pixel's sides and `rho^2 = x^2 + y^2`, the linear limb law integrates in closed form along
    /// `x` over a chord of half-width `w = sqrt(r^2 - y^2)`:
    /// `int (1 - u + u sqrt(w^2 - x^2) / r) dx`, with `int sqrt(w^2 - x^2) dx =
    /// (x sqrt(w^2 - x^2) + w^2 asin(x / w)) / 2`; across `y = r sin(phi)` the
    /// [`SUN_PIXEL_ROWS`]-point midpoint rule in `phi` takes the disc's edge without the square root's
    /// singularity. `environment_sun_disc_pixel_radiance` is the GPU twin.
    pub fn pixel_radiance_of(
        &self,
        irradiance: Vec3,
        dir: Vec3,
        step_x: Vec3,
        step_y: Vec3,
    ) -> Vec3 {
        let radius = self.cos_radius.clamp(-1.0, 1.0).acos();
        let half = Vec2::new(step_x.length(), step_y.length()) * 0.5;
        let from_sun = dir - self.direction;
        if radius <= 0.0 || half.min_element() <= 0.0 {
            return Vec3::ZERO;
        }
        let centre = Vec2::new(
            from_sun.dot(step_x) / (2.0 * half.x),
            from_sun.dot(step_y) / (2.0 * half.y),
        );
        let (lo, hi) = (centre - half, centre + half);
        let phi = |y: f32| (y / radius).clamp(-1.0, 1.0).asin();
        let (phi_lo, phi_hi) = (phi(lo.y), phi(hi.y));
        if phi_hi <= phi_lo || lo.x >= radius || hi.x <= -radius {
            return Vec3::ZERO;
        }
        let u = self.limb_darkening;
        let dphi = (phi_hi - phi_lo) / SUN_PIXEL_ROWS as f32;
        let mut sum = 0.0;
        for k in 0..SUN_PIXEL_ROWS {
            let p = phi_lo + (k as f32 + 0.5) * dphi;
            let w = radius * p.cos();
            let (a, b) = (lo.x.clamp(-w, w), hi.x.clamp(-w, w));
            let chord = |x: f32| {
                0.5 * (x * (w * w - x * x).max(0.0).sqrt()
                    + w * w * (x / w).clamp(-1.0, 1.0).asin())
            };
            let row = (1.0 - u) * (b - a) + u / radius * (chord(b) - chord(a));
            sum += row * w * dphi;
        }
        let omega = TAU * (1.0 - self.cos_radius);
        irradiance * (sum / (1.0 - u / 3.0) / omega / (4.0 * half.x * half.y))
    }

    /// [`SunDisc::radiance_of`] the disc's own irradiance.
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        self.radiance_of(self.irradiance, dir)
    }
}

/// The sky and the air as a scene describes them: a renderer's settings, read when it is built or
/// edited. With a frame's sun they make the frame's [`Environment`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sky {
    /// The analytic sky and its haze (used by the gradient and constant models).
    pub radiance: SkyRadiance,
    /// Which sky lights the scene.
    pub model: SkyModel,
    /// The air of the atmosphere model.
    pub air: Air,
}

impl Sky {
    /// The sky a scene describes.
    pub fn from_scene(scene: &Scene) -> Sky {
        Sky {
            radiance: SkyRadiance::from_scene(scene),
            model: scene.sky.model,
            air: Air::from_scene(scene),
        }
    }
}

/// Sun, sky and haze of one frame, before any viewpoint: the uniform of `environment.wgsl`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Environment {
    /// The sun.
    pub sun: SunDisc,
    /// The analytic sky and its haze (used by the gradient and constant models).
    pub sky: SkyRadiance,
    /// Which sky lights the scene.
    pub sky_model: SkyModel,
    /// The air of the atmosphere model.
    pub air: Air,
}

impl Environment {
    /// The environment of `sky` under a frame's `sun`.
    pub fn new(sky: &Sky, sun: &FrameSun) -> Environment {
        Environment {
            sun: SunDisc {
                direction: sun.direction,
                irradiance: sun.irradiance,
                cos_radius: sun.angular_radius_rad.cos(),
                limb_darkening: SUN_LIMB_DARKENING,
            },
            sky: sky.radiance,
            sky_model: sky.model,
            air: sky.air,
        }
    }

    /// The environment a scene describes, its sun included (for CPU work on a whole scene: the
    /// path tracer, exports).
    pub fn from_scene(scene: &Scene) -> Environment {
        Environment::new(&Sky::from_scene(scene), &FrameSun::from_scene(&scene.sun))
    }

    /// Mean radiance of the diffuse light over the upper hemisphere at world point `p` under
    /// `tau_above` of cloud straight up, for droplets of mean scattering cosine `asymmetry`: the
    /// ambient light of a host's surfaces (no viewpoint's tables needed). Without clouds it is
    /// the sky's (`environment_sky_mean_radiance_up`). Under them the light entering their top,
    /// the sky's `E_sky` and the sun's `E_sun mu0` (through the air), leaves their base diffuse,
    /// thinned by the transmission of a conservative slab lit by diffuse light,
    /// `T = 1 / (1 + 3/4 (1 - g) tau)` (the two-stream result: Bohren 1987, "Multiple scattering
    /// of light and some of its observable consequences", Am. J. Phys. 55), the sun's part less
    /// what still arrives as the direct beam `exp(-tau / mu0)`:
    /// `L = T E_sky / pi + max(T - exp(-tau / mu0), 0) E_sun mu0 / pi`. The clouds are taken as
    /// a horizontal slab over `p`, as thick as the column above it. With the atmosphere it
    /// builds or reuses the atmosphere's CPU tables ([`crate::atmosphere`]'s `Atmosphere::shared`:
    /// about a second the first time in a debug build, then a look-up).
    pub fn diffuse_radiance_up(&self, p: Vec3, tau_above: f32, asymmetry: f32) -> Vec3 {
        let atmosphere =
            (self.sky_model == SkyModel::Atmosphere).then(|| Atmosphere::shared(&self.air));
        let atmosphere = atmosphere.as_deref();
        let sky = self.sky_hemisphere(atmosphere, p, 1);
        let tau = tau_above.max(0.0);
        if tau == 0.0 {
            return sky;
        }
        let through = 1.0 / (1.0 + 0.75 * (1.0 - asymmetry) * tau);
        let mu0 = self.sun.direction.y.max(0.0);
        let direct = if mu0 > 0.0 { (-tau / mu0).exp() } else { 0.0 };
        let sun = self.sun.irradiance * self.air_transmittance(atmosphere, p) * mu0;
        through * sky + (through - direct).max(0.0) * sun / PI
    }

    /// Transmittance of the air from `p` toward the sun, from `atmosphere`'s tables (1 without
    /// them: the analytic skies).
    fn air_transmittance(&self, atmosphere: Option<&Atmosphere>, p: Vec3) -> Vec3 {
        atmosphere.map_or(Vec3::ONE, |a| a.sun_transmittance(p, self.sun.direction))
    }

    /// The sky over an upward surface at `p`: its irradiance (`layer` 0) or its mean radiance
    /// (`layer` 1), from `atmosphere`'s tables (built for this air) or, without them, the
    /// analytic sky's.
    fn sky_hemisphere(&self, atmosphere: Option<&Atmosphere>, p: Vec3, layer: usize) -> Vec3 {
        match (atmosphere, layer) {
            (Some(a), _) => self.sun.irradiance * a.sky_irradiance(p, self.sun.direction, layer),
            (None, 0) => self.sky.irradiance_up(),
            (None, _) => self.sky.mean_radiance_up(),
        }
    }
}

/// The environment seen from one viewpoint: the CPU twin of every function of `environment.wgsl`
/// but the shadow map's ([`crate::shadow::CloudShadowMap`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ViewedEnvironment {
    /// The scene's environment.
    pub env: Environment,
    /// World point the sky and the aerial perspective are seen from.
    pub viewpoint_m: Vec3,
    /// The atmosphere's tables and the sky from the viewpoint (atmosphere model only).
    pub atmosphere: Option<(Arc<Atmosphere>, SkyView)>,
}

impl ViewedEnvironment {
    /// `env` seen from `viewpoint_m`; builds (or reuses) the atmosphere's tables when its model
    /// is the atmosphere.
    pub fn new(env: &Environment, viewpoint_m: Vec3) -> ViewedEnvironment {
        let atmosphere = (env.sky_model == SkyModel::Atmosphere).then(|| {
            let atmosphere = Atmosphere::shared(&env.air);
            let view = SkyView::new(&atmosphere, viewpoint_m, env.sun.direction);
            (atmosphere, view)
        });
        ViewedEnvironment {
            env: *env,
            viewpoint_m,
            atmosphere,
        }
    }

    /// Transmittance of the air from `p` toward the sun (1 for the analytic skies):
    /// `environment_sun_transmittance`.
    pub fn sun_transmittance(&self, p: Vec3) -> Vec3 {
        self.env.air_transmittance(self.tables(), p)
    }

    /// Sun irradiance reaching `p` on a surface facing the sun: `environment_sun_irradiance`.
    pub fn sun_irradiance(&self, p: Vec3) -> Vec3 {
        self.env.sun.irradiance * self.sun_transmittance(p)
    }

    /// Mean radiance of the sun's disc over the pixel around `dir` with sides `step_x`, `step_y`
    /// ([`SunDisc::pixel_radiance_of`]): `environment_sun_disc_pixel_radiance`.
    pub fn sun_disc_pixel_radiance(&self, dir: Vec3, step_x: Vec3, step_y: Vec3) -> Vec3 {
        let irradiance = self.sun_irradiance(self.viewpoint_m);
        self.env
            .sun
            .pixel_radiance_of(irradiance, dir, step_x, step_y)
    }

    /// Radiance of the sun's disc seen from the viewpoint along `dir`:
    /// `environment_sun_disc_radiance`.
    pub fn sun_disc_radiance(&self, dir: Vec3) -> Vec3 {
        let irradiance = self.sun_irradiance(self.viewpoint_m);
        self.env.sun.radiance_of(irradiance, dir)
    }

    /// Sky radiance arriving at the viewpoint from `dir`, the disc excluded:
    /// `environment_sky_radiance`.
    pub fn sky_radiance(&self, dir: Vec3) -> Vec3 {
        match &self.atmosphere {
            Some((atmosphere, view)) => {
                self.env.sun.irradiance * view.radiance(atmosphere.air(), dir)
            }
            None => self.env.sky.radiance(dir),
        }
    }

    /// Mean sky radiance over the upper hemisphere at `p`: `environment_sky_mean_radiance_up`.
    pub fn sky_mean_radiance_up(&self, p: Vec3) -> Vec3 {
        self.sky_hemisphere(p, 1)
    }

    /// Sky irradiance on an upward-facing surface at `p`: `environment_sky_irradiance_up`.
    pub fn sky_irradiance_up(&self, p: Vec3) -> Vec3 {
        self.sky_hemisphere(p, 0)
    }

    fn sky_hemisphere(&self, p: Vec3, layer: usize) -> Vec3 {
        self.env.sky_hemisphere(self.tables(), p, layer)
    }

    /// The atmosphere's tables, with that model.
    fn tables(&self) -> Option<&Atmosphere> {
        self.atmosphere.as_ref().map(|(a, _)| &**a)
    }

    /// Radiance leaving a Lambertian ground of `albedo` at `p` under the unshadowed sun and sky:
    /// `albedo / pi * (E_sun(p) max(0, sun.y) + E_sky(p))` (`environment_ground_radiance`).
    pub fn ground_radiance(&self, albedo: Vec3, p: Vec3) -> Vec3 {
        let sun = self.sun_irradiance(p) * self.env.sun.direction.y.max(0.0);
        albedo * (sun + self.sky_irradiance_up(p)) / PI
    }

    /// What the eye at the viewpoint sees of `radiance`, scattered by something covering
    /// fraction `coverage` of the pixel, `distance_m` along `dir`: with the atmosphere,
    /// `radiance T + coverage L_air`, the air's transmittance and in-scattered light over that
    /// distance (the sun's single scattering dimmed by `sun_visibility(t)`, the clouds' shadow at
    /// distance `t`); with the analytic skies, a fade toward the horizon radiance by
    /// `exp(-haze distance)` (Koschmieder 1924). `environment_aerial_perspective` reads the same
    /// from its 32 slices.
    pub fn aerial_perspective(
        &self,
        (radiance, coverage): (Vec3, f32),
        (dir, distance_m): (Vec3, f32),
        sun_visibility: impl FnMut(f32) -> f32,
    ) -> Vec3 {
        match &self.atmosphere {
            Some((atmosphere, _)) => {
                let sun = self.env.sun.direction;
                let ray = (self.viewpoint_m, dir);
                let (light, through) =
                    atmosphere.aerial_perspective(ray, sun, distance_m, sun_visibility);
                radiance * through + self.env.sun.irradiance * light * coverage
            }
            None => {
                let clear = (-self.env.sky.haze_per_m * distance_m).exp();
                radiance * clear + self.env.sky.horizon * coverage * (1.0 - clear)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
            irr += l * mu * 2.0 * PI / n as f32;
        }
        assert!(mean.abs_diff_eq(sky.mean_radiance_up(), 1e-3));
        assert!(irr.abs_diff_eq(sky.irradiance_up(), 1e-3));
    }

    #[test]
    fn diffuse_light_under_clouds_is_the_sky_without_them_and_thins_through_a_deck() {
        let env = Environment::from_scene(&Scene::default());
        let (p, g) = (Vec3::new(0.0, 2.0, 0.0), 0.85);
        let clear = env.diffuse_radiance_up(p, 0.0, g);
        let viewed = ViewedEnvironment::new(&env, p).sky_mean_radiance_up(p);
        assert!(
            clear.abs_diff_eq(viewed, 1e-6 * viewed.max_element()),
            "{clear} {viewed}"
        );
        // Continuous at no cloud: a vanishing veil scatters a vanishing part of the sun.
        let thin = env.diffuse_radiance_up(p, 1e-5, g);
        assert!((thin - clear).abs().max_element() < 1e-3 * clear.max_element());
        // A thick deck: everything that enters its top leaves its base diffuse, thinned by T.
        let tau = 100.0;
        let through = 1.0 / (1.0 + 0.75 * (1.0 - g) * tau);
        let mu0 = env.sun.direction.y;
        let atmosphere = Atmosphere::shared(&env.air);
        let sun = env.sun.irradiance * atmosphere.sun_transmittance(p, env.sun.direction) * mu0;
        let expected = through * (clear + sun / PI);
        let deck = env.diffuse_radiance_up(p, tau, g);
        assert!((deck - expected).abs().max_element() < 1e-3 * expected.max_element());
        // Thicker decks let less through, and a thin veil adds the sunlight it scatters.
        let radiance = |tau| env.diffuse_radiance_up(p, tau, g).y;
        assert!(radiance(1000.0) < radiance(100.0) && radiance(100.0) < radiance(10.0));
        assert!(
            radiance(0.5) > clear.y,
            "{} against {}",
            radiance(0.5),
            clear.y
        );
    }

    #[test]
    fn the_sun_disc_integrates_to_the_sun_irradiance() {
        let env = Environment::from_scene(&Scene::default());
        let sun = env.sun;
        // Integrate the disc's radiance over a cap slightly wider than it, in cos theta.
        let (n, cap) = (200_000, 1.0 - 2.0 * (1.0 - sun.cos_radius));
        let frame = glam::Mat3::from_quat(glam::Quat::from_rotation_arc(Vec3::Y, sun.direction));
        let mut total = Vec3::ZERO;
        for i in 0..n {
            let mu = cap + (1.0 - cap) * (i as f32 + 0.5) / n as f32;
            let dir = frame * Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), mu, 0.0);
            total += sun.radiance(dir) * TAU * (1.0 - cap) / n as f32;
        }
        // f32 resolves cos theta near 1 to about 6e-8, 0.5 % of the disc's 1 - cos r = 1.1e-5.
        let relative = (total - sun.irradiance).abs().max_element() / sun.irradiance.max_element();
        assert!(relative < 0.02, "{total} vs {}", sun.irradiance);
    }

    /// A pixel grid around the sun, `size` radians per pixel, shifted by `shift` pixels: each
    /// pixel's centre direction and its two sides.
    fn pixels_around(sun: &SunDisc, size: f32, shift: Vec2) -> Vec<(Vec3, Vec3, Vec3)> {
        let e1 = sun.direction.any_orthonormal_vector();
        let e2 = sun.direction.cross(e1);
        let n = (4.0 * sun.cos_radius.acos() / size).ceil() as i32 + 2;
        let mut pixels = Vec::new();
        for j in -n..=n {
            for i in -n..=n {
                let at = (Vec2::new(i as f32, j as f32) + shift) * size;
                let dir = (sun.direction + e1 * at.x + e2 * at.y).normalize();
                pixels.push((dir, e1 * size, e2 * size));
            }
        }
        pixels
    }

    #[test]
    fn an_anti_aliased_sun_keeps_its_flux_wherever_it_falls() {
        let sun = Environment::from_scene(&Scene::default()).sun;
        let radius = sun.cos_radius.acos();
        for (size, shift) in [
            (radius * 3.0, Vec2::ZERO),
            (radius * 1.3, Vec2::new(0.31, -0.47)),
            (radius * 0.4, Vec2::new(0.5, 0.5)),
            (radius * 0.07, Vec2::new(0.13, 0.71)),
        ] {
            let flux: Vec3 = pixels_around(&sun, size, shift)
                .iter()
                .map(|(d, x, y)| sun.pixel_radiance_of(sun.irradiance, *d, *x, *y) * size * size)
                .sum();
            let relative =
                (flux - sun.irradiance).abs().max_element() / sun.irradiance.max_element();
            assert!(
                relative < 0.01,
                "pixel {size} rad, shift {shift}: {flux} vs {}",
                sun.irradiance
            );
        }
    }

    #[test]
    fn a_pixel_far_smaller_than_the_sun_sees_its_radiance_there() {
        let sun = Environment::from_scene(&Scene::default()).sun;
        let size = sun.cos_radius.acos() * 0.01;
        for (dir, x, y) in pixels_around(&sun, size * 40.0, Vec2::new(0.2, 0.3)) {
            let point = sun.radiance(dir);
            let pixel = sun.pixel_radiance_of(sun.irradiance, dir, x / 40.0, y / 40.0);
            let near_rim = (sun.radiance(dir + x / 40.0) - point).abs().max_element() > 0.0
                || (sun.radiance(dir + y / 40.0) - point).abs().max_element() > 0.0;
            if !near_rim {
                assert!(
                    (pixel - point).abs().max_element() <= 0.01 * point.max_element() + 1e-6,
                    "{pixel} vs {point}"
                );
            }
        }
        let far = (sun.direction + Vec3::X * 0.05).normalize();
        assert_eq!(
            sun.pixel_radiance_of(sun.irradiance, far, Vec3::X * size, Vec3::Z * size),
            Vec3::ZERO
        );
    }
}
