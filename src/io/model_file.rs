//! Reading model files (TOML, docs/model-format.md).
//!
//! A file is read in three stages, each reporting every problem it can
//! find reliably:
//! 1. TOML syntax: the first error only (after a syntax error the rest of
//!    the file cannot be read as it was meant);
//! 2. the schema (unknown keys, wrong types, missing required keys): an
//!    unknown key is taken out and the file deserialised again, so that
//!    every misspelt key is reported in one go; any other schema error
//!    ends this stage, as what follows it would depend on a guess;
//! 3. the model's consistency ([`Model::from_input`]): every problem.
//!
//! A stage runs only when the one before found nothing.

use std::ops::Range;
use std::path::{Path, PathBuf};

use std::sync::Arc;

use serde::Deserialize;
use toml::de::{DeTable, DeValue};

use crate::analysis::AnalysisSettings;
use crate::model::input::{ModelInput, TOP_LEVEL_KEYS};
use crate::model::{Model, ModelErrors};

/// Most schema errors reported for one file.
pub const MAX_SCHEMA_ERRORS: usize = 20;

/// Why a model file could not be turned into a model.
#[derive(Debug, thiserror::Error)]
pub enum ModelFileError {
    /// The file could not be read.
    #[error("{path}: cannot read the file: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file is not valid TOML or does not follow the schema (unknown
    /// field, wrong type, missing field).
    #[error("{}", messages.iter().map(|m| format!("{}: {m}", path.display())).collect::<Vec<_>>().join("\n"))]
    Parse {
        /// The file.
        path: PathBuf,
        /// The parser's messages, each with its line and column: one for
        /// a syntax error, one per misspelt key (and at most one other
        /// schema error) otherwise.
        messages: Vec<String>,
    },
    /// The model is inconsistent (unknown node, zero-length beam...).
    #[error("{}", format_model_errors(path, errors))]
    Invalid {
        /// The file.
        path: PathBuf,
        /// Every problem found.
        errors: ModelErrors,
    },
}

