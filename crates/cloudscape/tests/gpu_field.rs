//! The GPU field agrees with the CPU specification at sample points: layered clouds (noise
//! generated on the GPU, weather map, type mix, wind) and voxel grids, dense and sparse.

#[path = "support/puffs.rs"]
mod puffs;

use cloudscape::field::VoxelGrid;
use cloudscape::field::sparse::{Block, SparseVoxels};
use cloudscape::field::vdb::{VdbGrid, VdbTransform, write_vdb};
use cloudscape::frame::Frame;
use cloudscape::gpu::GpuContext;
use cloudscape::probe::{Probe, ProbeFunction, ProbeInput};
use cloudscape::renderer::{CloudRenderer, Reuse};
use cloudscape::scene::{CloudTypeMix, Scene, VolumeGrid};
use glam::{DVec3, IVec3, UVec2, Vec3, Vec4};

/// A deterministic point in the box [min, max].
fn point(i: u32, min: Vec3, max: Vec3) -> Vec3 {
    let u = |k: u32| {
        cloudscape::field::noise::hash_to_unit(cloudscape::field::noise::pcg_hash(i * 3 + k))
    };
    min + (max - min) * Vec3::new(u(0), u(1), u(2))
}

/// How GPU and CPU extinction differ over a set of points.
struct Agreement {
    /// Largest absolute difference, m^-1.
    worst: f32,
    /// 99th percentile of the absolute difference, m^-1.
    p99: f32,
    /// Points where the CPU field has cloud.
    cloudy: usize,
}

/// Compares GPU and CPU extinction at `points`.
fn compare(scene: &Scene, base_dir: &std::path::Path, points: &[Vec3], time_s: f32) -> Agreement {
    let ctx = GpuContext::for_tests();
    let mut clouds = CloudRenderer::new(&ctx, scene, base_dir).expect("field");
    let frame = Frame {
        time_s,
        ..Frame::from_scene(scene, UVec2::new(16, 16))
    };
    clouds.begin_frame(&ctx, &frame, Reuse::None);
    let inputs: Vec<ProbeInput> = points
        .iter()
        .map(|p| ProbeInput {
            a: p.extend(1.0),
            b: Vec4::ZERO,
            c: Vec4::ZERO,
            d: Vec4::ZERO,
        })
        .collect();
    let probe = Probe::new(&ctx, &clouds.shared());
    let gpu = probe.run(&ctx, &clouds.shared(), ProbeFunction::Extinction, &inputs);
    let gpu_values: Vec<f32> = gpu.iter().map(|v| v.x).collect();
    let field = clouds.field();
    let cpu: Vec<f32> = points
        .iter()
        .map(|p| field.extinction_per_m(*p, time_s))
        .collect();
    let mut diffs: Vec<f32> = cpu
        .iter()
        .zip(&gpu_values)
        .map(|(c, g)| (c - g).abs())
        .collect();
    diffs.sort_by(f32::total_cmp);
    let agreement = Agreement {
        worst: diffs[diffs.len() - 1],
        p99: diffs[diffs.len() * 99 / 100],
        cloudy: cpu.iter().filter(|c| **c > 0.0).count(),
    };
    eprintln!(
        "|gpu - cpu|: max {:e}, p99 {:e} m^-1 over {} points, {} in cloud",
        agreement.worst,
        agreement.p99,
        points.len(),
        agreement.cloudy
    );
    agreement
}

#[test]
fn gpu_layer_density_equals_cpu_field() {
    let mut scene = Scene::default();
    scene.layers[0].types = CloudTypeMix {
        cumulus: 0.6,
        cumulonimbus: 0.4,
        ..CloudTypeMix::default()
    };
    scene.layers[0].coverage = 0.6;
    let layer = &scene.layers[0];
    let (min, max) = (
        Vec3::new(-8000.0, layer.bottom_m, -8000.0),
        Vec3::new(8000.0, layer.bottom_m + layer.thickness_m, 8000.0),
    );
    let points: Vec<Vec3> = (0..3000).map(|i| point(i, min, max)).collect();
    let a = compare(&scene, std::path::Path::new("."), &points, 37.0);
    assert!(
        a.cloudy > 600,
        "only {} of the points are in cloud: the comparison would prove little",
        a.cloudy
    );
    // Differences come only from the GPU's texture-filtering precision and float rounding, which the
    // coverage and erosion remaps amplify at a few points near thresholds.
    assert!(
        a.p99 < 0.02 * layer.extinction_per_m,
        "99th percentile difference {} m^-1",
        a.p99
    );
    assert!(
        a.worst < 0.15 * layer.extinction_per_m,
        "largest difference {} m^-1",
        a.worst
    );
}

