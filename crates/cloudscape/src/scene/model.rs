//! The scene data model: everything a render needs, in physical units.
//!
//! Coordinates: right-handed, metres, `y` up, `x` east, `z` south (so north is `-z`). Azimuths are
//! measured in degrees clockwise from north (90 = east). With a spherical planet the ground point
//! under the origin is `(0, 0, 0)` and the planet centre is `(0, -radius_m, 0)`.
//!
//! Radiometry: radiance and irradiance share one relative radiometric unit (think W m^-2 sr^-1 and
//! W m^-2, scaled); only ratios matter, and exposure maps them to the display.

use documented::{DocumentedFields, DocumentedVariants};
use serde::{Deserialize, Serialize};

/// A whole scene: camera, light, sky, ground, planet, clouds and render settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields, default)]
pub struct Scene {
    /// Where the eye is and where it looks.
    pub camera: Camera,
    /// The sun: direction, irradiance and colour.
    pub sun: Sun,
    /// Sky light falling on the clouds and seen behind them.
    pub sky: Sky,
    /// The clouds' shadow map.
    pub shadow: Shadow,
    /// The ground below the clouds (the planet surface, or a flat plane).
    pub ground: Ground,
    /// The planet's shape.
    pub planet: Planet,
    /// Cloud layers; an empty list gives a clear sky.
    pub layers: Vec<CloudLayer>,
    /// The 2D weather map that places clouds within every layer.
    pub weather: WeatherMap,
    /// Shape of the procedural 3D noise that builds each cloud.
    pub noise: NoiseSettings,
    /// Density grids loaded from files and placed in the world.
    pub volumes: Vec<VolumeGrid>,
    /// The single-scattering phase function of cloud droplets.
    pub phase: PhaseFunction,
    /// Lighting approximations used by the real-time techniques.
    pub lighting: Lighting,
    /// The reference particle of the particle technique, whose lighting is precomputed.
    pub particles: Particles,
    /// The sprite-cluster technique: field clouds, impostor ring, in-cloud lock, shading.
    pub sprites: Sprites,
    /// Hand-made sprite clouds, built from boxes (drawn by the sprite technique only).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub sprite_clouds: Vec<SpriteCloudSpec>,
    /// Image size, technique, quality, exposure and output.
    pub render: RenderSettings,
    /// Keyframed camera, sun and coverage over scene time; empty (a static scene) by default.
    #[serde(skip_serializing_if = "Animation::is_static")]
    pub animation: Animation,
}

impl Default for Scene {
    fn default() -> Self {
        Scene {
            camera: Camera::default(),
            sun: Sun::default(),
            sky: Sky::default(),
            shadow: Shadow::default(),
            ground: Ground::default(),
            planet: Planet::default(),
            layers: vec![CloudLayer::default()],
            weather: WeatherMap::default(),
            noise: NoiseSettings::default(),
            volumes: Vec::new(),
            phase: PhaseFunction::default(),
            lighting: Lighting::default(),
            particles: Particles::default(),
            sprites: Sprites::default(),
            sprite_clouds: Vec::new(),
            render: RenderSettings::default(),
            animation: Animation::default(),
        }
    }
}

/// A pinhole camera.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields, default)]
pub struct Camera {
    /// Eye position in metres (`y` is altitude above the ground under the origin).
    pub position_m: [f32; 3],
    /// Point looked at, in metres; when absent, `yaw_deg` and `pitch_deg` give the view direction.
    pub look_at_m: Option<[f32; 3]>,
    /// View azimuth in degrees clockwise from north (used without `look_at_m`).
    pub yaw_deg: f32,
    /// View elevation in degrees above the horizon, -90..90 (used without `look_at_m`).
    pub pitch_deg: f32,
    /// Vertical field of view in degrees, 1..179.
    pub fov_y_deg: f32,
    /// Near clip distance in metres (> 0).
    pub near_m: f32,
    /// Far distance in metres: nothing beyond it is marched (> near).
    pub far_m: f32,
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            position_m: [0.0, 30.0, 0.0],
            look_at_m: None,
            yaw_deg: 200.0,
            pitch_deg: 14.0,
            fov_y_deg: 65.0,
            near_m: 0.1,
            far_m: 120_000.0,
        }
    }
}

/// The sun, a distant disc light.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields, default)]
pub struct Sun {
    /// Elevation above the horizon in degrees, -90..90.
    pub elevation_deg: f32,
    /// Azimuth in degrees clockwise from north.
    pub azimuth_deg: f32,
    /// Irradiance on a surface facing the sun, in scene radiometric units (> 0 or 0 for no sun);
    /// above the air with the atmosphere, which reddens it on its way down.
    pub irradiance: f32,
    /// Linear RGB colour multiplying the irradiance, each 0..1.
    pub color: [f32; 3],
    /// Angular radius of the disc in degrees, 0..5; 0.2679 deg is the real sun (Bruneton 2017).
    pub angular_radius_deg: f32,
    /// When set, the sun's place from the local solar time, latitude and day of the year: it sets
    /// `elevation_deg` and `azimuth_deg`, which the file must then leave out.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_of_day: Option<TimeOfDay>,
}

