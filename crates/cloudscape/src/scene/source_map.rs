//! One address space for the scene file and its `--set` overrides, so that every span in the merged
//! document says where its text came from.
//!
//! The file occupies offsets `0..len`; each override follows, one offset after the previous text, so
//! that no two texts share an offset (even an empty span at the end of a text).

use std::ops::Range;

use super::SceneError;

/// The texts a scene was built from: the file and its overrides, laid end to end.
#[derive(Clone, Debug)]
pub(super) struct SourceMap {
    file: Text,
    overrides: Vec<Text>,
}

/// One text and where it starts in the shared address space.
#[derive(Clone, Debug)]
struct Text {
    /// Name for messages: the file name, or `--set key=value`.
    origin: String,
    /// The text itself: the whole file, or the whole `key=value` override.
    text: String,
    /// Offset of the text's first byte in the shared address space.
    start: usize,
}

impl Text {
    fn contains(&self, offset: usize) -> bool {
        (self.start..=self.start + self.text.len()).contains(&offset)
    }
}

impl SourceMap {
    /// Lays out `file_text` (named `origin`) and then each override.
    pub(super) fn new(origin: &str, file_text: &str, overrides: &[String]) -> SourceMap {
        let file = Text {
            origin: origin.to_string(),
            text: file_text.to_string(),
            start: 0,
        };
        let mut next_start = file_text.len() + 1;
        let overrides = overrides
            .iter()
            .map(|text| {
                let start = next_start;
                next_start += text.len() + 1;
                Text {
                    origin: format!("--set {text}"),
                    text: text.clone(),
                    start,
                }
            })
            .collect();
        SourceMap { file, overrides }
    }

    /// The scene file's text.
    pub(super) fn file_text(&self) -> &str {
        &self.file.text
    }

    /// Each override's text with its start offset in the shared address space.
    pub(super) fn overrides(&self) -> impl Iterator<Item = (&str, usize)> {
        self.overrides.iter().map(|o| (o.text.as_str(), o.start))
    }

    /// The text at `span` of the shared address space, when one text holds all of it.
    pub(super) fn text_at(&self, span: &Range<usize>) -> Option<&str> {
        std::iter::once(&self.file)
            .chain(&self.overrides)
            .find(|t| t.contains(span.start))
            .and_then(|t| t.text.get(span.start - t.start..span.end - t.start))
    }

    /// An error in the `index`th override as a whole (e.g. a malformed `key=value`), not at a span.
    pub(super) fn override_error(
        &self,
        index: usize,
        key: Option<String>,
        message: String,
    ) -> SceneError {
        let origin = self
            .overrides
            .get(index)
            .map_or_else(|| "--set".to_string(), |o| o.origin.clone());
        SceneError {
            origin,
            line: None,
            column: None,
            key,
            message,
        }
    }

    /// An error at `span` of the shared address space; line and column are given for the file only.
    /// Without a span the error names the file and no position.
    pub(super) fn error(
        &self,
        span: Option<Range<usize>>,
        key: Option<String>,
        message: String,
    ) -> SceneError {
        let at = span.map(|s| s.start);
        if let Some(text) = at.and_then(|offset| self.overrides.iter().find(|o| o.contains(offset)))
        {
            return SceneError {
                origin: text.origin.clone(),
                line: None,
                column: None,
                key,
                message,
            };
        }
        let position = at
            .filter(|&offset| self.file.contains(offset))
            .map(|offset| line_column(&self.file.text, offset));
        SceneError {
            origin: self.file.origin.clone(),
            line: position.map(|(line, _)| line),
            column: position.map(|(_, column)| column),
            key,
            message,
        }
    }
}

/// 1-based line and column (in characters) of a byte offset into `text`.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text.as_bytes()[..offset.min(text.len())];
    let line_start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |newline| newline + 1);
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let column = String::from_utf8_lossy(&before[line_start..])
        .chars()
        .count()
        + 1;
    (line, column)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_column_is_one_based_and_counts_characters() {
        let text = "a = 1\nbé = 2\n";
        assert_eq!(line_column(text, 0), (1, 1));
        assert_eq!(line_column(text, 4), (1, 5));
        let two = text.find('2').unwrap();
        assert_eq!(line_column(text, two), (2, 6));
        assert_eq!(line_column(text, text.len()), (3, 1));
    }

    #[test]
    fn spans_are_attributed_to_the_text_they_fall_in() {
        let overrides = ["render.width=0".to_string(), "a=b".to_string()];
        let map = SourceMap::new("scene.toml", "x = 1\n", &overrides);
        let in_file = map.error(Some(4..5), None, String::new());
        assert_eq!(
            (in_file.origin.as_str(), in_file.line, in_file.column),
            ("scene.toml", Some(1), Some(5))
        );
        let starts: Vec<usize> = map.overrides().map(|(_, start)| start).collect();
        assert_eq!(starts, [7, 22]);
        let first = map.error(Some(20..21), None, String::new());
        assert_eq!(
            (first.origin.as_str(), first.line),
            ("--set render.width=0", None)
        );
        let second = map.error(Some(22..23), None, String::new());
        assert_eq!(second.origin, "--set a=b");
        assert_eq!(map.error(None, None, String::new()).origin, "scene.toml");
    }
}
