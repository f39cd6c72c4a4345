//! The particle technique's look-up tables: the GPU bake against its CPU specification, the
//! look-ups against direct integration, the scattering tables' energy and symmetry, and the
//! shipped tables and the cache.

use cloudscape::gpu::GpuContext;
use cloudscape::particles::ParticleTableSpec;
use cloudscape::particles::density::{NoiseVolume, ReferenceParticle};
use cloudscape::particles::gpu::{NOISE_VOLUME_SIZE, OpticalDepthBaker};
use cloudscape::particles::optical_depth::{
    OpticalDepthLayout, OpticalDepthTable, lookup_accuracy, particle_rotation, random_chords,
};
use cloudscape::particles::store::{self, TableOrigin, TableStore};
use cloudscape::scene::{ParticleStyle, Scene, TableResolution};
use glam::{Quat, Vec3};

const STYLES: [ParticleStyle; 3] = [
    ParticleStyle::Smooth,
    ParticleStyle::Thresholded,
    ParticleStyle::Pyroclastic,
];

fn particle(style: ParticleStyle) -> ReferenceParticle {
    ReferenceParticle { style, seed: 3 }
}

#[test]
fn the_gpu_bake_is_its_cpu_specification_for_every_style() {
    let ctx = &GpuContext::for_tests();
    let baker = OpticalDepthBaker::new(ctx);
    let layout = OpticalDepthLayout::at(TableResolution::Low);
    for style in STYLES {
        let p = particle(style);
        let gpu = baker.bake(ctx, &p, layout).read(ctx);
        let cpu = OpticalDepthTable::bake_cpu(layout, &NoiseVolume::bake(&p, NOISE_VOLUME_SIZE));
        // Compare optical masses (what a look-up returns), not the ratios, which grazing chords
        // of no mass make ill-conditioned.
        let dims = layout.texture_dims();
        let worst = (0..layout.len())
            .map(|i| {
                let t = glam::UVec3::new(
                    i as u32 % dims.x,
                    (i as u32 / dims.x) % dims.y,
                    i as u32 / (dims.x * dims.y),
                );
                let (entry, dir) = layout.texel_ray(t);
                let chord = cpu.chords.mass(entry, dir);
                let (g, c) = (
                    gpu.values[i].to_f32() * chord,
                    cpu.values[i].to_f32() * chord,
                );
                (g - c).abs() / c.max(1e-3)
            })
            .fold(0.0, f32::max);
        assert!(
            worst < 4e-3,
            "{style:?}: GPU and CPU tables differ by {worst}"
        );
        assert!(
            cpu.values.iter().any(|v| v.to_f32() > 0.5),
            "{style:?} is not empty"
        );
    }
}

#[test]
fn the_gpu_look_up_of_a_rotated_particle_reads_what_the_cpu_look_up_reads() {
    let ctx = &GpuContext::for_tests();
    let baker = OpticalDepthBaker::new(ctx);
    let lut = baker.bake(
        ctx,
        &particle(ParticleStyle::Thresholded),
        OpticalDepthLayout::at(TableResolution::Low),
    );
    let table = lut.read(ctx);
    let chords = random_chords(2000);
    let gpu = baker.probe(ctx, &lut, &chords);
    let mut worst = 0.0f32;
    for (i, ((e, d), g)) in chords.iter().zip(&gpu).enumerate() {
        let turn = particle_rotation(i as u32);
        let c = table.lookup(turn * *e, turn * *d);
        // Hardware filters with 8-bit fractional weights: allow a little more than rounding.
        worst = worst.max((g - c).abs() / c.max(0.02));
    }
    assert!(worst < 0.01, "GPU and CPU look-ups differ by {worst}");
}

#[test]
fn optical_depth_look_ups_match_direct_integration_at_the_default_size() {
    let ctx = &GpuContext::for_tests();
    let baker = OpticalDepthBaker::new(ctx);
    // Mean relative error bound per style: the seed's resolution resolves the smooth and
    // thresholded particles; the pyroclastic surface is sharper than its cells.
    for (style, bound) in [
        (ParticleStyle::Smooth, 0.02),
        (ParticleStyle::Thresholded, 0.02),
        (ParticleStyle::Pyroclastic, 0.05),
    ] {
        let p = particle(style);
        let table = baker.bake(ctx, &p, OpticalDepthLayout::DEFAULT).read(ctx);
        let a = lookup_accuracy(10_000, |q| p.density(q), |e, d| table.lookup(e, d));
        eprintln!("{style:?}: {a:?}");
        assert_eq!(a.chords, 10_000);
        assert!(a.mean < bound, "{style:?}: mean relative error {}", a.mean);
        if style == ParticleStyle::Smooth {
            assert!(a.p95 < 0.02 && a.max < 0.05, "{a:?}");
        }
    }
}

/// The spec of the default scene at the low resolution, quick to bake.
fn low_spec() -> ParticleTableSpec {
    let mut scene = Scene::default();
    scene.particles.table_resolution = TableResolution::Low;
    ParticleTableSpec::from_scene(&scene)
}

