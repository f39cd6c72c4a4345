//! The ten cloud types of the sprite technique ([`CloudType`]; Wang 2003, "Real-world cloud
//! types": MSFS 2004 models ten, `../shared/references/peers.md`), each a recipe: the shape of its
//! boxes, how many sprites fill them, how large and how turned the sprites are, which of the 16
//! puff textures they wear, and how dense the cluster is (its cull radius).

use super::textures::{BLURRY, SOLID, WISPY};
use crate::scene::CloudType;

/// Every type, in declaration order.
pub const ALL_TYPES: [CloudType; 10] = [
    CloudType::FairWeather,
    CloudType::CumulusHumilis,
    CloudType::CumulusMediocris,
    CloudType::CumulusCongestus,
    CloudType::Cumulonimbus,
    CloudType::Stratocumulus,
    CloudType::Stratus,
    CloudType::Altocumulus,
    CloudType::Altostratus,
    CloudType::Nimbostratus,
];

/// Cull radius of typical clouds as a fraction of the cloud's height (Wang 2003, "Cloud sprite
/// generation": "1/3 of cloud height is good for typical clouds").
pub const CULL_FRACTION_TYPICAL: f32 = 1.0 / 3.0;
/// Cull radius of dense clouds as a fraction of the cloud's height (Wang 2003: "1/5 for dense
/// clouds").
pub const CULL_FRACTION_DENSE: f32 = 1.0 / 5.0;

/// How a type builds a cloud: the artist parameters of Wang 2003 ("Artist-specified
/// parameters": number of sprites, category, ranges of width, height and rotation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Recipe {
    /// Candidate sprites per cloud before culling (the artist's "# sprites", density).
    pub sprites: u32,
    /// Sprite width as fractions of the cloud's height, (min, max).
    pub width: (f32, f32),
    /// Sprite height as a fraction of its width, (min, max).
    pub aspect: (f32, f32),
    /// Sprite rotation about the view axis, degrees, (min, max).
    pub rotation_deg: (f32, f32),
    /// The puff textures it draws from (a bit mask over the 16 of the sheet).
    pub textures: u16,
    /// Cull radius as a fraction of the cloud's height.
    pub cull_fraction: f32,
    /// Footprint of a hand-made cloud of this type: width / height.
    pub footprint: f32,
    /// Stacked boxes of a hand-made cloud, each narrower than the one below by `taper`.
    pub tiers: u32,
    /// Width of each tier over the one below.
    pub taper: f32,
    /// Opacity of the type's sprites (Wang: "more transparency for stratus").
    pub opacity: f32,
    /// Sprites a shading group holds at most (Wang: 1-30).
    pub group_size: u32,
    /// A sheet (stratus, altostratus, nimbostratus): field sprites are sized by how far apart
    /// they lie across the deck, not by its thin height, so that they overlap into a veil.
    pub sheet: bool,
}

impl CloudType {
    /// The type's recipe. The proportions follow the WMO cloud atlas descriptions; sprite sizes
    /// are FlightGear's (`SGNewCloud`: sprites 200 x 150 m in clouds 500 x 400 m, so sprites about
    /// half the cloud's height), culling and opacity Wang 2003's.
    pub fn recipe(self) -> Recipe {
        use CloudType::*;
        let base = Recipe {
            sprites: 40,
            width: (0.6, 1.0),
            aspect: (0.75, 1.0),
            rotation_deg: (-180.0, 180.0),
            textures: SOLID,
            cull_fraction: CULL_FRACTION_TYPICAL,
            footprint: 1.5,
            tiers: 2,
            taper: 0.7,
            opacity: 1.0,
            group_size: 12,
            sheet: false,
        };
        match self {
            FairWeather => Recipe {
                sprites: 16,
                footprint: 2.5,
                tiers: 1,
                ..base
            },
            CumulusHumilis => Recipe {
                sprites: 30,
                footprint: 2.0,
                ..base
            },
            CumulusMediocris => base,
            CumulusCongestus => Recipe {
                sprites: 60,
                footprint: 0.8,
                tiers: 3,
                cull_fraction: CULL_FRACTION_DENSE,
                width: (0.3, 0.5),
                ..base
            },
            Cumulonimbus => Recipe {
                sprites: 90,
                footprint: 0.7,
                tiers: 4,
                taper: 1.0,
                cull_fraction: CULL_FRACTION_DENSE,
                width: (0.25, 0.4),
                group_size: 20,
                ..base
            },
            Stratocumulus => Recipe {
                sprites: 40,
                footprint: 4.0,
                tiers: 1,
                width: (1.0, 1.8),
                aspect: (0.5, 0.8),
                textures: SOLID | BLURRY,
                ..base
            },
            Stratus => Recipe {
                sprites: 30,
                footprint: 6.0,
                tiers: 1,
                width: (1.5, 2.5),
                aspect: (0.35, 0.6),
                rotation_deg: (-15.0, 15.0),
                textures: BLURRY,
                opacity: 0.7,
                sheet: true,
                ..base
            },
            Altocumulus => Recipe {
                sprites: 24,
                footprint: 3.0,
                tiers: 1,
                width: (0.5, 0.9),
                textures: SOLID | BLURRY,
                opacity: 0.85,
                ..base
            },
            Altostratus => Recipe {
                sprites: 24,
                footprint: 6.0,
                tiers: 1,
                width: (1.5, 2.5),
                aspect: (0.3, 0.5),
                rotation_deg: (-10.0, 10.0),
                textures: WISPY | BLURRY,
                opacity: 0.55,
                sheet: true,
                ..base
            },
            Nimbostratus => Recipe {
                sprites: 50,
                footprint: 4.0,
                tiers: 1,
                width: (0.8, 1.3),
                aspect: (0.5, 0.8),
                rotation_deg: (-30.0, 30.0),
                textures: BLURRY,
                cull_fraction: CULL_FRACTION_DENSE,
                sheet: true,
                ..base
            },
        }
    }

