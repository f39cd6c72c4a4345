//! The clouds' shared light-space transmittance map: one cheap pass over the coarse field per frame
//! that every technique's ground, the air's light shafts and a host's geometry are shadowed by.
//!
//! The map lies on the world's ground plane (`y = 0`), centred under the viewpoint, out to the
//! camera's far distance. Its texel coordinate `s` in `[-1, 1]` maps to the offset
//! `x = s (k + (1 - k) |s|)` half extents (a camera-centred warp: texels `k` times the mean size
//! under the eye, growing outward). Each texel holds two columns through the clouds from its
//! ground point: along the sun (layer 0, projected so that the point at height `y` is
//! `g + (sun.xz / sun.y) y`) and straight up (layer 1, for the sky's light). A column stores the
//! coarse optical depth from four checkpoint heights (`bottom + 0, 1/4, 1/2, 3/4` of the clouds'
//! height span) to the top; between checkpoints the depth is linear in height. A point is shadowed
//! by reading the column through it: `environment_cloud_sun_optical_depth(p)` in
//! `environment.wgsl`, which [`CloudShadowMap::optical_depth`] specifies, through
//! [`SHADOW_MAP_WGSL`]'s functions, which a host's own shaders import to read the map bound in
//! their own group.

use crate::field::CloudField;
use crate::scene::{PlanetShape, Scene};
use glam::{Vec2, Vec3};

/// Lowest sun the map's projection follows (its `y`); a lower sun is projected as if this high,
/// so the map stays bounded (its light is all but gone at the ground by then).
pub const SHADOW_MIN_SUN_Y: f32 = 0.05;
/// Height checkpoints per column.
pub const CHECKPOINTS: usize = 4;

/// Where the map lies and what it samples, for one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowParams {
    /// World xz of the map's centre (under the viewpoint).
    pub centre_m: Vec2,
    /// How far the map reaches from its centre along x and z, metres.
    pub half_extent_m: f32,
    /// Texel size at the centre over the mean texel size, `k`.
    pub warp: f32,
    /// World height of the lowest checkpoint: every cloud lies above it, metres.
    pub bottom_y_m: f32,
    /// World height above which no cloud lies, metres.
    pub top_y_m: f32,
    /// The sun's `y`, at least [`SHADOW_MIN_SUN_Y`].
    pub sun_y: f32,
    /// Whether there are clouds at all (the map reads zero when not).
    pub enabled: bool,
    /// Samples of the coarse field between two checkpoints.
    pub steps_per_checkpoint: u32,
}

impl ShadowParams {
    /// The map of `field` for the view from `viewpoint_m` with the sun at `sun` (unit), reaching
    /// the camera's far distance, with `scene.shadow`'s warp and steps.
    pub fn new(scene: &Scene, field: &CloudField, viewpoint_m: Vec3, sun: Vec3) -> ShadowParams {
        let half_extent_m = scene.camera.far_m.max(1000.0);
        let sun_y = sun.y.max(SHADOW_MIN_SUN_Y);
        let (bottom, top, enabled) = field.cloud_heights();
        // On a sphere the clouds sink below y = 0 with distance d by about d^2 / 2R; the columns
        // reach past the map by the sun's slant over the clouds' top.
        let slant = top.max(0.0) * Vec2::new(sun.x, sun.z).length() / sun_y;
        let reach = half_extent_m * std::f32::consts::SQRT_2 + slant;
        let drop = match field.planet.shape {
            PlanetShape::Flat => 0.0,
            PlanetShape::Spherical => reach * reach / (2.0 * field.planet.radius_m),
        };
        ShadowParams {
            centre_m: Vec2::new(viewpoint_m.x, viewpoint_m.z),
            half_extent_m,
            warp: scene.shadow.warp,
            bottom_y_m: bottom - drop,
            top_y_m: top.max(bottom - drop + 1.0),
            sun_y,
            enabled,
            steps_per_checkpoint: scene.shadow.steps.div_ceil(CHECKPOINTS as u32).max(1),
        }
    }

    /// Side of the map's finest texel, the one under its centre, for a map of `texels` per side:
    /// the warp's slope at the centre, `k`, times the mean texel size, metres.
    pub fn finest_texel_m(&self, texels: u32) -> f32 {
        self.warp * 2.0 * self.half_extent_m / texels.max(1) as f32
    }

