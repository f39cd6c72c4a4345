//! The main world's side: the [`Clouds`] settings on a camera, what such a camera needs from Bevy,
//! and each frame's inputs (the sky, the sun, the clock) gathered for the render world.

use crate::ambient::AmbientOwner;
use crate::sky::CloudSky;
use bevy::asset::{Assets, Handle};
use bevy::camera::{Camera3d, CameraMainTextureUsages, Exposure, Hdr};
use bevy::color::{ColorToComponents, LinearRgba};
use bevy::ecs::prelude::*;
use bevy::light::{AmbientLight, Atmosphere, DirectionalLight};
use bevy::log::{error, warn};
use bevy::platform::collections::HashSet;
use bevy::render::render_resource::TextureUsages;
use bevy::render::view::Msaa;
use bevy::time::Time;
use bevy::transform::components::GlobalTransform;
use cloudscape::frame::FrameSun;
use cloudscape::scene::{Quality, Scene, Technique};
use std::path::PathBuf;
use std::sync::Arc;

/// Clouds on a 3-D camera: which sky, which technique and how much work per frame. Every
/// `Camera3d` gets the default (the embedded default sky, the sky's own technique and quality,
/// 4x4 temporal reuse) once [`crate::CloudscapePlugin`] is added; set `enabled: false` for a
/// camera without clouds.
#[derive(Component, Clone, Debug)]
pub struct Clouds {
    /// Whether this camera draws clouds.
    pub enabled: bool,
    /// The sky (a scene file loaded as a [`CloudSky`]); None for cloudscape's embedded default.
    pub sky: Option<Handle<CloudSky>>,
    /// The technique, in place of the sky's `render.technique`.
    pub technique: Option<Technique>,
    /// The ray marcher's quality preset, in place of the sky's `render.quality`.
    pub quality: Option<Quality>,
    /// Temporal reuse: march one ray per `n x n` pixels a frame (2 or 4) and reproject the rest
    /// from the last frames; None marches every pixel every frame.
    pub temporal_grid: Option<u32>,
    /// Without temporal reuse, the fraction of the view's resolution the clouds are marched at:
    /// 1 (the default), 1/2 or 1/4 (others round to the nearest 1/n), then upsampled to the view
    /// against its depth. With temporal reuse the grid is the scale (one ray per `n x n` pixels a
    /// frame, the history at the view's resolution) and this is not read.
    pub render_scale: f32,
    /// Carry the lighting across frames as a game does (`LightingReuse::REAL_TIME`: the clouds'
    /// shadow map kept until the eye and the wind have moved half of its finest texel, the light
    /// volume warm-started); false rebuilds both every frame.
    pub reuse_lighting: bool,
    /// Light Bevy's materials with the sky: the camera's ambient light (set in the render world
    /// each frame) is the mean radiance of the diffuse light over it, cloudscape's sky thinned by
    /// the clouds straight above with the sunlight they scatter down. A camera with an
    /// `AmbientLight` of its own keeps it; false leaves the camera to Bevy's
    /// `GlobalAmbientLight`.
    pub sky_ambient: bool,
}

impl Default for Clouds {
    fn default() -> Clouds {
        Clouds {
            enabled: true,
            sky: None,
            technique: None,
            quality: None,
            temporal_grid: Some(4),
            render_scale: 1.0,
            reuse_lighting: true,
            sky_ambient: true,
        }
    }
}

impl Clouds {
    /// The default settings over `sky`.
    pub fn from_sky(sky: Handle<CloudSky>) -> Clouds {
        Clouds {
            sky: Some(sky),
            ..Clouds::default()
        }
    }
}

/// A camera's scene: its sky with its overrides.
#[derive(Clone)]
pub(crate) struct SkyScene {
    /// The scene with the camera's overrides, shared (a new one when the sky or a setting changed).
    pub scene: Arc<Scene>,
    /// The sky's own scene it was made from.
    source: Arc<Scene>,
    /// The camera's technique and quality it applies.
    overrides: (Option<Technique>, Option<Quality>),
    /// Where the scene's relative paths resolve.
    pub base_dir: PathBuf,
}

/// One camera's clouds this frame, as the render world receives them.
#[derive(Component, Clone)]
pub(crate) struct CloudView {
    /// The scene.
    pub sky: SkyScene,
    /// Temporal reuse's grid (None: every pixel every frame).
    pub temporal_grid: Option<u32>,
    /// Without temporal reuse, one ray per this many pixels along x and y (the render scale's
    /// inverse).
    pub scale_divisor: u32,
    /// Whether the lighting is carried across frames.
    pub reuse_lighting: bool,
    /// The sun: the first `DirectionalLight`, in the camera's exposed units.
    pub sun: FrameSun,
    /// Bevy's virtual time, seconds.
    pub time_s: f32,
    /// Whose ambient light the camera has.
    pub ambient: AmbientOwner,
}

/// What [`configure_cameras`] reads and sets on a camera.
type CameraTargets = (
    Entity,
    &'static Clouds,
    &'static mut Camera3d,
    Option<&'static mut Msaa>,
    Option<&'static mut CameraMainTextureUsages>,
    Has<Hdr>,
);

