use super::*;
use crate::scene::Scene;
use std::path::Path;

fn scene_field() -> (Scene, CloudField) {
    let scene = Scene::default();
    let field = CloudField::new(&scene, Path::new(".")).unwrap();
    (scene, field)
}

fn sun() -> Vec3 {
    Vec3::new(0.3, 0.6, -0.5).normalize()
}

#[test]
fn the_warp_round_trips_and_is_finest_under_the_eye() {
    let (scene, field) = scene_field();
    let params = ShadowParams::new(&scene, &field, Vec3::ZERO, sun());
    for s in [-0.9, -0.2, 0.0, 0.37, 1.0] {
        assert!((params.coord_of(params.offset_of(s)) - s).abs() < 1e-5);
    }
    let texel = |i| {
        let a = params.ground_point((i, 0), 256).x;
        params.ground_point((i + 1, 0), 256).x - a
    };
    assert!(
        texel(128) < 0.5 * texel(250),
        "{} {}",
        texel(128),
        texel(250)
    );
    let edge = params.ground_point((255, 255), 256);
    assert!(edge.x < params.half_extent_m && edge.x > 0.95 * params.half_extent_m);
}

#[test]
fn columns_decrease_upward_and_match_the_direct_optical_depth() {
    let (scene, field) = scene_field();
    let params = ShadowParams::new(&scene, &field, Vec3::ZERO, sun());
    let (mut checked, mut total_error) = (0, 0.0);
    for k in 0..40 {
        let g = Vec2::new(k as f32 * 731.0 - 14000.0, k as f32 * 377.0 - 7000.0);
        let column = params.column(&field, (g, 0), sun(), 0.0);
        assert!(column.windows(2).all(|w| w[0] >= w[1] - 1e-4), "{column:?}");
        // Straight from the ground point toward the sun, finely sampled.
        let p = Vec3::new(g.x, 0.0, g.y);
        let direct = field.coarse_optical_depth((p, sun()), (0.0, 12_000.0, 1.0), (400, 0.5), 0.0);
        if direct > 1.0 {
            total_error += (column[0] - direct).abs() / direct;
            checked += 1;
        }
    }
    assert!(checked >= 5, "the sample must cross clouds: {checked}");
    let mean_error = total_error / checked as f32;
    assert!(mean_error < 0.25, "{mean_error}");
}

#[test]
fn the_map_reads_the_columns_and_a_clear_sky_casts_nothing() {
    let (scene, field) = scene_field();
    let params = ShadowParams::new(&scene, &field, Vec3::ZERO, sun());
    let map = CloudShadowMap::build(&field, params, sun(), (32, 0.0));
    let ij = (9, 20);
    let g = params.ground_point(ij, 32);
    let column = map.columns[0][ij.1 as usize * 32 + ij.0 as usize];
    let on_ground = map.optical_depth(Vec3::new(g.x, 0.0, g.y), 0);
    assert!((on_ground - column[0]).abs() <= 1e-3 * column[0].max(1.0));
    assert_eq!(
        map.optical_depth(Vec3::new(g.x, params.top_y_m + 1.0, g.y), 0),
        0.0
    );

    let mut clear = scene.clone();
    clear.layers.clear();
    let clear_field = CloudField::new(&clear, Path::new(".")).unwrap();
    let clear_params = ShadowParams::new(&clear, &clear_field, Vec3::ZERO, sun());
    assert!(!clear_params.enabled);
    let clear_map = CloudShadowMap::build(&clear_field, clear_params, sun(), (8, 0.0));
    assert_eq!(clear_map.optical_depth(Vec3::ZERO, 0), 0.0);
}

#[test]
fn a_built_map_serves_until_its_shadows_drift_or_its_texels_grow_too_far() {
    let (scene, field) = scene_field();
    let at = |x: f32, time_s: f32, sun: Vec3| BuiltShadow {
        params: ShadowParams::new(&scene, &field, Vec3::new(x, 30.0, 0.0), sun),
        sun,
        texels: 256,
        time_s,
    };
    let built = at(0.0, 0.0, sun());
    let texel_m = built.params.finest_texel_m(256);
    let texel = |i| {
        let a = built.params.ground_point((i, 0), 256).x;
        built.params.ground_point((i + 1, 0), 256).x - a
    };
    // The texel beside the centre is a little larger: the warp grows away from it.
    assert!(
        (texel(128) - texel_m).abs() < 0.05 * texel_m,
        "{} {texel_m}",
        texel(128)
    );
    let reuse = LightingReuse::REAL_TIME;
    let wind = Vec2::new(6.0, 8.0);
    let served = |fresh: BuiltShadow| built.serves(&fresh, wind, reuse);
    // The eye may move until the texel under it is a quarter larger than the finest: at texel
    // coordinate s = 0.125 k / (1 - k), offset s (k + (1 - k) s) half extents.
    let k = built.params.warp;
    let s = 0.125 * k / (1.0 - k);
    let grown_m = s * (k + (1.0 - k) * s) * built.params.half_extent_m;
    assert!(grown_m > 4.0 * texel_m, "{grown_m} m");
    assert!(served(at(0.95 * grown_m, 0.0, sun())));
    assert!(!served(at(1.05 * grown_m, 0.0, sun())));
    // The clouds' shadows may lag half the finest texel.
    let half_texel_s = 0.5 * texel_m / 10.0;
    assert!(served(at(0.0, 0.9 * half_texel_s, sun())));
    assert!(!served(at(0.0, 1.1 * half_texel_s, sun())));
    assert!(!served(at(0.0, 0.0, Vec3::Y)));
    // A sun that moves shifts the highest clouds' shadows by its slope's change times their height.
    let span_m = built.params.top_y_m - built.params.bottom_y_m.min(0.0);
    let tilted = |shift_m: f32| {
        let s = sun();
        let slope = Vec2::new(s.x, s.z) / s.y + Vec2::new(shift_m / span_m, 0.0);
        Vec3::new(slope.x, 1.0, slope.y).normalize()
    };
    assert!(served(at(0.0, 0.0, tilted(0.4 * texel_m))));
    assert!(!served(at(0.0, 0.0, tilted(0.6 * texel_m))));
    assert!(!served(at(0.0, 0.6 * half_texel_s, tilted(0.3 * texel_m))));
    // Without a warp the texels never grow: the eye may move a fiftieth of the map's reach.
    let mut even = scene.clone();
    even.shadow.warp = 1.0;
    let even_at = |x: f32| BuiltShadow {
        params: ShadowParams::new(&even, &field, Vec3::new(x, 30.0, 0.0), sun()),
        ..built
    };
    let reach_m = even_at(0.0).params.half_extent_m;
    assert!(even_at(0.0).serves(&even_at(0.019 * reach_m), wind, reuse));
    assert!(!even_at(0.0).serves(&even_at(0.021 * reach_m), wind, reuse));
    assert!(!served(BuiltShadow {
        texels: 128,
        ..built
    }));
}
