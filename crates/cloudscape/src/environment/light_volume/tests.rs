//! The CPU solve held to physics: the infinite slab of `optics::slab` and the conservation of
//! energy through a conservative cloud.

use super::solve::{Boundaries, DiffuseField, Diffusion};
use super::{DiffuseOptics, LightVolumeCascade};
use crate::optics::PhaseLobes;
use crate::optics::slab::{ScaledSlab, diffuse_moments};
use crate::scene::Scene;
use glam::{IVec2, UVec3, Vec2, Vec3};

fn droplets() -> DiffuseOptics {
    let scene = Scene::default();
    DiffuseOptics::of(
        &scene
            .lighting
            .sun_slab(PhaseLobes::from_scene(&scene.phase)),
    )
}

fn dark() -> Boundaries {
    Boundaries {
        sky_down: Vec3::ZERO,
        ground_albedo: None,
        sky_up: Vec3::ZERO,
    }
}

/// A horizontally uniform slab of scaled thickness `thickness` in `n` layers of one column, lit
/// by a unit beam at `mu0` to the vertical.
fn slab(thickness: f32, n: u32, mu0: f32) -> Diffusion {
    let h = 10.0;
    let sigma = thickness / (n as f32 * h);
    let inputs = (0..n)
        .map(|y| {
            let depth = (n - y) as f32 - 0.5;
            let beam = (-sigma * h * depth / mu0).exp();
            [beam, beam, beam, sigma]
        })
        .collect();
    let sideways = (1.0 - mu0 * mu0).sqrt();
    Diffusion {
        cascade: LightVolumeCascade {
            min_m: Vec3::ZERO,
            cell_m: Vec3::new(100.0, h, 100.0),
        },
        cells: UVec3::new(1, n, 1),
        optics: droplets(),
        inputs,
        beam_direction: Vec3::new(sideways, -mu0, 0.0),
        boundaries: dark(),
    }
}

#[test]
fn an_infinite_slab_reproduces_the_two_stream_solution_at_every_sun_angle() {
    let optics = droplets();
    for mu0 in [1.0, 0.7, 0.4, 0.2] {
        let (thickness, n) = (8.0, 96);
        let problem = slab(thickness, n, mu0);
        let mut field = problem.cold_field();
        problem.solve(&mut field, 4, true);
        let exact = |y: u32| {
            let depth = ((n - y) as f32 - 0.5) * thickness / n as f32;
            let s = ScaledSlab {
                albedo: optics.albedo,
                asymmetry: optics.asymmetry,
                depth,
                thickness,
                incidence: mu0,
            };
            diffuse_moments(&s).0
        };
        let peak = (0..n).map(exact).fold(0.0, f32::max);
        for y in 0..n {
            let got = field.radiance[y as usize].x;
            assert!(
                (got - exact(y)).abs() < 0.03 * peak,
                "mu0 {mu0}, layer {y}: I0 {got} against {} (peak {peak})",
                exact(y)
            );
        }
    }
}

/// A conservative blob in a box with a black ground, lit from straight above by a beam whose
/// loss in each cell is what that cell scatters.
fn blob() -> (Diffusion, f32) {
    let (n, h) = (12u32, 100.0f32);
    let cells = UVec3::new(n, n, n);
    let mut optics = droplets();
    optics.albedo = 1.0;
    let mut inputs = vec![[0.0; 4]; (n * n * n) as usize];
    let mut incident = 0.0;
    for z in 0..n {
        for x in 0..n {
            let mut beam = 1.0f32;
            incident += beam * h * h;
            for y in (0..n).rev() {
                let r = (UVec3::new(x, y, z).as_vec3() + 0.5 - n as f32 / 2.0).length()
                    / (n as f32 / 3.0);
                let sigma = 0.03 * (-r * r).exp();
                let out = beam * (-sigma * h).exp();
                // The beam's loss over the cell, as an irradiance at its centre that sigma h scatters.
                let mean = if sigma > 0.0 {
                    (beam - out) / (sigma * h)
                } else {
                    beam
                };
                inputs[(x + n * (y + n * z)) as usize] = [mean, mean, mean, sigma];
                beam = out;
            }
        }
    }
    let problem = Diffusion {
        cascade: LightVolumeCascade {
            min_m: Vec3::ZERO,
            cell_m: Vec3::splat(h),
        },
        cells,
        optics,
        inputs,
        beam_direction: Vec3::NEG_Y,
        boundaries: Boundaries {
            ground_albedo: Some(Vec3::ZERO),
            ..dark()
        },
    };
    (problem, incident)
}

