//! Scripted runs: timed actions that drive the viewer with no one at the keys (`--script FILE`),
//! for tests and for repeatable demonstrations.
//!
//! A script is TOML, a list of steps, each at a frame (counting from 0):
//!
//! ```toml
//! [[at]]
//! frame = 4
//! set = ["layers.0.coverage=0.8"]                                 # live edits, as `--set`
//! camera = { position_m = [0, 2500, 0], yaw_deg = 200, pitch_deg = 5 }   # a cut
//! hold = ["w", "shift"]        # keys held from this frame on (until a later `hold`)
//! orbit = true                 # orbit the point ahead (false: fly)
//! render_scale = 0.5           # 1, 0.5 or 0.25
//! window_size = [640, 360]     # asks the window system for this inner size, pixels
//! reset_camera = true          # back to the scene's camera
//! screenshot = "frame4.png"    # after the frame: its PNG and EXR
//! window_screenshot = "w.png"  # after the frame: the whole window, panels included
//! save = "saved.toml"          # after the frame: the live scene as a scene file
//! ```

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use serde::Deserialize;

use super::camera::Motion;
use super::keys::motion_of_names;

/// A whole script.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Script {
    /// The steps, in any order.
    #[serde(default)]
    pub at: Vec<Step>,
}

/// The eye's place and direction.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraPlacement {
    /// Eye position, m.
    pub position_m: [f32; 3],
    /// View azimuth, degrees clockwise from north.
    pub yaw_deg: f32,
    /// View elevation above the horizon, degrees.
    pub pitch_deg: f32,
}

/// What happens at one frame.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Step {
    /// The frame, counting from 0.
    pub frame: u64,
    /// Live edits, `key.path=value` as `--set` takes them.
    #[serde(default)]
    pub set: Vec<String>,
    /// Puts the camera here (a cut).
    pub camera: Option<CameraPlacement>,
    /// Keys held from this frame on: w a s d q e shift.
    pub hold: Option<Vec<String>>,
    /// Orbit the point ahead (true) or fly (false).
    pub orbit: Option<bool>,
    /// Render scale: 1, 0.5 or 0.25.
    pub render_scale: Option<f32>,
    /// Asks the window system for this inner size of the window, pixels.
    pub window_size: Option<[u32; 2]>,
    /// Back to the scene's camera.
    #[serde(default)]
    pub reset_camera: bool,
    /// After the frame: writes the rendered image as this PNG and as an EXR beside it.
    pub screenshot: Option<PathBuf>,
    /// After the frame: writes the whole window, panels included, as this PNG.
    pub window_screenshot: Option<PathBuf>,
    /// After the frame: writes the live scene as this scene file.
    pub save: Option<PathBuf>,
}

impl Script {
    /// Reads a script file; errors name its line and column.
    pub fn read(path: &Path) -> Result<Script> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read the script {}", path.display()))?;
        let origin = path.display().to_string();
        Ok(cloudscape::scene::parse_toml_document(
            &text, &origin, check,
        )?)
    }

    /// The steps at `frame`.
    pub fn steps_at(&self, frame: u64) -> impl Iterator<Item = &Step> {
        self.at.iter().filter(move |step| step.frame == frame)
    }

    /// The last frame any step names.
    pub fn last_frame(&self) -> Option<u64> {
        self.at.iter().map(|step| step.frame).max()
    }
}

/// The movement the `hold` keys of a step ask for.
pub fn held_motion(names: &[String]) -> Result<Motion, String> {
    motion_of_names(names.iter().map(String::as_str))
}

/// The checks serde cannot make: key names and render scales.
fn check(script: &Script) -> Result<(), (String, String)> {
    for (index, step) in script.at.iter().enumerate() {
        if let Some(names) = &step.hold {
            held_motion(names).map_err(|message| (format!("at.{index}.hold"), message))?;
        }
        if let Some(scale) = step.render_scale {
            super::parse_render_scale(&scale.to_string())
                .map_err(|message| (format!("at.{index}.render_scale"), message))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Script, String> {
        cloudscape::scene::parse_toml_document(text, "script.toml", check)
            .map_err(|e| e.to_string())
    }

    #[test]
    fn steps_are_found_by_frame() {
        let script = parse(
            "[[at]]\nframe = 3\nset = [\"layers.0.coverage=0.8\"]\n\
             [[at]]\nframe = 7\nhold = [\"w\", \"shift\"]\nscreenshot = \"a.png\"\n",
        )
        .unwrap();
        assert_eq!(script.steps_at(3).count(), 1);
        assert_eq!(script.steps_at(4).count(), 0);
        assert_eq!(script.last_frame(), Some(7));
        let held = held_motion(script.at[1].hold.as_ref().unwrap()).unwrap();
        assert_eq!((held.forward, held.fast), (1.0, true));
    }

    #[test]
    fn bad_keys_scales_and_fields_are_located() {
        let error = parse("[[at]]\nframe = 1\nhold = [\"x\"]\n").unwrap_err();
        assert!(error.contains("script.toml:3:8: at.0.hold"), "{error}");
        let error = parse("[[at]]\nframe = 1\nrender_scale = 0.3\n").unwrap_err();
        assert!(error.contains("at.0.render_scale"), "{error}");
        let error = parse("[[at]]\nframe = 1\nzoom = 2\n").unwrap_err();
        assert!(error.contains("script.toml:3:1"), "{error}");
    }
}