/// A moment and a place on Earth, which put the sun on the sky (see
/// [`super::solar_position`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields)]
pub struct TimeOfDay {
    /// Local solar time in hours, 0..24: 12 is solar noon, when the sun crosses the meridian.
    pub solar_time_h: f32,
    /// Latitude of the place in degrees, -90..90, north positive.
    pub latitude_deg: f32,
    /// Day of the year, 1..366 (1 is 1 January).
    pub day_of_year: u32,
}

impl Default for Sun {
    fn default() -> Self {
        Sun {
            elevation_deg: 30.0,
            azimuth_deg: 215.0,
            irradiance: 8.0,
            color: [1.0, 1.0, 1.0],
            angular_radius_deg: 0.2679,
            time_of_day: None,
        }
    }
}

/// How sky radiance varies with direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, DocumentedVariants)]
#[serde(rename_all = "snake_case")]
pub enum SkyModel {
    /// The same radiance (`sky.radiance`) in every direction.
    Constant,
    /// Horizon radiance blending to zenith radiance with elevation.
    Gradient,
    /// A physically based atmosphere (Rayleigh, Mie, ozone; Hillaire 2020): the sun's colour at
    /// every altitude, the sky and the aerial perspective follow from the sun's place.
    Atmosphere,
}

/// Sky light: the physically based atmosphere, or its simple analytic stand-ins.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields, default)]
pub struct Sky {
    /// Which sky model to use.
    pub model: SkyModel,
    /// Radiance of the constant sky, linear RGB, each >= 0.
    pub radiance: [f32; 3],
    /// Gradient sky: radiance straight up, linear RGB, each >= 0.
    pub zenith_radiance: [f32; 3],
    /// Gradient sky: radiance at the horizon, linear RGB, each >= 0.
    pub horizon_radiance: [f32; 3],
    /// Gradient sky: how fast the horizon colour gives way to the zenith colour, 0.05..10.
    pub gradient_exponent: f32,
    /// Meteorological visibility in metres, 100..10 000 000: the extinction 3.912 / visibility at
    /// the ground (Koschmieder). The atmosphere puts what Rayleigh leaves of it into its aerosol
    /// (Mie) layer; the analytic skies fade distant clouds and ground into the horizon radiance.
    pub visibility_m: f32,
}

impl Default for Sky {
    fn default() -> Self {
        Sky {
            model: SkyModel::Atmosphere,
            radiance: [0.3, 0.3, 0.3],
            zenith_radiance: [0.10, 0.22, 0.52],
            horizon_radiance: [0.42, 0.50, 0.62],
            gradient_exponent: 0.45,
            visibility_m: 80_000.0,
        }
    }
}

/// The clouds' shared shadow map (light-space transmittance), built from the coarse field each
/// frame: it shades the ground, the air's light shafts and a host's geometry. It reaches the
/// camera's far distance around the viewpoint.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields, default)]
pub struct Shadow {
    /// Texels per side of the map, 16..4096.
    pub resolution: u32,
    /// Samples of the coarse field along each column through the clouds, 4..256.
    pub steps: u32,
    /// Texel size under the viewpoint over the mean texel size, 0.05..1 (1: no warp; smaller
    /// gives finer shadows near the eye and coarser far away).
    pub warp: f32,
}

impl Default for Shadow {
    fn default() -> Self {
        Shadow {
            resolution: 256,
            steps: 16,
            warp: 0.25,
        }
    }
}

/// The ground: a Lambertian surface lit by the sun and the sky.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields, default)]
pub struct Ground {
    /// Whether there is a ground at all; without one, rays below the horizon see the sky.
    pub enabled: bool,
    /// Lambertian albedo, linear RGB, each 0..1.
    pub albedo: [f32; 3],
}

impl Default for Ground {
    fn default() -> Self {
        Ground {
            enabled: true,
            albedo: [0.12, 0.13, 0.10],
        }
    }
}

/// The planet's shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, DocumentedVariants)]
#[serde(rename_all = "snake_case")]
pub enum PlanetShape {
    /// A sphere of `radius_m`: layers follow its curvature and sink below the horizon.
    Spherical,
    /// An infinite plane at `y = 0`.
    Flat,
}

/// The planet under the clouds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields, default)]
pub struct Planet {
    /// Spherical or flat.
    pub shape: PlanetShape,
    /// Radius in metres of the spherical planet, 1 km..100 000 km; Earth is 6 360 km (Bruneton 2017).
    pub radius_m: f32,
}

impl Default for Planet {
    fn default() -> Self {
        Planet {
            shape: PlanetShape::Spherical,
            radius_m: 6_360_000.0,
        }
    }
}

/// Relative amounts of the four canonical cloud types in a layer; at least one must be positive.
/// The weather map's type channel picks among them (see [`crate::field`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields, default)]
pub struct CloudTypeMix {
    /// Weight of stratus: a thin flat sheet near the layer bottom, >= 0.
    pub stratus: f32,
    /// Weight of stratocumulus: lumpy, filling the lower half of the layer, >= 0.
    pub stratocumulus: f32,
    /// Weight of cumulus: rounded towers filling most of the layer, >= 0.
    pub cumulus: f32,
    /// Weight of cumulonimbus: the full layer with an anvil at the top, >= 0.
    pub cumulonimbus: f32,
}

