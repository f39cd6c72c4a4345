//! The particle technique on the GPU: generation and the tiled light occlusion against their CPU
//! specifications, light occlusion and its early exit, and volume-aware blending against alpha
//! blending on a sweeping camera.

use cloudscape::frame::Frame;
use cloudscape::gpu::GpuContext;
use cloudscape::gpu::pipeline::{clear_depth, texture_2d};
use cloudscape::gpu::readback::read_texture_rgba16f;
use cloudscape::output::{CloudOutput, SampleGrid};
use cloudscape::particles::generate::{self, Generation, Particle};
use cloudscape::particles::generate_gpu::GenerationCounts;
use cloudscape::particles::occlusion::{self, LightTiles, Walk};
use cloudscape::particles::occlusion_gpu::LightTileCounts;
use cloudscape::particles::optical_depth::ChordProfile;
use cloudscape::particles::render::ParticleRenderer;
use cloudscape::particles::{ParticleTableSpec, density::RadialProfile};
use cloudscape::renderer::{CloudRenderer, Reuse};
use cloudscape::scene::{Scene, SceneDocument};
use cloudscape::technique::{FrameInputs, Technique, TechniqueTargets};
use glam::{UVec2, Vec3};
use std::collections::HashMap;
use std::path::Path;

/// A particle renderer over the shared groups of a [`CloudRenderer`] (which uploads the frame,
/// environment and field time), with its own output and an empty depth buffer.
struct Harness {
    clouds: CloudRenderer,
    particles: ParticleRenderer,
    output: CloudOutput,
    depth: wgpu::TextureView,
}

impl Harness {
    fn new(ctx: &GpuContext, scene: &Scene) -> Harness {
        let clouds = CloudRenderer::new(ctx, scene, Path::new(".")).expect("field builds");
        let particles = ParticleRenderer::new(ctx, &clouds.shared());
        let size = UVec2::new(scene.render.width, scene.render.height);
        let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::RENDER_ATTACHMENT;
        let depth = texture_2d(ctx, "depth", size, wgpu::TextureFormat::Depth32Float, usage)
            .create_view(&Default::default());
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        clear_depth(&mut encoder, &depth, 1.0);
        ctx.queue.submit([encoder.finish()]);
        Harness {
            clouds,
            particles,
            output: CloudOutput::new(ctx, "particles", size),
            depth,
        }
    }

    /// Renders one full-resolution frame of `scene` seen through `frame`; the radiance and
    /// transmittance per texel.
    fn render(&mut self, ctx: &GpuContext, scene: &Scene, frame: &Frame) -> Vec<[f32; 4]> {
        self.clouds.begin_frame(ctx, frame, Reuse::None);
        self.particles
            .configure(ctx, scene, Path::new("."))
            .expect("the particles' tables load");
        let inputs = FrameInputs {
            field: self.clouds.field(),
            frame,
            environment: self.clouds.environment(),
            grid: &SampleGrid::FULL,
            shared: self.clouds.shared(),
            real_time: false,
        };
        self.particles.prepare(ctx, &inputs);
        let targets = TechniqueTargets {
            host_depth: &self.depth,
            output: &self.output,
        };
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.clouds.encode_environment(ctx, &mut encoder, None);
        let region = (UVec2::ZERO, self.output.size);
        let shared = self.clouds.shared();
        self.particles
            .encode_frame_setup(ctx, &mut encoder, &shared, &targets, None);
        self.particles
            .encode(ctx, &mut encoder, &shared, &targets, region, None);
        self.particles.finish_frame(&mut encoder);
        ctx.queue.submit([encoder.finish()]);
        read_texture_rgba16f(ctx, self.output.radiance_texture())
    }

    fn generated(&self, ctx: &GpuContext) -> (Vec<Particle>, GenerationCounts) {
        self.particles.generator().expect("rendered").read(ctx)
    }
}

/// The default scene with a smaller grid (three rings reaching 50 km, the default inner cells).
fn small_grid_scene(overrides: &[&str]) -> Scene {
    let mut all = vec![
        "render.width=96",
        "render.height=64",
        "particles.rings=3",
        "particles.distance_m=50000",
        "particles.resolution_divisor=1",
        "particles.table_resolution=low",
        "render.technique=particles",
        // A small light volume: these tests follow the particles' making, occlusion and blending,
        // and the default volume's cold solve would be most of each frame on a software GPU.
        "lighting.volume_cells_horizontal=16",
        "lighting.volume_cells_vertical=8",
    ];
    all.extend_from_slice(overrides);
    let all: Vec<String> = all.iter().map(|s| s.to_string()).collect();
    SceneDocument::load(None, &all).expect("valid").scene
}

