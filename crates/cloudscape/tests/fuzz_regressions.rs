//! Inputs of the fuzz targets kept as regression tests: every file in
//! `tests/fuzz-regressions/<target>/accept/` must be accepted and every file in `reject/` refused
//! with an error, by the very entry point its fuzz target calls (`fuzz/src/lib.rs`); none may
//! panic. The directories hold the crashes the fuzzers found (fixed since) and a small minimised
//! corpus of interesting inputs (docs/hardening.md).

#[path = "../../../fuzz/src/lib.rs"]
mod harness;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

/// The files of `target`'s `accept` or `reject` directory (none when it does not exist).
fn inputs(target: &str, outcome: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz-regressions")
        .join(target)
        .join(outcome);
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = entries
        .map(|entry| entry.expect("directory entry").path())
        .collect();
    files.sort();
    files
}

/// Feeds every kept input of `target` through its entry point; the failures, one line each.
fn failures(target: &str) -> Vec<String> {
    let (_, entry) = harness::TARGETS
        .into_iter()
        .find(|(name, _)| *name == target)
        .expect("a known target");
    let mut failures = Vec::new();
    let mut fed = 0;
    for (outcome, expect_ok) in [("accept", true), ("reject", false)] {
        for path in inputs(target, outcome) {
            fed += 1;
            let bytes = std::fs::read(&path).expect("read input");
            match catch_unwind(AssertUnwindSafe(|| entry(&bytes))) {
                Err(_) => failures.push(format!("{}: panicked", path.display())),
                Ok(result) if result.is_ok() != expect_ok => failures.push(format!(
                    "{}: expected {outcome}, got {result:?}",
                    path.display()
                )),
                Ok(_) => {}
            }
        }
    }
    assert!(fed > 0, "no kept input of {target}");
    failures
}

fn assert_all_pass(target: &str) {
    let failures = failures(target);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn scene_inputs() {
    assert_all_pass("scene");
}

#[test]
fn vol_inputs() {
    assert_all_pass("vol");
}

#[test]
fn vdb_inputs() {
    assert_all_pass("vdb");
}

#[test]
fn weather_png_inputs() {
    assert_all_pass("weather_png");
}

#[test]
fn table_file_inputs() {
    assert_all_pass("table_file");
}

#[test]
fn sprite_model_inputs() {
    assert_all_pass("sprite_model");
}

#[test]
fn metar_inputs() {
    assert_all_pass("metar");
}

/// The shipped scattering tables pass the checks the table-file target applies (the one input
/// too large to keep as a file twice).
#[test]
fn the_shipped_tables_are_accepted() {
    let mut input = vec![0u8];
    input.extend_from_slice(cloudscape::particles::store::SHIPPED_SCATTERING);
    assert_eq!(harness::table_file(&input), Ok(()));
}
