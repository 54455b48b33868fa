//! A PLY reader (ASCII, binary little- and big-endian) for triangle meshes: vertex
//! positions, optional normals and polygon faces (fan-triangulated). Unknown
//! properties and elements are skipped, in binary too (their sizes are computed
//! from the header). Every error names the file and, for ASCII, the line.

use crate::error::{Error, Result};
use glam::Vec3;
use std::path::Path;

mod ascii;
mod stream;
pub(crate) use stream::parse_gz;

/// What a PLY file yields: positions, triangles (vertex indices) and optional normals.
pub(crate) struct PlyData {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<[f32; 2]>>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Ty {
    fn parse(s: &str) -> Option<Ty> {
        Some(match s {
            "char" | "int8" => Ty::I8,
            "uchar" | "uint8" => Ty::U8,
            "short" | "int16" => Ty::I16,
            "ushort" | "uint16" => Ty::U16,
            "int" | "int32" => Ty::I32,
            "uint" | "uint32" => Ty::U32,
            "float" | "float32" => Ty::F32,
            "double" | "float64" => Ty::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::F64 => 8,
        }
    }

    fn is_int(self) -> bool {
        !matches!(self, Ty::F32 | Ty::F64)
    }
}

#[derive(Debug)]
enum Kind {
    Scalar(Ty),
    List(Ty, Ty),
}

#[derive(Debug)]
struct Prop {
    name: String,
    kind: Kind,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Prop>,
}

#[derive(Clone, Copy, PartialEq)]
enum Format {
    Ascii,
    LittleEndian,
    BigEndian,
}

/// Where the interesting data sits in the vertex and face elements.
struct Layout {
    xyz: [usize; 3],
    normal: Option<[usize; 3]>,
    uv: Option<[usize; 2]>,
    face_list: usize,
}

/// Parses a whole (decompressed) PLY file.
pub(crate) fn parse(data: &[u8], path: &Path) -> Result<PlyData> {
    parse_in(data, path, (data.len() >= PARALLEL_ASCII_BYTES).then_some(ASCII_CHUNK_LINES))
}

/// [`parse`], an ASCII body in chunks of `chunk_lines` lines on the thread
/// pool (`None`: line by line).
fn parse_in(data: &[u8], path: &Path, chunk_lines: Option<usize>) -> Result<PlyData> {
    let (elements, format, body, header_lines) = parse_header(data, path)?;
    let (vi, fi, layout) = layout_of(&elements, path)?;
    let (ve, fe) = (&elements[vi], &elements[fi]);
    // The header can claim any count: reserve no more than the body can hold (every
    // element takes at least one byte), or a corrupt count aborts on allocation.
    let (nv, nf) = (ve.count.min(body.len()), fe.count.min(body.len()));
    let mut out = PlyData {
        positions: Vec::with_capacity(nv),
        triangles: Vec::with_capacity(nf * 2),
        normals: layout.normal.map(|_| Vec::with_capacity(nv)),
        uvs: layout.uv.map(|_| Vec::with_capacity(nv)),
    };
    match format {
        Format::Ascii => {
            let text =
                std::str::from_utf8(body).map_err(|_| Error::mesh(path, "PLY body is not text (format says ascii)"))?;
            let a = Ascii { text, header_lines, elements: &elements, vi, fi, layout: &layout, path };
            if !chunk_lines.is_some_and(|n| a.read_chunked(&mut out, n)) {
                a.read_serial(&mut out)?;
            }
        }
        _ => read_binary(body, format, &elements, vi, fi, &layout, &mut out, path)?,
    }
    Ok(out)
}

/// Where the vertex and face elements are and where their data sits in them.
fn layout_of(elements: &[Element], path: &Path) -> Result<(usize, usize, Layout)> {
    let err = |msg: String| Error::mesh(path, msg);
    let vi = elements
        .iter()
        .position(|e| e.name == "vertex")
        .ok_or_else(|| err("PLY header has no 'vertex' element".into()))?;
    let fi =
        elements.iter().position(|e| e.name == "face").ok_or_else(|| err("PLY header has no 'face' element".into()))?;
    let find =
        |e: &Element, name: &str| e.props.iter().position(|p| p.name == name && matches!(p.kind, Kind::Scalar(_)));
    let ve = &elements[vi];
    let mut xyz = [0; 3];
    for (k, name) in ["x", "y", "z"].iter().enumerate() {
        xyz[k] = find(ve, name).ok_or_else(|| err(format!("PLY 'vertex' element has no scalar property '{name}'")))?;
    }
    let normal = match (find(ve, "nx"), find(ve, "ny"), find(ve, "nz")) {
        (Some(a), Some(b), Some(c)) => Some([a, b, c]),
        _ => None,
    };
    // Texture coordinates under the names PLY writers use (Blender and MeshLab:
    // `s t`; others `u v`, `texture_u texture_v`, `texture_s texture_t`).
    let uv = [["u", "v"], ["s", "t"], ["texture_u", "texture_v"], ["texture_s", "texture_t"]]
        .iter()
        .find_map(|[a, b]| Some([find(ve, a)?, find(ve, b)?]));
    let fe = &elements[fi];
    let face_list = fe
        .props
        .iter()
        .position(|p| (p.name == "vertex_indices" || p.name == "vertex_index") && matches!(p.kind, Kind::List(..)))
        .ok_or_else(|| err("PLY 'face' element has no list property 'vertex_indices' or 'vertex_index'".into()))?;
    if let Kind::List(c, i) = fe.props[face_list].kind
        && (!c.is_int() || !i.is_int())
    {
        return Err(err("PLY face list must have integer count and index types".into()));
    }
    Ok((vi, fi, Layout { xyz, normal, uv, face_list }))
}

type Header<'a> = (Vec<Element>, Format, &'a [u8], usize);

fn parse_header<'a>(data: &'a [u8], path: &Path) -> Result<Header<'a>> {
    let err = |line: usize, msg: String| Error::mesh(path, format!("line {line}: {msg}"));
    let mut pos = 0;
    let mut line_no = 0;
    let mut elements: Vec<Element> = Vec::new();
    let mut format = None;
    loop {
        line_no += 1;
        let Some(len) = data[pos..].iter().position(|&b| b == b'\n') else {
            return Err(err(line_no, "unexpected end of file in the PLY header (expected 'end_header')".into()));
        };
        let line = std::str::from_utf8(&data[pos..pos + len])
            .map_err(|_| err(line_no, "PLY header is not ASCII text".into()))?
            .trim();
        pos += len + 1;
        let words: Vec<&str> = line.split_ascii_whitespace().collect();
        if line_no == 1 {
            if line != "ply" {
                return Err(err(1, format!("expected 'ply', found '{line}'")));
            }
            continue;
        }
        match words.first().copied() {
            None | Some("comment") | Some("obj_info") => {}
            Some("format") => {
                format = Some(match words.get(1).copied() {
                    Some("ascii") => Format::Ascii,
                    Some("binary_little_endian") => Format::LittleEndian,
                    Some("binary_big_endian") => Format::BigEndian,
                    other => return Err(err(line_no, format!("unknown PLY format {other:?}"))),
                });
            }
            Some("element") => {
                let (Some(name), Some(count), 3) = (words.get(1), words.get(2), words.len()) else {
                    return Err(err(line_no, "expected 'element <name> <count>'".into()));
                };
                let count = count.parse().map_err(|_| err(line_no, format!("bad element count '{count}'")))?;
                elements.push(Element { name: name.to_string(), count, props: Vec::new() });
            }
            Some("property") => {
                let Some(el) = elements.last_mut() else {
                    return Err(err(line_no, "'property' before any 'element'".into()));
                };
                let ty = |s: &str| Ty::parse(s).ok_or_else(|| err(line_no, format!("unknown PLY type '{s}'")));
                let prop = match words.as_slice() {
                    ["property", "list", c, i, name] => {
                        Prop { name: name.to_string(), kind: Kind::List(ty(c)?, ty(i)?) }
                    }
                    ["property", t, name] => Prop { name: name.to_string(), kind: Kind::Scalar(ty(t)?) },
                    _ => {
                        return Err(err(
                            line_no,
                            "expected 'property <type> <name>' or 'property list <count type> <type> <name>'".into(),
                        ));
                    }
                };
                el.props.push(prop);
            }
            Some("end_header") => break,
            Some(other) => {
                return Err(err(line_no, format!("unknown PLY header keyword '{other}'")));
            }
        }
    }
    let format = format.ok_or_else(|| err(line_no, "PLY header has no 'format' line".into()))?;
    Ok((elements, format, &data[pos..], line_no))
}