#[test]
fn gpu_voxel_density_equals_cpu_field() {
    let dir = std::env::temp_dir().join(format!("cloudscape-gpu-voxel-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let grid = VoxelGrid::from_fn([24, 16, 20], Vec3::ZERO, Vec3::ONE, |p| {
        (1.0 - (p - Vec3::splat(0.5)).length() * 2.2).max(0.0) + 0.1 * (p.x * 20.0).sin().abs()
    });
    grid.write_vol(&dir.join("ball.vol")).expect("write .vol");
    let mut scene = Scene {
        layers: Vec::new(),
        ..Scene::default()
    };
    let volume = VolumeGrid {
        path: "ball.vol".into(),
        center_m: Some([100.0, 2000.0, -300.0]),
        size_m: Some([1200.0, 800.0, 1000.0]),
        extinction_per_m: 0.08,
        ..VolumeGrid::default()
    };
    let (centre, size) = (
        Vec3::new(100.0, 2000.0, -300.0),
        Vec3::new(1200.0, 800.0, 1000.0),
    );
    let (min, max) = (centre - size * 0.55, centre + size * 0.55);
    scene.volumes = vec![
        volume.clone(),
        VolumeGrid {
            center_m: Some([3000.0, 2500.0, 0.0]),
            ..volume
        },
    ];
    let points: Vec<Vec3> = (0..2000).map(|i| point(i, min, max)).collect();
    let a = compare(&scene, &dir, &points, 0.0);
    std::fs::remove_dir_all(&dir).ok();
    assert!(a.cloudy > 500, "only {} points inside the grid", a.cloudy);
    assert!(
        a.worst < 1e-4 * 0.08,
        "GPU and CPU grid extinction differ by {} m^-1",
        a.worst
    );
}

/// A sparse grid's voxels: two puffs far apart in a box off the brick lattice (its first voxel
/// at -21), one block of them a uniform tile.
fn two_puffs() -> SparseVoxels {
    let mut voxels = SparseVoxels {
        min: IVec3::new(-21, 5, 3),
        max: IVec3::new(266, 57, 77),
        ..SparseVoxels::default()
    };
    puffs::add_ball(&mut voxels, IVec3::new(-6, 20, 22), 15.0, 1.5);
    puffs::add_ball(&mut voxels, IVec3::new(250, 41, 60), 12.0, 1.5);
    voxels
        .blocks
        .insert(IVec3::new(-8, 16, 16), Block::Uniform(0.75));
    voxels
}

#[test]
fn gpu_sparse_vdb_density_equals_cpu_field() {
    let dir = std::env::temp_dir().join(format!("cloudscape-gpu-vdb-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let grid = VdbGrid {
        name: "density".into(),
        transform: VdbTransform {
            voxel_size: DVec3::new(10.0, 8.0, 12.0),
            translation: DVec3::new(500.0, 1500.0, -800.0),
        },
        voxels: two_puffs(),
    };
    write_vdb(&dir.join("puffs.vdb"), &grid).expect("write .vdb");
    let scene = Scene {
        layers: Vec::new(),
        volumes: vec![VolumeGrid {
            path: "puffs.vdb".into(),
            extinction_per_m: 0.06,
            ..VolumeGrid::default()
        }],
        ..Scene::default()
    };
    // Points around each puff, where the box holds values.
    let to_world = |v: IVec3| {
        v.as_dvec3().as_vec3() * Vec3::new(10.0, 8.0, 12.0) + Vec3::new(500.0, 1500.0, -800.0)
    };
    let points: Vec<Vec3> = (0..3000)
        .map(|i| {
            let (centre, reach) = if i % 2 == 0 {
                (IVec3::new(-6, 20, 22), 17)
            } else {
                (IVec3::new(250, 41, 60), 14)
            };
            point(i, to_world(centre - reach), to_world(centre + reach))
        })
        .collect();
    let a = compare(&scene, &dir, &points, 0.0);
    std::fs::remove_dir_all(&dir).ok();
    assert!(a.cloudy > 800, "only {} points inside the puffs", a.cloudy);
    assert!(
        a.worst < 1e-4 * 0.06,
        "GPU and CPU grid extinction differ by {} m^-1",
        a.worst
    );
}
