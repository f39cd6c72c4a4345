//! The loading pipeline: parse the file, apply the overrides, deserialise, validate; every error
//! located in the text it came from.

use std::ops::Range;

use serde::de::DeserializeOwned;
use toml::Spanned;
use toml::de::{DeTable, Deserializer};

use super::source_map::SourceMap;
use super::{Scene, SceneError, derive, key_path, locate, overrides, validate};

/// Builds the scene described by `sources`: the file with its overrides applied, checked, and
/// the values it derives from others (layers from a METAR report, the sun from the time of day)
/// filled in.
/// Also returns the notes of what the overrides replaced without naming it.
pub(super) fn scene(sources: &SourceMap) -> Result<(Scene, Vec<String>), SceneError> {
    let (root, notes) = document_with_notes(sources)?;
    let mut scene: Scene = deserialize(&root, sources)?;
    validate::validate(&scene).map_err(|v| error_at(Some(&root), sources, &v.key, v.message))?;
    derive::derive(&mut scene, &root, sources)?;
    Ok((scene, notes))
}

/// Builds the `T` that `sources` describe, checked by `check` (which names the dotted key of the
/// first bad value and what is wrong with it); every error located.
pub(super) fn document<T: DeserializeOwned>(
    sources: &SourceMap,
    check: impl Fn(&T) -> Result<(), (String, String)>,
) -> Result<T, SceneError> {
    let root = merged_document(sources)?;
    let value = deserialize(&root, sources)?;
    check(&value).map_err(|(key, message)| error_at(Some(&root), sources, &key, message))?;
    Ok(value)
}

/// The file's document with every override applied; spans index the address space of `sources`.
pub(super) fn merged_document(sources: &SourceMap) -> Result<DeTable<'_>, SceneError> {
    document_with_notes(sources).map(|(root, _)| root)
}

/// [`merged_document`], with the notes of what the overrides replaced without naming it.
fn document_with_notes(sources: &SourceMap) -> Result<(DeTable<'_>, Vec<String>), SceneError> {
    let mut root = parse_file(sources)?;
    let notes = overrides::apply_all(&mut root, sources)?;
    Ok((root, notes))
}

/// An error about the value at `key` (a dotted key path), located in `root` when the key (or the
/// table it would be in) is there.
pub(super) fn error_at(
    root: Option<&DeTable<'_>>,
    sources: &SourceMap,
    key: &str,
    message: String,
) -> SceneError {
    let path = key_path::parse(key).ok();
    let span = root
        .zip(path.as_deref())
        .and_then(|(root, path)| locate::span_of(root, path));
    let key = path.map_or_else(|| key.to_string(), |path| key_path::join(&path));
    sources.error(span, Some(key), message)
}

/// Parses the scene file; a syntax error is located, with the key it is in when known.
fn parse_file(sources: &SourceMap) -> Result<DeTable<'_>, SceneError> {
    let (root, errors) = DeTable::parse_recoverable(sources.file_text());
    let root = root.into_inner();
    match errors.into_iter().next() {
        None => Ok(root),
        Some(error) => {
            let key = error
                .span()
                .and_then(|span| syntax_error_key(&root, sources.file_text(), &span));
            Err(sources.error(error.span(), key, error.message().to_string()))
        }
    }
}

/// The key a syntax error at `span` is in: the key whose value holds it, or else the last key
/// that starts on its line before it (its value may be missing from the partial document).
fn syntax_error_key(root: &DeTable<'_>, text: &str, span: &Range<usize>) -> Option<String> {
    let line_start = text
        .get(..span.start)
        .and_then(|before| before.rfind('\n'))
        .map_or(0, |newline| newline + 1);
    locate::path_at(root, span).or_else(|| locate::last_key_in(root, &(line_start..span.start)))
}

/// Deserialises the merged document; unknown keys, wrong types and unknown enum strings are
/// reported at their span with the key path they are at.
fn deserialize<T: DeserializeOwned>(
    root: &DeTable<'_>,
    sources: &SourceMap,
) -> Result<T, SceneError> {
    let deserializer = Deserializer::from(Spanned::new(0..0, root.clone()));
    T::deserialize(deserializer).map_err(|error| {
        let key = error.span().and_then(|span| locate::path_at(root, &span));
        sources.error(error.span(), key, plain_words(error.message()))
    })
}

/// Rewrites serde's Rust type names in a message as the TOML types a user writes.
fn plain_words(message: &str) -> String {
    const RUST_TO_TOML: [(&str, &str); 3] = [
        ("expected f32", "expected a number"),
        ("expected u32", "expected an integer 0..4294967295"),
        ("expected a sequence", "expected an array"),
    ];
    let text = RUST_TO_TOML
        .iter()
        .fold(message.to_string(), |text, (rust, toml)| {
            text.replace(rust, toml)
        });
    // serde ends the message with "expected struct Name", the Rust type's name.
    match text.split_once("expected struct ") {
        Some((before, _rust_name)) => format!("{before}expected a table"),
        None => text,
    }
}
