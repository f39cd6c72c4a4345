//! From a report to the scene: one cloud layer per cloud group, the wind, and the haze.
//!
//! The rules (`docs/weather.md` explains them with their sources):
//!
//! - **Genus** from the cover, the base and a CB/TCU mark, by the étages (levels) of the WMO
//!   *International Cloud Atlas* (WMO-No. 407) for temperate regions, split at 2 km and 6 km
//!   ([`CloudGenus::of`]).
//! - **Shape**: each genus is drawn with one of the field's four types and has a typical depth and
//!   extinction ([`CloudGenus`]'s table). The layer's `thickness_m` is sized so that the type's
//!   height profile ([`TYPE_GRADIENTS`], which fills only part of a layer)
//!   spans the genus' depth.
//! - **Cover**: FEW, SCT and BKN get the layer `coverage` that makes the measured fraction of cloudy
//!   columns of that genus land mid-okta (FEW 1.5/8, SCT 3.5/8, BKN 6/8); OVC gets coverage 1, a
//!   sky with no gaps.
//! - **Wind**: the surface wind, blowing *from* its direction, carries every layer, scaled to the
//!   layer's base by the 1/7 power law up to 1 km ([`wind_at_m_per_s`]).
//! - **Haze**: the visibility group sets `sky.visibility_m` ([`scene_visibility_m`]).
//! - **Obscured sky** (`VV`): a stratus (fog) layer from the ground to the vertical visibility,
//!   which leaves 5 % contrast at that height; the visibility group's haze fogs the view too.
//! - `CAVOK`, `SKC`, `CLR`, `NSC`, `NCD`: no layers. Cloud groups whose base is not given (`///`)
//!   are left out.

use super::{CloudGroup, Convective, Cover, Report, SkyGroup, Visibility, Wind};
use crate::scene::{CloudLayer, CloudTypeMix, TYPE_GRADIENTS};

/// What a report sets in a scene.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneWeather {
    /// One layer per cloud group (and one for a vertical-visibility group), bottom up.
    pub layers: Vec<CloudLayer>,
    /// `sky.visibility_m` from the visibility group; `None` when the report has none.
    pub visibility_m: Option<f32>,
}

impl SceneWeather {
    /// The layers and haze of `report`, by the rules of this module.
    pub fn from_report(report: &Report) -> SceneWeather {
        let visibility_m = report.visibility.map(scene_visibility_m);
        let mut layers: Vec<CloudLayer> = report
            .sky
            .iter()
            .filter_map(|group| match group {
                SkyGroup::Cloud(cloud) => cloud_layer(cloud),
                SkyGroup::VerticalVisibility(height) => Some(obscuring_layer(*height)),
                SkyGroup::Clear(_) => None,
            })
            .collect();
        layers.sort_by(|a, b| a.bottom_m.total_cmp(&b.bottom_m));
        for (index, layer) in layers.iter_mut().enumerate() {
            layer.wind_m_per_s = report
                .wind
                .map_or([0.0, 0.0], |w| wind_at_m_per_s(&w, layer.bottom_m));
            layer.noise_seed = index as u32 + 1;
        }
        SceneWeather {
            layers,
            visibility_m,
        }
    }
}

/// The cloud genera the report's layers are drawn as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CloudGenus {
    /// Stratus: a low grey sheet (BKN or OVC based below 600 m).
    Stratus,
    /// Stratocumulus: a low lumpy layer (BKN or OVC based from 600 m to 2 km).
    Stratocumulus,
    /// Cumulus: low heaps (FEW or SCT below 2 km).
    Cumulus,
    /// Towering cumulus, cumulus congestus (TCU).
    ToweringCumulus,
    /// Cumulonimbus (CB), up to about 10 km.
    Cumulonimbus,
    /// Altocumulus: a thin mid-level layer of heaps (FEW, SCT or BKN from 2 to 6 km).
    Altocumulus,
    /// Altostratus: a mid-level grey sheet (OVC from 2 to 6 km).
    Altostratus,
    /// Cirrus and cirrocumulus: thin ice, in patches (FEW, SCT or BKN above 6 km).
    Cirrus,
    /// Cirrostratus: a thin ice veil (OVC above 6 km).
    Cirrostratus,
}

