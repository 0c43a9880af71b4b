//! The XML layer of the Mitsuba importer: parses files with roxmltree, expands `<include>`s
//! in place, applies `<default>` parameters and `$name` substitution in document order (as
//! Mitsuba 3's `parser.cpp` does), collects `<path>` search folders, and upgrades the property
//! names of scenes older than version 2 (camelCase → snake_case, `lookAt` → `lookat`).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::error::LoadError;

/// Deepest `<include>` nesting accepted (cycles are caught before that).
const MAX_INCLUDE_DEPTH: usize = 64;

/// Elements Mitsuba 3 knows; anything else is an error, as in Mitsuba.
const KNOWN_TAGS: &[&str] = &[
    "scene",
    "shape",
    "bsdf",
    "texture",
    "emitter",
    "sensor",
    "film",
    "sampler",
    "rfilter",
    "integrator",
    "medium",
    "phase",
    "volume",
    "spectrum",
    "include",
    "default",
    "path",
    "ref",
    "alias",
    "float",
    "integer",
    "boolean",
    "string",
    "point",
    "vector",
    "rgb",
    "transform",
    "translate",
    "rotate",
    "scale",
    "lookat",
    "matrix",
    "tensor",
];

/// One element after expansion.
#[derive(Clone, Debug)]
pub(crate) struct Node {
    pub(crate) tag: String,
    pub(crate) attrs: Vec<(String, String)>,
    pub(crate) children: Vec<Node>,
    /// Index into [`Document::files`].
    pub(crate) file: usize,
    pub(crate) line: u32,
    pub(crate) column: u32,
}

impl Node {
    /// The value of attribute `name`.
    pub(crate) fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// `<tag type="..." id="...">`, for messages.
    pub(crate) fn label(&self) -> String {
        let mut s = format!("<{}", self.tag);
        for key in ["type", "name", "id"] {
            if let Some(v) = self.attr(key) {
                s.push_str(&format!(" {key}=\"{v}\""));
            }
        }
        s.push('>');
        s
    }
}

/// A whole scene with every include expanded.
#[derive(Debug)]
pub(crate) struct Document {
    /// The `<scene>` element.
    pub(crate) root: Node,
    /// Every file read: the scene first, then includes.
    pub(crate) files: Vec<PathBuf>,
    /// Folders from `<path>` elements, most recent first, then the scene's own folder.
    pub(crate) search: Vec<PathBuf>,
}

impl Document {
    /// An error located at `node`.
    pub(crate) fn error(&self, node: &Node, message: impl Into<String>) -> LoadError {
        LoadError::Xml {
            path: self.files[node.file].clone(),
            line: Some(node.line),
            column: Some(node.column),
            element: node.label(),
            message: message.into(),
        }
    }

    /// Resolves a file name as Mitsuba's file resolver does: absolute as is, else the first of
    /// the search folders where it exists, else relative to the file of `node`.
    pub(crate) fn resolve(&self, node: &Node, name: &str) -> PathBuf {
        let p = Path::new(name);
        if p.is_absolute() {
            return p.to_path_buf();
        }
        for dir in &self.search {
            let candidate = dir.join(p);
            if super::super::files::exists(&candidate) {
                return candidate;
            }
        }
        let own = self.files[node.file]
            .parent()
            .map(|d| d.join(p))
            .unwrap_or_else(|| p.to_path_buf());
        if super::super::files::exists(&own) {
            return own;
        }
        self.search.last().map(|d| d.join(p)).unwrap_or(own)
    }
}

/// Reads a Mitsuba scene file and everything it includes.
pub(crate) fn read_document(path: &Path) -> Result<Document, LoadError> {
    let mut reader = Reader {
        files: Vec::new(),
        search: Vec::new(),
        params: HashMap::new(),
        stack: Vec::new(),
        legacy: false,
    };
    let scene_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut nodes = reader.read_file(path, None)?;
    let root = match nodes.len() {
        1 if nodes[0].tag == "scene" => nodes.remove(0),
        _ => {
            return Err(LoadError::Xml {
                path: path.to_path_buf(),
                line: Some(1),
                column: Some(1),
                element: String::new(),
                message: "the root element must be <scene>".to_owned(),
            });
        }
    };
    let mut search = reader.search;
    search.push(scene_dir);
    Ok(Document {
        root,
        files: reader.files,
        search,
    })
}

