//! Scene files: defaults, partial files, and every kind of error with its exact location.

use std::path::Path;

use cloudscape::scene::{CloudLayer, Scene, SceneDocument, SceneError};

fn parse(text: &str) -> Result<SceneDocument, SceneError> {
    SceneDocument::parse(text, "scene.toml", Path::new("scenes"), &[])
}

/// Parses `text`, which must fail, and checks where and about which key.
fn rejected(text: &str, line: usize, column: usize, key: &str) -> SceneError {
    let error = parse(text).expect_err("the scene should be rejected");
    assert_eq!(error.origin, "scene.toml", "{error}");
    assert_eq!(
        (error.line, error.column),
        (Some(line), Some(column)),
        "{error}"
    );
    assert_eq!(error.key.as_deref(), Some(key), "{error}");
    error
}

fn assert_mentions(error: &SceneError, words: &[&str]) {
    for word in words {
        assert!(
            error.message.contains(word),
            "`{}` does not mention `{word}`",
            error.message
        );
    }
}

#[test]
fn a_partial_file_keeps_the_defaults_of_missing_keys() {
    let scene = parse("[render]\nwidth = 640\n\n[[layers]]\ncoverage = 0.3\n")
        .unwrap()
        .scene;
    let expected = Scene {
        render: cloudscape::scene::RenderSettings {
            width: 640,
            ..Default::default()
        },
        layers: vec![CloudLayer {
            coverage: 0.3,
            ..Default::default()
        }],
        ..Scene::default()
    };
    assert_eq!(scene, expected);
    assert_eq!(parse("").unwrap().scene, Scene::default());
}

#[test]
fn syntax_errors_are_located() {
    let error = rejected(
        "[render]\nwidth = 640\nheight = = 3\n",
        3,
        10,
        "render.height",
    );
    assert_mentions(&error, &["expected"]);
    let error = parse("[render\nwidth = 1\n").unwrap_err();
    assert_eq!((error.line, error.column), (Some(1), Some(8)));
    assert_mentions(&error, &["unclosed table", "`]`"]);
}

#[test]
fn unknown_keys_list_the_keys_allowed_there() {
    let error = rejected("[camera]\nfov = 60.0\n", 2, 1, "camera.fov");
    assert_mentions(
        &error,
        &[
            "unknown field `fov`",
            "`fov_y_deg`",
            "`position_m`",
            "`far_m`",
        ],
    );
    let error = rejected(
        "[[layers]]\ncoverage = 0.5\n  colour = 1\n",
        3,
        3,
        "layers.0.colour",
    );
    assert_mentions(
        &error,
        &["unknown field `colour`", "`thickness_m`", "`types`"],
    );
    let error = rejected("[lights]\n", 1, 2, "lights");
    assert_mentions(&error, &["unknown field `lights`", "`lighting`"]);
}

#[test]
fn wrong_types_name_the_expected_type() {
    let error = rejected(
        "[camera]\nfov_y_deg = \"wide\"\n",
        2,
        13,
        "camera.fov_y_deg",
    );
    assert_mentions(&error, &["\"wide\"", "expected a number"]);
    let error = rejected("[sun]\ncolor = [1.0, \"red\", 1.0]\n", 2, 15, "sun.color.1");
    assert_mentions(&error, &["expected a number"]);
    let error = rejected("[render]\nwidth = 1.5\n", 2, 9, "render.width");
    assert_mentions(&error, &["expected an integer"]);
    let error = rejected(
        "[camera]\nposition_m = [1, 2]\n",
        2,
        14,
        "camera.position_m",
    );
    assert_mentions(&error, &["length 3"]);
    let error = rejected("camera = 5\n", 1, 10, "camera");
    assert_mentions(&error, &["expected a table"]);
}

#[test]
fn unknown_enum_strings_list_the_allowed_ones() {
    let error = rejected("[sky]\nmodel = \"blue\"\n", 2, 9, "sky.model");
    assert_mentions(&error, &["`blue`", "`constant`", "`gradient`"]);
    let error = rejected("[phase]\nmodel = \"rayleigh\"\n", 2, 9, "phase.model");
    assert_mentions(&error, &["`mie`", "`hg`", "`dual_hg`"]);
}

#[test]
fn out_of_range_values_are_located_at_the_value() {
    let error = rejected("[[layers]]\n  coverage = 1.5\n", 2, 14, "layers.0.coverage");
    assert_eq!(
        error.to_string(),
        "scene.toml:2:14: layers.0.coverage: 1.5 is out of range; allowed 0..1"
    );
    let error = rejected(
        "[[layers]]\n[[layers]]\nthickness_m = -5\n",
        3,
        15,
        "layers.1.thickness_m",
    );
    assert_eq!(error.message, "-5 is out of range; allowed 10..20000 m");
    let error = rejected("[render]\nwidth = 0\n", 2, 9, "render.width");
    assert_eq!(error.message, "0 is out of range; allowed >= 1 px");
    let error = rejected("[camera]\nfov_y_deg = 180\n", 2, 13, "camera.fov_y_deg");
    assert_eq!(error.message, "180 is out of range; allowed 1..179 deg");
    let error = rejected(
        "[render]\nsamples_per_pixel = 0\n",
        2,
        21,
        "render.samples_per_pixel",
    );
    assert_eq!(error.message, "0 is out of range; allowed 1..1024");
    let error = rejected("[sun]\ncolor = [1, 1, 2]\n", 2, 16, "sun.color.2");
    assert_eq!(error.message, "2 is out of range; allowed 0..1");
}

