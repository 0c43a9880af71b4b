//! Where a problem is: the line, the column, the table and the key of a toml error, found in
//! the spans of the toml crate's own parse of the file (`Spans`), and which `LoadError`
//! variant it is (from serde's error kinds: unknown field, missing field, unknown variant,
//! invalid type).

use super::schema::{LightToml, MaterialToml, ShapeToml};
use crate::error::LoadError;
use std::ops::Range;
use std::path::Path;

use ::toml::de::{DeTable, DeValue};

/// 1-based line and column of a byte offset.
pub(super) fn line_column(text: &str, offset: usize) -> (u32, u32) {
    let offset = offset.min(text.len());
    let before = text.get(..offset).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let column = before
        .rsplit('\n')
        .next()
        .map_or(1, |l| l.chars().count() + 1);
    (to_u32(line), to_u32(column))
}

pub(super) fn to_u32(x: usize) -> u32 {
    u32::try_from(x).unwrap_or(u32::MAX)
}

pub(super) fn syntax_error(path: &Path, text: &str, e: &::toml::de::Error) -> LoadError {
    let (line, column) = match e.span() {
        Some(span) => {
            let (l, c) = line_column(text, span.start);
            (Some(l), Some(c))
        }
        None => (None, None),
    };
    LoadError::Toml {
        path: path.to_path_buf(),
        line,
        column,
        message: first_line(e.message()),
    }
}

pub(super) fn first_line(s: &str) -> String {
    s.lines().next().unwrap_or("").trim().to_owned()
}

/// Where things are in the file, from the spans of the toml crate's own parse: every table
/// (by its header) and every key with its value.
struct Spans {
    /// `(start of the header, name)` of every table, in file order.
    tables: Vec<(usize, String)>,
    /// `(span of the key and its value, table name, key)` of every key of a table (the keys of
    /// an inline table count as the key that holds it).
    keys: Vec<(Range<usize>, String, String)>,
}

impl Spans {
    fn new(text: &str) -> Option<Self> {
        let root = DeTable::parse(text).ok()?;
        let mut spans = Self {
            tables: Vec::new(),
            keys: Vec::new(),
        };
        spans.table(text, root.get_ref(), None, "the top level");
        spans.tables.sort_by_key(|(start, _)| *start);
        Some(spans)
    }

    /// Records the keys of `table`, whose dotted path is `path` (`None` at the top level) and
    /// whose name in messages is `name`.
    fn table(&mut self, text: &str, table: &DeTable<'_>, path: Option<&str>, name: &str) {
        for (key, value) in table {
            let key_name = key.get_ref().to_string();
            let dotted = path.map_or_else(|| key_name.clone(), |p| format!("{p}.{key_name}"));
            let starts_with = |span: Range<usize>, c: char| {
                text.get(span.start..).is_some_and(|t| t.starts_with(c))
            };
            let is_header = |span: Range<usize>| starts_with(span, '[');
            match value.get_ref() {
                // A table of its own (a header, or implied by a dotted header), not an inline
                // `{ … }` value.
                DeValue::Table(inner) if !starts_with(value.span(), '{') => {
                    let inner_name = format!("[{dotted}]");
                    if is_header(value.span()) {
                        self.tables.push((value.span().start, inner_name.clone()));
                    }
                    self.table(text, inner, Some(&dotted), &inner_name);
                }
                DeValue::Array(items)
                    if items.iter().any(|i| {
                        matches!(i.get_ref(), DeValue::Table(_)) && is_header(i.span())
                    }) =>
                {
                    for (n, item) in items.iter().enumerate() {
                        if let DeValue::Table(inner) = item.get_ref() {
                            let inner_name = format!("[[{dotted}]] #{}", n + 1);
                            self.tables.push((item.span().start, inner_name.clone()));
                            self.table(text, inner, Some(&dotted), &inner_name);
                        }
                    }
                }
                _ => {
                    let span = key.span().start.min(value.span().start)..value.span().end;
                    self.keys.push((span, name.to_owned(), key_name));
                }
            }
        }
    }

    /// The table in force at byte `offset`: that of the last header at or before it.
    fn table_at(&self, offset: usize) -> String {
        self.tables
            .iter()
            .rfind(|(start, _)| *start <= offset)
            .map_or_else(|| "the top level".to_owned(), |(_, name)| name.clone())
    }

    /// The key whose key or value holds byte `offset`, with where it starts.
    fn key_at(&self, offset: usize) -> Option<(&str, usize)> {
        self.keys
            .iter()
            .find(|(span, _, _)| span.contains(&offset))
            .map(|(span, _, key)| (key.as_str(), span.start))
    }

    /// Where key `key` of table `table` starts.
    fn find_key(&self, table: &str, key: &str) -> Option<usize> {
        self.keys
            .iter()
            .find(|(_, t, k)| t == table && k == key)
            .map(|(span, _, _)| span.start)
    }
}