#[test]
fn a_conservative_cloud_sends_out_all_the_light_it_scatters() {
    let (problem, _) = blob();
    let mut field = problem.cold_field();
    problem.solve(&mut field, 200, true);
    let scattered: f32 = problem
        .inputs
        .iter()
        .map(|c| c[0] * c[3] * problem.optics.albedo)
        .sum::<f32>()
        * problem.cascade.cell_m.element_product();
    let (top, bottom) = problem.escaping(&field);
    let out = (top + bottom).x;
    assert!(
        (out / scattered - 1.0).abs() < 0.01,
        "scattered {scattered}, out through the top {} and the bottom {}",
        top.x,
        bottom.x
    );
    assert!(top.x > 0.0 && bottom.x > 0.0);
}

#[test]
fn light_diffuses_sideways_out_of_a_lit_column() {
    // One column lit in a uniform deck: its neighbours glow once the columns are coupled.
    let (mut problem, _) = blob();
    for (i, cell) in problem.inputs.iter_mut().enumerate() {
        let column = (i as u32 % 12, i as u32 / 144);
        if column != (6, 6) {
            cell[0] = 0.0;
            cell[1] = 0.0;
            cell[2] = 0.0;
        }
    }
    let neighbour = problem.index(UVec3::new(7, 6, 6));
    let glow = |sweeps| {
        let mut field: DiffuseField = problem.cold_field();
        problem.solve(&mut field, sweeps, true);
        field.radiance[neighbour].x
    };
    assert_eq!(
        glow(1),
        0.0,
        "the first sweep of a cold start keeps columns apart"
    );
    assert!(glow(20) > 0.0);
}

/// The ground's diffuse irradiance at `(x, z)` under `problem` lit by an isotropic sky of unit
/// radiance alone.
fn ground_under_sky(mut problem: Diffusion, (x, z): (f32, f32)) -> f32 {
    use super::read::LightVolume;
    for cell in problem.inputs.iter_mut() {
        cell[0] = 0.0;
        cell[1] = 0.0;
        cell[2] = 0.0;
    }
    problem.boundaries.sky_down = Vec3::ONE;
    let mut field = problem.cold_field();
    problem.solve(&mut field, 200, true);
    let volume = LightVolume {
        cascades: vec![(problem, field)],
        enabled: true,
    };
    volume
        .ground_irradiance(Vec3::new(x, -500.0, z))
        .expect("a volume")
        .x
}

#[test]
fn the_ground_sees_the_sky_in_clear_air_and_less_under_a_cloud() {
    let (cloud, _) = blob();
    let mut clear = cloud.clone();
    for cell in clear.inputs.iter_mut() {
        cell[3] = 0.0;
    }
    // A clear column passes the sky's irradiance `pi L` on as free streaming does, less what the
    // cap on the diffusion coefficient (one grid height) holds back: the column's resistance
    // `H / D = 1` beside Marshak's 4 at its two faces, a fifth.
    let sky = std::f32::consts::PI;
    let open = ground_under_sky(clear, (600.0, 600.0));
    assert!(
        (open / (0.8 * sky) - 1.0).abs() < 0.02,
        "clear air {open}, the sky gives {sky}"
    );
    let shaded = ground_under_sky(cloud, (600.0, 600.0));
    assert!(
        shaded < 0.8 * open,
        "under the cloud {shaded}, in clear air {open}"
    );
}

