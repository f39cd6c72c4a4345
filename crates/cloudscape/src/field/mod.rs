//! The cloud field: extinction (m^-1) at every point of the world and time, from a [`Scene`].
//!
//! This CPU implementation is the specification. `field.wgsl` is its GPU twin, and tests sample both
//! at the same points. Density follows Schneider 2015 ("The Real-time Volumetric Cloudscapes of
//! Horizon Zero Dawn", SIGGRAPH Advances): weather coverage, a per-type height gradient, a
//! Perlin-Worley base shape and Worley detail erosion, with curl noise displacing the detail.

pub mod brick;
pub mod gpu;
pub mod hiheight;
mod layer;
pub mod noise;
mod noise_cache;
mod placed;
pub mod profile;
pub mod read_gpu;
mod reader;
mod shared;
pub mod sparse;
pub(crate) mod texture;
#[cfg(feature = "vdb")]
pub mod vdb;
mod vol_file;
pub mod voxel;
pub mod weather;

pub use brick::BrickGrid;
pub use layer::{DetailStatistics, LayerField};
pub use noise::NoiseKind;
pub use placed::{FileGrid, PlacedVolume};
pub use reader::{CoarseFieldReader, CpuCoarseReader};
pub use texture::Texture8;
pub use voxel::VoxelGrid;
pub use weather::Weather;

pub use crate::scene::MAX_LAYERS;

use crate::scene::{NoiseSettings, PlanetShape, Scene};
use glam::{Vec2, Vec3, Vec4};
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

/// `(sqrt(5) - 1) / 2`: successive multiples modulo 1 spread evenly (Weyl's sequence), so the
/// segments of a light path sample decorrelated offsets.
pub const GOLDEN_RATIO_CONJUGATE: f32 = 0.618034;

/// Most voxel grids one field holds.
pub const MAX_VOLUMES: usize = 4;

/// A field that could not be built: which scene key is at fault, and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{key_path}: {message}")]
pub struct FieldError {
    /// Dotted key path in the scene ("weather.path", "volumes.0.path").
    pub key_path: String,
    /// What went wrong.
    pub message: String,
}

/// Which density: eroded by the detail noise, its mean over the noise, or uneroded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Detail {
    Eroded,
    Mean,
    Coarse,
}

/// Where the planet's ground is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanetGeometry {
    /// Spherical or flat.
    pub shape: PlanetShape,
    /// Radius of the spherical planet, metres.
    pub radius_m: f32,
}

impl PlanetGeometry {
    /// The ground a scene's `[planet]` describes.
    pub fn from_scene(planet: &crate::scene::Planet) -> PlanetGeometry {
        PlanetGeometry {
            shape: planet.shape,
            radius_m: planet.radius_m,
        }
    }

    /// Ray parameters `(t0, t1)` between which the line `origin + t dir` is below altitude
    /// `altitude_m` (inside the sphere of radius `R + h`, or under the plane `y = h`); infinite ends
    /// for a flat planet. None when it never is. In f64: `field_below` in `field.wgsl` is the f32
    /// twin, with a huge finite distance for the infinite ends and an empty interval for None.
    pub fn below(&self, origin: Vec3, dir: Vec3, altitude_m: f32) -> Option<(f64, f64)> {
        let (o, d, h) = (origin.as_dvec3(), dir.as_dvec3(), f64::from(altitude_m));
        match self.shape {
            PlanetShape::Flat => {
                if d.y.abs() < 1e-12 {
                    return (o.y < h).then_some((f64::NEG_INFINITY, f64::INFINITY));
                }
                let t = (h - o.y) / d.y;
                Some(if d.y > 0.0 {
                    (f64::NEG_INFINITY, t)
                } else {
                    (t, f64::INFINITY)
                })
            }
            PlanetShape::Spherical => {
                let r = f64::from(self.radius_m);
                let b = o.dot(d) + d.y * r;
                // |o - c|^2 - (R + h)^2 without cancellation: |o|^2 + 2 o.y R - h (2 R + h).
                let c = o.length_squared() + 2.0 * o.y * r - h * (2.0 * r + h);
                let disc = b * b - c;
                if disc < 0.0 {
                    return None;
                }
                let s = disc.sqrt();
                Some((-b - s, -b + s))
            }
        }
    }

