//! A Mitsuba 3 scene of the same clouds, for a path-traced ground truth.
//!
//! [`write_mitsuba_scene`] writes `clouds.vol` (the density grid) and `scene.xml`, which renders
//! with `mitsuba -m scalar_rgb scene.xml` (override the sample count with `-Dspp=N` and the path
//! depth with `-Dmax_depth=N`). What Mitsuba gets:
//!
//! - integrator `volpath` (delta tracking with next-event estimation), 1000 bounces by default:
//!   thick cores lose energy at shorter depths (`physics.md`);
//! - the camera as a `perspective` sensor with the vertical field of view, `hdrfilm`;
//! - the sun as a `directional` emitter: Mitsuba has no sun disc, so `angular_radius_deg` is
//!   ignored (a point sun, sharper shadows);
//! - the sky as a `constant` emitter; a gradient sky becomes the constant radiance that gives a
//!   horizontal surface the same irradiance, `H + (Z - H) 2 / (k + 2)` for the gradient
//!   `L = H + (Z - H) sin(elevation)^k` (its cosine-weighted mean over the upper hemisphere);
//! - the clouds as a `cube` over the grid box holding a `heterogeneous` medium whose extinction is
//!   the grid times `extinction_per_m`; the phase function exact as one or two HG lobes (`hg`,
//!   `blendphase`) for `hg` and `dual_hg`; for `mie`, the Draine-HG mixture of Jendersie & d'Eon
//!   2023 as a `tabphase` table of 65537 values over the scattering cosine, which keeps the
//!   function's integral and mean cosine and spreads its forward peak over the last 0.45 deg
//!   (`approximations::tabulate_phase`);
//! - the ground, when enabled, as a flat diffuse `rectangle` at `y = 0` reaching `far_m` around the
//!   camera (the planet's curvature is ignored).

use std::path::{Path, PathBuf};

use glam::Vec3;

use super::approximations::{ExportedPhase, HgLobe, constant_sky_radiance, exported_phase};
use super::xml::Element;
use crate::field::voxel::{VoxelError, VoxelGrid};
use crate::fsutil::write_bytes_atomically;
use crate::scene::{Camera, Ground, RenderSettings, Scene, Sun};

/// Name of the density grid written beside the scene file.
pub const GRID_FILE_NAME: &str = "clouds.vol";
/// Name of the scene file.
pub const SCENE_FILE_NAME: &str = "scene.xml";
/// Samples per pixel unless `-Dspp=N` is given (the sample count of pbrt-v4's cloud reference).
const DEFAULT_SAMPLES_PER_PIXEL: u32 = 1024;
/// Path depth unless `-Dmax_depth=N` is given.
const DEFAULT_MAX_DEPTH: u32 = 1000;

/// Why the Mitsuba scene could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The output directory could not be created or a file could not be written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The directory or file.
        path: PathBuf,
        /// The operating system's reason.
        #[source]
        source: std::io::Error,
    },
    /// Writing the density grid failed.
    #[error(transparent)]
    Grid(#[from] VoxelError),
    /// The grid box has no volume.
    #[error("the cloud grid box {min} .. {max} m has no volume: every max must exceed its min")]
    EmptyBox {
        /// Minimum corner, metres.
        min: Vec3,
        /// Maximum corner, metres.
        max: Vec3,
    },
    /// The extinction scale is negative or not a number.
    #[error("extinction_per_m is {0}: it must be a finite number >= 0")]
    BadExtinction(f32),
}