fn format_model_errors(path: &Path, errors: &ModelErrors) -> String {
    errors
        .0
        .iter()
        .map(|e| format!("{}: {e}", path.display()))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Parses model-file text (`path` is only used in messages): the first
/// syntax error, or every misspelt key (see the module documentation).
pub fn parse_model(text: &str, path: &Path) -> Result<ModelInput, ModelFileError> {
    let failed = |messages: Vec<String>| ModelFileError::Parse {
        path: path.to_path_buf(),
        messages,
    };
    let render = |e: &toml::de::Error| render_error(e, false);
    // a sound file is read once
    let first = match toml::from_str(text) {
        Ok(input) => return Ok(input),
        Err(e) => e,
    };
    let Ok(original) = DeTable::parse(text) else {
        return Err(failed(vec![render_error(&first, true)]));
    };
    let mut root = original.clone();
    // (position in the text, message)
    let mut messages: Vec<(usize, String)> = Vec::new();
    // spans of the tables whose misspelt keys were taken out
    let mut amended: Vec<Range<usize>> = Vec::new();
    while messages.len() < MAX_SCHEMA_ERRORS {
        let mut error = match ModelInput::deserialize(toml::de::Deserializer::from(root.clone())) {
            Ok(input) if messages.is_empty() => return Ok(input),
            Ok(_) => break,
            Err(e) => e,
        };
        error.set_input(Some(text));
        let Some(span) = error.span() else {
            messages.push((0, render(&error)));
            break;
        };
        // a required key missing from a table whose misspelt key was
        // taken out: the same mistake, already reported; the table is
        // left out to look further
        if error.message().starts_with("missing field")
            && amended.iter().any(|t| overlap(t, &span))
            && remove_table(root.get_mut(), &span)
        {
            continue;
        }
        let mut message = render(&error);
        let misspelt = if error.message().starts_with("unknown field") {
            find_key(original.get_ref(), &original.span(), &span, None)
        } else {
            None
        };
        if let Some(found) = &misspelt {
            if let (true, Some(table)) =
                (TOP_LEVEL_KEYS.contains(&found.key.as_str()), &found.table)
            {
                message.push_str(&format!(
                    "\nhint: `{}` is a top-level key, but here it is read as a key of {table}: TOML puts every key written after a `[table]` or `[[table]]` header into that table; write top-level keys before the first header",
                    found.key
                ));
            }
        }
        messages.push((span.start, message));
        match misspelt {
            Some(found) if remove_key(root.get_mut(), &span) => amended.push(found.table_span),
            _ => break,
        }
    }
    // in the order of the file (tables are deserialised in key order)
    messages.sort_by_key(|m| m.0);
    Err(failed(messages.into_iter().map(|m| m.1).collect()))
}

/// An error of the TOML reader in the words of a model file: "TOML syntax
/// error at line …" when the text is not TOML, "line …, column …" when a
/// value or key does not fit the model's schema, with the reader's
/// message said in model-file words (see [`humanize`]).
fn render_error(e: &toml::de::Error, syntax: bool) -> String {
    let mut text = e.to_string().trim_end().to_string();
    let head = if syntax { "TOML syntax error at " } else { "" };
    if let Some(rest) = text.strip_prefix("TOML parse error at ") {
        text = format!("{head}{rest}");
    }
    if !syntax {
        let message = e.message().trim_end();
        if let Some(at) = text.rfind(message) {
            text.replace_range(at..at + message.len(), &humanize(message));
        }
    }
    text
}

/// A schema error of the deserialiser in the words of a model file: the
/// Rust types serde names (`f64`, `u64`, `usize`, `a sequence`) as the
/// kinds of TOML value, a string that holds a number noticed (quotes make
/// it a string), a missing key said as such.
fn humanize(message: &str) -> String {
    if let Some(rest) = message.strip_prefix("missing field `") {
        let key = rest.split('`').next().unwrap_or(rest);
        return format!("the required key `{key}` is missing from this table");
    }
    let mut m = message.to_string();
    for (rust, words) in [
        ("expected f64", "expected a number"),
        ("expected f32", "expected a number"),
        ("expected u64", "expected a whole number, 0 or more"),
        ("expected u32", "expected a whole number, 0 or more"),
        ("expected usize", "expected a whole number, 0 or more"),
        ("expected i64", "expected a whole number"),
        ("expected i32", "expected a whole number"),
        ("expected a sequence", "expected a list `[…]`"),
        ("expected a map", "expected a table"),
        ("floating point `", "number `"),
        ("invalid type: sequence", "invalid type: list"),
        ("invalid type: map", "invalid type: table"),
    ] {
        m = m.replace(rust, words);
    }
    // `mass = "0.5"`: a number written as a string
    if let Some(rest) = m.strip_prefix("invalid type: string \"") {
        if let Some((text, expected)) = rest.split_once("\", ") {
            if expected.contains("number") && text.trim().parse::<f64>().is_ok() {
                m.push_str(&format!(
                    " (\"{text}\" is a string: write numbers without quotes, {text})"
                ));
            }
        }
    }
    m
}

/// Whether two spans of the text share a character (or are both the
/// same empty span).
fn overlap(a: &Range<usize>, b: &Range<usize>) -> bool {
    a == b || (a.start < b.end && b.start < a.end)
}

/// A key found in the file.
struct FoundKey {
    /// Its name.
    key: String,
    /// The table it is in, as the file writes it (`[analysis]`,
    /// `[[nodes]] entry 2`); `None` at the top level.
    table: Option<String>,
    /// The span of that table.
    table_span: Range<usize>,
}

/// The key at `span` in `table` (whose own span is `table_span` and name
/// `name`) or in a table within it.
fn find_key(
    table: &DeTable<'_>,
    table_span: &Range<usize>,
    span: &Range<usize>,
    name: Option<String>,
) -> Option<FoundKey> {
    if let Some(key) = table.keys().find(|k| k.span() == *span) {
        return Some(FoundKey {
            key: key.get_ref().to_string(),
            table: name,
            table_span: table_span.clone(),
        });
    }
    let label = |inner: String| match &name {
        None => inner,
        Some(outer) => format!("{inner} in {outer}"),
    };
    for (key, value) in table.iter() {
        let found =
            match value.get_ref() {
                DeValue::Table(t) => find_key(
                    t,
                    &value.span(),
                    span,
                    Some(label(format!("[{}]", key.get_ref()))),
                ),
                DeValue::Array(items) => items.iter().enumerate().find_map(|(i, item)| match item
                    .get_ref()
                {
                    DeValue::Table(t) => find_key(
                        t,
                        &item.span(),
                        span,
                        Some(label(format!("[[{}]] entry {}", key.get_ref(), i + 1))),
                    ),
                    _ => None,
                }),
                _ => None,
            };
        if found.is_some() {
            return found;
        }
    }
    None
}

/// Removes the entry whose key is at `span` from `table` or a table within
/// it; whether it was found.
fn remove_key(table: &mut DeTable<'_>, span: &Range<usize>) -> bool {
    if let Some(key) = table.keys().find(|k| k.span() == *span) {
        let key = key.get_ref().to_string();
        table.remove(key.as_str());
        return true;
    }
    table.iter_mut().any(|(_, value)| match value.get_mut() {
        DeValue::Table(t) => remove_key(t, span),
        DeValue::Array(items) => items.iter_mut().any(|item| match item.get_mut() {
            DeValue::Table(t) => remove_key(t, span),
            _ => false,
        }),
        _ => false,
    })
}

/// Removes the table at `span` (a table entry or an element of an array
/// of tables, never a whole array) from `table` or a table within it;
/// whether it was found.
fn remove_table<'i>(table: &mut DeTable<'i>, span: &Range<usize>) -> bool {
    if let Some(key) = table
        .iter()
        .find(|(_, v)| matches!(v.get_ref(), DeValue::Table(_)) && v.span() == *span)
        .map(|(k, _)| k.get_ref().to_string())
    {
        table.remove(key.as_str());
        return true;
    }
    table.iter_mut().any(|(_, value)| match value.get_mut() {
        DeValue::Table(t) => remove_table(t, span),
        DeValue::Array(items) => {
            if items.iter().any(|item| item.span() == *span) {
                let kept: toml::de::DeArray<'i> =
                    std::mem::replace(items, toml::de::DeArray::new())
                        .into_iter()
                        .filter(|item| item.span() != *span)
                        .collect();
                *items = kept;
                true
            } else {
                items.iter_mut().any(|item| match item.get_mut() {
                    DeValue::Table(t) => remove_table(t, span),
                    _ => false,
                })
            }
        }
        _ => false,
    })
}

