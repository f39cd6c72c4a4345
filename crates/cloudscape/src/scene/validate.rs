//! Range checks of every numeric field, from the knob tables of [`super::knobs`], and the checks
//! between fields.

use std::fmt;

use super::key_direction;
use super::knobs::{self, Field, Knob};
use super::model::{
    CameraKey, CloudLayer, CoverageKey, Scene, SpriteCloudSpec, SunKey, VolumeGrid, WeatherSource,
};

/// A value that breaks a rule, by dotted key path.
#[derive(Debug)]
pub(super) struct Violation {
    /// Dotted key path, e.g. `layers.0.coverage`.
    pub key: String,
    /// What is wrong and what is allowed.
    pub message: String,
}

/// Checks every field of `scene` and every relation between fields; the first violation found.
pub(super) fn validate(scene: &Scene) -> Result<(), Violation> {
    check(scene, "", knobs::SCENE, SCENE_RELATIONS)?;
    if let Some(time) = &scene.sun.time_of_day {
        check(time, "sun.time_of_day.", knobs::TIME_OF_DAY, &[])?;
    }
    for (index, layer) in scene.layers.iter().enumerate() {
        check(
            layer,
            &format!("layers.{index}."),
            knobs::LAYER,
            LAYER_RELATIONS,
        )?;
    }
    for (index, volume) in scene.volumes.iter().enumerate() {
        check(
            volume,
            &format!("volumes.{index}."),
            knobs::VOLUME,
            VOLUME_RELATIONS,
        )?;
    }
    validate_sprite_clouds(scene)?;
    validate_animation(scene)
}

/// Checks every hand-made sprite cloud and each of its boxes.
fn validate_sprite_clouds(scene: &Scene) -> Result<(), Violation> {
    for (index, cloud) in scene.sprite_clouds.iter().enumerate() {
        let prefix = format!("sprite_clouds.{index}.");
        check(cloud, &prefix, knobs::SPRITE_CLOUD, SPRITE_CLOUD_RELATIONS)?;
        for (b, sprite_box) in cloud.boxes.iter().enumerate() {
            check(
                sprite_box,
                &format!("{prefix}boxes.{b}."),
                knobs::SPRITE_BOX,
                &[],
            )?;
        }
    }
    Ok(())
}

/// Checks every keyframe of every animation path, then each path's order and consistency.
fn validate_animation(scene: &Scene) -> Result<(), Violation> {
    let animation = &scene.animation;
    check_path(
        &animation.camera_path,
        "animation.camera_path",
        &CAMERA_PATH,
    )?;
    check_path(&animation.time_of_day, "animation.time_of_day", &SUN_PATH)?;
    validate_sun_path(scene)?;
    check_path(
        &animation.coverage_scale,
        "animation.coverage_scale",
        &COVERAGE_PATH,
    )
}

/// A check between fields of `T`; `broken` returns the message when the check fails.
struct Relation<T> {
    /// Dotted key path (relative to `T`) of the field the message is about.
    key: &'static str,
    broken: fn(&T) -> Option<String>,
}

/// A check between a keyframe and the one before it; `broken(previous, key)` returns the message.
struct PairRelation<K> {
    /// Dotted key path (relative to the later keyframe) of the field the message is about.
    key: &'static str,
    broken: fn(&K, &K) -> Option<String>,
}

/// Everything checked on the keyframes of one path type.
struct PathRules<K: 'static> {
    /// The knobs of each keyframe.
    rules: &'static [Knob<K>],
    /// Checks within each keyframe.
    relations: &'static [Relation<K>],
    /// Checks between consecutive keyframes.
    pairs: &'static [PairRelation<K>],
}

/// Keyframes with a scene time.
trait Keyframe {
    fn time_s(&self) -> f32;
}

impl Keyframe for CameraKey {
    fn time_s(&self) -> f32 {
        self.time_s
    }
}

impl Keyframe for SunKey {
    fn time_s(&self) -> f32 {
        self.time_s
    }
}

impl Keyframe for CoverageKey {
    fn time_s(&self) -> f32 {
        self.time_s
    }
}

#[rustfmt::skip]
const SPRITE_CLOUD_RELATIONS: &[Relation<SpriteCloudSpec>] = &[
    Relation { key: "boxes", broken: no_boxes },
    Relation { key: "width", broken: width_range_reversed },
    Relation { key: "color_levels", broken: color_levels_malformed },
];

