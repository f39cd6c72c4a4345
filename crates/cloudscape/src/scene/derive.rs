//! Values a scene derives from others: the cloud layers and haze from `weather.metar`, the sun's
//! elevation and azimuth from `sun.time_of_day`. A value the file gives both ways is a located
//! error, and so is a METAR report that cannot be read (at the group, inside the string).

use std::ops::Range;

use toml::de::DeTable;

use super::metar::{self, SceneWeather};
use super::source_map::SourceMap;
use super::{MAX_LAYERS, Scene, SceneError, load, locate, solar_position};

/// Each value a scene derives others from, and the keys it derives: a document gives one or the
/// other, and a `--set` of the source replaces what the file gave of them
/// ([`super::overrides`]).
pub(super) const DERIVED: [(&str, &[&str]); 2] = [
    ("sun.time_of_day", &["sun.elevation_deg", "sun.azimuth_deg"]),
    ("weather.metar", &["layers", "sky.visibility_m"]),
];

/// The keys derived from `source`, one of [`DERIVED`]'s sources.
fn derived_from(source: &str) -> &'static [&'static str] {
    DERIVED
        .iter()
        .find(|(name, _)| *name == source)
        .map(|(_, derived)| *derived)
        .expect("a source listed in DERIVED")
}

/// Fills in the values `scene` derives from `weather.metar` and `sun.time_of_day`; `root` is the
/// merged document the scene came from, for locating errors.
pub(super) fn derive(
    scene: &mut Scene,
    root: &DeTable<'_>,
    sources: &SourceMap,
) -> Result<(), SceneError> {
    if let Some(time) = &scene.sun.time_of_day {
        keep_one(root, sources, "sun.time_of_day")?;
        solar_position(time).apply_to(&mut scene.sun);
    }
    if let Some(report) = &scene.weather.metar {
        keep_one(root, sources, "weather.metar")?;
        let weather = read_metar(report, root, sources)?;
        if weather.layers.len() > MAX_LAYERS {
            return Err(load::error_at(
                Some(root),
                sources,
                "weather.metar",
                format!(
                    "the report gives {} cloud layers; at most {MAX_LAYERS} can be drawn: leave \
                     out the highest",
                    weather.layers.len()
                ),
            ));
        }
        scene.layers = weather.layers;
        if let Some(visibility_m) = weather.visibility_m {
            scene.sky.visibility_m = visibility_m;
        }
    }
    Ok(())
}

/// An error at the first of `derived` the document gives, which `source` already sets.
fn keep_one(root: &DeTable<'_>, sources: &SourceMap, source: &str) -> Result<(), SceneError> {
    let derived = derived_from(source);
    let Some(given) = derived
        .iter()
        .find(|key| locate::given_span(root, &key.split('.').collect::<Vec<_>>()).is_some())
    else {
        return Ok(());
    };
    Err(load::error_at(
        Some(root),
        sources,
        given,
        format!(
            "{source} sets {}; keep one: {source} or {given}",
            derived.join(" and ")
        ),
    ))
}

/// Parses and maps the report; a bad group is located at the group inside the string.
fn read_metar(
    report: &str,
    root: &DeTable<'_>,
    sources: &SourceMap,
) -> Result<SceneWeather, SceneError> {
    let parsed = metar::parse(report).map_err(|error| {
        let value = locate::given_span(root, &["weather", "metar"]);
        let span = value.map(|value| group_span(&value, sources, report, &error));
        sources.error(
            span,
            Some("weather.metar".to_string()),
            format!("METAR group {error}"),
        )
    })?;
    Ok(SceneWeather::from_report(&parsed))
}

/// The span of the bad group in the source, when the string's text holds the report verbatim
/// (no escapes); else the span of the whole string.
fn group_span(
    value: &Range<usize>,
    sources: &SourceMap,
    report: &str,
    error: &metar::MetarError,
) -> Range<usize> {
    let start = sources
        .text_at(value)
        .and_then(|raw| raw.find(report))
        .map(|in_raw| value.start + in_raw + error.offset);
    start.map_or(value.clone(), |start| start..start + error.group.len())
}
