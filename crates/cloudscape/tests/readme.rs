//! The README's "Using the library" code is the example host's, line for line, so it compiles and
//! runs in CI and cannot go stale.

use std::path::Path;

#[test]
fn the_readme_shows_the_example_host() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(dir.join("../../README.md")).expect("README.md");
    let example = std::fs::read_to_string(dir.join("examples/host.rs")).expect("examples/host.rs");
    let section = &readme[readme.find("## Using the library").expect("the section")..];
    let start = section.find("```rust\n").expect("a rust block") + "```rust\n".len();
    let block = &section[start..start + section[start..].find("```").expect("closed block")];
    // A trailing `// comment` in the README is commentary, not code.
    let code = |l: &str| {
        l.split(" // ")
            .next()
            .unwrap_or_default()
            .trim()
            .to_string()
    };
    let lines: Vec<String> = block.lines().map(code).filter(|l| !l.is_empty()).collect();
    assert!(
        lines.len() >= 8,
        "the snippet shows the host's frame: {lines:?}"
    );
    for line in lines {
        assert!(
            example.contains(&line),
            "README line not in examples/host.rs: {line}"
        );
    }
}

#[test]
fn the_example_host_uses_only_the_prelude() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let example = std::fs::read_to_string(dir.join("examples/host.rs")).expect("examples/host.rs");
    let paths: Vec<&str> = example
        .match_indices("cloudscape::")
        .map(|(at, _)| &example[at..(at + 30).min(example.len())])
        .collect();
    assert!(!paths.is_empty(), "the example uses the library");
    for path in paths {
        assert!(
            path.starts_with("cloudscape::prelude::"),
            "the example reaches past the prelude: {path}"
        );
    }
}
