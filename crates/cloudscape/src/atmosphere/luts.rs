//! Hillaire 2020's look-up tables on the CPU: the specification the GPU tables are tested against.
//!
//! - transmittance (256 x 64) over radius and view cosine, Bruneton 2017's parameterisation;
//! - multiple scattering (32 x 32) over radius and sun cosine, Hillaire 2020 section 5.5.2;
//! - sky irradiance and mean sky radiance on an upward surface (32 x 32 each), the same axes;
//! - the sky view (192 x 108) seen from one point, by elevation and azimuth from the sun;
//! - aerial perspective along any ray, which the GPU stores in 32 slices of 4 km.
//!
//! Every radiance is for a sun of unit irradiance above the atmosphere.

use super::medium::{Air, advance};
use super::table::{Table2, texture_coord, unit_range};
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_PI_2, PI};

/// Transmittance table size: view cosine across, radius down (Hillaire 2020).
pub const TRANSMITTANCE_SIZE: (u32, u32) = (256, 64);
/// Multiple-scattering table size: sun cosine across, altitude down (Hillaire 2020).
pub const MULTIPLE_SCATTERING_SIZE: (u32, u32) = (32, 32);
/// Sky irradiance table size (per layer): sun cosine across, altitude down.
pub const IRRADIANCE_SIZE: (u32, u32) = (32, 32);
/// Sky-view table size: azimuth from the sun across, elevation down (Hillaire 2020).
pub const SKY_VIEW_SIZE: (u32, u32) = (192, 108);
/// Columns and rows of the aerial-perspective volume across the view (Hillaire 2020: 32 x 32).
pub const AERIAL_SIZE: (u32, u32) = (32, 32);
/// Depth of one aerial-perspective slice, metres (Hillaire 2020: 32 slices of 4 km).
pub const AERIAL_SLICE_M: f32 = 4_000.0;
/// Number of aerial-perspective slices (Hillaire 2020).
pub const AERIAL_SLICES: u32 = 32;
/// Integration steps per aerial-perspective slice: one sample per kilometre.
pub const AERIAL_STEPS_PER_SLICE: u32 = 4;

/// Steps of the transmittance integral along a ray to the top (Hillaire 2020 uses 40).
pub const TRANSMITTANCE_STEPS: u32 = 40;
/// Steps along each ray of the multiple-scattering table (Hillaire 2020 uses 20).
pub const MULTIPLE_SCATTERING_STEPS: u32 = 20;
/// Directions per side of the multiple-scattering table's sphere grid: 8 x 8 = 64 (Hillaire 2020).
pub const MULTIPLE_SCATTERING_DIRECTIONS: u32 = 8;
/// Steps along each sky-view ray (Hillaire 2020: 30).
pub const SKY_VIEW_STEPS: u32 = 30;
/// Steps along each ray of the irradiance table.
pub const IRRADIANCE_STEPS: u32 = 16;
/// Directions per side of the irradiance table's hemisphere grid (8 x 8, azimuth over half a turn).
pub const IRRADIANCE_DIRECTIONS: u32 = 8;

/// Texture coordinates of (radius, view cosine) in the transmittance table (Bruneton 2017,
/// `GetTransmittanceTextureUvFromRMu`).
pub fn transmittance_uv(air: &Air, r: f32, mu: f32) -> Vec2 {
    let horizon = (air.top_radius_m.powi(2) - air.bottom_radius_m.powi(2)).sqrt();
    let rho = (r * r - air.bottom_radius_m.powi(2)).max(0.0).sqrt();
    let d = air.distance_to_top(r, mu);
    let (d_min, d_max) = (air.top_radius_m - r, rho + horizon);
    let x_mu = if d_max > d_min {
        (d - d_min) / (d_max - d_min)
    } else {
        0.0
    };
    Vec2::new(
        texture_coord(x_mu, TRANSMITTANCE_SIZE.0),
        texture_coord(rho / horizon, TRANSMITTANCE_SIZE.1),
    )
}

