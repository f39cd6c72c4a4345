//! Dotted key paths that name a value in a scene file: `render.width`, `layers.0.coverage`.

/// Splits a key path into its segments. Accepts dots (`layers.0.coverage`) and brackets
/// (`layers[0].coverage`); a bracketed segment must be an array index.
pub(super) fn parse(text: &str) -> Result<Vec<String>, String> {
    let normalized = brackets_to_dots(text)?;
    let segments: Vec<String> = normalized
        .split('.')
        .map(|s| s.trim().to_string())
        .collect();
    if segments.iter().any(String::is_empty) {
        return Err(format!(
            "`{text}` is not a key path; expected names joined by dots, e.g. layers.0.coverage"
        ));
    }
    Ok(segments)
}

/// Joins segments into the canonical dotted form used in messages.
pub(super) fn join(segments: &[String]) -> String {
    segments.join(".")
}

/// The segment as an array index, when it is one.
pub(super) fn index(segment: &str) -> Option<usize> {
    segment.parse().ok()
}

/// Rewrites `a[0].b` as `a.0.b`, checking that every bracket holds an index.
fn brackets_to_dots(text: &str) -> Result<String, String> {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(open) = rest.find('[') {
        let close = rest[open..].find(']').map(|c| open + c);
        let Some(close) = close else {
            return Err(format!("`{text}` has a `[` without a matching `]`"));
        };
        let inside = &rest[open + 1..close];
        if index(inside.trim()).is_none() {
            return Err(format!(
                "`[{inside}]` in `{text}` is not an array index; expected e.g. layers[0]"
            ));
        }
        out.push_str(&rest[..open]);
        out.push('.');
        out.push_str(inside.trim());
        rest = &rest[close + 1..];
        if !(rest.is_empty() || rest.starts_with('.') || rest.starts_with('[')) {
            return Err(format!("`{text}` needs a `.` after `]`"));
        }
    }
    if rest.contains(']') {
        return Err(format!("`{text}` has a `]` without a matching `[`"));
    }
    out.push_str(rest);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dots_and_brackets_give_the_same_segments() {
        let expected = vec![
            "layers".to_string(),
            "0".to_string(),
            "coverage".to_string(),
        ];
        assert_eq!(parse("layers.0.coverage").unwrap(), expected);
        assert_eq!(parse("layers[0].coverage").unwrap(), expected);
        assert_eq!(join(&expected), "layers.0.coverage");
    }

    #[test]
    fn malformed_paths_are_rejected() {
        for bad in [
            "",
            "render.",
            ".width",
            "a..b",
            "layers[x].coverage",
            "layers[0.coverage",
            "a]",
            "layers[0]coverage",
        ] {
            assert!(parse(bad).is_err(), "{bad:?} should be rejected");
        }
    }
}