impl Default for CloudTypeMix {
    /// All zero: a table that names some types leaves the others out.
    fn default() -> Self {
        CloudTypeMix {
            stratus: 0.0,
            stratocumulus: 0.0,
            cumulus: 0.0,
            cumulonimbus: 0.0,
        }
    }
}

/// Density-height gradients of the four types of a [`CloudTypeMix`] (the anchor types of the cloud
/// field's type axis, `field::profile`) as (rise start, rise end, fall start, fall end),
/// fractions of the layer thickness. Stratus and stratocumulus are VolumeCloud's fallback gradients
/// (peers.md, from yangrc1234/VolumeCloud). Cumulus rises as fast as VolumeCloud's but thins from 20 %
/// of the layer to its top instead of holding full density to 75 %: thresholded by coverage, a long
/// linear fall gives domed tops where a plateau gives flat-topped slabs (tuned by eye on the default
/// scene). Cumulonimbus fills the layer like Schneider 2015's towering type.
pub const TYPE_GRADIENTS: [[f32; 4]; 4] = [
    [0.0, 0.07, 0.08, 0.15],
    [0.0, 0.2, 0.42, 0.6],
    [0.0, 0.1, 0.2, 1.0],
    [0.0, 0.05, 0.9, 1.0],
];

fn cumulus_only() -> CloudTypeMix {
    CloudTypeMix {
        cumulus: 1.0,
        ..CloudTypeMix::default()
    }
}

/// Most cloud layers a scene can draw: one cloud field holds at most this many (the GPU uniform's
/// array size).
pub const MAX_LAYERS: usize = 4;

/// One layer of clouds between two altitudes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields, default)]
pub struct CloudLayer {
    /// Altitude of the layer bottom above the ground, metres, >= 0.
    pub bottom_m: f32,
    /// Thickness of the layer, metres, 10..20 000.
    pub thickness_m: f32,
    /// Cloud cover, 0..1: the fraction of the sky the layer covers (calibrated on cumulus); 0 clears
    /// the layer, 1 fills it.
    pub coverage: f32,
    /// Extinction coefficient of the densest cloud, m^-1, 0..1 (cumulus 0.04-0.1, physics.md).
    pub extinction_per_m: f32,
    /// Mix of cloud types.
    #[serde(default = "cumulus_only")]
    pub types: CloudTypeMix,
    /// Wind velocity in m/s as `[east, south]`: moves the weather map and the noise.
    pub wind_m_per_s: [f32; 2],
    /// Seed that shifts this layer's noise and weather so layers do not repeat each other.
    pub noise_seed: u32,
}

impl Default for CloudLayer {
    fn default() -> Self {
        CloudLayer {
            bottom_m: 1500.0,
            thickness_m: 2200.0,
            coverage: 0.45,
            extinction_per_m: 0.05,
            types: cumulus_only(),
            wind_m_per_s: [8.0, 3.0],
            noise_seed: 1,
        }
    }
}

/// Where the weather map comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, DocumentedVariants)]
#[serde(rename_all = "snake_case")]
pub enum WeatherSource {
    /// Generated from `seed`.
    Procedural,
    /// Read from the PNG at `path`: R coverage, G type (position in the layer's type mix), B density.
    File,
}

/// The 2D weather map: per position, cloud coverage, cloud type and density. It repeats every
/// `extent_km` in both directions.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields, default)]
pub struct WeatherMap {
    /// Procedural or from a file.
    pub source: WeatherSource,
    /// Seed of the procedural map.
    pub seed: u32,
    /// Side of the square area the map covers before repeating, km, 0.1..10 000.
    pub extent_km: f32,
    /// Texels per side of the procedural map, 8..4096.
    pub resolution: u32,
    /// Typical size of a cloudy region in the procedural map, km, > 0.
    pub feature_size_km: f32,
    /// PNG file for `source = "file"`, relative to the scene file.
    pub path: Option<String>,
    /// A METAR weather report (WMO FM 15) that builds the scene's cloud layers and haze (see
    /// [`crate::scene::metar`]); the file must then give no `layers` and no `sky.visibility_m`.
    pub metar: Option<String>,
}

impl Default for WeatherMap {
    fn default() -> Self {
        WeatherMap {
            source: WeatherSource::Procedural,
            seed: 7,
            extent_km: 64.0,
            resolution: 512,
            feature_size_km: 6.0,
            path: None,
            metar: None,
        }
    }
}

/// The 3D noise that gives clouds their shape (Schneider 2015, Horizon Zero Dawn).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields, default)]
pub struct NoiseSettings {
    /// Seed of the noise textures.
    pub seed: u32,
    /// World size of one tile of the 128^3 Perlin-Worley base noise, metres, > 0.
    pub base_period_m: f32,
    /// World size of one tile of the 32^3 Worley detail noise, metres, > 0.
    pub detail_period_m: f32,
    /// How much the detail noise erodes cloud edges, 0..1.
    pub detail_erosion: f32,
    /// How far the curl noise displaces the detail noise, metres, >= 0.
    pub curl_displacement_m: f32,
}