struct Reader {
    files: Vec<PathBuf>,
    search: Vec<PathBuf>,
    /// `<default>` parameters, by name without the `$`.
    params: HashMap<String, String>,
    /// Canonical paths of the files being read, for cycle detection.
    stack: Vec<PathBuf>,
    /// The scene is older than version 2: property names are camelCase.
    legacy: bool,
}

impl Reader {
    /// Reads one file; returns its root element, or the root's children when it is an included
    /// `<scene>` (Mitsuba drops an included scene's root).
    fn read_file(
        &mut self,
        path: &Path,
        included_from: Option<(&Path, u32, u32)>,
    ) -> Result<Vec<Node>, LoadError> {
        let canonical = super::super::files::canonical(path);
        if let Some((from, line, column)) = included_from {
            if self.stack.contains(&canonical) {
                return Err(LoadError::Xml {
                    path: from.to_path_buf(),
                    line: Some(line),
                    column: Some(column),
                    element: "<include>".to_owned(),
                    message: format!("include cycle: {} includes itself", path.display()),
                });
            }
            if self.stack.len() >= MAX_INCLUDE_DEPTH {
                return Err(LoadError::Xml {
                    path: from.to_path_buf(),
                    line: Some(line),
                    column: Some(column),
                    element: "<include>".to_owned(),
                    message: format!("includes nested deeper than {MAX_INCLUDE_DEPTH}"),
                });
            }
        }
        let text = super::super::read_text(path)?;
        let doc = roxmltree::Document::parse(&text).map_err(|e| {
            let pos = e.pos();
            LoadError::Xml {
                path: path.to_path_buf(),
                line: Some(pos.row),
                column: Some(pos.col),
                element: String::new(),
                message: format!(
                    "malformed xml: {}",
                    crate::error::lower_first(&strip_position(&e.to_string()))
                ),
            }
        })?;
        let file = self.files.len();
        self.files.push(path.to_path_buf());
        self.stack.push(canonical);
        let root = doc.root_element();
        if root.tag_name().name() == "scene"
            && let Some(version) = root.attribute("version")
        {
            let major: u32 = version
                .split('.')
                .next()
                .and_then(|m| m.trim().parse().ok())
                .unwrap_or(3);
            if included_from.is_none() {
                self.legacy = major < 2;
            }
        }
        let mut out = Vec::new();
        self.convert(&doc, root, file, path, &mut out)?;
        self.stack.pop();
        if included_from.is_some() && out.len() == 1 && out[0].tag == "scene" {
            return Ok(std::mem::take(&mut out[0].children));
        }
        Ok(out)
    }

