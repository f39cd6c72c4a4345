//! WGSL programs assembled from modules that import what they use.
//!
//! Each `.wgsl` file of the crate is a module named in [`MODULES`]. A module's first lines may be
//! `#import a b ...`: the modules it uses. [`program`] starts from a root module (one with an entry
//! point), puts every module it reaches once, each after everything it imports, and drops the
//! `#import` lines, so the result is plain WGSL that naga and every wgpu backend accept. The
//! `constants` module is generated from the Rust constants it mirrors ([`constants_wgsl`]), so a
//! value shared by both sides is written once.
//!
//! A registry rather than naga_oil: the modules already prefix their names (`field_`, `frame_`,
//! `march_`), so no name mangling is needed, and the programs stay WGSL text that the shader
//! tests parse with naga and that wgpu's GL backend translates like any other.

use std::collections::HashSet;
use std::fmt::Write;

/// One WGSL module: its name in `#import` lines and its source.
#[derive(Clone, Copy, Debug)]
pub struct WgslModule {
    /// The name other modules import it by.
    pub name: &'static str,
    /// The WGSL text, `#import` lines included.
    pub source: &'static str,
}

const fn module(name: &'static str, source: &'static str) -> WgslModule {
    WgslModule { name, source }
}

/// Every WGSL module of the crate but the generated `constants`.
pub const MODULES: &[WgslModule] = &[
    module("noise", include_str!("field/noise.wgsl")),
    module("noise_gen", include_str!("field/noise_gen.wgsl")),
    module("field", include_str!("field/field.wgsl")),
    module("hiheight", include_str!("field/hiheight.wgsl")),
    module("phase", include_str!("optics/phase.wgsl")),
    module("slab", include_str!("optics/slab.wgsl")),
    module("frame", include_str!("frame/frame.wgsl")),
    module("atmosphere", include_str!("atmosphere/atmosphere.wgsl")),
    module("environment", include_str!("environment/environment.wgsl")),
    module(
        "atmosphere_march",
        include_str!("atmosphere/atmosphere_march.wgsl"),
    ),
    module(
        "atmosphere_luts",
        include_str!("atmosphere/atmosphere_luts.wgsl"),
    ),
    module(
        "atmosphere_aerial",
        include_str!("atmosphere/atmosphere_aerial.wgsl"),
    ),
    module("cloud_shadow", include_str!("shadow/cloud_shadow.wgsl")),
    module("march_light", include_str!("raymarch/march_light.wgsl")),
    module("raymarch", include_str!("raymarch/raymarch.wgsl")),
    module("upsample", include_str!("temporal/upsample.wgsl")),
    module("temporal", include_str!("temporal/temporal.wgsl")),
    module("upsample_still", include_str!("post/upsample.wgsl")),
    module("compose", include_str!("post/compose.wgsl")),
    module("tonemap", include_str!("post/tonemap.wgsl")),
    module("display", include_str!("post/display.wgsl")),
    module("probe", include_str!("probe/probe.wgsl")),
    module("particle", include_str!("particles/particle.wgsl")),
    module(
        "particle_bake",
        include_str!("particles/particle_bake.wgsl"),
    ),
    module(
        "particle_lookup",
        include_str!("particles/particle_lookup.wgsl"),
    ),
    module(
        "particle_generate",
        include_str!("particles/particle_generate.wgsl"),
    ),
    module(
        "particle_blend",
        include_str!("particles/particle_blend.wgsl"),
    ),
    module(
        "particle_render",
        include_str!("particles/particle_render.wgsl"),
    ),
    module("sprite", include_str!("sprites/sprite.wgsl")),
    module("sprite_render", include_str!("sprites/sprite_render.wgsl")),
    module(
        "sprite_impostor",
        include_str!("sprites/sprite_impostor.wgsl"),
    ),
    module(
        "sprite_resolve",
        include_str!("sprites/sprite_resolve.wgsl"),
    ),
];

/// The modules with entry points: every pipeline the crate builds starts from one of these.
pub const PROGRAMS: &[&str] = &[
    "noise_gen",
    "atmosphere_luts",
    "atmosphere_aerial",
    "cloud_shadow",
    "raymarch",
    "temporal",
    "upsample_still",
    "compose",
    "display",
    "probe",
    "particle_bake",
    "particle_generate",
    "particle_render",
    "sprite_render",
    "sprite_impostor",
    "sprite_resolve",
];

/// Bind group slots shared by every program: the field, the frame, the environment; each pass
/// binds its own resources at [`PASS_GROUP`].
pub const FIELD_GROUP: u32 = 0;
/// Slot of [`crate::frame::FrameGpu`]'s bind group.
pub const FRAME_GROUP: u32 = 1;
/// Slot of [`crate::environment::EnvironmentGpu`]'s bind group.
pub const ENVIRONMENT_GROUP: u32 = 2;
/// Slot of a pass's own bind group.
pub const PASS_GROUP: u32 = 3;