impl Default for NoiseSettings {
    fn default() -> Self {
        NoiseSettings {
            seed: 3,
            base_period_m: 9000.0,
            detail_period_m: 700.0,
            detail_erosion: 0.4,
            curl_displacement_m: 120.0,
        }
    }
}

/// A density grid from a file, placed in an axis-aligned box in the world.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields, default)]
pub struct VolumeGrid {
    /// A Mitsuba 3 `.vol` file or an OpenVDB `.vdb` file, relative to the scene file.
    pub path: String,
    /// The grid of a `.vdb` file to draw, by name; unset: its first float grid.
    pub grid: Option<String>,
    /// Centre of the box, metres; unset: where a `.vdb` grid's transform puts its active voxels,
    /// [0, 2500, -6000] for a `.vol` file.
    pub center_m: Option<[f32; 3]>,
    /// Size of the box along x, y, z, metres, each > 0; unset: a `.vdb` grid's active voxels
    /// times its voxel size, 2000 m a side for a `.vol` file.
    pub size_m: Option<[f32; 3]>,
    /// Extinction in m^-1 where the grid value is 1, 0..10.
    pub extinction_per_m: f32,
    /// Replace the file's values that are not densities (NaN and negative by 0, above 65504 by
    /// 65504) instead of refusing the file; off by default.
    pub sanitize: bool,
}

impl Default for VolumeGrid {
    fn default() -> Self {
        VolumeGrid {
            path: String::new(),
            grid: None,
            center_m: None,
            size_m: None,
            extinction_per_m: 0.05,
            sanitize: false,
        }
    }
}

/// Which phase function scatters light in the cloud.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, DocumentedVariants)]
#[serde(rename_all = "snake_case")]
pub enum PhaseModel {
    /// Approximate Mie for water droplets (Jendersie & d'Eon 2023), from `droplet_diameter_um`.
    Mie,
    /// Henyey-Greenstein with asymmetry `g`.
    Hg,
    /// `forward_weight * HG(g_forward) + (1 - forward_weight) * HG(g_back)`.
    DualHg,
}

/// The phase function and its parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields, default)]
pub struct PhaseFunction {
    /// Which model.
    pub model: PhaseModel,
    /// Approximate Mie: effective droplet diameter in micrometres, 5..50.
    pub droplet_diameter_um: f32,
    /// Henyey-Greenstein asymmetry, -0.99..0.99.
    pub g: f32,
    /// Dual-lobe HG: forward lobe asymmetry, -0.99..0.99.
    pub g_forward: f32,
    /// Dual-lobe HG: backward lobe asymmetry, -0.99..0.99.
    pub g_back: f32,
    /// Dual-lobe HG: weight of the forward lobe, 0..1.
    pub forward_weight: f32,
}

impl Default for PhaseFunction {
    fn default() -> Self {
        PhaseFunction {
            model: PhaseModel::Mie,
            droplet_diameter_um: 20.0,
            g: 0.8,
            g_forward: 0.8,
            g_back: -0.3,
            forward_weight: 0.7,
        }
    }
}

impl crate::optics::PhaseLobes {
    /// The lobes of a scene's phase-function settings.
    pub fn from_scene(p: &PhaseFunction) -> Self {
        match p.model {
            PhaseModel::Mie => Self::approximate_mie(p.droplet_diameter_um),
            PhaseModel::Hg => Self::henyey_greenstein(p.g),
            PhaseModel::DualHg => {
                Self::dual_henyey_greenstein(p.g_forward, p.g_back, p.forward_weight)
            }
        }
    }
}

/// How the ray marcher models the sun's light scattered more than once in the clouds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, DocumentedVariants)]
#[serde(rename_all = "snake_case")]
pub enum LightingModel {
    /// The light volume: the δ-Eddington equations solved in 3-D on grids that follow the camera
    /// (`environment::light_volume`), read for the diffuse light; single scattering and the
    /// forward peak per sample as with the slab.
    Volume,
    /// The δ-Eddington solution of a slab along the sun, from the optical depths toward the sun
    /// and away from it (`optics::slab`).
    Slab,
    /// Multiple-scattering octaves (Wrenninge 2013), from the optical depth toward the sun.
    Octaves,
}