/// A fine cascade hands over to the coarse one around it over `CASCADE_BLEND_CELLS` of its cells,
/// not at a seam: walking out across the fine cascade's side in steps of an eighth of a cell, the
/// diffuse light goes from the fine cascade's value to the coarse one's without a jump.
#[test]
fn the_cascades_blend_without_a_seam() {
    use super::read::{CASCADE_BLEND_CELLS, LightVolume};
    let (fine, _) = blob();
    let mut coarse = fine.clone();
    coarse.cascade.cell_m *= 2.0;
    coarse.cascade.min_m -= 0.5 * coarse.cells.as_vec3() * fine.cascade.cell_m;
    let filled = |problem: &Diffusion, value: f32| {
        let mut field = problem.cold_field();
        field
            .radiance
            .iter_mut()
            .for_each(|r| *r = Vec3::splat(value));
        field
    };
    let (fine_field, coarse_field) = (filled(&fine, 1.0), filled(&coarse, 3.0));
    let cell_m = fine.cascade.cell_m.x;
    let (min_m, size_m) = (
        fine.cascade.min_m,
        fine.cells.as_vec3() * fine.cascade.cell_m,
    );
    let volume = LightVolume {
        cascades: vec![(fine, fine_field), (coarse, coarse_field)],
        enabled: true,
    };
    let centre = min_m + 0.5 * size_m;
    let light = |x: f32| {
        let p = Vec3::new(x, centre.y, centre.z);
        volume.diffuse(p, Vec3::Y).x
    };
    let (inside, outside) = (centre.x, min_m.x + size_m.x + 2.0 * cell_m);
    let steps: Vec<f32> = (0..=((outside - inside) / cell_m * 8.0) as u32)
        .map(|k| light(inside + k as f32 * cell_m / 8.0))
        .collect();
    let largest = steps
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f32::max);
    assert!((steps[0] - 1.0).abs() < 1e-4 && (steps[steps.len() - 1] - 3.0).abs() < 1e-4);
    let smooth = 2.0 / (8.0 * CASCADE_BLEND_CELLS);
    assert!(
        largest <= 1.01 * smooth,
        "largest step {largest}, a linear hand-over {smooth}"
    );
}

/// A grid recentred under a moving eye lines up with the one it replaces by whole cells of each
/// cascade, which the GPU scrolls the last solution by; a grid through other heights does not.
#[test]
fn a_recentred_grid_lines_up_with_the_last_by_whole_cells() {
    use super::{LightVolumeGrid, LightVolumeSettings};
    use crate::field::CloudField;
    let scene = Scene::default();
    let field = CloudField::new(&scene, std::path::Path::new(".")).expect("the default field");
    let settings = LightVolumeSettings::from_scene(&scene);
    let old = LightVolumeGrid::new(&settings, &field, Vec3::ZERO);
    let cell_m = old.cascades[0].cell_m.x;
    let new = LightVolumeGrid::new(
        &settings,
        &field,
        Vec3::new(6.2 * cell_m, 0.0, -2.7 * cell_m),
    );
    let shift = new.shift_cells_from(&old).expect("the grids line up");
    assert_eq!(shift.len(), old.cascades.len());
    for (k, (s, cascade)) in shift.iter().zip(&new.cascades).enumerate() {
        let moved = (cascade.min_m - old.cascades[k].min_m) / cascade.cell_m;
        let error = (s.as_vec2() - Vec2::new(moved.x, moved.z))
            .abs()
            .max_element();
        assert!(error < 1e-3, "cascade {k}: {s} for {moved}");
    }
    assert_eq!(shift[0], IVec2::new(6, -3));
    let mut higher = new.clone();
    higher.cascades[0].min_m.y += 10.0;
    assert!(higher.shift_cells_from(&old).is_none());
}
