//! `cloudscape fit-lighting`: fits the ray marcher's models of the sun's multiply scattered light
//! to the path tracer. Generated scenes (none of them canonical) are lit by the sun alone; at
//! points inside their clouds the path tracer estimates the light scattered toward the eye, and
//! each model's factors are chosen to predict it from what the march knows there (its light
//! samples' optical depths toward the sun and away from it, and the scattering angle): the slab
//! model's diffuse and far-side factors, the octaves' `(a, b, c)`. Held-out scenes score the fits.

mod fit;
mod ground;
mod samples;

use crate::common::progress_bar;
use anyhow::{Context, Result};
use clap::Args;
use cloudscape::optics::PhaseLobes;
use cloudscape::scene::Scene;
use fit::{Class, Model, Score, class_ratio, fit_octaves, fit_slab, score};
use glam::Vec3;
use samples::{Sample, fill_volume, scene_samples};
use std::path::{Path, PathBuf};

/// Index of the first held-out scene: far from the training scenes' indices.
const FIRST_VALIDATION_SCENE: u32 = 1000;

/// Arguments of `cloudscape fit-lighting`.
#[derive(Args, Debug)]
pub struct FitLightingArgs {
    /// Generated scenes to fit on.
    #[arg(long, default_value_t = 24)]
    scenes: u32,
    /// Generated scenes held out to score the fit.
    #[arg(long, default_value_t = 8)]
    validation: u32,
    /// Camera rays per scene (the ones that meet a cloud give a sample).
    #[arg(long, default_value_t = 1000)]
    points: u32,
    /// Paths traced per sample.
    #[arg(long, default_value_t = 32)]
    paths: u32,
    /// Where the samples are kept between runs (one file per scene and setting).
    #[arg(long, default_value = "target/fit-lighting")]
    data: PathBuf,
}

/// Gathers the samples, fits the octaves, and prints the fit and its scores.
pub fn run(args: FitLightingArgs) -> Result<()> {
    std::fs::create_dir_all(&args.data).with_context(|| args.data.display().to_string())?;
    let training = gather(0..args.scenes, &args)?;
    let validation = gather(
        FIRST_VALIDATION_SCENE..FIRST_VALIDATION_SCENE + args.validation,
        &args,
    )?;
    let defaults = Scene::default();
    let lobes = PhaseLobes::from_scene(&defaults.phase);
    let lighting = &defaults.lighting;
    let octaves = lighting.octaves();
    let fitted_octaves = fit_octaves(octaves.count, &lobes, &training);
    let fitted_slab = fit_slab(lobes, lighting.albedo, &training);
    println!(
        "{} training samples, {} held out\n",
        training.len(),
        validation.len()
    );
    println!(
        "| model | factors | training rel. RMS | held-out rel. RMS | held-out mean ratio | held-out scene ratios |"
    );
    println!("|---|---|---|---|---|---|");
    let models = [
        ("slab, default", Model::Slab(lighting.sun_slab(lobes))),
        ("slab, fitted", Model::Slab(fitted_slab)),
        ("octaves, default", Model::Octaves(octaves, lobes)),
        ("octaves, fitted", Model::Octaves(fitted_octaves, lobes)),
    ];
    for (name, model) in models {
        print_row(
            name,
            &model,
            score(&model, &training),
            score(&model, &validation),
        );
    }
    print_classes(
        lighting.sun_slab(lobes),
        fitted_slab,
        &training,
        &validation,
    );
    print_ground(&args)?;
    println!(
        "\n[lighting]\nslab_diffuse_scale = {:.3}\nslab_back_scale = {:.3}\noctave_attenuation = {:.3}\noctave_contribution = {:.3}\noctave_eccentricity = {:.3}",
        fitted_slab.diffuse_scale,
        fitted_slab.back_scale,
        fitted_octaves.attenuation,
        fitted_octaves.contribution,
        fitted_octaves.eccentricity
    );
    Ok(())
}

/// Per class of point, over every scene's points in the light volume's finest cascade: each
/// model's mean prediction over the path tracer's mean source.
fn print_classes(
    slab: cloudscape::optics::SunSlab,
    fitted: cloudscape::optics::SunSlab,
    training: &[Sample],
    validation: &[Sample],
) {
    let inside: Vec<Sample> = training
        .iter()
        .chain(validation)
        .filter(|s| s.volume_diffuse.is_finite())
        .copied()
        .collect();
    println!(
        "\nBy class, the {} points of all scenes inside the light volume's finest cascade: mean \
         prediction / mean path-traced source\n",
        inside.len()
    );
    println!("| class | points | light volume | slab, default | slab, fitted |");
    println!("|---|---|---|---|---|");
    let models = [Model::Volume(slab), Model::Slab(slab), Model::Slab(fitted)];
    for class in Class::ALL {
        let ratios = models.map(|m| class_ratio(&m, &inside, class));
        println!(
            "| {} | {} | {:.3} | {:.3} | {:.3} |",
            class.name(),
            ratios[0].1,
            ratios[0].0,
            ratios[1].0,
            ratios[2].0
        );
    }
    let all = models.map(|m| score(&m, &inside));
    println!(
        "| all (rel. RMS) | {} | {:.3} ({:.3}) | {:.3} ({:.3}) | {:.3} ({:.3}) |",
        inside.len(),
        all[0].mean_ratio,
        all[0].relative_rms,
        all[1].mean_ratio,
        all[1].relative_rms,
        all[2].mean_ratio,
        all[2].relative_rms
    );
}

/// Ground points per scene: a fifth of the camera rays.
const GROUND_POINTS_DIVISOR: u32 = 5;

