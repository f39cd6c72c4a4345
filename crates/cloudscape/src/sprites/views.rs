//! The views the sprite technique draws from, each with its back-to-front list of sprites: the
//! frame's camera (clouds within the impostor ring, or all without one) and the ring's sectors
//! (clouds beyond it). Sorting is on the CPU, once per view and frame.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec2, Vec3, Vec4};

use super::cloud_set::{CloudSet, GpuSprite, NO_LAYER};
use super::impostors::{HALF_ANGLE_RAD, SectorView, sector_direction};
use crate::frame::Frame;
use crate::output::SampleGrid;
use crate::scene::{Scene, Sprites};

/// Clouds fade out over this last fraction of `sprites.distance_m`.
pub const FADE_FRACTION: f32 = 0.2;

/// The `View` uniform of `sprite.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ViewUniform {
    clip_from_world: Mat4,
    eye_m: Vec3,
    host_depth_test: u32,
    forward: Vec3,
    lock_distance_m: f32,
    target_offset_ndc: Vec2,
    fade_start_m: f32,
    fade_end_m: f32,
}

/// What the views read of the scene's `[sprites]`, taken when the technique is configured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewSettings {
    /// Field clouds fade out over the last fifth of this horizontal distance, m.
    pub distance_m: f32,
    /// Sprites nearer than this face along the view, m.
    pub lock_distance_m: f32,
    /// Radius of the impostor ring, m (0: no ring).
    pub ring_radius_m: f32,
    /// Texels along each impostor's width.
    pub impostor_texels: u32,
}

impl ViewSettings {
    /// The settings of a scene's `[sprites]`.
    pub fn of(sprites: &Sprites) -> ViewSettings {
        ViewSettings {
            distance_m: sprites.distance_m,
            lock_distance_m: sprites.lock_distance_m,
            ring_radius_m: sprites.ring_radius_m,
            impostor_texels: sprites.impostor_texels,
        }
    }
}

/// The drift of each layer's wind frame at `time_s`, m (east, south), for the `Settings` uniform.
pub fn wind_offsets_m(winds_m_per_s: &[Vec2; 4], time_s: f32) -> [Vec4; 4] {
    winds_m_per_s.map(|wind| (wind * time_s).extend(0.0).extend(0.0))
}

/// The winds of the scene's first four layers, m/s (zero where there is no layer).
pub fn layer_winds_m_per_s(scene: &Scene) -> [Vec2; 4] {
    std::array::from_fn(|i| {
        scene
            .layers
            .get(i)
            .map_or(Vec2::ZERO, |l| Vec2::from_array(l.wind_m_per_s))
    })
}

/// Where sprite `s` is at the drift `offsets`.
pub fn sprite_now(s: &GpuSprite, offsets: &[Vec4; 4]) -> Vec3 {
    match offsets.get(s.layer as usize) {
        Some(o) if s.layer < NO_LAYER => s.position_m + Vec3::new(o.x, 0.0, o.y),
        _ => s.position_m,
    }
}

impl ViewUniform {
    /// The frame's own view: its camera, the host-depth test, and the shift of the sample grid's
    /// rays to the output texels' centres.
    pub fn of_frame(frame: &Frame, grid: &SampleGrid, sprites: &ViewSettings) -> ViewUniform {
        let forward = -frame
            .view_from_world
            .inverse()
            .z_axis
            .truncate()
            .normalize();
        let size = grid.size(frame.size).as_vec2();
        // Texel x of the output holds the ray through full pixel x d + s + 1/2, i.e. output
        // coordinate x + (s + 1/2) / d, where the raster samples x + 1/2.
        let shift = (grid.subpixel.as_vec2() + 0.5) / grid.divisor as f32 - 0.5;
        let fade_end = sprites.distance_m;
        ViewUniform {
            clip_from_world: frame.clip_from_world(),
            eye_m: frame.camera_position_m,
            host_depth_test: 1,
            forward,
            lock_distance_m: sprites.lock_distance_m,
            target_offset_ndc: Vec2::new(-2.0 * shift.x / size.x, 2.0 * shift.y / size.y),
            fade_start_m: fade_end * (1.0 - FADE_FRACTION),
            fade_end_m: fade_end,
        }
    }

    /// The view of an impostor sector: no host depth, no lock (the ring is far away).
    pub fn of_sector(sector: &SectorView, sprites: &ViewSettings) -> ViewUniform {
        let fade_end = sprites.distance_m;
        ViewUniform {
            clip_from_world: sector.clip_from_world,
            eye_m: sector.eye_m,
            host_depth_test: 0,
            forward: sector.forward,
            lock_distance_m: 0.0,
            target_offset_ndc: Vec2::ZERO,
            fade_start_m: fade_end * (1.0 - FADE_FRACTION),
            fade_end_m: fade_end,
        }
    }
}

