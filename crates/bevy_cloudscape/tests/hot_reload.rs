//! A scene file edited on disk while the app runs reaches the next frames: the flight world's
//! balloon, in a clear sky, disappears once its sky file is rewritten as an overcast deck.

mod harness;

use harness::{Step, color_around, needs, redness, world};
use std::path::Path;

/// A sky with a layer but no cloud in it.
const CLEAR: &str = "[[layers]]\ncoverage = 0.0\n[render]\nquality = \"low\"\n";

#[test]
fn an_edited_scene_file_reaches_the_next_frames() {
    let dir = std::env::temp_dir().join(format!("bevy-cloudscape-reload-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("asset directory");
    let sky = dir.join("sky.toml");
    std::fs::write(&sky, CLEAR).expect("write the clear sky");
    let overcast = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/assets/overcast.toml"),
    )
    .expect("the overcast sky");
    let script = vec![
        Step::Frames(30),
        Step::Screenshot,
        Step::Write(sky.clone(), overcast),
        Step::AwaitSkyReload,
        Step::Frames(3),
        Step::Screenshot,
    ];
    let Some(shots) = harness::run(&dir, "sky.toml", script) else {
        return;
    };
    let _ = std::fs::remove_dir_all(&dir);
    // The red balloon above the layer: in view under the clear sky (through 10 km of haze, which
    // pales it: measured 1.64), hidden by the deck (the deck's grey: 1.0-1.1).
    let balloon = |i: usize| redness(color_around(&shots[i], world::BALLOON, 0.015));
    let (before, after) = (balloon(0), balloon(1));
    eprintln!("the balloon's red over green and blue: {before:.2} clear, {after:.2} overcast");
    assert!(
        before > 1.4,
        "under the clear sky the balloon should show (red over green and blue {before:.2})"
    );
    assert!(
        after < 1.3,
        "after the file changed to an overcast deck the balloon still shows (red over green and \
         blue {after:.2} before {before:.2}): the edit did not reach the frames"
    );
}
