//! Where in a RON scene file a field path points: `objects[3].shape.radius`
//! becomes the line and column of `radius:` inside the fourth object's shape,
//! so that an error found while building the scene (after serde has parsed it
//! and forgotten the positions) names the place in the file as well as the
//! field. The path is followed as far as the text allows; the position of the
//! deepest part found is returned (a default left out of the file points at
//! the item that would hold it).
//!
//! A small scanner over RON's surface syntax: brackets `( [ {`, strings
//! (with escapes, and raw strings `r#"…"#`), character literals, and `//` and
//! nested `/* */` comments. It never fails: text it does not understand ends
//! the walk.

/// One step of a field path.
#[derive(Debug, PartialEq)]
enum Step<'a> {
    /// `name` in `(name: value)`.
    Field(&'a str),
    /// `[i]` of a list.
    Index(usize),
    /// `."key"` of a map.
    Key(&'a str),
}

/// Splits `objects[3].shape.radius` or `materials."glass".ior` into steps
/// (`None` for a path it cannot read).
fn steps(path: &str) -> Option<Vec<Step<'_>>> {
    let mut out = Vec::new();
    let mut rest = path;
    while !rest.is_empty() {
        rest = rest.strip_prefix('.').unwrap_or(rest);
        if let Some(r) = rest.strip_prefix('"') {
            let end = r.find('"')?;
            out.push(Step::Key(&r[..end]));
            rest = &r[end + 1..];
        } else if let Some(r) = rest.strip_prefix('[') {
            let end = r.find(']')?;
            out.push(Step::Index(r[..end].parse().ok()?));
            rest = &r[end + 1..];
        } else {
            let end = rest.find(['.', '[']).unwrap_or(rest.len());
            if end == 0 {
                return None;
            }
            out.push(Step::Field(&rest[..end]));
            rest = &rest[end..];
        }
    }
    Some(out)
}

/// The byte offset of the place `field` names in `text` (see the module docs).
pub(super) fn offset_of(text: &str, field: &str) -> Option<usize> {
    let steps = steps(field)?;
    let b = text.as_bytes();
    let mut value = skip(b, 0);
    let mut found = None;
    for step in steps {
        let entries = entries(b, value)?;
        let hit = match step {
            Step::Field(name) => entries.iter().find(|e| e.key.is_some_and(|k| &text[k.0..k.1] == name)),
            Step::Key(name) => entries.iter().find(|e| e.key.is_some_and(|k| text[k.0..k.1].trim_matches('"') == name)),
            Step::Index(i) => entries.get(i),
        };
        let Some(e) = hit else { break };
        found = Some(e.start);
        value = e.value;
    }
    found
}

/// An entry of a bracketed value: where it starts, its key's span (a field
/// name or a quoted map key), and where its value starts.
#[derive(Clone, Copy, Debug)]
struct Entry {
    start: usize,
    key: Option<(usize, usize)>,
    value: usize,
}

/// The entries of the bracketed value at `at`. A value written `Name(...)`
/// (a variant, `Some(...)`) is looked into; `Some(x)` and one-field variants
/// holding a list or map are looked through to the list or map.
fn entries(b: &[u8], at: usize) -> Option<Vec<Entry>> {
    let mut at = at;
    // `Name(` or `Some(`: step inside the parenthesis.
    let id_start = at;
    let id_end = ident_end(b, at);
    if id_end > at {
        at = skip(b, id_end);
        if b.get(at) != Some(&b'(') {
            return None;
        }
        let inner = skip(b, at + 1);
        // `Some([..])` or `Some({..})`: the list or map itself.
        if matches!(b.get(inner), Some(b'[' | b'{')) && &b[id_start..id_end] == b"Some" {
            at = inner;
        }
    }
    let open = *b.get(at)?;
    let close = match open {
        b'(' => b')',
        b'[' => b']',
        b'{' => b'}',
        _ => return None,
    };
    let mut out = Vec::new();
    let mut i = skip(b, at + 1);
    while i < b.len() && b[i] != close {
        let start = i;
        // A key: an identifier or a string followed by `:` (not `::`).
        let key_end = if b[i] == b'"' { string_end(b, i) } else { ident_end(b, i) };
        let after = skip(b, key_end);
        let (key, value) = if key_end > i && b.get(after) == Some(&b':') && b.get(after + 1) != Some(&b':') {
            (Some((i, key_end)), skip(b, after + 1))
        } else {
            (None, i)
        };
        out.push(Entry { start, key, value });
        // Past the value to the next top-level comma or the closing bracket.
        i = value;
        let mut depth = 0usize;
        while i < b.len() {
            match b[i] {
                b'(' | b'[' | b'{' => depth += 1,
                b')' | b']' | b'}' if depth == 0 => break,
                b')' | b']' | b'}' => depth -= 1,
                b',' if depth == 0 => break,
                b'"' | b'\'' | b'r' | b'/' => {
                    let j = token_end(b, i);
                    if j > i + 1 || b[i] != b'r' {
                        i = j;
                        continue;
                    }
                }
                _ => {}
            }
            i += 1;
        }
        if b.get(i) == Some(&b',') {
            i += 1;
        }
        i = skip(b, i);
    }
    Some(out)
}

/// Past whitespace and comments from `i`.
fn skip(b: &[u8], mut i: usize) -> usize {
    loop {
        while i < b.len() && b[i].is_ascii_whitespace() {
            i += 1;
        }
        if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            i = block_comment_end(b, i);
        } else {
            return i;
        }
    }
}