#[test]
fn non_finite_numbers_are_rejected_even_without_a_range() {
    let error = rejected("[camera]\nyaw_deg = nan\n", 2, 11, "camera.yaw_deg");
    assert_eq!(
        error.message,
        "NaN is not a finite number; allowed any finite number (deg)"
    );
    let error = rejected(
        "[[layers]]\nwind_m_per_s = [1, -inf]\n",
        2,
        20,
        "layers.0.wind_m_per_s.1",
    );
    assert_mentions(&error, &["-inf is not a finite number"]);
}

#[test]
fn relations_between_fields_are_checked() {
    let error = rejected("[camera]\nnear_m = 10\nfar_m = 5\n", 3, 9, "camera.far_m");
    assert_eq!(
        error.message,
        "far_m (5 m) must be greater than near_m (10 m)"
    );
    let error = rejected(
        "[[layers]]\n[layers.types]\nstratus = 0\n",
        2,
        1,
        "layers.0.types",
    );
    assert_mentions(&error, &["at least one must be > 0"]);
    let error = rejected("[weather]\nsource = \"file\"\n", 2, 10, "weather.source");
    assert_mentions(&error, &["needs `path`"]);
    let error = rejected("[render]\noutput = \"frame.jpg\"\n", 2, 10, "render.output");
    assert_mentions(&error, &[".png", ".exr"]);
}

#[test]
fn a_key_left_at_its_default_is_located_at_its_table() {
    // far_m keeps its default; the near_m that breaks the relation is set in the [camera] table.
    let error = rejected("\n[camera]\nnear_m = 200000.0\n", 2, 1, "camera.far_m");
    assert_mentions(&error, &["must be greater than near_m"]);
    let error = rejected("[[volumes]]\nsize_m = [1, 1, 1]\n", 1, 1, "volumes.0.path");
    assert_mentions(&error, &["needs `path`"]);
}

#[test]
fn error_at_locates_keys_in_the_file() {
    let document = parse("[render]\nwidth = 99999\n\n[[layers]]\ncoverage = 0.5\n").unwrap();
    let error = document.error_at(
        "render.width",
        "99999 is above this GPU's maximum texture size, 16384",
    );
    assert_eq!(
        error.to_string(),
        "scene.toml:2:9: render.width: 99999 is above this GPU's maximum texture size, 16384"
    );
    let error = document.error_at("layers[0].coverage", "message");
    assert_eq!(
        (error.line, error.column, error.key.as_deref()),
        (Some(5), Some(12), Some("layers.0.coverage"))
    );
    let error = document.error_at("weather.path", "cannot read weather.png");
    assert_eq!((error.line, error.column), (None, None));
    assert_eq!(error.origin, "scene.toml");
}

#[test]
fn paths_resolve_against_the_scene_file_directory() {
    let directory =
        std::env::temp_dir().join(format!("cloudscape-scene-test-{}", std::process::id()));
    std::fs::create_dir_all(&directory).unwrap();
    let file = directory.join("scene.toml");
    std::fs::write(
        &file,
        "[weather]\nsource = \"file\"\npath = \"maps/weather.png\"\n",
    )
    .unwrap();
    let document = SceneDocument::load(Some(&file), &[]).unwrap();
    assert_eq!(
        document.resolve_path("maps/weather.png"),
        directory.join("maps/weather.png")
    );
    std::fs::remove_dir_all(&directory).unwrap();

    let missing = SceneDocument::load(Some(&directory.join("absent.toml")), &[]).unwrap_err();
    assert!(missing.origin.ends_with("absent.toml"));
    assert!(
        missing.message.starts_with("cannot read the scene file"),
        "{missing}"
    );
}

#[test]
fn the_embedded_default_is_the_default_scene() {
    let document = SceneDocument::load(None, &[]).unwrap();
    assert_eq!(document.scene, Scene::default());
    let error = document.error_at("render.width", "too wide");
    assert_eq!(error.origin, "<default scene>");
    assert!(error.line.is_some());
}

#[test]
fn a_sprite_cloud_without_boxes_is_located() {
    let error = rejected(
        "[[sprite_clouds]]\ntype = \"stratus\"\ncenter_m = [0.0, 900.0, 0.0]\nboxes = []\n",
        4,
        9,
        "sprite_clouds.0.boxes",
    );
    assert_mentions(&error, &["at least one box"]);
    let error = rejected(
        "[[sprite_clouds]]\ntype = \"cumulus_congestus\"\ncenter_m = [0.0, 900.0, 0.0]\nboxes = [{ center_m = [0.0, 0.0, 0.0], size_m = [100.0, -1.0, 100.0] }]\n",
        4,
        57,
        "sprite_clouds.0.boxes.0.size_m.1",
    );
    assert_mentions(&error, &["> 0"]);
}
