//! The knob tables: one per table type of the scene file, in the order of its fields. A knob's
//! range and unit are written here and nowhere else; its description is its field's doc comment.

use super::Allowed::{Above, AtLeast, Between, Finite, Listed};
use super::{Knob, knob};
use crate::scene::model::{
    CameraKey, CloudLayer, CoverageKey, Scene, SpriteBoxSpec, SpriteCloudSpec, SunKey, TimeOfDay,
    VolumeGrid,
};

/// Every knob of the scene outside its lists (layers, volumes, sprite clouds, animation).
#[rustfmt::skip]
pub const SCENE: &[Knob<Scene>] = &[
    knob!(Scene, camera.position_m, Finite, "m"),
    knob!(Scene, camera.look_at_m, Finite, "m"),
    knob!(Scene, camera.yaw_deg, Finite, "deg"),
    knob!(Scene, camera.pitch_deg, Between(-90.0, 90.0), "deg"),
    knob!(Scene, camera.fov_y_deg, Between(1.0, 179.0), "deg"),
    knob!(Scene, camera.near_m, Above(0.0), "m"),
    knob!(Scene, camera.far_m, Above(0.0), "m"),
    knob!(Scene, sun.elevation_deg, Between(-90.0, 90.0), "deg"),
    knob!(Scene, sun.azimuth_deg, Finite, "deg"),
    knob!(Scene, sun.irradiance, AtLeast(0.0), ""),
    knob!(Scene, sun.color, Between(0.0, 1.0), ""),
    knob!(Scene, sun.angular_radius_deg, Between(0.0, 5.0), "deg"),
    knob!(Scene, sky.model, Listed, ""),
    knob!(Scene, sky.radiance, AtLeast(0.0), ""),
    knob!(Scene, sky.zenith_radiance, AtLeast(0.0), ""),
    knob!(Scene, sky.horizon_radiance, AtLeast(0.0), ""),
    knob!(Scene, sky.gradient_exponent, Between(0.05, 10.0), ""),
    knob!(Scene, sky.visibility_m, Between(100.0, 1.0e7), "m"),
    knob!(Scene, shadow.resolution, Between(16.0, 4096.0), "texels"),
    knob!(Scene, shadow.steps, Between(4.0, 256.0), ""),
    knob!(Scene, shadow.warp, Between(0.05, 1.0), ""),
    knob!(Scene, ground.enabled, Listed, ""),
    knob!(Scene, ground.albedo, Between(0.0, 1.0), ""),
    knob!(Scene, planet.shape, Listed, ""),
    knob!(Scene, planet.radius_m, Between(1.0e3, 1.0e8), "m"),
    knob!(Scene, weather.source, Listed, ""),
    knob!(Scene, weather.seed, AtLeast(0.0), ""),
    knob!(Scene, weather.extent_km, Between(0.1, 1.0e4), "km"),
    knob!(Scene, weather.resolution, Between(8.0, 4096.0), "texels"),
    knob!(Scene, weather.feature_size_km, Above(0.0), "km"),
    knob!(Scene, noise.seed, AtLeast(0.0), ""),
    knob!(Scene, noise.base_period_m, Above(0.0), "m"),
    knob!(Scene, noise.detail_period_m, Above(0.0), "m"),
    knob!(Scene, noise.detail_erosion, Between(0.0, 1.0), ""),
    knob!(Scene, noise.curl_displacement_m, AtLeast(0.0), "m"),
    knob!(Scene, phase.model, Listed, ""),
    knob!(Scene, phase.droplet_diameter_um, Between(5.0, 50.0), "um"),
    knob!(Scene, phase.g, Between(-0.99, 0.99), ""),
    knob!(Scene, phase.g_forward, Between(-0.99, 0.99), ""),
    knob!(Scene, phase.g_back, Between(-0.99, 0.99), ""),
    knob!(Scene, phase.forward_weight, Between(0.0, 1.0), ""),
    knob!(Scene, lighting.albedo, Between(0.0, 1.0), ""),
    knob!(Scene, lighting.model, Listed, ""),
    knob!(Scene, lighting.slab_diffuse_scale, Between(0.0, 4.0), ""),
    knob!(Scene, lighting.slab_back_scale, Between(0.0, 4.0), ""),
    knob!(Scene, lighting.octaves, Between(1.0, 8.0), ""),
    knob!(Scene, lighting.octave_attenuation, Between(0.0, 1.0), ""),
    knob!(Scene, lighting.octave_contribution, Between(0.0, 1.0), ""),
    knob!(Scene, lighting.octave_eccentricity, Between(0.0, 1.0), ""),
    knob!(Scene, lighting.ambient_scale, Between(0.0, 4.0), ""),
    knob!(Scene, lighting.volume_cells_horizontal, Between(8.0, 256.0), ""),
    knob!(Scene, lighting.volume_cells_vertical, Between(4.0, 64.0), ""),
    knob!(Scene, lighting.volume_extent_m, Between(500.0, 200000.0), "m"),
    knob!(Scene, lighting.volume_cascades, Between(1.0, 4.0), ""),
    knob!(Scene, lighting.volume_sweeps, Between(1.0, 256.0), ""),
    knob!(Scene, lighting.volume_warm_sweeps, Between(0.0, 64.0), ""),
    knob!(Scene, lighting.volume_beam_steps, Between(4.0, 64.0), ""),
    knob!(Scene, particles.style, Listed, ""),
    knob!(Scene, particles.radius_m, Between(10.0, 5000.0), "m"),
    knob!(Scene, particles.table_resolution, Listed, ""),
    knob!(Scene, particles.rings, Between(1.0, 8.0), ""),
    knob!(Scene, particles.ring_cells, Between(16.0, 512.0), ""),
    knob!(Scene, particles.cell_layers, Between(0.0, 16.0), ""),
    knob!(Scene, particles.distance_m, Between(1.0e3, 1.0e6), "m"),
    knob!(Scene, particles.blending, Listed, ""),
    knob!(Scene, particles.resolution_divisor, Between(1.0, 4.0), ""),
    knob!(Scene, particles.occlusion, Listed, ""),
    knob!(Scene, particles.occlusion_early_exit, Listed, ""),
    knob!(Scene, sprites.field_clouds, Listed, ""),
    knob!(Scene, sprites.cloud_size_m, Between(200.0, 20_000.0), "m"),
    knob!(Scene, sprites.distance_m, Between(1.0e3, 5.0e5), "m"),
    knob!(Scene, sprites.ring_radius_m, Between(0.0, 2.0e5), "m"),
    knob!(Scene, sprites.impostor_texels, Between(64.0, 2048.0), ""),
    knob!(Scene, sprites.lod, Listed, ""),
    knob!(Scene, sprites.lock_distance_m, Between(0.0, 5000.0), "m"),
    knob!(Scene, sprites.ambient_color, AtLeast(0.0), ""),
    knob!(Scene, sprites.directional_color, AtLeast(0.0), ""),
    knob!(Scene, render.width, AtLeast(1.0), "px"),
    knob!(Scene, render.height, AtLeast(1.0), "px"),
    knob!(Scene, render.technique, Listed, ""),
    knob!(Scene, render.quality, Listed, ""),
    knob!(Scene, render.primary_steps, Between(1.0, 4096.0), ""),
    knob!(Scene, render.light_steps, Between(1.0, 64.0), ""),
    knob!(Scene, render.samples_per_pixel, Between(1.0, 1024.0), ""),
    knob!(Scene, render.empty_space_skipping, Listed, ""),
    knob!(Scene, render.exposure_ev, Between(-20.0, 20.0), "EV"),
    knob!(Scene, render.tonemap, Listed, ""),
    knob!(Scene, render.time_s, Finite, "s"),
];

