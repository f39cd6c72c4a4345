//! `--set key.path=value` overrides: values, array indices, arrays from the defaults, and errors
//! that name the override.

use std::path::Path;

use cloudscape::scene::{CloudLayer, Scene, SceneDocument, SceneError};

fn parse(text: &str, overrides: &[&str]) -> Result<SceneDocument, SceneError> {
    let overrides: Vec<String> = overrides.iter().map(|o| o.to_string()).collect();
    SceneDocument::parse(text, "scene.toml", Path::new(""), &overrides)
}

fn scene(text: &str, overrides: &[&str]) -> Scene {
    parse(text, overrides).unwrap().scene
}

/// Parses with one override, which must fail; checks that the error names the override.
fn override_error(text: &str, set: &str) -> SceneError {
    let error = parse(text, &[set]).expect_err("the override should be rejected");
    assert_eq!(error.origin, format!("--set {set}"), "{error}");
    assert_eq!((error.line, error.column), (None, None), "{error}");
    error
}

#[test]
fn overrides_set_numbers_arrays_and_strings() {
    let set = scene(
        "",
        &[
            "render.width=640",
            "camera.position_m=[0,500,0]",
            "render.output=out.png",
        ],
    );
    assert_eq!(set.render.width, 640);
    assert_eq!(set.camera.position_m, [0.0, 500.0, 0.0]);
    assert_eq!(set.render.output, "out.png");
    assert_eq!(set.render.height, Scene::default().render.height);
    assert_eq!(
        scene("", &["render.output=\"quoted.exr\""]).render.output,
        "quoted.exr"
    );
    assert_eq!(
        scene("", &["weather.path = maps/w 1.png "])
            .weather
            .path
            .as_deref(),
        Some("maps/w 1.png")
    );
}

#[test]
fn overrides_replace_file_values_in_order() {
    let text = "[render]\nwidth = 0\nheight = 100\n";
    let set = scene(text, &["render.width=320", "render.width=800"]);
    assert_eq!((set.render.width, set.render.height), (800, 100));
}

#[test]
fn an_index_selects_one_entry_of_the_file_array() {
    let text = "[[layers]]\ncoverage = 0.1\n[[layers]]\nbottom_m = 6000\ncoverage = 0.2\n";
    for set in ["layers.1.coverage=0.9", "layers[1].coverage=0.9"] {
        let layers = scene(text, &[set]).layers;
        assert_eq!(
            (layers[0].coverage, layers[1].coverage, layers[1].bottom_m),
            (0.1, 0.9, 6000.0)
        );
    }
}

#[test]
fn an_index_into_an_array_the_file_lacks_takes_the_default_array() {
    let layers = scene("[render]\nwidth = 64\n", &["layers.0.coverage=0.3"]).layers;
    assert_eq!(
        layers,
        vec![CloudLayer {
            coverage: 0.3,
            ..CloudLayer::default()
        }]
    );
    let layers = scene("", &["layers.0.types.stratus=0.5"]).layers;
    assert_eq!(
        (layers[0].types.stratus, layers[0].types.cumulus),
        (0.5, 1.0)
    );
}

#[test]
fn out_of_range_override_values_name_the_override() {
    let error = override_error("", "layers.0.coverage=2");
    assert_eq!(
        error.to_string(),
        "--set layers.0.coverage=2: layers.0.coverage: 2 is out of range; allowed 0..1"
    );
    let error = override_error("[render]\nwidth = 64\n", "render.width=0");
    assert_eq!(error.key.as_deref(), Some("render.width"));
}

#[test]
fn unknown_keys_and_wrong_types_in_overrides_name_the_override() {
    let error = override_error("", "render.widht=640");
    assert_eq!(error.key.as_deref(), Some("render.widht"));
    assert!(
        error.message.contains("unknown field `widht`") && error.message.contains("`width`"),
        "{error}"
    );
    let error = override_error("", "render.width=abc");
    assert!(error.message.contains("expected an integer"), "{error}");
    let error = override_error("", "sky.model=blue");
    assert!(error.message.contains("`constant`"), "{error}");
}

#[test]
fn malformed_overrides_are_clear_errors() {
    let cases = [
        ("render.width", "expected key.path=value"),
        ("=3", "the key before `=` is empty"),
        ("render..width=3", "is not a key path"),
        ("layers[x].coverage=1", "is not an array index"),
        (
            "layers.3.coverage=1",
            "index 3 is past the end of layers (length 1)",
        ),
        ("layers.first.coverage=1", "`first` is not an index"),
        (
            "render.width.max=1",
            "render.width is a single value (integer), not a table with `max` in it",
        ),
        ("camera.position_m=[0,500", "is not a valid TOML value"),
    ];
    for (set, expected) in cases {
        let error = override_error("", set);
        assert!(
            error.message.contains(expected),
            "--set {set}: `{}` lacks `{expected}`",
            error.message
        );
    }
}

#[test]
fn file_errors_keep_their_location_when_there_are_overrides() {
    let error = parse("[render]\nwidth = 0\n", &["camera.fov_y_deg=50"]).unwrap_err();
    assert_eq!(
        error.to_string(),
        "scene.toml:2:9: render.width: 0 is out of range; allowed >= 1 px"
    );
    assert!(parse("[render]\nwidth = 0\n", &["render.width=64"]).is_ok());
}

#[test]
fn error_at_names_the_override_that_set_the_key() {
    let document = parse("[render]\nwidth = 64\n", &["render.height=9999"]).unwrap();
    let error = document.error_at("render.height", "too tall");
    assert_eq!(
        error.to_string(),
        "--set render.height=9999: render.height: too tall"
    );
    assert_eq!(document.error_at("render.width", "too wide").line, Some(2));
}