/// ASCII bodies of at least this many bytes are parsed in chunks on the thread pool.
const PARALLEL_ASCII_BYTES: usize = 1 << 20;

/// Non-blank lines per chunk of a parallel ASCII parse.
const ASCII_CHUNK_LINES: usize = 16384;

/// Where an ASCII body's data sits, shared by its readers.
struct Ascii<'a> {
    text: &'a str,
    header_lines: usize,
    elements: &'a [Element],
    vi: usize,
    fi: usize,
    layout: &'a Layout,
    path: &'a Path,
}

/// One part of a chunked ASCII parse: element `ei`'s lines in `range` of the
/// text, the first of them line `first_line` of the file, `lines` of them not
/// blank.
struct Chunk {
    ei: usize,
    range: std::ops::Range<usize>,
    first_line: usize,
    lines: usize,
}

impl Ascii<'_> {
    /// The whole body, line by line: the reference reader, and the one whose
    /// errors every reader reports.
    fn read_serial(&self, out: &mut PlyData) -> Result<()> {
        let mut lines = self.text.lines().enumerate().map(|(i, l)| (i + self.header_lines + 1, l));
        let mut last_line = self.header_lines;
        let (mut vals, mut poly) = (Vec::new(), Vec::new());
        for (ei, el) in self.elements.iter().enumerate() {
            for instance in 0..el.count {
                // Next non-blank line.
                let (ln, line) = loop {
                    match lines.next() {
                        Some((ln, l)) if l.trim().is_empty() => last_line = ln,
                        Some(x) => break x,
                        None => {
                            return Err(Error::mesh(
                                self.path,
                                format!(
                                    "line {}: unexpected end of file: expected {} '{}' lines, found {instance}",
                                    last_line + 1,
                                    el.count,
                                    el.name
                                ),
                            ));
                        }
                    }
                };
                last_line = ln;
                self.line(ei, line, ln, out, &mut vals, &mut poly)?;
            }
        }
        Ok(())
    }

    /// The body in chunks of `chunk_lines` non-blank lines, parsed at once on
    /// the thread pool and joined in file order: the same data as
    /// [`Ascii::read_serial`], bit for bit. A serial scan finds the chunks'
    /// byte ranges (no per-line index is kept). False, with `out` untouched,
    /// when any line is bad or the file ends early: the serial reader then
    /// reports the first error as it always has.
    fn read_chunked(&self, out: &mut PlyData, chunk_lines: usize) -> bool {
        use rayon::prelude::*;
        let Some(chunks) = self.chunks(chunk_lines) else { return false };
        let parts: Vec<Option<PlyData>> = chunks.par_iter().map(|c| self.chunk(c).ok()).collect();
        append(out, parts)
    }

    /// The body's chunks of at most `chunk_lines` non-blank lines of one
    /// element each, in file order; `None` when the file ends early.
    fn chunks(&self, chunk_lines: usize) -> Option<Vec<Chunk>> {
        let mut chunks = Vec::new();
        let (mut offset, mut ln) = (0usize, self.header_lines);
        for (ei, el) in self.elements.iter().enumerate() {
            let mut remaining = el.count;
            while remaining > 0 {
                let want = remaining.min(chunk_lines);
                let (bytes, lines, n) = ascii::take_lines(&self.text[offset..], want);
                if n < want {
                    return None;
                }
                let start = offset;
                offset += bytes;
                chunks.push(Chunk { ei, range: start..offset, first_line: ln + 1, lines: n });
                ln += lines;
                remaining -= n;
            }
        }
        Some(chunks)
    }

    /// One chunk's vertices or triangles: by the fast path
    /// ([`Ascii::fast_chunk`]) where it can, else line by line.
    fn chunk(&self, c: &Chunk) -> Result<PlyData> {
        self.fast_chunk(c).map_or_else(|| self.chunk_by_lines(c), Ok)
    }

    /// One chunk's vertices or triangles, line by line with [`Ascii::line`]
    /// (the same data as [`Ascii::fast_chunk`], and the errors).
    fn chunk_by_lines(&self, c: &Chunk) -> Result<PlyData> {
        let vertices = c.ei == self.vi;
        let mut part = PlyData {
            positions: Vec::new(),
            triangles: Vec::new(),
            normals: self.layout.normal.filter(|_| vertices).map(|_| Vec::new()),
            uvs: self.layout.uv.filter(|_| vertices).map(|_| Vec::new()),
        };
        let (mut vals, mut poly) = (Vec::new(), Vec::new());
        for (k, line) in self.text[c.range.clone()].lines().enumerate() {
            if !line.trim().is_empty() {
                self.line(c.ei, line, c.first_line + k, &mut part, &mut vals, &mut poly)?;
            }
        }
        Ok(part)
    }

    /// Parses line `ln`, an instance of element `ei`, into `out`.
    fn line(
        &self,
        ei: usize,
        line: &str,
        ln: usize,
        out: &mut PlyData,
        vals: &mut Vec<f64>,
        poly: &mut Vec<i64>,
    ) -> Result<()> {
        let el = &self.elements[ei];
        let err = |msg: String| Error::mesh(self.path, format!("line {ln}: {msg}"));
        let mut tok = line.split_ascii_whitespace();
        let mut next_num = |what: &dyn Fn() -> String| -> Result<f64> {
            let s = tok
                .next()
                .ok_or_else(|| err(format!("expected {} of element '{}', found end of line", what(), el.name)))?;
            s.parse::<f64>().map_err(|_| err(format!("expected a number for {}, found '{s}'", what())))
        };
        vals.clear();
        poly.clear();
        for (pi, p) in el.props.iter().enumerate() {
            match p.kind {
                Kind::Scalar(_) => vals.push(next_num(&|| format!("property '{}'", p.name))?),
                Kind::List(..) => {
                    let n = next_num(&|| format!("the count of list '{}'", p.name))?;
                    if !(n >= 0.0 && n.fract() == 0.0) {
                        return Err(err(format!("bad list count {n} for '{}'", p.name)));
                    }
                    let n = n as usize;
                    for k in 0..n {
                        let v = next_num(&|| format!("vertex index {} of {n} in list '{}'", k + 1, p.name))?;
                        if ei == self.fi && pi == self.layout.face_list {
                            if v.fract() != 0.0 {
                                return Err(err(format!("vertex index {v} is not an integer")));
                            }
                            poly.push(v as i64);
                        }
                    }
                    vals.push(0.0);
                }
            }
        }
        if tok.next().is_some() {
            return Err(err(format!("more values than the {} properties of element '{}'", el.props.len(), el.name)));
        }
        if ei == self.vi {
            push_vertex(out, self.layout, |k| vals[k]);
        } else if ei == self.fi {
            push_polygon(out, poly, self.elements[self.vi].count, err)?;
        }
        Ok(())
    }
}

