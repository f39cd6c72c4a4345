//! Shading of sprite clouds: Wang 2003's artist model (colour levels for the ambient light,
//! shading groups for the directional light), with its numbers derived from physics instead of
//! painted, so the same model stays right at dawn, noon and dusk.
//!
//! - **Ambient** (Wang 2003, "Simulate the filtering of light from the sky"): five colour levels,
//!   each a height in the cloud with an RGBA colour; a vertex takes the colour interpolated at its
//!   height, times the maximum ambient colour of the time of day. Here the levels' percentages are
//!   the two-stream (Eddington) transmittance of skylight through the cloud above the level,
//!   `1 / (1 + 3/4 (1 - g) tau_above)` ([`crate::optics::diffuse_transmittance`]): dark bases
//!   under thick clouds, nearly flat shading for thin ones. The maximum ambient colour is the
//!   sky's mean radiance from above times the albedo (the environment, per frame, on the GPU).
//! - **Directional** (Wang 2003, "Directional shading"): each shading group gets a factor from 0 to
//!   1, times the maximum directional colour. Wang's factor is the dot product of the direction to
//!   the sun and the group's direction from the cloud's centre, so the sun-facing side is lit
//!   (the slide's "vector from vertex to cloud center" would light the far side; its text says the
//!   side facing the sun receives more). Here it runs from the multiply scattered sunlight that
//!   crosses the cloud (the far side) to 1. Field clouds go further: each group's factor is the
//!   multiply scattered sunlight after the field's own optical depth toward the sun, marched from
//!   the group's centre, so groups of a cloud that spans two tiles shade as one cloud. Multiple
//!   scattering is the ray marcher's octave model (Wrenninge 2013, "Oz: the great and volumetric",
//!   `lighting.octaves`): `sum_i b^i exp(-a^i tau) / sum_i b^i`, the scene's `[lighting]`, tuned
//!   against the path tracer, so both techniques dim a shadowed group alike. The maximum
//!   directional colour is the sun's irradiance times the albedo over pi: the radiance of a white
//!   Lambertian surface facing the sun.
//! - **Silver lining**: thin sprite edges also scatter the unscattered sun once, by the phase
//!   function toward the eye, weighted by the group's direct-sun transmittance `exp(-tau_sun)`.
//!
//! The artist keeps the last word: a scene sets `sprites.ambient_color` or
//! `sprites.directional_color` to replace the maxima, and a hand-made cloud's `color_levels`
//! replace its derived levels.

use glam::{Vec3, Vec4};

use super::model::SpriteCloud;
use crate::field::CloudField;
use crate::optics::diffuse_transmittance;

/// Colour levels per cloud (Wang 2003: "Artist specifies 5 color levels").
pub const LEVELS: usize = 5;
/// Mean density of a cloud's matter relative to its densest, for the optical depth across a cloud
/// whose density is not known (hand-made clouds): half.
pub const MEAN_RELATIVE_DENSITY: f32 = 0.5;
/// Segments of the march toward the sun from a field cloud's shading group (each twice the one
/// before, as the ray marcher's light samples, Schneider 2015).
pub const SUN_SEGMENTS: u32 = 6;
/// Length of that march, m.
pub const SUN_MARCH_M: f32 = 6000.0;

/// One colour level: a height fraction of the cloud (0 bottom, 1 top) and an RGBA colour (rgb:
/// the ambient percentage per channel, a: opacity).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColorLevel {
    /// Height within the cloud, 0 (bottom) to 1 (top).
    pub height: f32,
    /// Ambient fraction per channel and opacity.
    pub rgba: Vec4,
}

/// The five levels of a cloud of `height_m` whose matter has extinction `extinction_per_m` and
/// mean cosine `g`, at heights 0, 1/4, ..., 1: the two-stream transmittance of skylight through
/// the cloud above each level.
pub fn physical_levels(height_m: f32, extinction_per_m: f32, g: f32) -> [ColorLevel; LEVELS] {
    std::array::from_fn(|i| {
        let h = i as f32 / (LEVELS - 1) as f32;
        let tau_above = extinction_per_m * MEAN_RELATIVE_DENSITY * height_m * (1.0 - h);
        let t = diffuse_transmittance(tau_above, g);
        ColorLevel {
            height: h,
            rgba: Vec4::new(t, t, t, 1.0),
        }
    })
}

