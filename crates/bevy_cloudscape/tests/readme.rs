//! The repository README's Bevy snippet is the code of this crate's README, which `cargo test`
//! compiles as a doctest.

use std::path::Path;

/// The text of the first code block opening with `fence` after `heading` in `file`.
fn block(file: &str, heading: &str, fence: &str) -> String {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(file))
        .unwrap_or_else(|e| panic!("read {file}: {e}"));
    let section = &text[text
        .find(heading)
        .unwrap_or_else(|| panic!("{heading} in {file}"))..];
    let start = section.find(fence).expect("a code block") + fence.len();
    let end = start + section[start..].find("```").expect("the block's end");
    section[start..end].to_string()
}

#[test]
fn the_repository_readme_shows_this_crates_compiled_code() {
    let shown = block("../../README.md", "### In Bevy", "```rust,ignore\n");
    let compiled = block("README.md", "# bevy_cloudscape", "```rust,no_run\n");
    assert!(
        compiled.contains(shown.trim_end()),
        "the README's Bevy snippet is not part of crates/bevy_cloudscape/README.md's example:\n{shown}"
    );
}