/// Appends the parts of a chunked parse to `out` in order; false, with `out`
/// untouched, when any part failed.
fn append(out: &mut PlyData, parts: Vec<Option<PlyData>>) -> bool {
    if parts.iter().any(Option::is_none) {
        return false;
    }
    // The whole arrays at once: growing them part by part copied each several times.
    let total = |len: fn(&PlyData) -> usize| parts.iter().flatten().map(len).sum::<usize>();
    out.positions.reserve_exact(total(|p| p.positions.len()));
    out.triangles.reserve_exact(total(|p| p.triangles.len()));
    if let Some(o) = out.normals.as_mut() {
        o.reserve_exact(total(|p| p.normals.as_ref().map_or(0, Vec::len)));
    }
    if let Some(o) = out.uvs.as_mut() {
        o.reserve_exact(total(|p| p.uvs.as_ref().map_or(0, Vec::len)));
    }
    for part in parts.into_iter().flatten() {
        out.positions.extend_from_slice(&part.positions);
        out.triangles.extend_from_slice(&part.triangles);
        if let (Some(o), Some(p)) = (out.normals.as_mut(), &part.normals) {
            o.extend_from_slice(p);
        }
        if let (Some(o), Some(p)) = (out.uvs.as_mut(), &part.uvs) {
            o.extend_from_slice(p);
        }
    }
    true
}

