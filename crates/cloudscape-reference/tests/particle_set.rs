//! The particle technique's particles as a path-traced medium (`ParticleSetMedium`): its
//! extinction is the brute-force sum over the particles, its majorants bound it, and a render of
//! a few particles under the default scene's sun shows them.

use cloudscape::particles::density::{NoiseVolume, ReferenceParticle};
use cloudscape::particles::generate::Particle;
use cloudscape::particles::gpu::NOISE_VOLUME_SIZE;
use cloudscape::particles::optical_depth::particle_rotation;
use cloudscape::scene::{ParticleStyle, Scene};
use cloudscape_reference::geometry::Aabb;
use cloudscape_reference::medium::Medium;
use cloudscape_reference::rng::Rng;
use cloudscape_reference::tracking::TrackedMedium;
use cloudscape_reference::{ParticleSetMedium, PathTracer, ProgressiveRender};
use glam::{UVec2, Vec2, Vec3};

const STYLES: [ParticleStyle; 3] = [
    ParticleStyle::Smooth,
    ParticleStyle::Thresholded,
    ParticleStyle::Pyroclastic,
];
/// Extinction of density 1, m^-1.
const SIGMA_MAX_PER_M: f32 = 0.05;

fn reference(style: ParticleStyle) -> ReferenceParticle {
    ReferenceParticle { style, seed: 7 }
}

/// A uniform point of the box.
fn point_in(b: &Aabb, rng: &mut Rng) -> Vec3 {
    let u = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
    b.min + (b.max - b.min) * u
}

/// `count` particles of random sizes, densities (some zero) and ids in a 2 km box.
fn random_particles(count: u64, seed: u64) -> Vec<Particle> {
    let region = Aabb {
        min: Vec3::new(-1000.0, 500.0, -1000.0),
        max: Vec3::new(1000.0, 2500.0, 1000.0),
    };
    (0..count)
        .map(|i| {
            let mut rng = Rng::for_sample(seed, 0, i);
            let centre_m = point_in(&region, &mut rng);
            let radius_m = 50.0 + 350.0 * rng.next_f32();
            let height_m = radius_m * (0.4 + 0.8 * rng.next_f32());
            let density = if i % 10 == 0 {
                0.0
            } else {
                2.0 * rng.next_f32()
            };
            Particle {
                centre_m,
                radius_m,
                height_m,
                density,
                sun_optical_depth: 0.0,
                id: (rng.next_f32() * u32::MAX as f32) as u32,
                optical_depth_up: 0.0,
                optical_depth_down: 0.0,
                ring: 0,
                reserved: 0,
            }
        })
        .collect()
}

/// Query points: half uniform over the particles' surroundings, half inside random particles
/// (where the medium is).
fn query_points(particles: &[Particle], count: u64, seed: u64) -> Vec<Vec3> {
    let around = Aabb {
        min: Vec3::new(-1500.0, 0.0, -1500.0),
        max: Vec3::new(1500.0, 3000.0, 1500.0),
    };
    (0..count)
        .map(|i| {
            let mut rng = Rng::for_sample(seed, 1, i);
            if i % 2 == 0 {
                return point_in(&around, &mut rng);
            }
            let p =
                &particles[(rng.next_f32() * particles.len() as f32) as usize % particles.len()];
            let unit = Aabb {
                min: Vec3::splat(-1.0),
                max: Vec3::splat(1.0),
            };
            let radii = Vec3::new(p.radius_m, p.height_m, p.radius_m);
            p.centre_m + point_in(&unit, &mut rng) * radii
        })
        .collect()
}

/// The definition, particle by particle: `sigma_max * density * density(q * local)` with
/// `local = (p - centre) / (radius, height, radius)` and `q = particle_rotation(id)`, as
/// `particle_segment` in `particle_render.wgsl` reads the reference particle, `density` the
/// reference particle's with its noise from `volume` (as the GPU bakes its tables) or, without
/// it, evaluated exactly.
fn brute_force(
    particles: &[Particle],
    reference: &ReferenceParticle,
    volume: Option<&NoiseVolume>,
    p: Vec3,
) -> f32 {
    particles
        .iter()
        .map(|k| {
            let local = (p - k.centre_m) / Vec3::new(k.radius_m, k.height_m, k.radius_m);
            let q = particle_rotation(k.id) * local;
            let density = volume.map_or_else(|| reference.density(q), |v| v.density(q));
            SIGMA_MAX_PER_M * k.density * density
        })
        .sum()
}

