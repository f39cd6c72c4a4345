//! Small renders of fixed scenes against golden images, compared by FLIP (Andersson et al. 2020).
//!
//! `CLOUDSCAPE_UPDATE_GOLDENS=1 cargo test --test golden` rewrites the goldens in `tests/golden/`.
//! A failing comparison writes `<name>-actual.png` and `<name>-difference.png` to
//! `target/golden-failures/`.

use cloudscape::field::VoxelGrid;
use cloudscape::gpu::GpuContext;
use cloudscape::image::LdrImage;
use cloudscape::renderer::SceneRenderer;
use cloudscape::scene::SceneDocument;
use glam::Vec3;
use std::path::{Path, PathBuf};
use support::{check, manifest_dir};

mod support;

/// Size of every golden render: small, because CI renders them on a 2-core software GPU.
const SIZE: [u32; 2] = [256, 144];

/// Renders `toml` (with `overrides`) at [`SIZE`], files resolving against `base_dir`.
fn render(toml: &str, base_dir: &Path, overrides: &[&str]) -> LdrImage {
    let mut all: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    all.push(format!("render.width={}", SIZE[0]));
    all.push(format!("render.height={}", SIZE[1]));
    let doc = SceneDocument::parse(toml, "golden scene", base_dir, &all)
        .expect("golden scenes are valid");
    let ctx = GpuContext::for_tests();
    let mut renderer = SceneRenderer::new(&ctx, &doc.scene, base_dir).expect("field builds");
    renderer.render(&ctx, |_| {}).ldr
}

#[test]
fn cumulus_from_the_ground() {
    check(
        "cumulus_ground",
        &render("", Path::new("."), &["render.quality=medium"]),
    );
}

#[test]
fn cumulus_layer_from_above() {
    let view = [
        "camera.position_m=[0,6500,0]",
        "camera.pitch_deg=-35",
        "render.quality=medium",
    ];
    check("cumulus_above", &render("", Path::new("."), &view));
}

#[test]
fn inside_the_layer() {
    let view = [
        "camera.position_m=[4000,2300,-3000]",
        "camera.pitch_deg=3",
        "render.quality=medium",
    ];
    check("cumulus_inside", &render("", Path::new("."), &view));
}

#[test]
fn backlit_cumulus_at_sunset_has_silver_linings() {
    let view = [
        "sun.elevation_deg=7",
        "sun.azimuth_deg=250",
        "camera.yaw_deg=250",
        "camera.pitch_deg=9",
        "render.quality=medium",
    ];
    check("cumulus_backlit", &render("", Path::new("."), &view));
}

#[test]
fn overcast_stratocumulus_on_a_flat_planet() {
    let toml = "[planet]\nshape = \"flat\"\n[[layers]]\ncoverage = 0.9\nthickness_m = 900.0\ntypes = { stratocumulus = 0.7, stratus = 0.3 }\n";
    check(
        "stratocumulus_flat",
        &render(
            toml,
            Path::new("."),
            &["camera.pitch_deg=20", "render.quality=medium"],
        ),
    );
}

#[test]
fn voxel_grid_cloud_with_henyey_greenstein_and_agx() {
    let dir = std::env::temp_dir().join(format!("cloudscape-golden-voxel-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let grid = VoxelGrid::from_fn([32, 24, 32], Vec3::ZERO, Vec3::ONE, |p| {
        let lobes = [
            (Vec3::new(0.5, 0.4, 0.5), 0.32),
            (Vec3::new(0.3, 0.55, 0.45), 0.2),
            (Vec3::new(0.7, 0.6, 0.55), 0.22),
        ];
        lobes
            .iter()
            .map(|(c, r)| (1.0 - (p - *c).length() / r).clamp(0.0, 1.0))
            .fold(0.0, f32::max)
    });
    grid.write_vol(&dir.join("cloud.vol")).expect("write grid");
    let toml = "layers = []\n[phase]\nmodel = \"hg\"\ng = 0.85\n[render]\ntonemap = \"agx\"\nquality = \"medium\"\n\
        [camera]\nposition_m = [0.0, 1200.0, 3000.0]\nlook_at_m = [0.0, 2000.0, -1000.0]\nfov_y_deg = 40.0\n\
        [[volumes]]\npath = \"cloud.vol\"\ncenter_m = [0.0, 2000.0, -1000.0]\nsize_m = [2400.0, 1600.0, 2400.0]\nextinction_per_m = 0.04\n";
    let image = render(toml, &dir, &[]);
    std::fs::remove_dir_all(&dir).ok();
    check("voxel_cloud", &image);
}

