#![doc = include_str!("../README.md")]

mod render;
mod sky;
mod view;

pub use sky::{CloudSky, CloudSkyLoader};
pub use view::Clouds;

/// What cloudscape's types the settings use: technique, quality and the scene model.
pub use cloudscape::scene::{Quality, Scene, Technique};

use bevy::app::{App, Plugin, PostUpdate};
use bevy::asset::io::file::FileAssetReader;
use bevy::asset::{AssetApp, AssetPlugin};
use bevy::camera::Camera3d;
use bevy::ecs::schedule::IntoScheduleConfigs;

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
        render::build(app);
    }
}
