//! The render world's side: one cloudscape renderer per camera on Bevy's device, each frame
//! started in Bevy's prepare stage and recorded into Bevy's encoder between the opaque and the
//! transparent passes.

use crate::shadow::ShadowMapCopy;
use crate::view::CloudView;
use bevy::app::{App, SubApp};
use bevy::camera::Camera3d;
use bevy::core_pipeline::core_3d::{main_opaque_pass_3d, main_transparent_pass_3d};
use bevy::core_pipeline::schedule::Core3d;
use bevy::core_pipeline::schedule::Core3dSystems;
use bevy::ecs::prelude::*;
use bevy::ecs::schedule::IntoScheduleConfigs;
use bevy::log::error;
use bevy::platform::collections::{HashMap, HashSet};
use bevy::render::camera::ExtractedCamera;
use bevy::render::renderer::{RenderAdapter, RenderContext, RenderDevice, RenderQueue, ViewQuery};
use bevy::render::sync_world::{MainEntity, RenderEntity};
use bevy::render::view::{ExtractedView, ViewDepthStencilTexture, ViewTarget};
use bevy::render::{Extract, ExtractSchedule, Render, RenderApp, RenderSystems};
use cloudscape::field::CloudField;
use cloudscape::frame::{DepthConvention, Frame};
use cloudscape::gpu::GpuContext;
use cloudscape::post::Background;
use cloudscape::renderer::{CloudRenderer, Reuse};
use cloudscape::scene::Scene;
use cloudscape::shadow::LightingReuse;
use cloudscape::temporal::TemporalSettings;
use std::sync::Arc;

/// Rays end this far away where Bevy's depth buffer holds nothing, metres.
const FAR_M: f32 = 1.2e5;

/// Adds the render world's systems to `app`'s render sub-app (none without one).
pub(crate) fn build(app: &mut App) {
    let Some(render_app) = app.get_sub_app_mut(RenderApp) else {
        return;
    };
    add_systems(render_app);
}

fn add_systems(render_app: &mut SubApp) {
    render_app
        .init_resource::<CloudRenderers>()
        .add_systems(ExtractSchedule, extract_cloud_views)
        .add_systems(
            Core3d,
            encode_environment
                .before(main_opaque_pass_3d)
                .in_set(Core3dSystems::Prepass),
        )
        .add_systems(
            Render,
            begin_cloud_frames
                .in_set(RenderSystems::Prepare)
                .after(RenderSystems::PrepareViews),
        )
        .add_systems(
            Core3d,
            draw_clouds
                .after(main_opaque_pass_3d)
                .before(main_transparent_pass_3d),
        );
}

/// One camera's renderer and what it was built from.
struct ViewClouds {
    renderer: CloudRenderer,
    /// The scene the renderer holds (an edit arrives as a new one).
    scene: Arc<Scene>,
    /// Frames begun, for temporal reuse's sample pattern.
    frame_index: u32,
    /// Whether this frame was begun (and may be drawn).
    begun: bool,
}

/// Every camera's clouds, on Bevy's device.
#[derive(Resource, Default)]
pub(crate) struct CloudRenderers {
    gpu: Option<GpuContext>,
    /// Keyed by the camera's main-world entity.
    views: HashMap<Entity, ViewClouds>,
    /// The camera whose shadow map materials read: the lowest `Camera::order` among those with
    /// clouds (then the lowest entity).
    shadow_source: Option<Entity>,
}

impl CloudRenderers {
    /// The cloud field (the CPU specification) of the camera with main-world entity `camera`,
    /// once its renderer is built.
    pub(crate) fn field(&self, camera: Entity) -> Option<&CloudField> {
        self.views.get(&camera).map(|v| v.renderer.field())
    }
}

