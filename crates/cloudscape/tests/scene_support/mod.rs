//! Helpers the scene-file tests share: parsing a scene text and checking where it is rejected.

use cloudscape::scene::{SceneDocument, SceneError};
use std::path::Path;

/// The scene document of `text`, as a file named `scene.toml` with no overrides.
pub fn parse(text: &str) -> Result<SceneDocument, SceneError> {
    SceneDocument::parse(text, "scene.toml", Path::new("."), &[])
}

/// Parses `text`, which must fail at `line`:`column` about `key`, with `words` in the message.
pub fn assert_rejected(text: &str, (line, column): (usize, usize), key: &str, words: &[&str]) {
    let error = parse(text).expect_err("the scene should be rejected");
    assert_eq!(
        (error.line, error.column),
        (Some(line), Some(column)),
        "{error}"
    );
    assert_eq!(error.key.as_deref(), Some(key), "{error}");
    for word in words {
        assert!(error.message.contains(word), "{word:?} missing: {error}");
    }
}
