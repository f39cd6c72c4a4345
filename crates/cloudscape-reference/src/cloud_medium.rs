//! The scene's clouds as a [`Medium`]: extinction from the CPU specification of the cloud field
//! (`cloudscape::field::CloudField`, the very function the GPU techniques are tested against), and
//! conservative bounds of it over boxes, proved from the structure of the density function rather
//! than sampled.
//!
//! A layer's extinction is `density * weather_density * extinction_per_m` with `density` in
//! [0, 1] built by Schneider 2015's chain: base shape (at most 1) times the height gradient, the
//! coverage remap `1 - (1 - shaped) / c` (increasing in both), and erosion (which never adds:
//! `remap(d, m, 1, 0, 1) <= d` for `d <= 1`). So over a box the density is at most the coverage
//! remap of the largest height gradient with the largest coverage the weather map holds under the
//! box's footprint, and the weather density is at most its largest texel there.

use crate::geometry::Aabb;
use crate::medium::{Medium, Shell, Support};
use cloudscape::field::profile::TYPE_GRADIENTS;
use cloudscape::field::{CloudField, LayerField, PlacedVolume, PlanetGeometry};
use cloudscape::scene::PlanetShape;
use glam::{DVec3, IVec2, IVec3, UVec3, Vec2, Vec3, Vec4};

/// Relative margin on every bound: the field rounds in `f32`, the bound must still hold.
const BOUND_RELATIVE_MARGIN: f32 = 1e-3;
/// Absolute margin on the height gradient and the coverage before the coverage remap, which
/// divides by a coverage that may be small.
const BOUND_INPUT_MARGIN: f32 = 1e-4;
/// Margin on a box's altitude range, metres (the field's altitude is exact to millimetres).
const ALTITUDE_MARGIN_M: f64 = 0.5;

/// The clouds of a [`CloudField`] at one moment, with the box its majorant grid should cover.
pub struct CloudMedium {
    field: CloudField,
    time_s: f32,
    support: Support,
}

impl CloudMedium {
    /// The field at scene time `time_s`. The majorant grid will cover every voxel grid and the
    /// layers within `reach_m` horizontally of `focus_m` (usually the camera and its far distance);
    /// beyond, one bound per altitude band applies. Bake the field's noise first for speed.
    pub fn new(field: CloudField, time_s: f32, focus_m: Vec3, reach_m: f32) -> CloudMedium {
        let layers = field.altitude_range_m().map(|band| {
            let grid_box = layer_box(&field.planet, band, focus_m, reach_m);
            let majorant_per_m = field
                .layers
                .iter()
                .map(|l| l.extinction_per_m * max_weather_density(&field))
                .sum::<f32>()
                * (1.0 + BOUND_RELATIVE_MARGIN);
            let shell = Shell {
                planet: field.planet,
                bottom_m: band.0,
                top_m: band.1,
                majorant_per_m,
            };
            (grid_box, shell)
        });
        let volumes = field
            .volumes
            .iter()
            .map(volume_box)
            .reduce(|a, b| a.union(&b));
        let grid_box = match (layers.map(|l| l.0), volumes) {
            (Some(a), Some(b)) => a.union(&b),
            (Some(a), None) | (None, Some(a)) => a,
            (None, None) => Aabb {
                min: focus_m - 0.5,
                max: focus_m + 0.5,
            },
        };
        CloudMedium {
            field,
            time_s,
            support: Support {
                grid_box,
                shell: layers.map(|l| l.1),
            },
        }
    }

    /// The field.
    pub fn field(&self) -> &CloudField {
        &self.field
    }