    /// How many times larger than the finest texel the map's texel over ground point `g` is, along
    /// its coarser axis: the warp's slope `k + 2 (1 - k) |s|` at `g`'s texel coordinate `s`, over
    /// `k`.
    pub fn texel_growth_at(&self, g: Vec2) -> f32 {
        let offset = (g - self.centre_m) / self.half_extent_m;
        let s = self
            .coord_of(offset.x)
            .abs()
            .max(self.coord_of(offset.y).abs());
        (self.warp + 2.0 * (1.0 - self.warp) * s) / self.warp
    }

    /// Ground-plane offset in half extents of texel coordinate `s` in `[-1, 1]`:
    /// `s (k + (1 - k) |s|)` (`cloud_shadow_offset`).
    pub fn offset_of(&self, s: f32) -> f32 {
        s * (self.warp + (1.0 - self.warp) * s.abs())
    }

    /// Texel coordinate of ground-plane offset `x` in half extents: the inverse of
    /// [`ShadowParams::offset_of`] (`cloud_shadow_coord`).
    pub fn coord_of(&self, x: f32) -> f32 {
        let (k, a) = (self.warp, x.abs());
        let s = if k < 1.0 {
            (-k + (k * k + 4.0 * (1.0 - k) * a).sqrt()) / (2.0 * (1.0 - k))
        } else {
            a
        };
        s.copysign(x)
    }

    /// Ground point of the centre of texel `(i, j)` of a map of `texels` per side.
    pub fn ground_point(&self, (i, j): (u32, u32), texels: u32) -> Vec2 {
        let s = |i: u32| (i as f32 + 0.5) / texels as f32 * 2.0 - 1.0;
        let offset = Vec2::new(self.offset_of(s(i)), self.offset_of(s(j)));
        self.centre_m + offset * self.half_extent_m
    }

    /// The column direction of `layer` scaled to rise one metre per unit: the sun's projection
    /// `(sun.x / sun_y, 1, sun.z / sun_y)` for layer 0, straight up for layer 1.
    pub fn rise(&self, sun: Vec3, layer: usize) -> Vec3 {
        if layer == 0 {
            Vec3::new(sun.x / self.sun_y, 1.0, sun.z / self.sun_y)
        } else {
            Vec3::Y
        }
    }

    /// Height of checkpoint `k` (0..=4; 4 is the top).
    pub fn checkpoint_y(&self, k: usize) -> f32 {
        self.bottom_y_m + (self.top_y_m - self.bottom_y_m) * k as f32 / CHECKPOINTS as f32
    }

    /// The column of `layer` from ground point `g`: the coarse optical depth from each
    /// checkpoint to the top, at scene time `time_s` (`shadow_build` in `cloud_shadow.wgsl`).
    pub fn column(
        &self,
        field: &CloudField,
        (g, layer): (Vec2, usize),
        sun: Vec3,
        time_s: f32,
    ) -> [f32; CHECKPOINTS] {
        let rise = self.rise(sun, layer);
        let (length, dir) = (rise.length(), rise.normalize());
        let base = Vec3::new(g.x, 0.0, g.y);
        let mut out = [0.0; CHECKPOINTS];
        let mut above = 0.0;
        for k in (0..CHECKPOINTS).rev() {
            let (y0, y1) = (self.checkpoint_y(k), self.checkpoint_y(k + 1));
            let span = (y0 * length, (y1 - y0) * length, 1.0);
            let samples = (self.steps_per_checkpoint, 0.5);
            above += field.coarse_optical_depth((base, dir), span, samples, time_s);
            out[k] = above;
        }
        out
    }

    /// Ground-plane point of the column of `layer` through world point `p`.
    pub fn ground_of(&self, p: Vec3, sun: Vec3, layer: usize) -> Vec2 {
        let rise = self.rise(sun, layer);
        Vec2::new(p.x - rise.x * p.y, p.z - rise.z * p.y)
    }