/// For a wrong value inside a table that serde buffered (an internally tagged enum:
/// `[materials.*]`, `[[shapes]]`, `[[lights]]`), whose error spans the whole table (for an
/// array of tables, the whole array) and names no key: the table and the key at fault. The
/// table is the first of its kind that does not read on its own; the key is found by reading it
/// again without each of its keys in turn: the key whose absence makes the table read, or fail
/// differently, is the one.
fn culprit(text: &str, table: &str) -> Option<(String, String)> {
    let doc: ::toml::Table = text.parse().ok()?;
    if let Some(name) = table
        .strip_prefix("[materials.")
        .and_then(|n| n.strip_suffix(']'))
    {
        let value = doc.get("materials")?.as_table()?.get(name)?.clone();
        return Some((table.to_owned(), culprit_in::<MaterialToml>(value)?));
    }
    let in_list = |list: &str, key: fn(::toml::Value) -> Option<String>| {
        let items = doc.get(list)?.as_array()?;
        items
            .iter()
            .enumerate()
            .find_map(|(i, item)| key(item.clone()).map(|k| (format!("[[{list}]] #{}", i + 1), k)))
    };
    if table.starts_with("[[shapes]]") {
        in_list("shapes", culprit_in::<ShapeToml>)
    } else if table.starts_with("[[lights]]") {
        in_list("lights", culprit_in::<LightToml>)
    } else {
        None
    }
}

fn culprit_in<T: serde::de::DeserializeOwned>(value: ::toml::Value) -> Option<String> {
    let ::toml::Value::Table(table) = value else {
        return None;
    };
    let baseline = T::deserialize(::toml::Value::Table(table.clone()))
        .err()?
        .to_string();
    table.keys().filter(|k| *k != "type").find_map(|key| {
        let mut without = table.clone();
        without.remove(key);
        match T::deserialize(::toml::Value::Table(without)) {
            Ok(_) => Some(key.clone()),
            Err(e) if e.to_string() != baseline => Some(key.clone()),
            Err(_) => None,
        }
    })
}

/// Turns a serde/toml error into the most specific variant.
pub(super) fn schema_error(path: &Path, text: &str, e: &::toml::de::Error) -> LoadError {
    let message = first_line(e.message());
    let offset = e.span().map(|s| s.start);
    let (line, column) = match offset {
        Some(o) => {
            let (l, c) = line_column(text, o);
            (Some(l), Some(c))
        }
        None => (None, None),
    };
    let spans = Spans::new(text);
    let mut table = match (offset, &spans) {
        (Some(o), Some(spans)) => spans.table_at(o),
        _ => "the scene".to_owned(),
    };
    let at = |o: usize| {
        let (l, c) = line_column(text, o);
        (Some(l), Some(c))
    };
    let path = path.to_path_buf();
    if let Some(rest) = message.strip_prefix("unknown field `")
        && let Some((key, rest)) = rest.split_once('`')
    {
        let (line, column) = match spans.as_ref().and_then(|s| s.find_key(&table, key)) {
            Some(o) => at(o),
            None => (line, column),
        };
        let mut expected = expected_list(rest);
        // Serde leaves the tag out of a tagged table's list.
        let tagged = ["[materials.", "[[shapes]]", "[[lights]]"]
            .iter()
            .any(|t| table.starts_with(t));
        if tagged && !expected.split(", ").any(|k| k == "type") {
            expected = format!("type, {expected}");
        }
        return LoadError::UnknownKey {
            path,
            line,
            column,
            table,
            key: key.to_owned(),
            expected,
        };
    }
    if let Some(rest) = message.strip_prefix("missing field `")
        && let Some((key, _)) = rest.split_once('`')
    {
        return LoadError::MissingKey {
            path,
            line,
            column,
            table,
            key: key.to_owned(),
        };
    }
    if let Some(rest) = message.strip_prefix("unknown variant `")
        && let Some((found, rest)) = rest.split_once('`')
    {
        return LoadError::UnknownType {
            path,
            line,
            column,
            table,
            found: found.to_owned(),
            expected: expected_list(rest),
        };
    }
    if message.starts_with("invalid type")
        || message.starts_with("invalid length")
        || message.starts_with("invalid value")
    {
        let found = offset.and_then(|o| spans.as_ref()?.key_at(o).map(|(k, s)| (k.to_owned(), s)));
        let (key, line, column) = match found {
            Some((key, start)) => {
                let (line, column) = at(start);
                (key, line, column)
            }
            None => match culprit(text, &table) {
                Some((in_table, key)) => {
                    let start = spans.as_ref().and_then(|s| s.find_key(&in_table, &key));
                    let (line, column) = start.map_or((line, column), at);
                    table = in_table;
                    (key, line, column)
                }
                None => (String::new(), line, column),
            },
        };
        return LoadError::WrongType {
            path,
            line,
            column,
            table,
            key,
            message,
        };
    }
    LoadError::Toml {
        path,
        line,
        column,
        message,
    }
}

/// `", expected one of `a`, `b`"` → `"a, b"`.
pub(super) fn expected_list(rest: &str) -> String {
    let names: Vec<&str> = rest.split('`').skip(1).step_by(2).collect();
    if names.is_empty() {
        "none".to_owned()
    } else {
        names.join(", ")
    }
}