/// Top of the low étage, m (WMO-No. 407: low clouds from the surface to 2 km).
pub const LOW_TOP_M: f32 = 2000.0;
/// Bottom of the high étage as drawn here, m (WMO-No. 407 gives 5-13 km for high clouds and
/// 2-7 km for middle clouds in temperate regions; the étages overlap, and we split at 6 km).
pub const HIGH_BOTTOM_M: f32 = 6000.0;
/// Highest base of stratus, m: stratus is based below about 2000 ft (FAA-H-8083-28, *Aviation
/// Weather Handbook*, chapter 14, and WMO-No. 407 put its base near the ground to a few hundred
/// metres); broken or overcast cloud based higher is stratocumulus.
pub const STRATUS_TOP_BASE_M: f32 = 600.0;
/// Top of a cumulonimbus, m: near the mid-latitude tropopause, where the anvil spreads.
pub const CUMULONIMBUS_TOP_M: f32 = 10_000.0;
/// Least depth of a cumulonimbus, m, for one based unusually high.
pub const CUMULONIMBUS_LEAST_DEPTH_M: f32 = 3000.0;

/// The field's four cloud types (the axis of [`crate::field::profile`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FieldType {
    Stratus = 0,
    Stratocumulus = 1,
    Cumulus = 2,
    Cumulonimbus = 3,
}

impl FieldType {
    /// A mix of this type alone.
    fn mix(self) -> CloudTypeMix {
        let mut mix = CloudTypeMix::default();
        *match self {
            FieldType::Stratus => &mut mix.stratus,
            FieldType::Stratocumulus => &mut mix.stratocumulus,
            FieldType::Cumulus => &mut mix.cumulus,
            FieldType::Cumulonimbus => &mut mix.cumulonimbus,
        } = 1.0;
        mix
    }

    /// Fraction of a layer's thickness the type's height profile fills (its fall end).
    fn filled_fraction(self) -> f32 {
        TYPE_GRADIENTS[self as usize][3]
    }
}

/// How one genus is drawn.
struct Look {
    /// The field type.
    field_type: FieldType,
    /// Depth of the cloud from base to top, m (cumulonimbus: see [`CUMULONIMBUS_TOP_M`]).
    depth_m: f32,
    /// Extinction of the densest cloud, m^-1.
    extinction_per_m: f32,
    /// Layer `coverage` for FEW, SCT and BKN, measured so that the cloudy fraction of columns lands
    /// mid-okta (`tests/metar.rs`, `print_metar_coverage`).
    coverage: [f32; 3],
}

/// Depths are typical values for each genus (rounded; e.g. Wallace & Hobbs 2006, *Atmospheric
/// Science*, 2nd ed., chapter 6), taken at the thick end for the sheets: the field's noise varies
/// little across a thin sheet, and its erosion then empties whole columns, so 300 m of stratus or
/// 400 m of altocumulus left 10-50 % of an overcast sky clear (measured with
/// `print_overcast_optical_depth` in `tests/metar.rs`); 800 m leaves no gaps. Extinction is
/// sigma = 3 LWC / (2 rho_w r_e) (physics.md) with typical liquid water content and effective
/// radius: stratus and stratocumulus LWC 0.25-0.3 g/m^3, r_e 8-10 um (Miles, Verlinde & Clothiaux
/// 2000, J. Atmos. Sci. 57) give 0.045 m^-1 (an overcast sheet's median optical depth is then 7-10);
/// cumulus 0.05 m^-1 and congestus and cumulonimbus 0.08 m^-1 within physics.md's 0.04-0.1 m^-1;
/// altocumulus and altostratus LWC about 0.1 g/m^3 give 0.02 m^-1. Cirrus and cirrostratus, 1000 m
/// of ice at 0.0045 m^-1, have median column optical depths of 1-1.4: opaque cirrus in Sassen &
/// Cho's (1992, J. Appl. Meteor. 31) classes (thin 0.03-0.3, opaque 0.3-3).
///
/// The coverages were measured with `print_metar_coverage` in `tests/metar.rs` (400 columns over
/// the default weather map, four layer seeds, a column cloudy above optical depth 1, or 0.3 for
/// cirrus); re-measure when the field's noise or profiles change.
#[rustfmt::skip]
fn look(genus: CloudGenus) -> Look {
    use FieldType as T;
    let look = |field_type, depth_m, extinction_per_m, coverage| Look { field_type, depth_m, extinction_per_m, coverage };
    match genus {
        CloudGenus::Stratus => look(T::Stratus, 800.0, 0.045, [0.521, 0.788, 0.959]),
        CloudGenus::Stratocumulus => look(T::Stratocumulus, 800.0, 0.045, [0.412, 0.709, 0.928]),
        CloudGenus::Cumulus => look(T::Cumulus, 1500.0, 0.05, [0.477, 0.763, 0.946]),
        CloudGenus::ToweringCumulus => look(T::Cumulus, 4000.0, 0.08, [0.353, 0.681, 0.903]),
        CloudGenus::Cumulonimbus => look(T::Cumulonimbus, 0.0, 0.08, [0.074, 0.371, 0.723]),
        CloudGenus::Altocumulus => look(T::Stratocumulus, 800.0, 0.02, [0.434, 0.750, 0.934]),
        CloudGenus::Altostratus => look(T::Stratus, 1000.0, 0.02, [0.579, 0.824, 0.970]),
        CloudGenus::Cirrus => look(T::Stratocumulus, 1000.0, 0.0045, [0.390, 0.709, 0.928]),
        CloudGenus::Cirrostratus => look(T::Stratus, 1000.0, 0.0045, [0.598, 0.835, 0.975]),
    }
}