    /// Converts `node` (and its subtree) into `out`, expanding includes and defaults.
    fn convert(
        &mut self,
        doc: &roxmltree::Document<'_>,
        node: roxmltree::Node<'_, '_>,
        file: usize,
        path: &Path,
        out: &mut Vec<Node>,
    ) -> Result<(), LoadError> {
        let pos = doc.text_pos_at(node.range().start);
        let mut tag = node.tag_name().name().to_owned();
        if self.legacy && tag == "lookAt" {
            tag = "lookat".to_owned();
        }
        let mut element = Node {
            tag: tag.clone(),
            attrs: Vec::new(),
            children: Vec::new(),
            file,
            line: pos.row,
            column: pos.col,
        };
        for a in node.attributes() {
            let value = self.substitute(a.value()).map_err(|name| LoadError::Xml {
                path: path.to_path_buf(),
                line: Some(pos.row),
                column: Some(pos.col),
                element: format!("<{tag}>"),
                message: format!(
                    "undefined parameter ${name} (no <default name=\"{name}\" value=\"...\"/> before it)"
                ),
            })?;
            let value = if self.legacy && a.name() == "name" {
                camel_to_snake(&value)
            } else {
                value
            };
            element.attrs.push((a.name().to_owned(), value));
        }
        if !KNOWN_TAGS.contains(&tag.as_str()) {
            return Err(LoadError::Xml {
                path: path.to_path_buf(),
                line: Some(pos.row),
                column: Some(pos.col),
                element: String::new(),
                message: format!("unknown element <{tag}>"),
            });
        }
        let located = |message: String| LoadError::Xml {
            path: path.to_path_buf(),
            line: Some(pos.row),
            column: Some(pos.col),
            element: element.label(),
            message,
        };
        match tag.as_str() {
            "default" => {
                let (Some(name), Some(value)) = (element.attr("name"), element.attr("value"))
                else {
                    return Err(located("needs both name and value".to_owned()));
                };
                self.params
                    .entry(name.to_owned())
                    .or_insert_with(|| value.to_owned());
                return Ok(());
            }
            "path" => {
                let Some(value) = element.attr("value") else {
                    return Err(located("needs a value".to_owned()));
                };
                let dir = path.parent().unwrap_or(Path::new("")).join(value);
                self.search.insert(0, dir);
                return Ok(());
            }
            "include" => {
                let Some(name) = element.attr("filename") else {
                    return Err(located("needs a filename".to_owned()));
                };
                let own = path.parent().unwrap_or(Path::new("")).join(name);
                let target = if super::super::files::exists(&own) {
                    own
                } else {
                    self.search
                        .iter()
                        .map(|d| d.join(name))
                        .find(|p| super::super::files::exists(p))
                        .unwrap_or(own)
                };
                if !super::super::files::exists(&target) {
                    return Err(located(format!(
                        "included file {} not found",
                        target.display()
                    )));
                }
                let nodes = self.read_file(&target, Some((path, pos.row, pos.col)))?;
                out.extend(nodes);
                return Ok(());
            }
            _ => {}
        }
        for child in node.children().filter(roxmltree::Node::is_element) {
            self.convert(doc, child, file, path, &mut element.children)?;
        }
        out.push(element);
        Ok(())
    }

    /// Replaces every `$name` by its parameter; `Err(name)` for an undefined one.
    fn substitute(&self, value: &str) -> Result<String, String> {
        if !value.contains('$') {
            return Ok(value.to_owned());
        }
        let mut out = String::with_capacity(value.len());
        let mut chars = value.char_indices().peekable();
        let bytes = value.as_bytes();
        while let Some((i, c)) = chars.next() {
            if c != '$' || (i > 0 && bytes[i - 1] == b'\\') {
                out.push(c);
                continue;
            }
            let start = i + 1;
            let mut end = start;
            while end < value.len() && (bytes[end].is_ascii_alphanumeric() || bytes[end] == b'_') {
                end += 1;
            }
            // Longest defined parameter that the name starts with (Mitsuba replaces longest
            // keys first).
            let name = &value[start..end];
            let found = (1..=name.len())
                .rev()
                .find_map(|n| self.params.get(&name[..n]).map(|v| (n, v)));
            match found {
                Some((n, v)) => {
                    out.push_str(v);
                    for _ in 0..n {
                        chars.next();
                    }
                }
                None => return Err(name.to_owned()),
            }
        }
        Ok(out)
    }
}

/// Mitsuba's `camel_to_underscore_case`: `maxDepth` → `max_depth`, `intIOR` → `int_ior`.
fn camel_to_snake(input: &str) -> String {
    let chars: Vec<char> = input.chars().collect();
    let mut out = String::with_capacity(input.len() + 4);
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if i > 0 && chars[i - 1].is_ascii_lowercase() && c.is_ascii_uppercase() {
            out.push('_');
            out.push(c.to_ascii_lowercase());
            while i + 1 < chars.len() && chars[i + 1].is_ascii_uppercase() {
                i += 1;
                out.push(chars[i].to_ascii_lowercase());
            }
        } else {
            out.push(c);
        }
        i += 1;
    }
    out
}

/// roxmltree messages end in " at 3:5"; the position is reported separately.
fn strip_position(message: &str) -> String {
    match message.rfind(" at ") {
        Some(i)
            if message[i + 4..]
                .chars()
                .all(|c| c.is_ascii_digit() || c == ':') =>
        {
            message[..i].to_owned()
        }
        _ => message.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::camel_to_snake;

    #[test]
    fn camel_case_names_are_upgraded_as_mitsuba_does() {
        assert_eq!(camel_to_snake("maxDepth"), "max_depth");
        assert_eq!(camel_to_snake("intIOR"), "int_ior");
        assert_eq!(camel_to_snake("toWorld"), "to_world");
        assert_eq!(camel_to_snake("fov"), "fov");
    }
}