/// Gives cameras with clouds what cloudscape needs from their targets: no multisampling, an HDR
/// main target that can be copied into, and a depth buffer that can be sampled.
pub(crate) fn configure_cameras(
    mut commands: Commands,
    mut cameras: Query<CameraTargets, Changed<Clouds>>,
) {
    for (entity, clouds, mut camera, msaa, usages, hdr) in &mut cameras {
        if !clouds.enabled {
            continue;
        }
        let depth_usages = TextureUsages::from(camera.depth_texture_usages);
        if !depth_usages.contains(TextureUsages::TEXTURE_BINDING) {
            camera.depth_texture_usages = (depth_usages | TextureUsages::TEXTURE_BINDING).into();
        }
        match msaa {
            Some(mut msaa) if *msaa != Msaa::Off => {
                warn!(
                    "bevy_cloudscape: camera {entity} had {:?}; clouds need Msaa::Off",
                    *msaa
                );
                *msaa = Msaa::Off;
            }
            Some(_) => {}
            None => {
                commands.entity(entity).insert(Msaa::Off);
            }
        }
        let copy_into = TextureUsages::COPY_DST;
        match usages {
            Some(mut usages) => usages.0 |= copy_into,
            None => {
                let usages = CameraMainTextureUsages::default().with(copy_into);
                commands.entity(entity).insert(usages);
            }
        }
        if !hdr {
            commands.entity(entity).insert(Hdr);
        }
    }
}

/// cloudscape's embedded default sky, for cameras that name none.
#[derive(Resource)]
pub(crate) struct DefaultSky(pub CloudSky);

/// What [`update_cloud_views`] reads of a camera: its settings, exposure, last view and whether
/// it also has Bevy's `Atmosphere`.
type CameraSky = (
    Entity,
    &'static Clouds,
    Option<&'static Exposure>,
    Option<&'static CloudView>,
    Has<Atmosphere>,
    Has<AmbientLight>,
);

/// Gathers each camera's [`CloudView`] for the frame: its sky with the camera's overrides, the
/// sun from the first `DirectionalLight` and the clock from Bevy's virtual time. A camera that
/// also has Bevy's `Atmosphere` gets no clouds, and an error in the log once.
pub(crate) fn update_cloud_views(
    mut commands: Commands,
    cameras: Query<CameraSky>,
    lights: Query<(&DirectionalLight, &GlobalTransform)>,
    (skies, default_sky, time): (Res<Assets<CloudSky>>, Res<DefaultSky>, Res<Time>),
    mut refused: Local<HashSet<Entity>>,
) {
    for (entity, clouds, exposure, previous, atmosphere, own_ambient) in &cameras {
        if atmosphere && clouds.enabled && refused.insert(entity) {
            refuse_second_sky(entity);
        }
        let sky = match &clouds.sky {
            None => Some(&default_sky.0),
            Some(handle) => skies.get(handle),
        };
        let Some(sky) = sky.filter(|_| clouds.enabled && !atmosphere) else {
            commands.entity(entity).remove::<CloudView>();
            continue;
        };
        let sky = scene_of(sky, clouds, previous);
        let exposure = exposure.copied().unwrap_or_default().exposure();
        let radius_rad = sky.scene.sun.angular_radius_deg.to_radians();
        let sun = lights
            .iter()
            .next()
            .map(|(light, transform)| sun_of(light, transform, exposure, radius_rad))
            .unwrap_or_else(|| FrameSun::from_scene(&sky.scene.sun));
        commands.entity(entity).insert(CloudView {
            sky,
            temporal_grid: clouds.temporal_grid,
            scale_divisor: (1.0 / clouds.render_scale.clamp(0.125, 1.0)).round() as u32,
            reuse_lighting: clouds.reuse_lighting,
            sun,
            time_s: time.elapsed_secs(),
            ambient: match (own_ambient, clouds.sky_ambient) {
                (true, _) => AmbientOwner::Camera,
                (false, true) => AmbientOwner::Sky,
                (false, false) => AmbientOwner::Global,
            },
        });
    }
}

/// The sky's scene with the camera's technique and quality: the previous frame's unless the sky
/// (a new `Arc` after any edit or reload) or the camera's overrides changed, so that the render
/// world sees an edit as a new scene and nothing else as one, and a frame clones no scene.
fn scene_of(sky: &CloudSky, clouds: &Clouds, previous: Option<&CloudView>) -> SkyScene {
    let (source, base_dir) = sky.shared();
    let overrides = (clouds.technique, clouds.quality);
    if let Some(view) = previous
        && Arc::ptr_eq(&view.sky.source, &source)
        && view.sky.overrides == overrides
        && view.sky.base_dir == base_dir
    {
        return view.sky.clone();
    }
    let mut scene = (*source).clone();
    if let Some(technique) = clouds.technique {
        scene.render.technique = technique;
    }
    if let Some(quality) = clouds.quality {
        scene.render.quality = quality;
    }
    SkyScene {
        scene: Arc::new(scene),
        source,
        overrides,
        base_dir,
    }
}

/// cloudscape's sun from a Bevy light: toward the light (its transform's back), its colour times
/// its illuminance times the camera's exposure (Bevy's own pre-exposure of its lights).
fn sun_of(
    light: &DirectionalLight,
    transform: &GlobalTransform,
    exposure: f32,
    angular_radius_rad: f32,
) -> FrameSun {
    let toward = transform.back().as_vec3().to_array();
    let color = LinearRgba::from(light.color).to_vec3().to_array();
    let scale = light.illuminance * exposure;
    FrameSun {
        direction: glam::Vec3::from_array(toward).normalize(),
        irradiance: glam::Vec3::from_array(color) * scale,
        angular_radius_rad,
    }
}

/// Reports that Bevy's `Atmosphere` and the clouds were both asked for on one camera.
fn refuse_second_sky(entity: Entity) {
    error!(
        "bevy_cloudscape: camera {entity} has Bevy's Atmosphere as well as Clouds; cloudscape \
         draws its own physical sky, so the clouds are off on this camera (remove one of the two)"
    );
}