/// (radius, view cosine) at texture coordinates `uv`: the inverse of [`transmittance_uv`]
/// (Bruneton 2017, `GetRMuFromTransmittanceTextureUv`).
pub fn transmittance_r_mu(air: &Air, uv: Vec2) -> (f32, f32) {
    let horizon = (air.top_radius_m.powi(2) - air.bottom_radius_m.powi(2)).sqrt();
    let rho = horizon * unit_range(uv.y, TRANSMITTANCE_SIZE.1);
    let r = (rho * rho + air.bottom_radius_m.powi(2)).sqrt();
    let (d_min, d_max) = (air.top_radius_m - r, rho + horizon);
    let d = d_min + unit_range(uv.x, TRANSMITTANCE_SIZE.0) * (d_max - d_min);
    let mu = if d <= 0.0 {
        1.0
    } else {
        ((horizon * horizon - rho * rho - d * d) / (2.0 * r * d)).clamp(-1.0, 1.0)
    };
    (r, mu)
}

/// Texture coordinates of (radius, sun cosine) in the multiple-scattering and irradiance tables
/// (Hillaire 2020: sun cosine across, altitude down, both linear).
pub fn sun_table_uv(air: &Air, r: f32, mu_s: f32, size: (u32, u32)) -> Vec2 {
    let altitude = (r - air.bottom_radius_m) / (air.top_radius_m - air.bottom_radius_m);
    Vec2::new(
        texture_coord((mu_s * 0.5 + 0.5).clamp(0.0, 1.0), size.0),
        texture_coord(altitude.clamp(0.0, 1.0), size.1),
    )
}

/// (radius, sun cosine) at texture coordinates `uv` of a sun table: the inverse of
/// [`sun_table_uv`].
pub fn sun_table_r_mu(air: &Air, uv: Vec2, size: (u32, u32)) -> (f32, f32) {
    let mu_s = unit_range(uv.x, size.0) * 2.0 - 1.0;
    let altitude = unit_range(uv.y, size.1);
    let r = air.bottom_radius_m + altitude * (air.top_radius_m - air.bottom_radius_m);
    (r, mu_s)
}

/// Elevation of the geometric horizon seen from radius `r`, radians (negative above the ground).
fn horizon_elevation(air: &Air, r: f32) -> f32 {
    -(air.bottom_radius_m / r).clamp(0.0, 1.0).acos()
}

/// Texture coordinates of a view direction in the sky-view table seen from radius `r`: its
/// elevation above the local horizontal, radians, and its azimuth from the sun's, radians in
/// `[0, pi]`. Elevation maps non-linearly, with the geometric horizon at `v = 1/2` and the square
/// root concentrating texels near it where the sky changes fastest (after Hillaire 2020).
pub fn sky_view_uv(air: &Air, r: f32, elevation: f32, azimuth: f32) -> Vec2 {
    let horizon = horizon_elevation(air, r);
    let v = if elevation >= horizon {
        0.5 + 0.5
            * ((elevation - horizon) / (FRAC_PI_2 - horizon))
                .clamp(0.0, 1.0)
                .sqrt()
    } else {
        0.5 - 0.5
            * ((horizon - elevation) / (horizon + FRAC_PI_2))
                .clamp(0.0, 1.0)
                .sqrt()
    };
    Vec2::new(
        texture_coord((azimuth / PI).clamp(0.0, 1.0), SKY_VIEW_SIZE.0),
        texture_coord(v, SKY_VIEW_SIZE.1),
    )
}

/// (elevation, azimuth from the sun) at texture coordinates `uv` of the sky view from radius `r`:
/// the inverse of [`sky_view_uv`].
pub fn sky_view_angles(air: &Air, r: f32, uv: Vec2) -> (f32, f32) {
    let horizon = horizon_elevation(air, r);
    let v = unit_range(uv.y, SKY_VIEW_SIZE.1);
    let elevation = if v >= 0.5 {
        horizon + (2.0 * v - 1.0).powi(2) * (FRAC_PI_2 - horizon)
    } else {
        horizon - (1.0 - 2.0 * v).powi(2) * (horizon + FRAC_PI_2)
    };
    (elevation, unit_range(uv.x, SKY_VIEW_SIZE.0) * PI)
}

/// A ray through the air in a local frame: from `(0, r, 0)` along `dir`, with the sun at `sun`.
#[derive(Clone, Copy, Debug)]
pub struct LocalRay {
    /// Radius of the start, metres.
    pub r: f32,
    /// Unit direction (y up).
    pub dir: Vec3,
    /// Unit direction toward the sun.
    pub sun: Vec3,
}

