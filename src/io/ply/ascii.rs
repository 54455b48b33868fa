//! The fast path of an ASCII PLY chunk: its bytes scanned once, numbers read
//! digit by digit, face indices as integers, polygons fan-triangulated as
//! they are read. It gives [`Ascii::chunk_by_lines`]'s data bit for bit, or
//! `None` for anything it does not handle (a token that is no plain number,
//! too few or too many values on a line, a list count or vertex index that is
//! not a plain non-negative integer, an index out of range, fewer than 3
//! indices, bytes other than digits, signs, points and ASCII blanks): the
//! chunk is then parsed line by line, which reports the error exactly as
//! before.
//!
//! Numbers: a token `[+-]?digits[.digits]` (`digits.` and `.digits` too) with
//! at most 19 digits is an integer `m` over `10^f`. When
//! `m < 2^53` and `f <= 22` both are exact doubles and one IEEE division
//! rounds their quotient correctly (Clinger's fast path), so the value is
//! `str::parse::<f64>`'s (correctly rounded too) bit for bit. Any other token
//! (an exponent, more digits, `nan`, `inf`) goes to `str::parse::<f64>`.

use super::{Ascii, Chunk, Kind, PlyData, push_vertex};

/// 10^0 to 10^22, every one an exact double.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20,
    1e21, 1e22,
];

/// The bytes besides `\n` that `split_ascii_whitespace` splits at (and that
/// `trim` removes): a line of only these is blank.
#[inline]
fn is_blank(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | 0x0c)
}

/// Whether a token ends before `b` (`None`: the text's end).
#[inline]
fn ends_token(b: Option<&u8>) -> bool {
    b.is_none_or(|&b| b == b'\n' || is_blank(b))
}

/// A position in a chunk's bytes.
struct Bytes<'a> {
    b: &'a [u8],
    pos: usize,
}

impl Bytes<'_> {
    /// Skips blanks (not line ends); the byte there, `None` at the end.
    #[inline]
    fn skip_blanks(&mut self) -> Option<u8> {
        while let Some(&b) = self.b.get(self.pos) {
            if !is_blank(b) {
                return Some(b);
            }
            self.pos += 1;
        }
        None
    }

    /// The next token on this line as a number: `str::parse::<f64>`'s value;
    /// `None` at the line's end or for a token that is not a number.
    #[inline]
    fn number(&mut self) -> Option<f64> {
        match self.skip_blanks() {
            None | Some(b'\n') => return None,
            Some(_) => {}
        }
        let start = self.pos;
        if let Some((v, end)) = plain_number(self.b, start) {
            self.pos = end;
            return Some(v);
        }
        while !ends_token(self.b.get(self.pos)) {
            self.pos += 1;
        }
        // Tokens end at ASCII bytes of a `str`: each is UTF-8.
        std::str::from_utf8(&self.b[start..self.pos]).ok()?.parse().ok()
    }

    /// The next token on this line as a plain non-negative integer (ASCII
    /// digits only, at most 18 of them); `None` for anything else.
    #[inline]
    fn integer(&mut self) -> Option<u64> {
        self.skip_blanks();
        let (b, start) = (self.b, self.pos);
        let mut v = 0u64;
        let mut i = start;
        while let Some(&d) = b.get(i).filter(|d| d.is_ascii_digit()) {
            v = v.wrapping_mul(10).wrapping_add(u64::from(d - b'0'));
            i += 1;
        }
        if i == start || i - start > 18 || !ends_token(b.get(i)) {
            return None;
        }
        self.pos = i;
        Some(v)
    }

    /// The next token as a vertex index below `n`.
    #[inline]
    fn index(&mut self, n: u64) -> Option<u32> {
        self.integer().filter(|&i| i < n).map(|i| i as u32)
    }
}

/// Bytes looked at at once by [`take_lines`].
const SCAN_BLOCK: usize = 4096;

