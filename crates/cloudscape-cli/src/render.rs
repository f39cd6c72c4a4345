//! `cloudscape render`.

use crate::common::{GpuArgs, SceneArgs, Stages, progress_bar};
use anyhow::{Result, anyhow};
use clap::Args;
use cloudscape::image::write_image;
use cloudscape::renderer::SceneRenderer;
use std::path::PathBuf;

/// Arguments of `cloudscape render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Output image: `.png` (tone-mapped sRGB) or `.exr` (linear HDR radiance); default from the scene.
    #[arg(long)]
    out: Option<PathBuf>,
    #[command(flatten)]
    gpu: GpuArgs,
}

/// Loads, renders and writes.
pub fn run(args: RenderArgs) -> Result<()> {
    let mut stages = Stages::new();
    let out_override: Vec<String> = args
        .out
        .iter()
        .map(|p| format!("render.output={:?}", p.display().to_string()))
        .collect();
    let doc = stages.run("loading scene", || args.scene.load(&out_override))?;
    let scene = &doc.scene;
    let ctx = stages.run("opening GPU", || args.gpu.open(&doc))?;
    let mut renderer = stages.run("building cloud field", || {
        SceneRenderer::new(&ctx, scene, &doc.resolve_path(""))
            .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))
    })?;
    eprintln!(
        "rendering {}x{} with {:?} quality",
        scene.render.width, scene.render.height, scene.render.quality
    );
    let bar = progress_bar("rendering");
    let images = stages.run("rendering", || {
        Ok(renderer.render(&ctx, |f| bar.set_position((f * 1000.0) as u64)))
    })?;
    bar.finish_and_clear();
    let out = PathBuf::from(&scene.render.output);
    stages.run("writing image", || {
        if out
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"))
        {
            images.ldr.write_png(&out)?;
        } else {
            write_image(
                &out,
                &images.hdr,
                scene.render.exposure_ev,
                scene.render.tonemap,
            )?;
        }
        Ok(())
    })?;
    eprintln!("wrote {}", out.display());
    stages.print();
    Ok(())
}
