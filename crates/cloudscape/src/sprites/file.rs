//! Sprite model files (Wang 2003: "Export final model to a file to load into game"): TOML that
//! lists each cloud's type, centre, boxes and generated sprites, so a cloud renders exactly as it
//! was generated, without regenerating it. `cloudscape export --sprites` writes one;
//! `sprites.model` in a scene draws one. Loading validates it as a scene is validated: every
//! error is located (file, line, column, key) and nothing is rendered.

use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

use super::model::{Sprite, SpriteBox, SpriteCloud};
use crate::scene::{CloudType, SceneError, SpriteBoxSpec, parse_toml_document};

/// The `format` line of every sprite model file.
pub const FORMAT: &str = "cloudscape sprite model";
/// The version this build reads and writes.
pub const VERSION: u32 = 1;

/// A sprite model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelFile {
    /// Always [`FORMAT`].
    pub format: String,
    /// Always [`VERSION`].
    pub version: u32,
    /// The clouds.
    #[serde(default)]
    pub clouds: Vec<FileCloud>,
}

/// One cloud of a model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FileCloud {
    /// The cloud type.
    #[serde(rename = "type")]
    pub cloud_type: CloudType,
    /// Centre, m.
    pub center_m: [f32; 3],
    /// The layer whose wind carries it (none: it stays put).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layer: Option<u32>,
    /// The boxes it was filled from, relative to the centre.
    #[serde(default)]
    pub boxes: Vec<SpriteBoxSpec>,
    /// Its sprites.
    pub sprites: Vec<FileSprite>,
}

/// One sprite of a model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FileSprite {
    /// Centre relative to the cloud's centre, m.
    pub offset_m: [f32; 3],
    /// Width and height, m, each > 0.
    pub size_m: [f32; 2],
    /// Rotation about the view axis, degrees.
    pub rotation_deg: f32,
    /// Puff texture, 0..15.
    pub texture: u32,
    /// Shading group, 0..1000.
    pub group: u32,
    /// Opacity, 0..1.
    pub opacity: f32,
}

impl ModelFile {
    /// The file of `clouds`.
    pub fn of(clouds: &[SpriteCloud]) -> ModelFile {
        ModelFile {
            format: FORMAT.to_string(),
            version: VERSION,
            clouds: clouds.iter().map(FileCloud::of).collect(),
        }
    }

    /// The file as TOML text.
    pub fn to_toml(&self) -> String {
        format!(
            "# Sprite clouds (Wang 2003 cluster model), written by cloudscape.\n{}",
            toml::to_string(self).expect("a model file serialises")
        )
    }

    /// Writes the file to `path` atomically: a reader never sees a partial file.
    pub fn write(&self, path: &std::path::Path) -> std::io::Result<()> {
        crate::fsutil::write_bytes_atomically(path, self.to_toml().as_bytes())
    }

    /// Parses and validates `text` (named `origin` in errors).
    pub fn parse(text: &str, origin: &str) -> Result<ModelFile, SceneError> {
        parse_toml_document(text, origin, ModelFile::check)
    }

    /// Reads and validates the file at `path`.
    pub fn read(path: &std::path::Path) -> Result<ModelFile, SceneError> {
        let origin = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| SceneError {
            origin: origin.clone(),
            line: None,
            column: None,
            key: None,
            message: format!("cannot read the sprite model file: {e}"),
        })?;
        ModelFile::parse(&text, &origin)
    }

    /// The clouds, ready to draw.
    pub fn clouds(&self) -> Vec<SpriteCloud> {
        self.clouds.iter().map(FileCloud::cloud).collect()
    }

    /// The first value that is out of range: its key and what is allowed.
    fn check(&self) -> Result<(), (String, String)> {
        let fail = |key: String, message: String| Err((key, message));
        if self.format != FORMAT {
            return fail(
                "format".into(),
                format!("{:?} is not {FORMAT:?}", self.format),
            );
        }
        if self.version != VERSION {
            return fail(
                "version".into(),
                format!(
                    "version {} is not supported; this build reads {VERSION}",
                    self.version
                ),
            );
        }
        for (c, cloud) in self.clouds.iter().enumerate() {
            let key = |rest: &str| format!("clouds.{c}.{rest}");
            finite(&cloud.center_m).map_err(|i| (key(&format!("center_m.{i}")), FINITE.into()))?;
            for (b, sprite_box) in cloud.boxes.iter().enumerate() {
                let at = |field: &str, i: usize| key(&format!("boxes.{b}.{field}.{i}"));
                finite(&sprite_box.center_m).map_err(|i| (at("center_m", i), FINITE.into()))?;
                positive(&sprite_box.size_m).map_err(|i| (at("size_m", i), POSITIVE.into()))?;
            }
            for (s, sprite) in cloud.sprites.iter().enumerate() {
                sprite
                    .check()
                    .map_err(|(field, message)| (key(&format!("sprites.{s}.{field}")), message))?;
            }
        }
        Ok(())
    }
}

const FINITE: &str = "must be a finite number (m)";
const POSITIVE: &str = "must be a finite number > 0 (m)";

/// The index of the first non-finite value.
fn finite(values: &[f32]) -> Result<(), usize> {
    values
        .iter()
        .position(|v| !v.is_finite())
        .map_or(Ok(()), Err)
}

