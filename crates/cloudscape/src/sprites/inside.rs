//! The view from inside a cloud. Sprites the eye has passed fade away (Wang 2003), and a cluster
//! thins toward its edge, so from inside, the view between the sprites ahead would open onto the
//! sky where a real cloud is opaque within a hundred metres. The matter the faded sprites stood
//! for is drawn instead as fog in front of the sprites: the cloud's extinction where the eye is,
//! over the distance within which sprites fade ([`FOG_SPRITE_LOCKS`] lock distances), ending where
//! the view ray leaves the cloud. The resolve pass (`sprite_resolve.wgsl`) composites it, lit as
//! the sprites are.

use glam::Vec3;

use super::cloud_set::{CloudSet, NO_LAYER};
use super::shading::{self, MEAN_RELATIVE_DENSITY};
use crate::field::CloudField;

/// The fog spans this many lock distances from the eye: within it, sprites fade as the eye passes
/// them (`sprite_render.wgsl`); beyond it they are drawn whole.
pub const FOG_SPRITE_LOCKS: f32 = 2.0;
/// A hand-made cloud's fog thickens over this depth inside its boxes, m, so entering one is not a
/// jump.
pub const FOG_RAMP_M: f32 = 150.0;
/// Half-extent of the box that bounds field fog, m: the field's own density bounds it.
const UNBOUNDED_M: f32 = 1.0e7;

/// The fog around the eye.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct InCloudFog {
    /// Extinction of the cloud at the eye, m^-1 (0: the eye is in clear air).
    pub extinction_per_m: f32,
    /// The fog ends this far from the eye, m.
    pub depth_m: f32,
    /// The fog ends where the view ray leaves this box (world, m).
    pub box_m: (Vec3, Vec3),
    /// Share of the sky's light from above that reaches the eye through the cloud (Wang's colour
    /// level at the eye's height), for frames without a light volume.
    pub ambient: f32,
    /// The multiply scattered sun's share (Wang's directional factor), likewise.
    pub directional: f32,
    /// Whether the fog is the field's, lit from the light volume when the frame has one.
    pub from_field: bool,
}

impl CloudSet {
    /// The fog around `eye_m` at `time_s`: the field's coarse extinction there, or that of a
    /// hand-made cloud whose boxes hold the eye; none in clear air. `lock_distance_m` is the
    /// sprites' lock distance.
    pub fn fog_at(
        &self,
        field: &CloudField,
        eye_m: Vec3,
        time_s: f32,
        lock_distance_m: f32,
    ) -> InCloudFog {
        let depth_m = FOG_SPRITE_LOCKS * lock_distance_m;
        let light = self.light();
        let field_extinction = match self.has_field_clouds() {
            true => field.coarse_extinction_per_m(eye_m, time_s),
            false => 0.0,
        };
        if field_extinction > 0.0 {
            let tau_sun = field.coarse_optical_depth(
                (eye_m, light.sun),
                (0.0, shading::SUN_MARCH_M, 2.0),
                (shading::SUN_SEGMENTS, 0.5),
                time_s,
            );
            return InCloudFog {
                extinction_per_m: field_extinction,
                depth_m,
                box_m: (Vec3::splat(-UNBOUNDED_M), Vec3::splat(UNBOUNDED_M)),
                ambient: crate::optics::diffuse_transmittance(tau_sun, light.g),
                directional: light.multiple_scattering(tau_sun),
                from_field: true,
            };
        }
        self.hand_made_fog(eye_m, depth_m).unwrap_or_default()
    }

    /// The fog of the first hand-made cloud whose boxes hold `eye_m`.
    fn hand_made_fog(&self, eye_m: Vec3, depth_m: f32) -> Option<InCloudFog> {
        let light = self.light();
        self.authored_clouds().find_map(|(cloud, levels)| {
            if cloud.layer.is_some_and(|l| l != NO_LAYER) {
                return None;
            }
            let local = eye_m - cloud.center_m;
            let (inside, b) = cloud
                .boxes
                .iter()
                .map(|b| {
                    let depth = (0.5 * b.size_m - (local - b.center_m).abs()).min_element();
                    (depth, b)
                })
                .max_by(|a, b| a.0.total_cmp(&b.0))?;
            if inside <= 0.0 {
                return None;
            }
            let (lo, hi) = cloud.vertical_extent_m();
            let height = (hi - lo).max(1.0);
            let h = ((local.y - lo) / height).clamp(0.0, 1.0);
            let levels = levels.unwrap_or_else(|| {
                shading::physical_levels(height, light.extinction_per_m, light.g)
            });
            let ramp = (inside / FOG_RAMP_M).min(1.0);
            let diameter = shading::cloud_diameter_m(cloud).max(height);
            let centre = cloud.center_m + b.center_m;
            Some(InCloudFog {
                extinction_per_m: light.extinction_per_m * MEAN_RELATIVE_DENSITY * ramp,
                depth_m,
                box_m: (centre - 0.5 * b.size_m, centre + 0.5 * b.size_m),
                ambient: shading::level_at(&levels, h).x,
                directional: shading::wang_group_light(&light, local, diameter).directional,
                from_field: false,
            })
        })
    }
}