    /// Optical depth above height `y` in a column's checkpoints: linear between them, zero at
    /// and above the top (`cloud_shadow_read`).
    pub fn depth_above(&self, column: [f32; CHECKPOINTS], y: f32) -> f32 {
        if !self.enabled || y >= self.top_y_m {
            return 0.0;
        }
        let span = self.top_y_m - self.bottom_y_m;
        let f = ((y - self.bottom_y_m) / span).clamp(0.0, 1.0) * CHECKPOINTS as f32;
        let i = (f as usize).min(CHECKPOINTS - 1);
        let next = if i + 1 < CHECKPOINTS {
            column[i + 1]
        } else {
            0.0
        };
        column[i] + (next - column[i]) * (f - i as f32)
    }
}

/// Reuse of the lighting across frames, for a real-time host. The shadow map is built once and read
/// until the clouds or the sun have moved its shadows too far, the eye has moved so far that the
/// texels under it have grown too coarse, or the map's settings changed; between builds the
/// shadows lag the clouds by at most the drift allowed. The light volume's solve starts from the
/// last frame's solution (the scene's `lighting.volume_warm_sweeps` sweeps a frame) and its grid
/// is recentred only once the eye has moved
/// [`crate::environment::light_volume::RECENTRE_CELLS`] cells. The sprite technique remakes its
/// clouds over frames after an edit of coverage, nearest the eye first
/// ([`crate::technique::FrameInputs::real_time`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightingReuse {
    /// The map is rebuilt once the shadows it holds lie this many of its finest texels from where
    /// the clouds cast them now (the clouds moved with the wind, the sun moved).
    pub max_shadow_drift_texels: f32,
    /// The map is rebuilt once the texel under the eye is this share larger than its finest:
    /// the map stays in place as the eye moves, its warp's fine texels left behind.
    pub max_texel_growth: f32,
}

impl LightingReuse {
    /// What a game at a real-time frame rate carries: the shadow map kept until the clouds' shadows
    /// have drifted half of its finest texel (about 120 m in the default scene), a lag no one sees,
    /// or the eye has moved until the texel under it is a quarter larger (about 1.2 km in the
    /// default scene: a rebuild every 1.2 s at 1 km/s, not every 7 frames as when the eye's move
    /// counted as drift), for a pass that costs more than the rest of the frame on a software
    /// adapter; the light volume warm-started.
    pub const REAL_TIME: LightingReuse = LightingReuse {
        max_shadow_drift_texels: 0.5,
        max_texel_growth: 0.25,
    };
}

/// A kept map is rebuilt once the eye has moved this share of its reach (the camera's far
/// distance) from where it was built: ahead of the eye it still reaches 98 % as far. (Without a
/// warp the texels do not grow as the eye moves; this bounds the move.)
pub const MAX_SHADOW_REACH_LOSS: f32 = 0.02;

/// What a built map was built for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuiltShadow {
    /// Where it lies and what it sampled.
    pub params: ShadowParams,
    /// The unit direction to the sun.
    pub sun: Vec3,
    /// Texels per side.
    pub texels: u32,
    /// Scene time of the clouds it sampled, s.
    pub time_s: f32,
}

impl BuiltShadow {
    /// Whether this map still serves a frame that would build `fresh` while the clouds move at
    /// `wind_m_per_s`: the same size and settings, the shadows it holds within `reuse`'s drift of
    /// where the clouds cast them now, and the texel under the new eye within `reuse`'s growth.
    /// A sun that moves (a time of day that passes) shifts the shadow of a cloud `h` metres over
    /// the lowest point the map serves by `h` times the change of its slope `sun.xz / sun.y`: a
    /// few metres a frame, so the map is kept, not rebuilt every frame as an exact match of the
    /// sun would have it. (On a sphere the sun's slant also lowers the map's bottom a little, by
    /// as much as it moves; that counts as drift too.)
    pub fn serves(&self, fresh: &BuiltShadow, wind_m_per_s: Vec2, reuse: LightingReuse) -> bool {
        let recentred = ShadowParams {
            centre_m: self.params.centre_m,
            sun_y: self.params.sun_y,
            bottom_y_m: self.params.bottom_y_m,
            ..fresh.params
        };
        if recentred != self.params || fresh.texels != self.texels {
            return false;
        }
        let clouds_m = wind_m_per_s.length() * (fresh.time_s - self.time_s).abs();
        let span_m = self.params.top_y_m - self.params.bottom_y_m.min(0.0);
        let sun_m = span_m * (fresh.sun_slope() - self.sun_slope()).length();
        let bottom_m = (fresh.params.bottom_y_m - self.params.bottom_y_m).abs();
        let drift_m = clouds_m + sun_m + bottom_m;
        let growth = self.params.texel_growth_at(fresh.params.centre_m);
        let eye_m = (fresh.params.centre_m - self.params.centre_m).length();
        drift_m <= reuse.max_shadow_drift_texels * self.params.finest_texel_m(self.texels)
            && growth <= 1.0 + reuse.max_texel_growth
            && eye_m <= MAX_SHADOW_REACH_LOSS * self.params.half_extent_m
    }

