//! Directives, parameter lists, the graphics state and transforms of a pbrt-v4
//! scene file, with `Include` and `Import` (both read the named file in place;
//! relative paths resolve against the main scene file's folder, as pbrt-v4
//! does). What each entity becomes in the scene description is [`super::map`]'s
//! work; this file keeps the state it needs: the current transformation matrix
//! (pbrt post-multiplies every transform directive), `ReverseOrientation`, the
//! current material and area light, attribute and object blocks.

use std::cell::Cell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{DMat4, DVec3};

use super::lexer::{Lexer, Tok, Token};
use super::map::{AreaLight, Built, MatRef, ShapeRec};
use crate::error::{Error, Result};
use crate::io::{fnv1a, read_input};
use crate::scene::check::Check;

mod directives;

/// How deep `Include`/`Import` may nest (a cycle is reported before this).
pub(crate) const MAX_INCLUDE_DEPTH: usize = 32;

/// Where something is: a file (index into [`Parser::files`]), line and column.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Loc {
    pub(crate) file: usize,
    pub(crate) line: usize,
    pub(crate) col: usize,
}

/// A parameter's values.
#[derive(Clone, Debug)]
pub(crate) enum Value {
    Nums(Vec<f64>),
    Strs(Vec<String>),
    Bools(Vec<bool>),
}

/// One `"type name" value` of a parameter list.
#[derive(Clone, Debug)]
pub(crate) struct Param {
    pub(crate) ty: String,
    pub(crate) name: String,
    pub(crate) value: Value,
    pub(crate) loc: Loc,
    pub(crate) used: Cell<bool>,
}

/// A directive's parameter list.
#[derive(Clone, Debug, Default)]
pub(crate) struct Params(pub(crate) Vec<Param>, pub(crate) std::cell::RefCell<Vec<String>>);

const NUMERIC_TYPES: [&str; 13] = [
    "integer",
    "float",
    "point2",
    "vector2",
    "point3",
    "vector3",
    "normal3",
    "normal",
    "point",
    "vector",
    "rgb",
    "color",
    "blackbody",
];
const ALL_TYPES: &str = "integer, float, point2, vector2, point3, vector3, normal3, point, vector, normal, rgb, \
                         blackbody, spectrum, bool, string, texture";

/// The graphics state that `AttributeBegin`/`AttributeEnd` save and restore.
#[derive(Clone, Debug)]
pub(crate) struct State {
    pub(crate) ctm: DMat4,
    pub(crate) reverse: bool,
    pub(crate) material: MatRef,
    pub(crate) area: Option<AreaLight>,
    /// `MediumInterface`: the medium inside shapes and the one outside (and
    /// around the camera), by name; empty for vacuum.
    pub(crate) inside: String,
    pub(crate) outside: String,
}

/// Collected warnings: each distinct message once, with its first place and how
/// many more times it came up.
#[derive(Default)]
pub(crate) struct Warnings {
    pub(crate) list: Vec<(String, Loc, usize)>,
    index: HashMap<String, usize>,
}

/// One open file of the include stack.
struct Open {
    lexer: Lexer,
    file: usize,
}

/// The parser: the include stack, the graphics state and what has been built.
pub(crate) struct Parser<'c> {
    pub(crate) ctx: &'c Check<'c>,
    pub(crate) strict: bool,
    pub(crate) files: Vec<PathBuf>,
    stack: Vec<Open>,
    peeked: Option<(Token, usize)>,
    pub(crate) warnings: Warnings,
    pub(crate) state: State,
    saved: Vec<(State, bool, Loc)>,
    named_cs: HashMap<String, DMat4>,
    pub(crate) world: bool,
    /// The object being defined (`ObjectBegin`): its name and its shapes.
    object: Option<(String, Vec<ShapeRec>, Loc)>,
    objects: HashMap<String, Vec<ShapeRec>>,
    pub(crate) built: Built,
}

