//! Between key paths and spans of a parsed TOML document.

use std::ops::Range;

use toml::Spanned;
use toml::de::{DeTable, DeValue};

use super::key_path;

/// The span of the value at `path`; when the path goes deeper than the document, the span of the
/// deepest value it reaches (the table a default was taken from). `None` when not even the first
/// segment is in the document.
pub(super) fn span_of(root: &DeTable<'_>, path: &[String]) -> Option<Range<usize>> {
    let (first, rest) = path.split_first()?;
    let mut node = root.get(first.as_str())?;
    for segment in rest {
        match child(node.get_ref(), segment) {
            Some(next) => node = next,
            None => break,
        }
    }
    Some(node.span())
}

/// The span of the value at `path` when the document gives it (no fallback to a table above).
pub(super) fn given_span(root: &DeTable<'_>, path: &[&str]) -> Option<Range<usize>> {
    let (first, rest) = path.split_first()?;
    let mut node = root.get(*first)?;
    for segment in rest {
        node = child(node.get_ref(), segment)?;
    }
    Some(node.span())
}

/// The key path of the deepest key or value whose span contains `span`.
pub(super) fn path_at(root: &DeTable<'_>, span: &Range<usize>) -> Option<String> {
    let mut best: Option<Vec<String>> = None;
    visit_table(root, &mut Vec::new(), &mut |path, key_span, value_span| {
        let inside = key_span.is_some_and(|key| contains(key, span)) || contains(value_span, span);
        if inside && best.as_ref().is_none_or(|b| path.len() > b.len()) {
            best = Some(path.to_vec());
        }
    });
    best.map(|path| key_path::join(&path))
}

/// The key path of the last key that starts within `range` (e.g. a line up to a syntax error).
pub(super) fn last_key_in(root: &DeTable<'_>, range: &Range<usize>) -> Option<String> {
    let mut best: Option<(usize, Vec<String>)> = None;
    visit_table(root, &mut Vec::new(), &mut |path, key_span, _| {
        let Some(start) = key_span.map(|key| key.start) else {
            return;
        };
        if range.contains(&start) && best.as_ref().is_none_or(|(b, _)| start >= *b) {
            best = Some((start, path.to_vec()));
        }
    });
    best.map(|(_, path)| key_path::join(&path))
}

/// The child of a table (by key) or an array (by index).
fn child<'a, 'i>(value: &'a DeValue<'i>, segment: &str) -> Option<&'a Spanned<DeValue<'i>>> {
    match value {
        DeValue::Table(table) => table.get(segment),
        DeValue::Array(array) => array.get(key_path::index(segment)?),
        _ => None,
    }
}

fn contains(outer: &Range<usize>, inner: &Range<usize>) -> bool {
    outer.start <= inner.start && inner.end <= outer.end
}

/// Calls `f` with the path, key span and value span of every entry of the tree, depth first, and
/// with the path and span of every array element (which has no key). The whole tree is visited because a table's span is its `[header]`, which does not
/// contain the table's keys.
fn visit_table(table: &DeTable<'_>, path: &mut Vec<String>, f: &mut Visitor<'_>) {
    for (key, value) in table.iter() {
        path.push(key.get_ref().to_string());
        f(path, Some(&key.span()), &value.span());
        visit_children(value.get_ref(), path, f);
        path.pop();
    }
}

/// Called with a path, its key's span (none for array elements) and its value's span.
type Visitor<'f> = dyn FnMut(&[String], Option<&Range<usize>>, &Range<usize>) + 'f;

fn visit_children(value: &DeValue<'_>, path: &mut Vec<String>, f: &mut Visitor<'_>) {
    match value {
        DeValue::Table(table) => visit_table(table, path, f),
        DeValue::Array(array) => {
            for (index, element) in array.iter().enumerate() {
                path.push(index.to_string());
                f(path, None, &element.span());
                visit_children(element.get_ref(), path, f);
                path.pop();
            }
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str =
        "[camera]\nfov_y_deg = 5\nposition_m = [1, 2, 3]\n\n[[layers]]\ncoverage = 0.5\n";

    fn path(text: &str) -> Vec<String> {
        key_path::parse(text).unwrap()
    }

    #[test]
    fn span_of_finds_values_array_elements_and_falls_back_to_tables() {
        let root = DeTable::parse(TEXT).unwrap().into_inner();
        let text_at = |p: &str| span_of(&root, &path(p)).map(|s| &TEXT[s]);
        assert_eq!(text_at("camera.fov_y_deg"), Some("5"));
        assert_eq!(text_at("camera.position_m.1"), Some("2"));
        assert_eq!(text_at("layers.0.coverage"), Some("0.5"));
        assert_eq!(text_at("camera.near_m"), Some("[camera]"));
        assert_eq!(text_at("render.width"), None);
    }

    #[test]
    fn path_at_names_the_deepest_key() {
        let root = DeTable::parse(TEXT).unwrap().into_inner();
        let at = |needle: &str| {
            let start = TEXT.find(needle).unwrap();
            path_at(&root, &(start..start + needle.len()))
        };
        assert_eq!(at("fov_y_deg").as_deref(), Some("camera.fov_y_deg"));
        assert_eq!(at("2").as_deref(), Some("camera.position_m.1"));
        assert_eq!(at("0.5").as_deref(), Some("layers.0.coverage"));
        assert_eq!(path_at(&root, &(7000..7001)), None);
    }

    #[test]
    fn last_key_in_finds_the_key_on_a_line() {
        let root = DeTable::parse(TEXT).unwrap().into_inner();
        let line = TEXT.find("position_m").unwrap()..TEXT.find("[[layers]]").unwrap();
        assert_eq!(
            last_key_in(&root, &line).as_deref(),
            Some("camera.position_m")
        );
        assert_eq!(last_key_in(&root, &(0..1)), None);
    }
}
