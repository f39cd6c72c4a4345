//! The hierarchical height map ("hi-height", the volumecloud seed, after hi-Z screen-space
//! reflections): per weather-map cell and layer, the highest altitude at which that layer can hold
//! any cloud, and a 2x2 max pyramid of it, so rays skip the empty space above the clouds.
//!
//! A cell is the square between four weather texel centres: every point in it filters exactly those
//! four texels. Density is positive only where `gradient(f) * shape > 1 - c` (see
//! [`super::layer::apply_coverage`]) and the base shape never exceeds 1 while erosion only removes
//! density, so `gradient(f) > 1 - c` bounds the cloud from above; taking the cell's largest coverage
//! and its whole type range keeps the bound conservative.

use super::layer::LayerField;
use super::profile::height_gradient;
use super::{CloudField, MAX_LAYERS};
use rayon::prelude::*;

/// Altitude stored where a layer can hold no cloud at all.
pub const NO_CLOUD_M: f32 = -1.0e9;
/// Steps of the height-fraction scan that finds each top (the top is rounded up to the next step).
const HEIGHT_STEPS: u32 = 128;

/// One level of the pyramid: `width * height` cells of per-layer tops (metres).
#[derive(Clone, Debug, PartialEq)]
pub struct HiHeightLevel {
    /// Cells along x.
    pub width: u32,
    /// Cells along z.
    pub height: u32,
    /// Highest possible cloud altitude per layer (up to four), or [`NO_CLOUD_M`].
    pub tops_m: Vec<[f32; MAX_LAYERS]>,
}

/// The pyramid, finest level first (level 0 has one cell per weather texel).
#[derive(Clone, Debug, PartialEq)]
pub struct HiHeight {
    /// Levels from the weather map's resolution down to 1 x 1.
    pub levels: Vec<HiHeightLevel>,
}

impl HiHeight {
    /// Builds the pyramid of a field's layers over its weather map.
    pub fn new(field: &CloudField) -> HiHeight {
        let mut levels = vec![base_level(field)];
        while levels.last().is_some_and(|l| l.width > 1 || l.height > 1) {
            levels.push(reduce(levels.last().expect("non-empty")));
        }
        HiHeight { levels }
    }

    /// Every level's cells back to back (finest first) and, per level, (first cell, width, height):
    /// the layout `hiheight.wgsl` reads.
    pub fn packed(&self) -> (Vec<[f32; MAX_LAYERS]>, Vec<[u32; 3]>) {
        let mut cells = Vec::new();
        let mut table = Vec::new();
        for l in &self.levels {
            table.push([cells.len() as u32, l.width, l.height]);
            cells.extend_from_slice(&l.tops_m);
        }
        (cells, table)
    }

    /// Top of layer `layer` over level-0 cell `(x, z)` (wrapped).
    pub fn top_m(&self, layer: usize, x: i32, z: i32) -> f32 {
        let l = &self.levels[0];
        let (w, h) = (l.width as i32, l.height as i32);
        l.tops_m[(z.rem_euclid(h) * w + x.rem_euclid(w)) as usize][layer]
    }
}

fn base_level(field: &CloudField) -> HiHeightLevel {
    let dims = field.weather.texture.dims;
    let (w, h) = (dims.x as i32, dims.y as i32);
    let tops_m = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (x, z) = (i % w, i / w);
            let corners = [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(dx, dz)| {
                field
                    .weather
                    .texture
                    .fetch(glam::IVec3::new(x + dx, z + dz, 0))
            });
            let mut tops = [NO_CLOUD_M; MAX_LAYERS];
            for (top, layer) in tops.iter_mut().zip(&field.layers) {
                let coverage = corners
                    .iter()
                    .map(|c| layer.local_coverage(c.x))
                    .fold(0.0, f32::max);
                let (lo, hi) = corners.iter().fold((f32::MAX, f32::MIN), |(lo, hi), c| {
                    (lo.min(c.y), hi.max(c.y))
                });
                *top = layer_top_m(
                    layer,
                    coverage,
                    (layer.types.type_coord(lo), layer.types.type_coord(hi)),
                );
            }
            tops
        })
        .collect();
    HiHeightLevel {
        width: dims.x,
        height: dims.y,
        tops_m,
    }
}