/// The colour at height fraction `h`, interpolated linearly between the levels (held at the ends):
/// `sprite_level` in `sprite.wgsl`.
pub fn level_at(levels: &[ColorLevel; LEVELS], h: f32) -> Vec4 {
    if h <= levels[0].height {
        return levels[0].rgba;
    }
    for pair in levels.windows(2) {
        if h <= pair[1].height {
            let span = (pair[1].height - pair[0].height).max(1e-6);
            return pair[0].rgba.lerp(pair[1].rgba, (h - pair[0].height) / span);
        }
    }
    levels[LEVELS - 1].rgba
}

/// Sprite optical depth at most: beyond it a puff's core is opaque anyway, and its soft rim is
/// kept (`textures.rs` tests the rim at this depth).
pub const MAX_SPRITE_OPTICAL_DEPTH: f32 = 3.0;

/// Optical depth through the densest column of a sprite `width_m` wide of matter of extinction
/// `extinction_per_m` at its mean density, at most [`MAX_SPRITE_OPTICAL_DEPTH`].
pub fn sprite_optical_depth(extinction_per_m: f32, width_m: f32) -> f32 {
    (extinction_per_m * MEAN_RELATIVE_DENSITY * width_m).min(MAX_SPRITE_OPTICAL_DEPTH)
}

/// The light of one shading group: the diffuse directional factor and the direct sun's
/// transmittance to it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GroupLight {
    /// Directional factor, 0..1 (times the maximum directional colour).
    pub directional: f32,
    /// Transmittance of the unscattered sun to the group, 0..1 (silver lining).
    pub sun_transmittance: f32,
}

/// How sunlight reaches the groups: the sun, the octave model and the matter's optics.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SunLight {
    /// Unit vector toward the sun.
    pub sun: Vec3,
    /// Octaves of multiple scattering (`lighting.octaves`).
    pub octaves: u32,
    /// Octave attenuation a (`lighting.octave_attenuation`).
    pub attenuation: f32,
    /// Octave contribution b (`lighting.octave_contribution`).
    pub contribution: f32,
    /// Mean cosine of the phase function.
    pub g: f32,
    /// Extinction of the densest cloud, m^-1 (hand-made clouds and colour levels).
    pub extinction_per_m: f32,
}

impl SunLight {
    /// The light of `scene` from `sun`, phase mean cosine `g`.
    pub fn from_scene(scene: &crate::scene::Scene, sun: Vec3, g: f32) -> SunLight {
        let l = &scene.lighting;
        SunLight {
            sun,
            octaves: l.octaves,
            attenuation: l.octave_attenuation,
            contribution: l.octave_contribution,
            g,
            extinction_per_m: crate::particles::DEFAULT_EXTINCTION_PER_M,
        }
    }

    /// The same light for matter of extinction `extinction_per_m`.
    pub fn with_extinction(&self, extinction_per_m: f32) -> SunLight {
        SunLight {
            extinction_per_m,
            ..*self
        }
    }

    /// Multiply scattered sunlight after optical depth `tau`, relative to none (Wrenninge 2013's
    /// octaves): `sum_i b^i exp(-a^i tau) / sum_i b^i`.
    pub fn multiple_scattering(&self, tau: f32) -> f32 {
        let (mut sum, mut total, mut a, mut b) = (0.0, 0.0, 1.0, 1.0);
        for _ in 0..self.octaves.max(1) {
            sum += b * (-a * tau).exp();
            total += b;
            a *= self.attenuation;
            b *= self.contribution;
        }
        sum / total
    }

    /// The group's light after optical depth `tau` toward the sun.
    fn after(&self, tau: f32) -> GroupLight {
        GroupLight {
            directional: self.multiple_scattering(tau),
            sun_transmittance: (-tau).exp(),
        }
    }
}

/// Wang 2003's directional factor of a group at `offset_m` from its cloud's centre, for a cloud of
/// diameter `diameter_m`: from the two-stream diffuse transmittance across the cloud on the far
/// side (the light that diffuses through a slab that thick) to 1 on the side facing the sun. How
/// far a group faces the sun grows with its offset out to the cloud's radius, so the light is
/// continuous through the centre (where the eye may fly).
pub fn wang_group_light(light: &SunLight, offset_m: Vec3, diameter_m: f32) -> GroupLight {
    let reach = (offset_m / (0.5 * diameter_m).max(1e-3)).clamp_length_max(1.0);
    let facing = 0.5 + 0.5 * light.sun.dot(reach);
    let tau = light.extinction_per_m * MEAN_RELATIVE_DENSITY * diameter_m * (1.0 - facing);
    GroupLight {
        directional: diffuse_transmittance(tau, light.g),
        sun_transmittance: (-tau).exp(),
    }
}