/// The first `want` non-blank lines of `text` (lines end after `\n`; blank:
/// empty after `str::trim`) and any blank lines among them: the bytes and the
/// lines taken and how many were not blank, fewer than `want` where the text
/// ends first. What `text.split_inclusive('\n')` gives piece by piece, but
/// [`SCAN_BLOCK`] bytes at a time where every line in them starts with a
/// visible ASCII byte (none is blank): their line ends are then counted in a
/// loop the compiler vectorizes.
pub(super) fn take_lines(text: &str, want: usize) -> (usize, usize, usize) {
    let b = text.as_bytes();
    let (mut pos, mut lines, mut n) = (0, 0, 0);
    while n < want && pos < b.len() {
        if b[pos].is_ascii_graphic() && pos + SCAN_BLOCK < b.len() {
            let block = &b[pos..pos + SCAN_BLOCK];
            let ends = block.iter().fold(0usize, |c, &x| c + usize::from(x == b'\n'));
            let blank_next = block
                .iter()
                .zip(&b[pos + 1..])
                .fold(0usize, |c, (&x, y)| c + usize::from(x == b'\n' && !y.is_ascii_graphic()));
            if ends > 0 && blank_next == 0 && n + ends <= want {
                pos += block.iter().rposition(|&x| x == b'\n').map_or(0, |i| i + 1);
                (lines, n) = (lines + ends, n + ends);
                continue;
            }
        }
        let end = text[pos..].find('\n').map_or(b.len(), |i| pos + i + 1);
        lines += 1;
        n += usize::from(!text[pos..end].trim().is_empty());
        pos = end;
    }
    (pos, lines, n)
}

/// The plain decimal number that starts at `b[start]` (see the module's
/// notes) and where it ends; `None` when the token there is anything else or
/// outside Clinger's fast path.
#[inline]
fn plain_number(b: &[u8], start: usize) -> Option<(f64, usize)> {
    let mut i = start;
    let neg = match b.get(i) {
        Some(b'-') => {
            i += 1;
            true
        }
        Some(b'+') => {
            i += 1;
            false
        }
        _ => false,
    };
    // `m` holds the digits (past 19 it may have wrapped, and the token is refused).
    let (mut m, mut digits, mut frac) = (0u64, 0usize, 0usize);
    while let Some(&d) = b.get(i).filter(|d| d.is_ascii_digit()) {
        m = m.wrapping_mul(10).wrapping_add(u64::from(d - b'0'));
        digits += 1;
        i += 1;
    }
    if b.get(i) == Some(&b'.') {
        i += 1;
        while let Some(&d) = b.get(i).filter(|d| d.is_ascii_digit()) {
            m = m.wrapping_mul(10).wrapping_add(u64::from(d - b'0'));
            frac += 1;
            i += 1;
        }
    }
    if digits + frac == 0 || digits + frac > 19 || m >= 1 << 53 || frac > 22 || !ends_token(b.get(i)) {
        return None;
    }
    let v = m as f64 / POW10[frac];
    Some((if neg { -v } else { v }, i))
}