#[rustfmt::skip]
const CAMERA_PATH: PathRules<CameraKey> = PathRules {
    rules: knobs::CAMERA_KEY,
    relations: &[Relation { key: "look_at_m", broken: key_looks_at_its_eye }],
    pairs: &[
        PairRelation { key: "time_s", broken: time_not_increasing },
        PairRelation { key: "look_at_m", broken: look_at_on_some_keys_only },
    ],
};

#[rustfmt::skip]
const SUN_PATH: PathRules<SunKey> = PathRules {
    rules: knobs::SUN_KEY,
    relations: &[
        Relation { key: "solar_time_h", broken: sun_key_given_both_ways },
        Relation { key: "sun_azimuth_deg", broken: sun_key_has_one_angle },
        Relation { key: "time_s", broken: sun_key_has_no_place },
    ],
    pairs: &[PairRelation { key: "time_s", broken: time_not_increasing }],
};

#[rustfmt::skip]
const COVERAGE_PATH: PathRules<CoverageKey> = PathRules {
    rules: knobs::COVERAGE_KEY,
    relations: &[],
    pairs: &[PairRelation { key: "time_s", broken: time_not_increasing }],
};

#[rustfmt::skip]
const SCENE_RELATIONS: &[Relation<Scene>] = &[
    Relation { key: "camera.far_m", broken: far_not_beyond_near },
    Relation { key: "camera.look_at_m", broken: look_at_is_the_eye },
    Relation { key: "weather.source", broken: weather_file_without_path },
    Relation { key: "render.output", broken: output_not_png_or_exr },
    Relation { key: "particles.ring_cells", broken: ring_cells_odd },
    Relation { key: "particles.resolution_divisor", broken: divisor_not_1_2_or_4 },
];

#[rustfmt::skip]
const LAYER_RELATIONS: &[Relation<CloudLayer>] = &[
    Relation { key: "types", broken: no_cloud_type },
];

#[rustfmt::skip]
const VOLUME_RELATIONS: &[Relation<VolumeGrid>] = &[
    Relation { key: "path", broken: volume_without_path },
];

fn no_boxes(cloud: &SpriteCloudSpec) -> Option<String> {
    cloud.boxes.is_empty().then(|| {
        "a sprite cloud needs at least one box: boxes = [{ center_m = [..], size_m = [..] }]"
            .to_string()
    })
}

fn width_range_reversed(cloud: &SpriteCloudSpec) -> Option<String> {
    let [lo, hi] = cloud.width?;
    (lo > hi).then(|| format!("[{lo}, {hi}] is reversed; give [min, max]"))
}

fn color_levels_malformed(cloud: &SpriteCloudSpec) -> Option<String> {
    let levels = cloud.color_levels.as_ref()?;
    if levels.len() != 5 {
        return Some(format!(
            "{} levels given; exactly 5 [height, r, g, b, a] are needed",
            levels.len()
        ));
    }
    let increasing = levels.windows(2).all(|w| w[0][0] < w[1][0]);
    let in_range = levels.iter().all(|[h, r, g, b, a]| {
        (0.0..=1.0).contains(h)
            && [r, g, b].iter().all(|c| (0.0..=4.0).contains(*c))
            && (0.0..=1.0).contains(a)
    });
    (!increasing || !in_range).then(|| {
        "levels need heights rising within 0..1, rgb within 0..4 and a within 0..1".to_string()
    })
}

fn ring_cells_odd(scene: &Scene) -> Option<String> {
    let cells = scene.particles.ring_cells;
    (cells % 2 == 1).then(|| format!("{cells} is odd; a ring needs an even number of cells"))
}

fn divisor_not_1_2_or_4(scene: &Scene) -> Option<String> {
    let divisor = scene.particles.resolution_divisor;
    (![1, 2, 4].contains(&divisor)).then(|| format!("{divisor} is not 1, 2 or 4"))
}

fn far_not_beyond_near(scene: &Scene) -> Option<String> {
    let (near, far) = (scene.camera.near_m, scene.camera.far_m);
    (far <= near).then(|| format!("far_m ({far} m) must be greater than near_m ({near} m)"))
}

fn look_at_is_the_eye(scene: &Scene) -> Option<String> {
    (scene.camera.look_at_m == Some(scene.camera.position_m)).then(|| {
        "look_at_m equals position_m, which gives no view direction; move it, or remove it to use yaw_deg \
         and pitch_deg"
            .to_string()
    })
}