fn push_vertex(out: &mut PlyData, layout: &Layout, val: impl Fn(usize) -> f64) {
    let [x, y, z] = layout.xyz;
    out.positions.push(Vec3::new(val(x) as f32, val(y) as f32, val(z) as f32));
    if let (Some(ns), Some([a, b, c])) = (out.normals.as_mut(), layout.normal) {
        ns.push(Vec3::new(val(a) as f32, val(b) as f32, val(c) as f32));
    }
    if let (Some(uvs), Some([u, v])) = (out.uvs.as_mut(), layout.uv) {
        uvs.push([val(u) as f32, val(v) as f32]);
    }
}

/// Fan-triangulates one polygon after checking its indices.
fn push_polygon(out: &mut PlyData, poly: &[i64], n_vertices: usize, err: impl Fn(String) -> Error) -> Result<()> {
    if poly.len() < 3 {
        return Err(err(format!("expected at least 3 vertex indices, found {}", poly.len())));
    }
    for &i in poly {
        if i < 0 || i as usize >= n_vertices {
            return Err(err(format!("vertex index {i} out of range (the file has {n_vertices} vertices)")));
        }
    }
    for k in 1..poly.len() - 1 {
        out.triangles.push([poly[0] as u32, poly[k] as u32, poly[k + 1] as u32]);
    }
    Ok(())
}

