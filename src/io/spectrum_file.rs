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
//! A bad row is reported with its line and column, so the loader can name file and line.

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

/// Parses a two-column spectrum file into `(nm, value)` pairs in file order.
pub fn parse_spectrum_file(text: &str) -> Result<Vec<(f32, f32)>, SpectrumFileError> {
    let mut out: Vec<(f32, f32)> = Vec::new();
    let mut seen_row = false;
    for (n, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("");
        if line.trim().is_empty() {
            continue;
        }
        // Fields with their 1-based starting column.
        let mut fields = Vec::new();
        let mut start = None;
        for (i, ch) in line.char_indices().chain(std::iter::once((line.len(), ','))) {
            let sep = matches!(ch, ',' | ';' | '\t' | ' ') || i == line.len();
            match (sep, start) {
                (true, Some(s)) => {
                    fields.push((&line[s..i], line[..s].chars().count() + 1));
                    start = None;
                }
                (false, None) => start = Some(i),
                _ => {}
            }
        }
        let nums: Vec<Option<f32>> = fields.iter().map(|(f, _)| f.parse::<f32>().ok()).collect();
        let err = |col: usize, message: String| SpectrumFileError { line: n + 1, col, message };
        if !seen_row && nums.iter().all(Option::is_none) {
            seen_row = true; // a header line
            continue;
        }
        seen_row = true;
        if fields.len() != 2 {
            return Err(err(1, format!("expected two numbers `nm,value`, found {} fields in {:?}", fields.len(), raw)));
        }
        let mut pair = [0.0f32; 2];
        for (k, ((text, col), num)) in fields.iter().zip(&nums).enumerate() {
            match num {
                Some(v) if v.is_finite() => pair[k] = *v,
                _ => return Err(err(*col, format!("expected a finite number, found {text:?}"))),
            }
        }
        if let Some(&(prev, _)) = out.last()
            && pair[0] <= prev
        {
            return Err(err(fields[0].1, format!("wavelengths must increase: {} nm follows {prev} nm", pair[0])));
        }
        out.push((pair[0], pair[1]));
    }
    if out.is_empty() {
        return Err(SpectrumFileError { line: 1, col: 1, message: "expected at least one `nm,value` row".into() });
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
}