/// The end of a `/* */` comment starting at `i` (nested, as RON allows).
fn block_comment_end(b: &[u8], mut i: usize) -> usize {
    let mut depth = 0;
    while i < b.len() {
        if b[i..].starts_with(b"/*") {
            depth += 1;
            i += 2;
        } else if b[i..].starts_with(b"*/") {
            depth -= 1;
            i += 2;
            if depth == 0 {
                return i;
            }
        } else {
            i += 1;
        }
    }
    b.len()
}

/// The end of the string, character, raw string or comment starting at `i`
/// (`i + 1` for anything else).
fn token_end(b: &[u8], i: usize) -> usize {
    match b[i] {
        b'"' => string_end(b, i),
        b'\'' => {
            // A character literal: 'x', '\n', '\''.
            let mut j = i + 1;
            if b.get(j) == Some(&b'\\') {
                j += 1;
            }
            j += 1;
            if b.get(j) == Some(&b'\'') { j + 1 } else { i + 1 }
        }
        b'r' if matches!(b.get(i + 1), Some(b'"' | b'#')) && (i == 0 || !is_ident(b[i - 1])) => {
            let hashes = b[i + 1..].iter().take_while(|&&c| c == b'#').count();
            let open = i + 1 + hashes;
            if b.get(open) != Some(&b'"') {
                return i + 1;
            }
            let mut close = vec![b'"'];
            close.extend(std::iter::repeat_n(b'#', hashes));
            b[open + 1..]
                .windows(close.len())
                .position(|w| w == close.as_slice())
                .map_or(b.len(), |p| open + 1 + p + close.len())
        }
        b'/' if b.get(i + 1) == Some(&b'/') => b[i..].iter().position(|&c| c == b'\n').map_or(b.len(), |p| i + p),
        b'/' if b.get(i + 1) == Some(&b'*') => block_comment_end(b, i),
        _ => i + 1,
    }
}

/// The end of the string starting at `i` (a `"`), past its closing quote.
fn string_end(b: &[u8], i: usize) -> usize {
    let mut j = i + 1;
    while j < b.len() {
        match b[j] {
            b'\\' => j += 2,
            b'"' => return j + 1,
            _ => j += 1,
        }
    }
    b.len()
}

fn is_ident(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_'
}

/// The end of the identifier starting at `i` (`i` when there is none).
fn ident_end(b: &[u8], i: usize) -> usize {
    if !b.get(i).is_some_and(|&c| c.is_ascii_alphabetic() || c == b'_') {
        return i;
    }
    let mut j = i;
    while j < b.len() && is_ident(b[j]) {
        j += 1;
    }
    j
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = r#"// A scene with comments /* and ( brackets ) in them
(
    camera: (eye: (0, 1, 4), look_at: (0, 0, 0)),
    materials: {
        "white": Lambertian(reflectance: Constant(0.5)), /* a "quoted" ( comment */
        "glass": Dielectric(ior: Named("N-BK7"), roughness: 0.1),
    },
    objects: [
        (shape: Sphere(center: (0, 0, 0), radius: 1), material: "white"),
        // "objects[1]" is next
        (shape: Triangles(positions: [(0, 0, 0), (1, 0, 0), (0, 1, 0)], indices: [(0, 1, 2)],
                          uvs: Some([(0, 0), (1, 0), (0, 1)])), material: "glass"),
    ],
)"#;

    /// Line and column (1-based) of `field`'s place. The expected values below
    /// were read off the text with a text editor's search (the `radius:` key,
    /// the third `(0, 1)` after `uvs:`, ...), not from this code.
    fn at(field: &str) -> Option<(usize, usize)> {
        let o = offset_of(SCENE, field)?;
        let before = &SCENE[..o];
        let line = before.matches('\n').count() + 1;
        let col = before.len() - before.rfind('\n').map_or(0, |p| p + 1) + 1;
        Some((line, col))
    }

    #[test]
    fn field_paths_point_into_the_text() {
        assert_eq!(at("camera"), Some((3, 5)));
        assert_eq!(at("camera.look_at"), Some((3, 30)));
        assert_eq!(at("materials.\"glass\""), Some((6, 9)));
        assert_eq!(at("materials.\"glass\".roughness"), Some((6, 50)));
        assert_eq!(at("objects[0]"), Some((9, 9)));
        assert_eq!(at("objects[0].shape.radius"), Some((9, 43)));
        assert_eq!(at("objects[1].material"), Some((12, 65)));
        assert_eq!(at("objects[1].shape.indices[0]"), Some((11, 83)));
        assert_eq!(at("objects[1].shape.uvs[2]"), Some((12, 54)));
        // A field left out (a default) points at the item that would hold it;
        // an index beyond the list at the list's key.
        assert_eq!(at("objects[0].priority"), Some((9, 9)));
        assert_eq!(at("objects[7].shape"), Some((8, 5)));
        assert_eq!(at("lights[0]"), None);
    }

    #[test]
    fn paths_split_into_steps() {
        assert_eq!(
            steps("materials.\"a.b\".ior[2].x"),
            Some(vec![
                Step::Field("materials"),
                Step::Key("a.b"),
                Step::Field("ior"),
                Step::Index(2),
                Step::Field("x")
            ])
        );
        assert_eq!(steps("objects[x]"), None);
    }

    #[test]
    fn hostile_text_never_panics() {
        for text in ["", "(", "(objects: [", "(objects: [(shape: \"", "/* unterminated", "r#\"", "(a: 'x', b: '\\'')"] {
            let _ = offset_of(text, "objects[0].shape");
            let _ = offset_of(text, "a");
        }
    }
}