/// The knobs of each cloud layer (`layers.N.`).
#[rustfmt::skip]
pub const LAYER: &[Knob<CloudLayer>] = &[
    knob!(CloudLayer, bottom_m, AtLeast(0.0), "m"),
    knob!(CloudLayer, thickness_m, Between(10.0, 20_000.0), "m"),
    knob!(CloudLayer, coverage, Between(0.0, 1.0), ""),
    knob!(CloudLayer, extinction_per_m, Between(0.0, 1.0), "m^-1"),
    knob!(CloudLayer, types.stratus, AtLeast(0.0), ""),
    knob!(CloudLayer, types.stratocumulus, AtLeast(0.0), ""),
    knob!(CloudLayer, types.cumulus, AtLeast(0.0), ""),
    knob!(CloudLayer, types.cumulonimbus, AtLeast(0.0), ""),
    knob!(CloudLayer, wind_m_per_s, Finite, "m/s"),
    knob!(CloudLayer, noise_seed, AtLeast(0.0), ""),
];

/// The knobs of `sun.time_of_day`, when it is set.
#[rustfmt::skip]
pub const TIME_OF_DAY: &[Knob<TimeOfDay>] = &[
    knob!(TimeOfDay, solar_time_h, Between(0.0, 24.0), "h"),
    knob!(TimeOfDay, latitude_deg, Between(-90.0, 90.0), "deg"),
    knob!(TimeOfDay, day_of_year, Between(1.0, 366.0), ""),
];

