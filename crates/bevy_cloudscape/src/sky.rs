//! The sky's settings as a Bevy asset: a cloudscape scene file (its layers, weather, phase
//! function, atmosphere and quality), loaded by the `AssetServer` and reloaded when it changes.

use bevy::asset::io::Reader;
use bevy::asset::{Asset, AssetLoader, LoadContext};
use bevy::reflect::TypePath;
use cloudscape::scene::{Scene, SceneDocument, SceneError};
use std::path::PathBuf;
use std::sync::Arc;

/// A cloudscape scene: what the clouds of the cameras that name it look like. Its camera, sun and
/// clock are Bevy's (the camera entity, the first `DirectionalLight`, `Time`); the rest is read from
/// the file. Edit a loaded one with `Assets::<CloudSky>::get_mut` (through [`CloudSky::scene_mut`])
/// and the cameras rebuild only what the edit changed, as they do when the file changes on disk.
#[derive(Asset, TypePath, Clone, Debug)]
pub struct CloudSky {
    scene: Arc<Scene>,
    /// Directory that the scene's relative paths (weather maps, voxel grids) resolve against.
    base_dir: PathBuf,
}

impl CloudSky {
    /// cloudscape's embedded default scene: a broken cumulus layer over a flat ground.
    pub fn embedded_default() -> CloudSky {
        CloudSky::new(SceneDocument::embedded_default().scene, PathBuf::new())
    }

    /// A sky from a scene, its relative paths resolving against `base_dir`.
    pub fn new(scene: Scene, base_dir: PathBuf) -> CloudSky {
        CloudSky {
            scene: Arc::new(scene),
            base_dir,
        }
    }

    /// Parses a scene file's text; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str, base_dir: PathBuf) -> Result<CloudSky, SceneError> {
        let doc = SceneDocument::parse(text, origin, &base_dir, &[])?;
        Ok(CloudSky::new(doc.scene, base_dir))
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The scene, to edit (e.g. `layers[0].coverage`): the cameras pick the edit up next frame.
    pub fn scene_mut(&mut self) -> &mut Scene {
        Arc::make_mut(&mut self.scene)
    }

    /// The scene as shared with the render world, and the directory its paths resolve against.
    pub(crate) fn shared(&self) -> (Arc<Scene>, PathBuf) {
        (self.scene.clone(), self.base_dir.clone())
    }
}

/// Loads `.toml` cloudscape scene files as [`CloudSky`] assets.
#[derive(TypePath)]
pub struct CloudSkyLoader {
    /// Directory of the default asset source on disk (for the scene's relative paths).
    pub(crate) asset_root: PathBuf,
}

/// Why a scene file did not load.
#[derive(Debug)]
pub enum CloudSkyError {
    /// The file could not be read.
    Io(std::io::Error),
    /// The file is not a valid cloudscape scene (located: line, column and key).
    Scene(SceneError),
}

impl std::fmt::Display for CloudSkyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CloudSkyError::Io(e) => write!(f, "cannot read the cloudscape scene: {e}"),
            CloudSkyError::Scene(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for CloudSkyError {}

impl AssetLoader for CloudSkyLoader {
    type Asset = CloudSky;
    type Settings = ();
    type Error = CloudSkyError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        _settings: &(),
        load_context: &mut LoadContext<'_>,
    ) -> Result<CloudSky, CloudSkyError> {
        let mut bytes = Vec::new();
        reader
            .read_to_end(&mut bytes)
            .await
            .map_err(CloudSkyError::Io)?;
        let text = String::from_utf8_lossy(&bytes);
        let path = load_context.path().path();
        let base_dir = self.asset_root.join(path.parent().unwrap_or(path.as_ref()));
        CloudSky::parse(&text, &path.display().to_string(), base_dir).map_err(CloudSkyError::Scene)
    }

    fn extensions(&self) -> &[&str] {
        &["toml"]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_flight_examples_sky_file_loads() {
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets");
        let text = std::fs::read_to_string(dir.join("sky.toml")).expect("assets/sky.toml");
        let sky = CloudSky::parse(&text, "sky.toml", dir).expect("the example's sky is valid");
        assert_eq!(sky.scene().layers.len(), 1);
    }

    #[test]
    fn an_invalid_scene_file_names_its_line_and_key() {
        let error = CloudSky::parse("[[layers]]\ncoverage = 2.0\n", "bad.toml", PathBuf::new())
            .expect_err("coverage 2 is out of range");
        let message = error.to_string();
        assert!(message.contains("bad.toml:2"), "{message}");
        assert!(message.contains("coverage"), "{message}");
    }
}
