//! `cloudscape export`: the cloud field over a box as a Mitsuba 3 `.vol` grid and scene and
//! (`--vdb`) as an OpenVDB file, (`--sprites`) the scene's sprite clouds as a sprite model file, or (`--puff-sheet`) the sprite
//! technique's puffs as a picture.

use crate::common::{SceneArgs, Stages};
use anyhow::{Result, anyhow};
use clap::Args;
use cloudscape::export::write_mitsuba_scene;
use cloudscape::field::sparse::SparseVoxels;
use cloudscape::field::vdb::{VdbGrid, VdbTransform, write_vdb};
use cloudscape::field::{CloudField, VoxelGrid};
use cloudscape::sprites::ModelFile;
use cloudscape::sprites::cloud_set::scene_clouds;
use glam::Vec3;
use std::path::PathBuf;

/// Arguments of `cloudscape export`.
#[derive(Args, Debug)]
pub struct ExportArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Directory to write `clouds.vol` and `scene.xml` into (created if missing).
    #[arg(long, required_unless_present_any = ["sprites", "puff_sheet", "vdb"])]
    out: Option<PathBuf>,
    /// Write the same grid as an OpenVDB file (a fog volume named `density`, 1 at the peak
    /// extinction, placed in the world by its transform); prints the `[[volumes]]` entry that
    /// draws it.
    #[arg(long)]
    vdb: Option<PathBuf>,
    /// Write the scene's sprite clouds (hand-made, model file and the field's around the camera)
    /// to this sprite model file instead; `sprites.model` draws it.
    #[arg(long, conflicts_with_all = ["out", "vdb"])]
    sprites: Option<PathBuf>,
    /// Write the sprite technique's sheet of 16 puffs to this PNG instead (each at the highest
    /// optical depth a sprite gets, over a sky blue; two pixels per texel).
    #[arg(long, conflicts_with_all = ["out", "sprites", "vdb"])]
    puff_sheet: Option<PathBuf>,
    /// Voxels along the longest side of the box.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(2..=2048))]
    resolution: u32,
    /// Horizontal side of the box around the camera for layered clouds, km.
    #[arg(long, default_value_t = 16.0)]
    size_km: f32,
}

/// The world box the export samples: the layers' altitude band over a square around the camera,
/// joined with every voxel grid's box.
fn export_box(field: &CloudField, camera: Vec3, size_m: f32) -> Option<(Vec3, Vec3)> {
    let layers = field.altitude_range_m().map(|(bottom, top)| {
        let half = Vec3::new(size_m * 0.5, 0.0, size_m * 0.5);
        (
            Vec3::new(camera.x, bottom, camera.z) - half,
            Vec3::new(camera.x, top, camera.z) + half,
        )
    });
    let volumes = field.volumes.iter().map(|v| (v.min_m, v.min_m + v.size_m));
    layers
        .into_iter()
        .chain(volumes)
        .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
}

/// Samples the field and writes the Mitsuba scene, or writes the sprite model.
pub fn run(args: ExportArgs) -> Result<()> {
    let mut stages = Stages::new();
    if let Some(path) = &args.puff_sheet {
        let sheet = stages.run("baking the puffs", || {
            Ok(cloudscape::sprites::puff_sheet_preview(2))
        })?;
        return stages.run("writing image", || Ok(sheet.write_png(path)?));
    }
    let doc = stages.run("loading scene", || args.scene.load(&[]))?;
    let scene = &doc.scene;
    let field = stages.run("building cloud field", || {
        CloudField::new(scene, &doc.resolve_path(""))
            .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))
    })?;
    if let Some(path) = &args.sprites {
        return write_sprites(&doc, &field, path, stages);
    }
    if args.out.is_none() && args.vdb.is_none() {
        return Err(anyhow!(
            "give --out DIR (Mitsuba), --vdb FILE, --sprites FILE or --puff-sheet PNG"
        ));
    }
    let camera = Vec3::from_array(scene.camera.position_m);
    let (min, max) = export_box(&field, camera, args.size_km * 1000.0)
        .ok_or_else(|| anyhow!("the scene has no clouds to export"))?;
    let extent = max - min;
    let voxel_m = extent.max_element() / args.resolution as f32;
    let resolution = (extent / voxel_m)
        .ceil()
        .max(Vec3::ONE)
        .as_uvec3()
        .to_array();
    eprintln!("sampling {resolution:?} voxels over {min} .. {max} m");
    stages.run("baking noise", || {
        field.bake_noise();
        Ok(())
    })?;
    let time_s = scene.render.time_s;
    let sigma = stages.run("sampling field", || {
        Ok(VoxelGrid::from_fn(resolution, min, max, |p| {
            field.extinction_per_m(p, time_s)
        }))
    })?;
    let peak = sigma.max_value().max(f32::MIN_POSITIVE);
    let normalised = VoxelGrid {
        values: sigma.values.iter().map(|v| v / peak).collect(),
        ..sigma
    };
    if let Some(out) = &args.out {
        let path = stages.run("writing Mitsuba scene", || {
            Ok(write_mitsuba_scene(out, scene, &normalised, peak)?)
        })?;
        eprintln!("wrote {} (peak extinction {peak:.4} m^-1)", path.display());
    }
    if let Some(path) = &args.vdb {
        stages.run("writing OpenVDB file", || {
            Ok(write_vdb(path, &density_grid(&normalised))?)
        })?;
        eprintln!(
            "wrote {}; draw it with\n[[volumes]]\npath = {:?}\nextinction_per_m = {peak:.6}",
            path.display(),
            path.display().to_string()
        );
    }
    stages.print();
    Ok(())
}

/// A dense grid as an OpenVDB fog volume named `density`: cell `[x, y, z]` is voxel `(x, y, z)`,
/// whose centre the transform puts at the cell's centre in the world.
fn density_grid(grid: &VoxelGrid) -> VdbGrid {
    let resolution = glam::UVec3::from_array(grid.resolution).as_vec3();
    let voxel_m = (grid.bbox_max - grid.bbox_min) / resolution;
    VdbGrid {
        name: "density".into(),
        transform: VdbTransform {
            voxel_size: voxel_m.as_dvec3(),
            translation: (grid.bbox_min + 0.5 * voxel_m).as_dvec3(),
        },
        voxels: SparseVoxels::from_dense(grid),
    }
}

/// Writes the scene's sprite clouds as a model file at `path`.
fn write_sprites(
    doc: &cloudscape::scene::SceneDocument,
    field: &CloudField,
    path: &std::path::Path,
    mut stages: Stages,
) -> Result<()> {
    let clouds = stages.run("making sprite clouds", || {
        scene_clouds(&doc.scene, field, &doc.resolve_path(""))
            .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))
    })?;
    stages.run("writing", || Ok(ModelFile::of(&clouds).write(path)?))?;
    let sprites: usize = clouds.iter().map(|c| c.sprites.len()).sum();
    eprintln!(
        "wrote {} clouds, {sprites} sprites to {}",
        clouds.len(),
        path.display()
    );
    stages.print();
    Ok(())
}
