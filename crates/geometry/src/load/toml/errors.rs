//! Where a problem is: the line, the column and the table of a toml error, and which
//! `LoadError` variant it is.

use crate::error::LoadError;
use std::path::Path;

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

/// Byte offset of the end of the line holding `offset`.
pub(super) fn end_of_line(text: &str, offset: usize) -> usize {
    let offset = offset.min(text.len());
    text.get(offset..)
        .and_then(|rest| rest.find('\n'))
        .map_or(text.len(), |i| offset + i)
}

/// Strips a `#` comment (good enough for header lines).
pub(super) fn uncomment(line: &str) -> &str {
    line.split('#').next().unwrap_or(line).trim()
}

/// The table header in force at byte `offset` (the header line itself counts):
/// `[camera]`, `[materials.white]`, `[[shapes]] #2`, or `the top level`.
pub(super) fn table_at(text: &str, offset: usize) -> String {
    let before = text.get(..end_of_line(text, offset)).unwrap_or(text);
    let header = before.lines().map(str::trim).rfind(|l| l.starts_with('['));
    match header {
        None => "the top level".to_owned(),
        Some(h) => {
            let h = uncomment(h);
            if h.starts_with("[[") {
                let n = before.lines().filter(|l| uncomment(l) == h).count();
                format!("{h} #{n}")
            } else {
                h.to_owned()
            }
        }
    }
}

/// The key on the line at byte `offset` (`albedo` in `albedo = "red"`), if any.
pub(super) fn key_at(text: &str, offset: usize) -> Option<String> {
    let start = text
        .get(..offset.min(text.len()))
        .and_then(|b| b.rfind('\n'))
        .map_or(0, |i| i + 1);
    let line = text
        .get(start..)
        .and_then(|l| l.lines().next())
        .unwrap_or("");
    match line.split_once('=') {
        Some((k, _)) if !line.trim_start().starts_with('[') => Some(k.trim().to_owned()),
        _ => None,
    }
}

/// The lines of the table whose header (or any line) holds `offset`, with 0-based indices:
/// from the table's header line to the line before the next header.
pub(super) fn section(text: &str, offset: usize) -> Vec<(usize, &str)> {
    let first = text
        .get(..end_of_line(text, offset))
        .unwrap_or(text)
        .lines()
        .enumerate()
        .filter(|(_, l)| l.trim_start().starts_with('['))
        .map(|(i, _)| i)
        .last()
        .unwrap_or(0);
    text.lines()
        .enumerate()
        .skip(first)
        .take_while(|(i, l)| *i == first || !l.trim_start().starts_with('['))
        .collect()
}

/// The line and column of `key = …` inside the table holding `offset`.
pub(super) fn find_key(text: &str, offset: usize, key: &str) -> Option<(u32, u32)> {
    section(text, offset).into_iter().find_map(|(i, l)| {
        let (k, _) = l.split_once('=')?;
        (k.trim() == key).then(|| (to_u32(i + 1), to_u32(l.len() - l.trim_start().len() + 1)))
    })
}

/// For `invalid type: string "white", …`, the key in the table holding `offset` whose value
/// is written `"white"` (serde does not name the key; this finds it for plain values).
pub(super) fn find_key_by_value(
    text: &str,
    offset: usize,
    message: &str,
) -> Option<(String, u32, u32)> {
    let matches: Box<dyn Fn(&str) -> bool> = if let Some(rest) =
        message.strip_prefix("invalid length ")
    {
        // `invalid length 2, expected an array of length 3`: an array of 2 elements.
        let n: usize = rest.split(',').next()?.trim().parse().ok()?;
        Box::new(move |v: &str| {
            v.strip_prefix('[')
                .and_then(|v| v.strip_suffix(']'))
                .is_some_and(|inner| inner.split(',').filter(|e| !e.trim().is_empty()).count() == n)
        })
    } else {
        let rest = message.strip_prefix("invalid type: ")?;
        let literal = if let Some(r) = rest.strip_prefix("string ") {
            r.split(", expected").next()?.to_owned()
        } else {
            let (_, r) = rest.split_once('`')?;
            r.split('`').next()?.to_owned()
        };
        Box::new(move |v: &str| v == literal)
    };
    section(text, offset).into_iter().find_map(|(i, l)| {
        let (k, v) = l.split_once('=')?;
        matches(uncomment(v)).then(|| {
            (
                k.trim().to_owned(),
                to_u32(i + 1),
                to_u32(l.len() - l.trim_start().len() + 1),
            )
        })
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
    let table = offset.map_or_else(|| "the scene".to_owned(), |o| table_at(text, o));
    let path = path.to_path_buf();
    if let Some(rest) = message.strip_prefix("unknown field `")
        && let Some((key, rest)) = rest.split_once('`')
    {
        let (line, column) = match offset.and_then(|o| find_key(text, o, key)) {
            Some((l, c)) => (Some(l), Some(c)),
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
        let (key, line, column) = match offset.and_then(|o| key_at(text, o)) {
            Some(key) => (key, line, column),
            None => match offset.and_then(|o| find_key_by_value(text, o, &message)) {
                Some((key, l, c)) => (key, Some(l), Some(c)),
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