/// Which clouds a view draws, by horizontal distance of the cloud's centre from the eye.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reach {
    /// Every cloud.
    All,
    /// Clouds nearer than the ring radius, m.
    Within(f32),
    /// Clouds at or beyond the ring radius, m.
    Beyond(f32),
}

/// A view's sorted list: sprite indices farthest first, and the sprites' screen coverage summed
/// (overdraw, in multiples of the view's area).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SortedView {
    /// Sprite indices, back to front.
    pub order: Vec<u32>,
    /// Sum of the sprites' projected areas (their bounding squares, clipped to the view) over
    /// the view's area: layers of sprites per texel.
    pub overdraw: f64,
}

/// The sprites of `set` that `reach` keeps and that the view `clip_from_world` sees (frustum
/// culled on their bounding circle), farthest from `eye_m` first.
pub fn sort_view(
    set: &CloudSet,
    offsets: &[Vec4; 4],
    (eye_m, clip_from_world): (Vec3, Mat4),
    reach: Reach,
) -> SortedView {
    let keep_cloud: Vec<bool> = set
        .cloud_centres
        .iter()
        .map(|&(c, layer)| {
            let probe = GpuSprite {
                position_m: c,
                layer,
                ..GpuSprite::zeroed()
            };
            let d = sprite_now(&probe, offsets) - eye_m;
            let horizontal = Vec2::new(d.x, d.z).length();
            match reach {
                Reach::All => true,
                Reach::Within(r) => horizontal < r,
                Reach::Beyond(r) => horizontal >= r,
            }
        })
        .collect();
    // Clip-space size of one metre at clip w = 1, per axis.
    let scale = Vec2::new(
        clip_from_world.row(0).truncate().length(),
        clip_from_world.row(1).truncate().length(),
    );
    let mut keyed: Vec<(f32, u32)> = Vec::new();
    let mut overdraw = 0.0f64;
    for (i, s) in set.sprites.iter().enumerate() {
        if !keep_cloud[s.cloud as usize] || s.optical_depth <= 0.0 {
            continue;
        }
        let p = sprite_now(s, offsets);
        let radius = 0.5 * s.size_m.length();
        let clip = clip_from_world * p.extend(1.0);
        let reach = scale * radius;
        // Outside a side plane of the frustum by more than its radius: never drawn.
        if clip.x.abs() - reach.x > clip.w || clip.y.abs() - reach.y > clip.w || clip.w < -radius {
            continue;
        }
        let w = clip.w.max(radius);
        let half = (reach / w).min(Vec2::splat(1.0));
        overdraw += f64::from(half.x * half.y);
        keyed.push(((p - eye_m).length(), i as u32));
    }
    keyed.sort_unstable_by(|a, b| b.0.total_cmp(&a.0));
    SortedView {
        order: keyed.into_iter().map(|(_, i)| i).collect(),
        overdraw,
    }
}

/// Tangents of the lowest and highest elevation at which sector `k` seen from `eye_m` must show
/// the clouds beyond `radius_m` (their sprites' bottoms and tops at the ring, where they look
/// largest), with a margin; a thin band at the horizon when there are none.
pub fn sector_elevations(
    set: &CloudSet,
    offsets: &[Vec4; 4],
    eye_m: Vec3,
    k: usize,
    radius_m: f32,
) -> (f32, f32) {
    let axis = sector_direction(k);
    let cos_edge = (HALF_ANGLE_RAD * 1.2).cos();
    let (mut lo, mut hi) = (f32::MAX, f32::MIN);
    for s in &set.sprites {
        let to = sprite_now(s, offsets) - eye_m;
        let flat = Vec2::new(to.x, to.z);
        let horizontal = flat.length();
        if horizontal < radius_m || flat.dot(Vec2::new(axis.x, axis.z)) < cos_edge * horizontal {
            continue;
        }
        let half = 0.5 * s.size_m.length();
        lo = lo.min((to.y - half) / horizontal);
        hi = hi.max((to.y + half) / horizontal);
    }
    if lo > hi {
        return (-0.01, 0.01);
    }
    let margin = 0.02 * (hi - lo) + 1e-3;
    (lo - margin, hi + margin)
}

/// What the sprite passes share (`sprite.wgsl`).
pub static SPRITE_WGSL: crate::shader::WgslModule =
    crate::shader::wgsl_module!("sprite", "sprite.wgsl", [&crate::frame::FRAME_WGSL]);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::layout_check::assert_wgsl_layout;

    #[test]
    fn the_view_uniform_matches_its_wgsl_layout() {
        assert_wgsl_layout!(
            &crate::sprites::render::SPRITE_RENDER_WGSL,
            "View",
            ViewUniform {
                clip_from_world,
                eye_m,
                host_depth_test,
                forward,
                lock_distance_m,
                target_offset_ndc,
                fade_start_m,
                fade_end_m,
            }
        );
    }
}