/// One frame of `scene`'s particles made on the GPU: the harness, the frame, the particles and
/// their counts.
fn generated_on_gpu(
    ctx: &GpuContext,
    scene: &Scene,
) -> (Harness, Frame, Vec<Particle>, GenerationCounts) {
    let mut harness = Harness::new(ctx, scene);
    let frame = Frame::from_scene(scene, UVec2::new(96, 64));
    harness.render(ctx, scene, &frame);
    let (particles, counts) = harness.generated(ctx);
    (harness, frame, particles, counts)
}

/// The scene's table spec and its reference particle's mean density.
fn reference_particle(scene: &Scene) -> (ParticleTableSpec, f32) {
    let spec = ParticleTableSpec::from_scene(scene);
    let mean = RadialProfile::of(&spec.particle).volume_mean();
    (spec, mean)
}

fn cpu_generation(scene: &Scene, field_mean: f32, early_exit: bool) -> Generation {
    Generation {
        occlusion_early_exit: early_exit,
        ..Generation::from_scene(scene, field_mean)
    }
}

fn close(a: f32, b: f32, relative: f32, absolute: f32) -> bool {
    (a - b).abs() <= absolute + relative * a.abs().max(b.abs())
}

/// The GPU makes the particles its CPU twin makes: the same count (under 2 % differ, where the
/// field's density sits near the threshold and the GPU's filtered noise and weather differ from
/// the CPU's by a few per cent, as `gpu_field` allows: both where a particle is made and the
/// column span that sets its altitude), and matched by id the same positions, sizes, densities
/// and light occlusion.
#[test]
fn gpu_particles_match_their_cpu_specification() {
    let ctx = GpuContext::for_tests();
    // From above the layer, moved off the grid's lattice, at a time the wind has moved the field.
    let scene = small_grid_scene(&[
        "camera.position_m=[1234.5,3000,-777.7]",
        "render.time_s=90",
        "particles.occlusion=march",
    ]);
    let (mut harness, _, gpu, counts) = generated_on_gpu(&ctx, &scene);
    let (_, mean) = reference_particle(&scene);
    let cpu = generate::generate(harness.clouds.field(), &cpu_generation(&scene, mean, true));
    assert!(
        cpu.len() > 10_000,
        "the default sky makes many particles: {}",
        cpu.len()
    );
    assert_eq!(counts.particles as usize, gpu.len());
    assert_eq!(counts.dropped, 0);
    ctx.wait_idle();
    let stats = harness
        .particles
        .particle_stats(&ctx)
        .expect("a finished frame");
    assert_eq!(
        stats.dropped_tile_entries, 0,
        "no tile's list overflowed: {stats:?}"
    );
    assert!(
        stats.binned > 0 && stats.binned < counts.particles,
        "{stats:?}: culled out of view"
    );
    let by_id: HashMap<u32, &Particle> = cpu.iter().map(|p| (p.id, p)).collect();
    let matched: Vec<(&Particle, &Particle)> = gpu
        .iter()
        .filter_map(|g| by_id.get(&g.id).map(|c| (g, *c)))
        .collect();
    let unmatched = gpu.len() + cpu.len() - 2 * matched.len();
    assert!(
        unmatched * 50 <= cpu.len(),
        "{unmatched} of {} particles differ between GPU and CPU",
        cpu.len()
    );
    // Horizontal positions are exact up to the f32 rounding of a point 6360 km from the planet's
    // centre (0.5 m); altitudes follow the column's span, from the field. Densities and optical
    // depths follow the field, whose GPU twin differs by up to 2 % of the peak at 1 % of points
    // (`gpu_field`); a particle's mass-conserving density scales that up by its cell's volume
    // over its own, so they agree in distribution: exactly at the median, within per cent for
    // most.
    let planet_centre = Vec3::new(0.0, -scene.planet.radius_m, 0.0);
    let up = |p: &Particle| (p.centre_m - planet_centre).normalize();
    for (g, c) in &matched {
        let across = (g.centre_m - c.centre_m).reject_from(up(c)).length();
        assert!(across < 0.6, "GPU {g:?}\nCPU {c:?}");
        assert_eq!(g.ring, c.ring);
    }
    let quantiles = |f: &dyn Fn(&Particle, &Particle) -> Option<f32>| {
        let mut e: Vec<f32> = matched.iter().filter_map(|(g, c)| f(g, c)).collect();
        e.sort_by(f32::total_cmp);
        [0.5, 0.9, 0.99].map(|q| e[((e.len() - 1) as f32 * q) as usize])
    };
    let altitude = quantiles(&|g, c| Some((g.centre_m - c.centre_m).dot(up(c)).abs()));
    let relative = |a: f32, b: f32| (a - b).abs() / b.abs().max(1e-3);
    let radius = quantiles(&|g, c| Some(relative(g.radius_m, c.radius_m)));
    let density = quantiles(&|g, c| Some(relative(g.density, c.density)));
    let sun = quantiles(&|g, c| {
        (g.sun_optical_depth < 4.0 && c.sun_optical_depth < 4.0)
            .then(|| (g.sun_optical_depth - c.sun_optical_depth).abs())
    });
    eprintln!(
        "altitude {altitude:?} m, relative radius {radius:?}, density {density:?}; sun optical \
         depth {sun:?}"
    );
    assert!(
        altitude[0] < 0.6 && altitude[1] < 10.0,
        "altitude {altitude:?}"
    );
    assert!(radius[0] < 1e-4 && radius[1] < 0.03, "radius {radius:?}");
    assert!(density[0] < 0.01 && density[1] < 0.1, "density {density:?}");
    assert!(sun[0] < 0.01 && sun[1] < 0.1, "sun optical depth {sun:?}");
}

