//! The sky's light on Bevy's materials: each camera that draws clouds gets, in the render world,
//! an `AmbientLight` of the diffuse light over it (the sky's, thinned and whitened by the clouds
//! above), so faces the sun does not reach, or the clouds shadow, are lit as the sky would light
//! them rather than by Bevy's fixed default.

use crate::render::CloudRenderers;
use crate::view::CloudView;
use bevy::color::Color;
use bevy::ecs::prelude::*;
use bevy::light::AmbientLight;
use bevy::render::camera::ExtractedCamera;
use bevy::render::sync_world::MainEntity;
use bevy::render::view::ExtractedView;
use cloudscape::environment::{Environment, Sky};
use cloudscape::field::CloudField;
use cloudscape::frame::FrameSun;
use cloudscape::optics::PhaseLobes;
use cloudscape::scene::Scene;

/// Marks an `AmbientLight` the plugin put on a camera's render entity.
#[derive(Component)]
pub(crate) struct SkyAmbient;

/// Whose ambient light a camera has: what [`light_materials_with_the_sky`] does with it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum AmbientOwner {
    /// The plugin's: the diffuse light over the camera ([`crate::Clouds::sky_ambient`]).
    Sky,
    /// Bevy's `GlobalAmbientLight` (the camera asked for no sky ambient).
    Global,
    /// The camera's own `AmbientLight`, left alone.
    Camera,
}

/// What [`light_materials_with_the_sky`] reads and sets on a view.
type ViewAmbient = (
    Entity,
    MainEntity,
    &'static CloudView,
    &'static ExtractedView,
    &'static ExtractedCamera,
    Option<&'static mut AmbientLight>,
    Has<SkyAmbient>,
);

/// Sets the ambient light of each view whose camera takes it from the sky, before Bevy prepares
/// its lights; takes it off views that no longer do (their own light, extracted from the main
/// world, stays).
pub(crate) fn light_materials_with_the_sky(
    mut commands: Commands,
    mut views: Query<ViewAmbient>,
    stale: Query<Entity, (With<SkyAmbient>, Without<CloudView>)>,
    renderers: Res<CloudRenderers>,
) {
    for (entity, camera, view, extracted, extracted_camera, ambient, ours) in &mut views {
        match view.ambient {
            AmbientOwner::Sky => {
                let eye = extracted.world_from_view.translation().to_array();
                let clouds = renderers.field(camera).map(|f| (f, view.time_s));
                let scene = &view.sky.scene;
                let light =
                    sky_ambient_light(scene, &view.sun, clouds, (eye, extracted_camera.exposure));
                match ambient {
                    Some(mut ambient) => *ambient = light,
                    None => {
                        commands.entity(entity).insert((light, SkyAmbient));
                    }
                }
            }
            AmbientOwner::Global if ours => {
                commands
                    .entity(entity)
                    .remove::<(AmbientLight, SkyAmbient)>();
            }
            AmbientOwner::Camera if ours => {
                commands.entity(entity).remove::<SkyAmbient>();
            }
            AmbientOwner::Global | AmbientOwner::Camera => {}
        }
    }
    for entity in &stale {
        commands
            .entity(entity)
            .remove::<(AmbientLight, SkyAmbient)>();
    }
}