    /// Altitude of `p` above the ground, metres. For the sphere (centre `(0, -R, 0)`) this is
    /// `(|p|^2 + 2 y R) / (|p - c| + R)`, algebraically `|p - c| - R` but free of the cancellation
    /// that loses metres in f32 at R = 6360 km.
    pub fn altitude_m(&self, p: Vec3) -> f32 {
        match self.shape {
            PlanetShape::Flat => p.y,
            PlanetShape::Spherical => {
                let r = self.radius_m;
                let to_centre = Vec3::new(p.x, p.y + r, p.z).length();
                (p.length_squared() + 2.0 * p.y * r) / (to_centre + r)
            }
        }
    }
}

/// The 3D noise a field samples: computed texel by texel on demand, or baked once for heavy use.
#[derive(Debug)]
struct NoiseSource {
    kind: NoiseKind,
    seed: u32,
    baked: OnceLock<Arc<Texture8>>,
}

impl NoiseSource {
    fn new(kind: NoiseKind, seed: u32) -> NoiseSource {
        NoiseSource {
            kind,
            seed,
            baked: OnceLock::new(),
        }
    }

    fn sample(&self, uvw: Vec3) -> Vec4 {
        match self.baked.get() {
            Some(t) => t.sample(uvw),
            None => texture::sample_linear(self.kind.dims(), uvw, |t| {
                texture::unorm8(self.kind.texel(self.seed, t))
            }),
        }
    }

    fn bake(&self) {
        self.baked.get_or_init(|| shared_bake(self.kind, self.seed));
    }
}

/// The baked noise of `kind` and `seed`, shared by every field that holds it at once.
fn shared_bake(kind: NoiseKind, seed: u32) -> Arc<Texture8> {
    static CACHE: shared::SharedCache<(NoiseKind, u32), Texture8> = shared::SharedCache::new();
    let baked: Result<_, std::convert::Infallible> =
        CACHE.get_or_make((kind, seed), || Ok(kind.bake(seed)));
    baked.unwrap_or_else(|never| match never {})
}

/// Every cloud of a scene, as extinction over space and time.
#[derive(Debug)]
pub struct CloudField {
    /// The planet under the layers.
    pub planet: PlanetGeometry,
    /// Cloud layers, bottom-up as in the scene.
    pub layers: Vec<LayerField>,
    /// The weather map all layers read (each at its own offset).
    pub weather: Weather,
    /// Noise periods and erosion.
    pub noise: NoiseSettings,
    /// Voxel grids.
    pub volumes: Vec<PlacedVolume>,
    base: NoiseSource,
    detail: NoiseSource,
    curl: NoiseSource,
    detail_statistics: OnceLock<layer::DetailStatistics>,
}

impl CloudField {
    /// Builds the field of `scene`; files (weather PNG, `.vol` and `.vdb` grids) resolve against
    /// `base_dir`.
    pub fn new(scene: &Scene, base_dir: &Path) -> Result<CloudField, FieldError> {
        let err = |key: &str, message: String| FieldError {
            key_path: key.to_string(),
            message,
        };
        if scene.layers.len() > MAX_LAYERS {
            return Err(err(
                "layers",
                format!(
                    "{} layers given; at most {MAX_LAYERS} are supported",
                    scene.layers.len()
                ),
            ));
        }
        if scene.volumes.len() > MAX_VOLUMES {
            return Err(err(
                "volumes",
                format!(
                    "{} volumes given; at most {MAX_VOLUMES} are supported",
                    scene.volumes.len()
                ),
            ));
        }
        let resolve = |p: &str| -> PathBuf { base_dir.join(p) };
        let weather_file = scene.weather.path.as_deref().map(resolve);
        let weather = Weather::from_scene(&scene.weather, weather_file.as_deref())
            .map_err(|m| err("weather.path", m))?;
        let volumes = scene
            .volumes
            .iter()
            .enumerate()
            .map(|(i, v)| {
                placed::load(v, &resolve(&v.path))
                    .map_err(|(key, m)| err(&format!("volumes.{i}.{key}"), m))
            })
            .collect::<Result<Vec<_>, FieldError>>()?;
        let seed = scene.noise.seed;
        Ok(CloudField {
            planet: PlanetGeometry::from_scene(&scene.planet),
            layers: scene.layers.iter().map(LayerField::new).collect(),
            weather,
            noise: scene.noise.clone(),
            volumes,
            base: NoiseSource::new(NoiseKind::Base, seed),
            detail: NoiseSource::new(NoiseKind::Detail, seed),
            curl: NoiseSource::new(NoiseKind::Curl, seed),
            detail_statistics: OnceLock::new(),
        })
    }

