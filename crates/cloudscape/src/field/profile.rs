//! Cloud types and their height profiles.
//!
//! A cloud type is a coordinate on a continuous axis: 0 stratus, 1 stratocumulus, 2 cumulus,
//! 3 cumulonimbus (Schneider 2015 blends profiles along such an axis). Each anchor type has a
//! density-height gradient; between anchors the gradient's parameters interpolate.

use super::noise::remap;
use crate::scene::CloudTypeMix;
pub use crate::scene::TYPE_GRADIENTS;

/// Half-width of the blend between two types of a mix, on the weather map's type channel (0..1).
pub const TYPE_BLEND_HALF_WIDTH: f32 = 0.05;

/// The density gradient of type coordinate `type_coord` (0..3) at height fraction `f` (0..1).
pub fn height_gradient(type_coord: f32, f: f32) -> f32 {
    let t = type_coord.clamp(0.0, 3.0);
    let lo = (t.floor() as usize).min(2);
    let w = t - lo as f32;
    let g: [f32; 4] =
        std::array::from_fn(|i| TYPE_GRADIENTS[lo][i] * (1.0 - w) + TYPE_GRADIENTS[lo + 1][i] * w);
    let rise = remap(f, g[0], g[1], 0.0, 1.0).clamp(0.0, 1.0);
    let fall = remap(f, g[2], g[3], 1.0, 0.0).clamp(0.0, 1.0);
    rise * fall
}

/// How a layer's type mix turns the weather map's type channel (0..1) into a type coordinate:
/// the channel is a position in the mix's cumulative weights, so a mix of 70 % cumulus and 30 %
/// stratocumulus gives cumulus over 70 % of a uniformly distributed channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TypeTable {
    /// Type coordinate where the channel is 0.
    pub first: f32,
    /// Channel values where the next type begins (unused entries are 2, never reached).
    pub bounds: [f32; 3],
    /// Change of the type coordinate at each bound.
    pub steps: [f32; 3],
}

impl TypeTable {
    /// The table of a mix; weights need not sum to 1 but one must be positive.
    pub fn from_mix(mix: &CloudTypeMix) -> TypeTable {
        let weights = [
            mix.stratus,
            mix.stratocumulus,
            mix.cumulus,
            mix.cumulonimbus,
        ];
        let total: f32 = weights.iter().sum();
        let present: Vec<(f32, f32)> = weights
            .iter()
            .enumerate()
            .filter(|(_, w)| **w > 0.0)
            .map(|(i, w)| (i as f32, w / total))
            .collect();
        let mut table = TypeTable {
            first: present.first().map_or(2.0, |p| p.0),
            bounds: [2.0; 3],
            steps: [0.0; 3],
        };
        let mut cumulative = 0.0;
        for (j, pair) in present.windows(2).enumerate() {
            cumulative += pair[0].1;
            table.bounds[j] = cumulative;
            table.steps[j] = pair[1].0 - pair[0].0;
        }
        table
    }

    /// Type coordinate for a type-channel value.
    pub fn type_coord(&self, channel: f32) -> f32 {
        let e = TYPE_BLEND_HALF_WIDTH;
        self.bounds
            .iter()
            .zip(self.steps)
            .fold(self.first, |t, (b, s)| {
                t + s * smoothstep(b - e, b + e, channel)
            })
    }
}

/// GLSL/WGSL `smoothstep`.
pub fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gradients_vanish_outside_their_band() {
        assert_eq!(height_gradient(0.0, 0.5), 0.0, "stratus stays low");
        assert!(height_gradient(0.0, 0.075) > 0.9);
        assert!(
            height_gradient(2.0, 0.15) > 0.99,
            "cumulus is densest low in the layer"
        );
        let dome = height_gradient(2.0, 0.6);
        assert!(
            dome > 0.3 && dome < 0.7,
            "and thins gradually upward into domes: {dome}"
        );
        assert_eq!(height_gradient(2.0, 1.0), 0.0);
        assert!(
            height_gradient(3.0, 0.95) > 0.4,
            "cumulonimbus reaches the top"
        );
    }

    #[test]
    fn mix_maps_channel_through_cumulative_weights() {
        let mix = CloudTypeMix {
            stratocumulus: 0.3,
            cumulus: 0.7,
            ..CloudTypeMix::default()
        };
        let t = TypeTable::from_mix(&mix);
        assert_eq!(t.type_coord(0.0), 1.0);
        assert!((t.type_coord(0.2) - 1.0).abs() < 1e-6);
        assert!(
            (t.type_coord(0.3) - 1.5).abs() < 1e-6,
            "halfway at the bound"
        );
        assert!((t.type_coord(0.9) - 2.0).abs() < 1e-6);
        let single = TypeTable::from_mix(&CloudTypeMix {
            cumulonimbus: 2.0,
            ..CloudTypeMix::default()
        });
        assert_eq!(single.type_coord(0.5), 3.0);
    }
}
