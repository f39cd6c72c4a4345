//! Every example scene in `scenes/` loads and validates.

use cloudscape::scene::SceneDocument;
use std::path::Path;

#[test]
fn example_scenes_load() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).expect("scenes/ exists") {
        let path = entry.expect("readable entry").path();
        if path.extension().is_some_and(|e| e == "toml") {
            SceneDocument::load(Some(&path), &[]).unwrap_or_else(|e| panic!("{e}"));
            count += 1;
        }
    }
    assert!(count >= 5, "found {count} scenes in {}", dir.display());
}