fn weather_file_without_path(scene: &Scene) -> Option<String> {
    let has_path = scene
        .weather
        .path
        .as_deref()
        .is_some_and(|p| !p.trim().is_empty());
    (scene.weather.source == WeatherSource::File && !has_path).then(|| {
        "source = \"file\" needs `path`, a PNG file relative to the scene file".to_string()
    })
}

fn output_not_png_or_exr(scene: &Scene) -> Option<String> {
    let output = &scene.render.output;
    let lower = output.to_ascii_lowercase();
    (!lower.ends_with(".png") && !lower.ends_with(".exr")).then(|| {
        format!("\"{output}\" must end in .png (tone-mapped sRGB) or .exr (linear HDR radiance)")
    })
}

fn no_cloud_type(layer: &CloudLayer) -> Option<String> {
    let t = &layer.types;
    (t.stratus + t.stratocumulus + t.cumulus + t.cumulonimbus <= 0.0).then(|| {
        "every type weight (stratus, stratocumulus, cumulus, cumulonimbus) is 0; at least one must be > 0"
            .to_string()
    })
}

fn volume_without_path(volume: &VolumeGrid) -> Option<String> {
    volume.path.trim().is_empty().then(|| {
        "a volume needs `path`, a Mitsuba 3 .vol or OpenVDB .vdb file relative to the scene file".to_string()
    })
}

fn key_looks_at_its_eye(key: &CameraKey) -> Option<String> {
    (key.look_at_m == Some(key.position_m))
        .then(|| "look_at_m equals position_m, which gives no view direction; move it".to_string())
}

fn time_not_increasing<K: Keyframe>(previous: &K, key: &K) -> Option<String> {
    let (before, now) = (previous.time_s(), key.time_s());
    (now <= before).then(|| {
        format!(
            "{now} s is not after the previous keyframe's {before} s; times must strictly increase"
        )
    })
}

fn look_at_on_some_keys_only(previous: &CameraKey, key: &CameraKey) -> Option<String> {
    let has = |k: &CameraKey| {
        if k.look_at_m.is_some() {
            "has"
        } else {
            "has no"
        }
    };
    (previous.look_at_m.is_some() != key.look_at_m.is_some()).then(|| {
        format!(
            "this keyframe {} look_at_m but the previous one {}; give look_at_m on every keyframe of \
             the path (targets follow their own spline) or on none (yaw_deg and pitch_deg are used)",
            has(key),
            has(previous)
        )
    })
}

fn sun_key_given_both_ways(key: &SunKey) -> Option<String> {
    let angles = key.sun_elevation_deg.is_some() || key.sun_azimuth_deg.is_some();
    (angles && key.solar_time_h.is_some()).then(|| {
        "this keyframe gives both solar_time_h and sun angles; keep one: solar_time_h, or \
         sun_elevation_deg and sun_azimuth_deg"
            .to_string()
    })
}

fn sun_key_has_one_angle(key: &SunKey) -> Option<String> {
    (key.sun_elevation_deg.is_some() != key.sun_azimuth_deg.is_some()).then(|| {
        "give sun_elevation_deg and sun_azimuth_deg together (or solar_time_h instead)".to_string()
    })
}

fn sun_key_has_no_place(key: &SunKey) -> Option<String> {
    let none = key.sun_elevation_deg.is_none()
        && key.sun_azimuth_deg.is_none()
        && key.solar_time_h.is_none();
    none.then(|| {
        "this keyframe puts the sun nowhere: give sun_elevation_deg and sun_azimuth_deg, or \
         solar_time_h"
            .to_string()
    })
}

