#![doc = include_str!("../README.md")]

mod ambient;
mod render;
mod shadow;
mod sky;
mod view;

pub use shadow::{CloudShadow, CloudShadowedMaterial};
pub use sky::{CloudSky, CloudSkyLoader};
pub use view::Clouds;

/// What cloudscape's types the settings use: technique, quality and the scene model.
pub use cloudscape::scene::{Quality, Scene, Technique};

use bevy::app::{App, Plugin, PostUpdate};
use bevy::asset::io::file::FileAssetReader;
use bevy::asset::{AssetApp, AssetPlugin, Assets};
use bevy::camera::Camera3d;
use bevy::ecs::schedule::IntoScheduleConfigs;
use bevy::pbr::{MaterialPlugin, PbrPlugin, prepare_lights};
use bevy::render::renderer::RenderDevice;
use bevy::render::{Render, RenderApp, RenderSystems};
use bevy::shader::Shader;

/// Clouds over every `Camera3d`: add it to the `App` and each 3-D camera draws the clouds of its
/// [`Clouds`] component (the embedded default sky unless one is given).
pub struct CloudscapePlugin;

impl Plugin for CloudscapePlugin {
    fn build(&self, app: &mut App) {
        // The scene's relative paths resolve against the asset source's directory on disk.
        let asset_dir = app
            .get_added_plugins::<AssetPlugin>()
            .first()
            .map_or_else(|| "assets".to_string(), |p| p.file_path.clone());
        let asset_root = FileAssetReader::get_base_path().join(asset_dir);
        app.init_asset::<CloudSky>()
            .register_asset_loader(CloudSkyLoader { asset_root })
            .insert_resource(view::DefaultSky(CloudSky::embedded_default()))
            .register_required_components::<Camera3d, Clouds>()
            .add_systems(
                PostUpdate,
                (view::configure_cameras, view::update_cloud_views).chain(),
            );
        add_cloud_shadow(app);
        render::build(app);
        add_sky_ambient(app);
    }

    fn finish(&self, app: &mut App) {
        let generation = app
            .world()
            .resource::<shadow::ShadowMapGeneration>()
            .clone();
        if let Some(render_app) = app.get_sub_app_mut(RenderApp) {
            let device = render_app.world().resource::<RenderDevice>();
            let copy = shadow::ShadowMapCopy::new(device, generation);
            render_app.insert_resource(copy);
        }
    }
}

/// The sky's light on Bevy's materials (with Bevy's PBR): each view's ambient light, set before
/// Bevy prepares its lights.
fn add_sky_ambient(app: &mut App) {
    if !app.is_plugin_added::<PbrPlugin>() {
        return;
    }
    if let Some(render_app) = app.get_sub_app_mut(RenderApp) {
        render_app.add_systems(
            Render,
            ambient::light_materials_with_the_sky
                .in_set(RenderSystems::CreateViews)
                .before(prepare_lights),
        );
    }
}

/// The clouds' shadow for materials: the shaders, [`CloudShadowedMaterial`] (with Bevy's PBR) and
/// the systems that keep its bindings current.
fn add_cloud_shadow(app: &mut App) {
    if let Some(mut shaders) = app.world_mut().get_resource_mut::<Assets<Shader>>() {
        shadow::add_shaders(&mut shaders);
    }
    app.init_resource::<shadow::ShadowMapGeneration>();
    if app.is_plugin_added::<PbrPlugin>() {
        app.add_plugins(MaterialPlugin::<CloudShadowedMaterial>::default())
            .add_systems(
                PostUpdate,
                (shadow::rebind_materials, shadow::warn_unshadowed_sun),
            );
    }
}
