//! Writing a scene back as a scene file, and keeping live edits consistent with the values a scene
//! derives from others (see [`super::derive`]).

use std::path::Path;

use super::{Scene, solar_position};
use crate::fsutil::write_bytes_atomically;

/// Values a scene derives from another key, which a file must leave out when it gives that key:
/// (the source, the derived keys).
const DERIVED: [(&str, &[&str]); 2] = [
    ("sun.time_of_day", &["sun.elevation_deg", "sun.azimuth_deg"]),
    ("weather.metar", &["layers", "sky.visibility_m"]),
];

impl Scene {
    /// The scene as a scene file that loads back to exactly this scene: every value written out,
    /// but those derived from another key (the sun's angles from `sun.time_of_day`, the layers and
    /// the visibility from `weather.metar`), which the file must leave out.
    pub fn to_toml(&self) -> String {
        self.to_toml_before_setting("")
    }

    /// Like [`Scene::to_toml`], for a file that `--set key=...` will then be applied to: when `key`
    /// is (or lies within) a key others derive from, the values derived from it are left out too,
    /// so that the new value takes their place.
    pub fn to_toml_before_setting(&self, key: &str) -> String {
        let mut table = toml::Table::try_from(self).expect("a scene serialises to a TOML table");
        for (source, derived) in DERIVED {
            if lookup(&table, source).is_some() || within(key, source) {
                derived.iter().for_each(|key| remove(&mut table, key));
            }
        }
        toml::to_string(&table).expect("a TOML table serialises")
    }

    /// Writes [`Scene::to_toml`] to `path`, whole or not at all (through a temporary file).
    pub fn write_toml(&self, path: &Path) -> std::io::Result<()> {
        write_bytes_atomically(path, self.to_toml().as_bytes())
    }

    /// Keeps the scene consistent after a live edit of the value at dotted key `key`: an edit of a
    /// derived value drops the key it was derived from (the sun's angles drop `sun.time_of_day`;
    /// a layer or the visibility drops `weather.metar`), so that it stays as edited; an edit of
    /// the time of day moves the sun.
    pub fn settle_edit(&mut self, key: &str) {
        for (source, derived) in DERIVED {
            if derived.iter().any(|d| within(key, d)) {
                match source {
                    "sun.time_of_day" => self.sun.time_of_day = None,
                    _ => self.weather.metar = None,
                }
            }
        }
        if within(key, "sun.time_of_day") {
            if let Some(time) = &self.sun.time_of_day {
                solar_position(time).apply_to(&mut self.sun);
            }
        }
    }
}

/// Whether dotted key `key` is `prefix` or lies within it.
fn within(key: &str, prefix: &str) -> bool {
    key.strip_prefix(prefix)
        .is_some_and(|rest| rest.is_empty() || rest.starts_with('.'))
}

/// The value at dotted key `key` in `table`.
fn lookup<'a>(table: &'a toml::Table, key: &str) -> Option<&'a toml::Value> {
    let (parent, last) = split(key);
    let mut current = table;
    for segment in parent {
        current = current.get(segment)?.as_table()?;
    }
    current.get(last)
}

/// Removes the value at dotted key `key` from `table`, if there.
fn remove(table: &mut toml::Table, key: &str) {
    let (parent, last) = split(key);
    let mut current = table;
    for segment in parent {
        match current.get_mut(segment).and_then(toml::Value::as_table_mut) {
            Some(child) => current = child,
            None => return,
        }
    }
    current.remove(last);
}

/// The segments of `key` before its last, and its last.
fn split(key: &str) -> (impl Iterator<Item = &str>, &str) {
    let (parent, last) = key.rsplit_once('.').unwrap_or(("", key));
    (parent.split('.').filter(|s| !s.is_empty()), last)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{SceneDocument, TimeOfDay};

    /// `scene` written out and loaded back.
    fn round_trip(scene: &Scene) -> Scene {
        let text = scene.to_toml();
        SceneDocument::parse(&text, "saved", Path::new(""), &[])
            .unwrap_or_else(|e| panic!("{e}\n{text}"))
            .scene
    }

    #[test]
    fn every_example_scene_loads_back_exactly() {
        let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let mut count = 0;
        for entry in std::fs::read_dir(scenes).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                let scene = SceneDocument::load(Some(&path), &[]).unwrap().scene;
                assert_eq!(round_trip(&scene), scene, "{}", path.display());
                count += 1;
            }
        }
        assert!(count >= 8, "only {count} scenes found");
    }

    #[test]
    fn a_file_written_before_setting_a_source_leaves_its_derived_values_out() {
        let text = Scene::default().to_toml_before_setting("weather.metar");
        let report = "weather.metar=\"EDDM 011750Z 24012KT 9999 FEW040 18/12 Q1012\"";
        let scene = SceneDocument::parse(&text, "saved", Path::new(""), &[report.to_string()])
            .unwrap()
            .scene;
        assert!(scene.weather.metar.is_some());
        assert_ne!(scene.layers, Scene::default().layers);
    }

    #[test]
    fn edited_numbers_load_back_to_the_same_bits() {
        let mut scene = Scene::default();
        scene.layers[0].coverage = 0.1 + 0.2;
        scene.camera.yaw_deg = 1.0 / 3.0;
        scene.render.exposure_ev = -0.3;
        assert_eq!(round_trip(&scene), scene);
    }

    #[test]
    fn an_edit_of_a_derived_value_drops_its_source_and_a_time_of_day_moves_the_sun() {
        let mut scene = Scene::default();
        scene.sun.time_of_day = Some(TimeOfDay {
            solar_time_h: 9.0,
            latitude_deg: 48.0,
            day_of_year: 172,
        });
        scene.settle_edit("sun.time_of_day.solar_time_h");
        let morning = scene.sun.elevation_deg;
        assert!(morning > 20.0 && morning < 60.0, "{morning}");
        assert!(scene.sun.azimuth_deg < 180.0, "{}", scene.sun.azimuth_deg);
        assert_eq!(round_trip(&scene), scene);

        scene.sun.elevation_deg = 5.0;
        scene.settle_edit("sun.elevation_deg");
        assert_eq!(scene.sun.time_of_day, None);
        assert_eq!(round_trip(&scene).sun.elevation_deg, 5.0);

        scene.weather.metar = Some("EDDM 011750Z 24012KT 9999 FEW040 18/12 Q1012".into());
        scene.layers[0].coverage = 0.9;
        scene.settle_edit("layers.0.coverage");
        assert_eq!(scene.weather.metar, None);
        assert_eq!(round_trip(&scene), scene);
    }
}