/// The class "ground under cloud": every scene's ground points under cloud (optical depth of at
/// least [`ground::MIN_OPTICAL_DEPTH_ABOVE`] straight up) inside the light volume's finest
/// cascade, each model's mean light leaving the ground over the path tracer's.
fn print_ground(args: &FitLightingArgs) -> Result<()> {
    let scenes =
        (0..args.scenes).chain(FIRST_VALIDATION_SCENE..FIRST_VALIDATION_SCENE + args.validation);
    let bar = progress_bar("ground");
    bar.set_length(u64::from(args.scenes + args.validation));
    let (mut traced, mut volume, mut shadow_map, mut n) = (0.0f64, 0.0f64, 0.0f64, 0);
    for index in scenes {
        let points = args.points / GROUND_POINTS_DIVISOR;
        let path = args.data.join(format!(
            "ground-{index}-{points}x{}-r{}.csv",
            args.paths,
            cloudscape_reference::TRACER_REVISION
        ));
        let samples = match ground::read(&path) {
            Some(samples) => samples,
            None => {
                let reach = Scene::default().lighting.volume_extent_m;
                let samples = ground::ground_samples(index, (points, args.paths), reach)?;
                ground::write(&path, &samples)?;
                samples
            }
        };
        for (s, p) in samples.iter().zip(ground::predict(index, &samples)?) {
            traced += f64::from(s.radiance);
            volume += f64::from(p.volume);
            shadow_map += f64::from(p.shadow_map);
            n += 1;
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    println!(
        "\nGround under cloud, the {n} ground points of all scenes under an optical depth of at \
         least {} inside the finest cascade: mean light leaving the ground over the path tracer's\n",
        ground::MIN_OPTICAL_DEPTH_ABOVE
    );
    println!("| class | points | light volume | shadow map's diffuse transmittance |");
    println!("|---|---|---|---|");
    let t = traced.max(1e-12);
    println!(
        "| ground under cloud | {n} | {:.3} | {:.3} |",
        volume / t,
        shadow_map / t
    );
    Ok(())
}

fn print_row(name: &str, model: &Model, training: Score, held_out: Score) {
    let factors = match model {
        Model::Slab(s) => format!("k {:.3}, back {:.3}", s.diffuse_scale, s.back_scale),
        Model::Volume(_) => "none".to_string(),
        Model::Octaves(o, _) => format!(
            "a {:.3}, b {:.3}, c {:.3}",
            o.attenuation, o.contribution, o.eccentricity
        ),
    };
    println!(
        "| {name} | {factors} | {:.3} | {:.3} | {:.3} | {:.2}..{:.2} |",
        training.relative_rms,
        held_out.relative_rms,
        held_out.mean_ratio,
        held_out.scene_ratio_range.0,
        held_out.scene_ratio_range.1
    );
}

/// The samples of `scenes`, from the data directory where a run with the same settings left them.
fn gather(scenes: std::ops::Range<u32>, args: &FitLightingArgs) -> Result<Vec<Sample>> {
    let bar = progress_bar("scenes");
    bar.set_length(u64::from(scenes.end - scenes.start));
    let mut all = Vec::new();
    for index in scenes {
        let path = args.data.join(format!(
            "scene-{index}-{}x{}-r{}.csv",
            args.points,
            args.paths,
            cloudscape_reference::TRACER_REVISION
        ));
        let mut samples = match read(&path, index)? {
            Some(samples) => samples,
            None => {
                let samples = scene_samples(index, args.points, args.paths)?;
                write(&path, &samples)?;
                samples
            }
        };
        fill_volume(index, &mut samples)?;
        all.extend(samples);
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(all)
}

/// Columns of a samples file.
const HEADER: &str =
    "scene,tau_sun,tau_back,cos_theta,sun_y,source,source_error,x_m,y_m,z_m,dir_x,dir_y,dir_z";

fn write(path: &Path, samples: &[Sample]) -> Result<()> {
    let mut text = format!("{HEADER}\n");
    for s in samples {
        let (p, d) = (s.point_m, s.direction);
        text += &format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            s.scene,
            s.tau_sun,
            s.tau_back,
            s.cos_theta,
            s.sun_y,
            s.source,
            s.source_error,
            p.x,
            p.y,
            p.z,
            d.x,
            d.y,
            d.z
        );
    }
    std::fs::write(path, text).with_context(|| path.display().to_string())
}

/// The samples of scene `index` in `path`; None when it is missing or not a samples file.
fn read(path: &Path, index: u32) -> Result<Option<Vec<Sample>>> {
    let Some(rows) = csv_rows(path, HEADER) else {
        return Ok(None);
    };
    let (_, family) = samples::training_scene(index, false)?;
    Ok(rows
        .into_iter()
        .map(|v| {
            (v.len() == 13).then(|| Sample {
                scene: v[0] as u32,
                tau_sun: v[1],
                tau_back: v[2],
                cos_theta: v[3],
                sun_y: v[4],
                source: v[5],
                source_error: v[6],
                point_m: Vec3::new(v[7], v[8], v[9]),
                direction: Vec3::new(v[10], v[11], v[12]),
                family,
                volume_diffuse: f32::NAN,
            })
        })
        .collect())
}

/// The rows of numbers of the samples file `path` under `header`; None when it is missing, has
/// another header or holds a value that is not a number.
fn csv_rows(path: &Path, header: &str) -> Option<Vec<Vec<f32>>> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut lines = text.lines();
    if lines.next() != Some(header) {
        return None;
    }
    lines
        .map(|line| line.split(',').map(|x| x.parse().ok()).collect())
        .collect()
}