impl<'c> Parser<'c> {
    /// A parser of the main file `path` with its text.
    pub(crate) fn new(ctx: &'c Check<'c>, path: &Path, text: String, strict: bool) -> Parser<'c> {
        Parser {
            ctx,
            strict,
            files: vec![path.to_path_buf()],
            stack: vec![Open { lexer: Lexer::new(text), file: 0 }],
            peeked: None,
            warnings: Warnings::default(),
            state: State {
                ctm: DMat4::IDENTITY,
                reverse: false,
                material: MatRef::Default,
                area: None,
                inside: String::new(),
                outside: String::new(),
            },
            saved: Vec::new(),
            named_cs: HashMap::new(),
            world: false,
            object: None,
            objects: HashMap::new(),
            built: Built::default(),
        }
    }

    /// An error at `loc`.
    pub(crate) fn err(&self, loc: Loc, message: impl Into<String>) -> Error {
        Error::Scene {
            path: self.files[loc.file].clone(),
            position: Some((loc.line, loc.col)),
            field: String::new(),
            message: message.into(),
        }
    }

    /// A warning at `loc` (an error with `--strict`). The same message again
    /// counts as a further use of the first.
    pub(crate) fn warn(&mut self, loc: Loc, message: impl Into<String>) -> Result<()> {
        let message = message.into();
        if self.strict {
            return Err(self.err(loc, format!("{message} (--strict)")));
        }
        match self.warnings.index.get(&message) {
            Some(&i) => self.warnings.list[i].2 += 1,
            None => {
                self.warnings.index.insert(message.clone(), self.warnings.list.len());
                self.warnings.list.push((message, loc, 0));
            }
        }
        Ok(())
    }

    /// A note: a warning line about something understood but not carried over
    /// (an output file name, an option), never an error, even with `--strict`.
    pub(crate) fn note(&mut self, loc: Loc, message: impl Into<String>) {
        let strict = std::mem::replace(&mut self.strict, false);
        let _ = self.warn(loc, message);
        self.strict = strict;
    }

    /// The warnings as lines: `FILE:LINE:COL: message (and N more)`.
    pub(crate) fn warning_lines(&self) -> Vec<String> {
        self.warnings
            .list
            .iter()
            .map(|(m, loc, more)| {
                let place = format!("{}:{}:{}", crate::error::show_path(&self.files[loc.file]), loc.line, loc.col);
                if *more > 0 { format!("{place}: {m} (and {more} more)") } else { format!("{place}: {m}") }
            })
            .collect()
    }

    fn lex(&mut self) -> Result<Option<(Token, usize)>> {
        loop {
            let Some(top) = self.stack.last_mut() else { return Ok(None) };
            let file = top.file;
            match top.lexer.next_token() {
                Ok(Some(t)) => return Ok(Some((t, file))),
                Ok(None) => {
                    self.stack.pop();
                }
                Err(e) => return Err(self.err(Loc { file, line: e.line, col: e.col }, e.message)),
            }
        }
    }

    fn next(&mut self) -> Result<Option<(Token, usize)>> {
        match self.peeked.take() {
            Some(t) => Ok(Some(t)),
            None => self.lex(),
        }
    }

    fn peek(&mut self) -> Result<Option<&Tok>> {
        if self.peeked.is_none() {
            self.peeked = self.lex()?;
        }
        Ok(self.peeked.as_ref().map(|(t, _)| &t.tok))
    }

    fn loc(t: &Token, file: usize) -> Loc {
        Loc { file, line: t.line, col: t.col }
    }

    /// The next token, which must exist (`what` is what was expected).
    fn need(&mut self, after: Loc, what: &str) -> Result<(Token, Loc)> {
        match self.next()? {
            Some((t, f)) => {
                let l = Self::loc(&t, f);
                Ok((t, l))
            }
            None => Err(self.err(after, format!("the file ends here: expected {what}"))),
        }
    }

    fn string_arg(&mut self, after: Loc, what: &str) -> Result<(String, Loc)> {
        let (t, loc) = self.need(after, what)?;
        match t.tok {
            Tok::Str(s) => Ok((s, loc)),
            other => Err(self.err(loc, format!("expected {what}, found {}", other.describe()))),
        }
    }

    /// `n` numbers, optionally in brackets.
    fn numbers(&mut self, after: Loc, n: usize, what: &str) -> Result<Vec<f64>> {
        let bracketed = matches!(self.peek()?, Some(Tok::Open));
        if bracketed {
            self.next()?;
        }
        let mut out = Vec::with_capacity(n);
        let mut last = after;
        for _ in 0..n {
            let (t, loc) = self.need(last, &format!("{n} numbers for {what}"))?;
            last = loc;
            match t.tok {
                Tok::Num(v) => out.push(v),
                other => {
                    return Err(self.err(
                        loc,
                        format!("expected {n} numbers for {what}, found {} after {}", other.describe(), out.len()),
                    ));
                }
            }
        }
        if bracketed {
            let (t, loc) = self.need(last, "`]`")?;
            if t.tok != Tok::Close {
                return Err(
                    self.err(loc, format!("expected `]` after {n} numbers for {what}, found {}", t.tok.describe()))
                );
            }
        }
        Ok(out)
    }

    /// A parameter list: `"type name" value` pairs while the next token is a string.
    fn params(&mut self) -> Result<Params> {
        let mut out = Params::default();
        while let Some(Tok::Str(_)) = self.peek()? {
            let Some((t, f)) = self.next()? else { break };
            let loc = Self::loc(&t, f);
            let Tok::Str(decl) = t.tok else { unreachable!() };
            let words: Vec<&str> = decl.split_whitespace().collect();
            let [ty, name] = words[..] else {
                return Err(self.err(
                    loc,
                    format!("expected a parameter as \"TYPE NAME\" (such as \"float radius\"), found \"{decl}\""),
                ));
            };
            let ty = match ty {
                "point" => "point3",
                "vector" => "vector3",
                "normal" => "normal3",
                "color" => "rgb",
                t => t,
            }
            .to_string();
            if !NUMERIC_TYPES.contains(&ty.as_str())
                && !["spectrum", "bool", "string", "texture"].contains(&ty.as_str())
            {
                return Err(self
                    .err(loc, format!("unknown parameter type \"{ty}\" in \"{decl}\": expected one of {ALL_TYPES}")));
            }
            let value = self.param_value(loc, &ty, name)?;
            let len = match &value {
                Value::Nums(v) => v.len(),
                Value::Strs(v) => v.len(),
                Value::Bools(v) => v.len(),
            };
            let multiple = match ty.as_str() {
                "point2" | "vector2" => 2,
                "point3" | "vector3" | "normal3" | "rgb" => 3,
                "spectrum" if matches!(value, Value::Nums(_)) => 2,
                _ => 1,
            };
            if len == 0 || len % multiple != 0 || (ty == "rgb" && len != 3) {
                let expected = match (ty.as_str(), multiple) {
                    ("rgb", _) => "exactly 3 values (r g b)".to_string(),
                    ("spectrum", _) => "(wavelength, value) pairs: an even, non-zero count".to_string(),
                    (_, 1) => "at least one value".to_string(),
                    (_, m) => format!("a non-zero multiple of {m} values"),
                };
                return Err(self.err(loc, format!("\"{decl}\" has {len} values: expected {expected}")));
            }
            if let Some(prev) = out.0.iter().find(|p| p.name == name) {
                let at = prev.loc;
                return Err(self.err(loc, format!("parameter \"{name}\" given twice (first at line {})", at.line)));
            }
            out.0.push(Param { ty, name: name.to_string(), value, loc, used: Cell::new(false) });
        }
        Ok(out)
    }

    fn param_value(&mut self, decl_loc: Loc, ty: &str, name: &str) -> Result<Value> {
        let (first, loc) = self.need(decl_loc, &format!("a value for \"{ty} {name}\""))?;
        let mut items = Vec::new();
        if first.tok == Tok::Open {
            let mut last = loc;
            loop {
                let (t, l) = self.need(last, "`]`")?;
                last = l;
                if t.tok == Tok::Close {
                    break;
                }
                if t.tok == Tok::Open {
                    return Err(self.err(l, "expected a value or `]`, found `[` (lists do not nest)"));
                }
                items.push((t.tok, l));
            }
        } else {
            items.push((first.tok, loc));
        }
        let numeric = NUMERIC_TYPES.contains(&ty);
        let kind_err = |p: &Self, found: &Tok, l: Loc, want: &str| {
            p.err(l, format!("\"{ty} {name}\" expects {want}, found {}", found.describe()))
        };
        if ty == "bool" {
            let mut out = Vec::new();
            for (t, l) in &items {
                match t {
                    Tok::Word(w) | Tok::Str(w) if w == "true" || w == "false" => out.push(w == "true"),
                    t => return Err(kind_err(self, t, *l, "true or false")),
                }
            }
            return Ok(Value::Bools(out));
        }
        let strings = matches!(items.first(), Some((Tok::Str(_), _)));
        if numeric || (ty == "spectrum" && !strings) {
            let mut out = Vec::with_capacity(items.len());
            for (t, l) in &items {
                match t {
                    Tok::Num(v) => out.push(*v),
                    t => return Err(kind_err(self, t, *l, "numbers")),
                }
            }
            return Ok(Value::Nums(out));
        }
        let mut out = Vec::new();
        for (t, l) in items {
            match t {
                Tok::Str(s) => out.push(s),
                t => return Err(kind_err(self, &t, l, "strings")),
            }
        }
        if ty == "spectrum" && out.len() != 1 {
            return Err(
                self.err(loc, format!("\"spectrum {name}\" expects one name or file name, found {}", out.len()))
            );
        }
        Ok(Value::Strs(out))
    }
}