/// A camera's render entity and its clouds, if any.
type CameraView = (RenderEntity, Option<&'static CloudView>);

/// Copies each camera's [`CloudView`] to its render entity, and takes it away from cameras
/// that no longer draw clouds.
fn extract_cloud_views(
    mut commands: Commands,
    cameras: Extract<Query<CameraView, With<Camera3d>>>,
) {
    for (render_entity, view) in &cameras {
        let Ok(mut entity) = commands.get_entity(render_entity) else {
            continue;
        };
        match view {
            Some(view) => entity.insert(view.clone()),
            None => entity.remove::<CloudView>(),
        };
    }
}

/// Builds a renderer for each new camera, hands it the sky's edits, and starts its frame
/// (uploads only: nothing is recorded or waited on here).
fn begin_cloud_frames(
    views: Query<(MainEntity, &CloudView, &ExtractedView, &ExtractedCamera)>,
    mut renderers: ResMut<CloudRenderers>,
    mut copy: ResMut<ShadowMapCopy>,
    (adapter, device, queue): (Res<RenderAdapter>, Res<RenderDevice>, Res<RenderQueue>),
) {
    let renderers = &mut *renderers;
    let gpu = renderers.gpu.get_or_insert_with(|| {
        GpuContext::from_wgpu(
            (**adapter).clone(),
            device.wgpu_device().clone(),
            (**queue).clone(),
        )
    });
    let mut seen = HashSet::new();
    renderers.shadow_source = views
        .iter()
        .map(|(main, .., camera)| (camera.order, main))
        .min()
        .map(|(_, main)| main);
    if renderers.shadow_source.is_none() {
        copy.clear(&queue);
    }
    for (main, cloud_view, view, camera) in &views {
        seen.insert(main);
        let Some(size) = camera.physical_target_size.filter(|s| s.x > 0 && s.y > 0) else {
            continue;
        };
        let Some(clouds) = view_clouds(gpu, &mut renderers.views, main, cloud_view) else {
            continue;
        };
        let frame = frame_of(
            cloud_view,
            view,
            glam::UVec2::new(size.x, size.y),
            clouds.frame_index,
        );
        let reuse = match cloud_view.temporal_grid {
            Some(divisor) => Reuse::Temporal(TemporalSettings {
                divisor,
                ..TemporalSettings::default()
            }),
            None => Reuse::Scaled(cloud_view.scale_divisor),
        };
        let lighting = cloud_view
            .reuse_lighting
            .then_some(LightingReuse::REAL_TIME);
        clouds.renderer.set_lighting_reuse(lighting);
        clouds.renderer.begin_frame(gpu, &frame, reuse);
        clouds.frame_index = clouds.frame_index.wrapping_add(1);
        clouds.begun = true;
    }
    renderers.views.retain(|main, _| seen.contains(main));
}

/// The camera's renderer, built on first use and given the sky's edits; None (the error
/// logged) when the sky cannot be built.
fn view_clouds<'a>(
    gpu: &GpuContext,
    views: &'a mut HashMap<Entity, ViewClouds>,
    main: Entity,
    cloud_view: &CloudView,
) -> Option<&'a mut ViewClouds> {
    let (scene, dir) = (&cloud_view.sky.scene, &cloud_view.sky.base_dir);
    if let Some(clouds) = views.get_mut(&main) {
        if !Arc::ptr_eq(&clouds.scene, scene) {
            if let Err(e) = clouds.renderer.apply_edit(gpu, scene, dir) {
                error!("bevy_cloudscape: the edited sky cannot be drawn: {e}");
            }
            clouds.scene = scene.clone();
        }
    } else {
        match CloudRenderer::new(gpu, scene, dir) {
            Ok(renderer) => {
                let clouds = ViewClouds {
                    renderer,
                    scene: scene.clone(),
                    frame_index: 0,
                    begun: false,
                };
                views.insert(main, clouds);
            }
            Err(e) => {
                error!("bevy_cloudscape: the sky cannot be drawn: {e}");
                return None;
            }
        }
    }
    views.get_mut(&main)
}

/// cloudscape's frame from Bevy's view: its camera and its projection (reversed-Z with an
/// infinite far plane), the sun and the clock of the main world.
fn frame_of(cloud_view: &CloudView, view: &ExtractedView, size: glam::UVec2, index: u32) -> Frame {
    let mat = |m: bevy::math::Mat4| glam::Mat4::from_cols_array(&m.to_cols_array());
    let world_from_view = mat(view.world_from_view.to_matrix());
    Frame {
        size,
        camera_position_m: world_from_view.w_axis.truncate(),
        view_from_world: world_from_view.inverse(),
        clip_from_view: mat(view.clip_from_view),
        depth: DepthConvention::ReversedInfinite,
        far_m: FAR_M,
        sun: cloud_view.sun,
        time_s: cloud_view.time_s,
        exposure_ev: 0.0,
        frame_index: index,
    }
}

/// Records the frame's environment passes (the clouds' shadow map, the sky's tables) before Bevy's
/// opaque pass, and copies the shadow map that materials read out of the source camera's.
fn encode_environment(
    view: ViewQuery<MainEntity, With<CloudView>>,
    mut renderers: ResMut<CloudRenderers>,
    mut copy: ResMut<ShadowMapCopy>,
    (device, queue): (Res<RenderDevice>, Res<RenderQueue>),
    mut ctx: RenderContext,
) {
    let main = view.into_inner();
    let renderers = &mut *renderers;
    let (Some(gpu), Some(clouds)) = (&renderers.gpu, renderers.views.get_mut(&main)) else {
        return;
    };
    if !clouds.begun {
        return;
    }
    let encoder = ctx.command_encoder();
    clouds.renderer.encode_environment(gpu, encoder, None);
    if renderers.shadow_source == Some(main)
        && let Some(map) = clouds.renderer.shadow_map()
    {
        copy.update(&device, &queue, encoder, map);
    }
}

/// Records the camera's clouds against Bevy's depth, composes them over the opaque scene and
/// writes the result into the view's HDR target (its next main texture).
fn draw_clouds(
    view: ViewQuery<(MainEntity, &ViewTarget, &ViewDepthStencilTexture), With<CloudView>>,
    mut renderers: ResMut<CloudRenderers>,
    mut ctx: RenderContext,
) {
    let (main, target, depth) = view.into_inner();
    let renderers = &mut *renderers;
    let (Some(gpu), Some(clouds)) = (&renderers.gpu, renderers.views.get_mut(&main)) else {
        return;
    };
    let Some(depth) = depth.attachment.depth_stencil_views().depth_only_view() else {
        return;
    };
    if !std::mem::take(&mut clouds.begun) {
        return;
    }
    let encoder = ctx.command_encoder();
    clouds
        .renderer
        .encode_clouds(gpu, encoder, depth, None, None);
    let write = target.post_process_write();
    let background = Background {
        color: write.source,
        depth,
    };
    clouds
        .renderer
        .encode_finish(gpu, encoder, &background, None);
    let composed = clouds.renderer.images().hdr;
    encoder.copy_texture_to_texture(
        composed.as_image_copy(),
        write.destination_texture.as_image_copy(),
        composed.size(),
    );
}
