//! The flight example's world: a ground, towers near the camera, a balloon above the clouds, the
//! sun and a camera with clouds. Shared with the tests, which render it in a window.

use bevy::camera::Exposure;
use bevy::light::CascadeShadowConfigBuilder;
use bevy::prelude::*;
use bevy_cloudscape::{CloudShadowedMaterial, CloudSky, Clouds};

/// Where the camera starts, metres.
pub const START: Vec3 = Vec3::new(0.0, 40.0, 0.0);
/// The colour of the near tower, unlit: what the tests look for where it stands.
pub const TOWER_COLOR: Color = Color::linear_rgb(0.8, 0.05, 0.05);
/// The near tower: centre on the ground and half-size, metres (straight ahead of the camera).
pub const TOWER: (Vec3, Vec3) = (Vec3::new(0.0, 0.0, -400.0), Vec3::new(25.0, 120.0, 25.0));
/// The balloon above the cloud layer, ahead and to the right of the camera, metres: the clouds
/// hide it.
pub const BALLOON: Vec3 = Vec3::new(2500.0, 4500.0, -9000.0);
/// The balloon's radius, metres.
pub const BALLOON_RADIUS_M: f32 = 400.0;

/// The camera's exposure: a bright day's, at which raw sunlight (130,000 lux) gives sunlit clouds
/// about the radiance cloudscape's own renders show at their default exposure (Bevy's
/// `Exposure::SUNLIGHT`, 15, leaves them grey).
pub const EV100: f32 = 13.5;

/// The camera's starting orientation: north, a little above the horizon.
pub fn start_transform() -> Transform {
    Transform::from_translation(START).looking_to(Vec3::new(0.0, 0.35, -1.0), Vec3::Y)
}

/// The ground's colour: what the tests compare under a clear and an overcast sky.
pub const GROUND_COLOR: Color = Color::srgb(0.30, 0.34, 0.22);
/// The concrete towers beyond the red one: x and z of the centre, half-width and height, metres.
/// The sun (behind the camera) lights their faces toward the camera.
pub const CONCRETE_TOWERS: [(f32, f32, f32, f32); 3] = [
    (-260.0, -700.0, 40.0, 180.0),
    (300.0, -900.0, 60.0, 260.0),
    (-600.0, -1400.0, 80.0, 140.0),
];
/// The concrete towers' colour.
pub const CONCRETE_COLOR: Color = Color::srgb(0.55, 0.53, 0.5);

/// Where the world's materials go: the unlit markers are Bevy's `StandardMaterial`, the lit ground
/// and towers a `CloudShadowedMaterial` (the clouds' shadow falls on them).
pub struct Materials<'a> {
    /// Bevy's own.
    pub standard: &'a mut Assets<StandardMaterial>,
    /// Under the clouds' shadow.
    pub shadowed: &'a mut Assets<CloudShadowedMaterial>,
}

/// A lit material of `color` and `roughness` under the clouds' shadow.
fn shadowed(color: Color, roughness: f32) -> CloudShadowedMaterial {
    CloudShadowedMaterial {
        base: StandardMaterial {
            base_color: color,
            perceptual_roughness: roughness,
            ..default()
        },
        extension: default(),
    }
}

/// Spawns the world, the sun and a camera whose clouds are `sky`.
pub fn spawn_world(
    commands: &mut Commands,
    meshes: &mut Assets<Mesh>,
    materials: Materials,
    sky: Handle<CloudSky>,
) {
    let Materials {
        standard,
        shadowed: lit,
    } = materials;
    let ground = lit.add(shadowed(GROUND_COLOR, 1.0));
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(60_000.0, 60_000.0))),
        MeshMaterial3d(ground),
    ));
    let concrete = lit.add(shadowed(CONCRETE_COLOR, 0.9));
    for (x, z, half, height) in CONCRETE_TOWERS {
        commands.spawn((
            Mesh3d(meshes.add(Cuboid::new(2.0 * half, height, 2.0 * half))),
            MeshMaterial3d(concrete.clone()),
            Transform::from_xyz(x, 0.5 * height, z),
        ));
    }
    let unlit = |color: Color| StandardMaterial {
        base_color: color,
        unlit: true,
        ..default()
    };
    let (centre, half) = TOWER;
    commands.spawn((
        Mesh3d(meshes.add(Cuboid::new(2.0 * half.x, 2.0 * half.y, 2.0 * half.z))),
        MeshMaterial3d(standard.add(unlit(TOWER_COLOR))),
        Transform::from_translation(centre + Vec3::Y * half.y),
    ));
    commands.spawn((
        Mesh3d(meshes.add(Sphere::new(BALLOON_RADIUS_M))),
        MeshMaterial3d(standard.add(unlit(TOWER_COLOR))),
        Transform::from_translation(BALLOON),
    ));
    commands.spawn((
        DirectionalLight {
            illuminance: light_consts::lux::RAW_SUNLIGHT,
            // Bevy applies the clouds' shadow to a light with shadow maps.
            shadow_maps_enabled: true,
            ..default()
        },
        // The towers' shadows near the camera; the clouds' shadow reaches the far distance.
        CascadeShadowConfigBuilder {
            num_cascades: 2,
            maximum_distance: 3000.0,
            ..default()
        }
        .build(),
        sun_transform(35.0, 200.0),
    ));
    commands.spawn((
        Camera3d::default(),
        Exposure { ev100: EV100 },
        start_transform(),
        Clouds::from_sky(sky),
    ));
}

/// A light shining from the sun at `elevation_deg` above the horizon and `azimuth_deg` clockwise
/// from north (-z).
pub fn sun_transform(elevation_deg: f32, azimuth_deg: f32) -> Transform {
    let (elevation, azimuth) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
    let toward_sun = Vec3::new(
        elevation.cos() * azimuth.sin(),
        elevation.sin(),
        -elevation.cos() * azimuth.cos(),
    );
    Transform::default().looking_to(-toward_sun, Vec3::Y)
}
