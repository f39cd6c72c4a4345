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
    reason = "the harness's file edits and clouds off serve the hot-reload test"
)]
mod harness;

use bevy::math::Vec3;
use cloudscape::image::LdrImage;
use harness::{Step, color_around, needs, redness, world};
use std::path::Path;
use std::sync::OnceLock;

/// Frames before the screenshot: Bevy's pipelines compiled and the scene drawn.
const WARMUP_FRAMES: u32 = 30;

/// The screenshots of the flight world under `tests/assets/overcast.toml`, taken once for every
/// test of this file (a process opens one window event loop): at the full render scale, then at
/// 1/2; None without Xvfb (outside CI).
fn screenshots() -> Option<&'static [LdrImage; 2]> {
    static SHOTS: OnceLock<Option<[LdrImage; 2]>> = OnceLock::new();
    SHOTS
        .get_or_init(|| {
            let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/assets");
            let script = vec![
                Step::Frames(WARMUP_FRAMES),
                Step::Screenshot,
                Step::RenderScale(0.5),
                Step::Frames(3),
                Step::Screenshot,
            ];
            let shots = harness::run(&assets, "overcast.toml", script)?;
            Some(shots.try_into().expect("two screenshots"))
        })
        .as_ref()
}

/// The screenshot at the full render scale.
fn screenshot() -> Option<&'static LdrImage> {
    screenshots().map(|shots| &shots[0])
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
fn at_half_the_render_scale_the_window_barely_changes() {
    let Some([full, half]) = screenshots() else {
        return;
    };
    let (stats, _) = cloudscape::image::flip(full, half).expect("same size");
    eprintln!(
        "FLIP of the half render scale against the full: mean {:.4}",
        stats.mean
    );
    assert!(
        stats.mean < 0.03,
        "at a render scale of 1/2 the window differs from the full scale by FLIP {:.4}",
        stats.mean
    );
    assert!(
        stats.mean > 1e-4,
        "the window at a render scale of 1/2 is the full scale's: the scale was not applied"
    );
    let (base, half_size) = world::TOWER;
    let color = color_around(half, base + Vec3::Y * (1.8 * half_size.y), 0.02);
    assert!(
        redness(color) > 2.0,
        "at a render scale of 1/2 the clouds were drawn over the tower in front ({color})"
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