impl CloudGenus {
    /// The genus of a layer of `cover` based at `base_m` (above the aerodrome), `convective` when
    /// the group names CB or TCU. CB and TCU win at any base; otherwise low (below
    /// [`LOW_TOP_M`]) FEW and SCT are cumulus, and BKN and OVC stratus (below
    /// [`STRATUS_TOP_BASE_M`]) or stratocumulus; mid-level OVC is altostratus and other mid-level
    /// cover altocumulus; high (from [`HIGH_BOTTOM_M`]) OVC is cirrostratus, the rest cirrus.
    pub fn of(cover: Cover, base_m: f32, convective: Option<Convective>) -> CloudGenus {
        let overcast = cover == Cover::Overcast;
        match convective {
            Some(Convective::Cumulonimbus) => CloudGenus::Cumulonimbus,
            Some(Convective::ToweringCumulus) => CloudGenus::ToweringCumulus,
            None if base_m < LOW_TOP_M => match cover {
                Cover::Few | Cover::Scattered => CloudGenus::Cumulus,
                _ if base_m < STRATUS_TOP_BASE_M => CloudGenus::Stratus,
                _ => CloudGenus::Stratocumulus,
            },
            None if base_m < HIGH_BOTTOM_M && overcast => CloudGenus::Altostratus,
            None if base_m < HIGH_BOTTOM_M => CloudGenus::Altocumulus,
            None if overcast => CloudGenus::Cirrostratus,
            None => CloudGenus::Cirrus,
        }
    }

    /// The layer of this genus based at `bottom_m` with `cover` (wind and seed left at zero).
    pub fn layer(self, bottom_m: f32, cover: Cover) -> CloudLayer {
        let look = look(self);
        let depth_m = match self {
            CloudGenus::Cumulonimbus => {
                (CUMULONIMBUS_TOP_M - bottom_m).max(CUMULONIMBUS_LEAST_DEPTH_M)
            }
            _ => look.depth_m,
        };
        let coverage = match cover {
            Cover::Few => look.coverage[0],
            Cover::Scattered => look.coverage[1],
            Cover::Broken => look.coverage[2],
            Cover::Overcast => 1.0,
        };
        CloudLayer {
            bottom_m,
            thickness_m: depth_m / look.field_type.filled_fraction(),
            coverage,
            extinction_per_m: look.extinction_per_m,
            types: look.field_type.mix(),
            wind_m_per_s: [0.0, 0.0],
            noise_seed: 0,
        }
    }
}

/// The layer of a cloud group; `None` when the report gives no base.
fn cloud_layer(group: &CloudGroup) -> Option<CloudLayer> {
    let base_m = group.base_m()?;
    Some(CloudGenus::of(group.cover, base_m, group.convective).layer(base_m, group.cover))
}

/// `ln(20)`: the meteorological optical range is where a beam keeps 5 % of its light (WMO-No. 8,
/// *Guide to Instruments and Methods of Observation*, volume I, chapter 9), so its extinction is
/// `ln(20) / MOR`; aeronautical visibility by day equals the MOR (ICAO Annex 3, chapter 1).
const MOR_CONTRAST_DEPTH: f32 = 2.995_732;
/// `ln(50)`: the scene's visibility is where 2 % contrast is left (Koschmieder; see
/// `crate::environment`).
const SCENE_CONTRAST_DEPTH: f32 = 3.912_023;