    /// Computes all noise texels now (a few seconds on all cores in a release build), making every
    /// later [`CloudField::extinction_per_m`] call cheap. For CPU renderers; the GPU needs none of it.
    pub fn bake_noise(&self) {
        rayon::join(
            || self.base.bake(),
            || rayon::join(|| self.detail.bake(), || self.curl.bake()),
        );
    }

    /// Computes the base noise's texels now (the only noise [`CloudField::coarse_extinction_per_m`]
    /// reads), making later coarse evaluations cheap: for CPU work that reads the coarse field at
    /// many points (sprite clouds).
    pub fn bake_coarse_noise(&self) {
        self.base.bake();
    }

    /// The detail noise's statistics that the mean density
    /// ([`CloudField::mean_extinction_per_m`]) reads, from the baked detail noise (baked now if
    /// it is not yet: 32^3 texels).
    pub fn detail_statistics(&self) -> layer::DetailStatistics {
        *self.detail_statistics.get_or_init(|| {
            self.detail.bake();
            let baked = self.detail.baked.get().expect("baked above");
            layer::DetailStatistics::of(baked)
        })
    }

    /// Seed of the noise textures (the GPU generates them from it).
    pub fn noise_seed(&self) -> u32 {
        self.base.seed
    }

    /// Extinction coefficient sigma_t in m^-1 at world point `p` (metres) at scene time `time_s`:
    /// the sum over layers and voxel grids.
    pub fn extinction_per_m(&self, p: Vec3, time_s: f32) -> f32 {
        self.extinction(p, time_s, Detail::Eroded)
    }

    /// Extinction without the detail erosion: the cheap density Schneider 2015 uses for light paths,
    /// and an upper bound of [`CloudField::extinction_per_m`] (erosion only removes density).
    pub fn coarse_extinction_per_m(&self, p: Vec3, time_s: f32) -> f32 {
        self.extinction(p, time_s, Detail::Coarse)
    }

    /// The eroded extinction's mean over the detail noise ([`layer::mean_erode`]): the density
    /// light paths read, as smooth as the coarse one and without its excess.
    pub fn mean_extinction_per_m(&self, p: Vec3, time_s: f32) -> f32 {
        self.extinction(p, time_s, Detail::Mean)
    }

    /// Optical depth of the coarse field along `p + t dir` over `t` in `[start_m, start_m +
    /// length_m]`, from `n` segments whose lengths grow by `growth` from one to the next (2:
    /// Schneider 2015's doubling light samples, fine near `p`; 1: uniform), each sampled at a point
    /// offset by `jitter` and decorrelated from the others by the golden ratio: the cloud shadow
    /// map's columns, `field_optical_depth_coarse` in `field.wgsl`.
    pub fn coarse_optical_depth(
        &self,
        ray: (Vec3, Vec3),
        span: (f32, f32, f32),
        samples: (u32, f32),
        time_s: f32,
    ) -> f32 {
        self.optical_depth(Detail::Coarse, ray, span, samples, time_s)
    }

    /// [`CloudField::coarse_optical_depth`] through the mean density
    /// ([`CloudField::mean_extinction_per_m`]): the light paths of the ray marcher and the light
    /// volume, `field_optical_depth_mean` in `field.wgsl`.
    pub fn mean_optical_depth(
        &self,
        ray: (Vec3, Vec3),
        span: (f32, f32, f32),
        samples: (u32, f32),
        time_s: f32,
    ) -> f32 {
        self.optical_depth(Detail::Mean, ray, span, samples, time_s)
    }

    fn optical_depth(
        &self,
        detail: Detail,
        (p, dir): (Vec3, Vec3),
        (start_m, length_m, growth): (f32, f32, f32),
        (n, jitter): (u32, f32),
        time_s: f32,
    ) -> f32 {
        let total = if growth == 1.0 {
            n as f32
        } else {
            (growth.powi(n as i32) - 1.0) / (growth - 1.0)
        };
        let (mut width, mut start, mut tau) = (length_m / total, start_m, 0.0);
        for k in 0..n {
            let offset = (jitter + (k + 1) as f32 * GOLDEN_RATIO_CONJUGATE).fract();
            tau += self.extinction(p + dir * (start + width * offset), time_s, detail) * width;
            start += width;
            width *= growth;
        }
        tau
    }