/// The seed's tiled light occlusion on the GPU walks the light tiles its CPU specification walks:
/// the GPU's particles, occluded again on the CPU, get the same optical depth toward the sun (up
/// to the f32 rounding that can move a particle on a tile's edge into the next tile).
#[test]
fn tiled_light_occlusion_matches_its_cpu_specification() {
    let ctx = GpuContext::for_tests();
    let scene = small_grid_scene(&[
        "camera.position_m=[1234.5,1000,-777.7]",
        "sun.elevation_deg=35",
    ]);
    let (harness, frame, gpu, counts) = generated_on_gpu(&ctx, &scene);
    let tiles_counted = harness
        .particles
        .light_occlusion()
        .expect("tiles")
        .read(&ctx);
    assert_eq!(
        tiles_counted,
        LightTileCounts::default(),
        "no tile overflowed, none outside"
    );
    let (spec, mean) = reference_particle(&scene);
    let g = Generation::from_scene(&scene, mean).for_frame(&frame);
    let tiles = LightTiles::new(&g);
    let chord = ChordProfile::of_particle(&spec.particle);
    let walk = Walk {
        tiles: &tiles,
        sigma_max_per_m: g.sigma_max_per_m,
        chord: &chord,
        early_exit: true,
    };
    let mut cpu = gpu.clone();
    let walked = occlusion::occlude(&mut cpu, &walk);
    eprintln!(
        "{} particles; list entries walked: GPU {}, CPU {walked}",
        gpu.len(),
        counts.occlusion_steps
    );
    let mut errors: Vec<f32> = gpu
        .iter()
        .zip(&cpu)
        .filter(|(a, b)| a.sun_optical_depth < 4.0 && b.sun_optical_depth < 4.0)
        .map(|(a, b)| (a.sun_optical_depth - b.sun_optical_depth).abs())
        .collect();
    errors.sort_by(f32::total_cmp);
    let quantile = |q: f32| errors[((errors.len() - 1) as f32 * q) as usize];
    let occluded = cpu.iter().filter(|p| p.sun_optical_depth > 0.1).count();
    eprintln!(
        "|GPU - CPU| optical depth: median {}, 99th {}; {occluded} occluded",
        quantile(0.5),
        quantile(0.99)
    );
    assert!(
        occluded * 4 > cpu.len(),
        "most particles lie under others: {occluded}"
    );
    assert!(quantile(0.5) < 1e-3 && quantile(0.99) < 0.05);
}

/// Light occlusion, by either method: particles under more cloud see less sun, and the march or
/// walk toward the sun stops at transmittance 0.01 without changing any optical depth below that
/// threshold.
#[test]
fn light_occlusion_darkens_low_particles_and_its_early_exit_only_skips_opaque_paths() {
    for method in ["tiles", "march"] {
        occlusion_darkens_low_particles(&format!("particles.occlusion={method}"));
    }
}

