//! The majorant grid over a real cloud field is conservative: no extinction the field returns
//! anywhere exceeds the majorant that delta tracking uses there.

use cloudscape::field::{CloudField, VoxelGrid};
use cloudscape::scene::{CloudLayer, CloudTypeMix, PlanetShape, Scene, VolumeGrid};
use cloudscape_reference::CloudMedium;
use cloudscape_reference::majorant::MajorantGrid;
use cloudscape_reference::medium::Medium;
use cloudscape_reference::rng::Rng;
use glam::Vec3;
use std::ops::ControlFlow;
use std::path::PathBuf;

/// A scene with a cumulus layer, a taller cumulonimbus-stratus layer and a voxel grid whose file
/// is written to `dir`, on a planet of `shape`, with the wind blowing for 10 minutes.
fn scene(shape: PlanetShape, dir: &std::path::Path) -> Scene {
    let grid = VoxelGrid::from_fn([9, 7, 8], Vec3::ZERO, Vec3::ONE, |p| {
        ((p * 7.0).sin().element_sum() * 0.4 + 0.5).max(0.0)
    });
    grid.write_vol(&dir.join("blob.vol")).unwrap();
    let mut scene = Scene::default();
    scene.planet.shape = shape;
    scene.render.time_s = 600.0;
    scene.layers.push(CloudLayer {
        bottom_m: 1200.0,
        thickness_m: 6000.0,
        coverage: 0.6,
        extinction_per_m: 0.07,
        types: CloudTypeMix {
            cumulonimbus: 0.6,
            stratus: 0.4,
            ..CloudTypeMix::default()
        },
        noise_seed: 5,
        ..CloudLayer::default()
    });
    scene.volumes.push(VolumeGrid {
        path: "blob.vol".into(),
        center_m: Some([800.0, 2600.0, -3000.0]),
        size_m: Some([1500.0, 1200.0, 1700.0]),
        extinction_per_m: 0.09,
        ..VolumeGrid::default()
    });
    scene
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "cloudscape-reference-{name}-{}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn no_extinction_exceeds_its_majorant() {
    let dir = scratch("majorant");
    for shape in [PlanetShape::Spherical, PlanetShape::Flat] {
        let scene = scene(shape, &dir);
        let field = CloudField::new(&scene, &dir).unwrap();
        let camera = Vec3::from_array(scene.camera.position_m);
        let medium = CloudMedium::new(field, scene.render.time_s, camera, 12_000.0);
        let grid = MajorantGrid::build(&medium, 20_000);
        let b = grid.bounds();
        let mut rng = Rng::for_sample(5, 0, 0);
        let mut cloudy = 0;
        // Points anywhere in the grid's box and in the band beyond it.
        for i in 0..6000 {
            let reach = if i % 4 == 0 { 3.0 } else { 1.0 };
            let centre = (b.min + b.max) * 0.5;
            let p =
                centre + (rng.next_vec3() - 0.5) * (b.max - b.min) * Vec3::new(reach, 1.0, reach);
            let sigma = medium.extinction_per_m(p);
            cloudy += usize::from(sigma > 0.0);
            assert!(
                sigma <= grid.majorant_at(p),
                "{shape:?} at {p}: {sigma} > {}",
                grid.majorant_at(p)
            );
        }
        // Points along rays, against the majorant of the segment the walk gives them.
        for _ in 0..300 {
            let origin = camera + (rng.next_vec3() - 0.5) * 4000.0;
            let dir = cloudscape_reference::sampling::uniform_sphere(rng.next_vec2());
            let _: ControlFlow<()> = grid.walk(origin, dir, 30_000.0, |s| {
                for _ in 0..4 {
                    let t = s.start + (s.end - s.start) * rng.next_f32();
                    let sigma = medium.extinction_per_m(origin + dir * t);
                    cloudy += usize::from(sigma > 0.0);
                    assert!(sigma <= s.majorant_per_m, "{shape:?}: {sigma} > {s:?}");
                }
                ControlFlow::Continue(())
            });
        }
        assert!(
            cloudy > 300,
            "{shape:?}: only {cloudy} samples in cloud, the test proves little"
        );
        // The grid is useful: much of the box is bounded below the largest extinction.
        assert!(
            grid.mean_majorant_per_m() < 0.5 * 0.16,
            "{}",
            grid.mean_majorant_per_m()
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