    /// Bound of one layer's extinction over `b`, whose footprint has the weather bound `w`.
    fn layer_bound(&self, layer: &LayerField, w: &WeatherBound, b: &Aabb) -> f32 {
        let (h0, h1) = altitude_range(&self.field.planet, b);
        let f0 = ((h0 - layer.bottom_m) / layer.thickness_m).max(0.0);
        let f1 = ((h1 - layer.bottom_m) / layer.thickness_m).min(1.0);
        if f1 < f0 {
            return 0.0;
        }
        let coverage = layer.local_coverage(w.coverage_max);
        if coverage <= 0.0 {
            return 0.0;
        }
        let types = (
            layer.types.type_coord(w.type_min),
            layer.types.type_coord(w.type_max),
        );
        let gradient = height_gradient_bound(types, (f0, f1));
        let density = coverage_remap_bound(gradient, coverage, types.1, f1);
        density * w.density_max * layer.extinction_per_m * (1.0 + BOUND_RELATIVE_MARGIN)
    }

    /// Extremes of the weather channels over the texels a layer's lookups under `b` can touch
    /// (linear filtering reads the two texels around each coordinate).
    fn weather_bound(&self, layer: &LayerField, b: &Aabb) -> WeatherBound {
        let weather = &self.field.weather;
        let shift = layer.wind_m_per_s * self.time_s;
        let dims = weather.texture.dims.truncate().as_ivec2();
        let texel = |xz: Vec2| {
            ((xz - shift) / weather.extent_m + layer.weather_offset) * dims.as_vec2() - 0.5
        };
        let lo = texel(Vec2::new(b.min.x, b.min.z)).floor().as_ivec2();
        let hi = (texel(Vec2::new(b.max.x, b.max.z)).floor().as_ivec2() + 1).min(lo + dims - 1);
        let mut bound = WeatherBound::EMPTY;
        for y in lo.y..=hi.y {
            for x in lo.x..=hi.x {
                bound.include(weather.texture.fetch(IVec2::new(x, y).extend(0)));
            }
        }
        bound
    }
}

impl Medium for CloudMedium {
    fn extinction_per_m(&self, p: Vec3) -> f32 {
        self.field.extinction_per_m(p, self.time_s)
    }

    fn max_extinction_in_box(&self, b: &Aabb) -> f32 {
        let mut bound = [0.0];
        self.max_extinction_in_column(std::slice::from_ref(b), &mut bound);
        bound[0]
    }

    fn max_extinction_in_column(&self, cells: &[Aabb], out: &mut [f32]) {
        let Some(footprint) = cells.first() else {
            return;
        };
        let weather: Vec<WeatherBound> = self
            .field
            .layers
            .iter()
            .map(|l| self.weather_bound(l, footprint))
            .collect();
        for (cell, bound) in cells.iter().zip(out) {
            let layers: f32 = self
                .field
                .layers
                .iter()
                .zip(&weather)
                .map(|(l, w)| self.layer_bound(l, w, cell))
                .sum();
            let volumes: f32 = self
                .field
                .volumes
                .iter()
                .map(|v| volume_bound(v, cell))
                .sum();
            *bound = layers + volumes;
        }
    }

    fn support(&self) -> Support {
        self.support
    }
}

/// Extremes of the weather map's channels over some texels.
struct WeatherBound {
    coverage_max: f32,
    type_min: f32,
    type_max: f32,
    density_max: f32,
}

impl WeatherBound {
    const EMPTY: WeatherBound = WeatherBound {
        coverage_max: 0.0,
        type_min: 1.0,
        type_max: 0.0,
        density_max: 0.0,
    };

    fn include(&mut self, texel: Vec4) {
        self.coverage_max = self.coverage_max.max(texel.x);
        self.type_min = self.type_min.min(texel.y);
        self.type_max = self.type_max.max(texel.y);
        self.density_max = self.density_max.max(texel.z);
    }
}

/// The largest density texel of the weather map.
fn max_weather_density(field: &CloudField) -> f32 {
    let texels = &field.weather.texture.texels;
    f32::from(texels.iter().map(|t| t[2]).max().unwrap_or(0)) / 255.0
}