#[test]
fn scattered_and_transmitted_light_add_up_to_the_light_in() {
    let spec = low_spec();
    let (tables, report) = store::bake_scattering(&spec, &mut |_, _| {});
    let e = tables.energy_balance(&spec.symmetric_particle(), 100_000);
    eprintln!("{e:?} after {} orders", report.orders);
    assert!((e.total() - 1.0).abs() < 0.01, "{e:?}: {}", e.total());
    assert!(
        e.multiple > e.single && e.single > 0.05,
        "a thick particle scatters mostly more than once"
    );
    assert!(
        report.orders >= 8,
        "orders stop at 0.1 %, not before: {}",
        report.orders
    );
}

#[test]
fn the_scattering_look_up_is_invariant_under_rotation_and_mirroring() {
    let tables = store::scattering_from_file(
        &cloudscape::particles::table_file::TableFile::decode(
            store::SHIPPED_SCATTERING,
            cloudscape::particles::table_file::TableKind::Scattering,
            ParticleTableSpec::from_scene(&Scene::default()).scattering_key(),
        )
        .expect("the shipped tables are the default scene's"),
    );
    let rotation = Quat::from_axis_angle(Vec3::new(-0.2, 0.9, 0.4).normalize(), 0.77);
    let mirror = |v: Vec3| v - 2.0 * v.dot(Vec3::Y) * Vec3::Y;
    for (point, out, to_light) in random_chords(500)
        .into_iter()
        .map(|(e, d)| (e, -d.reflect(e), Vec3::new(0.3, 0.8, -0.52).normalize()))
    {
        let base = tables.lookup(point, out, to_light);
        let rotated = tables.lookup(rotation * point, rotation * out, rotation * to_light);
        let mirrored = tables.lookup(mirror(point), mirror(out), mirror(to_light));
        for other in [rotated, mirrored] {
            assert!(
                (other.0 - base.0).abs() <= 2e-3 * (1.0 + base.0),
                "{base:?} {other:?}"
            );
            assert!(
                (other.1 - base.1).abs() <= 2e-3 * (1.0 + base.1),
                "{base:?} {other:?}"
            );
        }
    }
}

#[test]
fn the_default_scene_uses_the_shipped_tables_and_others_are_baked_once_then_cached() {
    let dir = std::env::temp_dir().join(format!("cloudscape-table-cache-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let cache = TableStore::new(&dir);
    let (_, origin) = cache
        .scattering(
            &ParticleTableSpec::from_scene(&Scene::default()),
            &mut |_, _| {},
        )
        .unwrap();
    assert!(matches!(origin, TableOrigin::Shipped), "{origin:?}");

    let spec = low_spec();
    let (baked, origin) = cache.scattering(&spec, &mut |_, _| {}).unwrap();
    let TableOrigin::Baked {
        path,
        replaced: None,
        ..
    } = origin
    else {
        panic!("expected a bake, got {origin:?}");
    };
    let (cached, origin) = cache.scattering(&spec, &mut |_, _| {}).unwrap();
    assert!(matches!(origin, TableOrigin::Cached(_)), "{origin:?}");
    let close = |a: &[f32], b: &[f32]| {
        a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= 1e-3 * (1.0 + x.abs()))
    };
    assert!(close(&baked.single, &cached.single) && close(&baked.multiple, &cached.multiple));

    // A truncated file is named, replaced by a fresh bake, never read.
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    let (_, origin) = cache.scattering(&spec, &mut |_, _| {}).unwrap();
    let TableOrigin::Baked {
        replaced: Some(error),
        ..
    } = origin
    else {
        panic!("expected a rebuild, got {origin:?}");
    };
    let message = error.to_string();
    assert!(
        message.contains(&path.display().to_string()) && message.contains("truncated"),
        "{message}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn table_keys_follow_every_input() {
    let base = ParticleTableSpec::from_scene(&Scene::default());
    let changed = |edit: fn(&mut Scene)| {
        let mut scene = Scene::default();
        edit(&mut scene);
        ParticleTableSpec::from_scene(&scene)
    };
    for spec in [
        changed(|s| s.particles.style = ParticleStyle::Pyroclastic),
        changed(|s| s.noise.seed = 4),
        changed(|s| s.particles.table_resolution = TableResolution::High),
    ] {
        assert_ne!(spec.optical_depth_key(), base.optical_depth_key());
        assert_ne!(spec.scattering_key(), base.scattering_key());
    }
    for spec in [
        changed(|s| s.particles.radius_m = 150.0),
        changed(|s| s.layers[0].extinction_per_m = 0.06),
        changed(|s| s.lighting.albedo = 0.99),
        changed(|s| s.phase.droplet_diameter_um = 12.0),
    ] {
        assert_eq!(
            spec.optical_depth_key(),
            base.optical_depth_key(),
            "optical depth is in particle radii"
        );
        assert_ne!(spec.scattering_key(), base.scattering_key());
    }
}
