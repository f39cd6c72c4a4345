//! Every WGSL program the crate builds parses and validates with naga, with no GPU; and every
//! `.wgsl` file in the source tree is part of at least one of them.

use cloudscape::{field, post, raymarch};
use std::path::Path;

fn programs() -> Vec<(&'static str, String)> {
    vec![
        ("noise generator", field::gpu::noise_gen_source()),
        ("field probe", field::gpu::probe_source()),
        ("raymarch", raymarch::shader_source()),
        ("compose", post::compose_source()),
        ("display", post::display_source()),
        ("temporal resolve", raymarch::temporal::resolve_source()),
    ]
}

#[test]
fn every_program_validates() {
    for (name, source) in programs() {
        let module = naga::front::wgsl::parse_str(&source)
            .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::empty(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
    }
}

fn wgsl_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir)
        .expect("source directory is readable")
        .flatten()
    {
        let path = entry.path();
        if path.is_dir() {
            wgsl_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "wgsl") {
            out.push(path);
        }
    }
}

#[test]
fn every_wgsl_file_is_in_a_program() {
    let mut files = Vec::new();
    wgsl_files(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("src"),
        &mut files,
    );
    assert!(files.len() >= 8, "found only {files:?}");
    let all: String = programs().into_iter().map(|(_, s)| s).collect();
    for file in files {
        let text = std::fs::read_to_string(&file).expect("readable");
        assert!(
            all.contains(&text),
            "{} is not part of any validated program",
            file.display()
        );
    }
}
