//! METAR weather reports: a parser of the aerodrome routine report into a typed [`Report`], and the
//! rules that turn a report into the scene's cloud layers and haze ([`SceneWeather`]).
//!
//! The report is the code form FM 15 METAR (and FM 16 SPECI) of WMO, *Manual on Codes*, Volume I.1,
//! WMO-No. 306, Part A, with the conventions of ICAO Annex 3 (*Meteorological Service for
//! International Air Navigation*, appendix 3) and the United States' variant in the FAA's
//! *Aeronautical Information Manual*, chapter 7 (statute miles, `A` altimeter settings, `CLR`).
//! Groups come in the order FM 15 gives them, each optional unless said:
//!
//! | group | example | here |
//! |---|---|---|
//! | `METAR`, `SPECI`, `COR` | `METAR COR` | [`Report::kind`], [`Report::corrected`] |
//! | station (required) | `EGLL` | [`Report::station`] |
//! | day and time, UTC (required) | `011750Z` | [`Report::time`] |
//! | `AUTO`, `COR` | `AUTO` | [`Report::automatic`] |
//! | wind | `24012KT`, `24012G25KT`, `VRB02KT`, `00000KT`, `05005MPS`, `/////KT` | [`Report::wind`] |
//! | wind variation | `210V270` | [`Wind::varying_deg`] |
//! | visibility | `9999`, `0800`, `CAVOK`, `10SM`, `1/2SM`, `1 1/2SM`, `P6SM`, `M1/4SM` | [`Report::visibility`] |
//! | lowest visibility by direction | `1200NE` | parsed and ignored |
//! | runway visual range | `R27L/P1500N`, `R09/0600V1000U` | parsed and ignored |
//! | present weather | `-RA`, `+TSRA`, `VCSH`, `BR`, `FZFG` | [`Report::weather`] |
//! | cloud | `FEW012`, `BKN045CB`, `SCT030TCU`, `OVC///`, `BKN020///` | [`SkyGroup::Cloud`] |
//! | vertical visibility | `VV002`, `VV///` | [`SkyGroup::VerticalVisibility`] |
//! | no cloud | `SKC`, `CLR`, `NSC`, `NCD` | [`SkyGroup::Clear`] |
//! | temperature / dew point, deg C | `18/12`, `M02/M05` | [`Report::temperature_c`] |
//! | pressure | `Q1012` (hPa), `A2992` (hundredths of inHg) | [`Report::qnh_hpa`] |
//! | recent weather | `RERA` | parsed and ignored |
//!
//! The report ends at the trend or the remarks (`NOSIG`, `BECMG`, `TEMPO`, `RMK`), which are not
//! read, or at a closing `=`. Any other group is an error that names it and its column.

mod layers;
mod parse;

pub use layers::{CloudGenus, SceneWeather};
pub use parse::parse;

/// A report that cannot be read: the group at fault, where it is, and what was expected.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("`{group}` at column {column} of the report: {message}")]
pub struct MetarError {
    /// The group as written in the report (empty for an empty report).
    pub group: String,
    /// 1-based column of the group's first character in the report, in characters.
    pub column: usize,
    /// Byte offset of the group in the report text.
    pub offset: usize,
    /// What is wrong and what was expected.
    pub message: String,
}

/// A METAR or SPECI report, as far as this parser reads it.
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// Routine (`METAR`, also when the report has no leading word) or special (`SPECI`).
    pub kind: ReportKind,
    /// ICAO location indicator of the aerodrome, e.g. `EGLL`.
    pub station: String,
    /// Day of the month and time of the observation, UTC.
    pub time: ObservationTime,
    /// Whether the report corrects an earlier one (`COR`).
    pub corrected: bool,
    /// Whether the report was made without a human observer (`AUTO`).
    pub automatic: bool,
    /// The surface wind; `None` when the group is missing or not available (`/////KT`).
    pub wind: Option<Wind>,
    /// The prevailing visibility; `None` when the group is missing.
    pub visibility: Option<Visibility>,
    /// Whether the report says `CAVOK`: visibility 10 km or more, no cloud below 5000 ft or the
    /// highest minimum sector altitude, no cumulonimbus or towering cumulus, no significant weather.
    pub cavok: bool,
    /// Present weather groups, in order.
    pub weather: Vec<WeatherGroup>,
    /// Cloud, vertical visibility and no-cloud groups, in order (bottom up for clouds).
    pub sky: Vec<SkyGroup>,
    /// Air temperature, whole deg C.
    pub temperature_c: Option<i32>,
    /// Dew-point temperature, whole deg C.
    pub dew_point_c: Option<i32>,
    /// Altimeter setting (QNH), hPa; an `A` group in inches of mercury is converted with
    /// 1 inHg = 33.8639 hPa.
    pub qnh_hpa: Option<f32>,
}