/// A cursor over binary PLY data.
struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
    big: bool,
}

impl Cursor<'_> {
    #[inline]
    fn read(&mut self, ty: Ty) -> Option<f64> {
        let n = ty.size();
        let b = self.data.get(self.pos..self.pos + n)?;
        self.pos += n;
        let mut a = [0u8; 8];
        a[..n].copy_from_slice(b);
        if self.big {
            a[..n].reverse();
        }
        Some(match ty {
            Ty::I8 => a[0] as i8 as f64,
            Ty::U8 => a[0] as f64,
            Ty::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
            Ty::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
            Ty::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Ty::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Ty::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Ty::F64 => f64::from_le_bytes(a),
        })
    }
}

#[allow(clippy::too_many_arguments)]
fn read_binary(
    body: &[u8],
    format: Format,
    elements: &[Element],
    vi: usize,
    fi: usize,
    layout: &Layout,
    out: &mut PlyData,
    path: &Path,
) -> Result<()> {
    let mut cur = Cursor { data: body, pos: 0, big: format == Format::BigEndian };
    let mut vals: Vec<f64> = Vec::new();
    let mut poly: Vec<i64> = Vec::new();
    for (ei, el) in elements.iter().enumerate() {
        for instance in 0..el.count {
            let err =
                |msg: String| Error::mesh(path, format!("element '{}' #{instance} (of {}): {msg}", el.name, el.count));
            let eof = || err("unexpected end of file (truncated?)".into());
            vals.clear();
            poly.clear();
            for (pi, p) in el.props.iter().enumerate() {
                match p.kind {
                    Kind::Scalar(t) => vals.push(cur.read(t).ok_or_else(eof)?),
                    Kind::List(ct, it) => {
                        let n = cur.read(ct).ok_or_else(eof)?;
                        if n < 0.0 {
                            return Err(err(format!("negative list count {n}")));
                        }
                        let n = n as usize;
                        if ei == fi && pi == layout.face_list {
                            for _ in 0..n {
                                poly.push(cur.read(it).ok_or_else(eof)? as i64);
                            }
                        } else {
                            // Skip the items without decoding them.
                            let skip = n.checked_mul(it.size()).ok_or_else(eof)?;
                            if cur.pos + skip > body.len() {
                                return Err(eof());
                            }
                            cur.pos += skip;
                        }
                        vals.push(0.0);
                    }
                }
            }
            if ei == vi {
                push_vertex(out, layout, |k| vals[k]);
            } else if ei == fi {
                push_polygon(out, &poly, elements[vi].count, err)?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An ASCII PLY with normals, uvs, an element between vertices and faces,
    /// quads, blank lines and CRLF line ends.
    pub(super) fn text(vertices: usize) -> String {
        let mut t = format!(
            "ply\nformat ascii 1.0\nelement vertex {vertices}\nproperty float x\nproperty float y\nproperty float z\n\
             property float nx\nproperty float ny\nproperty float nz\nproperty float s\nproperty float t\n\
             element edge 2\nproperty int a\nproperty int b\n\
             element face {}\nproperty list uchar int vertex_indices\nend_header\n",
            vertices - 3
        );
        for i in 0..vertices {
            let f = i as f32;
            t += &format!("{} {} {} 0 0 1 {} {}\r\n", f * 0.5, f * 0.25 - 3.0, 1.0 / (f + 1.0), f / 7.0, f / 11.0);
            if i % 5 == 2 {
                t += "   \n\n";
            }
        }
        t += "0 1\n\n1 2\n";
        for i in 0..vertices - 3 {
            if i % 3 == 0 {
                t += &format!("4 {} {} {} {}\n", i, i + 1, i + 2, i + 3)
            } else {
                t += &format!("3 {} {} {}\n", i, i + 1, i + 2)
            }
        }
        t
    }

    pub(super) fn same(a: &PlyData, b: &PlyData) -> bool {
        a.positions == b.positions && a.triangles == b.triangles && a.normals == b.normals && a.uvs == b.uvs
    }

    /// The chunked ASCII reader gives exactly the serial reader's data, for
    /// chunks from 1 line to more than the file, and exactly its error (the
    /// first in the file) for a bad number, an index out of range and a
    /// truncated file.
    #[test]
    fn chunked_ascii_equals_serial() {
        let path = Path::new("t.ply");
        let good = text(40);
        let serial = parse_in(good.as_bytes(), path, None).unwrap();
        assert_eq!(serial.positions.len(), 40);
        assert!(serial.triangles.len() > 37);
        for chunk in [1, 2, 3, 7, 16, 1000] {
            let chunked = parse_in(good.as_bytes(), path, Some(chunk)).unwrap();
            assert!(same(&serial, &chunked), "chunks of {chunk}");
        }
        let bad_number = good.replacen("\n10 2 ", "\n10 x2 ", 1);
        let out_of_range = good.replacen("3 20 21 22", "3 20 21 99", 1);
        let truncated = good[..good.len() - 30].to_string();
        for bad in [bad_number, out_of_range, truncated] {
            assert_ne!(bad, good);
            let want = parse_in(bad.as_bytes(), path, None).err().expect("an error").to_string();
            for chunk in [1, 3, 16] {
                let got = parse_in(bad.as_bytes(), path, Some(chunk)).err().expect("an error").to_string();
                assert_eq!(got, want);
            }
        }
    }
}
