//! Validation of the path tracer against analytic and independently computed results.

mod support;

use cloudscape::optics::PhaseLobes;
use cloudscape_reference::geometry::Aabb;
use cloudscape_reference::medium::HomogeneousBox;
use cloudscape_reference::sampling::{cosine_hemisphere, uniform_sphere};
use glam::{UVec2, Vec3};
use support::adding_doubling::{Slab, diffuse_reflectance_transmittance};
use support::{environment, mean_and_error, slab, sun, tracer, two_tone_sky};

/// White furnace: a non-absorbing medium inside a uniform sky of radiance 1 neither adds nor
/// removes light, so every view of it has radiance 1, whatever the phase function.
#[test]
fn white_furnace_is_uniformly_one() {
    let cube = HomogeneousBox {
        bounds: Aabb {
            min: Vec3::splat(-100.0),
            max: Vec3::splat(100.0),
        },
        extinction_per_m: 0.03,
    };
    for phase in [
        PhaseLobes::approximate_mie(20.0),
        PhaseLobes::dual_henyey_greenstein(0.8, -0.3, 0.7),
    ] {
        let t = tracer(
            cube,
            phase,
            1.0,
            environment(two_tone_sky(1.0, 1.0), None),
            UVec2::ONE,
        );
        let (mean, error) = mean_and_error(3000, |rng| {
            // From 500 m away, toward a random point of the cube.
            let origin = uniform_sphere(rng.next_vec2()) * 500.0;
            let target = (rng.next_vec3() - 0.5) * 200.0;
            let dir = (target - origin).normalize();
            f64::from(t.ray_radiance(origin, dir, f32::INFINITY, rng).y)
        });
        assert!(
            (mean - 1.0).abs() < (4.0 * error).max(2e-3),
            "{phase:?}: {mean} +- {error}"
        );
    }
}

/// Beer-Lambert: seen through a purely absorbing slab, the sky is dimmed by exp(-tau / cos).
#[test]
fn collimated_transmittance_is_beer_lambert() {
    for (tau, cos_theta) in [(0.5f32, 1.0f32), (1.0, 0.6), (2.0, 0.9)] {
        let t = tracer(
            slab(tau),
            PhaseLobes::henyey_greenstein(0.0),
            0.0,
            environment(two_tone_sky(1.0, 0.0), None),
            UVec2::ONE,
        );
        let dir = Vec3::new((1.0 - cos_theta * cos_theta).sqrt(), cos_theta, 0.0);
        let origin = Vec3::new(0.0, -5.0, 0.0);
        let expected = f64::from((-tau / cos_theta).exp());
        let (seen, error) = mean_and_error(20_000, |rng| {
            f64::from(t.ray_radiance(origin, dir, f32::INFINITY, rng).x)
        });
        assert!(
            (seen - expected).abs() < 4.0 * error + 1e-4,
            "{tau}: {seen} vs {expected}"
        );
        let (ratio, error) = mean_and_error(20_000, |rng| {
            f64::from(t.volume.transmittance(origin, dir, f32::INFINITY, rng))
        });
        assert!(
            (ratio - expected).abs() < 4.0 * error + 1e-4,
            "{tau}: {ratio} vs {expected}"
        );
    }
}

/// Diffuse reflectance and transmittance of a conservative slab under a sky of radiance 1 from
/// above, against adding-doubling: the reflected (transmitted) flux over pi is the mean radiance
/// seen looking down from above (up from below) along cosine-distributed directions.
#[test]
fn conservative_slab_matches_adding_doubling() {
    for (tau, g) in [(1.0f32, 0.0f32), (4.0, 0.7)] {
        let (r_expected, t_expected) = diffuse_reflectance_transmittance(
            &Slab {
                optical_depth: f64::from(tau),
                albedo: 1.0,
                g: f64::from(g),
            },
            24,
        );
        let t = tracer(
            slab(tau),
            PhaseLobes::henyey_greenstein(g),
            1.0,
            environment(two_tone_sky(1.0, 0.0), None),
            UVec2::ONE,
        );
        let flux = |origin: Vec3, up: Vec3| {
            mean_and_error(60_000, |rng| {
                let dir = cosine_hemisphere(up, rng.next_vec2());
                f64::from(t.ray_radiance(origin, dir, f32::INFINITY, rng).x)
            })
        };
        let (r, r_error) = flux(Vec3::new(0.0, 101.0, 0.0), Vec3::NEG_Y);
        let (tr, t_error) = flux(Vec3::new(0.0, -1.0, 0.0), Vec3::Y);
        let what = format!(
            "tau {tau} g {g}: R {r} +- {r_error} vs {r_expected}, T {tr} +- {t_error} vs {t_expected}"
        );
        assert!((r - r_expected).abs() < 4.0 * r_error + 1e-3, "{what}");
        assert!((tr - t_expected).abs() < 4.0 * t_error + 1e-3, "{what}");
    }
}

/// Energy conservation under the sun: a conservative slab lit by a (wide) sun from straight
/// above reflects and transmits all of it, so the fluxes seen above and below (the direct beam
/// included, through the sun's disc) add up to the incident irradiance. This exercises sun
/// next-event estimation, the sun probe and the sun disc seen directly.
#[test]
fn sunlit_conservative_slab_conserves_energy() {
    let t = tracer(
        slab(2.0),
        PhaseLobes::approximate_mie(20.0),
        1.0,
        environment(two_tone_sky(0.0, 0.0), Some(sun(Vec3::Y, 5.0))),
        UVec2::ONE,
    );
    let flux = |origin: Vec3, up: Vec3| {
        mean_and_error(60_000, |rng| {
            let dir = cosine_hemisphere(up, rng.next_vec2());
            std::f64::consts::PI * f64::from(t.ray_radiance(origin, dir, f32::INFINITY, rng).x)
        })
    };
    let (r, r_error) = flux(Vec3::new(0.0, 101.0, 0.0), Vec3::NEG_Y);
    let (tr, t_error) = flux(Vec3::new(0.0, -1.0, 0.0), Vec3::Y);
    let error = (r_error * r_error + t_error * t_error).sqrt();
    assert!(
        (r + tr - 1.0).abs() < 4.0 * error + 2e-3,
        "R {r} + T {tr} (+- {error})"
    );
    assert!(r > 0.05 && tr > 0.5, "R {r}, T {tr}");
}

