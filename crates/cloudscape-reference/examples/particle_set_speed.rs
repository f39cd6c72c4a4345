//! Timing harness: samples per second of the path tracer on the default scene's cloud field and on
//! the particle technique's own particle set of it (as `cloudscape report` traces them), at
//! 160x90 with a few samples per pixel.
//!
//! `cargo run --release -p cloudscape-reference --example particle_set_speed [spp] [seconds] [both|field|particles]`
//! (`REACH=metres` keeps only the particles whose centres are that close to the camera).

use cloudscape::field::CloudField;
use cloudscape::particles::ParticleTableSpec;
use cloudscape::particles::density::RadialProfile;
use cloudscape::particles::generate::{self, Generation};
use cloudscape::scene::Scene;
use cloudscape_reference::geometry::Aabb;
use cloudscape_reference::medium::Medium;
use cloudscape_reference::medium::Support;
use cloudscape_reference::tracking::TrackedMedium;
use cloudscape_reference::{DEFAULT_MAJORANT_CELLS, PathTracer, ProgressiveRender};
use glam::{UVec2, Vec3};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// A medium that counts its extinction queries.
struct Counted<M> {
    medium: M,
    queries: AtomicU64,
}

impl<M: Medium> Medium for Counted<M> {
    fn extinction_per_m(&self, p: Vec3) -> f32 {
        self.queries.fetch_add(1, Ordering::Relaxed);
        self.medium.extinction_per_m(p)
    }
    fn max_extinction_in_box(&self, b: &Aabb) -> f32 {
        self.medium.max_extinction_in_box(b)
    }
    fn support(&self) -> Support {
        self.medium.support()
    }
}

/// `tracer` with its extinction queries counted.
fn counted<M: Medium>(tracer: PathTracer<M>) -> PathTracer<Counted<M>> {
    PathTracer {
        volume: TrackedMedium {
            medium: Counted {
                medium: tracer.volume.medium,
                queries: AtomicU64::new(0),
            },
            grid: tracer.volume.grid,
        },
        phase: tracer.phase,
        albedo: tracer.albedo,
        environment: tracer.environment,
        frame: tracer.frame,
        max_scattering_orders: tracer.max_scattering_orders,
    }
}

/// Extinction queries per sample, and seconds per query, of `spp` samples per pixel within
/// `budget_s`.
fn report<M: Medium>(name: &str, tracer: PathTracer<M>, spp: u32, budget_s: f64) -> f64 {
    let tracer = counted(tracer);
    let mut render = ProgressiveRender::new(&tracer, 1);
    let deadline = Instant::now() + std::time::Duration::from_secs_f64(budget_s);
    let stop = || Instant::now() >= deadline;
    render.run_pass(spp, &stop, &|_| {});
    let stats = render.stats();
    let queries = tracer.volume.medium.queries.load(Ordering::Relaxed) as f64;
    eprintln!(
        "{name}: {:.0} samples/s, {:.0} extinction queries per sample",
        stats.samples_per_second(),
        queries / stats.samples as f64
    );
    stats.samples_per_second()
}

fn main() {
    let mut args = std::env::args().skip(1);
    let spp: u32 = args.next().and_then(|s| s.parse().ok()).unwrap_or(4);
    let budget_s: f64 = args.next().and_then(|s| s.parse().ok()).unwrap_or(20.0);
    let which = args.next().unwrap_or_else(|| "both".into());
    let scene = Scene::default();
    let size = UVec2::new(160, 90);

    let mut field_speed = f64::NAN;
    if which != "particles" {
        let start = Instant::now();
        let field_tracer =
            PathTracer::for_scene(&scene, Path::new(""), size, DEFAULT_MAJORANT_CELLS)
                .expect("the default scene");
        eprintln!("field tracer built in {:?}", start.elapsed());
        field_speed = report("field", field_tracer, spp, budget_s);
    }
    if which == "field" {
        return;
    }
    let field = CloudField::new(&scene, Path::new("")).expect("the default scene");
    field.bake_noise();
    let spec = ParticleTableSpec::from_scene(&scene);
    let generation =
        Generation::from_scene(&scene, RadialProfile::of(&spec.particle).volume_mean());
    let start = Instant::now();
    let mut particles = generate::generate(&field, &generation);
    if let Some(reach) = std::env::var("REACH")
        .ok()
        .and_then(|s| s.parse::<f32>().ok())
    {
        let c = generation.camera_m;
        particles.retain(|p| (p.centre_m - c).length() < reach);
    }
    eprintln!(
        "{} particles generated in {:?}",
        particles.len(),
        start.elapsed()
    );
    let start = Instant::now();
    let tracer = PathTracer::for_particle_set(
        &scene,
        size,
        &particles,
        spec.particle,
        spec.extinction_per_m,
        DEFAULT_MAJORANT_CELLS,
    );
    eprintln!(
        "particle tracer built in {:?}: {} particles in the medium, {} grid levels over {:?}, mean majorant {:.5} m^-1",
        start.elapsed(),
        tracer.volume.medium.len(),
        tracer.volume.grid.level_count(),
        tracer.volume.grid.bounds(),
        tracer.volume.grid.mean_majorant_per_m()
    );
    let particle_speed = report("particles", tracer, spp, budget_s);
    println!(
        "field {field_speed:.0} samples/s, particles {particle_speed:.0} samples/s, ratio {:.1}",
        field_speed / particle_speed
    );
}