    /// How far the shadows lie from what casts them per metre of height: the sun's `xz` over its
    /// `y` (as the map's columns rise, [`ShadowParams::rise`]).
    fn sun_slope(&self) -> Vec2 {
        Vec2::new(self.sun.x, self.sun.z) / self.params.sun_y
    }
}

/// The map on the CPU: the specification of the GPU pass and of `cloud_shadow_read`.
#[derive(Clone, Debug, PartialEq)]
pub struct CloudShadowMap {
    /// Where it lies.
    pub params: ShadowParams,
    /// Unit direction toward the sun.
    pub sun: Vec3,
    /// Texels per side.
    pub texels: u32,
    /// Columns by layer (sun, up), row by row (`j` down, `i` across).
    pub columns: [Vec<[f32; CHECKPOINTS]>; 2],
}

impl CloudShadowMap {
    /// Builds the map of `field` at time `time_s`, `texels` per side.
    pub fn build(
        field: &CloudField,
        params: ShadowParams,
        sun: Vec3,
        (texels, time_s): (u32, f32),
    ) -> CloudShadowMap {
        let layer = |layer| {
            (0..texels)
                .flat_map(|j| (0..texels).map(move |i| (i, j)))
                .map(|ij| {
                    let g = params.ground_point(ij, texels);
                    params.column(field, (g, layer), sun, time_s)
                })
                .collect()
        };
        CloudShadowMap {
            params,
            sun,
            texels,
            columns: [layer(0), layer(1)],
        }
    }

    /// Optical depth of the clouds from world point `p` along `layer`'s column (0: toward the
    /// sun, 1: straight up), bilinear between texels as the GPU samples them.
    pub fn optical_depth(&self, p: Vec3, layer: usize) -> f32 {
        let params = &self.params;
        let g = params.ground_of(p, self.sun, layer);
        let x = (g - params.centre_m) / params.half_extent_m;
        if x.abs().max_element() > 1.0 {
            return 0.0;
        }
        let s = Vec2::new(params.coord_of(x.x), params.coord_of(x.y));
        let texel = (s * 0.5 + 0.5) * self.texels as f32 - 0.5;
        let (i0, f) = (texel.floor(), texel - texel.floor());
        let at = |di: f32, dj: f32| {
            let n = self.texels as f32 - 1.0;
            let i = (i0.x + di).clamp(0.0, n) as usize;
            let j = (i0.y + dj).clamp(0.0, n) as usize;
            params.depth_above(self.columns[layer][j * self.texels as usize + i], p.y)
        };
        let top = at(0.0, 0.0) + (at(1.0, 0.0) - at(0.0, 0.0)) * f.x;
        let bottom = at(0.0, 1.0) + (at(1.0, 1.0) - at(0.0, 1.0)) * f.x;
        top + (bottom - top) * f.y
    }
}

#[cfg(test)]
mod tests;

/// Reading the map in WGSL (`shadow_map.wgsl`): the `CloudShadow` struct (where the map lies, as
/// the environment's `CloudShadowUniform` lays it out) and
/// `cloud_shadow_sun_optical_depth(s, map, sampler, sun, p)`, with the map, a filtering sampler and
/// the sun as arguments, so that the environment and a host's shaders read the map by the same code
/// wherever it is bound.
pub static SHADOW_MAP_WGSL: crate::shader::WgslModule =
    crate::shader::wgsl_module!("shadow_map", "shadow_map.wgsl", []);