/// The WGSL of the Rust constants the shaders share, one `const` each.
pub fn constants_wgsl() -> String {
    use crate::field::{
        GOLDEN_RATIO_CONJUGATE, MAX_LAYERS, MAX_VOLUMES, gpu::MAX_HIHEIGHT_LEVELS, profile,
    };
    let mut s = String::from("// Generated from Rust by shader::constants_wgsl: edit the Rust.\n");
    let mut put = |line: String| writeln!(s, "{line}").expect("writing to a String");
    put(format!("const PI: f32 = {:?};", std::f32::consts::PI));
    put(format!("const MAX_LAYERS: u32 = {MAX_LAYERS}u;"));
    put(format!(
        "const GOLDEN_RATIO_CONJUGATE: f32 = {GOLDEN_RATIO_CONJUGATE:?};"
    ));
    put(format!("const MAX_VOLUMES: u32 = {MAX_VOLUMES}u;"));
    put(format!(
        "const MAX_HIHEIGHT_LEVELS: u32 = {MAX_HIHEIGHT_LEVELS}u;"
    ));
    put(format!(
        "const MARCH_SUN_PATH_MIN_M: f32 = {:?};",
        crate::raymarch::SUN_PATH_M.0
    ));
    put(format!(
        "const MARCH_SUN_PATH_MAX_M: f32 = {:?};",
        crate::raymarch::SUN_PATH_M.1
    ));
    put(format!(
        "const SLAB_MAX_TWO_STREAM_ALBEDO: f32 = {:?};",
        crate::optics::slab::MAX_TWO_STREAM_ALBEDO
    ));
    atmosphere_constants(&mut put);
    let gradients: Vec<String> = profile::TYPE_GRADIENTS
        .iter()
        .map(|g| format!("vec4<f32>({:?}, {:?}, {:?}, {:?})", g[0], g[1], g[2], g[3]))
        .collect();
    put(format!(
        "const TYPE_GRADIENTS = array<vec4<f32>, {}>({});",
        gradients.len(),
        gradients.join(", ")
    ));
    put(format!(
        "const TYPE_BLEND_HALF_WIDTH: f32 = {:?};",
        profile::TYPE_BLEND_HALF_WIDTH
    ));
    s
}

/// The atmosphere's constants (atmosphere::medium, atmosphere::luts) as WGSL `const`s.
fn atmosphere_constants(put: &mut impl FnMut(String)) {
    use crate::atmosphere::luts as l;
    use crate::atmosphere::medium as m;
    let scalars = [
        ("RAYLEIGH_SCALE_HEIGHT_M", m::RAYLEIGH_SCALE_HEIGHT_M),
        ("MIE_SCALE_HEIGHT_M", m::MIE_SCALE_HEIGHT_M),
        ("OZONE_PEAK_ALTITUDE_M", m::OZONE_PEAK_ALTITUDE_M),
        ("OZONE_HALF_WIDTH_M", m::OZONE_HALF_WIDTH_M),
        ("AERIAL_SLICE_M", l::AERIAL_SLICE_M),
    ];
    for (name, value) in scalars {
        put(format!("const ATMOSPHERE_{name}: f32 = {value:?};"));
    }
    let counts = [
        ("AERIAL_SLICES", l::AERIAL_SLICES),
        ("AERIAL_STEPS_PER_SLICE", l::AERIAL_STEPS_PER_SLICE),
        ("TRANSMITTANCE_STEPS", l::TRANSMITTANCE_STEPS),
        ("MULTIPLE_SCATTERING_STEPS", l::MULTIPLE_SCATTERING_STEPS),
        (
            "MULTIPLE_SCATTERING_DIRECTIONS",
            l::MULTIPLE_SCATTERING_DIRECTIONS,
        ),
        ("SKY_VIEW_STEPS", l::SKY_VIEW_STEPS),
        ("IRRADIANCE_STEPS", l::IRRADIANCE_STEPS),
        ("IRRADIANCE_DIRECTIONS", l::IRRADIANCE_DIRECTIONS),
    ];
    for (name, value) in counts {
        put(format!("const ATMOSPHERE_{name}: u32 = {value}u;"));
    }
    let sizes = [
        ("TRANSMITTANCE_SIZE", l::TRANSMITTANCE_SIZE),
        ("MULTIPLE_SCATTERING_SIZE", l::MULTIPLE_SCATTERING_SIZE),
        ("IRRADIANCE_SIZE", l::IRRADIANCE_SIZE),
        ("SKY_VIEW_SIZE", l::SKY_VIEW_SIZE),
        ("AERIAL_SIZE", l::AERIAL_SIZE),
    ];
    for (name, (w, h)) in sizes {
        put(format!("const ATMOSPHERE_{name} = vec2<u32>({w}u, {h}u);"));
    }
}

