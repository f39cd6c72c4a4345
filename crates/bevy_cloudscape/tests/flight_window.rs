//! The flight example's world with the plugin, in a real window on Xvfb and the test adapter:
//! the screenshot against a golden by FLIP, the tower in front of the clouds hiding them, and the
//! clouds hiding the balloon above them.
//!
//! `CLOUDSCAPE_UPDATE_GOLDENS=1 cargo test -p bevy_cloudscape --ignore-rust-version` rewrites the
//! golden in `tests/golden/`.

#[path = "../../cloudscape/tests/support/mod.rs"]
mod golden;
#[allow(
    dead_code,
    reason = "the harness's file edits serve the hot-reload test"
)]
mod harness;

use bevy::math::Vec3;
use cloudscape::image::LdrImage;
use harness::{Step, color_around, needs, redness, world};
use std::path::Path;
use std::sync::OnceLock;

/// Frames before the screenshot: Bevy's pipelines compiled and the scene drawn.
const WARMUP_FRAMES: u32 = 30;

/// The screenshot of the flight world under `tests/assets/overcast.toml`, taken once for every
/// test of this file (a process opens one window event loop); None without Xvfb (outside CI).
fn screenshot() -> Option<&'static LdrImage> {
    static SHOT: OnceLock<Option<LdrImage>> = OnceLock::new();
    SHOT.get_or_init(|| {
        let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/assets");
        let script = vec![Step::Frames(WARMUP_FRAMES), Step::Screenshot];
        harness::run(&assets, "overcast.toml", script).map(|mut shots| shots.remove(0))
    })
    .as_ref()
}

#[test]
fn the_window_matches_the_golden() {
    if let Some(shot) = screenshot() {
        golden::check("flight", shot);
    }
}

#[test]
fn the_tower_in_front_hides_the_clouds() {
    let Some(shot) = screenshot() else { return };
    let (base, half) = world::TOWER;
    // Its upper part, against the cloud deck.
    let upper = base + Vec3::Y * (1.8 * half.y);
    let color = color_around(shot, upper, 0.02);
    assert!(
        redness(color) > 2.0,
        "the tower in front of the clouds shows {color} (red over green and blue {:.2}): \
         the clouds were drawn over it",
        redness(color)
    );
}

#[test]
fn the_clouds_hide_the_balloon_above_them() {
    let Some(shot) = screenshot() else { return };
    let color = color_around(shot, world::BALLOON, 0.015);
    assert!(
        redness(color) < 1.3,
        "the balloon above the overcast shows through it: {color} (red over green and blue {:.2})",
        redness(color)
    );
}