/// Routine or special report.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReportKind {
    /// FM 15 METAR, the routine report.
    Metar,
    /// FM 16 SPECI, a special report made when the weather changes significantly.
    Speci,
}

/// Day of the month and time of an observation, UTC (group `YYGGggZ`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ObservationTime {
    /// Day of the month, 1..31.
    pub day: u32,
    /// Hour, 0..23.
    pub hour: u32,
    /// Minute, 0..59.
    pub minute: u32,
}

/// The surface wind, a 10-minute mean at 10 m above the ground (WMO-No. 306, FM 15 regulation 15.5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wind {
    /// Direction the wind blows from, degrees clockwise from true north (10-degree steps); `None`
    /// for variable (`VRB`) and for calm (`00000KT`).
    pub from_deg: Option<u32>,
    /// Mean speed, m/s, converted from knots (1 kt = 0.514444 m/s), m/s or km/h.
    pub speed_m_per_s: f32,
    /// Gust speed, m/s (`G` group).
    pub gust_m_per_s: Option<f32>,
    /// The extreme directions between which the wind varies (`dddVddd`), degrees.
    pub varying_deg: Option<[u32; 2]>,
}

/// A visibility, as a distance and how the report bounds it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Visibility {
    /// Distance, m (statute miles converted with 1 mi = 1609.344 m).
    pub distance_m: f32,
    /// Whether the distance is exact or a bound.
    pub bound: Bound,
}

/// How a reported value bounds the true one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bound {
    /// The value itself, to the reporting step.
    Exact,
    /// The value or more: `9999` and `CAVOK` (10 km or more), `P6SM`.
    AtLeast,
    /// Less than the value: `0000` (less than 50 m), `M1/4SM`.
    LessThan,
}

