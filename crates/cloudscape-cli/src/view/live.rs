//! The scene being viewed: the file it came from (watched, and reloaded when it changes on disk),
//! the live edits made to it, and saving it back. Every change is validated as a scene file is: a
//! broken edit is refused with its located error and the last good scene stays.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};

use anyhow::{Context, Result};
use cloudscape::field::FieldError;
use cloudscape::scene::{Camera, Scene, SceneDocument};

/// How often the scene file's modification time is looked at.
const POLL_INTERVAL: Duration = Duration::from_millis(400);

/// The origin named in errors about live edits.
const LIVE_ORIGIN: &str = "live scene";

/// The scene file, its last good load and the live state.
pub struct LiveScene {
    /// The scene file; None for the embedded default.
    path: Option<PathBuf>,
    /// `--set` overrides, applied again at every reload.
    overrides: Vec<String>,
    /// The last good load of the file.
    document: SceneDocument,
    /// The scene as viewed: the file's, with the live edits.
    pub scene: Scene,
    /// The file's modification time at the last look.
    modified: Option<SystemTime>,
    last_poll: Instant,
    /// The newest problem: an edit of the file or a live edit that was refused.
    pub error: Option<String>,
}

/// What a reload of the scene file changed.
pub struct Reload {
    /// The file's camera moved: the view cuts to it.
    pub camera_changed: bool,
}

impl LiveScene {
    /// Loads the scene `path` (the embedded default when None) with `overrides`.
    pub fn load(path: Option<&Path>, overrides: &[String]) -> Result<LiveScene> {
        let document = SceneDocument::load(path, overrides)?;
        crate::common::print_notes(&document);
        Ok(LiveScene {
            path: path.map(Path::to_path_buf),
            overrides: overrides.to_vec(),
            scene: document.scene.clone(),
            document,
            modified: path.and_then(modified),
            last_poll: Instant::now(),
            error: None,
        })
    }

    /// The scene's file name, or `<default scene>`.
    pub fn origin(&self) -> String {
        self.path
            .as_ref()
            .map_or("<default scene>".to_string(), |p| p.display().to_string())
    }

    /// A renderer's error about a scene key (an unreadable file the scene names), located in the
    /// scene file.
    pub fn field_error(&self, error: FieldError) -> anyhow::Error {
        anyhow::anyhow!(self.document.error_at(&error.key_path, error.message))
    }

    /// The directory files named in the scene resolve against.
    pub fn base_dir(&self) -> PathBuf {
        self.document.resolve_path("")
    }

    /// The camera the scene file gives.
    pub fn file_camera(&self) -> &Camera {
        &self.document.scene.camera
    }

    /// Where "Save scene" writes by default: beside the scene file, `NAME-view.toml` (relative
    /// paths in the scene stay valid), or `cloudscape-view.toml` for the embedded default.
    pub fn default_save_path(&self) -> PathBuf {
        match &self.path {
            Some(path) => {
                let stem = path.file_stem().unwrap_or_default().to_string_lossy();
                path.with_file_name(format!("{stem}-view.toml"))
            }
            None => PathBuf::from("cloudscape-view.toml"),
        }
    }

    /// Looks at the scene file (at most every [`POLL_INTERVAL`]) and reloads it when it changed.
    /// A file that no longer loads leaves the scene as it was, with the located error in
    /// [`LiveScene::error`]; None when nothing was reloaded.
    pub fn poll_file(&mut self) -> Option<Reload> {
        let path = self.path.clone()?;
        if self.last_poll.elapsed() < POLL_INTERVAL {
            return None;
        }
        self.last_poll = Instant::now();
        let now = modified(&path);
        if now == self.modified {
            return None;
        }
        self.modified = now;
        match SceneDocument::load(Some(&path), &self.overrides) {
            Ok(document) => {
                let camera_changed = document.scene.camera != self.document.scene.camera;
                self.scene = document.scene.clone();
                self.document = document;
                self.error = None;
                Some(Reload { camera_changed })
            }
            Err(error) => {
                self.error = Some(format!("{error}\n(the last good scene stays)"));
                None
            }
        }
    }

    /// Applies `key.path=value` to the live scene, as `--set` does to a file: the value is
    /// checked and a bad one refused with its located error.
    pub fn set(&mut self, assignment: &str) -> Result<(), String> {
        let key = assignment
            .split_once('=')
            .map_or(assignment, |(k, _)| k)
            .trim();
        let mut base = self.scene.clone();
        base.settle_edit(key);
        let text = base.to_toml_before_setting(key);
        self.load_text(&text, &[assignment.to_string()])
    }

