//! pbrt-v4's scene-file tokens: quoted strings, `[` `]`, and bare words (directive names,
//! numbers, `true`/`false`), with `#` comments to the end of the line. Every token keeps its
//! file and 1-based line and column for error messages.

use std::path::Path;

use crate::error::LoadError;

/// One token.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Tok {
    /// A quoted string, without its quotes (escapes resolved).
    Str(String),
    /// A bare word: a directive, a number, `true` or `false`.
    Word(String),
    /// `[`
    Open,
    /// `]`
    Close,
}

/// A token with where it is.
#[derive(Clone, Debug)]
pub(crate) struct Token {
    pub(crate) tok: Tok,
    /// Index of the file in the parser's file list.
    pub(crate) file: usize,
    pub(crate) line: u32,
    pub(crate) column: u32,
}

/// Splits `text` (the contents of file number `file`, at `path`) into tokens.
pub(crate) fn tokenize(text: &str, file: usize, path: &Path) -> Result<Vec<Token>, LoadError> {
    let mut out = Vec::new();
    let mut chars = text.chars().peekable();
    let (mut line, mut column) = (1u32, 1u32);
    let error = |line: u32, column: u32, message: &str| LoadError::Pbrt {
        path: path.to_path_buf(),
        line: Some(line),
        column: Some(column),
        message: message.to_owned(),
    };
    while let Some(&c) = chars.peek() {
        let (l0, c0) = (line, column);
        let mut advance = |chars: &mut std::iter::Peekable<std::str::Chars<'_>>| {
            let c = chars.next();
            if c == Some('\n') {
                line += 1;
                column = 1;
            } else {
                column += 1;
            }
            c
        };
        match c {
            c if c.is_whitespace() => {
                advance(&mut chars);
            }
            '#' => {
                while let Some(&c) = chars.peek() {
                    if c == '\n' {
                        break;
                    }
                    advance(&mut chars);
                }
            }
            '[' | ']' => {
                advance(&mut chars);
                out.push(Token {
                    tok: if c == '[' { Tok::Open } else { Tok::Close },
                    file,
                    line: l0,
                    column: c0,
                });
            }
            '"' => {
                advance(&mut chars);
                let mut s = String::new();
                loop {
                    match advance(&mut chars) {
                        None | Some('\n') => {
                            return Err(error(l0, c0, "syntax error: unterminated string"));
                        }
                        Some('"') => break,
                        Some('\\') => match advance(&mut chars) {
                            Some('n') => s.push('\n'),
                            Some('t') => s.push('\t'),
                            Some(other) => s.push(other),
                            None => return Err(error(l0, c0, "syntax error: unterminated string")),
                        },
                        Some(other) => s.push(other),
                    }
                }
                out.push(Token {
                    tok: Tok::Str(s),
                    file,
                    line: l0,
                    column: c0,
                });
            }
            _ => {
                let mut s = String::new();
                while let Some(&c) = chars.peek() {
                    if c.is_whitespace() || matches!(c, '"' | '[' | ']' | '#') {
                        break;
                    }
                    s.push(c);
                    advance(&mut chars);
                }
                out.push(Token {
                    tok: Tok::Word(s),
                    file,
                    line: l0,
                    column: c0,
                });
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_with_positions() {
        let t = tokenize(
            "Shape \"sphere\" # c\n  \"float radius\" [ 2 ]",
            0,
            Path::new("a.pbrt"),
        )
        .unwrap();
        let toks: Vec<&Tok> = t.iter().map(|t| &t.tok).collect();
        assert_eq!(
            toks,
            [
                &Tok::Word("Shape".into()),
                &Tok::Str("sphere".into()),
                &Tok::Str("float radius".into()),
                &Tok::Open,
                &Tok::Word("2".into()),
                &Tok::Close
            ]
        );
        assert_eq!((t[2].line, t[2].column), (2, 3));
    }

    #[test]
    fn unterminated_string_is_a_syntax_error() {
        let e = tokenize("Shape \"sphere\n", 0, Path::new("a.pbrt")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "a.pbrt: line 1, column 7: syntax error: unterminated string"
        );
    }
}
