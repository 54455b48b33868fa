//! A gzip-compressed ASCII PLY parsed while it inflates: this thread inflates
//! the file block by block, the header parses from the first block, and every
//! block's complete lines go to the thread pool as chunks at once, joined in
//! file order. The inflate, serial until now, overlaps the parse. The data is
//! [`super::parse`]'s of the inflated file, bit for bit; anything else (a
//! binary body, a bad line, a file that ends early, a gzip error) gives `None`
//! and the caller inflates and parses the whole file as before, so every error
//! is the serial reader's.

use std::io::Read;
use std::path::Path;
use std::sync::{Arc, mpsc};

use super::ascii::take_lines;
use super::{ASCII_CHUNK_LINES, Ascii, Chunk, Element, Format, PlyData, append, layout_of, parse_header};

/// Inflated bytes per block.
const BLOCK: usize = 1 << 20;

/// Inflated bytes per block while looking for the header's end (a binary
/// file's body is inflated only once, by the ordinary reader).
const HEADER_BLOCK: usize = 1 << 16;

/// The header must end within this many inflated bytes, or the whole file is
/// parsed the ordinary way.
const MAX_HEADER: usize = 1 << 20;

/// The PLY data of gzip-compressed `raw`, inflated and parsed at once (see the
/// module's notes); `None`: use [`super::parse`] on the inflated file instead.
pub(crate) fn parse_gz(raw: &[u8], path: &Path) -> Option<PlyData> {
    parse_gz_in(raw, path, BLOCK, ASCII_CHUNK_LINES)
}

/// [`parse_gz`] with `block` inflated bytes per block and at most `chunk_lines`
/// non-blank lines per chunk.
fn parse_gz_in(raw: &[u8], path: &Path, block: usize, chunk_lines: usize) -> Option<PlyData> {
    let mut gz = flate2::read::MultiGzDecoder::new(raw);
    let mut inflate = |buf: &mut Vec<u8>, max: usize| -> Option<usize> {
        buf.reserve(max);
        (&mut gz).take(max as u64).read_to_end(buf).ok()
    };
    // The header, from as many blocks as it takes.
    let mut head = Vec::new();
    let (elements, header_lines, body_start) = loop {
        let n = inflate(&mut head, block.min(HEADER_BLOCK))?;
        match parse_header(&head, path) {
            Ok((elements, Format::Ascii, body, lines)) => break (elements, lines, head.len() - body.len()),
            Ok(_) => return None,
            Err(_) if n > 0 && head.len() < MAX_HEADER => {}
            Err(_) => return None,
        }
    };
    let (vi, fi, layout) = layout_of(&elements, path).ok()?;
    let a = Ascii { text: "", header_lines, elements: &elements, vi, fi, layout: &layout, path };
    let mut scan = Scan::new(&elements, header_lines, chunk_lines);
    let mut carry = head.split_off(body_start);
    // `carry`'s first `no_newline` bytes have no line end.
    let mut no_newline = 0;
    drop(head);
    let (tx, rx) = mpsc::channel::<(usize, Option<PlyData>)>();
    let complete = rayon::scope(|s| {
        loop {
            let n = inflate(&mut carry, block)?;
            // The complete lines so far (at the end, all that is left). Only bytes not
            // searched before are searched: a line of any length costs linear time.
            let cut = match n {
                0 => carry.len(),
                _ => carry[no_newline..].iter().rposition(|&b| b == b'\n').map_or(0, |i| no_newline + i + 1),
            };
            if cut == 0 && n > 0 {
                no_newline = carry.len();
                continue;
            }
            let rest = carry[cut..].to_vec();
            no_newline = rest.len();
            carry.truncate(cut);
            let text = Arc::new(String::from_utf8(std::mem::replace(&mut carry, rest)).ok()?);
            for (k, chunk) in scan.chunks(&text, &elements) {
                let (tx, text, a) = (tx.clone(), Arc::clone(&text), &a);
                s.spawn(move |_| {
                    let part = Ascii { text: &text, ..*a }.chunk(&chunk).ok();
                    let _ = tx.send((k, part));
                });
            }
            if n == 0 {
                return Some(scan.ei == elements.len());
            }
        }
    });
    drop(tx);
    if complete != Some(true) {
        return None;
    }
    let mut parts: Vec<(usize, Option<PlyData>)> = rx.into_iter().collect();
    parts.sort_unstable_by_key(|p| p.0);
    let parts: Vec<Option<PlyData>> = parts.into_iter().map(|p| p.1).collect();
    let size = |f: fn(&PlyData) -> usize| parts.iter().flatten().map(f).sum::<usize>();
    let nv = size(|p| p.positions.len());
    let mut out = PlyData {
        positions: Vec::with_capacity(nv),
        triangles: Vec::with_capacity(size(|p| p.triangles.len())),
        normals: layout.normal.map(|_| Vec::with_capacity(nv)),
        uvs: layout.uv.map(|_| Vec::with_capacity(nv)),
    };
    append(&mut out, parts).then_some(out)
}

/// Where the streaming scan stands: element `ei` with `remaining` non-blank
/// lines to come, the last line seen `ln` (of the file), `chunks` made so far.
struct Scan {
    ei: usize,
    remaining: usize,
    ln: usize,
    chunk_lines: usize,
    chunks: usize,
}

impl Scan {
    fn new(elements: &[Element], ln: usize, chunk_lines: usize) -> Scan {
        let mut scan = Scan { ei: 0, remaining: elements.first().map_or(0, |e| e.count), ln, chunk_lines, chunks: 0 };
        scan.skip_done(elements);
        scan
    }