/// Writes `dir/clouds.vol` and `dir/scene.xml` (creating `dir`) and returns the scene file's path.
///
/// The medium's extinction is `grid value * extinction_per_m` in m^-1. Each file is written whole
/// or not at all.
pub fn write_mitsuba_scene(
    dir: &Path,
    scene: &Scene,
    grid: &VoxelGrid,
    extinction_per_m: f32,
) -> Result<PathBuf, ExportError> {
    if !(extinction_per_m.is_finite() && extinction_per_m >= 0.0) {
        return Err(ExportError::BadExtinction(extinction_per_m));
    }
    if grid.bbox_max.cmple(grid.bbox_min).any() {
        return Err(ExportError::EmptyBox {
            min: grid.bbox_min,
            max: grid.bbox_max,
        });
    }
    std::fs::create_dir_all(dir).map_err(|source| io_error(dir, source))?;
    grid.write_vol(&dir.join(GRID_FILE_NAME))?;
    let scene_path = dir.join(SCENE_FILE_NAME);
    let document = scene_element(scene, grid, extinction_per_m).to_document();
    write_bytes_atomically(&scene_path, document.as_bytes())
        .map_err(|source| io_error(&scene_path, source))?;
    Ok(scene_path)
}

fn io_error(path: &Path, source: std::io::Error) -> ExportError {
    ExportError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Unit vector toward azimuth `azimuth_deg` (clockwise from north) and elevation `elevation_deg`,
/// in the scene frame of [`crate::scene`]: x east, y up, z south, so
/// `(sin az cos el, sin el, -cos az cos el)`.
fn direction(azimuth_deg: f32, elevation_deg: f32) -> Vec3 {
    let (sin_az, cos_az) = azimuth_deg.to_radians().sin_cos();
    let (sin_el, cos_el) = elevation_deg.to_radians().sin_cos();
    Vec3::new(sin_az * cos_el, sin_el, -cos_az * cos_el)
}

fn scene_element(scene: &Scene, grid: &VoxelGrid, extinction_per_m: f32) -> Element {
    let ground = scene
        .ground
        .enabled
        .then(|| ground_shape(&scene.ground, &scene.camera));
    Element::new("scene")
        .attr("version", "3.0.0")
        .child(
            Element::new("default")
                .attr("name", "spp")
                .attr("value", DEFAULT_SAMPLES_PER_PIXEL),
        )
        .child(
            Element::new("default")
                .attr("name", "max_depth")
                .attr("value", DEFAULT_MAX_DEPTH),
        )
        .child(plugin("integrator", "volpath").child(integer("max_depth", "$max_depth")))
        .child(sensor(&scene.camera, &scene.render))
        .child(sun_emitter(&scene.sun))
        .child(plugin("emitter", "constant").child(rgb("radiance", constant_sky_radiance(scene))))
        .child(clouds_shape(scene, grid, extinction_per_m))
        .children(ground)
}

fn sensor(camera: &Camera, render: &RenderSettings) -> Element {
    let origin = Vec3::from_array(camera.position_m);
    let forward = direction(camera.yaw_deg, camera.pitch_deg);
    let target = camera.look_at_m.map_or(origin + forward, Vec3::from_array);
    let lookat = Element::new("lookat")
        .attr("origin", vector(origin))
        .attr("target", vector(target))
        .attr("up", vector(camera_up(target - origin, camera.yaw_deg)));
    plugin("sensor", "perspective")
        .child(float("fov", camera.fov_y_deg))
        .child(string("fov_axis", "y"))
        .child(float("near_clip", camera.near_m))
        .child(float("far_clip", camera.far_m))
        .child(
            Element::new("transform")
                .attr("name", "to_world")
                .child(lookat),
        )
        .child(plugin("sampler", "independent").child(integer("sample_count", "$spp")))
        .child(
            plugin("film", "hdrfilm")
                .child(integer("width", render.width))
                .child(integer("height", render.height))
                .child(Element::new("rfilter").attr("type", "box")),
        )
}

/// World up, or the horizontal view azimuth when looking straight up or down (where world up
/// would leave the camera's roll undefined).
fn camera_up(view: Vec3, yaw_deg: f32) -> Vec3 {
    if view.normalize_or_zero().cross(Vec3::Y).length() > 1e-4 {
        Vec3::Y
    } else {
        direction(yaw_deg, 0.0)
    }
}

/// Mitsuba's `direction` is where the light travels: away from the sun.
fn sun_emitter(sun: &Sun) -> Element {
    let travel = -direction(sun.azimuth_deg, sun.elevation_deg);
    plugin("emitter", "directional")
        .child(
            Element::new("vector")
                .attr("name", "direction")
                .attr("value", vector(travel)),
        )
        .child(rgb("irradiance", sun.color.map(|c| c * sun.irradiance)))
}

fn clouds_shape(scene: &Scene, grid: &VoxelGrid, extinction_per_m: f32) -> Element {
    let centre = (grid.bbox_min + grid.bbox_max) * 0.5;
    let half_size = (grid.bbox_max - grid.bbox_min) * 0.5;
    let density = plugin("volume", "gridvolume")
        .attr("name", "sigma_t")
        .child(string("filename", GRID_FILE_NAME))
        .child(
            Element::new("boolean")
                .attr("name", "use_grid_bbox")
                .attr("value", "true"),
        );
    let medium = plugin("medium", "heterogeneous")
        .attr("name", "interior")
        .child(density)
        .child(float("scale", extinction_per_m))
        .child(float("albedo", scene.lighting.albedo))
        .child(phase(&exported_phase(&scene.phase)));
    let to_world = Element::new("transform")
        .attr("name", "to_world")
        .child(xyz("scale", half_size))
        .child(xyz("translate", centre));
    plugin("shape", "cube")
        .child(to_world)
        .child(plugin("bsdf", "null"))
        .child(medium)
}

/// A table as `tabphase` (its `values`, comma-separated, from `cos_theta = -1` to 1); one HG lobe
/// as `hg`; two as `blendphase`, whose `weight` is the share of its second child.
fn phase(exported: &ExportedPhase) -> Element {
    let lobes = match exported {
        ExportedPhase::Table(values) => {
            let values: Vec<String> = values.iter().map(f32::to_string).collect();
            return plugin("phase", "tabphase").child(string("values", &values.join(", ")));
        }
        ExportedPhase::Lobes(lobes) => lobes,
    };
    let hg = |lobe: &HgLobe| plugin("phase", "hg").child(float("g", lobe.g));
    match lobes.as_slice() {
        [first, second] => plugin("phase", "blendphase")
            .child(float("weight", second.weight))
            .child(hg(first).attr("name", "phase_0"))
            .child(hg(second).attr("name", "phase_1")),
        _ => hg(&lobes[0]),
    }
}

/// Mitsuba's rectangle spans [-1, 1]^2 in the xy plane facing +z: scale it, turn it to face +y
/// (-90 degrees about x) and centre it under the camera.
fn ground_shape(ground: &Ground, camera: &Camera) -> Element {
    let [x, _, z] = camera.position_m;
    let to_world = Element::new("transform")
        .attr("name", "to_world")
        .child(xyz("scale", Vec3::new(camera.far_m, camera.far_m, 1.0)))
        .child(Element::new("rotate").attr("x", 1).attr("angle", -90))
        .child(xyz("translate", Vec3::new(x, 0.0, z)));
    plugin("shape", "rectangle")
        .child(to_world)
        .child(plugin("bsdf", "diffuse").child(rgb("reflectance", ground.albedo)))
}

fn plugin(tag: &'static str, kind: &str) -> Element {
    Element::new(tag).attr("type", kind)
}

fn float(name: &str, value: f32) -> Element {
    Element::new("float")
        .attr("name", name)
        .attr("value", value)
}

fn integer(name: &str, value: impl std::fmt::Display) -> Element {
    Element::new("integer")
        .attr("name", name)
        .attr("value", value)
}

fn string(name: &str, value: &str) -> Element {
    Element::new("string")
        .attr("name", name)
        .attr("value", value)
}

fn rgb(name: &str, value: [f32; 3]) -> Element {
    Element::new("rgb")
        .attr("name", name)
        .attr("value", vector(Vec3::from_array(value)))
}

/// A transform step such as `<scale x=".." y=".." z=".."/>`.
fn xyz(tag: &'static str, value: Vec3) -> Element {
    Element::new(tag)
        .attr("x", value.x)
        .attr("y", value.y)
        .attr("z", value.z)
}

fn vector(value: Vec3) -> String {
    format!("{}, {}, {}", value.x, value.y, value.z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fsutil::ScratchDir;
    use crate::scene::{PhaseModel, SkyModel};

    fn test_grid() -> VoxelGrid {
        let (min, max) = (
            Vec3::new(-1000.0, 1500.0, -7000.0),
            Vec3::new(1000.0, 3500.0, -5000.0),
        );
        VoxelGrid::from_fn([6, 5, 4], min, max, |p| (p.y - 1500.0) / 2000.0)
    }

    /// Exports `scene` to a temporary directory and returns the grid read back and the XML.
    fn export(name: &str, scene: &Scene) -> (VoxelGrid, String) {
        let scratch = ScratchDir::new(&format!("mitsuba-{name}"));
        let dir = scratch.join("scene");
        let path = write_mitsuba_scene(&dir, scene, &test_grid(), 0.06).unwrap();
        let xml = std::fs::read_to_string(&path).unwrap();
        let grid = VoxelGrid::read_vol(&dir.join(GRID_FILE_NAME)).unwrap();
        (grid, xml)
    }

    /// The three numbers of the first attribute value that follows `marker`.
    fn triple_after(xml: &str, marker: &str) -> Vec3 {
        let rest = &xml[xml
            .find(marker)
            .unwrap_or_else(|| panic!("{marker} missing"))
            + marker.len()..];
        let value = &rest[..rest.find('"').unwrap()];
        let numbers: Vec<f32> = value
            .split(',')
            .map(|n| n.trim().parse().unwrap())
            .collect();
        Vec3::from_slice(&numbers)
    }

    #[test]
    fn scene_has_every_part_with_the_scene_numbers() {
        let (grid, xml) = export("parts", &Scene::default());
        for expected in [
            "<scene version=\"3.0.0\">",
            "<integrator type=\"volpath\">",
            "<default name=\"max_depth\" value=\"1000\"/>",
            "<float name=\"fov\" value=\"65\"/>",
            "<string name=\"fov_axis\" value=\"y\"/>",
            "<float name=\"far_clip\" value=\"120000\"/>",
            "<integer name=\"width\" value=\"1280\"/>",
            "<integer name=\"height\" value=\"720\"/>",
            "<sampler type=\"independent\">",
            "<emitter type=\"directional\">",
            "<emitter type=\"constant\">",
            "<shape type=\"cube\">",
            "<scale x=\"1000\" y=\"1000\" z=\"1000\"/>",
            "<translate x=\"0\" y=\"2500\" z=\"-6000\"/>",
            "<bsdf type=\"null\"/>",
            "<medium type=\"heterogeneous\" name=\"interior\">",
            "<string name=\"filename\" value=\"clouds.vol\"/>",
            "<float name=\"scale\" value=\"0.06\"/>",
            "<float name=\"albedo\" value=\"1\"/>",
            "<phase type=\"tabphase\">",
            "<shape type=\"rectangle\">",
            "<rgb name=\"reflectance\" value=\"0.12, 0.13, 0.1\"/>",
        ] {
            assert!(xml.contains(expected), "{expected} missing from\n{xml}");
        }
        assert!(!xml.contains("<phase type=\"hg\""));
        assert_eq!(grid, test_grid());
    }

    #[test]
    fn sun_light_travels_away_from_the_sun() {
        let sun = Sun {
            elevation_deg: 30.0,
            azimuth_deg: 90.0,
            irradiance: 2.0,
            ..Sun::default()
        };
        let scene = Scene {
            sun,
            ..Scene::default()
        };
        let (_, xml) = export("sun", &scene);
        let travel = triple_after(&xml, "name=\"direction\" value=\"");
        // The sun stands in the east, 30 degrees up: light travels west and down.
        assert!(
            travel.abs_diff_eq(Vec3::new(-0.75f32.sqrt(), -0.5, 0.0), 1e-6),
            "{travel}"
        );
        let irradiance = triple_after(&xml, "name=\"irradiance\" value=\"");
        assert!(
            irradiance.abs_diff_eq(Vec3::splat(2.0), 1e-6),
            "{irradiance}"
        );
    }

    #[test]
    fn camera_target_follows_yaw_and_pitch_or_look_at() {
        let mut scene = Scene::default();
        scene.camera.yaw_deg = 180.0;
        scene.camera.pitch_deg = 0.0;
        let (_, xml) = export("yaw", &scene);
        // Yaw 180 looks south, +z.
        let target = triple_after(&xml, "target=\"");
        assert!(
            target.abs_diff_eq(Vec3::new(0.0, 30.0, 1.0), 1e-6),
            "{target}"
        );
        scene.camera.look_at_m = Some([5.0, 6.0, 7.0]);
        let (_, xml) = export("look-at", &scene);
        assert_eq!(triple_after(&xml, "target=\""), Vec3::new(5.0, 6.0, 7.0));
    }

    #[test]
    fn looking_straight_up_keeps_a_valid_up_vector() {
        let up = camera_up(Vec3::Y * 10.0, 0.0);
        assert!(up.abs_diff_eq(Vec3::new(0.0, 0.0, -1.0), 1e-6), "{up}");
        assert_eq!(camera_up(Vec3::new(1.0, 0.2, 0.0), 0.0), Vec3::Y);
    }

    #[test]
    fn phase_sky_and_ground_follow_the_scene() {
        let mut scene = Scene::default();
        scene.phase.model = PhaseModel::Hg;
        scene.phase.g = 0.85;
        scene.sky.model = SkyModel::Constant;
        scene.sky.radiance = [0.03, 0.07, 0.23];
        scene.ground.enabled = false;
        let (_, xml) = export("variants", &scene);
        assert!(xml.contains("<float name=\"g\" value=\"0.85\"/>"));
        assert!(!xml.contains("blendphase") && !xml.contains("rectangle"));
        assert!(xml.contains("<rgb name=\"radiance\" value=\"0.03, 0.07, 0.23\"/>"));
    }

    /// The default (`mie`) phase function is written as the table, back-scattering value first.
    #[test]
    fn mie_phase_is_the_table() {
        let (_, xml) = export("mie", &Scene::default());
        let marker = "<string name=\"values\" value=\"";
        let rest = &xml[xml.find(marker).expect("tabphase values missing") + marker.len()..];
        let written: Vec<f32> = rest[..rest.find('"').unwrap()]
            .split(',')
            .map(|v| v.trim().parse().unwrap())
            .collect();
        let ExportedPhase::Table(expected) = exported_phase(&Scene::default().phase) else {
            panic!("mie is tabulated");
        };
        assert_eq!(written, expected);
        assert!(written[0] < *written.last().unwrap());
    }

    #[test]
    fn dual_hg_is_a_blend_of_two_hg_lobes() {
        let mut scene = Scene::default();
        scene.phase.model = PhaseModel::DualHg;
        let (_, xml) = export("dual-hg", &scene);
        assert!(xml.contains("<phase type=\"blendphase\">"), "{xml}");
        assert_eq!(xml.matches("<phase type=\"hg\"").count(), 2);
        assert!(
            xml.contains("<float name=\"weight\" value=\"0.3\"/>"),
            "{xml}"
        );
        assert!(!xml.contains("tabphase"));
    }

    #[test]
    fn bad_inputs_write_nothing() {
        let scratch = ScratchDir::new("mitsuba-bad");
        let dir = scratch.join("scene");
        let error =
            write_mitsuba_scene(&dir, &Scene::default(), &test_grid(), f32::NAN).unwrap_err();
        assert!(matches!(error, ExportError::BadExtinction(_)));
        let mut flat = test_grid();
        flat.bbox_max.y = flat.bbox_min.y;
        let error = write_mitsuba_scene(&dir, &Scene::default(), &flat, 0.05).unwrap_err();
        assert!(error.to_string().contains("has no volume"), "{error}");
        assert!(scratch.entries().is_empty());
    }
}