/// The particle technique over the default scene from the ground, at its default half
/// resolution (covering the shared upsampling), and with alpha blending for comparison.
#[test]
fn particles_from_the_ground() {
    let particles = [
        "render.technique=particles",
        "particles.table_resolution=low",
    ];
    check("particles_ground", &render("", Path::new("."), &particles));
    let alpha = [&particles[..], &["particles.blending=alpha"]].concat();
    check(
        "particles_ground_alpha",
        &render("", Path::new("."), &alpha),
    );
}

/// The particle technique from above the layer and from inside a cloud (particles clipped at
/// the camera, not dropped).
#[test]
fn particles_from_above_and_inside() {
    let particles = [
        "render.technique=particles",
        "particles.table_resolution=low",
    ];
    let above = ["camera.position_m=[0,6500,0]", "camera.pitch_deg=-35"];
    check(
        "particles_above",
        &render("", Path::new("."), &[&particles[..], &above].concat()),
    );
    let inside = ["camera.position_m=[4000,2300,-3000]", "camera.pitch_deg=3"];
    check(
        "particles_inside",
        &render("", Path::new("."), &[&particles[..], &inside].concat()),
    );
}

/// The sprite technique over the default scene's field clouds, with the impostor ring holding the
/// clouds beyond 6 km, from the ground, from above the layer and from inside a cloud.
#[test]
fn sprites_from_the_ground_above_and_inside() {
    let sprites = [
        "render.technique=sprites",
        "sprites.distance_m=20000",
        "sprites.ring_radius_m=6000",
    ];
    check("sprites_ground", &render("", Path::new("."), &sprites));
    let above = ["camera.position_m=[0,6500,0]", "camera.pitch_deg=-35"];
    check(
        "sprites_above",
        &render("", Path::new("."), &[&sprites[..], &above].concat()),
    );
    let inside = ["camera.position_m=[4000,2300,-3000]", "camera.pitch_deg=3"];
    check(
        "sprites_inside",
        &render("", Path::new("."), &[&sprites[..], &inside].concat()),
    );
}

/// Hand-made sprite clouds of three types built from boxes, one with artist colour levels and
/// an artist ambient colour, and the single-billboard level of detail of the same clouds.
#[test]
fn hand_made_sprite_clouds_and_their_billboards() {
    let toml = "[render]\ntechnique = \"sprites\"\n[sprites]\nfield_clouds = false\n\
        [camera]\nposition_m = [0.0, 800.0, 4000.0]\nlook_at_m = [0.0, 1800.0, -3000.0]\n\
        [[sprite_clouds]]\ntype = \"cumulonimbus\"\ncenter_m = [-2500.0, 2500.0, -4000.0]\nseed = 4\n\
        boxes = [{ center_m = [0.0, -1000.0, 0.0], size_m = [2000.0, 1000.0, 2000.0] }, { center_m = [0.0, 300.0, 0.0], size_m = [1400.0, 1600.0, 1400.0] }, { center_m = [0.0, 1400.0, 0.0], size_m = [3200.0, 500.0, 2400.0] }]\n\
        [[sprite_clouds]]\ntype = \"cumulus_mediocris\"\ncenter_m = [1200.0, 1700.0, -2000.0]\nseed = 5\n\
        color_levels = [[0.0, 0.25, 0.25, 0.3, 1.0], [0.25, 0.45, 0.45, 0.5, 1.0], [0.5, 0.7, 0.7, 0.72, 1.0], [0.75, 0.9, 0.9, 0.9, 1.0], [1.0, 1.0, 1.0, 1.0, 1.0]]\n\
        boxes = [{ center_m = [0.0, 0.0, 0.0], size_m = [1400.0, 600.0, 1000.0] }, { center_m = [200.0, 450.0, 0.0], size_m = [800.0, 500.0, 700.0] }]\n\
        [[sprite_clouds]]\ntype = \"stratus\"\ncenter_m = [2500.0, 1200.0, -6000.0]\nseed = 6\n\
        boxes = [{ center_m = [0.0, 0.0, 0.0], size_m = [5000.0, 250.0, 3000.0] }]\n";
    check("sprites_hand_made", &render(toml, Path::new("."), &[]));
    check(
        "sprites_billboards",
        &render(toml, Path::new("."), &["sprites.lod=billboards"]),
    );
}

/// The goldens directory exists (a typo in the path would make every golden missing).
#[test]
fn goldens_directory_exists() {
    let path: PathBuf = manifest_dir().join("tests/golden");
    assert!(path.is_dir(), "{} is missing", path.display());
}