/// A sunlit cube over a ground seen at one pixel: two seeds give estimates that agree within
/// their estimated variance, and the same seed gives the same image however the passes split.
#[test]
fn seeds_agree_within_variance_and_repeat_exactly() {
    use cloudscape_reference::ProgressiveRender;
    use cloudscape_reference::environment::SunDisc;
    let cube = HomogeneousBox {
        bounds: Aabb {
            min: Vec3::new(-400.0, 1000.0, -2400.0),
            max: Vec3::new(400.0, 1800.0, -1600.0),
        },
        extinction_per_m: 0.02,
    };
    let sun = SunDisc {
        direction: Vec3::new(0.3, 0.6, 0.2).normalize(),
        irradiance: Vec3::splat(5.0),
        cos_radius: 0.2679f32.to_radians().cos(),
        limb_darkening: 0.0,
    };
    let mut env = environment(two_tone_sky(0.3, 0.4), Some(sun));
    env.ground_albedo = Some(Vec3::splat(0.2));
    let mut t = tracer(
        cube,
        PhaseLobes::approximate_mie(20.0),
        1.0,
        env,
        UVec2::new(6, 4),
    );
    t.frame = cloudscape::frame::Frame::from_scene(
        &cloudscape::scene::Scene {
            camera: cloudscape::scene::Camera {
                look_at_m: Some([0.0, 1400.0, -2000.0]),
                fov_y_deg: 30.0,
                ..Default::default()
            },
            ..Default::default()
        },
        UVec2::new(6, 4),
    );
    let render = |seed: u64, passes: &[u32]| {
        let mut r = ProgressiveRender::new(&t, seed);
        for &spp in passes {
            assert!(r.run_pass(spp, &|| false, &|_| {}));
        }
        r
    };
    let (a, b) = (render(1, &[96]), render(2, &[96]));
    let mut outliers = 0;
    for (x, y) in (0..6).flat_map(|x| (0..4).map(move |y| (x, y))) {
        let (pa, pb) = (a.pixel(x, y), b.pixel(x, y));
        let luminance = |m: glam::DVec3| m.dot(glam::DVec3::new(0.2126, 0.7152, 0.0722));
        let sigma = (pa.luminance_variance_of_mean + pb.luminance_variance_of_mean).sqrt();
        let gap = (luminance(pa.mean) - luminance(pb.mean)).abs();
        assert!(gap < 5.0 * sigma + 1e-6, "pixel {x},{y}: {pa:?} vs {pb:?}");
        outliers += usize::from(gap > 3.0 * sigma);
        assert!(pa.samples == 96 && sigma > 0.0);
    }
    assert!(
        outliers <= 1,
        "{outliers} pixels differ by more than 3 sigma"
    );
    assert_eq!(render(1, &[40, 56]).image(), a.image());
    assert_eq!(a.stats().non_finite, 0);
    // Alpha holds the share of each pixel's paths that met cloud: the report's cloud mask.
    let image = a.image();
    let share = |x: usize, y: usize| image.pixels[y * 6 + x][3];
    assert!(share(2, 1) > 0.9 && share(3, 2) > 0.9, "{}", share(2, 1));
    assert_eq!(share(0, 1), 0.0, "only ground and sky beside the cube");
    // A render continuing seed 1 from sample 40 holds exactly the samples the first 40 lack.
    let mut rest = ProgressiveRender::starting_at(&t, 1, 40);
    assert!(rest.run_pass(56, &|| false, &|_| {}));
    let (first, rest) = (render(1, &[40]).image(), rest.image());
    for ((p, q), whole) in first.pixels.iter().zip(&rest.pixels).zip(&a.image().pixels) {
        for c in 0..3 {
            let joined = (40.0 * p[c] + 56.0 * q[c]) / 96.0;
            assert!((joined - whole[c]).abs() <= 1e-5 * whole[c].abs().max(1e-3));
        }
    }
}

/// The forward peak of cloud droplets converges: under a slab of optical depth 4 lit by the real
/// sun 60 degrees up, looking up 25 degrees from the sun, the light comes mostly from paths that
/// scatter a few times within a degree of the sun's direction. Phase sampling alone meets such a
/// direction at a deep vertex only rarely and then as a firefly (relative error 0.27 at this
/// sample count without the probe); the sun probe draws it on purpose (0.06).
#[test]
fn the_forward_peak_under_a_slab_converges() {
    let sun_direction = Vec3::new(0.5, 0.75f32.sqrt(), 0.0);
    let t = tracer(
        slab(4.0),
        PhaseLobes::approximate_mie(20.0),
        1.0,
        environment(two_tone_sky(0.0, 0.0), Some(sun(sun_direction, 0.2679))),
        UVec2::ONE,
    );
    let view = glam::Quat::from_rotation_z(25f32.to_radians()) * sun_direction;
    let (mean, error) = mean_and_error(4000, |rng| {
        f64::from(
            t.ray_radiance(Vec3::new(0.0, -1.0, 0.0), view, f32::INFINITY, rng)
                .x,
        )
    });
    assert!(mean > 0.0 && error / mean < 0.08, "{mean} +- {error}");
}
