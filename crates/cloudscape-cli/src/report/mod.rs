//! `cloudscape report`: the canonical scenes rendered by the GPU ray marcher and by the path
//! tracer, compared, and written up as `docs/realism.md` with the images side by side.
//!
//! Path-traced references are kept in a cache directory keyed by the scene, the size, the sample
//! count and the seed, so tuning the ray marcher reruns only the GPU side.

mod particles;
mod sprites;

use crate::common::{GpuArgs, SceneArgs};
use crate::compare::Comparison;
use crate::reference::deadline_after;
use anyhow::{Context, Result, anyhow};
use clap::Args;
use cloudscape::field::noise::perlin;
use cloudscape::field::{CloudField, VoxelGrid};
use cloudscape::gpu::GpuContext;
use cloudscape::image::{HdrImage, write_image};
use cloudscape::renderer::{Rendered, SceneRenderer};
use cloudscape::scene::{Scene, SceneDocument, Technique};
use cloudscape::temporal::halton;
use cloudscape_reference::medium::Medium;
use cloudscape_reference::{DEFAULT_MAJORANT_CELLS, PathTracer, ProgressiveRender};
use glam::{UVec2, Vec3};
use std::fmt::Write as _;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of `cloudscape report`.
#[derive(Args, Debug)]
pub struct ReportArgs {
    /// Directory of the canonical scene files.
    #[arg(long, default_value = "scenes")]
    scenes: PathBuf,
    /// Directory to write `realism.md` and its images (`realism/`) into.
    #[arg(long, default_value = "docs")]
    out: PathBuf,
    /// Image width in pixels.
    #[arg(long, default_value_t = 160)]
    width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 90)]
    height: u32,
    /// Path-traced samples per pixel (half with each of two seeds, for the noise floor). 256 take
    /// about 15 minutes for the cumulonimbus on 2 cores, a few minutes for the others.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(2..))]
    spp: u32,
    /// Most seconds of path tracing per scene; the image so far is used after it.
    #[arg(long, default_value_t = 1800.0)]
    time_budget: f64,
    /// Seed of the path tracer (the noise-floor half uses the next one).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Where path-traced references are kept between runs (delete it after changing the path
    /// tracer).
    #[arg(long, default_value = "target/realism-cache")]
    cache: PathBuf,
    /// Only the scenes whose name contains this text.
    #[arg(long)]
    only: Option<String>,
    #[command(flatten)]
    gpu: GpuArgs,
}

/// Where a canonical scene comes from.
enum Source {
    /// The embedded default scene with overrides.
    Default(&'static [&'static str]),
    /// A file of the scenes directory.
    File(&'static str),
    /// The generated voxel-grid cloud.
    Voxel,
}

/// A canonical scene of the report.
struct Canonical {
    name: &'static str,
    title: &'static str,
    source: Source,
}

/// The scenes the report covers (issue 3).
const CANONICAL: [Canonical; 6] = [
    Canonical {
        name: "cumulus-noon",
        title: "Cumulus at noon",
        source: Source::Default(&["sun.elevation_deg=65"]),
    },
    Canonical {
        name: "backlit-sunset",
        title: "Cumulus backlit near sunset (silver lining)",
        source: Source::File("backlit-sunset.toml"),
    },
    Canonical {
        name: "overcast-below",
        title: "Overcast stratocumulus seen from below",
        source: Source::File("overcast-stratocumulus.toml"),
    },
    Canonical {
        name: "cumulonimbus",
        title: "Towering cumulonimbus",
        source: Source::File("cumulonimbus.toml"),
    },
    Canonical {
        name: "layer-above",
        title: "The layer seen from above",
        source: Source::File("above-the-layer.toml"),
    },
    Canonical {
        name: "voxel-cloud",
        title: "A single voxel-grid cloud",
        source: Source::Voxel,
    },
];

/// One scene's results.
struct Row {
    name: &'static str,
    title: &'static str,
    comparison: Comparison,
    noise_floor: Comparison,
    samples_per_second: f64,
    spp: f64,
    gpu_ms: f64,
    particles: Option<particles::ParticleRow>,
    sprites: sprites::SpriteRow,
}