/// Checks what the sun path needs of the rest of the scene: solar-time keyframes need
/// `sun.time_of_day` (its latitude and day), and neighbouring keyframes, which are interpolated
/// as vectors (see `crate::animation`), must be less than 90 degrees of sky apart, except two
/// solar-time keyframes, between which the path traces the sun's course.
fn validate_sun_path(scene: &Scene) -> Result<(), Violation> {
    let day = scene.sun.time_of_day.as_ref();
    let keys = &scene.animation.time_of_day;
    let field = |key: &SunKey| {
        if key.solar_time_h.is_some() {
            "solar_time_h"
        } else {
            "sun_azimuth_deg"
        }
    };
    let violation = |index: usize, message: String| Violation {
        key: format!("animation.time_of_day.{index}.{}", field(&keys[index])),
        message,
    };
    if let (Some(index), None) = (keys.iter().position(|k| k.solar_time_h.is_some()), day) {
        return Err(violation(
            index,
            "a keyframe by solar time needs [sun] time_of_day = { solar_time_h, latitude_deg, \
             day_of_year } for its latitude and day"
                .to_string(),
        ));
    }
    for (index, pair) in keys.windows(2).enumerate() {
        if pair[0].solar_time_h.is_some() && pair[1].solar_time_h.is_some() {
            continue;
        }
        let directions = key_direction(&pair[0], day).zip(key_direction(&pair[1], day));
        let Some((before, after)) = directions else {
            continue;
        };
        let angle_deg = before.dot(after).clamp(-1.0, 1.0).acos().to_degrees();
        if angle_deg >= 90.0 {
            return Err(violation(
                index + 1,
                format!(
                    "the sun moves {angle_deg:.1} deg across the sky from the previous keyframe; \
                     allowed < 90 deg: add a keyframe in between"
                ),
            ));
        }
    }
    Ok(())
}

/// Checks every keyframe of `keys` (dotted path `path`), that there are none or at least 2, and
/// the relations between consecutive keyframes.
fn check_path<K: Keyframe>(keys: &[K], path: &str, rules: &PathRules<K>) -> Result<(), Violation> {
    for (index, key) in keys.iter().enumerate() {
        check(
            key,
            &format!("{path}.{index}."),
            rules.rules,
            rules.relations,
        )?;
    }
    if keys.len() == 1 {
        return Err(Violation {
            key: path.to_string(),
            message: "1 keyframe given; a path needs at least 2 (or none, for no change)"
                .to_string(),
        });
    }
    for (index, pair) in keys.windows(2).enumerate() {
        for relation in rules.pairs {
            if let Some(message) = (relation.broken)(&pair[0], &pair[1]) {
                return Err(Violation {
                    key: format!("{path}.{}.{}", index + 1, relation.key),
                    message,
                });
            }
        }
    }
    Ok(())
}

/// Checks the knobs, then the relations, of one item whose keys start with `prefix`.
fn check<T>(
    item: &T,
    prefix: &str,
    knobs: &[Knob<T>],
    relations: &[Relation<T>],
) -> Result<(), Violation> {
    for knob in knobs {
        check_knob(knob, item, prefix)?;
    }
    for relation in relations {
        if let Some(message) = (relation.broken)(item) {
            return Err(Violation {
                key: format!("{prefix}{}", relation.key),
                message,
            });
        }
    }
    Ok(())
}

/// Checks that every number `knob` reads from `item` is allowed.
fn check_knob<T>(knob: &Knob<T>, item: &T, prefix: &str) -> Result<(), Violation> {
    let key = format!("{prefix}{}", knob.key);
    match knob.get(item) {
        Field::Float(value) => check_number(knob, key, f64::from(value), &value),
        Field::Int(value) => check_number(knob, key, f64::from(value), &value),
        Field::Floats(values) => values.iter().enumerate().try_for_each(|(index, value)| {
            check_number(knob, format!("{key}.{index}"), f64::from(*value), value)
        }),
        Field::Bool(_) | Field::Choice(_) | Field::Absent => Ok(()),
    }
}