/// A field cloud's group at world point `p` (the layer's wind frame at time 0): its light after
/// the coarse field's optical depth toward the sun.
pub fn field_group_light(field: &CloudField, p: Vec3, light: &SunLight) -> GroupLight {
    let tau = field.coarse_optical_depth(
        (p, light.sun),
        (0.0, SUN_MARCH_M, 2.0),
        (SUN_SEGMENTS, 0.5),
        0.0,
    );
    light.after(tau)
}

/// The light of every group of `cloud`: from the field for field clouds (`field` given), Wang's
/// rule otherwise.
pub fn group_lights(
    cloud: &SpriteCloud,
    field: Option<&CloudField>,
    light: &SunLight,
) -> Vec<GroupLight> {
    let (lo, hi) = cloud.vertical_extent_m();
    let diameter = cloud_diameter_m(cloud).max(hi - lo);
    cloud
        .group_centres_m()
        .into_iter()
        .map(|offset| match field {
            Some(field) => field_group_light(field, cloud.center_m + offset, light),
            None => wang_group_light(light, offset, diameter),
        })
        .collect()
}

/// Horizontal diameter of a cloud's sprites, m.
pub fn cloud_diameter_m(cloud: &SpriteCloud) -> f32 {
    cloud
        .sprites
        .iter()
        .map(|s| 2.0 * glam::Vec2::new(s.offset_m.x, s.offset_m.z).length() + s.size_m.x)
        .fold(0.0, f32::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_darken_downward_and_more_for_thicker_clouds() {
        let thin = physical_levels(200.0, 0.05, 0.8);
        let thick = physical_levels(2000.0, 0.05, 0.8);
        assert_eq!(thick[LEVELS - 1].rgba.x, 1.0);
        assert!(thick.windows(2).all(|w| w[0].rgba.x < w[1].rgba.x));
        assert!(thick[0].rgba.x < thin[0].rgba.x);
        assert!(
            thin[0].rgba.x > 0.5 && thick[0].rgba.x < 0.2,
            "{thin:?} {thick:?}"
        );
        let mid = level_at(&thick, 0.125);
        assert!((mid.x - 0.5 * (thick[0].rgba.x + thick[1].rgba.x)).abs() < 1e-6);
        assert_eq!(level_at(&thick, -1.0), thick[0].rgba);
    }

    #[test]
    fn the_sun_facing_side_is_lit_the_far_side_gets_what_scatters_through() {
        let light = SunLight {
            sun: Vec3::X,
            octaves: 6,
            attenuation: 0.5,
            contribution: 0.7,
            g: 0.8,
            extinction_per_m: 0.05,
        };
        let near = wang_group_light(&light, Vec3::X * 500.0, 1000.0);
        let side = wang_group_light(&light, Vec3::Z * 500.0, 1000.0);
        let far = wang_group_light(&light, -Vec3::X * 500.0, 1000.0);
        assert_eq!((near.directional, near.sun_transmittance), (1.0, 1.0));
        assert!(far.directional < side.directional && side.directional < 1.0);
        assert!((far.directional - diffuse_transmittance(25.0, 0.8)).abs() < 1e-6);
        assert!(far.sun_transmittance < 1e-6);
        // Halfway out toward the sun, halfway lit; continuous through the centre.
        let halfway = wang_group_light(&light, Vec3::X * 250.0, 1000.0);
        assert!((halfway.sun_transmittance - (-6.25f32).exp()).abs() < 1e-6);
        let [a, b] = [1.0, -1.0].map(|s| wang_group_light(&light, Vec3::X * s, 1000.0));
        assert!((a.directional - b.directional).abs() < 1e-3);
        // One octave is Beer-Lambert; more octaves carry light deeper.
        let beer = SunLight {
            octaves: 1,
            ..light
        };
        assert!((beer.multiple_scattering(2.0) - (-2.0f32).exp()).abs() < 1e-6);
        assert!(light.multiple_scattering(2.0) > beer.multiple_scattering(2.0));
    }
}