impl LocalRay {
    /// The ray in the frame where the start is `(0, r, 0)` and the sun lies in the xy plane, with
    /// sun cosine `mu_s`, elevation `elevation` and azimuth from the sun `azimuth`.
    pub fn from_angles(r: f32, mu_s: f32, elevation: f32, azimuth: f32) -> LocalRay {
        let (ce, se) = (elevation.cos(), elevation.sin());
        LocalRay {
            r,
            dir: Vec3::new(ce * azimuth.cos(), se, ce * azimuth.sin()),
            sun: Vec3::new((1.0 - mu_s * mu_s).max(0.0).sqrt(), mu_s, 0.0),
        }
    }
}

/// The transmittance table, from the integral of the air's extinction to the top.
pub fn transmittance_table(air: &Air) -> Table2 {
    let (w, h) = TRANSMITTANCE_SIZE;
    Table2::from_fn(w, h, |uv| {
        let (r, mu) = transmittance_r_mu(air, uv);
        let d = air.distance_to_top(r, mu);
        let dt = d / TRANSMITTANCE_STEPS as f32;
        let depth: Vec3 = (0..TRANSMITTANCE_STEPS)
            .map(|i| air.at(advance(r, mu, (i as f32 + 0.5) * dt).0).extinction * dt)
            .sum();
        (-depth).exp()
    })
}

/// The tables the sky is integrated with, and the air they describe.
#[derive(Clone, Debug, PartialEq)]
pub struct SkyTables {
    /// The air.
    pub air: Air,
    /// Transmittance to the top by radius and view cosine.
    pub transmittance: Table2,
    /// Hillaire's multiple-scattering transfer `Psi_ms` by radius and sun cosine.
    pub multiple_scattering: Table2,
}

impl SkyTables {
    /// The transmittance and multiple-scattering tables of `air`.
    pub fn new(air: &Air) -> SkyTables {
        let transmittance = transmittance_table(air);
        let partial = SkyTables {
            air: *air,
            transmittance,
            multiple_scattering: Table2::from_fn(1, 1, |_| Vec3::ZERO),
        };
        let (w, h) = MULTIPLE_SCATTERING_SIZE;
        let multiple_scattering = Table2::from_fn(w, h, |uv| {
            let (r, mu_s) = sun_table_r_mu(air, uv, MULTIPLE_SCATTERING_SIZE);
            partial.multiple_scattering_at(r, mu_s)
        });
        SkyTables {
            multiple_scattering,
            ..partial
        }
    }

    /// Transmittance from radius `r` toward the sun at cosine `mu_s`, with the part of the sun's
    /// disc the planet hides (Bruneton 2017, `GetTransmittanceToSun`): zero once the sun is set.
    pub fn sun_transmittance(&self, r: f32, mu_s: f32) -> Vec3 {
        let air = &self.air;
        let sin_horizon = air.bottom_radius_m / r.max(air.bottom_radius_m);
        let cos_horizon = -(1.0 - sin_horizon * sin_horizon).max(0.0).sqrt();
        let edge = sin_horizon * air.sun_angular_radius_rad;
        let visible = smoothstep(-edge, edge, mu_s - cos_horizon);
        self.transmittance.sample(transmittance_uv(air, r, mu_s)) * visible
    }

    /// `Psi_ms` at radius `r` and sun cosine `mu_s`, from the table.
    pub fn multiple_scattering(&self, r: f32, mu_s: f32) -> Vec3 {
        let uv = sun_table_uv(&self.air, r, mu_s, MULTIPLE_SCATTERING_SIZE);
        self.multiple_scattering.sample(uv)
    }

    /// Hillaire 2020 eq. 5-9: the second-order light `L_2` and the transfer `f_ms` averaged over
    /// the sphere of directions (isotropic phase, with the ground's Lambertian bounce), and
    /// `Psi_ms = L_2 / (1 - f_ms)`, the sum of every higher order as a geometric series.
    fn multiple_scattering_at(&self, r: f32, mu_s: f32) -> Vec3 {
        let n = MULTIPLE_SCATTERING_DIRECTIONS;
        let (mut second_order, mut transfer) = (Vec3::ZERO, Vec3::ZERO);
        for i in 0..n {
            for j in 0..n {
                let cos_zenith = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
                let azimuth = 2.0 * PI * (j as f32 + 0.5) / n as f32;
                let ray = LocalRay::from_angles(r, mu_s, cos_zenith.asin(), azimuth);
                let (l, f) = self.isotropic_transfer(ray);
                second_order += l;
                transfer += f;
            }
        }
        let count = (n * n) as f32;
        (second_order / count) / (Vec3::ONE - transfer / count)
    }

