//! The 3D scattering tables of the reference particle (Yusov 2014, "Pre-computing scattering"):
//! for the spherically symmetric particle ([`SymmetricParticle`]) lit by a directional light of
//! unit irradiance, the radiance leaving each point of its surface toward each outward direction,
//! by three angles:
//!
//! - the entry angle `theta_e` between the surface normal and the direction to the light (0 on
//!   the sunlit face, pi on the far side), over [0, pi];
//! - the view zenith between the outgoing ray and the normal, over [0, pi / 2];
//! - the view azimuth about the normal, from the tangent that points away from the light's
//!   sub-point, over [0, pi] (the field is mirror-symmetric).
//!
//! Two tables: **single** scattering without its phase function, `S = albedo * integral of
//! sigma exp(-tau_view - tau_light) ds` (the scattering angle is constant along a view ray, so
//! the phase function is applied exactly at look-up: `L_1 = E p(mu) S`); and **multiple**
//! scattering, orders 2 and up, in sr^-1 (`L_ms = E M`), from [`orders::multiple_scattering`].
//! Run time: `L = E (p(mu) S + M)` per light.

pub(crate) mod directions;
pub(crate) mod medium;
pub(crate) mod orders;

use glam::{UVec3, Vec3};
use rayon::prelude::*;
use std::f32::consts::{FRAC_PI_2, PI};

pub use medium::{SunDepth, SymmetricParticle};
pub use orders::{MultipleScattering, OrderGrid};

use crate::field::texture::sample_linear;
use crate::particles::density::{uniform_disc_point, uniform_sphere_point};

/// Sizes of the final tables.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ScatteringLayout {
    /// Entry angles over [0, pi].
    pub entry: u32,
    /// View zeniths over [0, pi / 2].
    pub view_zenith: u32,
    /// View azimuths over [0, pi].
    pub view_azimuth: u32,
}

impl ScatteringLayout {
    /// 64 entry angles x 32 view zeniths x 32 view azimuths: 64 K entries, two 16-bit tables in
    /// 256 KiB (Yusov's are 32 x 16 x 64).
    pub const DEFAULT: ScatteringLayout = ScatteringLayout {
        entry: 64,
        view_zenith: 32,
        view_azimuth: 32,
    };

    /// Width (view azimuth), height (view zenith) and depth (entry angle) of the 3D texture.
    pub fn texture_dims(&self) -> UVec3 {
        UVec3::new(self.view_azimuth, self.view_zenith, self.entry)
    }

    /// Entries per table.
    pub fn len(&self) -> usize {
        (self.entry * self.view_zenith * self.view_azimuth) as usize
    }

    /// Whether the tables are empty (never, for a valid layout).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The surface point and outgoing direction of texel `t`, in the particle's light frame
    /// (light travelling along `+z`, the point in the `x-z` half plane `x >= 0`).
    pub fn texel_ray(&self, t: UVec3) -> (Vec3, Vec3) {
        let entry = (t.z as f32 + 0.5) / self.entry as f32 * PI;
        let zenith = (t.y as f32 + 0.5) / self.view_zenith as f32 * FRAC_PI_2;
        let azimuth = (t.x as f32 + 0.5) / self.view_azimuth as f32 * PI;
        let (se, ce) = entry.sin_cos();
        let normal = Vec3::new(se, 0.0, -ce);
        let tangent = Vec3::new(ce, 0.0, se);
        let (sz, cz) = zenith.sin_cos();
        let (sa, ca) = azimuth.sin_cos();
        let out = cz * normal + sz * (ca * tangent + sa * Vec3::Y);
        (normal, out)
    }
}

/// The two tables, in texture order (x fastest).
#[derive(Clone, Debug, PartialEq)]
pub struct ScatteringTables {
    /// Their dimensions.
    pub layout: ScatteringLayout,
    /// Single scattering without the phase function, 0..1.
    pub single: Vec<f32>,
    /// Multiple scattering per unit irradiance, sr^-1.
    pub multiple: Vec<f32>,
}

/// What a bake did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BakeReport {
    /// Orders computed before the geometric tail.
    pub orders: u32,
    /// Ratio of the last two orders' power.
    pub last_order_ratio: f32,
}

/// What a bake reports as it goes: a stage name and its fraction done.
pub type Progress<'a> = &'a mut dyn FnMut(&str, f32);

impl ScatteringTables {
    /// Bakes both tables for `particle` at `layout`, with the orders on `grid`.
    pub fn bake(
        particle: &SymmetricParticle,
        layout: ScatteringLayout,
        grid: OrderGrid,
        progress: Progress,
    ) -> (ScatteringTables, BakeReport) {
        let sun = SunDepth::new(particle);
        let ms = orders::multiple_scattering(particle, grid, &sun, &mut |order| {
            let fraction = order as f32 / (order as f32 + 4.0);
            progress("scattering orders", fraction)
        });
        progress("final tables", 0.0);
        let dims = layout.texture_dims();
        let steps = 2 * grid.steps_per_radius;
        let pairs: Vec<(f32, f32)> = (0..layout.len())
            .into_par_iter()
            .map(|i| {
                let i = i as u32;
                let t = UVec3::new(i % dims.x, (i / dims.x) % dims.y, i / (dims.x * dims.y));
                let (point, out) = layout.texel_ray(t);
                let single =
                    orders::integrate_back(particle, point, out, steps, |q| (-sun.at(q)).exp())
                        * particle.albedo;
                let multiple = orders::integrate_back(particle, point, out, steps, |q| {
                    ms.source.sample(q, out)
                });
                (single, multiple)
            })
            .collect();
        progress("final tables", 1.0);
        let (single, multiple) = pairs.into_iter().unzip();
        let report = BakeReport {
            orders: ms.orders,
            last_order_ratio: ms.ratio,
        };
        (
            ScatteringTables {
                layout,
                single,
                multiple,
            },
            report,
        )
    }