#[test]
fn extinction_is_the_sum_over_the_particles() {
    let particles = random_particles(300, 1);
    for style in STYLES {
        let reference = reference(style);
        let medium = ParticleSetMedium::new(&particles, reference, SIGMA_MAX_PER_M);
        assert_eq!(medium.len(), 270, "the zero-density particles are left out");
        let volume = NoiseVolume::bake(&reference, NOISE_VOLUME_SIZE);
        assert_eq!(medium.noise(), &volume);
        let (mut inside, mut error, mut total) = (0, 0.0f64, 0.0f64);
        for p in query_points(&particles, 4000, 2) {
            let expected = brute_force(&particles, &reference, Some(&volume), p);
            let got = medium.extinction_per_m(p);
            assert!(
                (got - expected).abs() <= 1e-5 * expected + 1e-7,
                "{style:?} at {p}: {got} vs {expected}"
            );
            inside += usize::from(expected > 0.0);
            // The baked noise is within its trilinear error of the exact one.
            let exact = brute_force(&particles, &reference, None, p);
            error += f64::from((got - exact).abs());
            total += f64::from(exact);
        }
        assert!(
            inside > 1000,
            "{style:?}: only {inside} points in the medium"
        );
        eprintln!(
            "{style:?}: baked noise off the exact by {:.4}",
            error / total
        );
        assert!(error < 0.005 * total, "{style:?}: {error} of {total}");
    }
    // Outside every particle, and without particles, there is nothing.
    let medium = ParticleSetMedium::new(&particles, reference(ParticleStyle::Smooth), 1.0);
    assert_eq!(medium.extinction_per_m(Vec3::new(0.0, 10_000.0, 0.0)), 0.0);
    let empty = ParticleSetMedium::new(&[], reference(ParticleStyle::Smooth), 1.0);
    assert!(empty.is_empty());
    assert_eq!(empty.extinction_per_m(Vec3::ZERO), 0.0);
    assert_eq!(empty.max_extinction_in_box(&medium.support().grid_box), 0.0);
}

#[test]
fn majorants_bound_the_extinction() {
    let particles = random_particles(400, 3);
    for (style, nested) in STYLES.into_iter().flat_map(|s| [(s, false), (s, true)]) {
        let mut medium = ParticleSetMedium::new(&particles, reference(style), SIGMA_MAX_PER_M);
        if nested {
            // Levels 200 m, 400 m, 800 m and the whole set (1.4 km) wide about a corner.
            medium = medium.nested_about(Vec3::new(-300.0, 0.0, 200.0), 200.0);
        }
        let tracked = TrackedMedium::new(medium, 1 << 15);
        assert_eq!(tracked.grid.level_count(), if nested { 5 } else { 1 });
        let (mut in_medium, mut tightness) = (0, 0.0f64);
        for p in query_points(&particles, 60_000, 4) {
            let sigma = tracked.medium.extinction_per_m(p);
            let majorant = tracked.grid.majorant_at(p);
            assert!(sigma <= majorant, "{style:?} at {p}: {sigma} > {majorant}");
            if sigma > 0.0 {
                in_medium += 1;
                tightness += f64::from(sigma / majorant);
            }
        }
        assert!(in_medium > 20_000, "{style:?}: {in_medium}");
        eprintln!(
            "{style:?} (nested {nested}): mean extinction / majorant {:.3}, mean majorant {:.4} m^-1",
            tightness / in_medium as f64,
            tracked.grid.mean_majorant_per_m()
        );
        // Box bounds directly, over small boxes of random points.
        let mut rng = Rng::for_sample(5, 0, 0);
        for p in query_points(&particles, 400, 6) {
            let half = Vec3::splat(5.0 + 100.0 * rng.next_f32());
            let b = Aabb {
                min: p - half,
                max: p + half,
            };
            let bound = tracked.medium.max_extinction_in_box(&b);
            for _ in 0..25 {
                let q = point_in(&b, &mut rng);
                let sigma = tracked.medium.extinction_per_m(q);
                assert!(
                    sigma <= bound,
                    "{style:?} at {q} in {b:?}: {sigma} > {bound}"
                );
            }
        }
        // Along rays, the walk's stretches come in order and bound the extinction at every
        // point of the ray with medium (the nested levels' stretches included).
        let mut rng = Rng::for_sample(10, 0, 0);
        for _ in 0..200 {
            let origin = Vec3::new(-3000.0, 0.0, -3000.0) + rng.next_vec3() * 6000.0;
            let target = point_in(&tracked.grid.bounds(), &mut rng);
            let dir = (target - origin).normalize();
            let mut segments = Vec::new();
            let _: std::ops::ControlFlow<()> = tracked.grid.walk(origin, dir, 1e4, |s| {
                segments.push(s);
                std::ops::ControlFlow::Continue(())
            });
            assert!(segments.windows(2).all(|w| w[0].end <= w[1].start));
            for _ in 0..100 {
                let t = rng.next_f32() * 1e4;
                let sigma = tracked.medium.extinction_per_m(origin + dir * t);
                if sigma > 0.0 {
                    let bound = segments
                        .iter()
                        .find(|s| s.start <= t && t <= s.end)
                        .map_or(0.0, |s| s.majorant_per_m);
                    assert!(sigma <= bound, "{style:?} at t {t}: {sigma} > {bound}");
                }
            }
        }
        // Nothing outside the particles' bounds.
        let outside = Vec3::new(0.0, 5000.0, 0.0);
        assert_eq!(tracked.grid.majorant_at(outside), 0.0);
    }
}

