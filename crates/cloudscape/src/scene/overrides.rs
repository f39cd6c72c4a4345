//! `--set key.path=value` overrides, applied to the parsed document before it is deserialised.
//!
//! The value is TOML (`640`, `0.3`, `[0, 500, 0]`, `"out.png"`); text that is not a TOML value is
//! taken as a string (`render.output=out.png`). Missing tables on the path are created; an index into
//! an array the file lacks takes that array from the embedded default scene (so `layers.0.coverage`
//! works on a file without `[[layers]]`).
//!
//! The command line is the user's latest word: an override of a value others derive from
//! (`weather.metar`, `sun.time_of_day`) replaces what came before it of the values it derives
//! (the file's `layers` and `sky.visibility_m`, its sun angles), and says so in a note.

use std::borrow::Cow;
use std::ops::Range;

use toml::Spanned;
use toml::de::{DeArray, DeTable, DeValue};
use toml::map::Entry;

use super::derive::DERIVED;
use super::source_map::SourceMap;
use super::{DEFAULT_SCENE_TOML, SceneError, key_path};

/// Applies every override of `sources`, in order, to `root`. Returns a note, one line each, for
/// every value an override replaced without naming it (see the module documentation).
pub(super) fn apply_all<'a>(
    root: &mut DeTable<'a>,
    sources: &'a SourceMap,
) -> Result<Vec<String>, SceneError> {
    let mut notes = Vec::new();
    for (index, (text, start)) in sources.overrides().enumerate() {
        let parsed = Override::parse(text, start)
            .map_err(|message| sources.override_error(index, None, message))?;
        let key = key_path::join(&parsed.path);
        notes.extend(replace_derived(root, &key));
        parsed
            .apply(root)
            .map_err(|message| sources.override_error(index, Some(key), message))?;
    }
    Ok(notes)
}

/// When `key` sets (part of) a value that others derive from, removes those others from `root`
/// and names them; else nothing.
fn replace_derived(root: &mut DeTable<'_>, key: &str) -> Option<String> {
    let (source, derived) = DERIVED.iter().find(|(source, _)| {
        key == *source
            || key
                .strip_prefix(source)
                .is_some_and(|rest| rest.starts_with('.'))
    })?;
    let removed: Vec<&str> = derived
        .iter()
        .copied()
        .filter(|path| remove_path(root, &path.split('.').collect::<Vec<_>>()))
        .collect();
    (!removed.is_empty()).then(|| {
        format!(
            "--set {source} replaces the scene's {}",
            removed.join(" and ")
        )
    })
}

/// Removes the value at `path` (table keys only) from `table`; whether there was one.
fn remove_path(table: &mut DeTable<'_>, path: &[&str]) -> bool {
    match path {
        [] => false,
        [last] => table.remove(*last).is_some(),
        [first, rest @ ..] => match table.get_mut(*first).map(Spanned::get_mut) {
            Some(DeValue::Table(child)) => remove_path(child, rest),
            _ => false,
        },
    }
}

/// One parsed `key.path=value`, its spans in the shared address space of [`SourceMap`].
struct Override<'a> {
    path: Vec<String>,
    /// Span of the key text: new keys, and arrays copied from the defaults, are located here.
    key_span: Range<usize>,
    value: Spanned<DeValue<'a>>,
}

impl<'a> Override<'a> {
    fn parse(text: &'a str, start: usize) -> Result<Override<'a>, String> {
        let Some((key_text, value_text)) = text.split_once('=') else {
            return Err(
                "expected key.path=value, e.g. render.width=640 or layers.0.coverage=0.3"
                    .to_string(),
            );
        };
        if key_text.trim().is_empty() {
            return Err("the key before `=` is empty; expected e.g. render.width=640".to_string());
        }
        let path = key_path::parse(key_text)?;
        let key_span = start..start + key_text.len();
        let value = parse_value(value_text, start + key_text.len() + 1)?;
        Ok(Override {
            path,
            key_span,
            value,
        })
    }

    fn apply(self, root: &mut DeTable<'a>) -> Result<(), String> {
        let walk = Walk {
            path: &self.path,
            key_span: self.key_span,
        };
        walk.set_in_table(root, 0, self.value)
    }
}

/// Parses `text` (which starts at `start`) as a TOML value, or else takes it as a string. Text that
/// opens like a TOML array, table or quoted string must parse: a typo there is reported, not hidden.
fn parse_value(text: &str, start: usize) -> Result<Spanned<DeValue<'_>>, String> {
    let trimmed = text.trim();
    let offset = start + (text.len() - text.trim_start().len());
    match DeValue::parse(trimmed) {
        Ok(value) => Ok(respan(value, &|span| {
            offset + span.start..offset + span.end
        })),
        Err(error) if trimmed.starts_with(['[', '{', '"', '\'']) => Err(format!(
            "`{trimmed}` is not a valid TOML value: {}",
            error.message()
        )),
        Err(_) => Ok(Spanned::new(
            offset..offset + trimmed.len(),
            DeValue::String(Cow::Borrowed(trimmed)),
        )),
    }
}

