//! `cloudscape fit-lighting`: fits the ray marcher's multiple-scattering octaves to the path
//! tracer. Generated scenes (none of them canonical) are lit by the sun alone; at points inside
//! their clouds the path tracer estimates the light scattered toward the eye, and the octaves'
//! factors `(a, b, c)` are chosen to predict it from what the march knows there (its light
//! samples' optical depth toward the sun and the scattering angle). Held-out scenes score the fit.

mod fit;
mod samples;

use crate::common::progress_bar;
use anyhow::{Context, Result};
use clap::Args;
use cloudscape::optics::{Octaves, PhaseLobes};
use cloudscape::scene::Scene;
use fit::{Score, fit_octaves, score};
use samples::{Sample, scene_samples};
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
    let current = defaults.lighting.octaves();
    let fitted = fit_octaves(current.count, &lobes, &training);
    println!(
        "{} training samples, {} held out\n",
        training.len(),
        validation.len()
    );
    println!(
        "| octaves | a | b | c | training rel. RMS | held-out rel. RMS | held-out mean ratio | held-out scene ratios |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for (name, o) in [("default", current), ("fitted", fitted)] {
        let (t, v) = (score(&o, &lobes, &training), score(&o, &lobes, &validation));
        print_row(name, &o, t, v);
    }
    println!(
        "\n[lighting]\noctave_attenuation = {:.3}\noctave_contribution = {:.3}\noctave_eccentricity = {:.3}",
        fitted.attenuation, fitted.contribution, fitted.eccentricity
    );
    Ok(())
}

fn print_row(name: &str, o: &Octaves, training: Score, held_out: Score) {
    println!(
        "| {name} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.2}..{:.2} |",
        o.attenuation,
        o.contribution,
        o.eccentricity,
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
        let samples = match read(&path) {
            Some(samples) => samples,
            None => {
                let samples = scene_samples(index, args.points, args.paths)?;
                write(&path, &samples)?;
                samples
            }
        };
        all.extend(samples);
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(all)
}

/// Columns of a samples file.
const HEADER: &str = "scene,tau_sun,cos_theta,sun_y,source,source_error";

fn write(path: &Path, samples: &[Sample]) -> Result<()> {
    let mut text = format!("{HEADER}\n");
    for s in samples {
        text += &format!(
            "{},{},{},{},{},{}\n",
            s.scene, s.tau_sun, s.cos_theta, s.sun_y, s.source, s.source_error
        );
    }
    std::fs::write(path, text).with_context(|| path.display().to_string())
}

/// The samples in `path`; None when it is missing or not a samples file.
fn read(path: &Path) -> Option<Vec<Sample>> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut lines = text.lines();
    (lines.next()? == HEADER).then_some(())?;
    lines
        .map(|line| {
            let v: Vec<f32> = line
                .split(',')
                .map(|x| x.parse().ok())
                .collect::<Option<_>>()?;
            (v.len() == 6).then(|| Sample {
                scene: v[0] as u32,
                tau_sun: v[1],
                cos_theta: v[2],
                sun_y: v[3],
                source: v[4],
                source_error: v[5],
            })
        })
        .collect()
}
