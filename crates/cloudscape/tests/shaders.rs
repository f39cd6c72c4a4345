//! Every WGSL program the crate builds parses and validates with naga, with no GPU; every `.wgsl`
//! file in the source tree is a module that some program reaches; the shared groups sit at their
//! fixed slots, and a library module binds only in its own group.

use cloudscape::environment::ENVIRONMENT_WGSL;
use cloudscape::field::gpu::FIELD_WGSL;
use cloudscape::frame::FRAME_WGSL;
use cloudscape::renderer::PROGRAMS;
use cloudscape::shader::{ENVIRONMENT_GROUP, FIELD_GROUP, FRAME_GROUP, Program, WgslModule};
use cloudscape::shadow::SHADOW_MAP_WGSL;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

#[test]
fn every_program_validates() {
    for root in PROGRAMS {
        let (module, _) = Program::new(root)
            .validate()
            .unwrap_or_else(|e| panic!("{}: {e}", root.name));
        assert!(
            !module.entry_points.is_empty(),
            "{} has no entry point",
            root.name
        );
    }
}

#[test]
fn each_module_binds_only_its_own_group() {
    let own: [(&WgslModule, u32); 3] = [
        (&FIELD_WGSL, FIELD_GROUP),
        (&FRAME_WGSL, FRAME_GROUP),
        (&ENVIRONMENT_WGSL, ENVIRONMENT_GROUP),
    ];
    for root in PROGRAMS {
        for module in Program::new(root).modules() {
            let expected = match own.iter().find(|(m, _)| std::ptr::eq(*m, *module)) {
                Some((_, group)) => vec![*group],
                None if std::ptr::eq(*module, *root) => module.groups(),
                None => vec![],
            };
            assert_eq!(
                module.groups(),
                expected,
                "{} (in {}) binds outside its own group",
                module.name,
                root.name
            );
        }
    }
}

fn wgsl_files(dir: &Path, out: &mut BTreeSet<PathBuf>) {
    for entry in std::fs::read_dir(dir)
        .expect("source directory is readable")
        .flatten()
    {
        let path = entry.path();
        if path.is_dir() {
            wgsl_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "wgsl") {
            out.insert(path.canonicalize().expect("a real file"));
        }
    }
}

#[test]
fn every_wgsl_file_is_a_module_some_program_reaches() {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = BTreeSet::new();
    wgsl_files(&manifest.join("src"), &mut files);
    let workspace = manifest.join("../..");
    let mut reached = BTreeSet::new();
    for root in PROGRAMS {
        for module in Program::new(root).modules() {
            let path = workspace.join(module.path());
            if path.extension().is_some_and(|e| e == "wgsl") {
                let text = std::fs::read_to_string(&path).expect("the module's file exists");
                assert_eq!(text, module.source, "{} is its file", module.name);
                reached.insert(path.canonicalize().expect("a real file"));
            }
        }
    }
    assert_eq!(
        files, reached,
        "every .wgsl file, and only those, is reached"
    );
}

#[test]
fn a_host_shader_reaches_the_cloud_shadow() {
    let host = "@fragment fn host_fs(@location(0) p: vec3<f32>) -> @location(0) vec4<f32> {\n\
            return vec4<f32>(vec3<f32>(environment_cloud_sun_transmittance(p)), 1.0);\n\
        }\n";
    let program = Program::host(&[&ENVIRONMENT_WGSL], host);
    assert!(program.reaches(&ENVIRONMENT_WGSL));
    program.validate().unwrap_or_else(|e| panic!("{e}"));
    let broken = Program::host(&[&ENVIRONMENT_WGSL], "fn f() -> f32 { return nope; }\n");
    let error = broken.validate().expect_err("nope is undefined");
    assert!(error.to_string().starts_with("host source:1:"), "{error}");
}

#[test]
fn a_host_shader_reads_the_shadow_map_bound_in_its_own_group() {
    let host = "struct HostShadow { map: CloudShadow, sun: vec4<f32> }\n\
        @group(3) @binding(0) var<uniform> host_shadow: HostShadow;\n\
        @group(3) @binding(1) var host_map: texture_2d_array<f32>;\n\
        @group(3) @binding(2) var host_linear: sampler;\n\
        @fragment fn host_fs(@location(0) p: vec3<f32>) -> @location(0) vec4<f32> {\n\
            let tau = cloud_shadow_sun_optical_depth(host_shadow.map, host_map, host_linear, host_shadow.sun.xyz, p);\n\
            return vec4<f32>(vec3<f32>(exp(-tau)), 1.0);\n\
        }\n";
    let program = Program::host(&[&SHADOW_MAP_WGSL], host);
    assert_eq!(
        program.groups(),
        Vec::<u32>::new(),
        "the module binds nothing"
    );
    program.validate().unwrap_or_else(|e| panic!("{e}"));
}