/// Bevy's ambient light for a camera at `eye_m` under `scene`'s sky and the frame's `sun`
/// (exposed, as cloudscape receives it), with the `clouds` of a field at a scene time (once the
/// camera's renderer is built): cloudscape's `Environment::diffuse_radiance_up` (the mean
/// radiance over the upper hemisphere: the sky's, Hillaire 2020's atmosphere or the scene's
/// analytic sky, thinned by the coarse field's optical depth straight up, with the sunlight the
/// clouds scatter down), in Bevy's units before its `exposure` (cd/m^2 for a sun in lux). Under a
/// uniform radiance `L` a Lambertian face of albedo `a` sends back `a L`, which is Bevy's
/// ambient term.
pub(crate) fn sky_ambient_light(
    scene: &Scene,
    sun: &FrameSun,
    clouds: Option<(&CloudField, f32)>,
    (eye_m, exposure): ([f32; 3], f32),
) -> AmbientLight {
    let p = glam::Vec3::from_array(eye_m);
    let tau_above = clouds.map_or(0.0, |(f, time_s)| f.coarse_optical_depth_above(p, time_s));
    let asymmetry = PhaseLobes::from_scene(&scene.phase).mean_cosine();
    let env = Environment::new(&Sky::from_scene(scene), sun);
    let radiance = env.diffuse_radiance_up(p, tau_above, asymmetry) / exposure;
    let brightness = radiance.max_element().max(f32::MIN_POSITIVE);
    let color = radiance / brightness;
    AmbientLight {
        color: Color::linear_rgb(color.x, color.y, color.z),
        brightness,
        affects_lightmapped_meshes: true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bevy::color::{ColorToComponents, LinearRgba};
    use cloudscape::scene::SceneDocument;
    use std::path::Path;

    /// A sun of `lux` above the air, 45 degrees up, exposed by `exposure`.
    fn sun(lux: f32, exposure: f32) -> FrameSun {
        FrameSun {
            direction: glam::Vec3::new(0.0, 1.0, 1.0).normalize(),
            irradiance: glam::Vec3::splat(lux * exposure),
            angular_radius_rad: 0.0047,
        }
    }

    /// The ambient light's radiance, rgb.
    fn radiance(light: &AmbientLight) -> glam::Vec3 {
        glam::Vec3::from_array(LinearRgba::from(light.color).to_vec3().to_array())
            * light.brightness
    }

    const EYE: ([f32; 3], f32) = ([0.0, 2.0, 0.0], 1.0);

    #[test]
    fn the_clear_sky_is_blue_and_as_bright_as_daylight_measures() {
        let light = sky_ambient_light(&Scene::default(), &sun(128_000.0, 1.0), None, EYE);
        let rgb = radiance(&light);
        // A clear sky with the sun 45 degrees up sends 10-20 klux of diffuse light onto the ground
        // for the 128 klux above the air (CIE S 011/E:2003 standard clear sky; Darula & Kittler
        // 2002): a mean radiance E / pi of 0.025-0.05 of the sun's figure.
        let ratio = rgb.y / 128_000.0;
        assert!(
            (0.02..0.08).contains(&ratio),
            "sky radiance over the sun's irradiance {ratio}"
        );
        assert!(rgb.z > 1.2 * rgb.x, "a clear sky is blue: {rgb}");
    }

    #[test]
    fn the_ambient_light_does_not_depend_on_the_exposure() {
        let scene = Scene::default();
        let at =
            |exposure| sky_ambient_light(&scene, &sun(1e5, exposure), None, ([0.0; 3], exposure));
        let (a, b) = (at(1.0), at(1.0 / 64.0));
        let relative = (a.brightness - b.brightness).abs() / a.brightness;
        assert!(relative < 1e-4, "{} against {}", a.brightness, b.brightness);
    }

    #[test]
    fn under_an_overcast_deck_the_light_is_grey_and_no_more_than_enters_its_top() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/assets/overcast.toml");
        let doc = SceneDocument::load(Some(&path), &[]).expect("the test sky loads");
        let field = CloudField::new(&doc.scene, &doc.resolve_path("")).expect("the field builds");
        let lux = 1e5;
        let sun = sun(lux, 1.0);
        let tau = field.coarse_optical_depth_above(glam::Vec3::from_array(EYE.0), 0.0);
        let clear = radiance(&sky_ambient_light(&doc.scene, &sun, None, EYE));
        let deck = radiance(&sky_ambient_light(
            &doc.scene,
            &sun,
            Some((&field, 0.0)),
            EYE,
        ));
        eprintln!("optical depth above {tau:.1}: clear {clear}, under the deck {deck}");
        assert!(
            tau > 10.0,
            "the deck's optical depth above the eye is {tau}"
        );
        // All the light that enters the deck's top, the sky's and the sun's, spread evenly.
        let entering = clear.y + lux * sun.direction.y / std::f32::consts::PI;
        assert!(
            deck.y < 0.5 * entering,
            "under the deck {deck}, entering {entering}"
        );
        let blueness = |c: glam::Vec3| c.z / c.x;
        assert!(
            blueness(deck) < 0.5 * blueness(clear),
            "the deck whitens the light: {deck}, {clear}"
        );
    }
}