    /// Lowest and highest world heights of the clouds at the origin, and whether there are any.
    pub(crate) fn cloud_heights(&self) -> (f32, f32, bool) {
        let layers = self.altitude_range_m();
        let volumes = self
            .volumes
            .iter()
            .map(|v| (v.min_m.y, v.min_m.y + v.size_m.y))
            .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)));
        match (layers, volumes) {
            (Some(l), Some(v)) => (l.0.min(v.0), l.1.max(v.1), true),
            (Some(r), None) | (None, Some(r)) => (r.0, r.1, true),
            (None, None) => (0.0, 1.0, false),
        }
    }

    /// Optical depth of the coarse field straight up from `p` to the top of the clouds at scene
    /// time `time_s` (0 above them): the clouds over a point, from 32 uniform segments, as the
    /// cloud shadow map's sky column reads it.
    pub fn coarse_optical_depth_above(&self, p: Vec3, time_s: f32) -> f32 {
        let (bottom_m, top_m, any) = self.cloud_heights();
        let start_m = (bottom_m - p.y).max(0.0);
        let length_m = top_m - p.y - start_m;
        if !any || length_m <= 0.0 {
            return 0.0;
        }
        self.coarse_optical_depth((p, Vec3::Y), (start_m, length_m, 1.0), (32, 0.5), time_s)
    }

    fn extinction(&self, p: Vec3, time_s: f32, detail: Detail) -> f32 {
        let h = self.planet.altitude_m(p);
        let layers: f32 = self
            .layers
            .iter()
            .map(|l| self.layer_extinction(l, p, h, time_s, detail))
            .sum();
        layers
            + self
                .volumes
                .iter()
                .map(|v| v.extinction_per_m(p))
                .sum::<f32>()
    }

    /// Lowest layer bottom and highest layer top, metres (None without layers).
    pub fn altitude_range_m(&self) -> Option<(f32, f32)> {
        let bottom = self.layers.iter().map(|l| l.bottom_m).reduce(f32::min)?;
        let top = self
            .layers
            .iter()
            .map(|l| l.bottom_m + l.thickness_m)
            .reduce(f32::max)?;
        Some((bottom, top))
    }

    /// One layer's extinction at `p`, altitude `h`. Each line has a twin in `field.wgsl`.
    fn layer_extinction(
        &self,
        layer: &LayerField,
        p: Vec3,
        h: f32,
        time_s: f32,
        detail: Detail,
    ) -> f32 {
        let f = (h - layer.bottom_m) / layer.thickness_m;
        if !(0.0..=1.0).contains(&f) {
            return 0.0;
        }
        let wind = layer.wind_m_per_s * time_s;
        let xz = Vec2::new(p.x, p.z) - wind;
        let w = self
            .weather
            .texture
            .sample((xz / self.weather.extent_m + layer.weather_offset).extend(0.0));
        let coverage = layer.local_coverage(w.x);
        if coverage <= 0.0 {
            return 0.0;
        }
        let type_coord = layer.types.type_coord(w.y);
        let gradient = profile::height_gradient(type_coord, f);
        if gradient <= 0.0 {
            return 0.0;
        }
        let q = p - Vec3::new(wind.x, 0.0, wind.y) + layer.noise_offset_m;
        let base = self.base.sample(q / self.noise.base_period_m);
        let shaped = layer::base_shape(base) * gradient;
        let covered = layer::apply_coverage(shaped, coverage, type_coord, f);
        if covered <= 0.0 {
            return 0.0;
        }
        match detail {
            Detail::Coarse => return covered.min(1.0) * w.z * layer.extinction_per_m,
            Detail::Mean => {
                let noise = self.detail_statistics();
                let mean = layer::mean_erode(covered.min(1.0), f, self.noise.detail_erosion, noise);
                return mean * w.z * layer.extinction_per_m;
            }
            Detail::Eroded => {}
        }
        let curl = self
            .curl
            .sample(Vec3::new(q.x, q.z, 0.0) / self.noise.base_period_m);
        let swirl =
            (Vec2::new(curl.x, curl.y) * 2.0 - 1.0) * self.noise.curl_displacement_m * (1.0 - f);
        let detail = self
            .detail
            .sample((q + Vec3::new(swirl.x, 0.0, swirl.y)) / self.noise.detail_period_m);
        let density = layer::erode(covered, detail, f, self.noise.detail_erosion);
        density * w.z * layer.extinction_per_m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_baked_while_held_is_shared_and_freed_with_its_last_holder() {
        let first = shared_bake(NoiseKind::Curl, 11);
        let second = shared_bake(NoiseKind::Curl, 11);
        assert!(Arc::ptr_eq(&first, &second));
        assert!(!Arc::ptr_eq(&first, &shared_bake(NoiseKind::Curl, 12)));
        let weak = Arc::downgrade(&first);
        drop((first, second));
        assert!(weak.upgrade().is_none());
    }
}