/// Altitudes `(min, max)` over the box, metres, widened by [`ALTITUDE_MARGIN_M`].
fn altitude_range(planet: &PlanetGeometry, b: &Aabb) -> (f32, f32) {
    match planet.shape {
        PlanetShape::Flat => (b.min.y - 0.5, b.max.y + 0.5),
        PlanetShape::Spherical => {
            let r = f64::from(planet.radius_m);
            let centre = DVec3::new(0.0, -r, 0.0);
            let (min, max) = (b.min.as_dvec3(), b.max.as_dvec3());
            let nearest = centre.clamp(min, max);
            let farthest =
                DVec3::select((centre - min).abs().cmpgt((centre - max).abs()), min, max);
            (
                ((nearest - centre).length() - r - ALTITUDE_MARGIN_M) as f32,
                ((farthest - centre).length() - r + ALTITUDE_MARGIN_M) as f32,
            )
        }
    }
}

/// The box holding the altitude band `(bottom, top)` within `reach_m` horizontally of `focus`:
/// on a sphere the band sinks by about `d^2 / 2R` at horizontal distance `d` from the planet's
/// axis, so the box reaches down to where the band's bottom is at its farthest corner.
fn layer_box(
    planet: &PlanetGeometry,
    (bottom, top): (f32, f32),
    focus: Vec3,
    reach_m: f32,
) -> Aabb {
    let half = Vec3::new(reach_m, 0.0, reach_m);
    let (min_xz, max_xz) = (focus - half, focus + half);
    let (y_min, y_max) = match planet.shape {
        PlanetShape::Flat => (bottom, top),
        PlanetShape::Spherical => {
            let r = f64::from(planet.radius_m);
            let corner = min_xz.abs().max(max_xz.abs()).as_dvec3();
            let axis_distance_sq = corner.x * corner.x + corner.z * corner.z;
            let sunk = ((r + f64::from(bottom)).powi(2) - axis_distance_sq)
                .max(0.0)
                .sqrt()
                - r;
            (sunk as f32, top)
        }
    };
    Aabb {
        min: Vec3::new(min_xz.x, y_min, min_xz.z),
        max: Vec3::new(max_xz.x, y_max, max_xz.z),
    }
}

/// The height-gradient parameters of type coordinate `t`, as `profile::height_gradient` blends them.
fn gradient_params(t: f32) -> [f32; 4] {
    let t = t.clamp(0.0, 3.0);
    let lo = (t.floor() as usize).min(2);
    let w = t - lo as f32;
    std::array::from_fn(|i| TYPE_GRADIENTS[lo][i] * (1.0 - w) + TYPE_GRADIENTS[lo + 1][i] * w)
}

/// Upper bound of `profile::height_gradient(t, f)` over `t` in `types` and `f` in `fractions`.
///
/// The gradient is `rise * fall`, both in [0, 1]: `rise = clamp((f - g0) / (g1 - g0))` grows with
/// `f`, `fall = clamp((g3 - f) / (g3 - g2))` shrinks with it, so their largest values are at the
/// top and at the bottom of the range. In `t` each is a ratio of linear functions between anchor
/// types (denominators positive), hence monotone there: the largest values over `t` are at the
/// ends of the range or at anchors. The product is at most the smaller of the two maxima.
fn height_gradient_bound((t0, t1): (f32, f32), (f0, f1): (f32, f32)) -> f32 {
    let anchors = [1.0, 2.0].into_iter().filter(|&a| a > t0 && a < t1);
    let (mut rise, mut fall) = (0.0f32, 0.0f32);
    for t in [t0, t1].into_iter().chain(anchors) {
        let g = gradient_params(t);
        rise = rise.max(((f1 - g[0]) / (g[1] - g[0])).clamp(0.0, 1.0));
        fall = fall.max(((g[3] - f0) / (g[3] - g[2])).clamp(0.0, 1.0));
    }
    rise.min(fall)
}