    /// Takes `edited` (the live scene with the value at `key` changed), checked as a scene file
    /// is; a scene that breaks a rule is refused with the reason.
    pub fn edit(&mut self, mut edited: Scene, key: &str) -> Result<(), String> {
        edited.settle_edit(key);
        self.load_text(&edited.to_toml(), &[])
    }

    /// Replaces the live scene by the scene file `text` with `overrides`, read as `cloudscape
    /// render` would read it, so that what is viewed is what a saved file renders.
    fn load_text(&mut self, text: &str, overrides: &[String]) -> Result<(), String> {
        let loaded = SceneDocument::parse(text, LIVE_ORIGIN, &self.base_dir(), overrides);
        match loaded {
            Ok(document) => {
                self.scene = document.scene;
                self.error = None;
                Ok(())
            }
            Err(error) => {
                let message = error.to_string();
                self.error = Some(message.clone());
                Err(message)
            }
        }
    }
}

/// Writes `scene` to `path` as a scene file that `cloudscape render` renders exactly as viewed.
pub fn save_scene(scene: &Scene, path: &Path) -> Result<()> {
    scene
        .write_toml(path)
        .with_context(|| format!("cannot write the scene to {}", path.display()))
}

/// The file's modification time, if it can be read.
fn modified(path: &Path) -> Option<SystemTime> {
    std::fs::metadata(path).and_then(|m| m.modified()).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scratch directory for one test, removed at the end.
    struct Scratch(PathBuf);

    impl Scratch {
        fn new(name: &str) -> Scratch {
            let dir =
                std::env::temp_dir().join(format!("cloudscape-live-{name}-{}", std::process::id()));
            std::fs::create_dir_all(&dir).unwrap();
            Scratch(dir)
        }
    }

    impl Drop for Scratch {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    /// Writes `text` to `path` with a modification time `age_s` seconds from now.
    fn write(path: &Path, text: &str, age_s: u64) {
        std::fs::write(path, text).unwrap();
        let file = std::fs::File::options().write(true).open(path).unwrap();
        file.set_modified(SystemTime::now() + Duration::from_secs(age_s))
            .unwrap();
    }

    #[test]
    fn a_changed_file_is_reloaded_and_a_broken_one_keeps_the_last_good_scene() {
        let scratch = Scratch::new("reload");
        let path = scratch.0.join("scene.toml");
        write(&path, "[[layers]]\ncoverage = 0.3\n", 0);
        let mut live = LiveScene::load(Some(&path), &[]).unwrap();
        live.last_poll -= POLL_INTERVAL;
        assert!(live.poll_file().is_none(), "nothing changed");

        write(&path, "[[layers]]\ncoverage = 0.6\n", 5);
        live.last_poll -= POLL_INTERVAL;
        let reload = live.poll_file().expect("reloaded");
        assert!(!reload.camera_changed);
        assert_eq!(live.scene.layers[0].coverage, 0.6);

        write(&path, "[[layers]]\ncoverage = 1.6\n", 10);
        live.last_poll -= POLL_INTERVAL;
        assert!(live.poll_file().is_none());
        let error = live.error.clone().expect("the error is kept");
        assert!(error.contains("scene.toml:2:12"), "{error}");
        assert_eq!(live.scene.layers[0].coverage, 0.6);
    }

    #[test]
    fn live_edits_are_checked_and_a_bad_one_is_refused() {
        let mut live = LiveScene::load(None, &[]).unwrap();
        live.set("layers.0.coverage=0.8").unwrap();
        assert_eq!(live.scene.layers[0].coverage, 0.8);
        let error = live.set("layers.0.coverage=2").unwrap_err();
        assert!(error.contains("allowed 0..1"), "{error}");
        assert_eq!(live.scene.layers[0].coverage, 0.8);

        let mut edited = live.scene.clone();
        edited.camera.near_m = edited.camera.far_m * 2.0;
        assert!(live.edit(edited, "camera.near_m").is_err());
        assert!(live.error.is_some());
    }

    #[test]
    fn the_saved_scene_loads_back_as_the_live_scene() {
        let scratch = Scratch::new("save");
        let mut live = LiveScene::load(None, &[]).unwrap();
        live.set("sun.time_of_day={ solar_time_h = 16.5, latitude_deg = 45.0, day_of_year = 200 }")
            .unwrap();
        live.set("sun.elevation_deg=12").unwrap();
        live.scene.camera.yaw_deg = 123.456;
        let path = scratch.0.join("saved.toml");
        save_scene(&live.scene, &path).unwrap();
        let saved = SceneDocument::load(Some(&path), &[]).unwrap().scene;
        assert_eq!(saved, live.scene);
        assert_eq!(saved.sun.elevation_deg, 12.0);
    }
}