impl Ascii<'_> {
    /// Chunk `c` scanned byte by byte (see the module's notes): the data of
    /// [`Ascii::chunk_by_lines`], or `None` where that reader should run.
    pub(super) fn fast_chunk(&self, c: &Chunk) -> Option<PlyData> {
        let el = &self.elements[c.ei];
        let (vertices, faces) = (c.ei == self.vi, c.ei == self.fi);
        let n_vertices = self.elements[self.vi].count as u64;
        let mut part = PlyData {
            positions: Vec::with_capacity(if vertices { c.lines } else { 0 }),
            triangles: Vec::with_capacity(if faces { c.lines } else { 0 }),
            normals: self.layout.normal.filter(|_| vertices).map(|_| Vec::with_capacity(c.lines)),
            uvs: self.layout.uv.filter(|_| vertices).map(|_| Vec::with_capacity(c.lines)),
        };
        let mut vals = vec![0.0; el.props.len()];
        let mut at = Bytes { b: self.text[c.range.clone()].as_bytes(), pos: 0 };
        loop {
            match at.skip_blanks() {
                None => break,
                Some(b'\n') => {
                    at.pos += 1;
                    continue;
                }
                Some(_) => {}
            }
            for (pi, p) in el.props.iter().enumerate() {
                vals[pi] = match p.kind {
                    Kind::Scalar(_) => at.number()?,
                    Kind::List(..) if faces && pi == self.layout.face_list => {
                        let n = at.integer()?;
                        if n < 3 {
                            return None;
                        }
                        let first = at.index(n_vertices)?;
                        let mut prev = at.index(n_vertices)?;
                        for _ in 2..n {
                            let next = at.index(n_vertices)?;
                            part.triangles.push([first, prev, next]);
                            prev = next;
                        }
                        0.0
                    }
                    Kind::List(..) => {
                        for _ in 0..at.integer()? {
                            at.number()?;
                        }
                        0.0
                    }
                };
            }
            match at.skip_blanks() {
                None => {}
                Some(b'\n') => at.pos += 1,
                Some(_) => return None,
            }
            if vertices {
                push_vertex(&mut part, self.layout, |k| vals[k]);
            }
        }
        Some(part)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{same, text};
    use super::super::{ASCII_CHUNK_LINES, Format, layout_of, parse_header, parse_in};
    use super::*;
    use std::path::Path;

    /// A xorshift generator.
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }

        /// A number below `n`.
        fn below(&mut self, n: usize) -> usize {
            (self.next() % n as u64) as usize
        }
    }

    /// `Bytes::number` on one token, alone and followed by other tokens (the
    /// reader then sees bytes past it): the same value both ways, the token
    /// read to its end when it is a number.
    fn number(tok: &str) -> Option<f64> {
        let mut alone = Bytes { b: tok.as_bytes(), pos: 0 };
        let v = alone.number();
        let line = format!("{tok} 1234567890\t5\n");
        let mut followed = Bytes { b: line.as_bytes(), pos: 0 };
        assert_eq!(followed.number().map(f64::to_bits), v.map(f64::to_bits), "{tok:?}");
        if v.is_some() {
            assert_eq!((alone.pos, followed.pos), (tok.len(), tok.len()), "{tok:?} read to its end");
        }
        v
    }

    /// A random token: digits with a point somewhere or none, a sign or none,
    /// leading zeros, sometimes an exponent, sometimes junk.
    fn token(r: &mut Rng) -> String {
        let mut t = String::new();
        t += ["", "", "-", "+"][r.below(4)];
        let n = 1 + r.below(22);
        let point = r.below(n + 3);
        let zeros = if r.below(4) == 0 { r.below(4) } else { 0 };
        for k in 0..n {
            if k == point {
                t.push('.');
            }
            t.push(if k < zeros { '0' } else { char::from(b'0' + r.below(10) as u8) });
        }
        if point == n {
            t.push('.');
        }
        match r.below(20) {
            0 => t += &format!("e{}", r.below(60) as i32 - 30),
            1 => t += &format!("E+{}", r.below(400)),
            2 => t.insert(r.below(t.len() + 1), ['.', '-', '+', 'x', 'e'][r.below(5)]),
            _ => {}
        }
        t
    }

    /// The number reader against `str::parse::<f64>`, bit for bit (or both
    /// refuse), on over a million tokens: random digits, signs, points,
    /// leading zeros and exponents; random doubles and floats printed
    /// shortest, with 9 significant digits and with 17 decimals; midpoints
    /// between neighbouring floats (where the f64 to f32 rounding meets a
    /// tie); short decimals as mesh writers print them; the edges of the fast
    /// path (2^53, 19 digits, 10^22) and odd tokens. Every plain short token
    /// (at most 12 bytes of digits, signs and points that `str::parse`
    /// accepts, so at most 12 digits) takes the fast path, or the test would
    /// prove little.
    #[test]
    fn numbers_are_parse_f64_bit_for_bit() {
        let mut r = Rng(0x9e37_79b9_7f4a_7c15);
        let mut toks: Vec<String> = [
            "0",
            "-0",
            "+0",
            "0.",
            "-0.",
            ".5",
            "-.5",
            "+.5",
            ".",
            "-",
            "+",
            "-.",
            "00",
            "007.50",
            "1e5",
            "1.5E-3",
            "nan",
            "NaN",
            "inf",
            "-infinity",
            "1.2.3",
            "--1",
            "1-",
            "+-1",
            "0x10",
            "9007199254740991",
            "9007199254740992",
            "9007199254740993",
            "-9007199254740993",
            "1234567890123456789",
            "12345678901234567890",
            "0.0000000000000000000001",
            "0.00000000000000000000001",
            "4.9406564584124654e-324",
            "1797693134862315708145274237317043567981",
            "0.1",
            "0.2",
            "0.3",
            "1.7976931348623157",
            "3.4028235",
        ]
        .map(String::from)
        .into();
        for _ in 0..400_000 {
            toks.push(token(&mut r));
        }
        for _ in 0..100_000 {
            let d = f64::from_bits(r.next());
            let f = f32::from_bits(r.next() as u32);
            let mid = (f as f64 + f.next_up() as f64) / 2.0;
            // A float as a mesh has them, with 9 significant digits.
            let g = (r.below(1 << 24) as f32 / (1 << 23) as f32 - 1.0) * [0.01, 0.1, 1.0, 10.0, 100.0][r.below(5)];
            let decimals = (8 - g.abs().log10().floor() as i32).clamp(0, 20) as usize;
            let (int, w) = (r.below(1000), r.below(9));
            let sign = ["", "-"][r.below(2)];
            toks.extend([
                format!("{d}"),
                format!("{d:.17}"),
                format!("{f}"),
                format!("{f:.8e}"),
                format!("{mid}"),
                format!("{mid:.30}"),
                format!("{g}"),
                format!("{g:.decimals$}"),
                format!("{sign}{int}.{:0>w$}", r.below(10usize.pow(w as u32))),
            ]);
        }
        let (mut fast, mut plain, mut ints) = (0, 0, 0);
        for t in &toks {
            let want = t.parse::<f64>().ok();
            let got = number(t);
            assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits), "{t:?}");
            let quick = plain_number(t.as_bytes(), 0);
            if let Some((v, end)) = quick {
                assert_eq!((Some(v.to_bits()), end), (want.map(f64::to_bits), t.len()), "{t:?}");
            }
            if t.len() <= 12 && t.bytes().all(|b| b"+-.0123456789".contains(&b)) && want.is_some() {
                plain += 1;
                fast += usize::from(quick.is_some());
            }
            if !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit()) {
                // Indices and counts: `str::parse::<u64>`'s value up to 18 digits.
                let want = t.parse::<u64>().ok().filter(|_| t.len() <= 18);
                let line = format!("{t}\t7 8\n");
                let (mut alone, mut followed) =
                    (Bytes { b: t.as_bytes(), pos: 0 }, Bytes { b: line.as_bytes(), pos: 0 });
                assert_eq!((alone.integer(), followed.integer()), (want, want), "{t:?}");
                ints += 1;
            }
        }
        assert!(ints > 50_000, "{ints} integer tokens");
        assert!(toks.len() > 1_000_000, "{}", toks.len());
        assert!(plain > 300_000 && fast == plain, "{fast} of {plain} plain short tokens took the fast path");
    }

    /// [`take_lines`] against `split_inclusive('\n')` piece by piece (the
    /// scan it replaces), taking a text in runs of `want` non-blank lines to
    /// its end, on random texts: mostly number lines (runs longer than
    /// [`SCAN_BLOCK`] bytes with no blank line), some blank lines of spaces,
    /// tabs, `\r`, a vertical tab or a no-break space, lines starting with
    /// blanks, lines longer than a block, with or without a last line end.
    #[test]
    fn take_lines_counts_as_split_inclusive() {
        fn reference(text: &str, want: usize) -> (usize, usize, usize) {
            let (mut bytes, mut lines, mut n) = (0, 0, 0);
            for piece in text.split_inclusive('\n') {
                if n == want {
                    break;
                }
                (bytes, lines) = (bytes + piece.len(), lines + 1);
                n += usize::from(!piece.trim().is_empty());
            }
            (bytes, lines, n)
        }
        let mut r = Rng(0x1234_5678_9abc_def1);
        let odd = ["", "  ", "\t", "\r", "\x0b", "\u{a0}", " 1 2", "\t3", "\r\r", "x"];
        for round in 0..300 {
            let mut t = String::new();
            let rate = [10, 100, 10_000][round % 3];
            while t.len() < 30_000 {
                match r.below(rate) {
                    0 => t += odd[r.below(odd.len())],
                    1 => t += &"7 ".repeat(3000),
                    _ => t += &format!("{} {} -{}", r.below(1000), r.below(10), r.below(100_000)),
                }
                t += ["\n", "\r\n"][usize::from(r.below(20) == 0)];
            }
            if round % 2 == 0 {
                t.pop();
            }
            let want = 1 + r.below([3, 100, 5000][round % 3]);
            let (mut offset, mut total) = (0, 0);
            while offset < t.len() {
                let got = take_lines(&t[offset..], want);
                assert_eq!(got, reference(&t[offset..], want), "round {round}, at byte {offset}");
                (offset, total) = (offset + got.0, total + got.1);
            }
            assert_eq!(total, t.split_inclusive('\n').count());
        }
    }

    /// Both chunk readers on every chunk of `t` (at most `chunk_lines` lines
    /// each): the fast path gives data only where the line reader does, and
    /// the same data. How many chunks took the fast path, of how many; `None`
    /// where `t` has no ASCII chunks (a bad header, a short body).
    fn fast_agrees(t: &[u8], chunk_lines: usize) -> Option<(usize, usize)> {
        let path = Path::new("t.ply");
        let (elements, format, body, header_lines) = parse_header(t, path).ok()?;
        let (vi, fi, layout) = layout_of(&elements, path).ok()?;
        let text = std::str::from_utf8(body).ok().filter(|_| format == Format::Ascii)?;
        let a = Ascii { text, header_lines, elements: &elements, vi, fi, layout: &layout, path };
        let chunks = a.chunks(chunk_lines)?;
        let mut fast = 0;
        for c in &chunks {
            let by_lines = a.chunk_by_lines(c);
            if let Some(d) = a.fast_chunk(c) {
                let want = by_lines.as_ref().map_err(|e| e.to_string()).expect("no fast data for a bad chunk");
                assert!(same(&d, want), "{:?}", std::str::from_utf8(t));
                fast += 1;
            }
        }
        Some((fast, chunks.len()))
    }

    /// A PLY whose elements have lists and scalars around the face list, with
    /// tabs, numbers with exponents, signs and bare points, `-0` and long
    /// digit strings.
    fn odd() -> String {
        let mut t = String::from(
            "ply\nformat ascii 1.0\nelement vertex 6\nproperty double y\nproperty list uchar float w\n\
             property float x\nproperty float z\nelement face 4\nproperty int flags\n\
             property list uchar uint vertex_index\nproperty float q\nend_header\n",
        );
        let nums = ["1e-3", "+0.5", ".5", "5.", "-0", "0.1000000000000000055511151231257827", "-1.5E2", "7"];
        for i in 0..6 {
            let (a, b) = (nums[i % nums.len()], nums[(i * 3 + 1) % nums.len()]);
            t += &format!("{a}\t{} {}\t{b} {a} \n", i % 3, ["", "1e1", "3.5 -4"][i % 3]);
        }
        t += "0 3 0 1 2 1e0\n-7 4 2 3 4 5 .5\n\t3\t3 5 4 3\t+1\n1 5 0 1 2 3 4 -0\n";
        t
    }

    /// The fast path on whole files: every chunk of the test files, in
    /// chunks from 1 line to more than the file, takes it and gives the line
    /// reader's data; the whole chunked parse is the serial one.
    #[test]
    fn fast_chunks_equal_line_chunks() {
        let path = Path::new("t.ply");
        for t in [text(40), text(7), odd()] {
            let serial = parse_in(t.as_bytes(), path, None).unwrap();
            assert!(serial.positions.len() >= 6 && serial.triangles.len() >= 4);
            for chunk in [1, 2, 3, 7, 16, 1000] {
                let (fast, all) = fast_agrees(t.as_bytes(), chunk).expect("chunks");
                assert_eq!(fast, all, "chunks of {chunk}");
                assert!(same(&serial, &parse_in(t.as_bytes(), path, Some(chunk)).unwrap()), "chunks of {chunk}");
            }
        }
    }

    /// Random edits of the test files (bytes replaced, inserted and deleted:
    /// digits, signs, points, blanks, line ends, `e`, a vertical tab, a
    /// no-break space, a byte that is not UTF-8): the fast path never gives
    /// data for a chunk the line reader refuses, gives the same data
    /// otherwise, and refuses some chunks the line reader accepts (`+3` as a
    /// count, `3.` as an index). The chunked parse gives the serial parse's
    /// data or exactly its error.
    #[test]
    fn fast_chunks_agree_on_mutations() {
        let path = Path::new("t.ply");
        let mut r = Rng(0x2545_f491_4f6c_dd1d);
        let (mut fast, mut all, mut bad) = (0, 0, 0);
        for round in 0..3000 {
            let mut t = [text(12), odd()][round % 2].clone().into_bytes();
            for _ in 0..1 + r.below(3) {
                let k = r.below(t.len());
                let b = [
                    &b"\n"[..],
                    b" ",
                    b"\t",
                    b"\r",
                    b"7",
                    b"0",
                    b"-",
                    b"+",
                    b".",
                    b"e",
                    b"\x0b",
                    "\u{a0}".as_bytes(),
                    b"\xff",
                ][r.below(13)];
                match r.below(3) {
                    0 => drop(t.splice(k..k + 1, b.iter().copied())),
                    1 => drop(t.splice(k..k, b.iter().copied())),
                    _ => drop(t.remove(k)),
                }
            }
            if let Some((f, a)) = fast_agrees(&t, 1 + r.below(5)) {
                (fast, all) = (fast + f, all + a);
            }
            let serial = parse_in(&t, path, None).map_err(|e| e.to_string());
            let chunked = parse_in(&t, path, Some(1 + r.below(5))).map_err(|e| e.to_string());
            match (&serial, &chunked) {
                (Ok(a), Ok(b)) => assert!(same(a, b), "round {round}"),
                (a, b) => {
                    assert_eq!(a.as_ref().err(), b.as_ref().err(), "round {round}");
                    bad += 1;
                }
            }
        }
        assert!(all > 5_000 && fast > all / 2 && fast < all, "{fast} of {all} chunks took the fast path");
        assert!(bad > 300 && bad < 2900, "{bad} of 3000 edited files fail: the edits should break some, not all");
    }

    /// The full Stanford dragon, where `../shared/meshes` has it: every chunk
    /// takes the fast path, and the chunked and streamed parses give the
    /// serial reader's data.
    #[test]
    fn full_dragon_takes_the_fast_path() {
        use std::io::Read;
        let gz = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes/dragon_vrip.ply.gz");
        let Ok(raw) = std::fs::read(&gz) else {
            eprintln!("skipped: {} is absent", gz.display());
            return;
        };
        let mut data = Vec::new();
        flate2::read::MultiGzDecoder::new(raw.as_slice()).read_to_end(&mut data).unwrap();
        let path = Path::new("dragon_vrip.ply");
        let serial = parse_in(&data, path, None).unwrap();
        assert_eq!((serial.positions.len(), serial.triangles.len()), (437_645, 871_414));
        let (fast, all) = fast_agrees(&data, ASCII_CHUNK_LINES).unwrap();
        assert_eq!(fast, all);
        assert!(same(&serial, &parse_in(&data, path, Some(ASCII_CHUNK_LINES)).unwrap()));
        assert!(same(&serial, &super::super::parse_gz(&raw, path).unwrap()));
    }
}