/// Renders and compares every canonical scene, then writes the report.
pub fn run(args: ReportArgs) -> Result<()> {
    let images = args.out.join("realism");
    std::fs::create_dir_all(&images).with_context(|| images.display().to_string())?;
    std::fs::create_dir_all(&args.cache).with_context(|| args.cache.display().to_string())?;
    let voxel_dir = std::env::temp_dir().join("cloudscape-report");
    let mut ctx = None;
    let mut rows = Vec::new();
    for canonical in CANONICAL
        .iter()
        .filter(|c| args.only.as_deref().is_none_or(|o| c.name.contains(o)))
    {
        eprintln!("== {}", canonical.title);
        let doc = load(canonical, &args, &voxel_dir)?;
        let ctx = match &ctx {
            Some(c) => c,
            None => ctx.insert(args.gpu.open(&doc)?),
        };
        rows.push(scene_row(canonical, &doc, ctx, &args, &images)?);
    }
    let adapter = ctx.map_or_else(String::new, |c| c.summary());
    let path = args.out.join("realism.md");
    std::fs::write(&path, markdown(&rows, &args, &adapter))
        .with_context(|| path.display().to_string())?;
    eprintln!("wrote {}", path.display());
    Ok(())
}

/// A technique's render of `doc` (its technique replaced by `technique`): the renderer, the
/// images and the wall time of the GPU render, ms.
fn render_with(
    doc: &SceneDocument,
    ctx: &GpuContext,
    technique: Technique,
) -> Result<(SceneRenderer, Scene, Rendered, f64)> {
    let mut scene = doc.scene.clone();
    scene.render.technique = technique;
    let mut renderer = SceneRenderer::new(ctx, &scene, &doc.resolve_path(""))
        .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))?;
    let start = Instant::now();
    let gpu = renderer.render(ctx, &scene, |_| {});
    let gpu_ms = start.elapsed().as_secs_f64() * 1e3;
    Ok((renderer, scene, gpu, gpu_ms))
}

/// Loads a canonical scene at the report's size.
fn load(canonical: &Canonical, args: &ReportArgs, voxel_dir: &Path) -> Result<SceneDocument> {
    let (file, overrides): (Option<PathBuf>, &[&str]) = match canonical.source {
        Source::Default(overrides) => (None, overrides),
        Source::File(name) => (Some(args.scenes.join(name)), &[]),
        Source::Voxel => (Some(write_voxel_scene(voxel_dir)?), &[]),
    };
    let scene_args = SceneArgs {
        scene: file,
        overrides: overrides.iter().map(|s| s.to_string()).collect(),
        width: Some(args.width),
        height: Some(args.height),
        technique: None,
    };
    scene_args.load(&[])
}

/// GPU render, path-traced reference (cached), comparisons and images of one scene.
fn scene_row(
    canonical: &Canonical,
    doc: &SceneDocument,
    ctx: &GpuContext,
    args: &ReportArgs,
    images: &Path,
) -> Result<Row> {
    let scene = &doc.scene;
    let (_, _, gpu, gpu_ms) = render_with(doc, ctx, scene.render.technique)?;
    let reference = cached_reference(doc, args)?;
    let full = average(&reference.halves);
    let image_path = |kind: &str| images.join(format!("{}-{kind}.png", canonical.name));
    let comparison = Comparison::of(&full, &gpu.hdr, Some(&image_path("flip")))?;
    let noise_floor = Comparison::of(&reference.halves[0], &reference.halves[1], None)?;
    gpu.ldr.write_png(&image_path("raymarch"))?;
    let (ev, op) = (scene.render.exposure_ev, scene.render.tonemap);
    write_image(&image_path("reference"), &full, ev, op)?;
    eprintln!(
        "HDR-FLIP {:.4} relMSE {:.4} (noise floor {:.4} {:.4})",
        comparison.flip_mean,
        comparison.relative_mse,
        noise_floor.flip_mean,
        noise_floor.relative_mse
    );
    let key = cache_key(doc, args)?;
    let particles = particles::row(canonical.name, doc, ctx, (args, &key), (&full, images))?;
    let sprites = sprites::row(canonical.name, doc, ctx, (&full, images))?;
    Ok(Row {
        name: canonical.name,
        title: canonical.title,
        comparison,
        noise_floor,
        samples_per_second: reference.samples_per_second,
        spp: reference.spp,
        gpu_ms,
        particles,
        sprites,
    })
}