/// Rebuilds `value` with every span (its own and its children's) mapped by `map`.
fn respan<'i>(
    value: Spanned<DeValue<'i>>,
    map: &dyn Fn(Range<usize>) -> Range<usize>,
) -> Spanned<DeValue<'i>> {
    let span = map(value.span());
    let inner = match value.into_inner() {
        DeValue::Table(table) => DeValue::Table(
            table
                .into_iter()
                .map(|(key, child)| {
                    (
                        Spanned::new(map(key.span()), key.into_inner()),
                        respan(child, map),
                    )
                })
                .collect(),
        ),
        DeValue::Array(array) => {
            let mut rebuilt = DeArray::new();
            array
                .into_iter()
                .for_each(|element| rebuilt.push(respan(element, map)));
            DeValue::Array(rebuilt)
        }
        leaf => leaf,
    };
    Spanned::new(span, inner)
}

/// The walk of one override down its key path.
struct Walk<'p> {
    path: &'p [String],
    key_span: Range<usize>,
}

impl Walk<'_> {
    /// Sets `path[depth..]` inside `table` to `value`.
    fn set_in_table<'a>(
        &self,
        table: &mut DeTable<'a>,
        depth: usize,
        value: Spanned<DeValue<'a>>,
    ) -> Result<(), String> {
        let key = Spanned::new(self.key_span.clone(), Cow::Owned(self.path[depth].clone()));
        if depth + 1 == self.path.len() {
            table.insert(key, value);
            return Ok(());
        }
        let child = match table.entry(key) {
            Entry::Occupied(existing) => existing.into_mut(),
            Entry::Vacant(absent) => absent.insert(self.missing(depth)?),
        };
        self.set_in_value(child, depth + 1, value)
    }

    /// Sets `path[depth..]` inside `node`, a table or an array.
    fn set_in_value<'a>(
        &self,
        node: &mut Spanned<DeValue<'a>>,
        depth: usize,
        value: Spanned<DeValue<'a>>,
    ) -> Result<(), String> {
        let parent = key_path::join(&self.path[..depth]);
        match node.get_mut() {
            DeValue::Table(table) => self.set_in_table(table, depth, value),
            DeValue::Array(array) => {
                let segment = &self.path[depth];
                let index = key_path::index(segment).ok_or_else(|| {
                    format!("{parent} is an array; `{segment}` is not an index, e.g. {parent}.0")
                })?;
                let count = array.len();
                let element = array.get_mut(index).ok_or_else(|| {
                    format!("index {index} is past the end of {parent} (length {count})")
                })?;
                if depth + 1 == self.path.len() {
                    *element = value;
                    Ok(())
                } else {
                    self.set_in_value(element, depth + 1, value)
                }
            }
            other => Err(self.not_a_container(depth, other)),
        }
    }

    /// The value to create at `path[..=depth]`, absent from the document but not the last segment:
    /// the default scene's array when it has one there, else an empty table. A path through a
    /// single value of the default scene is an error.
    fn missing<'a>(&self, depth: usize) -> Result<Spanned<DeValue<'a>>, String> {
        let key_span = self.key_span.clone();
        match default_value(&self.path[..=depth]) {
            Some(value) if value.get_ref().is_array() => Ok(respan(value, &|_| key_span.clone())),
            Some(value) if !value.get_ref().is_table() => {
                Err(self.not_a_container(depth + 1, value.get_ref()))
            }
            _ => Ok(Spanned::new(key_span, DeValue::Table(DeTable::new()))),
        }
    }

    /// The message for a path that goes on below `path[..depth]`, which holds `value`.
    fn not_a_container(&self, depth: usize, value: &DeValue<'_>) -> String {
        let parent = key_path::join(&self.path[..depth]);
        format!(
            "{parent} is a single value ({}), not a table with `{}` in it",
            value.type_str(),
            self.path[depth]
        )
    }
}

/// The value at `path` in the embedded default scene, if there is one.
fn default_value(path: &[String]) -> Option<Spanned<DeValue<'static>>> {
    let mut table = DeTable::parse(DEFAULT_SCENE_TOML).ok()?.into_inner();
    let (last, parents) = path.split_last()?;
    for segment in parents {
        match table.remove(segment.as_str())?.into_inner() {
            DeValue::Table(child) => table = child,
            _ => return None,
        }
    }
    table.remove(last.as_str())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_that_are_not_toml_become_strings_and_spans_are_shifted() {
        let value = parse_value(" out.png", 100).unwrap();
        assert_eq!(value.get_ref().as_str(), Some("out.png"));
        assert_eq!(value.span(), 101..108);
        let array = parse_value("[0, 500, 0]", 10).unwrap();
        let second = array.get_ref().as_array().unwrap()[1].span();
        assert_eq!(second, 14..17);
    }

    #[test]
    fn broken_arrays_are_reported_not_taken_as_strings() {
        let error = parse_value("[1, 2", 0).unwrap_err();
        assert!(
            error.starts_with("`[1, 2` is not a valid TOML value"),
            "{error}"
        );
    }

    #[test]
    fn default_values_are_found_by_path() {
        let path = |text: &str| key_path::parse(text).unwrap();
        let layers = default_value(&path("layers")).unwrap();
        assert_eq!(layers.get_ref().as_array().unwrap().len(), 1);
        assert_eq!(
            default_value(&path("render.width"))
                .unwrap()
                .get_ref()
                .as_integer()
                .unwrap()
                .as_str(),
            "1280"
        );
        assert!(default_value(&path("render.nothing")).is_none());
    }
}
