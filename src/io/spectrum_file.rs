//! Spectrum files: two columns, wavelength in nm and value, one pair a line.
//!
//! A scene can take any spectrum from a file, `File("data/led.csv")`, relative to the scene
//! file. The format is the simplest CSV a spreadsheet or colour-science exports:
//!
//! ```text
//! wavelength_nm,value      <- an optional header (a first line that is not two numbers)
//! # comments and blank lines are skipped
//! 400, 0.12
//! 410, 0.15
//! ```
//!
//! Separators may be commas, semicolons, tabs or spaces. Wavelengths must increase strictly.
//! A bad row is reported with its line and column, so the loader can name file and line;
//! the row's text is quoted only up to [`EXCERPT_CHARS`] characters. Parsing takes time
//! linear in the file's length, however many fields a line has.

/// The most characters of a line or field an error quotes.
pub const EXCERPT_CHARS: usize = 60;

/// A row that cannot be read: 1-based line and column, and what was expected.
#[derive(Debug, PartialEq)]
pub struct SpectrumFileError {
    /// 1-based line number.
    pub line: usize,
    /// 1-based column (character) of the offending field.
    pub col: usize,
    /// What is wrong and what was expected.
    pub message: String,
}

/// One `nm,value` row of a spectrum file, with where it stands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpectrumRow {
    /// The wavelength in nm.
    pub nm: f32,
    /// The value.
    pub value: f32,
    /// 1-based line number.
    pub line: usize,
    /// 1-based column (character) of the value.
    pub value_col: usize,
}

/// `text` quoted (Rust string syntax, so control characters are escaped) for an error
/// message: whole when it has at most [`EXCERPT_CHARS`] characters, else its first
/// [`EXCERPT_CHARS`] followed by an ellipsis and the full length.
pub fn excerpt(text: &str) -> String {
    match text.char_indices().nth(EXCERPT_CHARS) {
        None => format!("{text:?}"),
        Some((end, _)) => format!("{:?}... ({} characters)", &text[..end], text.chars().count()),
    }
}

/// Parses a two-column spectrum file into `(nm, value)` pairs in file order.
pub fn parse_spectrum_file(text: &str) -> Result<Vec<(f32, f32)>, SpectrumFileError> {
    Ok(parse_spectrum_rows(text)?.into_iter().map(|r| (r.nm, r.value)).collect())
}

/// Parses a two-column spectrum file into its rows in file order, each with its line.
pub fn parse_spectrum_rows(text: &str) -> Result<Vec<SpectrumRow>, SpectrumFileError> {
    Ok(parse_table::<2>(text, "two numbers `nm,value`", "`nm,value`")?
        .into_iter()
        .map(|r| SpectrumRow { nm: r.values[0], value: r.values[1], line: r.line, value_col: r.cols[1] })
        .collect())
}

/// One row of a table of `K` numbers per line (wavelength first), with where it stands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TableRow<const K: usize> {
    /// The numbers, wavelength first.
    pub values: [f32; K],
    /// 1-based column (character) of each number.
    pub cols: [usize; K],
    /// 1-based line number.
    pub line: usize,
}

