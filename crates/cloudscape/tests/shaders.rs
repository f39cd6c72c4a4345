//! Every WGSL program the crate builds parses and validates with naga, with no GPU; every `.wgsl`
//! file in the source tree is a registered module that some program reaches; and every program
//! binds the shared groups at their fixed slots.

use cloudscape::shader::{self, ENVIRONMENT_GROUP, FIELD_GROUP, FRAME_GROUP, MODULES, PROGRAMS};
use std::collections::HashSet;
use std::path::Path;

fn parse(name: &str) -> naga::Module {
    let source = shader::program(name);
    let module = naga::front::wgsl::parse_str(&source)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
    module
}

#[test]
fn every_program_validates() {
    for name in PROGRAMS {
        let module = parse(name);
        assert!(!module.entry_points.is_empty(), "{name} has no entry point");
    }
}

#[test]
fn shared_groups_sit_at_the_same_slot_in_every_program() {
    let slots = [
        ("field", FIELD_GROUP),
        ("frame", FRAME_GROUP),
        ("environment", ENVIRONMENT_GROUP),
    ];
    for name in PROGRAMS {
        let module = parse(name);
        for (_, var) in module.global_variables.iter() {
            let (Some(var_name), Some(binding)) = (&var.name, &var.binding) else {
                continue;
            };
            if let Some((_, group)) = slots.iter().find(|(n, _)| n == var_name) {
                assert_eq!(binding.group, *group, "{name}: {var_name}");
                assert_eq!(binding.binding, 0, "{name}: {var_name}");
            }
        }
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
fn every_wgsl_file_is_a_module_some_program_reaches() {
    let mut files = Vec::new();
    wgsl_files(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("src"),
        &mut files,
    );
    assert_eq!(files.len(), MODULES.len(), "{files:?}");
    let mut reached = HashSet::new();
    for name in PROGRAMS {
        let text = shader::program(name);
        for m in MODULES {
            let body: String = m
                .source
                .lines()
                .filter(|l| !l.starts_with("#import "))
                .map(|l| format!("{l}\n"))
                .collect();
            if text.contains(&body) {
                reached.insert(m.name);
            }
        }
    }
    for file in files {
        let text = std::fs::read_to_string(&file).expect("readable");
        let module = MODULES
            .iter()
            .find(|m| m.source == text)
            .unwrap_or_else(|| panic!("{} is not a registered module", file.display()));
        assert!(
            reached.contains(module.name),
            "no program uses {}",
            module.name
        );
    }
}
