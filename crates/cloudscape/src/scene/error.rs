//! The one error type of scene loading: what was wrong, where, and what is allowed.

use std::fmt;

/// A scene that could not be loaded, located as precisely as the source allows.
///
/// Displays as `origin:line:column: key: message`, leaving out the parts that are unknown, e.g.
/// `scene.toml:12:11: layers.0.coverage: 1.5 is out of range; allowed 0..1` or
/// `--set layers.0.coverage=2: layers.0.coverage: 2 is out of range; allowed 0..1`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{}", Location(self))]
pub struct SceneError {
    /// The scene file's name, `<default scene>`, or `--set key=value` for an override.
    pub origin: String,
    /// 1-based line in the scene file; `None` for overrides and for values taken from defaults.
    pub line: Option<usize>,
    /// 1-based column in characters on `line`.
    pub column: Option<usize>,
    /// Dotted key path of the offending value, e.g. `layers.0.coverage`, when known.
    pub key: Option<String>,
    /// What is wrong and what is allowed.
    pub message: String,
}

/// Formats a [`SceneError`] as `origin:line:column: key: message`.
struct Location<'a>(&'a SceneError);

impl fmt::Display for Location<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let error = self.0;
        write!(f, "{}", error.origin)?;
        if let Some(line) = error.line {
            write!(f, ":{line}")?;
            if let Some(column) = error.column {
                write!(f, ":{column}")?;
            }
        }
        if let Some(key) = &error.key {
            write!(f, ": {key}")?;
        }
        write!(f, ": {}", error.message)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_leaves_out_unknown_parts() {
        let mut error = SceneError {
            origin: "scene.toml".into(),
            line: Some(12),
            column: Some(11),
            key: Some("layers.0.coverage".into()),
            message: "1.5 is out of range; allowed 0..1".into(),
        };
        assert_eq!(
            error.to_string(),
            "scene.toml:12:11: layers.0.coverage: 1.5 is out of range; allowed 0..1"
        );
        error.line = None;
        error.column = None;
        error.key = None;
        assert_eq!(
            error.to_string(),
            "scene.toml: 1.5 is out of range; allowed 0..1"
        );
    }
}