    /// `(S, M)` for light leaving the unit sphere at `point` along `out` (unit, away from the
    /// particle, toward the eye), lit from the direction `to_light` (unit, toward the light):
    /// linear in all three angles, clamped at the ends, as a GPU sampler reads the texture.
    pub fn lookup(&self, point: Vec3, out: Vec3, to_light: Vec3) -> (f32, f32) {
        let uvw = self.texture_coordinates(point, out, to_light);
        let dims = self.layout.texture_dims();
        let fetch = |t: glam::IVec3| {
            let c = t.clamp(glam::IVec3::ZERO, dims.as_ivec3() - 1).as_uvec3();
            let i = (c.x + dims.x * (c.y + dims.y * c.z)) as usize;
            glam::Vec4::new(self.single[i], self.multiple[i], 0.0, 0.0)
        };
        let v = sample_linear(dims, uvw, fetch);
        (v.x, v.y)
    }

    /// Normalised texture coordinates of a look-up (see [`Self::lookup`]).
    fn texture_coordinates(&self, point: Vec3, out: Vec3, to_light: Vec3) -> Vec3 {
        let n = point.normalize();
        let cos_entry = n.dot(to_light).clamp(-1.0, 1.0);
        let away = n * cos_entry - to_light;
        let tangent = if away.length_squared() > 1e-12 {
            away.normalize()
        } else {
            n.any_orthonormal_vector()
        };
        let bitangent = n.cross(tangent);
        let zenith = out.dot(n).clamp(0.0, 1.0).acos();
        let azimuth = out.dot(bitangent).abs().atan2(out.dot(tangent));
        Vec3::new(azimuth / PI, zenith / FRAC_PI_2, cos_entry.acos() / PI)
    }
}

/// Where the light falling on the particle goes, as fractions of the light intercepted by its
/// cross-section (they sum to 1 without absorption).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnergyBalance {
    /// Scattered once and leaving the particle.
    pub single: f32,
    /// Scattered more than once and leaving the particle.
    pub multiple: f32,
    /// Crossing the particle unscattered.
    pub transmitted: f32,
}

impl EnergyBalance {
    /// Everything leaving the particle.
    pub fn total(&self) -> f32 {
        self.single + self.multiple + self.transmitted
    }
}

impl ScatteringTables {
    /// Integrates the tables' outgoing radiance over the whole surface and every outgoing
    /// direction, by quasi-Monte Carlo with `samples` points: for each direction `w`, the light
    /// leaving along `w` integrated over the particle's cross-section perpendicular to `w`.
    /// Single scattering draws `w` from the phase function, multiple scattering uniformly.
    pub fn energy_balance(&self, particle: &SymmetricParticle, samples: u32) -> EnergyBalance {
        let sun = SunDepth::new(particle);
        let light = Vec3::Z;
        let (mut single, mut multiple, mut transmitted) = (0.0f64, 0.0f64, 0.0f64);
        for i in 0..samples {
            let u = |k: usize| ((i as f64 + 0.5) * KRONECKER[k]).fract() as f32;
            let disc = uniform_disc_point(glam::Vec2::new(u(0), u(1)));
            let phase_dir = particle.phase.sample(light, Vec3::new(u(2), u(3), u(4)));
            let uniform_dir = uniform_sphere_point(glam::Vec2::new(u(2), u(3)));
            single += f64::from(self.exit_lookup(disc, phase_dir, light).0);
            multiple += f64::from(self.exit_lookup(disc, uniform_dir, light).1);
            let exit = Vec3::new(
                disc.x,
                disc.y,
                (1.0 - disc.length_squared()).max(0.0).sqrt(),
            );
            transmitted += f64::from((-sun.at(exit)).exp());
        }
        let n = f64::from(samples);
        EnergyBalance {
            single: (single / n) as f32,
            multiple: (4.0 * f64::from(PI) * multiple / n) as f32,
            transmitted: (transmitted / n) as f32,
        }
    }

    /// The tables at the point where the line through cross-section point `disc` (in the plane
    /// perpendicular to `dir`) leaves the sphere along `dir`.
    fn exit_lookup(&self, disc: glam::Vec2, dir: Vec3, light: Vec3) -> (f32, f32) {
        let a = dir.any_orthonormal_vector();
        let b = dir.cross(a);
        let depth = (1.0 - disc.length_squared()).max(0.0).sqrt();
        let point = a * disc.x + b * disc.y + dir * depth;
        self.lookup(point, dir, -light)
    }
}

/// Fractional parts of square roots of primes: a Kronecker sequence per dimension.
const KRONECKER: [f64; 5] = [
    std::f64::consts::SQRT_2,
    1.732_050_807_568_877_2,
    2.236_067_977_499_79,
    2.645_751_311_064_590_6,
    3.316_624_790_355_4,
];
