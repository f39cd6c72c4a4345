//! `cloudscape bake`: the particle technique's look-up tables for a scene, with per-table
//! timings, sizes and checks; `--bench` times each bake several times.

use crate::common::{GpuArgs, SceneArgs, progress_bar};
use anyhow::{Context, Result};
use clap::Args;
use cloudscape::gpu::GpuContext;
use cloudscape::particles::ParticleTableSpec;
use cloudscape::particles::density::NoiseVolume;
use cloudscape::particles::gpu::{OpticalDepthBaker, OpticalDepthLut};
use cloudscape::particles::optical_depth::{OpticalDepthTable, lookup_accuracy};
use cloudscape::particles::scattering::ScatteringTables;
use cloudscape::particles::store::{self, TableStore};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Arguments of `cloudscape bake`.
#[derive(Args, Debug)]
pub struct BakeArgs {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    gpu: GpuArgs,
    /// Directory to write the table files into (default: the cache directory the renderer reads,
    /// `$CLOUDSCAPE_CACHE_DIR` or `~/.cache/cloudscape`).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Time every bake `--repeat` times (and the optical-depth table's CPU bake beside its GPU
    /// bake) and report the median and fastest.
    #[arg(long)]
    bench: bool,
    /// Repetitions of each bake with `--bench`.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=100))]
    repeat: u32,
    /// Write a PNG of the particle as the tables shade it, seen from the sun's side round to
    /// against the sun (top row), and of the noisy particle's opacity (bottom row).
    #[arg(long, value_name = "PATH.png")]
    preview: Option<PathBuf>,
}

/// Bakes both tables, writes them and prints what they cost and how right they are.
pub fn run(args: BakeArgs) -> Result<()> {
    let doc = args.scene.load(&[])?;
    let spec = ParticleTableSpec::from_scene(&doc.scene);
    let ctx = args.gpu.open(&doc)?;
    let out = TableStore::new(
        args.out
            .clone()
            .unwrap_or_else(|| TableStore::user_cache().dir),
    );
    let repeat = if args.bench { args.repeat } else { 1 };
    let optical_depth = bake_optical_depth(&ctx, &spec, repeat, args.bench)?;
    let path = out.optical_depth_path(spec.optical_depth_key());
    store::optical_depth_file(&optical_depth, spec.optical_depth_key())
        .write(&path)
        .with_context(|| format!("writing {}", path.display()))?;
    eprintln!("  wrote {}", path.display());
    let scattering = bake_scattering(&spec, repeat)?;
    let path = out.scattering_path(spec.scattering_key());
    store::scattering_file(&scattering, spec.scattering_key())
        .write(&path)
        .with_context(|| format!("writing {}", path.display()))?;
    eprintln!("  wrote {}", path.display());
    if let Some(preview) = &args.preview {
        write_preview(preview, &doc.scene, &spec, &optical_depth, &scattering)?;
        eprintln!("  wrote {}", preview.display());
    }
    Ok(())
}

/// Angles between the eye's view and the sunlight's direction in the preview, degrees.
const PREVIEW_ANGLES_DEG: [f32; 6] = [15.0, 60.0, 90.0, 125.0, 155.0, 170.0];
/// Pixels per side of each view in the preview.
const PREVIEW_PIXELS: u32 = 160;

/// The preview PNG: per view angle, the scattered light (top, under the scene's sun, tone mapped
/// as the scene says) and the optical mass through a differently rotated noisy particle (bottom,
/// linear grey, white at the largest).
fn write_preview(
    path: &std::path::Path,
    scene: &cloudscape::scene::Scene,
    spec: &ParticleTableSpec,
    optical_depth: &OpticalDepthTable,
    scattering: &ScatteringTables,
) -> Result<()> {
    use cloudscape::image::HdrImage;
    use cloudscape::particles::optical_depth::particle_rotation;
    use cloudscape::particles::preview::DiscView;
    use cloudscape::post::tonemap::{linear_to_srgb, quantize_u8};
    use glam::{Quat, Vec3};
    let n = PREVIEW_PIXELS;
    let columns = PREVIEW_ANGLES_DEG.len() as u32;
    let mut lit = HdrImage::new(n * columns, n);
    let mut masses = vec![0.0f32; (n * n * columns) as usize];
    let light = Vec3::new(0.2, -0.9, 0.3).normalize();
    let axis = light.any_orthonormal_vector();
    let sun = Vec3::from_array(scene.sun.color) * scene.sun.irradiance;
    for (column, angle) in PREVIEW_ANGLES_DEG.iter().enumerate() {
        let view = DiscView {
            dir: Quat::from_axis_angle(axis, angle.to_radians()) * light,
            pixels: n,
        };
        let (_, radiance) = view.scattering(scattering, &spec.phase, light, 2);
        let mass = view.optical_mass(optical_depth, particle_rotation(column as u32));
        for (k, (l, m)) in radiance.iter().zip(&mass).enumerate() {
            let index = ((k as u32 / n) * n * columns + column as u32 * n + k as u32 % n) as usize;
            let rgb = sun * *l;
            lit.pixels[index] = [rgb.x, rgb.y, rgb.z, 1.0];
            masses[index] = *m;
        }
    }
    let mut image = lit.to_ldr(scene.render.exposure_ev, scene.render.tonemap);
    let largest = masses.iter().copied().fold(0.0, f32::max).max(1e-6);
    image.pixels.extend(masses.iter().map(|m| {
        let grey = quantize_u8(linear_to_srgb(m / largest));
        [grey, grey, grey, 255]
    }));
    image.height *= 2;
    image
        .write_png(path)
        .with_context(|| format!("writing {}", path.display()))
}

