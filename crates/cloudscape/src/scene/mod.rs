//! The scene: data model, TOML loading, validation and error locations.
//!
//! A scene file is TOML; [`DEFAULT_SCENE_TOML`] is the default scene and documents every key (its
//! meaning, unit and range). Any key may be left out to keep its default. [`SceneDocument::load`]
//! reads a file, applies `--set key.path=value` overrides, deserialises and validates, and reports
//! every problem as a [`SceneError`] naming the file, line, column, key and what is allowed.

mod derive;
mod error;
mod key_path;
pub mod knobs;
mod load;
mod locate;
pub mod metar;
mod model;
mod overrides;
mod save;
mod solar;
mod source_map;
mod validate;

use std::path::{Path, PathBuf};

pub use error::SceneError;
pub use model::*;
pub(crate) use solar::angles_of;
pub use solar::{
    SunAngles, declination_rad, direction_from_angles_deg, key_direction, solar_direction,
    solar_position,
};
use source_map::SourceMap;

/// Parses a TOML document other than a scene (a sprite model file) with the scene's located
/// errors: syntax, unknown keys and wrong types at their line and column, and what `check` finds
/// (the dotted key of the first bad value and what is wrong) at the value. `origin` names the
/// file in messages.
pub fn parse_toml_document<T: serde::de::DeserializeOwned>(
    text: &str,
    origin: &str,
    check: impl Fn(&T) -> Result<(), (String, String)>,
) -> Result<T, SceneError> {
    load::document(&SourceMap::new(origin, text, &[]), check)
}

/// The embedded default scene: a commented TOML file restating every field of [`Scene::default`].
pub const DEFAULT_SCENE_TOML: &str = include_str!("default.toml");

/// The origin named in errors about the embedded default scene.
const DEFAULT_ORIGIN: &str = "<default scene>";

/// A loaded, validated scene, with what is needed to locate later errors in its source.
#[derive(Clone, Debug)]
pub struct SceneDocument {
    /// The validated scene.
    pub scene: Scene,
    /// The file text and the overrides, for locating errors found after loading.
    sources: SourceMap,
    /// Directory that relative paths in the scene resolve against.
    base_dir: PathBuf,
    /// What the overrides replaced without naming it, one line each.
    notes: Vec<String>,
}

impl SceneDocument {
    /// The embedded default scene (origin `<default scene>`); relative paths resolve against the
    /// current directory.
    pub fn embedded_default() -> SceneDocument {
        Self::parse(DEFAULT_SCENE_TOML, DEFAULT_ORIGIN, Path::new(""), &[])
            .expect("the embedded default scene is valid (tested in scene::tests)")
    }