/// The two half-sample references of a scene and how fast they were traced.
struct Reference {
    halves: [HdrImage; 2],
    samples_per_second: f64,
    spp: f64,
}

/// The path-traced references of the scene's cloud field, from the cache when this scene, size,
/// sample count and seed were traced before; otherwise traced (half the samples with each of two
/// seeds) and cached.
fn cached_reference(doc: &SceneDocument, args: &ReportArgs) -> Result<Reference> {
    let key = cache_key(doc, args)?;
    let size = UVec2::new(doc.scene.render.width, doc.scene.render.height);
    cached_trace(&key, size, args, || {
        PathTracer::for_scene(
            &doc.scene,
            &doc.resolve_path(""),
            size,
            DEFAULT_MAJORANT_CELLS,
        )
        .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))
    })
}

/// The references cached under `key`, or traced at `size` with the path tracer `tracer` makes
/// and cached.
fn cached_trace<M: Medium>(
    key: &str,
    size: UVec2,
    args: &ReportArgs,
    tracer: impl FnOnce() -> Result<PathTracer<M>>,
) -> Result<Reference> {
    let paths = [0, 1].map(|h| args.cache.join(format!("{key}-{h}.exr")));
    let stats_path = args.cache.join(format!("{key}.txt"));
    if let (Ok(a), Ok(b), Ok(stats)) = (
        HdrImage::read(&paths[0]),
        HdrImage::read(&paths[1]),
        std::fs::read_to_string(&stats_path),
    ) {
        let mut numbers = stats.split_whitespace().filter_map(|s| s.parse().ok());
        let (samples_per_second, spp) =
            (numbers.next().unwrap_or(0.0), numbers.next().unwrap_or(0.0));
        eprintln!("reference from the cache ({key})");
        return Ok(Reference {
            halves: [a, b],
            samples_per_second,
            spp,
        });
    }
    let tracer = tracer()?;

    let (mut samples, mut seconds) = (0u64, 0.0);
    let halves = [0u64, 1].map(|h| {
        let mut render = ProgressiveRender::new(&tracer, args.seed * 2 + h);
        let deadline = deadline_after(args.time_budget / 2.0);
        let stop = || deadline.is_some_and(|d| Instant::now() >= d);
        let mut done = 0;
        while done < args.spp / 2 && !stop() {
            render.run_pass(4.min(args.spp / 2 - done), &stop, &|_| {});
            done += 4;
        }
        let stats = render.stats();
        samples += stats.samples;
        seconds += stats.elapsed.as_secs_f64();
        render.image()
    });
    let reference = Reference {
        samples_per_second: samples as f64 / seconds.max(1e-9),
        spp: samples as f64 / f64::from(size.x * size.y),
        halves,
    };
    for (path, half) in paths.iter().zip(&reference.halves) {
        half.write_exr(path)?;
    }
    std::fs::write(
        &stats_path,
        format!("{} {}", reference.samples_per_second, reference.spp),
    )?;
    eprintln!(
        "traced {:.0} samples/s, {:.1} spp",
        reference.samples_per_second, reference.spp
    );
    Ok(reference)
}

/// A name for the references of this scene and these settings: what the path tracer sees, so
/// that tuning the ray marcher's lighting and steps, or their defaults, keeps the cached references.
fn cache_key(doc: &SceneDocument, args: &ReportArgs) -> Result<String> {
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    path_traced_part(&doc.scene)?.to_string().hash(&mut hasher);
    for path in doc.scene.volumes.iter().map(|v| doc.resolve_path(&v.path)) {
        std::fs::read(&path)
            .with_context(|| path.display().to_string())?
            .hash(&mut hasher);
    }
    hash_field(doc, &mut hasher)?;
    (args.spp, args.seed, env!("CARGO_PKG_VERSION")).hash(&mut hasher);
    Ok(format!("{:016x}", hasher.finish()))
}