/// Haze extinction of a reported visibility, m^-1: `ln(20) / MOR`.
fn haze_extinction_per_m(visibility: Visibility) -> f32 {
    MOR_CONTRAST_DEPTH / visibility.distance_m
}

/// `sky.visibility_m` for a reported visibility: the same haze extinction at the scene's 2 %
/// contrast threshold, `MOR ln(50) / ln(20) = 1.306 MOR`, within the scene's 100 m..10 000 km.
/// A bound is taken at its value: `9999` and `CAVOK` (10 km or more) give 13.1 km, the clearest air
/// the report vouches for, not a guess beyond it.
pub fn scene_visibility_m(visibility: Visibility) -> f32 {
    (SCENE_CONTRAST_DEPTH / haze_extinction_per_m(visibility)).clamp(100.0, 1.0e7)
}

/// The obscuring layer of a `VV` group: stratus (fog) from the ground to the vertical visibility
/// (at least 30 m; 100 ft when `VV///`), OVC. The vertical visibility is how far one sees up into
/// the obscuring layer (ICAO Annex 3, appendix 3, 4.5.1), so its extinction is the MOR's,
/// `ln(20) / VV`.
fn obscuring_layer(height_hundreds_ft: Option<u32>) -> CloudLayer {
    let top_m = (height_hundreds_ft.unwrap_or(1) as f32 * 100.0 * super::METRES_PER_FOOT).max(30.0);
    CloudLayer {
        thickness_m: top_m / FieldType::Stratus.filled_fraction(),
        extinction_per_m: (MOR_CONTRAST_DEPTH / top_m).min(1.0),
        ..CloudGenus::Stratus.layer(0.0, Cover::Overcast)
    }
}

/// Height of the surface wind measurement, m (WMO-No. 8: 10 m over open terrain).
pub const SURFACE_WIND_HEIGHT_M: f32 = 10.0;
/// Height up to which the wind grows by the power law, m: about the top of the daytime boundary
/// layer (Stull 1988, *An Introduction to Boundary Layer Meteorology*, chapter 1); above it the
/// wind is taken as constant.
pub const POWER_LAW_TOP_M: f32 = 1000.0;

/// Wind velocity `[east, south]`, m/s, at `height_m` from the surface wind `wind`: the wind goes
/// toward `from_deg + 180`, so `[-s sin d, s cos d]`; its speed grows with height by the 1/7 power
/// law `u(z) = u10 (z / 10 m)^(1/7)` (neutral stability over open terrain; Peterson & Hennessey
/// 1978, J. Appl. Meteor. 17) up to [`POWER_LAW_TOP_M`] (a factor 1.93). Calm and variable winds
/// give no drift.
pub fn wind_at_m_per_s(wind: &Wind, height_m: f32) -> [f32; 2] {
    let Some(from_deg) = wind.from_deg else {
        return [0.0, 0.0];
    };
    let z = height_m.clamp(SURFACE_WIND_HEIGHT_M, POWER_LAW_TOP_M);
    let speed = wind.speed_m_per_s * (z / SURFACE_WIND_HEIGHT_M).powf(1.0 / 7.0);
    let from = (from_deg as f32).to_radians();
    [-speed * from.sin(), speed * from.cos()]
}

#[cfg(test)]
mod tests {
    use super::super::parse;
    use super::*;

    fn weather(text: &str) -> SceneWeather {
        SceneWeather::from_report(&parse(text).unwrap())
    }

    #[test]
    fn genus_follows_cover_base_and_convection() {
        use CloudGenus as G;
        let of = |cover, base_m, convective| CloudGenus::of(cover, base_m, convective);
        assert_eq!(of(Cover::Overcast, 120.0, None), G::Stratus);
        assert_eq!(of(Cover::Broken, 900.0, None), G::Stratocumulus);
        assert_eq!(of(Cover::Few, 300.0, None), G::Cumulus);
        assert_eq!(of(Cover::Scattered, 1500.0, None), G::Cumulus);
        assert_eq!(
            of(Cover::Few, 450.0, Some(Convective::Cumulonimbus)),
            G::Cumulonimbus
        );
        assert_eq!(
            of(Cover::Scattered, 900.0, Some(Convective::ToweringCumulus)),
            G::ToweringCumulus
        );
        assert_eq!(of(Cover::Broken, 3000.0, None), G::Altocumulus);
        assert_eq!(of(Cover::Overcast, 3048.0, None), G::Altostratus);
        assert_eq!(of(Cover::Scattered, 7600.0, None), G::Cirrus);
        assert_eq!(of(Cover::Overcast, 7600.0, None), G::Cirrostratus);
    }