    /// Along one ray to where it leaves the air: the sun's light scattered once toward the start
    /// by an isotropic phase function (plus the ground's bounce), and the fraction `f_ms` of light
    /// scattered back to the start (Hillaire 2020 eq. 6 and 7).
    fn isotropic_transfer(&self, ray: LocalRay) -> (Vec3, Vec3) {
        let air = &self.air;
        let mu = ray.dir.y;
        let t_max = air.distance_to_boundary(ray.r, mu);
        let dt = t_max / MULTIPLE_SCATTERING_STEPS as f32;
        let (mut light, mut transfer, mut through) = (Vec3::ZERO, Vec3::ZERO, Vec3::ONE);
        let isotropic = 1.0 / (4.0 * PI);
        for i in 0..MULTIPLE_SCATTERING_STEPS {
            let p = Vec3::new(0.0, ray.r, 0.0) + ray.dir * ((i as f32 + 0.5) * dt);
            let (r, up) = (p.length(), p.normalize());
            let sample = air.at(r);
            let sun = self.sun_transmittance(r, up.dot(ray.sun));
            let step = (-sample.extinction * dt).exp();
            let integral = (Vec3::ONE - step) / sample.extinction.max(Vec3::splat(1e-12));
            light += through * sample.scattering() * sun * isotropic * integral;
            transfer += through * sample.scattering() * integral;
            through *= step;
        }
        if air.hits_ground(ray.r, mu) {
            let ground = Vec3::new(0.0, ray.r, 0.0) + ray.dir * t_max;
            let up = ground.normalize();
            let mu_s = up.dot(ray.sun);
            let sun = self.sun_transmittance(air.bottom_radius_m, mu_s);
            light += through * sun * mu_s.max(0.0) * air.ground_albedo / PI;
        }
        (light, transfer)
    }

    /// Light scattered toward the start of `ray` by the air over `[t_start, t_end]` (Hillaire 2020
    /// eq. 1-4: single scattering of the sun by Rayleigh and Mie phase, plus `Psi_ms` times the
    /// scattering coefficient) and the transmittance over it, from `steps` samples at `t(x)` for
    /// `x` at the step midpoints in `[0, 1]`. `sun_visibility(t)` dims the single scattering at
    /// distance `t` along the ray, for the clouds' shadows (1 without clouds).
    pub fn scattered_along(
        &self,
        ray: LocalRay,
        span: (f32, f32),
        steps: u32,
        spacing: Spacing,
        mut sun_visibility: impl FnMut(f32) -> f32,
    ) -> (Vec3, Vec3) {
        let air = &self.air;
        let cos_theta = ray.dir.dot(ray.sun);
        let rayleigh_phase = Air::rayleigh_phase(cos_theta);
        let mie_phase = air.mie_phase(cos_theta);
        let (mut light, mut through) = (Vec3::ZERO, Vec3::ONE);
        for i in 0..steps {
            let (t0, t1) = (
                spacing.at(span, i as f32 / steps as f32),
                spacing.at(span, (i + 1) as f32 / steps as f32),
            );
            let t = 0.5 * (t0 + t1);
            let p = Vec3::new(0.0, ray.r, 0.0) + ray.dir * t;
            let (r, up) = (p.length(), p.normalize());
            let mu_s = up.dot(ray.sun);
            let sample = air.at(r);
            let sun = self.sun_transmittance(r, mu_s) * sun_visibility(t);
            let single = sample.rayleigh_scattering * rayleigh_phase
                + Vec3::splat(sample.mie_scattering * mie_phase);
            let source = single * sun + self.multiple_scattering(r, mu_s) * sample.scattering();
            let step = (-sample.extinction * (t1 - t0)).exp();
            let integral = (Vec3::ONE - step) / sample.extinction.max(Vec3::splat(1e-12));
            light += through * source * integral;
            through *= step;
        }
        (light, through)
    }

    /// Sky radiance seen along `ray` to where it leaves the air (the sun's disc excluded), as the
    /// sky-view table stores it.
    pub fn sky_radiance(&self, ray: LocalRay) -> Vec3 {
        let t_max = self.air.distance_to_boundary(ray.r, ray.dir.y);
        let span = (0.0, t_max);
        self.scattered_along(ray, span, SKY_VIEW_STEPS, Spacing::Quadratic, |_| 1.0)
            .0
    }