/// The index of the first value that is not finite and positive.
fn positive(values: &[f32]) -> Result<(), usize> {
    values
        .iter()
        .position(|v| !(v.is_finite() && *v > 0.0))
        .map_or(Ok(()), Err)
}

impl FileSprite {
    /// The first bad field: its key relative to the sprite and what is allowed.
    fn check(&self) -> Result<(), (String, String)> {
        let at = |field: &str, i: usize| format!("{field}.{i}");
        finite(&self.offset_m).map_err(|i| (at("offset_m", i), FINITE.into()))?;
        positive(&self.size_m).map_err(|i| (at("size_m", i), POSITIVE.into()))?;
        if !self.rotation_deg.is_finite() {
            return Err((
                "rotation_deg".into(),
                "must be a finite number (deg)".into(),
            ));
        }
        if self.texture > 15 {
            return Err((
                "texture".into(),
                format!("{} is out of range; allowed 0..15", self.texture),
            ));
        }
        if self.group > 1000 {
            return Err((
                "group".into(),
                format!("{} is out of range; allowed 0..1000", self.group),
            ));
        }
        if !(0.0..=1.0).contains(&self.opacity) {
            return Err((
                "opacity".into(),
                format!("{} is out of range; allowed 0..1", self.opacity),
            ));
        }
        Ok(())
    }
}

impl FileCloud {
    fn of(cloud: &SpriteCloud) -> FileCloud {
        FileCloud {
            cloud_type: cloud.cloud_type,
            center_m: cloud.center_m.to_array(),
            layer: cloud.layer,
            boxes: cloud
                .boxes
                .iter()
                .map(|b| SpriteBoxSpec {
                    center_m: b.center_m.to_array(),
                    size_m: b.size_m.to_array(),
                })
                .collect(),
            sprites: cloud
                .sprites
                .iter()
                .map(|s| FileSprite {
                    offset_m: s.offset_m.to_array(),
                    size_m: s.size_m.to_array(),
                    rotation_deg: s.rotation_rad.to_degrees(),
                    texture: s.texture,
                    group: s.group,
                    // A model's clouds are drawn as hand-made ones, whose opacity is a share of
                    // their chord's depth: a field sprite denser than a puff shows (above 1,
                    // `from_field.rs`) is written as a whole one.
                    opacity: s.opacity.min(1.0),
                })
                .collect(),
        }
    }

    fn cloud(&self) -> SpriteCloud {
        SpriteCloud {
            cloud_type: self.cloud_type,
            center_m: Vec3::from_array(self.center_m),
            boxes: self.boxes.iter().map(SpriteBox::from).collect(),
            layer: self.layer,
            sprites: self
                .sprites
                .iter()
                .map(|s| Sprite {
                    offset_m: Vec3::from_array(s.offset_m),
                    size_m: Vec2::from_array(s.size_m),
                    rotation_rad: s.rotation_deg.to_radians(),
                    texture: s.texture,
                    group: s.group,
                    opacity: s.opacity,
                })
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sprites::model::CloudModel;

    fn cloud() -> SpriteCloud {
        CloudModel {
            cloud_type: CloudType::CumulusHumilis,
            center_m: Vec3::new(0.0, 1200.0, -3000.0),
            boxes: vec![SpriteBox {
                center_m: Vec3::ZERO,
                size_m: Vec3::new(900.0, 400.0, 700.0),
            }],
            seed: 3,
            recipe: CloudType::CumulusHumilis.recipe(),
        }
        .generate(Some(0))
    }

    #[test]
    fn a_written_model_reads_back_as_the_same_clouds() {
        let clouds = vec![cloud()];
        let text = ModelFile::of(&clouds).to_toml();
        let back = ModelFile::parse(&text, "m.toml").unwrap().clouds();
        assert_eq!(back.len(), 1);
        assert_eq!(back[0].sprites.len(), clouds[0].sprites.len());
        for (a, b) in back[0].sprites.iter().zip(&clouds[0].sprites) {
            assert!(a.offset_m.distance(b.offset_m) < 1e-3);
            assert!((a.rotation_rad - b.rotation_rad).abs() < 1e-5);
            assert_eq!((a.texture, a.group), (b.texture, b.group));
        }
    }

    #[test]
    fn a_bad_value_is_located_at_its_line_and_key() {
        let text = ModelFile::of(&[cloud()]).to_toml();
        let bad = text.replacen("texture = ", "texture = 9", 1);
        let error = ModelFile::parse(&bad, "m.toml").unwrap_err();
        assert_eq!(error.key.as_deref(), Some("clouds.0.sprites.0.texture"));
        let line = bad.lines().position(|l| l.contains("texture = 9")).unwrap() + 1;
        assert_eq!(error.line, Some(line), "{error}");
        assert!(error.to_string().contains("allowed 0..15"), "{error}");
        let error = ModelFile::parse("format = \"x\"\nversion = 1\n", "m.toml").unwrap_err();
        assert_eq!(error.key.as_deref(), Some("format"));
        let error = ModelFile::parse("format = 3", "m.toml").unwrap_err();
        assert_eq!(error.line, Some(1), "{error}");
    }
}