/// Lighting approximations of the real-time techniques (the path tracer needs none of them).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields, default)]
pub struct Lighting {
    /// Single-scattering albedo sigma_s / sigma_t, 0..1; cloud droplets are about 1 (physics.md).
    pub albedo: f32,
    /// The ray marcher's model of the sun's multiply scattered light.
    pub model: LightingModel,
    /// Slab model: scale of its diffuse light, 0..4; below 1 a finite cloud loses light through
    /// its sides that the infinite slab keeps. The default is fitted to the path tracer on
    /// generated scenes (`cloudscape fit-lighting --scenes 16 --validation 6 --points 300
    /// --paths 256`, docs/lighting.md).
    pub slab_diffuse_scale: f32,
    /// Slab model: factor of the optical depth to the far side of the layers, 0..4; fitted with
    /// `slab_diffuse_scale`.
    pub slab_back_scale: f32,
    /// Multiple-scattering octaves (Wrenninge 2013), 1..8; 1 is single scattering only.
    pub octaves: u32,
    /// Octave extinction factor `a`, 0..1: each octave sees `a^i` of the optical depth to the sun.
    pub octave_attenuation: f32,
    /// Octave scattering factor `b`, 0..1: octave `i` scatters `b^i` of the light. Wrenninge 2013
    /// keeps it at most the extinction factor; the default is larger, tuned against the path
    /// tracer (`docs/realism.md`), and still below the light a thick cloud reflects: lit at normal
    /// incidence and seen along its normal, with isotropic octave phases, the defaults give
    /// `0.16 E` where a semi-infinite conservative medium gives `0.34 E` (Chandrasekhar 1960,
    /// "Radiative Transfer", H(1) = 2.908).
    pub octave_contribution: f32,
    /// Octave eccentricity factor `c`, 0..1: each octave's phase anisotropy is scaled by `c^i`.
    pub octave_eccentricity: f32,
    /// Slab and octave models: scale of the light scattered from the sky and the ground into the
    /// cloud, 0..4.
    pub ambient_scale: f32,
    /// Light volume: cells of each cascade along x and z, 8..256.
    pub volume_cells_horizontal: u32,
    /// Light volume: cells through the clouds' heights, 4..64.
    pub volume_cells_vertical: u32,
    /// Light volume: half width of the finest cascade, metres; each next one reaches 4 times as
    /// far.
    pub volume_extent_m: f32,
    /// Light volume: cascades, 1..4.
    pub volume_cascades: u32,
    /// Light volume: relaxation sweeps when the grid is new or has moved, 1..256.
    pub volume_sweeps: u32,
    /// Light volume: sweeps a turn gives the one cascade it solves while the grid stays put
    /// (warm-started from the last solution; the cascades take turns of three frames: the
    /// cells, the sweeps, the table), 0..64.
    pub volume_warm_sweeps: u32,
    /// Light volume: samples of the coarse field toward the sun per cell, 4..64.
    pub volume_beam_steps: u32,
}

impl Scene {
    /// The slab model of the scene's lighting and phase function: what every technique's sun beam
    /// (the forward peak) and the light volume's optics follow.
    pub fn sun_slab(&self) -> crate::optics::SunSlab {
        self.lighting
            .sun_slab(crate::optics::PhaseLobes::from_scene(&self.phase))
    }
}

impl Lighting {
    /// The slab model these settings describe for `lobes`.
    pub fn sun_slab(&self, lobes: crate::optics::PhaseLobes) -> crate::optics::SunSlab {
        crate::optics::SunSlab::new(
            lobes,
            self.albedo,
            self.slab_diffuse_scale,
            self.slab_back_scale,
        )
    }

    /// The multiple-scattering octaves these settings describe.
    pub fn octaves(&self) -> crate::optics::Octaves {
        crate::optics::Octaves {
            count: self.octaves,
            attenuation: self.octave_attenuation,
            contribution: self.octave_contribution,
            eccentricity: self.octave_eccentricity,
        }
    }
}

impl Default for Lighting {
    fn default() -> Self {
        Lighting {
            albedo: 1.0,
            model: LightingModel::Volume,
            slab_diffuse_scale: 0.613,
            slab_back_scale: 1.422,
            octaves: 6,
            octave_attenuation: 0.5,
            octave_contribution: 0.7,
            octave_eccentricity: 0.7,
            ambient_scale: 1.0,
            volume_cells_horizontal: 48,
            volume_cells_vertical: 24,
            volume_extent_m: 8000.0,
            volume_cascades: 2,
            volume_sweeps: 32,
            volume_warm_sweeps: 1,
            volume_beam_steps: 24,
        }
    }
}

/// How 3D noise shapes the reference particle (Yusov 2014, "Pre-computing optical depth: 3D noise
/// generation").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, DocumentedVariants)]
#[serde(rename_all = "snake_case")]
pub enum ParticleStyle {
    /// A smooth radial falloff whose density the noise modulates.
    Smooth,
    /// The noisy falloff thresholded: a denser core with crisp, lumpy edges.
    Thresholded,
    /// A sphere whose surface the noise displaces radially: billowing, cauliflower-like.
    Pyroclastic,
}

impl ParticleStyle {
    /// The index the shaders switch on (`PARTICLE_SMOOTH`, ... in `particle.wgsl`).
    pub fn gpu_index(self) -> u32 {
        match self {
            ParticleStyle::Smooth => 0,
            ParticleStyle::Thresholded => 1,
            ParticleStyle::Pyroclastic => 2,
        }
    }
}