/// The knobs of each density grid (`volumes.N.`).
#[rustfmt::skip]
pub const VOLUME: &[Knob<VolumeGrid>] = &[
    knob!(VolumeGrid, center_m, Finite, "m"),
    knob!(VolumeGrid, size_m, Above(0.0), "m"),
    knob!(VolumeGrid, extinction_per_m, Between(0.0, 10.0), "m^-1"),
    knob!(VolumeGrid, sanitize, Listed, ""),
];

/// The knobs of each hand-made sprite cloud (`sprite_clouds.N.`).
#[rustfmt::skip]
pub const SPRITE_CLOUD: &[Knob<SpriteCloudSpec>] = &[
    knob!(SpriteCloudSpec, center_m, Finite, "m"),
    knob!(SpriteCloudSpec, seed, AtLeast(0.0), ""),
    knob!(SpriteCloudSpec, sprites, Between(1.0, 1000.0), ""),
    knob!(SpriteCloudSpec, width, Between(0.01, 10.0), ""),
    knob!(SpriteCloudSpec, rotation_deg, Between(-180.0, 180.0), "deg"),
    knob!(SpriteCloudSpec, color_levels, Between(0.0, 4.0), ""),
];

/// The knobs of each box of a hand-made sprite cloud (`sprite_clouds.N.boxes.M.`).
#[rustfmt::skip]
pub const SPRITE_BOX: &[Knob<SpriteBoxSpec>] = &[
    knob!(SpriteBoxSpec, center_m, Finite, "m"),
    knob!(SpriteBoxSpec, size_m, Above(0.0), "m"),
];

/// The knobs of each camera keyframe (`animation.camera_path.N.`).
#[rustfmt::skip]
pub const CAMERA_KEY: &[Knob<CameraKey>] = &[
    knob!(CameraKey, time_s, Finite, "s"),
    knob!(CameraKey, position_m, Finite, "m"),
    knob!(CameraKey, look_at_m, Finite, "m"),
    knob!(CameraKey, yaw_deg, Finite, "deg"),
    knob!(CameraKey, pitch_deg, Between(-90.0, 90.0), "deg"),
];

/// The knobs of each sun keyframe (`animation.time_of_day.N.`).
#[rustfmt::skip]
pub const SUN_KEY: &[Knob<SunKey>] = &[
    knob!(SunKey, time_s, Finite, "s"),
    knob!(SunKey, sun_elevation_deg, Between(-90.0, 90.0), "deg"),
    knob!(SunKey, sun_azimuth_deg, Finite, "deg"),
    knob!(SunKey, solar_time_h, Between(0.0, 24.0), "h"),
];

/// The knobs of each coverage keyframe (`animation.coverage_scale.N.`).
#[rustfmt::skip]
pub const COVERAGE_KEY: &[Knob<CoverageKey>] = &[
    knob!(CoverageKey, time_s, Finite, "s"),
    knob!(CoverageKey, scale, AtLeast(0.0), ""),
];