/// Checks one number `value` (displayed as `shown`) against `knob`'s range.
fn check_number<T>(
    knob: &Knob<T>,
    key: String,
    value: f64,
    shown: &dyn fmt::Display,
) -> Result<(), Violation> {
    let problem = if !value.is_finite() {
        "is not a finite number"
    } else if !knob.allowed.contains(value) {
        "is out of range"
    } else {
        return Ok(());
    };
    Err(Violation {
        key,
        message: format!(
            "{shown} {problem}; allowed {}",
            knob.allowed.describe(knob.unit)
        ),
    })
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::scene::model::{Animation, CloudType, SpriteBoxSpec, TimeOfDay, VolumeGrid};

    /// Two camera keyframes 10 s apart that look at a point, two sun and two coverage keyframes.
    pub(in crate::scene) fn two_key_animation() -> Animation {
        let camera = |time_s, x| CameraKey {
            time_s,
            position_m: [x, 30.0, 0.0],
            look_at_m: Some([0.0, 2500.0, -6000.0]),
            yaw_deg: 0.0,
            pitch_deg: 0.0,
        };
        let sun = |time_s, sun_azimuth_deg| SunKey::at_angles(time_s, 30.0, sun_azimuth_deg);
        let coverage = |time_s, scale| CoverageKey { time_s, scale };
        Animation {
            camera_path: vec![camera(0.0, 0.0), camera(10.0, 500.0)],
            time_of_day: vec![sun(0.0, 215.0), sun(10.0, 220.0)],
            coverage_scale: vec![coverage(0.0, 1.0), coverage(10.0, 1.2)],
        }
    }

    /// A scene with every optional field set and one volume, so serialising it names every key.
    pub(in crate::scene) fn fully_populated() -> Scene {
        let mut scene = Scene::default();
        scene.camera.look_at_m = Some([0.0, 2500.0, -6000.0]);
        scene.weather.path = Some("weather.png".into());
        scene.render.primary_steps = Some(128);
        scene.render.light_steps = Some(6);
        scene.render.samples_per_pixel = Some(4);
        scene.volumes.push(VolumeGrid {
            path: "storm.vdb".into(),
            grid: Some("density".into()),
            center_m: Some([0.0, 2500.0, -6000.0]),
            size_m: Some([2000.0; 3]),
            ..VolumeGrid::default()
        });
        scene.sprites.ambient_color = Some([0.3, 0.35, 0.45]);
        scene.sprites.directional_color = Some([2.5, 2.4, 2.2]);
        scene.sprites.model = Some("clouds.sprites.toml".into());
        scene.sprite_clouds.push(SpriteCloudSpec {
            cloud_type: CloudType::CumulusMediocris,
            center_m: [0.0, 1800.0, -6000.0],
            boxes: vec![SpriteBoxSpec {
                center_m: [0.0; 3],
                size_m: [1400.0, 500.0, 1000.0],
            }],
            seed: 1,
            sprites: Some(40),
            width: Some([0.45, 0.8]),
            rotation_deg: Some([-180.0, 180.0]),
            color_levels: Some(vec![
                [0.0, 0.4, 0.4, 0.45, 1.0],
                [0.25, 0.55, 0.55, 0.6, 1.0],
                [0.5, 0.7, 0.7, 0.75, 1.0],
                [0.75, 0.85, 0.85, 0.9, 1.0],
                [1.0, 1.0, 1.0, 1.0, 1.0],
            ]),
        });
        scene.animation = two_key_animation();
        scene.sun.time_of_day = Some(TimeOfDay {
            solar_time_h: 15.0,
            latitude_deg: 51.5,
            day_of_year: 172,
        });
        scene
            .animation
            .time_of_day
            .push(SunKey::at_solar_time(20.0, 15.0));
        scene.weather.metar = Some("EGLL 011750Z 24012KT 9999 FEW012 SCT030 18/12 Q1012".into());
        scene
    }

    /// What a leaf of a scene file holds.
    #[derive(Clone, Copy, PartialEq, Debug)]
    enum Leaf {
        /// A number or an array of numbers.
        Numeric,
        /// True or false.
        Bool,
        /// A string: a name from a list or free text.
        Text,
    }

    /// Dotted paths of the leaves of a TOML value, by kind; array-of-table indices are left out.
    fn leaves(value: &toml::Value, prefix: &str, out: &mut Vec<(String, Leaf)>) {
        let kind = match value {
            toml::Value::Table(table) => {
                for (key, child) in table {
                    leaves(child, &format!("{prefix}{key}."), out);
                }
                return;
            }
            toml::Value::Array(items) if items.iter().all(toml::Value::is_table) => {
                items.iter().for_each(|item| leaves(item, prefix, out));
                return;
            }
            toml::Value::Boolean(_) => Leaf::Bool,
            toml::Value::String(_) => Leaf::Text,
            _ => Leaf::Numeric,
        };
        out.push((prefix.trim_end_matches('.').to_string(), kind));
    }

    /// The keys of `knobs`, each after `prefix`, with whether each holds a number.
    fn prefixed<T>(prefix: &str, knobs: &[Knob<T>]) -> Vec<(String, bool)> {
        let numeric = |k: &Knob<T>| k.allowed != knobs::Allowed::Listed;
        knobs
            .iter()
            .map(|k| (format!("{prefix}{}", k.key), numeric(k)))
            .collect()
    }

    #[test]
    fn every_number_switch_and_choice_has_exactly_one_knob() {
        let serialized = toml::Value::try_from(fully_populated()).unwrap();
        let mut fields = Vec::new();
        leaves(&serialized, "", &mut fields);
        fields.sort_by(|a, b| a.0.cmp(&b.0));
        fields.dedup();
        let mut knobbed: Vec<(String, bool)> = [
            prefixed("", knobs::SCENE),
            prefixed("sun.time_of_day.", knobs::TIME_OF_DAY),
            prefixed("layers.", knobs::LAYER),
            prefixed("volumes.", knobs::VOLUME),
            prefixed("sprite_clouds.", knobs::SPRITE_CLOUD),
            prefixed("sprite_clouds.boxes.", knobs::SPRITE_BOX),
            prefixed("animation.camera_path.", knobs::CAMERA_KEY),
            prefixed("animation.time_of_day.", knobs::SUN_KEY),
            prefixed("animation.coverage_scale.", knobs::COVERAGE_KEY),
        ]
        .concat();
        knobbed.sort();
        let numbers = |leaf: Leaf| leaf == Leaf::Numeric;
        let numeric: Vec<&String> = fields
            .iter()
            .filter(|f| numbers(f.1))
            .map(|f| &f.0)
            .collect();
        let numeric_knobs: Vec<&String> = knobbed.iter().filter(|k| k.1).map(|k| &k.0).collect();
        assert_eq!(numeric_knobs, numeric);
        for (key, leaf) in &fields {
            let knob = knobbed.iter().find(|k| &k.0 == key);
            if *leaf == Leaf::Bool {
                assert!(knob.is_some(), "the switch {key} has no knob");
            }
        }
        for (key, numeric) in &knobbed {
            let leaf = fields.iter().find(|f| &f.0 == key).map(|f| f.1);
            assert!(
                *numeric || leaf == Some(Leaf::Bool) || leaf == Some(Leaf::Text),
                "{key}"
            );
        }
    }

    #[test]
    fn defaults_and_the_fully_populated_scene_are_valid() {
        validate(&Scene::default()).unwrap();
        validate(&fully_populated()).unwrap();
    }

    #[test]
    fn bounds_are_compared_in_f32_so_the_documented_limits_are_allowed() {
        let mut scene = Scene::default();
        scene.phase.g = 0.99;
        scene.phase.g_back = -0.99;
        scene.weather.extent_km = 0.1;
        scene.sky.gradient_exponent = 0.05;
        validate(&scene).unwrap();
    }

    #[test]
    fn violations_name_the_element_value_and_range() {
        let mut scene = Scene::default();
        scene.sun.color[1] = 1.5;
        let violation = validate(&scene).unwrap_err();
        assert_eq!(violation.key, "sun.color.1");
        assert_eq!(violation.message, "1.5 is out of range; allowed 0..1");

        let mut scene = Scene::default();
        scene.camera.fov_y_deg = f32::NAN;
        let violation = validate(&scene).unwrap_err();
        assert_eq!(
            violation.message,
            "NaN is not a finite number; allowed 1..179 deg"
        );
    }

    #[test]
    fn relations_between_fields_are_checked() {
        type Breaker = fn(&mut Scene);
        let cases: [(Breaker, &str); 6] = [
            (|s| s.camera.far_m = s.camera.near_m, "camera.far_m"),
            (
                |s| s.camera.look_at_m = Some(s.camera.position_m),
                "camera.look_at_m",
            ),
            (|s| s.weather.source = WeatherSource::File, "weather.source"),
            (|s| s.render.output = "frame.jpg".into(), "render.output"),
            (|s| s.layers[0].types.cumulus = 0.0, "layers.0.types"),
            (|s| s.volumes.push(VolumeGrid::default()), "volumes.0.path"),
        ];
        for (break_it, key) in cases {
            let mut scene = Scene::default();
            break_it(&mut scene);
            assert_eq!(validate(&scene).unwrap_err().key, key);
        }
    }

    /// The default scene with [`two_key_animation`].
    fn animated_scene() -> Scene {
        Scene {
            animation: two_key_animation(),
            ..Scene::default()
        }
    }

    /// The violation of the default scene with `two_key_animation`, changed by `break_it`.
    fn animation_violation(break_it: fn(&mut Animation)) -> Violation {
        let mut scene = animated_scene();
        break_it(&mut scene.animation);
        validate(&scene).unwrap_err()
    }

    #[test]
    fn keyframe_times_must_strictly_increase() {
        let violation = animation_violation(|a| a.time_of_day[1].time_s = 0.0);
        assert_eq!(violation.key, "animation.time_of_day.1.time_s");
        assert_eq!(
            violation.message,
            "0 s is not after the previous keyframe's 0 s; times must strictly increase"
        );
        let violation = animation_violation(|a| a.camera_path[1].time_s = -1.0);
        assert_eq!(violation.key, "animation.camera_path.1.time_s");
    }

    #[test]
    fn a_path_of_one_keyframe_is_rejected_and_an_empty_one_allowed() {
        let violation = animation_violation(|a| a.coverage_scale.truncate(1));
        assert_eq!(violation.key, "animation.coverage_scale");
        assert!(
            violation.message.contains("at least 2"),
            "{}",
            violation.message
        );
        let mut scene = animated_scene();
        scene.animation.coverage_scale.clear();
        validate(&scene).unwrap();
    }

    #[test]
    fn keyframe_fields_and_relations_are_checked_with_their_index() {
        type Breaker = fn(&mut Animation);
        let cases: [(Breaker, &str); 5] = [
            (
                |a| a.camera_path[1].pitch_deg = 91.0,
                "animation.camera_path.1.pitch_deg",
            ),
            (
                |a| a.coverage_scale[0].scale = -0.5,
                "animation.coverage_scale.0.scale",
            ),
            (
                |a| a.camera_path[1].look_at_m = None,
                "animation.camera_path.1.look_at_m",
            ),
            (
                |a| a.camera_path[0].look_at_m = Some(a.camera_path[0].position_m),
                "animation.camera_path.0.look_at_m",
            ),
            (
                |a| a.time_of_day[1].sun_azimuth_deg = Some(35.0),
                "animation.time_of_day.1.sun_azimuth_deg",
            ),
        ];
        for (break_it, key) in cases {
            assert_eq!(animation_violation(break_it).key, key);
        }
    }

    #[test]
    fn sun_keyframes_just_under_90_degrees_apart_are_allowed() {
        let mut scene = animated_scene();
        scene.animation.time_of_day[0] = SunKey::at_angles(0.0, 0.0, 215.0);
        scene.animation.time_of_day[1] = SunKey::at_angles(10.0, 0.0, 215.0 + 89.5);
        validate(&scene).unwrap();
    }

    #[test]
    fn sun_keyframes_are_given_one_way_or_the_other() {
        type Breaker = fn(&mut Animation);
        let cases: [(Breaker, &str, &str); 4] = [
            (
                |a| a.time_of_day[1].solar_time_h = Some(14.0),
                "solar_time_h",
                "keep one",
            ),
            (
                |a| a.time_of_day[1].sun_elevation_deg = None,
                "sun_azimuth_deg",
                "together",
            ),
            (
                |a| {
                    a.time_of_day[1] = SunKey {
                        solar_time_h: None,
                        ..SunKey::at_solar_time(10.0, 0.0)
                    }
                },
                "time_s",
                "nowhere",
            ),
            (
                |a| a.time_of_day[1] = SunKey::at_solar_time(10.0, 14.0),
                "solar_time_h",
                "sun.time_of_day",
            ),
        ];
        for (break_it, key, words) in cases {
            let violation = animation_violation(break_it);
            assert_eq!(violation.key, format!("animation.time_of_day.1.{key}"));
            assert!(
                violation.message.contains(words) || violation.message.contains("time_of_day ="),
                "{}",
                violation.message
            );
        }
    }

    #[test]
    fn solar_time_keyframes_may_span_the_day_and_others_stay_within_90_degrees() {
        let mut scene = fully_populated();
        let day = [6.0, 12.0, 18.0].map(|h| SunKey::at_solar_time(h * 10.0, h));
        scene.animation.time_of_day = day.to_vec();
        validate(&scene).unwrap();
        scene.animation.time_of_day[2] = SunKey::at_angles(180.0, 5.0, 30.0);
        let violation = validate(&scene).unwrap_err();
        assert_eq!(violation.key, "animation.time_of_day.2.sun_azimuth_deg");
        assert!(
            violation.message.contains("90 deg"),
            "{}",
            violation.message
        );
    }
}