/// The module named `name`.
///
/// # Panics
/// When no module has that name (a typo in an `#import` line, caught by the shader tests).
pub fn find(name: &str) -> WgslModule {
    MODULES
        .iter()
        .copied()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("no WGSL module named {name:?}"))
}

/// The modules `source` imports, in the order its `#import` lines name them.
pub fn imports(source: &str) -> Vec<&str> {
    source
        .lines()
        .filter_map(|line| line.trim().strip_prefix("#import "))
        .flat_map(str::split_whitespace)
        .collect()
}

/// The whole program of root module `root`: the generated constants, then every module it
/// reaches, each after its imports, without the `#import` lines.
pub fn program(root: &str) -> String {
    let mut order = Vec::new();
    visit(root, &mut HashSet::new(), &mut order);
    program_of(order.iter().map(|m| m.source))
}

/// A host's own WGSL `source` with the modules its `#import` lines name (and theirs) put before it:
/// how a game engine's shader reaches the environment's functions, e.g. `#import environment` and
/// `environment_cloud_sun_transmittance(p)` for the clouds' shadow on its geometry. The host binds
/// [`crate::renderer::CloudRenderer::shared`]'s environment group at [`ENVIRONMENT_GROUP`] and
/// keeps its own resources at other slots.
pub fn host_program(source: &str) -> String {
    let (mut seen, mut order) = (HashSet::new(), Vec::new());
    for name in imports(source) {
        visit(name, &mut seen, &mut order);
    }
    program_of(order.iter().map(|m| m.source).chain([source]))
}

/// The generated constants, then every source in order without its `#import` lines.
fn program_of<'a>(sources: impl Iterator<Item = &'a str>) -> String {
    let mut text = constants_wgsl();
    for source in sources {
        for line in source.lines() {
            if !line.trim_start().starts_with("#import ") {
                text.push_str(line);
                text.push('\n');
            }
        }
    }
    text
}

/// The names of the modules program `root` reaches, `root` included.
pub fn reached(root: &str) -> Vec<&'static str> {
    let mut order = Vec::new();
    visit(root, &mut HashSet::new(), &mut order);
    order.into_iter().map(|m| m.name).collect()
}

/// Depth-first: `name`'s imports, then `name` itself, each module once.
fn visit(name: &str, seen: &mut HashSet<String>, order: &mut Vec<WgslModule>) {
    if name == "constants" || !seen.insert(name.to_string()) {
        return;
    }
    let m = find(name);
    for dependency in imports(m.source) {
        visit(dependency, seen, order);
    }
    order.push(m);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_host_shader_reaches_the_cloud_shadow() {
        let host = "#import environment\n\
            @fragment fn host_fs(@location(0) p: vec3<f32>) -> @location(0) vec4<f32> {\n\
                return vec4<f32>(vec3<f32>(environment_cloud_sun_transmittance(p)), 1.0);\n\
            }\n";
        let text = host_program(host);
        assert!(text.contains("fn environment_cloud_sun_transmittance"));
        crate::optics::test_support::validate_wgsl("host", &text);
    }

    #[test]
    fn a_module_follows_everything_it_imports() {
        let text = program("raymarch");
        let at = |marker: &str| {
            text.find(marker)
                .unwrap_or_else(|| panic!("{marker} is missing"))
        };
        assert!(at("const MAX_LAYERS") < at("struct Field {"));
        assert!(at("fn noise_pcg_hash") < at("fn frame_pixel_jitter"));
        assert!(at("struct Field {") < at("fn march_clouds"));
        assert_eq!(
            text.matches("struct Field {").count(),
            1,
            "each module once"
        );
        assert!(!text.contains("#import"));
    }

    #[test]
    fn every_module_validates_on_its_own_and_every_program_too() {
        for m in MODULES {
            let text = program(m.name);
            crate::optics::test_support::validate_wgsl(m.name, &text);
        }
    }

    #[test]
    fn imports_are_read_from_the_header() {
        assert_eq!(
            imports("#import a b\n#import c\nfn x() {}"),
            ["a", "b", "c"]
        );
    }

    #[test]
    fn generated_constants_are_the_rust_values() {
        let text = constants_wgsl();
        assert!(text.contains(&format!(
            "const MAX_LAYERS: u32 = {}u;",
            crate::field::MAX_LAYERS
        )));
        assert!(text.contains("vec4<f32>(0.0, 0.07, 0.08, 0.15)"));
    }
}