/// Defines a code table: an enum whose variants each have a code letters and a doc line, with
/// `code()` and `from_code()`.
macro_rules! code_table {
    ($(#[$meta:meta])* $name:ident { $($(#[$doc:meta])* $variant:ident = $code:literal,)+ }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum $name {
            $($(#[$doc])* $variant,)+
        }

        impl $name {
            /// Every entry of the table.
            pub const ALL: &[$name] = &[$($name::$variant,)+];

            /// The letters the report uses.
            pub fn code(self) -> &'static str {
                match self {
                    $($name::$variant => $code,)+
                }
            }

            /// The entry written `code`, if any.
            pub fn from_code(code: &str) -> Option<$name> {
                $name::ALL.iter().copied().find(|entry| entry.code() == code)
            }
        }
    };
}

code_table! {
    /// Cloud amount in eighths of the sky (oktas), code table 2700 of WMO-No. 306.
    Cover {
        /// Few: 1 to 2 oktas.
        Few = "FEW",
        /// Scattered: 3 to 4 oktas.
        Scattered = "SCT",
        /// Broken: 5 to 7 oktas.
        Broken = "BKN",
        /// Overcast: 8 oktas.
        Overcast = "OVC",
    }
}

code_table! {
    /// The convective clouds a cloud group names.
    Convective {
        /// Cumulonimbus.
        Cumulonimbus = "CB",
        /// Towering cumulus (cumulus congestus).
        ToweringCumulus = "TCU",
    }
}

code_table! {
    /// A sky reported free of cloud, and how.
    ClearSky {
        /// Sky clear, by an observer.
        SkyClear = "SKC",
        /// No cloud below 12 000 ft detected by an automatic station (United States).
        Clear = "CLR",
        /// No significant cloud: none below 5000 ft or the minimum sector altitude, no CB or TCU.
        NoSignificantCloud = "NSC",
        /// No cloud detected by an automatic station.
        NoCloudDetected = "NCD",
    }
}

code_table! {
    /// Descriptor of present weather, code table 4678 of WMO-No. 306.
    Descriptor {
        /// Shallow.
        Shallow = "MI",
        /// Patches.
        Patches = "BC",
        /// Partial.
        Partial = "PR",
        /// Low drifting.
        LowDrifting = "DR",
        /// Blowing.
        Blowing = "BL",
        /// Showers.
        Showers = "SH",
        /// Thunderstorm.
        Thunderstorm = "TS",
        /// Freezing.
        Freezing = "FZ",
    }
}

code_table! {
    /// Weather phenomenon, code table 4678 of WMO-No. 306.
    Phenomenon {
        /// Drizzle.
        Drizzle = "DZ",
        /// Rain.
        Rain = "RA",
        /// Snow.
        Snow = "SN",
        /// Snow grains.
        SnowGrains = "SG",
        /// Ice pellets.
        IcePellets = "PL",
        /// Ice crystals (diamond dust).
        IceCrystals = "IC",
        /// Hail.
        Hail = "GR",
        /// Small hail or snow pellets.
        SmallHail = "GS",
        /// Unknown precipitation (automatic stations).
        UnknownPrecipitation = "UP",
        /// Mist: visibility 1000 m to 5000 m.
        Mist = "BR",
        /// Fog: visibility below 1000 m.
        Fog = "FG",
        /// Smoke.
        Smoke = "FU",
        /// Volcanic ash.
        VolcanicAsh = "VA",
        /// Widespread dust.
        Dust = "DU",
        /// Sand.
        Sand = "SA",
        /// Haze.
        Haze = "HZ",
        /// Spray.
        Spray = "PY",
        /// Dust or sand whirls.
        DustWhirls = "PO",
        /// Squalls.
        Squalls = "SQ",
        /// Funnel cloud, tornado or waterspout.
        FunnelCloud = "FC",
        /// Sandstorm.
        Sandstorm = "SS",
        /// Duststorm.
        Duststorm = "DS",
    }
}

/// How strong present weather is, or that it is near rather than at the aerodrome.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Intensity {
    /// `-`.
    Light,
    /// No sign.
    Moderate,
    /// `+`.
    Heavy,
    /// `VC`: within 8 km of the aerodrome but not at it.
    Vicinity,
}

/// One present-weather group, e.g. `+TSRA`: intensity, descriptor and phenomena.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WeatherGroup {
    /// Intensity or proximity.
    pub intensity: Intensity,
    /// Descriptor, e.g. showers or thunderstorm.
    pub descriptor: Option<Descriptor>,
    /// Phenomena, e.g. rain and snow; none for a bare `TS` or `VCSH`.
    pub phenomena: Vec<Phenomenon>,
}

/// One cloud layer of the report.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CloudGroup {
    /// Amount.
    pub cover: Cover,
    /// Height of the base above the aerodrome, hundreds of feet; `None` for `///` (not known, or
    /// below the station).
    pub base_hundreds_ft: Option<u32>,
    /// Cumulonimbus or towering cumulus, when named.
    pub convective: Option<Convective>,
}

/// One group of the sky condition.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SkyGroup {
    /// A cloud layer (`FEW`, `SCT`, `BKN`, `OVC`).
    Cloud(CloudGroup),
    /// Sky obscured (fog, snow): vertical visibility in hundreds of feet (`VVhhh`); `None` for
    /// `VV///`.
    VerticalVisibility(Option<u32>),
    /// No cloud.
    Clear(ClearSky),
}

impl Cover {
    /// The oktas (eighths of the sky covered) the amount stands for: FEW 1-2, SCT 3-4, BKN 5-7,
    /// OVC 8 (ICAO Annex 3, appendix 3, 4.5.4.3; WMO-No. 306 code table 2700).
    pub fn oktas(self) -> std::ops::RangeInclusive<u32> {
        match self {
            Cover::Few => 1..=2,
            Cover::Scattered => 3..=4,
            Cover::Broken => 5..=7,
            Cover::Overcast => 8..=8,
        }
    }
}

/// Metres in one foot (exact, international foot).
pub const METRES_PER_FOOT: f32 = 0.3048;

impl CloudGroup {
    /// Height of the base above the aerodrome, m; `None` when the report does not give it.
    pub fn base_m(&self) -> Option<f32> {
        self.base_hundreds_ft
            .map(|h| h as f32 * 100.0 * METRES_PER_FOOT)
    }
}