/// Hashes the scene's cloud field itself, its extinction at a fixed scatter of points through the
/// layers and the voxel boxes, so that a change to the field's code (noise, profiles, coverage)
/// retraces the references as a change to the scene does.
fn hash_field(doc: &SceneDocument, hasher: &mut impl Hasher) -> Result<()> {
    let field = CloudField::new(&doc.scene, &doc.resolve_path(""))
        .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))?;
    let (bottom_m, top_m) = field.altitude_range_m().unwrap_or((0.0, 0.0));
    let layer_box = (
        Vec3::new(-20_000.0, bottom_m, -20_000.0),
        Vec3::new(40_000.0, top_m - bottom_m, 40_000.0),
    );
    let boxes = field.volumes.iter().map(|v| (v.min_m, v.size_m));
    for (min_m, size_m) in std::iter::once(layer_box).chain(boxes) {
        for i in 0..512_u32 {
            let unit = Vec3::new(halton(i + 1, 2), halton(i + 1, 3), halton(i + 1, 5));
            let p = min_m + unit * size_m;
            let extinction = field.extinction_per_m(p, doc.scene.render.time_s);
            extinction.to_bits().hash(hasher);
        }
    }
    Ok(())
}

/// Keys of the `[lighting]` and `[render]` tables that the path tracer reads; the others only
/// steer the real-time techniques.
const PATH_TRACED_KEYS: [(&str, &[&str]); 2] = [
    ("lighting", &["albedo"]),
    ("render", &["width", "height", "time_s"]),
];

/// `scene` as a TOML table without the settings only the real-time techniques read.
fn path_traced_part(scene: &Scene) -> Result<toml::Table> {
    let mut table = toml::Table::try_from(scene)?;
    for real_time_only in ["particles", "sprites", "sprite_clouds"] {
        table.remove(real_time_only);
    }
    for (section, kept) in PATH_TRACED_KEYS {
        if let Some(toml::Value::Table(t)) = table.get_mut(section) {
            t.retain(|key, _| kept.contains(&key));
        }
    }
    Ok(table)
}

/// The pixel-wise mean of two images of one size.
fn average([a, b]: &[HdrImage; 2]) -> HdrImage {
    let pixels = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| std::array::from_fn(|c| 0.5 * (p[c] + q[c])))
        .collect();
    HdrImage {
        pixels,
        ..a.clone()
    }
}

/// Writes the voxel-grid cloud (a few merged puffs over a flat base, roughened by Perlin noise)
/// and its scene file into `dir`; returns the scene file.
fn write_voxel_scene(dir: &Path) -> Result<PathBuf> {
    std::fs::create_dir_all(dir)?;
    let puffs = [
        (Vec3::new(0.5, 0.35, 0.5), 0.3),
        (Vec3::new(0.3, 0.3, 0.45), 0.22),
        (Vec3::new(0.68, 0.33, 0.55), 0.24),
        (Vec3::new(0.52, 0.58, 0.48), 0.22),
        (Vec3::new(0.42, 0.72, 0.52), 0.14),
    ];
    let grid = VoxelGrid::from_fn([64, 48, 64], Vec3::ZERO, Vec3::ONE, |p| {
        let puff = puffs
            .iter()
            .map(|&(c, r)| 1.0 - (p - c).length() / r)
            .fold(0.0f32, f32::max);
        let base = ((p.y - 0.12) * 20.0).clamp(0.0, 1.0);
        ((puff * 3.0 + 0.4 * perlin(p * 8.0, 8, 11)) * base).clamp(0.0, 1.0)
    });
    grid.write_vol(&dir.join("voxel-cloud.vol"))?;
    let path = dir.join("voxel-cloud.toml");
    std::fs::write(&path, VOXEL_SCENE)?;
    Ok(path)
}

/// The scene around the generated voxel cloud: side-lit, seen from below its base.
const VOXEL_SCENE: &str = r#"# Generated by `cloudscape report`: one voxel-grid cumulus.
layers = []

[camera]
position_m = [0.0, 1400.0, -2000.0]
look_at_m = [0.0, 2400.0, -6000.0]
fov_y_deg = 40.0

[sun]
elevation_deg = 40.0
azimuth_deg = 120.0

[[volumes]]
path = "voxel-cloud.vol"
center_m = [0.0, 2400.0, -6000.0]
size_m = [2400.0, 1800.0, 2400.0]
extinction_per_m = 0.06
"#;