/// The reference particle of the particle technique (Yusov 2014): its lighting is precomputed
/// once, for this particle, into look-up tables (`cloudscape bake`). Its peak extinction is the
/// largest `extinction_per_m` of the layers (0.05 m^-1 without layers), its phase function and
/// albedo those of the scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields, default)]
pub struct Particles {
    /// How 3D noise shapes the particle.
    pub style: ParticleStyle,
    /// Radius of the reference particle, m, 10..5000 (Yusov's sample: 200 m).
    pub radius_m: f32,
    /// How finely the tables are sampled.
    pub table_resolution: TableResolution,
    /// Concentric rings of the camera-centred cell grid, 1..8 (Yusov's sample: 5); each ring's
    /// cells are twice the size of the inner ring's.
    pub rings: u32,
    /// Cells along each side of a ring, even, 16..512 (Yusov: 136, the inner 128 plus 4 on each
    /// side); rings past the first skip their centre.
    pub ring_cells: u32,
    /// Particles stacked in each cell across the layer band, 0..16 (Yusov: 4 over 700 m); 0 stacks
    /// as many as make the inner ring's cells about as tall as they are wide.
    pub cell_layers: u32,
    /// Reach of the cell grid from the camera, m, 1000..1e6 (Yusov: 200 km); it sets the cell size.
    pub distance_m: f32,
    /// How overlapping particles are blended.
    pub blending: ParticleBlending,
    /// Particles render at 1/divisor of the image resolution: 1, 2 or 4 (Yusov: 2).
    pub resolution_divisor: u32,
    /// How each particle finds the light the clouds between it and the sun take away.
    pub occlusion: ParticleOcclusion,
    /// Stop each particle's march or walk toward the sun once its light is below 1 % (Yusov's
    /// early exit); off only to measure what it saves.
    pub occlusion_early_exit: bool,
}

/// How the particle technique occludes each particle's sunlight (Yusov 2014, "Light occlusion").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, DocumentedVariants)]
#[serde(rename_all = "snake_case")]
pub enum ParticleOcclusion {
    /// The seed's method: the particles binned from the sun into light-space tiles, each tile's
    /// list sorted in light order, each particle walking its tile's list up to its own place.
    Tiles,
    /// Yusov's released code: a coarse march through the field toward the sun.
    March,
}

/// How the particle technique blends particles that overlap along a view ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, DocumentedVariants)]
#[serde(rename_all = "snake_case")]
pub enum ParticleBlending {
    /// Yusov 2014's volume-aware blending: overlapping particles merge as one volume.
    VolumeAware,
    /// Conventional alpha blending in distance order, for comparison.
    Alpha,
}

/// How finely the particle tables are sampled (sizes in `particles::ParticleTableSpec`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, DocumentedVariants)]
#[serde(rename_all = "snake_case")]
pub enum TableResolution {
    /// A quarter of the standard entries: quick previews and tests.
    Low,
    /// The seed's sizes.
    Standard,
    /// Four times the standard entries: stills, and fast GPUs.
    High,
}

impl Default for Particles {
    fn default() -> Self {
        Particles {
            style: ParticleStyle::Smooth,
            radius_m: 200.0,
            table_resolution: TableResolution::Standard,
            rings: 5,
            ring_cells: 136,
            cell_layers: 0,
            distance_m: 200_000.0,
            blending: ParticleBlending::VolumeAware,
            resolution_divisor: 2,
            occlusion: ParticleOcclusion::Tiles,
            occlusion_early_exit: true,
        }
    }
}

/// The sprite-cluster technique (Wang 2003, "Realistic and Fast Cloud Rendering in Computer
/// Games", Microsoft Flight Simulator): clouds of 5-50 textured sprites, from the cloud field and
/// from hand-made boxes, with an octagonal ring of impostors for the distance.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields, default)]
pub struct Sprites {
    /// Build sprite clouds from the cloud field's layers (off: only `sprite_clouds` and `model`).
    pub field_clouds: bool,
    /// Side of the wind-borne tiles a field cloud fills, m, 200..20000: the largest a field cloud
    /// gets.
    pub cloud_size_m: f32,
    /// Field clouds are made out to this horizontal distance from the camera, m, 1000..500000;
    /// they fade out over its last fifth.
    pub distance_m: f32,
    /// Radius of the octagonal impostor ring, m, 0..200000 (Wang: a user setting; smaller is
    /// faster with more anomalies); clouds beyond it are drawn into 8 impostors. 0: no ring.
    pub ring_radius_m: f32,
    /// Texels along each impostor's width, 64..2048.
    pub impostor_texels: u32,
    /// Level of detail: every sprite of each cloud, or one billboard per cloud (Wang's fallback).
    pub lod: SpriteLod,
    /// Sprites nearer the eye than this turn to face along the view, not toward the eye, so they
    /// do not part as the camera flies through (Wang's lock), m, 0..5000.
    pub lock_distance_m: f32,
    /// Replaces the maximum ambient colour (by default the sky's mean radiance times the albedo).
    pub ambient_color: Option<[f32; 3]>,
    /// Replaces the maximum directional colour (by default the sun's irradiance times the
    /// albedo over pi).
    pub directional_color: Option<[f32; 3]>,
    /// A sprite model file (`cloudscape export --sprites` writes one) whose clouds are drawn too,
    /// relative to the scene file.
    pub model: Option<String>,
}