/// Upper bound of the coverage remap `1 - (1 - shaped) / c^e` (`layer::apply_coverage`) for
/// `shaped <= gradient`, local coverage at most `coverage`, type coordinate at most `type_max` and
/// height fraction at most `f_max`. The anvil exponent `e` (Schneider 2017) is 1 below 70 % of the
/// layer and at least `lerp(1, 0.5, anvil)` above; `c^e` grows as `e` shrinks.
fn coverage_remap_bound(gradient: f32, coverage: f32, type_max: f32, f_max: f32) -> f32 {
    let anvil = (type_max - 2.0).clamp(0.0, 1.0);
    let exponent = if f_max > 0.7 { 1.0 - 0.5 * anvil } else { 1.0 };
    let c = (coverage + BOUND_INPUT_MARGIN).min(1.0).powf(exponent);
    let shaped = (gradient + BOUND_INPUT_MARGIN).min(1.0);
    (1.0 - (1.0 - shaped) / c).max(0.0)
}

/// World box of a voxel grid.
pub(crate) fn volume_box(v: &PlacedVolume) -> Aabb {
    Aabb {
        min: v.min_m,
        max: v.min_m + v.size_m,
    }
}

/// Bound of a voxel grid's extinction over `b`: trilinear filtering never exceeds the largest of
/// the texels it reads (clamped to the edge, as `BrickGrid::sample`), and no texel exceeds the
/// largest of its brick.
fn volume_bound(v: &PlacedVolume, b: &Aabb) -> f32 {
    if !volume_box(v).overlaps(b) {
        return 0.0;
    }
    let n = UVec3::from_array(v.grid().resolution);
    let last = n.as_ivec3() - 1;
    let texel = |p: Vec3| {
        let uvw = ((p - v.min_m) / v.size_m).clamp(Vec3::ZERO, Vec3::ONE);
        (uvw * n.as_vec3() - 0.5)
            .floor()
            .as_ivec3()
            .clamp(IVec3::ZERO, last)
    };
    let (lo, hi) = (texel(b.min), (texel(b.max) + 1).min(last));
    let max = v.grid().max_in_voxels(lo.as_uvec3(), hi.as_uvec3());
    max * v.extinction_per_m * (1.0 + BOUND_RELATIVE_MARGIN)
}

#[cfg(test)]
mod tests {
    use super::*;
    use cloudscape::field::profile::height_gradient;

    #[test]
    fn gradient_bound_holds_on_a_dense_sample() {
        let ranges = [(0.0, 0.4), (0.9, 2.3), (1.7, 3.0), (2.0, 2.0), (0.0, 3.0)];
        for &(t0, t1) in &ranges {
            for k in 0..20 {
                let (f0, f1) = (k as f32 * 0.05, k as f32 * 0.05 + 0.07);
                let bound = height_gradient_bound((t0, t1), (f0, f1));
                for i in 0..=30 {
                    for j in 0..=30 {
                        let t = t0 + (t1 - t0) * i as f32 / 30.0;
                        let f = f0 + (f1 - f0) * j as f32 / 30.0;
                        let g = height_gradient(t, f);
                        assert!(g <= bound + 1e-6, "t {t} f {f}: {g} > {bound}");
                    }
                }
            }
        }
        // Stratus ends at 15 % of the layer: nothing above it.
        assert_eq!(height_gradient_bound((0.0, 0.0), (0.2, 1.0)), 0.0);
    }

    #[test]
    fn altitude_range_brackets_the_corners() {
        let planet = PlanetGeometry {
            shape: PlanetShape::Spherical,
            radius_m: 6_360_000.0,
        };
        let b = Aabb {
            min: Vec3::new(50_000.0, 1000.0, -20_000.0),
            max: Vec3::new(51_000.0, 1500.0, -19_000.0),
        };
        let (lo, hi) = altitude_range(&planet, &b);
        for i in 0..8 {
            let corner = Vec3::select(
                glam::BVec3::new(i & 1 != 0, i & 2 != 0, i & 4 != 0),
                b.max,
                b.min,
            );
            let h = planet.altitude_m(corner);
            assert!(h >= lo && h <= hi, "{h} outside {lo}..{hi}");
        }
        assert!(hi - lo < 520.0, "{lo}..{hi}");
    }
}