fn occlusion_darkens_low_particles(method: &str) {
    let ctx = GpuContext::for_tests();
    let scene = small_grid_scene(&["sun.elevation_deg=60", method]);
    let mut harness = Harness::new(&ctx, &scene);
    let frame = Frame::from_scene(&scene, UVec2::new(96, 64));
    harness.render(&ctx, &scene, &frame);
    let (with_exit, counts_with) = harness.generated(&ctx);
    let mut without = scene.clone();
    without.particles.occlusion_early_exit = false;
    harness.render(&ctx, &without, &frame);
    let (without_exit, counts_without) = harness.generated(&ctx);
    eprintln!(
        "{method}: occlusion steps with the early exit {}, without {}",
        counts_with.occlusion_steps, counts_without.occlusion_steps
    );
    assert!(
        counts_with.occlusion_steps < counts_without.occlusion_steps,
        "{counts_with:?} vs {counts_without:?}"
    );
    let full: HashMap<u32, f32> = without_exit
        .iter()
        .map(|p| (p.id, p.sun_optical_depth))
        .collect();
    // Generation lists the particles in a different order each run, and the light tiles sum the
    // same occluders in that order: equal up to f32 rounding.
    let same = |a: f32, b: f32| close(a, b, 1e-4, 1e-5);
    for p in &with_exit {
        let reference = full[&p.id];
        if reference < 4.0 {
            assert!(same(p.sun_optical_depth, reference), "{p:?} vs {reference}");
        } else {
            assert!(p.sun_optical_depth > 4.6 || same(p.sun_optical_depth, reference));
        }
    }
    let (bottom, top) = harness.clouds.field().altitude_range_m().expect("a layer");
    let mean_depth = |lo: f32, hi: f32| {
        let band: Vec<f32> = full_particles(&without_exit, lo, hi);
        band.iter().sum::<f32>() / band.len().max(1) as f32
    };
    let third = (top - bottom) / 3.0;
    let low = mean_depth(bottom, bottom + third);
    let high = mean_depth(top - third, top);
    assert!(low > 2.0 * high, "low particles {low} vs high {high}");
}

fn full_particles(particles: &[Particle], lo: f32, hi: f32) -> Vec<f32> {
    particles
        .iter()
        .filter(|p| p.ring == 0 && p.centre_m.y >= lo && p.centre_m.y < hi)
        .map(|p| p.sun_optical_depth)
        .collect()
}

/// Two intersecting particles, one in shadow and one in sunlight, seen from a camera sweeping
/// past the point where their distance order flips. Alpha blending in distance order swaps which
/// covers the other at that point: the image pops. Volume-aware blending merges them by density
/// whatever their order: the image changes as smoothly there as anywhere else.
#[test]
fn volume_aware_blending_does_not_pop_where_alpha_blending_does() {
    let steps = |blending: &str| -> Vec<f32> {
        let ctx = GpuContext::for_tests();
        let scene = small_grid_scene(&[&format!("particles.blending={blending}"), "layers=[]"]);
        let mut harness = Harness::new(&ctx, &scene);
        let centre = Vec3::new(0.0, 2000.0, -3000.0);
        let particle = |x: f32, shadow: f32, id: u32| Particle {
            centre_m: centre + Vec3::new(x, 0.0, 0.0),
            radius_m: 300.0,
            height_m: 300.0,
            density: 0.3,
            sun_optical_depth: shadow,
            id,
            optical_depth_up: 0.0,
            optical_depth_down: 0.0,
            ring: 0,
            reserved: 0,
        };
        harness.particles.set_particles(Some(vec![
            particle(-150.0, 6.0, 1),
            particle(150.0, 0.0, 2),
        ]));
        let frames: Vec<Vec<[f32; 4]>> = (0..17)
            .map(|k| {
                let angle = (k as f32 - 8.0) * 0.02;
                let eye = centre + 1500.0 * Vec3::new(angle.sin(), 0.0, angle.cos());
                let mut s = scene.clone();
                s.camera.position_m = eye.to_array();
                s.camera.look_at_m = Some(centre.to_array());
                s.camera.fov_y_deg = 40.0;
                harness.render(&ctx, &s, &Frame::from_scene(&s, UVec2::new(96, 64)))
            })
            .collect();
        frames
            .windows(2)
            .map(|w| {
                let diff: f32 = w[0]
                    .iter()
                    .zip(&w[1])
                    .map(|(a, b)| (a[0] - b[0]).abs() + (a[1] - b[1]).abs() + (a[2] - b[2]).abs())
                    .sum();
                diff / w[0].len() as f32
            })
            .collect()
    };
    let volume = steps("volume_aware");
    let alpha = steps("alpha");
    let largest = |s: &[f32]| s.iter().copied().fold(0.0, f32::max);
    let median = |s: &[f32]| {
        let mut v = s.to_vec();
        v.sort_by(f32::total_cmp);
        v[v.len() / 2]
    };
    eprintln!("volume-aware steps {volume:?}\nalpha steps {alpha:?}");
    assert!(
        largest(&alpha) > 4.0 * median(&alpha),
        "alpha blending pops: {alpha:?}"
    );
    assert!(
        largest(&volume) < 2.0 * median(&volume),
        "volume-aware does not: {volume:?}"
    );
}