/// A model file read and validated: the model and, beside it, the
/// analyses the file asks for, in order.
pub struct ModelFile {
    /// The file as written.
    pub input: ModelInput,
    /// The model.
    pub model: Arc<Model>,
    /// The analyses (`[analysis]`, or each `[[analysis]]` of a sequence).
    pub analyses: Vec<AnalysisSettings>,
}

/// Reads and validates a model file.
pub fn read_model(path: &Path) -> Result<ModelFile, ModelFileError> {
    let text = std::fs::read_to_string(path).map_err(|source| ModelFileError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let mut input = parse_model(&text, path)?;
    input.base_dir = path.parent().map(Path::to_path_buf);
    let invalid = |errors| ModelFileError::Invalid {
        path: path.to_path_buf(),
        errors,
    };
    let model = Model::from_input(&input).map_err(invalid)?;
    let analyses = input.analyses().map_err(invalid)?;
    Ok(ModelFile {
        input,
        model: Arc::new(model),
        analyses,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`TOP_LEVEL_KEYS`] are exactly the keys the schema accepts at the
    /// top level (as the parser lists them for an unknown one).
    #[test]
    fn top_level_keys_are_the_schema_keys() {
        let e = toml::from_str::<ModelInput>("not_a_key = 1").unwrap_err();
        let listed: Vec<&str> = e
            .message()
            .split("expected one of ")
            .nth(1)
            .unwrap()
            .split(", ")
            .map(|k| k.trim_matches('`'))
            .collect();
        assert_eq!(listed, TOP_LEVEL_KEYS);
    }

    /// Misspelt keys are all found, each once, in the order of the file;
    /// a table left without its required key after its misspelt one was
    /// taken out is not reported again; a syntax error stops at once.
    #[test]
    fn misspelt_keys_are_collected() {
        let path = Path::new("m.toml");
        let messages = |text: &str| match parse_model(text, path) {
            Err(ModelFileError::Parse { messages, .. }) => messages,
            other => panic!("{other:?}"),
        };
        let m = messages(
            "titel = \"x\"\n[[nodes]]\nidd = 1\nx = [0.0, 0.0, 0.0]\n[[nodes]]\nid = 2\nx = [1.0, 0.0, 0.0]\nxx = 1\n",
        );
        assert_eq!(m.len(), 3, "{m:?}");
        assert!(m[0].contains("`titel`") && m[1].contains("`idd`") && m[2].contains("`xx`"));
        assert!(m.iter().all(|m| !m.contains("missing field")));
        let m = messages("[[nodes]\nid = 1\nfoo = 2\n");
        assert_eq!(m.len(), 1, "{m:?}");
        assert!(m[0].contains("line 1"), "{m:?}");
        // at most MAX_SCHEMA_ERRORS
        let many: String = (0..30).map(|i| format!("k{i} = 1\n")).collect();
        assert_eq!(messages(&many).len(), MAX_SCHEMA_ERRORS);
    }
}
