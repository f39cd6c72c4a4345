//! The weather map: per position, cloud coverage (R), cloud type (G, a position in the layer's type
//! mix) and density (B), repeating over a square of `extent_km` (VolumeCloud and Schneider 2015 use
//! the same three channels).

use super::noise::{hash_to_unit, pcg_hash, perlin};
use super::texture::Texture8;
use crate::scene::{WeatherMap, WeatherSource};
use glam::{UVec3, Vec2, Vec3};
use rayon::prelude::*;
use std::path::Path;

/// A weather map ready for sampling and upload.
#[derive(Clone, Debug, PartialEq)]
pub struct Weather {
    /// The texels (depth 1).
    pub texture: Texture8,
    /// World size covered by the texture before it repeats, metres (x east, z south).
    pub extent_m: Vec2,
}

impl Weather {
    /// Builds the map a scene describes; a file map is read from `file` (already resolved), a PNG
    /// that needs the cargo feature `png`.
    pub fn from_scene(map: &WeatherMap, file: Option<&Path>) -> Result<Weather, String> {
        let extent = map.extent_km * 1000.0;
        match (map.source, file) {
            (WeatherSource::File, Some(path)) => {
                let texture = read_png(path)?;
                let aspect = texture.dims.y as f32 / texture.dims.x as f32;
                Ok(Weather {
                    texture,
                    extent_m: Vec2::new(extent, extent * aspect),
                })
            }
            (WeatherSource::File, None) => {
                Err("weather.source = \"file\" needs weather.path".into())
            }
            (WeatherSource::Procedural, _) => {
                let cells = (map.extent_km / map.feature_size_km).round().max(1.0) as i32;
                Ok(Weather {
                    texture: procedural(map.seed, map.resolution, cells),
                    extent_m: Vec2::splat(extent),
                })
            }
        }
    }

    /// (coverage, type, density) at world position `xz` in metres, linear-filtered and repeating.
    pub fn sample(&self, xz: Vec2) -> Vec3 {
        self.texture
            .sample((xz / self.extent_m).extend(0.0))
            .truncate()
    }
}

/// Most texels along either side of a weather map file: WebGPU's guaranteed
/// `maxTextureDimension2D`, the size of the texture the map is uploaded to.
pub const MAX_WEATHER_TEXELS: u32 = 8192;
/// Most bytes the PNG decoder may allocate for one weather map: 512 MiB.
pub const MAX_WEATHER_DECODE_BYTES: u64 = 512 << 20;

/// Reads a PNG weather map file (cargo feature `png`).
fn read_png(path: &Path) -> Result<Texture8, String> {
    let bytes = std::fs::read(path)
        .map_err(|e| format!("cannot read weather map {}: {e}", path.display()))?;
    Weather::texture_from_png(&bytes, path)
}

impl Weather {
    /// Decodes the bytes of a PNG weather map (named `path` in errors) into 8-bit RGBA texels,
    /// refusing images above [`MAX_WEATHER_TEXELS`] a side or [`MAX_WEATHER_DECODE_BYTES`] of
    /// decoding before they are decoded. PNG samples are unsigned integers, so every texel is a
    /// finite value in 0..1. Needs the cargo feature `png`.
    #[cfg(feature = "png")]
    pub fn texture_from_png(bytes: &[u8], path: &Path) -> Result<Texture8, String> {
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(MAX_WEATHER_TEXELS);
        limits.max_image_height = Some(MAX_WEATHER_TEXELS);
        limits.max_alloc = Some(MAX_WEATHER_DECODE_BYTES);
        let mut reader =
            image::ImageReader::with_format(std::io::Cursor::new(bytes), image::ImageFormat::Png);
        reader.limits(limits);
        let img = reader.decode().map_err(|e| {
            format!(
                "cannot read weather map {}: {e} (a PNG of at most {MAX_WEATHER_TEXELS}x\
                 {MAX_WEATHER_TEXELS} texels is allowed)",
                path.display()
            )
        })?;
        let rgba = img.into_rgba8();
        let dims = UVec3::new(rgba.width(), rgba.height(), 1);
        let texels = rgba.pixels().map(|p| p.0).collect();
        Ok(Texture8 { dims, texels })
    }

    /// Without the `png` feature a weather map is an error that names the feature.
    #[cfg(not(feature = "png"))]
    pub fn texture_from_png(_bytes: &[u8], path: &Path) -> Result<Texture8, String> {
        Err(format!(
            "cannot read weather map {}: this build of cloudscape reads no PNG files; enable the \
             `png` cargo feature of cloudscape, or use weather.source = \"procedural\"",
            path.display()
        ))
    }
}