#[test]
fn a_hundred_thousand_particles_build_and_answer_quickly() {
    // A layer of particles over 20 km, as the ring grid makes them: overlapping neighbours.
    let side = 316u64;
    let cell = 20_000.0 / side as f32;
    let particles: Vec<Particle> = (0..side * side)
        .map(|i| {
            let mut rng = Rng::for_sample(8, 0, i);
            let (x, z) = ((i % side) as f32, (i / side) as f32);
            Particle {
                centre_m: Vec3::new(
                    (x + rng.next_f32()) * cell - 10_000.0,
                    1500.0 + 200.0 * rng.next_f32(),
                    (z + rng.next_f32()) * cell - 10_000.0,
                ),
                radius_m: 1.1 * cell,
                height_m: 0.8 * cell,
                density: rng.next_f32(),
                sun_optical_depth: 0.0,
                id: i as u32,
                optical_depth_up: 0.0,
                optical_depth_down: 0.0,
                ring: 0,
                reserved: 0,
            }
        })
        .collect();
    let start = std::time::Instant::now();
    let medium = ParticleSetMedium::new(&particles, reference(ParticleStyle::Smooth), 0.05);
    let tracked = TrackedMedium::new(medium, 1 << 18);
    let built = start.elapsed();
    let start = std::time::Instant::now();
    let mut rng = Rng::for_sample(9, 0, 0);
    let b = tracked.grid.bounds();
    for _ in 0..20_000 {
        let p = point_in(&b, &mut rng);
        assert!(tracked.medium.extinction_per_m(p) <= tracked.grid.majorant_at(p));
    }
    eprintln!(
        "{} particles: medium and 2^18 majorant cells in {built:?}, 20k queries in {:?}",
        tracked.medium.len(),
        start.elapsed()
    );
}

/// Luminance of a colour.
fn luminance(c: glam::DVec3) -> f64 {
    c.dot(glam::DVec3::new(0.2126, 0.7152, 0.0722))
}

/// Whether the ray `origin + t dir` meets the ellipsoid of `p` grown by `scale`.
fn hits(p: &Particle, scale: f32, origin: Vec3, dir: Vec3) -> bool {
    let radii = Vec3::new(p.radius_m, p.height_m, p.radius_m) * scale;
    let (o, d) = ((origin - p.centre_m) / radii, dir / radii);
    let (a, b, c) = (d.dot(d), o.dot(d), o.dot(o) - 1.0);
    let disc = b * b - a * c;
    disc > 0.0 && -b + disc.sqrt() > 0.0
}

