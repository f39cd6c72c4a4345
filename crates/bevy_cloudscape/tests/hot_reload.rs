//! A scene file edited on disk while the app runs reaches the next frames: the flight world's
//! balloon, in a clear sky, disappears once its sky file is rewritten as an overcast deck; the
//! deck's shadow falls on the towers' `CloudShadowedMaterial` (measured without the sky's ambient
//! light, so only the sun's part changes), the sky's ambient light under the deck lights the face
//! again, and the shadow leaves when the camera's clouds are turned off.

#[allow(
    dead_code,
    reason = "the harness's render scale serves the window test"
)]
mod harness;

use bevy::math::Vec3;
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
        Step::SkyAmbient(false),
        Step::Frames(30),
        Step::Screenshot,
        Step::Write(sky.clone(), overcast),
        Step::AwaitSkyReload,
        Step::Frames(3),
        Step::Screenshot,
        Step::SkyAmbient(true),
        Step::Frames(3),
        Step::Screenshot,
        Step::SkyAmbient(false),
        Step::CloudsOff,
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
    let faces = [0, 1, 2, 3].map(|i| sunlit_face(&shots[i]));
    let [clear_face, overcast_face, sky_lit_face, cloudless_face] = faces;
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
    // The deck (optical depth in the hundreds) takes the sun off the face; Bevy's ambient light
    // and the haze in front are what is left.
    eprintln!("the tower's sunlit face: {clear_face:.3} clear, {overcast_face:.3} overcast");
    assert!(
        clear_face > 0.25,
        "under the clear sky the sunlit face of the tower is dark ({clear_face:.3})"
    );
    assert!(
        overcast_face < 0.3 * clear_face,
        "under the overcast deck the tower's sunlit face is {overcast_face:.3}, {:.2} of its \
         {clear_face:.3} under the clear sky: the clouds cast no shadow on the material",
        overcast_face / clear_face
    );
    // The sky's light under the deck (an optical depth of about 15 overhead lets a third of the
    // light through, diffuse) lights the face far more than Bevy's default ambient light.
    eprintln!("the tower's face under the deck with the sky's ambient light: {sky_lit_face:.3}");
    assert!(
        sky_lit_face > 1.5 * overcast_face,
        "under the deck the sky's ambient light leaves the tower's face at {sky_lit_face:.3}, \
         {overcast_face:.3} without it: the camera's ambient light was not set"
    );
    // With the camera's clouds off, nothing shadows the materials any more.
    eprintln!("the tower's sunlit face with the clouds off: {cloudless_face:.3}");
    assert!(
        cloudless_face > 0.8 * clear_face,
        "with the clouds turned off the tower's sunlit face stays dark ({cloudless_face:.3}, \
         {clear_face:.3} under the clear sky): the materials still read the last shadow"
    );
}

/// The mean brightness (0-1, of the tone-mapped colour's channels) of the tallest concrete
/// tower's face toward the camera, which the sun behind the camera lights.
fn sunlit_face(shot: &cloudscape::image::LdrImage) -> f32 {
    let (x, z, half, height) = world::CONCRETE_TOWERS[1];
    let face = Vec3::new(x, 0.5 * height, z + half);
    let color = color_around(shot, face, 0.03);
    (color.x + color.y + color.z) / 3.0
}