    #[test]
    fn layer_bands_give_the_genus_depth_to_the_type_profile() {
        let stratus = CloudGenus::Stratus.layer(120.0, Cover::Overcast);
        assert_eq!(stratus.types.stratus, 1.0);
        assert!((stratus.thickness_m * TYPE_GRADIENTS[0][3] - 800.0).abs() < 1e-3);
        assert_eq!(stratus.coverage, 1.0);
        let cb = CloudGenus::Cumulonimbus.layer(1372.0, Cover::Broken);
        assert!((cb.bottom_m + cb.thickness_m - CUMULONIMBUS_TOP_M).abs() < 1e-3);
        assert_eq!(cb.types.cumulonimbus, 1.0);
        let tcu = CloudGenus::ToweringCumulus.layer(900.0, Cover::Scattered);
        assert_eq!((tcu.types.cumulus, tcu.thickness_m), (1.0, 4000.0));
    }

    #[test]
    fn wind_goes_where_it_blows_to_and_grows_with_height() {
        let wind = |from_deg| Wind {
            from_deg,
            speed_m_per_s: 10.0,
            gust_m_per_s: None,
            varying_deg: None,
        };
        let [east, south] = wind_at_m_per_s(&wind(Some(270)), 10.0);
        assert!(
            (east - 10.0).abs() < 1e-4 && south.abs() < 1e-4,
            "a west wind blows east"
        );
        let [east, south] = wind_at_m_per_s(&wind(Some(0)), 10.0);
        assert!(
            east.abs() < 1e-4 && (south - 10.0).abs() < 1e-4,
            "a north wind blows south"
        );
        let aloft = wind_at_m_per_s(&wind(Some(270)), 3000.0)[0];
        assert!(
            (aloft - 10.0 * 100f32.powf(1.0 / 7.0)).abs() < 1e-3,
            "{aloft}"
        );
        assert_eq!(wind_at_m_per_s(&wind(None), 500.0), [0.0, 0.0]);
    }

    #[test]
    fn visibility_sets_the_haze_at_the_scenes_contrast() {
        let v = weather("EGLL 011750Z 24012KT 9999 NSC")
            .visibility_m
            .unwrap();
        assert!((v - 13_058.0).abs() < 2.0, "{v}");
        let v = weather("EGLL 011750Z 24012KT 0800 FG NSC")
            .visibility_m
            .unwrap();
        assert!((v - 800.0 * 1.3059).abs() < 1.0, "{v}");
        assert_eq!(weather("EGLL 011750Z 24012KT NSC").visibility_m, None);
    }

    #[test]
    fn clear_skies_have_no_layers() {
        for sky in ["CAVOK", "9999 SKC", "9999 NSC", "10SM CLR", "9999 NCD"] {
            let w = weather(&format!("LFPG 011730Z 24012KT {sky} 18/12 Q1012"));
            assert!(w.layers.is_empty(), "{sky}");
        }
    }

    #[test]
    fn an_obscured_sky_is_fog_from_the_ground() {
        let w = weather("EGLL 010650Z 00000KT 0150 FG VV001 08/08 Q1020");
        let [fog] = &w.layers[..] else {
            panic!("{:?}", w.layers)
        };
        assert_eq!(
            (fog.bottom_m, fog.coverage, fog.types.stratus),
            (0.0, 1.0, 1.0)
        );
        assert!((fog.thickness_m * TYPE_GRADIENTS[0][3] - 30.48).abs() < 1e-3);
        assert!((fog.extinction_per_m - 2.9957 / 30.48).abs() < 1e-4);
    }

    #[test]
    fn groups_without_a_base_are_left_out() {
        let w = weather("EGLL 011750Z AUTO 24012KT 9999 BKN/// SCT040 18/12 Q1012");
        assert_eq!(w.layers.len(), 1);
        assert!((w.layers[0].bottom_m - 1219.2).abs() < 1e-2);
    }
}