    /// Moves past elements with no lines left.
    fn skip_done(&mut self, elements: &[Element]) {
        while self.ei < elements.len() && self.remaining == 0 {
            self.ei += 1;
            self.remaining = elements.get(self.ei).map_or(0, |e| e.count);
        }
    }

    /// `text`'s chunks (the complete lines that follow the last text's),
    /// numbered in file order: at most `chunk_lines` non-blank lines of one
    /// element each, as [`Ascii::read_chunked`] makes them, and cut at the
    /// text's end. Lines after the last element are left alone.
    fn chunks(&mut self, text: &str, elements: &[Element]) -> Vec<(usize, Chunk)> {
        let mut out = Vec::new();
        let mut offset = 0;
        while self.ei < elements.len() {
            let (start, first_line) = (offset, self.ln + 1);
            let want = self.remaining.min(self.chunk_lines);
            let (bytes, lines, n) = take_lines(&text[offset..], want);
            self.ln += lines;
            offset += bytes;
            if n > 0 {
                out.push((self.chunks, Chunk { ei: self.ei, range: start..offset, first_line, lines: n }));
                self.chunks += 1;
            }
            self.remaining -= n;
            if n < want {
                break;
            }
            self.skip_done(elements);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{same, text};
    use super::*;
    use crate::io::gzip;

    /// Parsed while inflating, the data is the serial reader's of the inflated
    /// file bit for bit, for blocks from 1 byte (a block boundary in every line
    /// and in the header) to more than the file, and chunks from 1 line up; a
    /// file ending without a newline and one with lines after the last element
    /// too. A bad line, a truncated file, a binary body or a header that does
    /// not parse gives `None` (the ordinary reader then reports the error).
    #[test]
    fn streamed_equals_serial() {
        let path = Path::new("t.ply.gz");
        let good = text(40);
        let serial = super::super::parse_in(good.as_bytes(), path, None).unwrap();
        assert_eq!(serial.positions.len(), 40);
        let no_newline = good.trim_end().to_string();
        let trailing = format!("{good}\nextra line\n");
        for t in [&good, &no_newline, &trailing] {
            let gz = gzip(t.as_bytes());
            for block in [1, 2, 5, 64, 1000, 1 << 20] {
                for chunk in [1, 3, 16, 1000] {
                    let got = parse_gz_in(&gz, path, block, chunk).expect("streamed");
                    assert!(same(&serial, &got), "block {block}, chunk {chunk}");
                }
            }
        }
        // A line longer than many blocks (a vertex line padded with 5000 spaces).
        let padded = good.replacen("\n10 ", &format!("\n{}10 ", " ".repeat(5000)), 1);
        assert_ne!(padded, good);
        for block in [1, 7, 64] {
            let got = parse_gz_in(&gzip(padded.as_bytes()), path, block, 3).expect("streamed");
            assert!(same(&serial, &got), "padded, block {block}");
        }
        let bad_number = good.replacen("\n10 2 ", "\n10 x2 ", 1);
        let out_of_range = good.replacen("3 20 21 22", "3 20 21 99", 1);
        let truncated = good[..good.len() - 30].to_string();
        let binary = good.replacen("format ascii 1.0", "format binary_little_endian 1.0", 1);
        let no_face = good.replacen("element face", "element fac", 1);
        let not_utf8 = [good.as_bytes(), b"\xff\n"].concat();
        for bad in [
            bad_number.as_bytes(),
            out_of_range.as_bytes(),
            truncated.as_bytes(),
            binary.as_bytes(),
            no_face.as_bytes(),
            &not_utf8,
        ] {
            assert_ne!(bad, good.as_bytes());
            for block in [1, 7, 1 << 20] {
                assert!(parse_gz_in(&gzip(bad), path, block, 3).is_none());
            }
        }
    }

    /// Random byte edits of a small file (bit flips, digits, spaces, newlines,
    /// bytes that are not UTF-8): the streamed reader gives data exactly when
    /// the serial reader of the inflated text does, and then the same data;
    /// random edits of the gzip stream itself never panic and never give data
    /// unless the stream still inflates to a file the serial reader accepts.
    #[test]
    fn streamed_agrees_with_serial_on_mutations() {
        let path = Path::new("t.ply.gz");
        let good = text(12).into_bytes();
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = |n: usize| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % n as u64) as usize
        };
        let mut some = 0;
        for round in 0..400 {
            let mut t = good.clone();
            for _ in 0..1 + next(3) {
                let k = next(t.len());
                t[k] = [b'\n', b' ', b'7', b'-', b'.', 0xff, t[k] ^ 1][next(7)];
            }
            let gz = gzip(&t);
            let serial = super::super::parse_in(&t, path, None);
            let streamed = parse_gz_in(&gz, path, 1 + next(40), 1 + next(5));
            assert_eq!(streamed.is_some(), serial.is_ok(), "round {round}");
            if let (Some(a), Ok(b)) = (&streamed, &serial) {
                assert!(same(a, b), "round {round}");
                some += 1;
            }
            let mut z = gzip(&good);
            let k = next(z.len());
            z[k] ^= 1 << next(8);
            let inflated = {
                let mut out = Vec::new();
                flate2::read::MultiGzDecoder::new(z.as_slice()).read_to_end(&mut out).ok().map(|_| out)
            };
            if let Some(d) = parse_gz_in(&z, path, 1 + next(40), 1 + next(5)) {
                let text = inflated.expect("data only from a stream that inflates");
                assert!(same(&d, &super::super::parse_in(&text, path, None).expect("serial accepts it")));
            }
        }
        assert!(some > 20 && some < 380, "{some} of 400 edited files parse: the edits should break some, not all");
    }
}