/// A procedural map: coverage and type are periodic Perlin fBm with `cells` features across the
/// map, histogram-equalised to a uniform 0..1 so that coverage and the type mix mean what they say;
/// density varies gently between 0.6 and 1.
pub fn procedural(seed: u32, resolution: u32, cells: i32) -> Texture8 {
    let n = resolution as usize;
    let field = |channel: u32, cells: i32| -> Vec<f32> {
        (0..n * n)
            .into_par_iter()
            .map(|i| {
                let uv = Vec2::new((i % n) as f32 + 0.5, (i / n) as f32 + 0.5) / n as f32;
                fbm2(uv, cells, seed ^ pcg_hash(channel))
            })
            .collect()
    };
    let coverage = equalise(&field(1, cells));
    let kind = equalise(&field(2, (cells / 2).max(1)));
    let density = field(3, cells * 2);
    let texels = (0..n * n)
        .map(|i| {
            let d = (0.8 + 0.4 * density[i]).clamp(0.6, 1.0);
            [coverage[i], kind[i], d, 1.0].map(super::noise::quantize_unorm8)
        })
        .collect();
    Texture8 {
        dims: UVec3::new(resolution, resolution, 1),
        texels,
    }
}

/// Four octaves of periodic 2D Perlin noise (a z = const slice of the 3D noise), about -0.5..0.5.
fn fbm2(uv: Vec2, cells: i32, seed: u32) -> f32 {
    let z = hash_to_unit(pcg_hash(seed)) * 0.5 + 0.25;
    (0..4)
        .map(|o| {
            let c = cells << o;
            perlin(
                Vec3::new(uv.x * c as f32, uv.y * c as f32, z),
                c,
                seed ^ o as u32,
            ) * 0.5f32.powi(o)
        })
        .sum::<f32>()
        / 1.875
}

/// Replaces each value by its rank / (n - 1): a uniform distribution with the same ordering.
fn equalise(values: &[f32]) -> Vec<f32> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let mut out = vec![0.0; values.len()];
    let last = (values.len().max(2) - 1) as f32;
    for (rank, &i) in order.iter().enumerate() {
        out[i] = rank as f32 / last;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn procedural_channels_are_uniform_and_tile() {
        let t = procedural(5, 64, 4);
        let cov: Vec<f32> = t.texels.iter().map(|p| p[0] as f32 / 255.0).collect();
        let below_half = cov.iter().filter(|&&c| c < 0.5).count() as f32 / cov.len() as f32;
        assert!(
            (below_half - 0.5).abs() < 0.02,
            "equalised coverage: {below_half}"
        );
        let density_min = t.texels.iter().map(|p| p[2]).min().unwrap();
        assert!(density_min as f32 / 255.0 >= 0.6 - 1e-2);
        // Opposite edges are neighbours on the torus: far closer than random pairs.
        let edge_diff: f32 = (0..64)
            .map(|y| {
                (t.fetch(glam::IVec3::new(0, y, 0)) - t.fetch(glam::IVec3::new(63, y, 0)))
                    .x
                    .abs()
            })
            .sum();
        let far_diff: f32 = (0..64)
            .map(|y| {
                (t.fetch(glam::IVec3::new(0, y, 0)) - t.fetch(glam::IVec3::new(32, y, 0)))
                    .x
                    .abs()
            })
            .sum();
        assert!(edge_diff < 0.5 * far_diff, "{edge_diff} vs {far_diff}");
    }

    #[test]
    fn an_oversized_or_broken_png_is_refused_with_its_path() {
        let too_wide = crate::image::LdrImage {
            width: MAX_WEATHER_TEXELS + 1,
            height: 1,
            pixels: vec![[0; 4]; MAX_WEATHER_TEXELS as usize + 1],
        };
        let dir = crate::fsutil::ScratchDir::new("weather-too-wide");
        let path = dir.join("wide.png");
        too_wide.write_png(&path).unwrap();
        let map = WeatherMap {
            source: WeatherSource::File,
            ..WeatherMap::default()
        };
        let err = Weather::from_scene(&map, Some(&path)).unwrap_err();
        assert!(
            err.contains("wide.png") && err.contains("8192x8192"),
            "{err}"
        );
        let bytes = std::fs::read(&path).unwrap();
        let err = Weather::texture_from_png(&bytes[..60], &path).unwrap_err();
        assert!(err.starts_with("cannot read weather map"), "{err}");
    }

    #[test]
    fn missing_file_is_a_clear_error() {
        let map = WeatherMap {
            source: WeatherSource::File,
            ..WeatherMap::default()
        };
        let err = Weather::from_scene(&map, Some(Path::new("/nonexistent/w.png"))).unwrap_err();
        assert!(err.contains("/nonexistent/w.png"), "{err}");
    }
}