impl Default for Sprites {
    fn default() -> Self {
        Sprites {
            field_clouds: true,
            cloud_size_m: 1500.0,
            distance_m: 40_000.0,
            ring_radius_m: 12_000.0,
            impostor_texels: 512,
            lod: SpriteLod::Clusters,
            lock_distance_m: 150.0,
            ambient_color: None,
            directional_color: None,
            model: None,
        }
    }
}

/// How much of each sprite cloud is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, DocumentedVariants)]
#[serde(rename_all = "snake_case")]
pub enum SpriteLod {
    /// Every sprite of every cloud.
    Clusters,
    /// One billboard per cloud (Wang 2003's fallback for slow machines).
    Billboards,
}

/// A cloud type of the sprite technique.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CloudType {
    /// Small, flat fair-weather puffs (cumulus fractus).
    FairWeather,
    /// Cumulus humilis: wider than tall.
    CumulusHumilis,
    /// Cumulus mediocris: about as tall as wide.
    CumulusMediocris,
    /// Cumulus congestus: towering, taller than wide.
    CumulusCongestus,
    /// Cumulonimbus: a tower to the layer top with a spreading anvil.
    Cumulonimbus,
    /// Stratocumulus: broad, lumpy rolls.
    Stratocumulus,
    /// Stratus: a flat, blurry sheet.
    Stratus,
    /// Altocumulus: small lumpy cloudlets high up.
    Altocumulus,
    /// Altostratus: a thin, wispy high sheet.
    Altostratus,
    /// Nimbostratus: a thick, dark, blurry deck.
    Nimbostratus,
}

/// A hand-made sprite cloud (Wang 2003, "Cloud creation": an artist builds the shape from boxes,
/// and a script fills them with sprites). Unset artist parameters come from the type's recipe.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields)]
pub struct SpriteCloudSpec {
    /// The cloud type: `fair_weather`, `cumulus_humilis`, `cumulus_mediocris`,
    /// `cumulus_congestus`, `cumulonimbus`, `stratocumulus`, `stratus`, `altocumulus`,
    /// `altostratus` or `nimbostratus`.
    #[serde(rename = "type")]
    pub cloud_type: CloudType,
    /// Centre of the cloud, m.
    pub center_m: [f32; 3],
    /// The boxes, relative to the centre; at least one.
    pub boxes: Vec<SpriteBoxSpec>,
    /// Seed of the sprite placement.
    #[serde(default)]
    pub seed: u32,
    /// Candidate sprites before culling, 1..1000 (the type's by default).
    #[serde(default)]
    pub sprites: Option<u32>,
    /// Sprite width range as fractions of the cloud's height, each 0.01..10.
    #[serde(default)]
    pub width: Option<[f32; 2]>,
    /// Sprite rotation range, degrees, each -180..180.
    #[serde(default)]
    pub rotation_deg: Option<[f32; 2]>,
    /// Five colour levels `[height 0..1, r, g, b, a]` from the bottom up (derived from physics
    /// by default); rgb 0..4, a 0..1.
    #[serde(default)]
    pub color_levels: Option<Vec<[f32; 5]>>,
}

/// One box of a hand-made sprite cloud.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields)]
pub struct SpriteBoxSpec {
    /// Centre of the box relative to the cloud's centre, m.
    pub center_m: [f32; 3],
    /// Size of the box, m, each > 0.
    pub size_m: [f32; 3],
}

/// Which renderer draws the clouds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, DocumentedVariants)]
#[serde(rename_all = "snake_case")]
pub enum Technique {
    /// Ray-marched clouds (compute).
    Raymarch,
    /// Volumetric particles with precomputed lighting (Yusov 2014).
    Particles,
    /// Sprite-cluster clouds (Wang 2003).
    Sprites,
}

impl Technique {
    /// Every technique, in declaration order.
    pub const ALL: &[Technique] = &[
        Technique::Raymarch,
        Technique::Particles,
        Technique::Sprites,
    ];

    /// The name scene files use.
    pub fn name(self) -> &'static str {
        match self {
            Technique::Raymarch => "raymarch",
            Technique::Particles => "particles",
            Technique::Sprites => "sprites",
        }
    }
}

/// Named sets of step counts, from fast to converged.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, DocumentedVariants)]
#[serde(rename_all = "snake_case")]
pub enum Quality {
    /// Real-time budget on a low-end GPU.
    Low,
    /// Real-time budget on a mid-range GPU.
    Medium,
    /// Stills: enough steps for no visible banding.
    High,
    /// Near-converged: for references and tuning.
    Ultra,
}

/// Tone-mapping operator from HDR radiance to display values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, DocumentedVariants)]
#[serde(rename_all = "snake_case")]
pub enum Tonemap {
    /// ACES filmic fit (Hill's RRT+ODT fit).
    Aces,
    /// AgX (Sobotka), base look.
    Agx,
}