    /// The sky-view table seen from radius `r` with the sun at cosine `mu_s`.
    pub fn sky_view_table(&self, r: f32, mu_s: f32) -> Table2 {
        let (w, h) = SKY_VIEW_SIZE;
        Table2::from_fn(w, h, |uv| {
            let (elevation, azimuth) = sky_view_angles(&self.air, r, uv);
            self.sky_radiance(LocalRay::from_angles(r, mu_s, elevation, azimuth))
        })
    }

    /// Aerial perspective over the first `distance_m` of `ray`: the light the air scatters
    /// toward the eye and its transmittance, one sample per [`AERIAL_SLICE_M`] /
    /// [`AERIAL_STEPS_PER_SLICE`], as the GPU's slices integrate it.
    pub fn aerial_perspective(
        &self,
        ray: LocalRay,
        distance_m: f32,
        sun_visibility: impl FnMut(f32) -> f32,
    ) -> (Vec3, Vec3) {
        let step_m = AERIAL_SLICE_M / AERIAL_STEPS_PER_SLICE as f32;
        let steps = (distance_m / step_m).ceil().max(1.0) as u32;
        let span = (0.0, distance_m);
        self.scattered_along(ray, span, steps, Spacing::Uniform, sun_visibility)
    }

    /// The sky irradiance table: layer 0 the irradiance on an upward surface, layer 1 the mean
    /// radiance over the upper hemisphere, by radius and sun cosine.
    pub fn irradiance_tables(&self) -> [Table2; 2] {
        let (w, h) = IRRADIANCE_SIZE;
        let at = |uv| {
            let (r, mu_s) = sun_table_r_mu(&self.air, uv, IRRADIANCE_SIZE);
            self.irradiance_at(r, mu_s)
        };
        [
            Table2::from_fn(w, h, |uv| at(uv)[0]),
            Table2::from_fn(w, h, |uv| at(uv)[1]),
        ]
    }

    /// Irradiance on an upward surface at radius `r` and mean radiance over the hemisphere above
    /// it, from a grid of directions uniform in cosine and azimuth (the sky is symmetric about
    /// the sun's vertical, so azimuth spans half a turn).
    pub fn irradiance_at(&self, r: f32, mu_s: f32) -> [Vec3; 2] {
        let n = IRRADIANCE_DIRECTIONS;
        let (mut irradiance, mut mean) = (Vec3::ZERO, Vec3::ZERO);
        for i in 0..n {
            let cos_zenith = (i as f32 + 0.5) / n as f32;
            for j in 0..n {
                let azimuth = PI * (j as f32 + 0.5) / n as f32;
                let ray = LocalRay::from_angles(r, mu_s, cos_zenith.asin(), azimuth);
                let t_max = self.air.distance_to_boundary(r, ray.dir.y);
                let span = (0.0, t_max);
                let radiance = self
                    .scattered_along(ray, span, IRRADIANCE_STEPS, Spacing::Quadratic, |_| 1.0)
                    .0;
                irradiance += radiance * cos_zenith;
                mean += radiance;
            }
        }
        let count = (n * n) as f32;
        [irradiance * (2.0 * PI / count), mean / count]
    }
}

/// How integration samples spread over a span.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spacing {
    /// Evenly.
    Uniform,
    /// As `x^2`: dense near the start, where the eye is and the air is densest (Hillaire 2020
    /// spaces the sky view's samples non-uniformly for the same reason).
    Quadratic,
}

impl Spacing {
    /// The distance at fraction `x` of `span`.
    pub fn at(self, span: (f32, f32), x: f32) -> f32 {
        let x = match self {
            Spacing::Uniform => x,
            Spacing::Quadratic => x * x,
        };
        span.0 + (span.1 - span.0) * x
    }
}

/// Hermite step from 0 at `edge0` to 1 at `edge1`, as WGSL's `smoothstep`.
fn smoothstep(edge0: f32, edge1: f32, x: f32) -> f32 {
    if edge1 <= edge0 {
        return if x >= edge0 { 1.0 } else { 0.0 };
    }
    let t = ((x - edge0) / (edge1 - edge0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}