/// Highest altitude where `layer` can be cloudy given a coverage of at most `coverage` and type
/// coordinates in `types` (the type table is monotone, so its range maps to this interval).
pub fn layer_top_m(layer: &LayerField, coverage: f32, types: (f32, f32)) -> f32 {
    if coverage <= 0.0 {
        return NO_CLOUD_M;
    }
    // The gradient's parameters are linear in the type between integer anchors, and the gradient at
    // a fixed height is monotone in each parameter, so its maximum over a type range is at the
    // range's ends or at an anchor inside it.
    let anchors = (types.0.ceil() as i32..=types.1.floor() as i32).map(|a| a as f32);
    let candidates: Vec<f32> = [types.0, types.1].into_iter().chain(anchors).collect();
    // The anvil widens coverage to at most c^0.5 (field::layer::apply_coverage).
    let widened = if types.1 > 2.0 {
        coverage.sqrt()
    } else {
        coverage
    };
    let top_step = (0..=HEIGHT_STEPS).rev().find(|&k| {
        let f = k as f32 / HEIGHT_STEPS as f32;
        let c = if f >= 0.7 { widened } else { coverage };
        candidates.iter().any(|&t| height_gradient(t, f) > 1.0 - c)
    });
    match top_step {
        None => NO_CLOUD_M,
        Some(k) => {
            layer.bottom_m
                + layer.thickness_m * ((k + 1).min(HEIGHT_STEPS) as f32 / HEIGHT_STEPS as f32)
        }
    }
}

/// The next level: each cell is the max of the (up to) 2x2 cells below it.
fn reduce(level: &HiHeightLevel) -> HiHeightLevel {
    let (w, h) = (level.width.div_ceil(2), level.height.div_ceil(2));
    let tops_m = (0..w * h)
        .map(|i| {
            let (x, z) = (i % w, i / w);
            let mut top = [NO_CLOUD_M; MAX_LAYERS];
            for (dx, dz) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let (cx, cz) = (
                    (2 * x + dx).min(level.width - 1),
                    (2 * z + dz).min(level.height - 1),
                );
                let cell = level.tops_m[(cz * level.width + cx) as usize];
                top.iter_mut().zip(cell).for_each(|(t, c)| *t = t.max(c));
            }
            top
        })
        .collect();
    HiHeightLevel {
        width: w,
        height: h,
        tops_m,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;
    use glam::{Vec2, Vec3};

    fn field(resolution: u32) -> CloudField {
        let mut scene = Scene::default();
        scene.weather.resolution = resolution;
        scene.weather.extent_km = resolution as f32 * 0.125;
        CloudField::new(&scene, std::path::Path::new(".")).expect("field")
    }

    #[test]
    fn no_cloud_is_ever_above_its_cell_top() {
        let f = field(24);
        let hi = HiHeight::new(&f);
        let layer = &f.layers[0];
        let mut cloudy = 0;
        for i in 0..4000u32 {
            let u = |k: u32| {
                super::super::noise::hash_to_unit(super::super::noise::pcg_hash(i * 3 + k))
            };
            let p = Vec3::new(
                u(0) * 3000.0,
                layer.bottom_m + u(1) * layer.thickness_m,
                u(2) * 3000.0,
            );
            if f.extinction_per_m(p, 0.0) <= 0.0 {
                continue;
            }
            cloudy += 1;
            // The cell of p: between the texel centres around its weather coordinate.
            let uv = Vec2::new(p.x, p.z) / f.weather.extent_m + layer.weather_offset;
            let texel =
                uv * Vec2::new(
                    f.weather.texture.dims.x as f32,
                    f.weather.texture.dims.y as f32,
                ) - 0.5;
            let top = hi.top_m(0, texel.x.floor() as i32, texel.y.floor() as i32);
            assert!(p.y <= top, "cloud at {p} above its cell's top {top}");
        }
        assert!(cloudy > 100, "only {cloudy} cloudy points tested");
    }

    #[test]
    fn pyramid_levels_hold_the_max_of_their_children_for_any_size() {
        let hi = HiHeight::new(&field(13));
        let sizes: Vec<u32> = hi.levels.iter().map(|l| l.width).collect();
        assert_eq!(sizes, [13, 7, 4, 2, 1]);
        let finest_max = hi.levels[0]
            .tops_m
            .iter()
            .map(|t| t[0])
            .fold(f32::MIN, f32::max);
        assert_eq!(hi.levels.last().expect("levels").tops_m[0][0], finest_max);
        let (l0, l1) = (&hi.levels[0], &hi.levels[1]);
        assert!(
            l1.tops_m[6 * 7 + 6][0] >= l0.tops_m[12 * 13 + 12][0],
            "odd edge cells are covered"
        );
    }

    #[test]
    fn tops_are_below_the_layer_top_and_follow_coverage() {
        let layer = LayerField::new(&crate::scene::CloudLayer::default());
        let top = |c| layer_top_m(&layer, c, (2.0, 2.0));
        assert_eq!(top(0.0), NO_CLOUD_M);
        assert!(top(0.2) < top(0.5) && top(0.5) <= layer.bottom_m + layer.thickness_m);
    }
}