    /// Loads `path` (or the embedded default when `None`), applies the `--set` overrides
    /// (`key.path=value`, in order) and validates the result.
    pub fn load(path: Option<&Path>, overrides: &[String]) -> Result<SceneDocument, SceneError> {
        let Some(path) = path else {
            return Self::parse(DEFAULT_SCENE_TOML, DEFAULT_ORIGIN, Path::new(""), overrides);
        };
        let origin = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|error| SceneError {
            origin: origin.clone(),
            line: None,
            column: None,
            key: None,
            message: format!("cannot read the scene file: {error}"),
        })?;
        Self::parse(
            &text,
            &origin,
            path.parent().unwrap_or(Path::new("")),
            overrides,
        )
    }

    /// Like [`SceneDocument::load`], from text: `origin` names the file in errors, and relative
    /// paths in the scene resolve against `base_dir`.
    pub fn parse(
        text: &str,
        origin: &str,
        base_dir: &Path,
        overrides: &[String],
    ) -> Result<SceneDocument, SceneError> {
        let sources = SourceMap::new(origin, text, overrides);
        let (scene, notes) = load::scene(&sources)?;
        Ok(SceneDocument {
            scene,
            sources,
            base_dir: base_dir.to_path_buf(),
            notes,
        })
    }

    /// What the overrides replaced without naming it, one line each, for the user to see: a
    /// `--set weather.metar=...` replaces the file's `layers` and `sky.visibility_m`, a
    /// `--set sun.time_of_day...` its sun angles.
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    /// An error about the value at a dotted key path (`render.width`, `layers.0.coverage`, or
    /// `layers[0].coverage`), for checks made after loading (a width above the GPU's maximum texture
    /// size, an unreadable weather PNG). It is located at the value when the file or an override
    /// sets it, at the enclosing table when the value is a default, and at no line otherwise.
    pub fn error_at(&self, key_path: &str, message: impl Into<String>) -> SceneError {
        let root = load::merged_document(&self.sources).ok();
        load::error_at(root.as_ref(), &self.sources, key_path, message.into())
    }

    /// A path from the scene file resolved against the scene file's directory; an absolute path is
    /// returned unchanged.
    pub fn resolve_path(&self, relative: &str) -> PathBuf {
        self.base_dir.join(relative)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_file_is_exactly_the_default_scene() {
        assert_eq!(SceneDocument::embedded_default().scene, Scene::default());
        assert_eq!(
            toml::from_str::<Scene>(DEFAULT_SCENE_TOML).unwrap(),
            Scene::default()
        );
    }

    /// Whether `line` (without a leading `# `) assigns a key or opens a `[[table]]`.
    fn is_key(line: &str) -> bool {
        let name = line.split(" = ").next().unwrap_or("");
        line.starts_with("[[")
            || (line.contains(" = ") && name.chars().all(|c| c.is_ascii_lowercase() || c == '_'))
    }

    /// `# key = value` and `# [[table]]` lines are keys shown commented out; other comments are prose.
    fn uncomment_keys(text: &str) -> String {
        let lines = text.lines().map(|line| match line.strip_prefix("# ") {
            Some(rest) if is_key(rest) => rest,
            _ => line,
        });
        lines.collect::<Vec<_>>().join("\n")
    }

    /// Dotted paths of every leaf of a TOML table; array-of-table indices are left out.
    fn leaf_keys(table: &toml::Table, prefix: &str, out: &mut Vec<String>) {
        for (key, value) in table {
            let path = format!("{prefix}{key}");
            match value {
                toml::Value::Table(child) => leaf_keys(child, &format!("{path}."), out),
                toml::Value::Array(items)
                    if !items.is_empty() && items.iter().all(toml::Value::is_table) =>
                {
                    items
                        .iter()
                        .filter_map(toml::Value::as_table)
                        .for_each(|t| leaf_keys(t, &format!("{path}."), out))
                }
                _ => out.push(path),
            }
        }
    }

    #[test]
    fn the_default_file_shows_every_key() {
        let documented: toml::Table = toml::from_str(&uncomment_keys(DEFAULT_SCENE_TOML)).unwrap();
        let every = toml::Table::try_from(validate::tests::fully_populated()).unwrap();
        let (mut shown, mut expected) = (Vec::new(), Vec::new());
        leaf_keys(&documented, "", &mut shown);
        leaf_keys(&every, "", &mut expected);
        shown.sort();
        expected.sort();
        assert_eq!(shown, expected);
    }

    #[test]
    fn every_key_in_the_default_file_has_a_comment_line_above_it() {
        let uncommented = |line: &str| line.strip_prefix("# ").unwrap_or(line).to_string();
        let lines: Vec<String> = DEFAULT_SCENE_TOML.lines().map(uncommented).collect();
        let raw: Vec<&str> = DEFAULT_SCENE_TOML.lines().collect();
        for number in 1..lines.len() {
            if is_key(&lines[number]) && !lines[number].starts_with("[[") {
                let above = raw[number - 1];
                assert!(
                    above.starts_with('#') && !is_key(&lines[number - 1]),
                    "line {} has no comment above it",
                    number + 1
                );
            }
        }
    }
}