#[test]
fn a_render_of_a_few_particles_shows_them_lit_by_the_scene() {
    // The default scene, looking away from its sun at a small cloud of particles 3 km away.
    let mut scene = Scene::default();
    let sun = cloudscape::environment::Environment::from_scene(&scene)
        .sun
        .direction;
    let away = -Vec2::new(sun.x, sun.z).normalize() * 3000.0;
    let focus = Vec3::new(away.x, 700.0, away.y);
    scene.camera.look_at_m = Some(focus.to_array());
    scene.camera.fov_y_deg = 35.0;
    let offsets = [
        (Vec3::ZERO, 450.0),
        (Vec3::new(450.0, 120.0, 0.0), 350.0),
        (Vec3::new(-400.0, -60.0, 100.0), 320.0),
        (Vec3::new(0.0, 250.0, -250.0), 300.0),
        (Vec3::new(100.0, -150.0, 350.0), 280.0),
    ];
    let particles: Vec<Particle> = offsets
        .iter()
        .enumerate()
        .map(|(i, &(offset, radius_m))| Particle {
            centre_m: focus + offset,
            radius_m,
            height_m: 0.8 * radius_m,
            density: 1.0,
            sun_optical_depth: 0.0,
            id: 1000 + i as u32,
            optical_depth_up: 0.0,
            optical_depth_down: 0.0,
            ring: 0,
            reserved: 0,
        })
        .collect();
    let size = UVec2::new(48, 27);
    let particle = reference(ParticleStyle::Smooth);
    let sigma = 0.2;
    let tracer = PathTracer::for_particle_set(&scene, size, &particles, particle, sigma, 1 << 15);
    let clear = PathTracer::for_particle_set(&scene, size, &[], particle, sigma, 1 << 15);
    assert_eq!(tracer.frame, clear.frame);
    assert_eq!(tracer.environment, clear.environment);
    fn render(t: &PathTracer<ParticleSetMedium>) -> ProgressiveRender<'_, ParticleSetMedium> {
        let mut r = ProgressiveRender::new(t, 11);
        assert!(r.run_pass(32, &|| false, &|_| {}));
        r
    }
    let start = std::time::Instant::now();
    let (cloudy, sky) = (render(&tracer), render(&clear));
    eprintln!("rendered in {:?}", start.elapsed());
    assert_eq!(cloudy.stats().non_finite, 0);
    let image = cloudy.image();
    assert!(
        image
            .pixels
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite() && *c >= 0.0))
    );
    // Pixels whose every corner looks through the particles' inner half, and sky pixels that
    // miss them by a wide margin.
    let (mut core, mut clear_sky) = (Vec::new(), Vec::new());
    for (x, y) in (0..size.x).flat_map(|x| (0..size.y).map(move |y| (x, y))) {
        let rays: Vec<(Vec3, Vec3)> = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
            .iter()
            .map(|&(u, v)| {
                tracer
                    .frame
                    .camera_ray(Vec2::new(x as f32 + u, y as f32 + v))
            })
            .collect();
        if rays
            .iter()
            .all(|&(o, d)| particles.iter().any(|p| hits(p, 0.6, o, d)))
        {
            core.push((x, y));
        }
        if rays
            .iter()
            .all(|&(o, d)| d.y > 0.01 && !particles.iter().any(|p| hits(p, 1.3, o, d)))
        {
            clear_sky.push((x, y));
        }
    }
    assert!(core.len() >= 10, "{} core pixels", core.len());
    assert!(
        clear_sky.len() >= 100,
        "{} clear sky pixels",
        clear_sky.len()
    );
    let mean = |r: &ProgressiveRender<ParticleSetMedium>, pixels: &[(u32, u32)]| {
        pixels
            .iter()
            .map(|&(x, y)| luminance(r.pixel(x, y).mean))
            .sum::<f64>()
            / pixels.len() as f64
    };
    // The sunlit particles outshine the sky behind them (which the clear render sees exactly:
    // rays that meet no medium see the sky and the sun disc alone), in the mean and in the
    // median pixel (which fireflies of the forward peak do not move).
    let (lit, behind) = (mean(&cloudy, &core), mean(&sky, &core));
    let mut lit_pixels: Vec<f64> = core
        .iter()
        .map(|&(x, y)| luminance(cloudy.pixel(x, y).mean))
        .collect();
    lit_pixels.sort_by(f64::total_cmp);
    let median = lit_pixels[lit_pixels.len() / 2];
    eprintln!("particles {lit:.3} (median {median:.3}), the clear sky there {behind:.3}");
    assert!(lit > 1.5 * behind, "particles {lit} vs sky {behind}");
    assert!(
        median > 1.4 * behind,
        "median particle {median} vs sky {behind}"
    );
    // ... and leave the sky around them as it is (the same rays see the same sky).
    for &(x, y) in &clear_sky {
        let (a, b) = (cloudy.pixel(x, y).mean, sky.pixel(x, y).mean);
        assert!(
            (a - b).abs().max_element() <= 1e-6 * b.max_element(),
            "{x},{y}: {a} vs {b}"
        );
    }
}