/// Bakes the optical-depth table on the GPU `repeat` times, with the CPU bake beside it when
/// benchmarking; prints the times and the look-up accuracy.
fn bake_optical_depth(
    ctx: &GpuContext,
    spec: &ParticleTableSpec,
    repeat: u32,
    with_cpu: bool,
) -> Result<OpticalDepthTable> {
    let l = spec.optical_depth;
    let baker = OpticalDepthBaker::new(ctx);
    let mut lut: Option<OpticalDepthLut> = None;
    let gpu = time(repeat, || {
        lut = Some(baker.bake(ctx, &spec.particle, l));
        ctx.wait_idle();
    });
    let table = lut.expect("baked at least once").read(ctx);
    let bytes = table.values.len() * 2;
    println!(
        "optical depth {}x{}x{}x{} ({} entries, {}): GPU {} on {}",
        l.start_zenith,
        l.start_azimuth,
        l.dir_zenith,
        l.dir_azimuth,
        table.values.len(),
        size(bytes),
        describe(&gpu),
        ctx.adapter_info().name
    );
    if with_cpu {
        let cpu = time(repeat, || {
            let volume = NoiseVolume::bake(
                &spec.particle,
                cloudscape::particles::gpu::NOISE_VOLUME_SIZE,
            );
            OpticalDepthTable::bake_cpu(l, &volume);
        });
        println!(
            "optical depth on the CPU ({} threads): {}; GPU / CPU time {:.3}",
            rayon_threads(),
            describe(&cpu),
            median(&gpu).as_secs_f64() / median(&cpu).as_secs_f64()
        );
    }
    let accuracy = lookup_accuracy(
        10_000,
        |p| spec.particle.density(p),
        |e, d| table.lookup(e, d),
    );
    println!(
        "optical depth look-up vs direct integration, {} chords over 5 % of the diameter: mean {:.2} %, rms {:.2} %, p95 {:.2} %, max {:.2} %",
        accuracy.chords,
        100.0 * accuracy.mean,
        100.0 * accuracy.rms,
        100.0 * accuracy.p95,
        100.0 * accuracy.max
    );
    Ok(table)
}

/// Bakes the scattering tables `repeat` times with a progress bar; prints the time, the orders
/// and the energy balance.
fn bake_scattering(spec: &ParticleTableSpec, repeat: u32) -> Result<ScatteringTables> {
    let mut result = None;
    let times = time(repeat, || {
        let bar = progress_bar("scattering");
        let baked = store::bake_scattering(spec, &mut |stage, fraction| {
            bar.set_message(stage.to_string());
            bar.set_position((fraction * 1000.0) as u64);
        });
        bar.finish_and_clear();
        result = Some(baked);
    });
    let (tables, report) = result.expect("baked at least once");
    let l = tables.layout;
    let o = spec.orders;
    println!(
        "scattering {}x{}x{} x 2 tables ({}), orders on {}x{} positions x {}x{} directions: {} orders (last ratio {:.3}), {} on the CPU ({} threads)",
        l.entry,
        l.view_zenith,
        l.view_azimuth,
        size(l.len() * 4),
        o.radii,
        o.polar,
        o.directions.zeniths,
        o.directions.azimuths,
        report.orders,
        report.last_order_ratio,
        describe(&times),
        rayon_threads()
    );
    let e = tables.energy_balance(&spec.symmetric_particle(), 200_000);
    println!(
        "energy: single {:.1} % + multiple {:.1} % + transmitted {:.1} % = {:.2} % of the light in (albedo {})",
        100.0 * e.single,
        100.0 * e.multiple,
        100.0 * e.transmitted,
        100.0 * e.total(),
        spec.albedo
    );
    Ok(tables)
}

/// Runs `f` `repeat` times; each run's wall time, sorted.
fn time(repeat: u32, mut f: impl FnMut()) -> Vec<Duration> {
    let mut times: Vec<Duration> = (0..repeat)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed()
        })
        .collect();
    times.sort();
    times
}

fn median(times: &[Duration]) -> Duration {
    times[times.len() / 2]
}

/// "1.234 s" for one run, "median 1.234 s, fastest 1.200 s of 3" for several.
fn describe(times: &[Duration]) -> String {
    if times.len() == 1 {
        return format!("{:.3} s", times[0].as_secs_f64());
    }
    format!(
        "median {:.3} s, fastest {:.3} s of {}",
        median(times).as_secs_f64(),
        times[0].as_secs_f64(),
        times.len()
    )
}

fn size(bytes: usize) -> String {
    if bytes >= 1 << 20 {
        format!("{:.1} MiB", bytes as f64 / f64::from(1 << 20))
    } else {
        format!("{} KiB", bytes / 1024)
    }
}

fn rayon_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}