/// Parses a table of `K` finite numbers a line, wavelengths (the first column) strictly
/// increasing, in the format of a spectrum file (optional header, comments, any of the
/// separators). `expected` says what a row is in errors (`"two numbers `nm,value`"`), `row`
/// what an empty file lacks.
pub fn parse_table<const K: usize>(
    text: &str,
    expected: &str,
    row: &str,
) -> Result<Vec<TableRow<K>>, SpectrumFileError> {
    let mut out: Vec<TableRow<K>> = Vec::new();
    let mut seen_row = false;
    let mut fields: Vec<(&str, usize)> = Vec::new();
    for (n, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("");
        if line.trim().is_empty() {
            continue;
        }
        // Fields with their 1-based starting column, counted as the scan goes (one pass).
        fields.clear();
        let mut start = None;
        for (col, (i, ch)) in line.char_indices().chain(std::iter::once((line.len(), ','))).enumerate() {
            let sep = i == line.len() || matches!(ch, ',' | ';' | '\t' | ' ');
            match (sep, start) {
                (true, Some((s, c))) => {
                    fields.push((&line[s..i], c));
                    start = None;
                }
                (false, None) => start = Some((i, col + 1)),
                _ => {}
            }
        }
        let err = |col: usize, message: String| SpectrumFileError { line: n + 1, col, message };
        if !seen_row && fields.iter().all(|(f, _)| f.parse::<f32>().is_err()) {
            seen_row = true; // a header line
            continue;
        }
        seen_row = true;
        if fields.len() != K {
            return Err(err(1, format!("expected {expected}, found {} fields in {}", fields.len(), excerpt(raw))));
        }
        let mut values = [0.0f32; K];
        let mut cols = [0usize; K];
        for (k, (text, col)) in fields.iter().enumerate() {
            match text.parse::<f32>() {
                Ok(v) if v.is_finite() => (values[k], cols[k]) = (v, *col),
                _ => return Err(err(*col, format!("expected a finite number, found {}", excerpt(text)))),
            }
        }
        if let Some(prev) = out.last()
            && values[0] <= prev.values[0]
        {
            return Err(err(
                fields[0].1,
                format!("wavelengths must increase: {} nm follows {} nm", values[0], prev.values[0]),
            ));
        }
        out.push(TableRow { values, cols, line: n + 1 });
    }
    if out.is_empty() {
        return Err(SpectrumFileError { line: 1, col: 1, message: format!("expected at least one {row} row") });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_header_comments_and_separators() {
        let t = "wavelength_nm,value\n# a comment\n\n400, 0.5\n500;0.25 # trailing\n600\t1e-1\n700 2\n";
        assert_eq!(parse_spectrum_file(t).unwrap(), vec![(400.0, 0.5), (500.0, 0.25), (600.0, 0.1), (700.0, 2.0)]);
    }

    #[test]
    fn bad_rows_name_line_and_column() {
        let e = parse_spectrum_file("nm,v\n400,0.1\n410,abc\n").unwrap_err();
        assert_eq!((e.line, e.col), (3, 5));
        assert!(e.message.contains("\"abc\""), "{}", e.message);
        let e = parse_spectrum_file("400,0.1\n400,0.2\n").unwrap_err();
        assert_eq!((e.line, e.col), (2, 1));
        assert!(e.message.contains("increase"));
        let e = parse_spectrum_file("400,0.1,3\n").unwrap_err();
        assert_eq!(e.line, 1);
        assert!(parse_spectrum_file("# nothing\n").is_err());
        assert!(parse_spectrum_file("400,inf\n").is_err());
        // A second non-numeric line is an error, not another header.
        assert_eq!(parse_spectrum_file("a,b\nc,d\n").unwrap_err().line, 2);
    }

    /// A line of a million fields is refused (the parse is linear in its
    /// length: before, each field's column was counted from the line's start,
    /// 6.7 s for 400 000 fields; the time is printed, not asserted). The error
    /// quotes at most [`EXCERPT_CHARS`] characters of the line, and of a huge
    /// field.
    #[test]
    fn a_million_fields_are_refused_with_a_short_excerpt() {
        let wide = vec!["1"; 1_000_000].join(",");
        let text = format!("nm,v\n400,0.5\n{wide}\n");
        let t = std::time::Instant::now();
        let e = parse_spectrum_file(&text).unwrap_err();
        let took = t.elapsed();
        assert_eq!(e.line, 3);
        assert!(e.message.contains("1000000 fields") && e.message.contains("..."), "{}", e.message);
        assert!(e.message.len() < 60 + 100, "{} bytes", e.message.len());
        eprintln!("a million fields: {took:?} (not asserted: no wall-clock limits in tests)");
        // One huge field: quoted up to 60 characters.
        let e = parse_spectrum_file(&format!("400,{}\n", "x".repeat(200_000))).unwrap_err();
        assert_eq!((e.line, e.col), (1, 5));
        assert!(e.message.len() < 60 + 100, "{} bytes", e.message.len());
        // Columns still count characters, not bytes.
        let e = parse_spectrum_file("400,0.1\n410;\u{e9}\u{e9} x\n").unwrap_err();
        assert_eq!((e.line, e.col), (2, 1));
        let e = parse_spectrum_file("400,0.1\n\u{e9},5\n").unwrap_err();
        assert_eq!((e.line, e.col), (2, 1));
        let e = parse_spectrum_file("400,0.1\n 410,\u{e9}\u{e9}\n").unwrap_err();
        assert_eq!((e.line, e.col), (2, 6));
    }

    /// `excerpt` keeps short texts whole and cuts long ones at 60 characters
    /// (not bytes: multi-byte characters are never split).
    #[test]
    fn excerpts_are_short() {
        assert_eq!(excerpt("abc"), "\"abc\"");
        let long = "\u{e9}".repeat(100);
        let e = excerpt(&long);
        assert!(e.starts_with(&format!("\"{}\"...", "\u{e9}".repeat(60))) && e.ends_with("(100 characters)"), "{e}");
    }

    /// Rows keep their line and the value's column.
    #[test]
    fn rows_know_where_they_stand() {
        let rows = parse_spectrum_rows("nm,v\n\n400, 0.5\n# c\n500\t2\n").unwrap();
        assert_eq!(rows.iter().map(|r| (r.line, r.value_col)).collect::<Vec<_>>(), vec![(3, 6), (5, 5)]);
    }
}
