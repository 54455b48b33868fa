//! The tokens of a pbrt-v4 scene file: quoted strings (with `\n`, `\t`, `\\`,
//! `\"` escapes; a string ends on its line), numbers, bare words (directive
//! names, `true`, `false`), `[` and `]`; `#` starts a comment to the end of
//! the line. Every token carries its 1-based line and column (in characters).

/// What a token is.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Tok {
    /// A quoted string, escapes resolved.
    Str(String),
    /// A number.
    Num(f64),
    /// A bare word: a directive name, `true` or `false`.
    Word(String),
    /// `[`.
    Open,
    /// `]`.
    Close,
}

impl Tok {
    /// How the token reads in an error message.
    pub(crate) fn describe(&self) -> String {
        match self {
            Tok::Str(s) => format!("the string \"{}\"", shorten(s)),
            Tok::Num(v) => format!("the number {v}"),
            Tok::Word(w) => format!("`{}`", shorten(w)),
            Tok::Open => "`[`".into(),
            Tok::Close => "`]`".into(),
        }
    }
}

/// At most 40 characters of `s` (a hostile file's 2 GB token stays out of messages).
fn shorten(s: &str) -> String {
    if s.chars().count() <= 40 { s.to_string() } else { format!("{}...", s.chars().take(40).collect::<String>()) }
}

/// A token and where it starts.
#[derive(Clone, Debug)]
pub(crate) struct Token {
    pub(crate) tok: Tok,
    pub(crate) line: usize,
    pub(crate) col: usize,
}

/// A lexing error: where, and what was expected.
#[derive(Debug)]
pub(crate) struct LexError {
    pub(crate) line: usize,
    pub(crate) col: usize,
    pub(crate) message: String,
}

/// Tokens of one file's text.
pub(crate) struct Lexer {
    text: String,
    pos: usize,
    line: usize,
    col: usize,
}

impl Lexer {
    /// A lexer over `text` (a leading byte-order mark is skipped).
    pub(crate) fn new(text: String) -> Lexer {
        let pos = if text.starts_with('\u{feff}') { '\u{feff}'.len_utf8() } else { 0 };
        Lexer { text, pos, line: 1, col: 1 }
    }

    fn peek_char(&self) -> Option<char> {
        self.text[self.pos..].chars().next()
    }

    fn bump(&mut self) -> Option<char> {
        let c = self.peek_char()?;
        self.pos += c.len_utf8();
        if c == '\n' {
            self.line += 1;
            self.col = 1;
        } else {
            self.col += 1;
        }
        Some(c)
    }

    /// The next token, `None` at the end of the text.
    pub(crate) fn next_token(&mut self) -> Result<Option<Token>, LexError> {
        loop {
            match self.peek_char() {
                None => return Ok(None),
                Some(c) if c.is_whitespace() => {
                    self.bump();
                }
                Some('#') => {
                    while let Some(c) = self.bump() {
                        if c == '\n' {
                            break;
                        }
                    }
                }
                Some(_) => break,
            }
        }
        let (line, col) = (self.line, self.col);
        let at = |tok| Ok(Some(Token { tok, line, col }));
        let c = self.peek_char().unwrap_or(' ');
        match c {
            '[' => {
                self.bump();
                at(Tok::Open)
            }
            ']' => {
                self.bump();
                at(Tok::Close)
            }
            '"' => {
                self.bump();
                let mut s = String::new();
                loop {
                    match self.bump() {
                        None | Some('\n') => {
                            return Err(LexError {
                                line,
                                col,
                                message: "unterminated string: expected a closing `\"` on the same line".into(),
                            });
                        }
                        Some('"') => break,
                        Some('\\') => match self.bump() {
                            Some('n') => s.push('\n'),
                            Some('t') => s.push('\t'),
                            Some('\\') => s.push('\\'),
                            Some('"') => s.push('"'),
                            Some('\n') | None => {
                                return Err(LexError {
                                    line,
                                    col,
                                    message: "unterminated string: expected a closing `\"` on the same line".into(),
                                });
                            }
                            Some(other) => {
                                return Err(LexError {
                                    line: self.line,
                                    col: self.col - 2,
                                    message: format!(
                                        "unknown escape `\\{other}` in a string: expected \\n, \\t, \\\\ or \\\""
                                    ),
                                });
                            }
                        },
                        Some(ch) => s.push(ch),
                    }
                }
                at(Tok::Str(s))
            }
            c if c.is_ascii_digit() || c == '-' || c == '+' || c == '.' => {
                let start = self.pos;
                while let Some(ch) = self.peek_char() {
                    if ch.is_ascii_alphanumeric() || matches!(ch, '.' | '-' | '+') {
                        self.bump();
                    } else {
                        break;
                    }
                }
                let text = &self.text[start..self.pos];
                match text.parse::<f64>() {
                    Ok(v) if v.is_finite() => at(Tok::Num(v)),
                    _ => Err(LexError {
                        line,
                        col,
                        message: format!("expected a finite number, found `{}`", shorten(text)),
                    }),
                }
            }
            c if c.is_alphabetic() || c == '_' => {
                let start = self.pos;
                while let Some(ch) = self.peek_char() {
                    if ch.is_alphanumeric() || ch == '_' {
                        self.bump();
                    } else {
                        break;
                    }
                }
                at(Tok::Word(self.text[start..self.pos].to_string()))
            }
            other => Err(LexError {
                line,
                col,
                message: format!(
                    "unexpected character `{other}`: expected a directive, a string, a number, `[` or `]`"
                ),
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all(text: &str) -> Result<Vec<(Tok, usize, usize)>, LexError> {
        let mut l = Lexer::new(text.into());
        let mut out = Vec::new();
        while let Some(t) = l.next_token()? {
            out.push((t.tok, t.line, t.col));
        }
        Ok(out)
    }

    #[test]
    fn tokens_comments_and_positions() {
        let toks = all("Shape \"sphere\" # a comment [ 1 ]\n  \"float radius\" [ -2.5e1 ] true").unwrap();
        assert_eq!(
            toks,
            vec![
                (Tok::Word("Shape".into()), 1, 1),
                (Tok::Str("sphere".into()), 1, 7),
                (Tok::Str("float radius".into()), 2, 3),
                (Tok::Open, 2, 18),
                (Tok::Num(-25.0), 2, 20),
                (Tok::Close, 2, 27),
                (Tok::Word("true".into()), 2, 29),
            ]
        );
        assert_eq!(all("\"a\\\"b\\n\"").unwrap()[0].0, Tok::Str("a\"b\n".into()));
        assert_eq!(
            all(".5 +3 1e-2").unwrap().iter().map(|t| t.0.clone()).collect::<Vec<_>>(),
            vec![Tok::Num(0.5), Tok::Num(3.0), Tok::Num(0.01)]
        );
    }

    #[test]
    fn bad_tokens_say_where_and_what() {
        let e = all("Shape \"sphere\n").unwrap_err();
        assert_eq!((e.line, e.col), (1, 7));
        assert!(e.message.contains("unterminated string"), "{}", e.message);
        let e = all("\n  1.2.3").unwrap_err();
        assert_eq!((e.line, e.col), (2, 3));
        assert!(e.message.contains("expected a finite number"), "{}", e.message);
        let e = all("Shape @").unwrap_err();
        assert_eq!((e.line, e.col), (1, 7));
        assert!(all("1e999").unwrap_err().message.contains("finite"));
    }
}