/// The report text.
fn markdown(rows: &[Row], args: &ReportArgs, adapter: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Realism: the ray marcher against the path tracer\n\n\
         Generated by `cloudscape report` (do not edit by hand): every canonical scene rendered at \
         {}x{} by the GPU ray marcher (its scene quality, on {adapter}) and by the CPU path tracer \
         (`cloudscape reference`, {} samples per pixel requested, two seeds), compared with \
         `cloudscape compare`'s metrics: HDR-FLIP (Andersson et al. 2021; 0 is identical) and \
         relative MSE on linear radiance. The noise floor compares the two half-sample path \
         traced images with each other: differences below it are not resolved by the reference.\n\n\
         Regenerate with `cargo run --release -p cloudscape-cli -- report` from the repository \
         root (path-traced references are cached in `target/realism-cache`; delete it after \
         changing the path tracer). Both renderers see the same cloud field, camera, sun disc, \
         ground and atmosphere (the same tables: the sun through the air at every altitude, the \
         sky, the aerial perspective); the path tracer applies the air between the eye and the \
         first scattering or ground hit, the ray marcher the air up to the transmittance-weighted \
         mean cloud depth, and only the ray marcher's air is shadowed by the clouds. The path tracer's noise is dominated by the \
         forward peak of cloud droplets (approximate Mie, g = 0.995 for half the light): rare \
         paths that leave a cloud within a fraction of a degree of the sun carry most of the \
         aureole, which shows as fireflies and as a large relative-MSE noise floor. Where the sun \
         is in frame its disc (radiance about 10^5) dominates the mean luminance: the path tracer \
         spreads it over its pixel, the ray marcher draws it only where a pixel centre falls \
         inside; HDR-FLIP is the robust number.\n",
        args.width, args.height, args.spp
    );
    let _ = writeln!(
        s,
        "| scene | HDR-FLIP mean | p95 | p99 | relMSE | luminance ratio | noise floor (FLIP / relMSE) | path tracer samples/s | spp | GPU ms |\n\
         |---|---|---|---|---|---|---|---|---|---|"
    );
    for r in rows {
        let c = &r.comparison;
        let _ = writeln!(
            s,
            "| {} | {:.4} | {:.4} | {:.4} | {:.4} | {:.3} | {:.4} / {:.4} | {:.0} | {:.1} | {:.0} |",
            r.title,
            c.flip_mean,
            c.flip_p95,
            c.flip_p99,
            c.relative_mse,
            c.luminance_ratio,
            r.noise_floor.flip_mean,
            r.noise_floor.relative_mse,
            r.samples_per_second,
            r.spp,
            r.gpu_ms
        );
    }
    particles::markdown(&mut s, rows.iter().map(|r| (r.title, &r.particles)));
    sprites::markdown(&mut s, rows.iter().map(|r| (r.title, &r.sprites)));
    let _ = writeln!(
        s,
        "\n## Images\n\nRay marcher | path tracer | HDR-FLIP error (magma)\n"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "### {}\n\n| ray marcher | path tracer | HDR-FLIP |\n|---|---|---|\n\
             | ![](realism/{n}-raymarch.png) | ![](realism/{n}-reference.png) | ![](realism/{n}-flip.png) |\n\n\
             | particles | path-traced particles | HDR-FLIP of particles |\n|---|---|---|\n\
             | ![](realism/{n}-particles.png) | ![](realism/{n}-particle-reference.png) | ![](realism/{n}-particles-flip.png) |\n\n\
             | sprites | path tracer | HDR-FLIP of sprites |\n|---|---|---|\n\
             | ![](realism/{n}-sprites.png) | ![](realism/{n}-reference.png) | ![](realism/{n}-sprites-flip.png) |\n",
            r.title,
            n = r.name
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use cloudscape::scene::Quality;

    #[test]
    fn cached_references_ignore_what_only_the_ray_marcher_reads() {
        let scene = Scene::default();
        let key = |s: &Scene| path_traced_part(s).expect("a scene serialises");
        let mut tuned = scene.clone();
        tuned.lighting.octaves += 1;
        tuned.lighting.ambient_scale *= 0.5;
        tuned.render.quality = Quality::Ultra;
        tuned.render.exposure_ev = 2.0;
        tuned.sprites.ring_radius_m = 0.0;
        tuned.particles.radius_m *= 2.0;
        assert_eq!(key(&scene), key(&tuned));
        let mut absorbing = scene.clone();
        absorbing.lighting.albedo = 0.9;
        assert_ne!(key(&scene), key(&absorbing));
        let mut wider = scene.clone();
        wider.render.width += 1;
        assert_ne!(key(&scene), key(&wider));
    }
}
