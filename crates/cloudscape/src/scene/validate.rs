//! Range checks of every numeric field, in one table per struct, and the checks between fields.
//!
//! The ranges restate the doc comments of [`super::model`]; change both together. Seeds are not
//! listed: every `u32` is a valid seed.

use std::fmt;

use crate::animation::key_direction;

use super::model::{
    CameraKey, CloudLayer, CoverageKey, Scene, SpriteBoxSpec, SpriteCloudSpec, SunKey, VolumeGrid,
    WeatherSource,
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
    check(scene, "", SCENE_RULES, SCENE_RELATIONS)?;
    for (index, layer) in scene.layers.iter().enumerate() {
        check(
            layer,
            &format!("layers.{index}."),
            LAYER_RULES,
            LAYER_RELATIONS,
        )?;
    }
    for (index, volume) in scene.volumes.iter().enumerate() {
        check(
            volume,
            &format!("volumes.{index}."),
            VOLUME_RULES,
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
        check(cloud, &prefix, SPRITE_CLOUD_RULES, SPRITE_CLOUD_RELATIONS)?;
        for (b, sprite_box) in cloud.boxes.iter().enumerate() {
            check(
                sprite_box,
                &format!("{prefix}boxes.{b}."),
                SPRITE_BOX_RULES,
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

/// The allowed values of a numeric field; every allowed value is also finite.
#[derive(Clone, Copy, Debug)]
enum Allowed {
    /// Any finite number.
    Finite,
    /// `min..=max`.
    Between(f32, f32),
    /// `>= min`.
    AtLeast(f32),
    /// `> min`.
    Above(f32),
}

impl Allowed {
    fn contains(self, value: f64) -> bool {
        match self {
            Allowed::Finite => true,
            Allowed::Between(min, max) => f64::from(min) <= value && value <= f64::from(max),
            Allowed::AtLeast(min) => f64::from(min) <= value,
            Allowed::Above(min) => f64::from(min) < value,
        }
    }

    /// The range in words, with its unit: `1..179 deg`, `>= 0`, `any finite number (m)`.
    fn describe(self, unit: &str) -> String {
        let range = match self {
            Allowed::Finite => "any finite number".to_string(),
            Allowed::Between(min, max) => format!("{min}..{max}"),
            Allowed::AtLeast(min) => format!(">= {min}"),
            Allowed::Above(min) => format!("> {min}"),
        };
        match (self, unit) {
            (_, "") => range,
            (Allowed::Finite, _) => format!("{range} ({unit})"),
            _ => format!("{range} {unit}"),
        }
    }
}

/// A numeric field as read from the scene.
enum Field<'a> {
    Float(f32),
    Int(u32),
    /// An array: each element is checked, and named by its index.
    Floats(&'a [f32]),
    /// An optional field that is not set.
    Absent,
}

fn optional_floats<const N: usize>(value: &Option<[f32; N]>) -> Field<'_> {
    value.as_ref().map_or(Field::Absent, |v| Field::Floats(v))
}

fn optional_float(value: Option<f32>) -> Field<'static> {
    value.map_or(Field::Absent, Field::Float)
}

fn optional_int(value: Option<u32>) -> Field<'static> {
    value.map_or(Field::Absent, Field::Int)
}

/// One row of a table: a field, its allowed values and its unit.
struct Rule<T> {
    /// Dotted key path relative to `T`.
    key: &'static str,
    allowed: Allowed,
    /// Unit for messages; empty for dimensionless fields.
    unit: &'static str,
    read: fn(&T) -> Field<'_>,
}

/// Shorthand that keeps each row of the tables on one line.
const fn rule<T>(
    key: &'static str,
    allowed: Allowed,
    unit: &'static str,
    read: fn(&T) -> Field<'_>,
) -> Rule<T> {
    Rule {
        key,
        allowed,
        unit,
        read,
    }
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
    /// Rules of each keyframe's numeric fields.
    rules: &'static [Rule<K>],
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

use Allowed::{Above, AtLeast, Between, Finite};
use Field::{Float, Floats, Int};

#[rustfmt::skip]
const SCENE_RULES: &[Rule<Scene>] = &[
    rule("camera.position_m", Finite, "m", |s| Floats(&s.camera.position_m)),
    rule("camera.look_at_m", Finite, "m", |s| optional_floats(&s.camera.look_at_m)),
    rule("camera.yaw_deg", Finite, "deg", |s| Float(s.camera.yaw_deg)),
    rule("camera.pitch_deg", Between(-90.0, 90.0), "deg", |s| Float(s.camera.pitch_deg)),
    rule("camera.fov_y_deg", Between(1.0, 179.0), "deg", |s| Float(s.camera.fov_y_deg)),
    rule("camera.near_m", Above(0.0), "m", |s| Float(s.camera.near_m)),
    rule("camera.far_m", Above(0.0), "m", |s| Float(s.camera.far_m)),
    rule("sun.elevation_deg", Between(-90.0, 90.0), "deg", |s| Float(s.sun.elevation_deg)),
    rule("sun.azimuth_deg", Finite, "deg", |s| Float(s.sun.azimuth_deg)),
    rule("sun.irradiance", AtLeast(0.0), "", |s| Float(s.sun.irradiance)),
    rule("sun.color", Between(0.0, 1.0), "", |s| Floats(&s.sun.color)),
    rule("sun.angular_radius_deg", Between(0.0, 5.0), "deg", |s| Float(s.sun.angular_radius_deg)),
    rule("sun.time_of_day.solar_time_h", Between(0.0, 24.0), "h", |s| optional_float(s.sun.time_of_day.as_ref().map(|t| t.solar_time_h))),
    rule("sun.time_of_day.latitude_deg", Between(-90.0, 90.0), "deg", |s| optional_float(s.sun.time_of_day.as_ref().map(|t| t.latitude_deg))),
    rule("sun.time_of_day.day_of_year", Between(1.0, 366.0), "", |s| optional_int(s.sun.time_of_day.as_ref().map(|t| t.day_of_year))),
    rule("sky.radiance", AtLeast(0.0), "", |s| Floats(&s.sky.radiance)),
    rule("sky.zenith_radiance", AtLeast(0.0), "", |s| Floats(&s.sky.zenith_radiance)),
    rule("sky.horizon_radiance", AtLeast(0.0), "", |s| Floats(&s.sky.horizon_radiance)),
    rule("sky.gradient_exponent", Between(0.05, 10.0), "", |s| Float(s.sky.gradient_exponent)),
    rule("sky.visibility_m", Between(100.0, 1.0e7), "m", |s| Float(s.sky.visibility_m)),
    rule("shadow.resolution", Between(16.0, 4096.0), "texels", |s| Int(s.shadow.resolution)),
    rule("shadow.steps", Between(4.0, 256.0), "", |s| Int(s.shadow.steps)),
    rule("shadow.warp", Between(0.05, 1.0), "", |s| Float(s.shadow.warp)),
    rule("ground.albedo", Between(0.0, 1.0), "", |s| Floats(&s.ground.albedo)),
    rule("planet.radius_m", Between(1.0e3, 1.0e8), "m", |s| Float(s.planet.radius_m)),
    rule("weather.extent_km", Between(0.1, 1.0e4), "km", |s| Float(s.weather.extent_km)),
    rule("weather.resolution", Between(8.0, 4096.0), "texels", |s| Int(s.weather.resolution)),
    rule("weather.feature_size_km", Above(0.0), "km", |s| Float(s.weather.feature_size_km)),
    rule("noise.base_period_m", Above(0.0), "m", |s| Float(s.noise.base_period_m)),
    rule("noise.detail_period_m", Above(0.0), "m", |s| Float(s.noise.detail_period_m)),
    rule("noise.detail_erosion", Between(0.0, 1.0), "", |s| Float(s.noise.detail_erosion)),
    rule("noise.curl_displacement_m", AtLeast(0.0), "m", |s| Float(s.noise.curl_displacement_m)),
    rule("phase.droplet_diameter_um", Between(5.0, 50.0), "um", |s| Float(s.phase.droplet_diameter_um)),
    rule("phase.g", Between(-0.99, 0.99), "", |s| Float(s.phase.g)),
    rule("phase.g_forward", Between(-0.99, 0.99), "", |s| Float(s.phase.g_forward)),
    rule("phase.g_back", Between(-0.99, 0.99), "", |s| Float(s.phase.g_back)),
    rule("phase.forward_weight", Between(0.0, 1.0), "", |s| Float(s.phase.forward_weight)),
    rule("lighting.albedo", Between(0.0, 1.0), "", |s| Float(s.lighting.albedo)),
    rule("lighting.octaves", Between(1.0, 8.0), "", |s| Int(s.lighting.octaves)),
    rule("lighting.octave_attenuation", Between(0.0, 1.0), "", |s| Float(s.lighting.octave_attenuation)),
    rule("lighting.octave_contribution", Between(0.0, 1.0), "", |s| Float(s.lighting.octave_contribution)),
    rule("lighting.octave_eccentricity", Between(0.0, 1.0), "", |s| Float(s.lighting.octave_eccentricity)),
    rule("lighting.ambient_scale", Between(0.0, 4.0), "", |s| Float(s.lighting.ambient_scale)),
    rule("particles.radius_m", Between(10.0, 5000.0), "m", |s| Float(s.particles.radius_m)),
    rule("particles.rings", Between(1.0, 8.0), "", |s| Int(s.particles.rings)),
    rule("particles.ring_cells", Between(16.0, 512.0), "", |s| Int(s.particles.ring_cells)),
    rule("particles.cell_layers", Between(0.0, 16.0), "", |s| Int(s.particles.cell_layers)),
    rule("particles.distance_m", Between(1.0e3, 1.0e6), "m", |s| Float(s.particles.distance_m)),
    rule("particles.resolution_divisor", Between(1.0, 4.0), "", |s| Int(s.particles.resolution_divisor)),
    rule("sprites.cloud_size_m", Between(200.0, 20_000.0), "m", |s| Float(s.sprites.cloud_size_m)),
    rule("sprites.distance_m", Between(1.0e3, 5.0e5), "m", |s| Float(s.sprites.distance_m)),
    rule("sprites.ring_radius_m", Between(0.0, 2.0e5), "m", |s| Float(s.sprites.ring_radius_m)),
    rule("sprites.impostor_texels", Between(64.0, 2048.0), "", |s| Int(s.sprites.impostor_texels)),
    rule("sprites.lock_distance_m", Between(0.0, 5000.0), "m", |s| Float(s.sprites.lock_distance_m)),
    rule("sprites.ambient_color", AtLeast(0.0), "", |s| optional_floats(&s.sprites.ambient_color)),
    rule("sprites.directional_color", AtLeast(0.0), "", |s| optional_floats(&s.sprites.directional_color)),
    rule("render.width", AtLeast(1.0), "px", |s| Int(s.render.width)),
    rule("render.height", AtLeast(1.0), "px", |s| Int(s.render.height)),
    rule("render.primary_steps", Between(1.0, 4096.0), "", |s| optional_int(s.render.primary_steps)),
    rule("render.light_steps", Between(1.0, 64.0), "", |s| optional_int(s.render.light_steps)),
    rule("render.samples_per_pixel", Between(1.0, 1024.0), "", |s| optional_int(s.render.samples_per_pixel)),
    rule("render.exposure_ev", Between(-20.0, 20.0), "EV", |s| Float(s.render.exposure_ev)),
    rule("render.time_s", Finite, "s", |s| Float(s.render.time_s)),
];

#[rustfmt::skip]
const LAYER_RULES: &[Rule<CloudLayer>] = &[
    rule("bottom_m", AtLeast(0.0), "m", |l| Float(l.bottom_m)),
    rule("thickness_m", Between(10.0, 20_000.0), "m", |l| Float(l.thickness_m)),
    rule("coverage", Between(0.0, 1.0), "", |l| Float(l.coverage)),
    rule("extinction_per_m", Between(0.0, 1.0), "m^-1", |l| Float(l.extinction_per_m)),
    rule("types.stratus", AtLeast(0.0), "", |l| Float(l.types.stratus)),
    rule("types.stratocumulus", AtLeast(0.0), "", |l| Float(l.types.stratocumulus)),
    rule("types.cumulus", AtLeast(0.0), "", |l| Float(l.types.cumulus)),
    rule("types.cumulonimbus", AtLeast(0.0), "", |l| Float(l.types.cumulonimbus)),
    rule("wind_m_per_s", Finite, "m/s", |l| Floats(&l.wind_m_per_s)),
];

#[rustfmt::skip]
const VOLUME_RULES: &[Rule<VolumeGrid>] = &[
    rule("center_m", Finite, "m", |v| Floats(&v.center_m)),
    rule("size_m", Above(0.0), "m", |v| Floats(&v.size_m)),
    rule("extinction_per_m", Between(0.0, 10.0), "m^-1", |v| Float(v.extinction_per_m)),
];

#[rustfmt::skip]
const SPRITE_CLOUD_RULES: &[Rule<SpriteCloudSpec>] = &[
    rule("center_m", Finite, "m", |c| Floats(&c.center_m)),
    rule("sprites", Between(1.0, 1000.0), "", |c| optional_int(c.sprites)),
    rule("width", Between(0.01, 10.0), "", |c| optional_floats(&c.width)),
    rule("rotation_deg", Between(-180.0, 180.0), "deg", |c| optional_floats(&c.rotation_deg)),
    rule("color_levels", Between(0.0, 4.0), "", |c| Floats(c.color_levels.as_deref().map_or(&[], |l| l.as_flattened()))),
];

#[rustfmt::skip]
const SPRITE_BOX_RULES: &[Rule<SpriteBoxSpec>] = &[
    rule("center_m", Finite, "m", |b| Floats(&b.center_m)),
    rule("size_m", Above(0.0), "m", |b| Floats(&b.size_m)),
];

#[rustfmt::skip]
const SPRITE_CLOUD_RELATIONS: &[Relation<SpriteCloudSpec>] = &[
    Relation { key: "boxes", broken: no_boxes },
    Relation { key: "width", broken: width_range_reversed },
    Relation { key: "color_levels", broken: color_levels_malformed },
];

#[rustfmt::skip]
const CAMERA_KEY_RULES: &[Rule<CameraKey>] = &[
    rule("time_s", Finite, "s", |k| Float(k.time_s)),
    rule("position_m", Finite, "m", |k| Floats(&k.position_m)),
    rule("look_at_m", Finite, "m", |k| optional_floats(&k.look_at_m)),
    rule("yaw_deg", Finite, "deg", |k| Float(k.yaw_deg)),
    rule("pitch_deg", Between(-90.0, 90.0), "deg", |k| Float(k.pitch_deg)),
];

#[rustfmt::skip]
const SUN_KEY_RULES: &[Rule<SunKey>] = &[
    rule("time_s", Finite, "s", |k| Float(k.time_s)),
    rule("sun_elevation_deg", Between(-90.0, 90.0), "deg", |k| optional_float(k.sun_elevation_deg)),
    rule("sun_azimuth_deg", Finite, "deg", |k| optional_float(k.sun_azimuth_deg)),
    rule("solar_time_h", Between(0.0, 24.0), "h", |k| optional_float(k.solar_time_h)),
];

#[rustfmt::skip]
const COVERAGE_KEY_RULES: &[Rule<CoverageKey>] = &[
    rule("time_s", Finite, "s", |k| Float(k.time_s)),
    rule("scale", AtLeast(0.0), "", |k| Float(k.scale)),
];

#[rustfmt::skip]
const CAMERA_PATH: PathRules<CameraKey> = PathRules {
    rules: CAMERA_KEY_RULES,
    relations: &[Relation { key: "look_at_m", broken: key_looks_at_its_eye }],
    pairs: &[
        PairRelation { key: "time_s", broken: time_not_increasing },
        PairRelation { key: "look_at_m", broken: look_at_on_some_keys_only },
    ],
};

#[rustfmt::skip]
const SUN_PATH: PathRules<SunKey> = PathRules {
    rules: SUN_KEY_RULES,
    relations: &[
        Relation { key: "solar_time_h", broken: sun_key_given_both_ways },
        Relation { key: "sun_azimuth_deg", broken: sun_key_has_one_angle },
        Relation { key: "time_s", broken: sun_key_has_no_place },
    ],
    pairs: &[PairRelation { key: "time_s", broken: time_not_increasing }],
};

#[rustfmt::skip]
const COVERAGE_PATH: PathRules<CoverageKey> = PathRules {
    rules: COVERAGE_KEY_RULES,
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
        "a volume needs `path`, a Mitsuba 3 .vol file relative to the scene file".to_string()
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

/// Runs the rules, then the relations, of one item whose keys start with `prefix`.
fn check<T>(
    item: &T,
    prefix: &str,
    rules: &[Rule<T>],
    relations: &[Relation<T>],
) -> Result<(), Violation> {
    for rule in rules {
        rule.check(item, prefix)?;
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

impl<T> Rule<T> {
    fn check(&self, item: &T, prefix: &str) -> Result<(), Violation> {
        let key = format!("{prefix}{}", self.key);
        match (self.read)(item) {
            Field::Float(value) => self.check_number(key, f64::from(value), &value),
            Field::Int(value) => self.check_number(key, f64::from(value), &value),
            Field::Floats(values) => values.iter().enumerate().try_for_each(|(index, value)| {
                self.check_number(format!("{key}.{index}"), f64::from(*value), value)
            }),
            Field::Absent => Ok(()),
        }
    }

    fn check_number(
        &self,
        key: String,
        value: f64,
        shown: &dyn fmt::Display,
    ) -> Result<(), Violation> {
        let problem = if !value.is_finite() {
            "is not a finite number"
        } else if !self.allowed.contains(value) {
            "is out of range"
        } else {
            return Ok(());
        };
        Err(Violation {
            key,
            message: format!(
                "{shown} {problem}; allowed {}",
                self.allowed.describe(self.unit)
            ),
        })
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::scene::model::{Animation, TimeOfDay, VolumeGrid};

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
            path: "cloud.vol".into(),
            ..VolumeGrid::default()
        });
        scene.sprites.ambient_color = Some([0.3, 0.35, 0.45]);
        scene.sprites.directional_color = Some([2.5, 2.4, 2.2]);
        scene.sprites.model = Some("clouds.sprites.toml".into());
        scene.sprite_clouds.push(SpriteCloudSpec {
            cloud_type: crate::sprites::CloudType::CumulusMediocris,
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

    /// Dotted paths of the numeric leaves of a TOML value; array-of-table indices are left out.
    fn numeric_keys(value: &toml::Value, prefix: &str, out: &mut Vec<String>) {
        match value {
            toml::Value::Table(table) => {
                for (key, child) in table {
                    numeric_keys(child, &format!("{prefix}{key}."), out);
                }
            }
            toml::Value::Array(items) if items.iter().all(toml::Value::is_table) => {
                items
                    .iter()
                    .for_each(|item| numeric_keys(item, prefix, out));
            }
            toml::Value::Array(_) | toml::Value::Integer(_) | toml::Value::Float(_) => {
                out.push(prefix.trim_end_matches('.').to_string());
            }
            _ => {}
        }
    }

    /// The keys of `rules`, each after `prefix`.
    fn prefixed<T>(prefix: &str, rules: &[Rule<T>]) -> Vec<String> {
        rules.iter().map(|r| format!("{prefix}{}", r.key)).collect()
    }

    #[test]
    fn every_numeric_field_except_seeds_has_exactly_one_rule() {
        let serialized = toml::Value::try_from(fully_populated()).unwrap();
        let mut fields = Vec::new();
        numeric_keys(&serialized, "", &mut fields);
        fields.retain(|key| !key.ends_with("seed"));
        fields.sort();
        fields.dedup();
        let mut ruled: Vec<String> = [
            prefixed("", SCENE_RULES),
            prefixed("layers.", LAYER_RULES),
            prefixed("volumes.", VOLUME_RULES),
            prefixed("sprite_clouds.", SPRITE_CLOUD_RULES),
            prefixed("sprite_clouds.boxes.", SPRITE_BOX_RULES),
            prefixed("animation.camera_path.", CAMERA_KEY_RULES),
            prefixed("animation.time_of_day.", SUN_KEY_RULES),
            prefixed("animation.coverage_scale.", COVERAGE_KEY_RULES),
        ]
        .concat();
        ruled.sort();
        assert_eq!(ruled, fields);
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