    /// The type a cloud of the field becomes: from the field's type coordinate (0 stratus, 1
    /// stratocumulus, 2 cumulus, 3 cumulonimbus; `field::profile`), the cloud's base altitude
    /// (above 2 km the WMO's middle étage: alto- types) and its height.
    pub fn from_field(type_coord: f32, base_m: f32, height_m: f32) -> CloudType {
        use CloudType::*;
        let high = base_m > MIDDLE_ETAGE_BASE_M;
        match type_coord {
            t if t < 0.5 && high => Altostratus,
            t if t < 0.5 && height_m > NIMBOSTRATUS_HEIGHT_M => Nimbostratus,
            t if t < 0.5 => Stratus,
            t if t < 1.5 && high => Altocumulus,
            t if t < 1.5 => Stratocumulus,
            t if t < 2.5 => match height_m {
                h if h < 300.0 => FairWeather,
                h if h < 700.0 => CumulusHumilis,
                h if h < 1500.0 => CumulusMediocris,
                _ => CumulusCongestus,
            },
            _ => Cumulonimbus,
        }
    }

    /// The name scene and model files use.
    pub fn name(self) -> String {
        toml::Value::try_from(self)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default()
    }
}

/// Lowest base of the middle étage in temperate latitudes, m (WMO International Cloud Atlas:
/// 2-7 km).
pub const MIDDLE_ETAGE_BASE_M: f32 = 2000.0;
/// A stratiform cloud thicker than this is nimbostratus, m (WMO: nimbostratus is "thick enough
/// to blot out the sun", typically over 2 km; lowered for the layers of a game scene).
pub const NIMBOSTRATUS_HEIGHT_M: f32 = 1200.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ten_distinct_types_with_distinct_recipes_and_names() {
        let names: std::collections::HashSet<String> = ALL_TYPES.iter().map(|t| t.name()).collect();
        assert_eq!(names.len(), 10);
        assert!(names.contains("cumulus_congestus"));
        for (i, a) in ALL_TYPES.iter().enumerate() {
            for b in &ALL_TYPES[i + 1..] {
                assert_ne!(a.recipe(), b.recipe(), "{a:?} and {b:?}");
            }
        }
    }

    #[test]
    fn the_field_maps_onto_every_type() {
        let mut seen = std::collections::HashSet::new();
        for t in [0.0, 1.0, 2.0, 3.0] {
            for base in [500.0, 3000.0] {
                for height in [200.0, 500.0, 1000.0, 2000.0] {
                    seen.insert(CloudType::from_field(t, base, height));
                }
            }
        }
        assert_eq!(seen.len(), 10, "{seen:?}");
    }

    #[test]
    fn dense_types_cull_at_a_fifth_typical_at_a_third() {
        assert_eq!(CloudType::Cumulonimbus.recipe().cull_fraction, 0.2);
        assert_eq!(
            CloudType::CumulusMediocris.recipe().cull_fraction,
            1.0 / 3.0
        );
    }
}