/// Image size, technique, quality and output.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields, default)]
pub struct RenderSettings {
    /// Image width in pixels, 1..the adapter's maximum texture size.
    pub width: u32,
    /// Image height in pixels, 1..the adapter's maximum texture size.
    pub height: u32,
    /// Which technique renders the clouds.
    pub technique: Technique,
    /// Step-count preset.
    pub quality: Quality,
    /// Overrides the preset's primary steps per ray, 1..4096.
    pub primary_steps: Option<u32>,
    /// Overrides the preset's steps toward the sun per sample, 1..64.
    pub light_steps: Option<u32>,
    /// Samples per pixel, 1..1024, each crossing the pixel at its own point, so several integrate
    /// the pixel's footprint (anti-aliasing): the ray marcher's jittered passes (its preset's by
    /// default); the particles and sprites draw the whole frame once per sample and average them
    /// ([`crate::renderer::SceneRenderer::render`]; 1 by default).
    pub samples_per_pixel: Option<u32>,
    /// Skip the empty space above the clouds with the hierarchical height map (same image, less
    /// work). On by default.
    pub empty_space_skipping: bool,
    /// Exposure in stops (EV) applied before tone mapping, -20..20.
    pub exposure_ev: f32,
    /// Tone-mapping operator for PNG output.
    pub tonemap: Tonemap,
    /// Scene time in seconds: wind has moved the clouds by `wind * time_s`.
    pub time_s: f32,
    /// Output file: `.png` (tone-mapped sRGB) or `.exr` (linear HDR radiance).
    pub output: String,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 1280,
            height: 720,
            technique: Technique::Raymarch,
            quality: Quality::High,
            primary_steps: None,
            light_steps: None,
            samples_per_pixel: None,
            empty_space_skipping: true,
            exposure_ev: 0.0,
            tonemap: Tonemap::Aces,
            time_s: 0.0,
            output: "cloudscape.png".to_string(),
        }
    }
}

/// Changes over scene time, as keyframed paths (see [`crate::animation`]). Each path is either
/// empty (that part of the scene stays as the rest of the scene says) or holds at least 2 keyframes
/// with strictly increasing `time_s`. Before its first keyframe and after its last, a path holds.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields, default)]
pub struct Animation {
    /// Camera keyframes: position, and orientation by look-at point or by yaw and pitch.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub camera_path: Vec<CameraKey>,
    /// Sun keyframes: elevation and azimuth, or local solar time.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub time_of_day: Vec<SunKey>,
    /// Keyframes of a factor on every layer's coverage: clouds grow (> 1) and decay (< 1).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub coverage_scale: Vec<CoverageKey>,
}

impl Animation {
    /// Whether no path is given: the scene looks the same at every time but for the wind.
    pub fn is_static(&self) -> bool {
        self.camera_path.is_empty() && self.time_of_day.is_empty() && self.coverage_scale.is_empty()
    }
}

/// One keyframe of the camera path.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields)]
pub struct CameraKey {
    /// Scene time of the keyframe, seconds; later than the previous keyframe's.
    pub time_s: f32,
    /// Eye position in metres.
    pub position_m: [f32; 3],
    /// Point looked at, metres (not the eye position); either every keyframe has one or none has.
    #[serde(default)]
    pub look_at_m: Option<[f32; 3]>,
    /// View azimuth in degrees clockwise from north, used without `look_at_m`; the camera turns the
    /// short way round between keyframes.
    #[serde(default)]
    pub yaw_deg: f32,
    /// View elevation in degrees above the horizon, -90..90, used without `look_at_m`.
    #[serde(default)]
    pub pitch_deg: f32,
}

/// One keyframe of the sun's path over the sky: by elevation and azimuth, or by local solar time
/// (at the latitude and day of `sun.time_of_day`), one or the other. Between two solar-time
/// keyframes the sun follows its true course over the sky.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields)]
pub struct SunKey {
    /// Scene time of the keyframe, seconds; later than the previous keyframe's.
    pub time_s: f32,
    /// Sun elevation above the horizon in degrees, -90..90; given with `sun_azimuth_deg`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sun_elevation_deg: Option<f32>,
    /// Sun azimuth in degrees clockwise from north; less than 90 degrees of sky from the previous
    /// keyframe's sun unless both are given by solar time.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sun_azimuth_deg: Option<f32>,
    /// Local solar time in hours, 0..24, instead of the two angles.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub solar_time_h: Option<f32>,
}

impl SunKey {
    /// A keyframe that puts the sun at `elevation_deg` and `azimuth_deg` at `time_s`.
    pub fn at_angles(time_s: f32, elevation_deg: f32, azimuth_deg: f32) -> SunKey {
        SunKey {
            time_s,
            sun_elevation_deg: Some(elevation_deg),
            sun_azimuth_deg: Some(azimuth_deg),
            solar_time_h: None,
        }
    }

    /// A keyframe that puts the sun where it is at local solar time `solar_time_h` at `time_s`.
    pub fn at_solar_time(time_s: f32, solar_time_h: f32) -> SunKey {
        SunKey {
            time_s,
            sun_elevation_deg: None,
            sun_azimuth_deg: None,
            solar_time_h: Some(solar_time_h),
        }
    }
}

/// One keyframe of the coverage factor.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, DocumentedFields)]
#[serde(deny_unknown_fields)]
pub struct CoverageKey {
    /// Scene time of the keyframe, seconds; later than the previous keyframe's.
    pub time_s: f32,
    /// Factor on every layer's `coverage`, >= 0; the product is clamped to 0..1.
    pub scale: f32,
}
